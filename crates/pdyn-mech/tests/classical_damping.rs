//! Damped modes without the companion form when the damping is classical (issue 33), against
//! closed forms derived by hand, and the companion form kept where the damping is not
//! classical (checked root by root against `det(s² M + s C + K) = 0`).

use nalgebra::{Complex, DMatrix};
use pdyn_mech::damped::{DampedMode, DampedPath};
use pdyn_mech::load;
use pdyn_mech::statics::{modes_about, About, ModesReport, ModesRequest, Solver};

/// The example's chain (walls at both ends, k = 100, m = 1) with `n` masses and `extra`
/// before `[simulate]`.
fn chain(n: usize, extra: &str) -> String {
    let text = include_str!("../../../examples/chain_modes.toml");
    text.replacen("n = 30", &format!("n = {n}"), 1)
        .replace("[simulate]", &format!("{extra}\n[simulate]"))
}

fn drag(c: f64) -> String {
    format!(
        "[[forces]]\nkind = \"linear_drag\"\nname = \"drag\"\nfor = \"i in 1..n\"\non = \"P[i]\"\nc = \"{c}\"\n"
    )
}

fn report(src: &str, solver: Solver, count: Option<usize>) -> ModesReport {
    let mut m = load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)));
    let request = ModesRequest {
        about: About::Equilibrium,
        solver,
        count,
    };
    modes_about(&mut m, &request).unwrap()
}

/// ω_j = 2 √(k/m) sin(jπ/(2(n+1))), k = 100, m = 1.
fn omega(j: usize, n: usize) -> f64 {
    20.0 * libm::sin(j as f64 * std::f64::consts::PI / (2.0 * (n as f64 + 1.0)))
}

/// The roots `s` (Im s ≥ 0) of `s² + c s + ω² = 0` for each `(c, ω²)`, as `(Re, Im)`, sorted
/// as the report sorts them: by `|s|`, then `Re s`.
fn expected(pairs: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for &(c, w2) in pairs {
        let d = c * c - 4.0 * w2;
        if d < 0.0 {
            out.push((-c / 2.0, (-d).sqrt() / 2.0));
        } else {
            out.push(((-c - d.sqrt()) / 2.0, 0.0));
            out.push(((-c + d.sqrt()) / 2.0, 0.0));
        }
    }
    out.sort_by(|a, b| {
        libm::hypot(a.0, a.1)
            .total_cmp(&libm::hypot(b.0, b.1))
            .then(a.0.total_cmp(&b.0))
    });
    out
}

fn assert_roots(found: &[DampedMode], want: &[(f64, f64)], tol: f64) {
    assert_eq!(found.len(), want.len(), "{found:?}");
    for (k, (d, &(re, im))) in found.iter().zip(want).enumerate() {
        let size = libm::hypot(re, im).max(1.0);
        assert!(
            (d.re - re).abs() <= tol * size && (d.im - im).abs() <= tol * size,
            "root {k}: {} + {} i, expected {re} + {im} i",
            d.re,
            d.im
        );
        assert_eq!(d.oscillatory, im > 0.0, "root {k}");
    }
}

#[test]
fn a_chain_with_drag_has_the_closed_form_damped_roots_without_the_companion() {
    // C = b I = (b/m) M: λ = −b/(2m) ± i √(ω_j² − b²/(4m²)); b = 4 makes the lowest modes
    // (ω_1 ≈ 1.5, ω_2 ≈ 3.0 < b/(2m) = 2 for j = 1) overdamped: two real roots each.
    let n = 20;
    for b in [0.3, 4.0] {
        let r = report(&chain(n, &drag(b)), Solver::Dense, None);
        assert_eq!(r.damped_path, Some(DampedPath::Classical), "b = {b}");
        assert!(r.commutation_defect <= 1e-12, "{}", r.commutation_defect);
        let pairs: Vec<(f64, f64)> = (1..=n).map(|j| (b, omega(j, n).powi(2))).collect();
        let want = expected(&pairs);
        let found = r.damped.as_ref().unwrap();
        assert_roots(found, &want[..found.len()], 1e-11);
        assert_eq!(found.len(), r.modes.modes.len().min(want.len()));
    }
}

#[test]
fn a_large_chain_with_drag_takes_the_sparse_modes_and_the_closed_form() {
    // 400 coordinates: the sparse solver, 8 modes.
    let (n, b) = (400, 0.3);
    let r = report(&chain(n, &drag(b)), Solver::Sparse, Some(8));
    assert!(r.sparse);
    assert_eq!(r.damped_path, Some(DampedPath::Classical));
    // ω_1 ≈ 0.078 < b/2: the lowest modes are overdamped (two real roots each); the 8 lowest
    // roots are the 8 modes' lowest.
    let pairs: Vec<(f64, f64)> = (1..=8).map(|j| (b, omega(j, n).powi(2))).collect();
    let found = r.damped.as_ref().unwrap();
    assert_eq!(found.len(), 8);
    assert_roots(found, &expected(&pairs)[..8], 1e-10);
}

#[test]
fn rayleigh_damping_is_classical_with_c_j_alpha_plus_beta_omega_squared() {
    // Drag α m on each mass and a damper β k beside each spring: C = α M + β K, so
    // c_j = α + β ω_j².
    let (n, alpha, beta) = (12, 0.5, 0.002);
    let dampers = format!(
        "{}[[forces]]\nkind = \"damper\"\nname = \"dashpot\"\nfor = \"i in 0..n\"\nbetween = [\"P[i+1]\", \"P[i]\"]\nc = \"{}\"\n",
        drag(alpha),
        beta * 100.0
    );
    let r = report(&chain(n, &dampers), Solver::Dense, None);
    assert_eq!(r.damped_path, Some(DampedPath::Classical));
    let pairs: Vec<(f64, f64)> = (1..=n)
        .map(|j| {
            let w2 = omega(j, n).powi(2);
            (alpha + beta * w2, w2)
        })
        .collect();
    assert_roots(r.damped.as_ref().unwrap(), &expected(&pairs), 1e-11);
}

/// `|det(s² M + s C + K)|` over Hadamard's bound (the product of the rows' norms): zero to
/// round-off at a root.
fn relative_determinant(r: &ModesReport, d: &DampedMode) -> f64 {
    let dense = r.matrices.to_dense();
    let s = Complex::new(d.re, d.im);
    let n = dense.mass.nrows();
    let a = DMatrix::from_fn(n, n, |i, j| {
        s * s * dense.mass[(i, j)] + s * dense.damping[(i, j)] + dense.stiffness[(i, j)]
    });
    let bound: f64 = (0..n)
        .map(|i| (0..n).map(|j| a[(i, j)].norm_sqr()).sum::<f64>().sqrt())
        .product();
    a.determinant().norm() / bound
}

#[test]
fn a_damper_on_one_mass_is_not_classical_and_takes_the_companion_form() {
    // Drag on P[1] only: C M⁻¹ K ≠ K M⁻¹ C. Every root must solve det(s² M + s C + K) = 0,
    // and there are n of them with Im s ≥ 0 (complex pairs here).
    let n = 6;
    let one = "[[forces]]\nkind = \"linear_drag\"\non = \"P[1]\"\nc = \"3.0\"\n";
    let r = report(&chain(n, one), Solver::Dense, None);
    assert_eq!(r.damped_path, Some(DampedPath::Companion));
    assert!(r.commutation_defect > 1e-3, "{}", r.commutation_defect);
    let found = r.damped.as_ref().unwrap();
    assert_eq!(found.len(), n);
    for d in found {
        let rel = relative_determinant(&r, d);
        assert!(rel < 1e-10, "{d:?}: relative det {rel:e}");
        assert!(d.re < 0.0 && d.oscillatory, "{d:?}");
    }
    // The undamped ω's are not the damped roots' (the shortcut would give |s| = ω_j).
    let shortcut_like = found
        .iter()
        .zip(1..=n)
        .all(|(d, j)| (d.omega_n - omega(j, n)).abs() < 1e-6 * omega(j, n));
    assert!(!shortcut_like);
}

#[test]
fn a_repeated_frequency_with_damping_along_one_axis_is_solved_in_its_cluster() {
    // A particle on an isotropic spring (K = k I) with a damper along the diagonal
    // e = (1, 1)/√2 only: C = c e eᵀ commutes with K (classical), but the eigensolver's basis
    // of the double ω² = k/m is (x, y), in which C is not diagonal.
    // Exact: s² + (c/m) s + k/m = 0 (along e) and s² + k/m = 0 (across it).
    let (m, k, c) = (2.0, 50.0, 3.0);
    let src = format!(
        r#"name = "isotropic"
[parameters]
m = {m}
k = {k}
c = {c}
[coordinates]
x = {{ initial = 0.01, rate = 0 }}
y = {{ initial = 0.02, rate = 0 }}
[particles.P]
mass = "m"
position = "[x, y, 0]"
[[forces]]
kind = "applied"
on = "P"
force = "[-k*x - c*(x' + y')/2, -k*y - c*(x' + y')/2, 0]"
[simulate]
t_end = 1
"#
    );
    let r = report(&src, Solver::Dense, None);
    assert_eq!(r.damped_path, Some(DampedPath::Classical));
    let want = expected(&[(c / m, k / m), (0.0, k / m)]);
    assert_roots(r.damped.as_ref().unwrap(), &want, 1e-12);
}

#[test]
fn a_free_chain_with_drag_keeps_its_rigid_mode_as_a_still_root_and_a_decay() {
    // No walls: ω_j = 2 √(k/m) sin(jπ/(2n)), j = 0..n-1, ω_0 = 0 the rigid translation. With
    // drag b on each mass its roots are s = 0 (it stays where it is pushed) and s = −b/m.
    let (n, b) = (6, 0.5);
    let src = format!(
        r#"name = "free chain"
[indices]
n = {n}
i = "1..n"
[parameters]
m = 1.0
k = 100.0
L = 0.1
[coordinates]
"x[i]" = {{ initial = "i*L", rate = 0 }}
[particles."P[i]"]
mass = "m"
position = "[x[i], 0, 0]"
[[forces]]
kind = "spring"
name = "spring"
for = "i in 1..n-1"
between = ["P[i+1]", "P[i]"]
k = "k"
l0 = "L"
{}
[simulate]
t_end = 1
"#,
        drag(b)
    );
    let mut m = load(&src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(&src)));
    let request = ModesRequest {
        about: About::Initial,
        solver: Solver::Dense,
        count: None,
    };
    let r = modes_about(&mut m, &request).unwrap();
    assert_eq!(r.damped_path, Some(DampedPath::Classical));
    let pairs: Vec<(f64, f64)> = (0..n)
        .map(|j| {
            let w = 20.0 * libm::sin(j as f64 * std::f64::consts::PI / (2.0 * n as f64));
            (b, w * w)
        })
        .collect();
    let want = expected(&pairs);
    let found = r.damped.as_ref().unwrap();
    assert_eq!(found.len(), n);
    assert_roots(found, &want[..n], 1e-10);
    assert!(found[0].re.abs() < 1e-10 && !found[0].oscillatory);
}
