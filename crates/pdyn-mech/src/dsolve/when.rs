//! [`when`]: the first instant `t ≥ 0` at which a condition on a closed-form solution holds,
//! and the state there (`pdyn dsolve --when "y' = 0"`: the apex of a throw).
//!
//! The condition `g(q, q', q'', …, t) = 0` becomes `g(t) = 0` by substituting the solution and
//! its derivatives; [`crate::kinematics::solve_time`] then finds the root, exactly when the
//! equation is linear in `t` or of the form `c tⁿ = target`, numerically otherwise.

use super::{ClosedForm, DsolveError};
use crate::kinematics::solve_time;
use pdyn_expr::{Id, Number, Pool};

/// The value of one state component at the instant.
#[derive(Clone, Debug, PartialEq)]
pub struct StateAt {
    /// `x` or `x'`.
    pub name: String,
    /// Its exact value.
    pub exact: Id,
    /// Its numeric value, when it has no free symbols.
    pub value: Option<f64>,
}

/// Result of [`when`].
#[derive(Clone, Debug, PartialEq)]
pub struct When {
    /// The instant, exact when it could be solved exactly (else a float node).
    pub t: Id,
    /// Whether `t` is exact.
    pub exact: bool,
    /// Its numeric value (NaN when it depends on symbols).
    pub value: f64,
    /// Every coordinate and its rate at `t`.
    pub state: Vec<StateAt>,
}

/// Highest derivative order a condition may contain.
const MAX_ORDER: u8 = 8;

/// Most simplification work spent tidying each component of the state at the instant.
const STATE_WORK: u64 = 60_000;

/// Largest exact number (in bits, about 300 digits) in a state that is still tidied.
const TIDY_BITS: u64 = 1_000;

/// The size in bits of the largest exact number in `e`.
fn largest_number_bits(pool: &Pool, e: Id) -> u64 {
    pool.topo_order(&[e])
        .into_iter()
        .filter_map(|n| match pool.as_num(n) {
            Some(Number::Rat(q)) => Some(q.bits()),
            _ => None,
        })
        .max()
        .unwrap_or(0)
}

/// The first `t ≥ 0` where `condition = 0` on the (single-case) solution `cf`.
pub fn when(pool: &mut Pool, cf: &ClosedForm, condition: Id) -> Result<When, DsolveError> {
    let [case] = cf.cases.as_slice() else {
        return Err(DsolveError::SeveralCases);
    };
    let sol = &case.solution;
    let mut e = condition;
    for (j, &c) in cf.coords.iter().enumerate() {
        for k in (0..=MAX_ORDER).rev() {
            let leaf = pool.coord(c, k);
            if pool.contains(e, leaf) {
                let d = pool.dt_n(sol[j], k as usize);
                e = pool.subs1(e, leaf, d);
            }
        }
    }
    let (exact, value) = solve_time(pool, e, Pool::ZERO).map_err(DsolveError::Instant)?;
    let t = pool.time();
    let tt = exact.unwrap_or_else(|| pool.num(Number::Float(value)));
    let mut state = Vec::new();
    for (j, &c) in cf.coords.iter().enumerate() {
        for k in 0..2 {
            let d = pool.dt_n(sol[j], k);
            let raw = pool.subs1(d, t, tt);
            // Tidying the state is a nicety, under a work bound, and skipped for numbers so
            // large that one polynomial gcd among them is already slow (a root of
            // 3,800-digit numbers took 14 s of pseudo-remainders here, found by fuzzing).
            let at = if largest_number_bits(pool, raw) > TIDY_BITS {
                raw
            } else {
                let (tidy, enough) = pool.with_simplify_budget(STATE_WORK, |p| {
                    let at = p.expand(raw);
                    p.simplify(at)
                });
                if enough {
                    tidy
                } else {
                    raw
                }
            };
            state.push(StateAt {
                name: format!("{}{}", pool.name(c), "'".repeat(k)),
                exact: at,
                value: pool.eval_const(at).ok(),
            });
        }
    }
    Ok(When {
        t: tt,
        exact: exact.is_some(),
        value,
        state,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsolve::solve_system;

    /// y'' = -g from y(0) = 0, y'(0) = v0: the apex y' = 0 is at t = v0/g, height v0²/(2g).
    #[test]
    fn apex_of_a_vertical_throw() {
        let mut p = Pool::new();
        for s in ["g", "v0"] {
            p.symbol(s, true);
        }
        let y = p.symbol("y", false);
        let eq = p.parse_scalar("y'' + g").unwrap();
        let (y0, y1) = (p.coord(y, 0), p.coord(y, 1));
        let v0 = p.var("v0");
        let cf = solve_system(&mut p, &[eq], &[y], &[(y0, Pool::ZERO), (y1, v0)]).unwrap();
        let cond = p.coord(y, 1);
        let w = when(&mut p, &cf, cond).unwrap();
        assert!(w.exact);
        assert_eq!(p.to_text(w.t), "v0/g");
        assert_eq!(w.state[0].name, "y");
        assert_eq!(p.to_text(w.state[0].exact), "v0^2/(2*g)");
        assert_eq!(p.to_text(w.state[1].exact), "0");
        assert_eq!(w.state[1].value, Some(0.0));
    }

    /// Found by fuzzing (the `dsolve` target, 2026-11-26): coefficients of 3,800 digits made
    /// tidying the state at the instant run for 14 s of polynomial pseudo-remainders (over 30 s
    /// under the sanitizer). The state is now left as substituted past `TIDY_BITS`.
    #[test]
    fn a_state_of_huge_numbers_is_not_tidied() {
        let mut p = Pool::new();
        let src = "ft2333-m/t3f33*9-ft3333-38/-4e3844--3/aK72e38/-1e3847-3/-339-f''";
        let eq = p.parse_scalar(src).unwrap();
        let f = p.find_symbol("f").unwrap();
        let (f0, f1) = (p.coord(f, 0), p.coord(f, 1));
        let cf = solve_system(&mut p, &[eq], &[f], &[(f0, Pool::ONE), (f1, Pool::ZERO)]).unwrap();
        let w = when(&mut p, &cf, f0).unwrap();
        assert!(w.exact);
        assert!(largest_number_bits(&p, w.state[0].exact) > TIDY_BITS);
    }

    #[test]
    fn a_condition_never_met_is_an_error() {
        let mut p = Pool::new();
        let y = p.symbol("y", false);
        let eq = p.parse_scalar("y'' + 1").unwrap();
        let (y0, y1) = (p.coord(y, 0), p.coord(y, 1));
        let cf = solve_system(&mut p, &[eq], &[y], &[(y0, Pool::ZERO), (y1, Pool::ZERO)]).unwrap();
        // y = -t^2/2 never reaches 1.
        let cond = p.parse_scalar("y(t) - 1").unwrap();
        assert!(matches!(
            when(&mut p, &cf, cond),
            Err(DsolveError::Instant(_))
        ));
    }
}
