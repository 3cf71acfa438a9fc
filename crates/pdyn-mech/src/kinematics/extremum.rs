//! The largest value of a kinematic quantity over a range.
//!
//! [`maximize`]: numerically, for `f(x)` with every other leaf a number — dense sampling (2 000
//! intervals) then golden-section refinement around the best sample.
//!
//! [`maximum`]: for `f(x; p₁…p_k)` with symbolic parameters. The location of the maximum of
//! the textbook's quantities (|a| on a sine road, on a manipulator arm) is usually a fixed
//! fraction of the range, independent of the parameters (x = L/4 on a road of wavelength L).
//! So: maximise numerically for two sets of parameter values; when the maximum sits at the
//! same small-denominator fraction `p/q` of the range both times, the exact location is
//! `lo + (p/q)(hi - lo)` and the exact value `f` there; a third parameter set checks that
//! value against a numerical maximisation. Otherwise the location depends on the parameters
//! and values must be given.

use super::{tidy_magnitude, KinError};
use pdyn_expr::{Id, Node, Number, Pool, Program};

/// Result of [`maximize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extremum {
    /// Where the maximum is.
    pub at: f64,
    /// The maximum value.
    pub value: f64,
}

/// Result of [`maximum`].
#[derive(Clone, Debug, PartialEq)]
pub enum Maximum {
    /// Every leaf had a value: the maximum found numerically.
    Numeric(Extremum),
    /// Symbolic parameters: the exact location and value.
    Exact {
        /// Where the maximum is (an expression in the parameters).
        at: Id,
        /// The maximum value.
        value: Id,
        /// The parameters the result depends on, by name.
        parameters: Vec<String>,
    },
}

/// Largest value of `f(var)` for `var` in `[lo, hi]` (every other leaf must be a number by
/// now): dense sampling, then golden-section refinement around the best sample. Among equal
/// maxima the first is returned.
pub fn maximize(pool: &mut Pool, f: Id, var: Id, lo: f64, hi: f64) -> Result<Extremum, KinError> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Err(KinError::InvalidRange { lo, hi });
    }
    let prog = Program::compile(pool, &[var], &[f]).map_err(|e| KinError::NotEvaluable {
        expr: pool.to_text(f),
        reason: e.to_string(),
    })?;
    let mut ws = prog.workspace();
    let mut eval = |x: f64| {
        let mut o = [0.0];
        prog.eval(&[x], &mut ws, &mut o);
        if o[0].is_finite() {
            o[0]
        } else {
            f64::NEG_INFINITY
        }
    };
    const N: usize = 2000;
    let mut best = (lo, eval(lo));
    for k in 0..=N {
        let x = lo + (hi - lo) * k as f64 / N as f64;
        let y = eval(x);
        if y > best.1 + 1e-12 * best.1.abs() {
            best = (x, y);
        }
    }
    if best.1 == f64::NEG_INFINITY {
        return Err(KinError::NotFinite {
            expr: pool.to_text(f),
        });
    }
    let h = (hi - lo) / N as f64;
    let (mut a, mut b) = ((best.0 - h).max(lo), (best.0 + h).min(hi));
    let gr = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - gr * (b - a);
    let mut d = a + gr * (b - a);
    let (mut fc, mut fd) = (eval(c), eval(d));
    for _ in 0..200 {
        if fc >= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - gr * (b - a);
            fc = eval(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + gr * (b - a);
            fd = eval(d);
        }
        if (b - a).abs() <= 1e-15 * (1.0 + a.abs()) {
            break;
        }
    }
    let x = 0.5 * (a + b);
    let fx = eval(x);
    Ok(if fx >= best.1 {
        Extremum { at: x, value: fx }
    } else {
        Extremum {
            at: best.0,
            value: best.1,
        }
    })
}

/// Seeds of the three parameter sets tried by [`maximum`] (fixed, so results are reproducible).
pub(crate) const TRIAL_SEEDS: [u64; 3] = [
    0x1234_5678_9abc_def1,
    0x0fed_cba9_8765_4321,
    0x5555_aaaa_3333_cccc,
];

/// Deterministic pseudo-random positive values in [0.5, 3) for parameter trials (xorshift).
pub(crate) fn trial_values(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            0.5 + 2.5 * (s % 100_000) as f64 / 100_000.0
        })
        .collect()
}

/// A close small-denominator fraction `p/q` (q ≤ 24) of `x` in [0, 1].
fn small_fraction(x: f64) -> Option<(i64, i64)> {
    for q in 1..=24i64 {
        let p = (x * q as f64).round();
        if (x - p / q as f64).abs() < 1e-7 {
            return Some((p as i64, q));
        }
    }
    None
}

fn tidy(pool: &mut Pool, e: Id) -> Id {
    let x = pool.expand(e);
    pool.simplify(x)
}

/// The largest value of `f` for `var` in `[lo, hi]`, where `f`, `lo` and `hi` may contain
/// parameters without values (assumed positive). See the module documentation for the method.
pub fn maximum(pool: &mut Pool, f: Id, var: Id, lo: Id, hi: Id) -> Result<Maximum, KinError> {
    let mut free: Vec<Id> = Vec::new();
    for n in pool.topo_order(&[f, lo, hi]) {
        if matches!(pool.node(n), Node::Sym(_) | Node::Time) && n != var && !free.contains(&n) {
            free.push(n);
        }
    }
    if free.contains(&pool.time()) {
        return Err(KinError::DependsOnTime {
            expr: pool.to_text(f),
        });
    }
    let trial = |pool: &mut Pool, vals: &[f64]| -> Result<(Extremum, f64, f64), KinError> {
        let map: Vec<(Id, Id)> = free
            .iter()
            .zip(vals)
            .map(|(&s, &v)| (s, pool.num(Number::Float(v))))
            .collect();
        let subs =
            |pool: &mut Pool, e: Id| map.iter().fold(e, |acc, &(k, v)| pool.subs1(acc, k, v));
        let (fs, l, h) = (subs(pool, f), subs(pool, lo), subs(pool, hi));
        let bound = |pool: &mut Pool, e: Id| {
            pool.eval_const(e).map_err(|err| KinError::NotEvaluable {
                expr: pool.to_text(e),
                reason: err.to_string(),
            })
        };
        let (lv, hv) = (bound(pool, l)?, bound(pool, h)?);
        Ok((maximize(pool, fs, var, lv, hv)?, lv, hv))
    };
    if free.is_empty() {
        return Ok(Maximum::Numeric(trial(pool, &[])?.0));
    }
    let parameters: Vec<String> = free.iter().map(|&s| pool.to_text(s)).collect();
    let depends = || KinError::LocationDependsOn {
        parameters: parameters.clone(),
    };
    let fraction = |(e, l, h): (Extremum, f64, f64)| small_fraction((e.at - l) / (h - l));
    let f1 = fraction(trial(pool, &trial_values(free.len(), TRIAL_SEEDS[0]))?);
    let f2 = fraction(trial(pool, &trial_values(free.len(), TRIAL_SEEDS[1]))?);
    let (p, q) = match (f1, f2) {
        (Some(a), Some(b)) if a == b => a,
        _ => return Err(depends()),
    };
    let width = pool.sub(hi, lo);
    let pq = pool.num(Number::ratio(p, q));
    let off = pool.mul2(pq, width);
    let at = pool.add2(lo, off);
    let at = tidy(pool, at);
    let value = pool.subs1(f, var, at);
    let value = tidy(pool, value);
    let value = tidy_magnitude(pool, value);
    // Check the exact value against a third, independent numerical maximisation.
    let check = trial_values(free.len(), TRIAL_SEEDS[2]);
    let (e3, _, _) = trial(pool, &check)?;
    let at_check = free.iter().zip(&check).fold(value, |acc, (&s, &v)| {
        let x = pool.num(Number::Float(v));
        pool.subs1(acc, s, x)
    });
    let v3 = pool.eval_const(at_check).map_err(|_| depends())?;
    // NaN fails the check too.
    let agrees = (v3 - e3.value).abs() <= 1e-8 * (1.0 + e3.value.abs());
    if !agrees {
        return Err(depends());
    }
    Ok(Maximum::Exact {
        at,
        value,
        parameters,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(p: &mut Pool, s: &str) -> Id {
        p.parse_scalar(s).unwrap()
    }

    #[test]
    fn numeric_maximum_of_a_parabola() {
        let mut p = Pool::new();
        let f = parse(&mut p, "1 - (x - 0.3)^2");
        let x = p.var("x");
        let e = maximize(&mut p, f, x, 0.0, 1.0).unwrap();
        assert!((e.at - 0.3).abs() < 1e-7 && (e.value - 1.0).abs() < 1e-14);
        assert_eq!(
            maximize(&mut p, f, x, 1.0, 0.0),
            Err(KinError::InvalidRange { lo: 1.0, hi: 0.0 })
        );
    }

    #[test]
    fn curvy_road_maximum_is_exact_at_a_quarter_wavelength() {
        // |a| on y = A sin(2 pi x/L) at speed V is V^2 |kappa|, largest at x = L/4.
        let mut p = Pool::new();
        for s in ["A", "L", "V"] {
            p.symbol(s, true);
        }
        let f = parse(
            &mut p,
            "V^2*abs(-A*(2*pi/L)^2*sin(2*pi*x/L))/(1 + (A*2*pi/L*cos(2*pi*x/L))^2)^(3/2)",
        );
        let (x, lo, hi) = (p.var("x"), Pool::ZERO, p.var("L"));
        match maximum(&mut p, f, x, lo, hi).unwrap() {
            Maximum::Exact {
                at,
                value,
                parameters,
            } => {
                assert_eq!(p.to_text(at), "L/4");
                assert_eq!(p.to_text(value), "4*pi^2*A*V^2/L^2");
                assert_eq!(parameters.len(), 3);
            }
            other => panic!("expected an exact maximum, got {other:?}"),
        }
    }

    #[test]
    fn a_location_that_moves_with_the_parameters_is_refused() {
        // max of -(x - c)^2 over [0, 1] is at x = c: not a fixed fraction of the range.
        let mut p = Pool::new();
        let f = parse(&mut p, "-(x - c/4)^2");
        let (x, one) = (p.var("x"), Pool::ONE);
        let err = maximum(&mut p, f, x, Pool::ZERO, one).unwrap_err();
        assert!(matches!(err, KinError::LocationDependsOn { .. }), "{err}");
        let g = parse(&mut p, "x*t");
        assert!(matches!(
            maximum(&mut p, g, x, Pool::ZERO, one),
            Err(KinError::DependsOnTime { .. })
        ));
    }
}
