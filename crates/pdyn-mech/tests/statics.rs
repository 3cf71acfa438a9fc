//! Equilibrium and modes (issue 33, items 4 and 5) against closed forms derived by hand.

use pdyn_mech::equilibrium::{solve, EquilibriumError, EquilibriumOptions};
use pdyn_mech::linearization::Linearizer;
use pdyn_mech::modes::modes;
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

fn chain(n: usize) -> String {
    let text = include_str!("../../../examples/chain_modes.toml");
    text.replacen("n = 30", &format!("n = {n}"), 1)
}

/// n equal masses between walls on n + 1 equal springs: K = k tridiag(-1, 2, -1), M = m I,
/// whose eigenvalues are (k/m) 4 sin²(jπ/(2(n+1))) (the discrete sine transform).
#[test]
fn the_uniform_chain_has_its_closed_form_frequencies() {
    let n = 30;
    let lin = linearizer(&chain(n));
    let eq = solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    // Released in its first mode's shape, the chain's equilibrium is x[i] = i L.
    for (i, q) in eq.q.iter().enumerate() {
        assert!(
            (q - (i + 1) as f64 * 0.1).abs() < 1e-12,
            "x[{}] = {q}",
            i + 1
        );
    }
    let result = modes(&eq.linearization).unwrap();
    assert_eq!(result.modes.len(), n);
    let (k, m) = (100.0f64, 1.0f64);
    for (j, mode) in result.modes.iter().enumerate() {
        let j = (j + 1) as f64;
        let exact =
            2.0 * (k / m).sqrt() * libm::sin(j * std::f64::consts::PI / (2.0 * (n as f64 + 1.0)));
        assert!(
            (mode.omega - exact).abs() <= 1e-12 * exact,
            "mode {j}: {} vs {exact}",
            mode.omega
        );
        // The mode shape is sin(j i π/(n+1)) along the chain.
        let shape: Vec<f64> = (1..=n)
            .map(|i| libm::sin(j * i as f64 * std::f64::consts::PI / (n as f64 + 1.0)))
            .collect();
        // Compared as unit vectors (two components may tie for the largest, and then the
        // one scaled to +1 is a matter of round-off).
        let unit = |v: &[f64]| {
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.iter().map(|x| x / norm).collect::<Vec<f64>>()
        };
        let (a, b) = (unit(&mode.shape), unit(&shape));
        let sign = a.iter().zip(&b).map(|(x, y)| x * y).sum::<f64>().signum();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - sign * y).abs() < 1e-9, "mode {j} shape");
        }
    }
    assert!(result.stiffness_asymmetry < 1e-12);
}

/// The chapter's 2-storey building: M = m I, K = 2k [[2, -1], [-1, 1]], so
/// ω² = (k/m)(3 ∓ √5).
#[test]
fn the_building_has_its_two_frequencies() {
    let lin = linearizer(include_str!("../../../examples/building.toml"));
    let eq = solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    let result = modes(&eq.linearization).unwrap();
    let (k, m) = (100.0f64, 1.0f64);
    let w1 = ((k / m) * (3.0 - 5f64.sqrt())).sqrt();
    let w2 = ((k / m) * (3.0 + 5f64.sqrt())).sqrt();
    assert!((result.modes[0].omega - w1).abs() < 1e-12 * w1);
    assert!((result.modes[1].omega - w2).abs() < 1e-12 * w2);
    // Its initial values (L - mg/k, 2L - 3mg/(2k)) are the static equilibrium already.
    assert!(eq.residual < 1e-9, "{}", eq.residual);
}

/// n masses hanging in a vertical line from a pin at the origin, springs k of natural length
/// L: spring j (counted from the top) carries the n - j + 1 masses below it, so it is
/// stretched by (n - j + 1) m g / k, and mass i sits at depth Σ_{j≤i} (L + (n-j+1) m g/k).
#[test]
fn a_hanging_chain_sags_as_the_springs_carry_the_weight_below() {
    let n = 6;
    let src = format!(
        r#"
gravity = "[0, 0, -g]"
[indices]
n = {n}
i = "0..n"
[parameters]
m = 0.5
k = 40.0
L = 0.2
g = 9.81
[coordinates]
"z[i]" = {{ initial = "-i*L", rate = 0, where = "i > 0" }}
[points]
"P[i]" = {{ position = "[0, 0, 0]", where = "i == 0" }}
[particles."P[i]"]
where = "i > 0"
mass = "m"
position = "[0, 0, z[i]]"
[[forces]]
kind = "spring"
for = "i in 1..n"
between = ["P[i]", "P[i-1]"]
k = "k"
l0 = "L"
"#
    );
    let lin = linearizer(&src);
    let eq = solve(&lin, None, &EquilibriumOptions::default()).unwrap();
    let (m, k, l, g) = (0.5, 40.0, 0.2, 9.81);
    let mut depth = 0.0;
    for i in 1..=n {
        depth += l + (n - i + 1) as f64 * m * g / k;
        assert!(
            (eq.q[i - 1] + depth).abs() < 1e-12,
            "z[{i}] = {} vs {}",
            eq.q[i - 1],
            -depth
        );
    }
    assert!(eq.residual <= 1e-12 * eq.scale);
    assert!(eq.neutral.is_empty());
}

/// The hanging net without its pins falls: no equilibrium, and the free motion named is the
/// rigid translation along z (every z coordinate alike).
#[test]
fn a_free_net_under_gravity_is_a_mechanism_with_its_directions_named() {
    let text = include_str!("../../../examples/hanging_net.toml").replacen("n = 5", "n = 3", 1);
    let src = text
        .replace(", where = \"not (j == 0 and (i == 0 or i == n-1))\"", "")
        .replace("where = \"not (j == 0 and (i == 0 or i == n-1))\"", "")
        .replace("[points]\n\"P[i,j]\"", "[points]\n#\"P[i,j]\"");
    let lin = linearizer(&src);
    let err = solve(&lin, None, &EquilibriumOptions::default()).unwrap_err();
    let EquilibriumError::Mechanism { directions, .. } = &err else {
        panic!("{err}")
    };
    // The flat net's stiffness is singular in many directions; the rigid translation along
    // z is one of them: some free direction moves every z coordinate alike.
    assert!(!directions.is_empty());
    let text = err.to_string();
    assert!(
        text.contains("no equilibrium") && text.contains("z["),
        "{text}"
    );
}
