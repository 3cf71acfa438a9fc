//! Orbital elements relative to a primary, to and from Cartesian state.
//!
//! For a body at relative position `r`, velocity `v` about a primary, with
//! `μ = G (M_primary + m)`: specific angular momentum `h = r × v`, eccentricity vector
//! `e = ((v² − μ/r) r − (r·v) v)/μ`, semi-major axis `a = 1/(2/r − v²/μ)` (negative for
//! hyperbolae), inclination `cos i = h_z/|h|`, longitude of the ascending node
//! `Ω = atan2(h_x, −h_y)`, argument of pericentre `ω` (node → pericentre, in the orbit plane)
//! and true anomaly `f` (pericentre → body). Mean anomaly: `M = E − e sin E` with
//! `tan(E/2) = √((1−e)/(1+e)) tan(f/2)` for ellipses, `M = e sinh F − F` for hyperbolae.
//!
//! Going back: `p = a(1−e²)`, `r = p/(1 + e cos f)`, perifocal position `r (cos f, sin f, 0)`
//! and velocity `√(μ/p) (−sin f, e + cos f, 0)`, rotated by `R_z(Ω) R_x(i) R_z(ω)`.
//!
//! Conventions for degenerate orbits follow REBOUND: for an equatorial orbit `Ω = 0`; for a
//! circular orbit `ω = 0` and `f` is measured from the node (or from the x axis when the
//! orbit is also equatorial). Parabolae (`e = 1`) cannot be given by `a` and are refused.

use std::f64::consts::PI;

use pdyn_particles::Vec3;

use crate::GravityError;

/// Where along the orbit the body is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anomaly {
    /// Mean anomaly `M` (radians).
    Mean(f64),
    /// True anomaly `f` (radians).
    True(f64),
}

/// Keplerian elements as given by a user (angles in radians).
#[allow(non_snake_case)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elements {
    /// Semi-major axis (length units; negative for hyperbolae).
    pub a: f64,
    /// Eccentricity (≥ 0, ≠ 1).
    pub e: f64,
    /// Inclination.
    pub inc: f64,
    /// Longitude of the ascending node Ω.
    pub Omega: f64,
    /// Argument of pericentre ω.
    pub omega: f64,
    /// Position along the orbit.
    pub anomaly: Anomaly,
}

impl Elements {
    /// A circular, equatorial orbit of radius `a` starting at true anomaly 0.
    pub fn circular(a: f64) -> Self {
        Elements {
            a,
            e: 0.0,
            inc: 0.0,
            Omega: 0.0,
            omega: 0.0,
            anomaly: Anomaly::True(0.0),
        }
    }
}

/// Keplerian elements computed from a Cartesian state, with derived quantities.
#[allow(non_snake_case)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// Semi-major axis (negative for hyperbolae, infinite for parabolae).
    pub a: f64,
    /// Eccentricity.
    pub e: f64,
    /// Inclination (radians, 0..π).
    pub inc: f64,
    /// Longitude of the ascending node (radians).
    pub Omega: f64,
    /// Argument of pericentre (radians).
    pub omega: f64,
    /// True anomaly (radians).
    pub f: f64,
    /// Mean anomaly (radians; for hyperbolae the hyperbolic mean anomaly).
    pub M: f64,
    /// Orbital period `2π √(a³/μ)` (infinite unless bound).
    pub period: f64,
    /// Specific angular momentum `|r × v|`.
    pub h: f64,
    /// Distance to the primary.
    pub d: f64,
}

/// Solves Kepler's equation `M = E − e sin E` for the eccentric anomaly (`e < 1`).
pub fn eccentric_anomaly(mean: f64, e: f64) -> f64 {
    let m = mean.rem_euclid(2.0 * PI);
    let mut ea = if e < 0.8 { m } else { PI };
    for _ in 0..100 {
        let f = ea - e * libm::sin(ea) - m;
        let fp = 1.0 - e * libm::cos(ea);
        let fpp = e * libm::sin(ea);
        // Halley's step.
        let d = f / (fp - 0.5 * f * fpp / fp);
        ea -= d;
        if d.abs() <= 4.0 * f64::EPSILON * ea.abs().max(1.0) {
            break;
        }
    }
    ea + (mean - m)
}

/// Solves `M = e sinh F − F` for the hyperbolic anomaly (`e > 1`).
pub fn hyperbolic_anomaly(mean: f64, e: f64) -> f64 {
    let mut fa = libm::asinh(mean / e);
    for _ in 0..200 {
        let f = e * libm::sinh(fa) - fa - mean;
        let fp = e * libm::cosh(fa) - 1.0;
        let d = f / fp;
        fa -= d;
        if d.abs() <= 4.0 * f64::EPSILON * fa.abs().max(1.0) {
            break;
        }
    }
    fa
}

/// True anomaly from mean anomaly.
pub fn mean_to_true(mean: f64, e: f64) -> f64 {
    if e < 1.0 {
        let ea = eccentric_anomaly(mean, e);
        let turns = (ea / (2.0 * PI)).floor() * 2.0 * PI;
        let ea0 = ea - turns;
        turns
            + libm::atan2((1.0 - e * e).sqrt() * libm::sin(ea0), libm::cos(ea0) - e)
                .rem_euclid(2.0 * PI)
    } else {
        let fa = hyperbolic_anomaly(mean, e);
        2.0 * libm::atan(((e + 1.0) / (e - 1.0)).sqrt() * libm::tanh(0.5 * fa))
    }
}

/// Mean anomaly from true anomaly.
pub fn true_to_mean(f: f64, e: f64) -> f64 {
    if e < 1.0 {
        let ea = libm::atan2((1.0 - e * e).sqrt() * libm::sin(f), e + libm::cos(f));
        (ea - e * libm::sin(ea)).rem_euclid(2.0 * PI)
    } else {
        let fa = 2.0 * libm::atanh(((e - 1.0) / (e + 1.0)).sqrt() * libm::tan(0.5 * f));
        e * libm::sinh(fa) - fa
    }
}

/// Relative position and velocity of a body on the orbit `el` about a primary with
/// `mu = G (M + m)`; a typed error when the elements describe no orbit.
pub fn elements_to_cartesian(mu: f64, el: &Elements) -> Result<(Vec3, Vec3), GravityError> {
    let Elements {
        a,
        e,
        inc,
        Omega,
        omega,
        anomaly,
    } = *el;
    let bad = |reason| Err(GravityError::InvalidElements { reason, a, e });
    if ![a, e, inc, Omega, omega].iter().all(|x| x.is_finite()) {
        return bad("non-finite element");
    }
    if e < 0.0 {
        return bad("e < 0");
    }
    if e == 1.0 {
        return bad("e = 1 (a parabola cannot be given by its semi-major axis)");
    }
    if e < 1.0 && a <= 0.0 {
        return bad("a <= 0 for e < 1");
    }
    if e > 1.0 && a >= 0.0 {
        return bad("a >= 0 for e > 1");
    }
    if !(mu > 0.0 && mu.is_finite()) {
        return bad("primary and body have zero total mass");
    }
    let f = match anomaly {
        Anomaly::True(f) => f,
        Anomaly::Mean(m) => mean_to_true(m, e),
    };
    if !f.is_finite() {
        return bad("non-finite anomaly");
    }
    let den = 1.0 + e * libm::cos(f);
    if den <= 0.0 {
        return bad("true anomaly beyond the asymptotes of the hyperbola");
    }
    let p = a * (1.0 - e * e);
    let r = p / den;
    let (sf, cf) = libm::sincos(f);
    let vfac = (mu / p).sqrt();
    let pf_r = [r * cf, r * sf];
    let pf_v = [-vfac * sf, vfac * (e + cf)];
    let (so, co) = libm::sincos(Omega);
    let (si, ci) = libm::sincos(inc);
    let (sw, cw) = libm::sincos(omega);
    // Columns of R_z(Ω) R_x(i) R_z(ω) for the perifocal x and y axes.
    let px = Vec3::new(co * cw - so * ci * sw, so * cw + co * ci * sw, si * sw);
    let py = Vec3::new(-co * sw - so * ci * cw, -so * sw + co * ci * cw, si * cw);
    Ok((pf_r[0] * px + pf_r[1] * py, pf_v[0] * px + pf_v[1] * py))
}

/// Orbital elements of relative state `(r, v)` with `mu = G (M + m)`; `None` when `r = 0`
/// or `mu ≤ 0`.
pub fn cartesian_to_orbit(mu: f64, r: Vec3, v: Vec3) -> Option<Orbit> {
    let d = r.norm();
    if !(d > 0.0 && mu > 0.0) {
        return None;
    }
    const TINY: f64 = 1e-13;
    let v2 = v.norm2();
    let hv = r.cross(v);
    let h = hv.norm();
    let a = 1.0 / (2.0 / d - v2 / mu);
    let ev = (1.0 / mu) * ((v2 - mu / d) * r - r.dot(v) * v);
    let e = ev.norm();
    let inc = if h > 0.0 {
        libm::acos((hv.0[2] / h).clamp(-1.0, 1.0))
    } else {
        0.0
    };
    let nv = Vec3::new(-hv.0[1], hv.0[0], 0.0);
    let n = nv.norm();
    let hhat = if h > 0.0 {
        (1.0 / h) * hv
    } else {
        Vec3::new(0.0, 0.0, 1.0)
    };
    let equatorial = n <= TINY * h.max(f64::MIN_POSITIVE);
    let circular = e <= TINY;
    let retro = if hv.0[2] < 0.0 { -1.0 } else { 1.0 };
    let omega_node = if equatorial {
        0.0
    } else {
        libm::atan2(hv.0[0], -hv.0[1])
    };
    let (omega, f) = match (equatorial, circular) {
        (false, false) => {
            let nh = (1.0 / n) * nv;
            let w = libm::atan2(hhat.dot(nh.cross(ev)), nh.dot(ev));
            let f = libm::atan2(hhat.dot(ev.cross(r)), ev.dot(r));
            (w, f)
        }
        (true, false) => {
            let w = retro * libm::atan2(ev.0[1], ev.0[0]);
            let f = libm::atan2(hhat.dot(ev.cross(r)), ev.dot(r));
            (w, f)
        }
        (false, true) => {
            let nh = (1.0 / n) * nv;
            (0.0, libm::atan2(hhat.dot(nh.cross(r)), nh.dot(r)))
        }
        (true, true) => (0.0, retro * libm::atan2(r.0[1], r.0[0])),
    };
    let period = if a > 0.0 {
        2.0 * PI * (a * a * a / mu).sqrt()
    } else {
        f64::INFINITY
    };
    let m = if (e - 1.0).abs() > TINY {
        true_to_mean(f, e)
    } else {
        f64::NAN
    };
    Some(Orbit {
        a,
        e,
        inc,
        Omega: omega_node.rem_euclid(2.0 * PI),
        omega: omega.rem_euclid(2.0 * PI),
        f: f.rem_euclid(2.0 * PI),
        M: if e < 1.0 { m.rem_euclid(2.0 * PI) } else { m },
        period,
        h,
        d,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_round_trip() {
        for &(a, e, inc) in &[
            (1.0, 0.3, 0.4),
            (2.5, 0.9, 2.0),
            (-1.5, 1.7, 0.7),
            (1.0, 0.01, 0.2),
        ] {
            let el = Elements {
                a,
                e,
                inc,
                Omega: 1.1,
                omega: 2.2,
                anomaly: Anomaly::Mean(0.7),
            };
            let (r, v) = elements_to_cartesian(1.3, &el).unwrap();
            let o = cartesian_to_orbit(1.3, r, v).unwrap();
            assert!((o.a - a).abs() < 1e-12 * a.abs(), "{o:?}");
            assert!((o.e - e).abs() < 1e-12, "{o:?}");
            assert!((o.inc - inc).abs() < 1e-12, "{o:?}");
            assert!((o.Omega - 1.1).abs() < 1e-12, "{o:?}");
            assert!((o.omega - 2.2).abs() < 1e-10, "{o:?}");
            assert!((o.M - 0.7).abs() < 1e-10, "{o:?}");
        }
    }

    #[test]
    fn anomalies_invert() {
        for &e in &[0.0, 0.5, 0.99] {
            for k in 0..12 {
                let m = 0.5 * k as f64;
                let f = mean_to_true(m, e);
                // Compared as angles: 2π − 1e-17 and 0 are the same mean anomaly.
                let d = (true_to_mean(f, e) - m).rem_euclid(2.0 * PI);
                let err = d.min(2.0 * PI - d);
                assert!(err < 1e-11, "e {e} m {m} err {err}");
            }
        }
    }

    #[test]
    fn invalid_elements_are_typed_errors() {
        let mut el = Elements::circular(1.0);
        for (a, e) in [(1.0, -0.1), (-1.0, 0.5), (0.0, 0.5), (1.0, 1.5), (1.0, 1.0)] {
            el.a = a;
            el.e = e;
            assert!(matches!(
                elements_to_cartesian(1.0, &el),
                Err(GravityError::InvalidElements { .. })
            ));
        }
        el = Elements {
            a: -1.0,
            e: 2.0,
            anomaly: Anomaly::True(3.0),
            ..Elements::circular(1.0)
        };
        assert!(elements_to_cartesian(1.0, &el).is_err());
    }
}
