//! The universal-variable Kepler solver (scalar and four-lane batch) against an independent
//! solution: Kepler's equation in the classical anomalies (`E − e sin E = M` for ellipses,
//! `e sinh H − H = M` for hyperbolae) solved by bisection, the state written from the
//! perifocal formulas. Eccentricities from 0 to 0.9999 and 1.0001 to 10, starts at and away
//! from pericentre, steps from 1/1000 of an orbit to several orbits, both signs.

use pdyn_gravity::kepler::{kepler_drift, kepler_drift_batch};

/// Bisection on an increasing function: the root in `[lo, hi]` to the last bit.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(f(lo) <= 0.0 && f(hi) >= 0.0, "bracket");
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return mid;
        }
        if f(mid) >= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
}

/// A fixed rotation (so that no coordinate is special), applied to perifocal vectors.
fn rotate(p: [f64; 2]) -> [f64; 3] {
    let (ci, si) = (libm::cos(0.8f64), libm::sin(0.8f64)); // inclination
    let (co, so) = (libm::cos(2.1f64), libm::sin(2.1f64)); // node
    let (x, y) = (p[0], p[1]);
    let (x1, y1, z1) = (x, y * ci, y * si);
    [co * x1 - so * y1, so * x1 + co * y1, z1]
}

/// State at mean anomaly `m` of the conic with `a > 0` (semi-major axis, or its absolute
/// value for `e > 1`) and eccentricity `e`, about `mu`.
fn state(mu: f64, a: f64, e: f64, m: f64) -> ([f64; 3], [f64; 3]) {
    if e < 1.0 {
        let ea = bisect(|ea| ea - e * libm::sin(ea) - m, m - 1.0, m + 1.0);
        let r = a * (1.0 - e * libm::cos(ea));
        let b = (1.0 - e * e).sqrt();
        let s = (mu * a).sqrt() / r;
        (
            rotate([a * (libm::cos(ea) - e), a * b * libm::sin(ea)]),
            rotate([-s * libm::sin(ea), s * b * libm::cos(ea)]),
        )
    } else {
        let mut span = 1.0f64;
        while (e * libm::sinh(span) - span) < m.abs() {
            span *= 2.0;
        }
        let h = bisect(|h| e * libm::sinh(h) - h - m, -span, span);
        let r = a * (e * libm::cosh(h) - 1.0);
        let b = (e * e - 1.0).sqrt();
        let s = (mu * a).sqrt() / r;
        (
            rotate([a * (e - libm::cosh(h)), a * b * libm::sinh(h)]),
            rotate([-s * libm::sinh(h), s * b * libm::cosh(h)]),
        )
    }
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

/// Every case: (e, start mean anomaly, step in units of 1/n).
fn cases() -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    let es = [
        0.0, 1e-3, 0.05, 0.5, 0.9, 0.99, 0.999, 0.9999, 1.0001, 1.01, 1.5, 3.0, 10.0,
    ];
    for &e in &es {
        for &m0 in &[0.0, -0.02, 0.3, 2.5] {
            for &dm in &[6e-3, 0.31, -0.31, 1.7, 9.0, -40.0] {
                // Hyperbolic starts far out on the incoming branch too.
                let m0 = if e > 1.0 && m0 == 2.5 { -25.0 } else { m0 };
                out.push((e, m0, dm));
            }
        }
    }
    out
}

/// The reference end state and the tolerance for a case. An exact solver still inherits the
/// round-off of its input amplified by the orbit's sensitivity: `β = 2μ/r₀ − v₀²` (the
/// inverse semi-major axis) loses the digits of `v₀²/|β| = (1 + e)/|1 − e|` at pericentre,
/// which shifts the mean motion, and so the position, in proportion to the time stepped.
fn reference(mu: f64, a: f64, e: f64, m0: f64, dm: f64) -> ([f64; 3], [f64; 3], f64, f64) {
    let (r0, v0) = state(mu, a, e, m0);
    let (r1, v1) = state(mu, a, e, m0 + dm);
    let beta = 2.0 * mu / norm(r0) - norm(v0).powi(2);
    let kappa = norm(v0).powi(2) / beta.abs();
    let n = (mu / (a * a * a)).sqrt();
    // Position and velocity scales of the arc: the larger of start and end.
    let (sr, sv) = (norm(r0).max(norm(r1)), norm(v0).max(norm(v1)));
    let amplification = 1.0 + kappa * (1.0 + dm.abs());
    let tol_r = 1e-14 * amplification * (sr + sv / n);
    let tol_v = 1e-14 * amplification * (sv + sr * n);
    (r1, v1, tol_r, tol_v)
}

#[test]
fn scalar_solver_matches_bisection_on_keplers_equation() {
    let (mu, a) = (1.3f64, 2.0f64);
    let n = (mu / (a * a * a)).sqrt();
    for (e, m0, dm) in cases() {
        let (mut r, mut v) = state(mu, a, e, m0);
        let (r1, v1, tol_r, tol_v) = reference(mu, a, e, m0, dm);
        kepler_drift(mu, &mut r, &mut v, dm / n).unwrap();
        let (er, ev) = (dist(r, r1), dist(v, v1));
        assert!(
            er <= tol_r,
            "e {e} M0 {m0} dM {dm}: |Δr| {er:e} > {tol_r:e}"
        );
        assert!(
            ev <= tol_v,
            "e {e} M0 {m0} dM {dm}: |Δv| {ev:e} > {tol_v:e}"
        );
    }
}

/// The batch solver on lanes of mixed orbits (so that a lane's neighbours differ) matches the
/// bisection solution as closely as the scalar solver.
#[test]
fn batch_solver_matches_bisection_on_keplers_equation() {
    let (mu, a) = (0.9f64, 0.7f64);
    let n = (mu / (a * a * a)).sqrt();
    let all = cases();
    // Groups of five bodies with the same step (one full batch of four and a single one).
    let mut by_dm: Vec<(f64, Vec<(f64, f64)>)> = Vec::new();
    for (e, m0, dm) in all {
        match by_dm.iter_mut().find(|(d, _)| *d == dm) {
            Some((_, v)) => v.push((e, m0)),
            None => by_dm.push((dm, vec![(e, m0)])),
        }
    }
    for (dm, bodies) in by_dm {
        for group in bodies.chunks(5) {
            let mut rs = Vec::new();
            let mut vs = Vec::new();
            for &(e, m0) in group {
                let (r, v) = state(mu, a, e, m0);
                rs.push(r);
                vs.push(v);
            }
            let mus = vec![mu; group.len()];
            if let Err(i) = kepler_drift_batch(&mus, &mut rs, &mut vs, dm / n) {
                panic!("body {:?} dm {dm}", group[i]);
            }
            for (k, &(e, m0)) in group.iter().enumerate() {
                let (r1, v1, tol_r, tol_v) = reference(mu, a, e, m0, dm);
                let (er, ev) = (dist(rs[k], r1), dist(vs[k], v1));
                assert!(
                    er <= tol_r,
                    "e {e} M0 {m0} dM {dm}: |Δr| {er:e} > {tol_r:e}"
                );
                assert!(
                    ev <= tol_v,
                    "e {e} M0 {m0} dM {dm}: |Δv| {ev:e} > {tol_v:e}"
                );
            }
        }
    }
}

/// Degenerate input is an error naming the body, never a panic or a silent NaN.
#[test]
fn batch_reports_degenerate_bodies() {
    let mu = [1.0, 1.0, -1.0];
    let mut r = [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let mut v = [[0.0, 1.0, 0.0]; 3];
    assert_eq!(kepler_drift_batch(&mu, &mut r, &mut v, 0.1), Err(2));
    let mut r = [[1.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0]];
    let mut v = [[0.0, 1.0, 0.0]; 2];
    assert_eq!(kepler_drift_batch(&mu[..2], &mut r, &mut v, 0.1), Err(1));
    let mut r = [[1.0, 0.0, 0.0]];
    let mut v = [[0.0, 1.0, 0.0]];
    assert_eq!(
        kepler_drift_batch(&mu[..1], &mut r, &mut v, f64::INFINITY),
        Err(0)
    );
}
