//! SI-unit models of planets and atoms run as their reduced-unit twins do (issue 12): the
//! same system written in metres, kilograms and seconds and in units where the coupling
//! constant, the length and the mass are 1 derives, prepares and integrates to the same
//! final positions once scaled. Each test compares the two runs with each other (not with a
//! stored number), so a preparation that loses precision on SI magnitudes (a common
//! denominator with `m^7` or `(r^2)^28` overflowing, say) fails here.

use pdyn::sim::{self, RunSettings};

/// Loads `src`, checks that `derive` succeeds, prepares and runs it: the final value of each
/// of `columns`.
fn final_values(src: &str, columns: &[&str]) -> Vec<f64> {
    let mut m = pdyn_mech::load(src, "<test>").unwrap_or_else(|e| panic!("{}", e.render(src)));
    // What `pdyn derive` does first (a copy: preparation derives again for running).
    let mut for_derive = m.clone();
    pdyn_mech::derive(&mut for_derive, &pdyn_mech::DeriveOptions::default())
        .unwrap_or_else(|e| panic!("derive: {e}\n{src}"));
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let prep = sim::prepare(&mut m).unwrap_or_else(|e| panic!("prepare: {e}\n{src}"));
    let res = sim::run(&prep, &set).unwrap_or_else(|e| panic!("run: {e}\n{src}"));
    assert!(res.failure.is_none(), "{:?}\n{src}", res.failure);
    columns
        .iter()
        .map(|c| {
            let v = RunSettings::final_value(&res, c).unwrap_or_else(|| panic!("no column {c}"));
            assert!(v.is_finite(), "{c} = {v}\n{src}");
            v
        })
        .collect()
}

/// Sun, Jupiter and Saturn with the gravitational constant `g`, masses `ms` (kg or solar
/// masses), positions scaled by `length` and speeds by `speed` from the SI values, run for
/// `t_end` with tolerances `rtol` and `atol`.
fn sun_jupiter_saturn(
    g: f64,
    ms: [f64; 3],
    length: f64,
    speed: f64,
    t_end: f64,
    atol: f64,
) -> String {
    let [ms, mj, mt] = ms;
    let (xj, xt) = (7.785e11 / length, 1.4335e12 / length);
    let (vj, vt) = (13070.0 / speed, 9680.0 / speed);
    format!(
        r#"
name = "Sun-Jupiter-Saturn"
[parameters]
G = {g:e}
mS = {ms:e}
mJ = {mj:e}
mT = {mt:e}
[coordinates]
xS = {{ initial = 0.0, rate = 0.0 }}
yS = {{ initial = 0.0, rate = 0.0 }}
xJ = {{ initial = {xj:e}, rate = 0.0 }}
yJ = {{ initial = 0.0, rate = {vj:e} }}
xT = {{ initial = {xt:e}, rate = 0.0 }}
yT = {{ initial = 0.0, rate = {vt:e} }}
[particles.sun]
mass = "mS"
position = "[xS, yS, 0]"
[particles.jup]
mass = "mJ"
position = "[xJ, yJ, 0]"
[particles.sat]
mass = "mT"
position = "[xT, yT, 0]"
[[forces]]
kind = "inverse_square"
between = ["sun", "jup"]
strength = "G*mS*mJ"
[[forces]]
kind = "inverse_square"
between = ["sun", "sat"]
strength = "G*mS*mT"
[[forces]]
kind = "inverse_square"
between = ["jup", "sat"]
strength = "G*mJ*mT"
[simulate]
t_end = {t_end:e}
rtol = 1e-12
atol = {atol:e}
"#
    )
}

/// The largest difference between `a` and `b`, relative to the largest magnitude in `b`.
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / scale)
        .fold(0.0, f64::max)
}

#[test]
fn sun_jupiter_saturn_in_si_runs_as_in_units_where_g_is_1() {
    const G: f64 = 6.674e-11;
    const M_SUN: f64 = 1.989e30;
    // Units: length L = 1e11 m, mass the Sun's, time T with G M T² / L³ = 1 (about 58 days).
    let length: f64 = 1e11;
    let time = (length.powi(3) / (G * M_SUN)).sqrt();
    let speed = length / time;
    // One Jupiter period and a bit (Saturn a third of the way round).
    let t_end = 4.0e8;
    // Absolute tolerances negligible against rtol * position in both systems.
    let si = sun_jupiter_saturn(G, [M_SUN, 1.898e27, 5.683e26], 1.0, 1.0, t_end, 1e-3);
    let reduced = sun_jupiter_saturn(
        1.0,
        [1.0, 1.898e27 / M_SUN, 5.683e26 / M_SUN],
        length,
        speed,
        t_end / time,
        1e-3 / length,
    );
    let cols = ["xS", "yS", "xJ", "yJ", "xT", "yT"];
    let a: Vec<f64> = final_values(&si, &cols)
        .iter()
        .map(|x| x / length)
        .collect();
    let b = final_values(&reduced, &cols);
    // Jupiter has moved: the comparison is not of two initial states.
    assert!((b[2] - 7.785).abs() > 0.5, "{b:?}");
    let d = relative_difference(&a, &b);
    assert!(
        d < 1e-8,
        "SI {a:?} vs G = 1 {b:?}: relative difference {d:e}"
    );
}

/// An argon dimer on a line under a Lennard-Jones pair potential with depth `eps`, range
/// `sigma` and masses `m`, the second atom at `x2` (the first at the origin), for `t_end`.
fn argon_dimer(eps: f64, sigma: f64, m: f64, x2: f64, t_end: f64, atol: f64) -> String {
    format!(
        r#"
name = "argon dimer"
[parameters]
eps = {eps:e}
sigma = {sigma:e}
m = {m:e}
[coordinates]
x1 = {{ initial = 0.0, rate = 0.0 }}
x2 = {{ initial = {x2:e}, rate = 0.0 }}
[particles.a]
mass = "m"
position = "[x1, 0, 0]"
[particles.b]
mass = "m"
position = "[x2, 0, 0]"
[[forces]]
kind = "potential"
between = ["a", "b"]
potential = "4*eps*((sigma/dist)^12 - (sigma/dist)^6)"
[simulate]
t_end = {t_end:e}
rtol = 1e-12
atol = {atol:e}
"#
    )
}

#[test]
fn argon_dimer_in_si_runs_as_in_reduced_lennard_jones_units() {
    const EPS: f64 = 1.654e-21; // J
    const SIGMA: f64 = 3.405e-10; // m
    const M: f64 = 6.63e-26; // kg
                             // Reduced units: sigma, eps, m; time tau = sigma sqrt(m / eps) (about 2.2 ps).
    let tau = SIGMA * (M / EPS).sqrt();
    let (x2, t_end) = (4.0e-10, 1.0e-11);
    let si = argon_dimer(EPS, SIGMA, M, x2, t_end, 1e-22);
    let reduced = argon_dimer(1.0, 1.0, 1.0, x2 / SIGMA, t_end / tau, 1e-22 / SIGMA);
    let cols = ["x1", "x2"];
    let a: Vec<f64> = final_values(&si, &cols).iter().map(|x| x / SIGMA).collect();
    let b = final_values(&reduced, &cols);
    // The atoms have moved (they start apart from the potential's minimum, at rest).
    assert!(b[0].abs() > 1e-3, "{b:?}");
    let d = relative_difference(&a, &b);
    assert!(
        d < 1e-8,
        "SI {a:?} vs reduced {b:?}: relative difference {d:e}"
    );
}
