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
            let at = pool.subs1(d, t, tt);
            let at = pool.expand(at);
            let at = pool.simplify(at);
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
