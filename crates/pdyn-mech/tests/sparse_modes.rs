//! The sparse path of equilibrium and modes (issue 33, item 5: "lowest 10 by the sparse path")
//! and damped modes, against closed forms derived by hand.

use pdyn_mech::damped::damped_modes;
use pdyn_mech::equilibrium::{EquilibriumError, EquilibriumOptions};
use pdyn_mech::linearization::Linearizer;
use pdyn_mech::sparse_statics::{lowest_modes, solve};
use pdyn_mech::{derive, load, DeriveOptions};

fn linearizer(src: &str) -> Linearizer {
    let mut m = load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)));
    let opts = DeriveOptions {
        simplify_printed: false,
        ..DeriveOptions::default()
    };
    let d = derive(&mut m, &opts).unwrap();
    Linearizer::new(&mut m, &d).unwrap()
}

/// The example's chain with `n` masses (a family: one line changes its size).
fn chain(n: usize) -> String {
    let text = include_str!("../../../examples/chain_modes.toml");
    text.replacen("n = 30", &format!("n = {n}"), 1)
}

/// ω_j = 2 sqrt(k/m) sin(jπ/(2(n+1))) with k = 100, m = 1.
fn exact(j: usize, n: usize) -> f64 {
    20.0 * libm::sin(j as f64 * std::f64::consts::PI / (2.0 * (n as f64 + 1.0)))
}

#[test]
fn a_thousand_mass_chain_has_its_ten_lowest_closed_form_frequencies() {
    let n = 1000;
    let lin = linearizer(&chain(n));
    let eq = solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    for (i, q) in eq.q.iter().enumerate() {
        assert!(
            (q - (i + 1) as f64 * 0.1).abs() < 1e-11,
            "x[{}] = {q}",
            i + 1
        );
    }
    assert!(eq.neutral.is_empty());
    // Sparse: the linearization holds 3n − 2 stiffness entries, not n².
    assert_eq!(eq.linearization.stiffness.nnz(), 3 * n - 2);
    let result = lowest_modes(&eq.linearization, 10).unwrap();
    assert_eq!(result.modes.len(), 10);
    for (j, mode) in result.modes.iter().enumerate() {
        let w = exact(j + 1, n);
        assert!(
            (mode.omega - w).abs() <= 1e-12 * w,
            "mode {}: {} vs {w} (relative {:e})",
            j + 1,
            mode.omega,
            (mode.omega - w).abs() / w
        );
        // The shape is sin(j i π/(n+1)), compared as unit vectors.
        let shape: Vec<f64> = (1..=n)
            .map(|i| libm::sin((j + 1) as f64 * i as f64 * std::f64::consts::PI / (n as f64 + 1.0)))
            .collect();
        let unit = |v: &[f64]| {
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.iter().map(|x| x / norm).collect::<Vec<f64>>()
        };
        let (a, b) = (unit(&mode.shape), unit(&shape));
        let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        assert!((dot.abs() - 1.0).abs() < 1e-10, "mode {}: {dot}", j + 1);
        // Modal mass of the shape scaled to a largest component of 1: with m = 1,
        // Σ_i sin²(j i π/(n+1)) = (n+1)/2, over the largest sin².
        let top = shape.iter().fold(0.0f64, |t, s| t.max(s * s));
        let mass = (n as f64 + 1.0) / 2.0 / top;
        assert!(
            (mode.modal_mass - mass).abs() < 1e-9 * mass,
            "{} vs {mass}",
            mode.modal_mass
        );
    }
}

#[test]
fn the_sparse_path_agrees_with_the_dense_one_on_the_hanging_net() {
    let text = include_str!("../../../examples/hanging_net.toml");
    let lin = linearizer(text);
    let sparse = solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    let dense = pdyn_mech::equilibrium::solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    for (a, b) in sparse.q.iter().zip(&dense.q) {
        assert!((a - b).abs() < 1e-10, "{a} vs {b}");
    }
    let s = lowest_modes(&sparse.linearization, 6).unwrap();
    let d = pdyn_mech::modes::modes(&dense.linearization).unwrap();
    for (a, b) in s.modes.iter().zip(&d.modes) {
        assert!(
            (a.omega - b.omega).abs() < 1e-9 * b.omega,
            "{} vs {}",
            a.omega,
            b.omega
        );
    }
}

#[test]
fn a_chain_with_one_wall_removed_under_a_push_is_a_mechanism() {
    // Without the right-hand spring and with a force along the chain there is no equilibrium;
    // without the force and without both walls' springs the chain floats (a neutral direction).
    let text = chain(200)
        .replace("for = \"i in 0..n\"", "for = \"i in 1..n-1\"")
        .replace("[simulate]", "[[forces]]\nkind = \"applied\"\nname = \"push\"\non = \"P[1]\"\nforce = \"[1, 0, 0]\"\n\n[simulate]");
    let lin = linearizer(&text);
    match solve(&lin, None, &EquilibriumOptions::default()) {
        Err(EquilibriumError::Mechanism { directions, .. }) => {
            assert_eq!(directions.len(), 1);
            // The rigid translation: every coordinate moves equally.
            assert_eq!(directions[0].moved, 200);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_damped_chain_has_the_damping_ratios_of_mass_proportional_damping() {
    // Linear drag c on each mass: C = c I = (c/m) M, so each mode keeps its shape and has
    // ζ_j = c / (2 m ω_j), ωₙ = ω_j.
    let n = 20;
    let c = 0.3;
    let text = chain(n).replace(
        "[simulate]",
        &format!(
            "[[forces]]\nkind = \"linear_drag\"\nname = \"drag\"\nfor = \"i in 1..n\"\non = \"P[i]\"\nc = \"{c}\"\n\n[simulate]"
        ),
    );
    let lin = linearizer(&text);
    let eq = pdyn_mech::equilibrium::solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    let modes = damped_modes(&eq.linearization).unwrap();
    assert_eq!(modes.len(), n);
    for (j, d) in modes.iter().enumerate() {
        let w = 2.0
            * 10.0
            * libm::sin((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n as f64 + 1.0)));
        let zeta = c / (2.0 * w);
        assert!(d.oscillatory);
        assert!((d.omega_n - w).abs() < 1e-11 * w, "{} vs {w}", d.omega_n);
        assert!(
            (d.damping_ratio - zeta).abs() < 1e-11,
            "{} vs {zeta}",
            d.damping_ratio
        );
    }
}

/// The uniform chain is symmetric: its even modes are antisymmetric (`φ_i = −φ_{n+1−i}`), so
/// their largest components tie in magnitude and round-off alone chose the sign of the shape
/// (the sparse and dense paths, or two builds, printed opposite shapes). The shape's sign is
/// now set by the first of the tied components: +1 on both paths, which then agree component
/// by component; the closed form `sin(j i π/(n+1))` fixes which component that is.
#[test]
fn tied_largest_components_give_the_shape_the_sign_of_the_first() {
    let n = 30;
    let lin = linearizer(&chain(n));
    let eq = solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    let sparse = lowest_modes(&eq.linearization, 10).unwrap();
    let dense_eq =
        pdyn_mech::equilibrium::solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    let dense = pdyn_mech::modes::modes(&dense_eq.linearization).unwrap();
    for (j, (s, d)) in sparse.modes.iter().zip(&dense.modes).enumerate() {
        let shape: Vec<f64> = (1..=n)
            .map(|i| libm::sin((j + 1) as f64 * i as f64 * std::f64::consts::PI / (n as f64 + 1.0)))
            .collect();
        let top = shape.iter().fold(0.0f64, |t, x| t.max(x.abs()));
        let first = shape
            .iter()
            .position(|x| x.abs() >= top * (1.0 - 1e-9))
            .unwrap();
        for mode in [s, d] {
            let big = mode.shape.iter().fold(0.0f64, |t, x| t.max(x.abs()));
            assert!((big - 1.0).abs() < 1e-12, "mode {}: largest {big}", j + 1);
            assert!(
                (mode.shape[first] - 1.0).abs() < 1e-9,
                "mode {}: component {} is {}",
                j + 1,
                first + 1,
                mode.shape[first]
            );
            // The closed form, scaled the same way.
            let scale = shape[first];
            for (a, b) in mode.shape.iter().zip(&shape) {
                assert!(
                    (a - b / scale).abs() < 1e-9,
                    "mode {}: {a} vs {}",
                    j + 1,
                    b / scale
                );
            }
        }
        for (a, b) in s.shape.iter().zip(&d.shape) {
            assert!(
                (a - b).abs() < 1e-9,
                "mode {}: sparse {a}, dense {b}",
                j + 1
            );
        }
    }
}

/// `unit_largest` on its own: a tie goes to the lowest index, a clear maximum divides by
/// itself (bits as before), a zero vector is left alone.
#[test]
fn unit_largest_breaks_ties_by_index() {
    use pdyn_mech::modes::unit_largest;
    let mut v = vec![0.5, -2.0, 2.0 * (1.0 + 1e-12), 1.0];
    unit_largest(&mut v);
    assert!(
        (v[1] - 1.0).abs() < 1e-11 && (v[2] + 1.0).abs() < 1e-11,
        "{v:?}"
    );
    let mut w = vec![0.3, -0.7, 0.2];
    unit_largest(&mut w);
    assert_eq!(w, vec![0.3 / -0.7, 1.0, 0.2 / -0.7]);
    let mut z = vec![0.0; 3];
    unit_largest(&mut z);
    assert_eq!(z, vec![0.0; 3]);
}
