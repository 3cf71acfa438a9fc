//! Antiderivatives of the forms the 1-D rules meet once the initial values are symbols.
//!
//! With `x(0) = x0`, `v(0) = v0` left symbolic, a linear position law `a = c - k x` (a spring,
//! a spring under gravity, a repulsion) gives `v(x)^2 = p + r x + q x^2` with a linear term
//! and a constant `p = v0^2 + ...` of no known sign, so the time `t(x) = ∫ dx/sqrt(v^2)` is not
//! the centred `1/sqrt(p + q x^2)` with `p > 0` that [`super::antiderivative`] first tries; a
//! linear speed law `a = -g - c v` gives the distance `x(v) = ∫ v dv/(-g - c v)`, a power of
//! `v` over a linear function. These are elementary:
//! - `∫ dx/sqrt(p + r x + q x^2)` = `asin((-2 q x - r)/sqrt(r^2 - 4 p q))/sqrt(-q)` for `q < 0`
//!   (needing only the sign of `q`: where the motion exists, `r^2 - 4 p q > 0`), and
//!   `log|2 sqrt(q) sqrt(p + r x + q x^2) + 2 q x + r|/sqrt(q)` for `q > 0`;
//! - `∫ dx/(p + r x + q x^2)` by the sign of the discriminant `D = r^2 - 4 p q`:
//!   `2 atan((2 q x + r)/sqrt(-D))/sqrt(-D)`, `log|(2 q x + r - sqrt D)/(2 q x + r + sqrt D)|/sqrt D`
//!   or `-2/(2 q x + r)`;
//! - `∫ x dx/(p + r x + q x^2)` = `log|b|/(2 q) - (r/(2 q)) ∫ dx/b` (the distance under
//!   a quadratic speed law with a linear term, `a = -g - b v - c v^2`);
//! - `∫ x^n (α x + β)^k dx` by the substitution `u = α x + β`, which turns it into a sum of
//!   powers of `u` (`log|u|` for `u^-1`).
//!
//! Like every antiderivative of the module, each is checked by differentiating it back.

use super::super::exact::sign_of;
use super::super::Relation;
use super::{free_of, integrate_rec, linear};
use pdyn_expr::{Func, Id, Node, Number, Pool};

/// `(p, r, q)` with `b = p + r x + q x^2` and `q ≠ 0`, or `None`.
fn coefficients(pool: &mut Pool, b: Id, var: Id) -> Option<(Id, Id, Id)> {
    let d1 = pool.diff(b, var);
    let d2 = pool.diff(d1, var);
    if d2 == Pool::ZERO || !free_of(pool, d2, var) {
        return None;
    }
    let half = pool.num(Number::ratio(1, 2));
    let q = pool.mul2(half, d2);
    let q = pool.simplify(q);
    let r = pool.subs1(d1, var, Pool::ZERO);
    let r = pool.simplify(r);
    let p = pool.subs1(b, var, Pool::ZERO);
    let p = pool.simplify(p);
    Some((p, r, q))
}

/// `r^2 - 4 p q`, simplified.
fn discriminant(pool: &mut Pool, p: Id, r: Id, q: Id) -> Id {
    let r2 = pool.powi(r, 2);
    let four = pool.int(4);
    let pq = pool.mul(&[four, p, q]);
    let d = pool.sub(r2, pq);
    pool.simplify(d)
}

/// `2 q x + r`.
fn slope(pool: &mut Pool, r: Id, q: Id, var: Id) -> Id {
    let two = pool.int(2);
    let qx = pool.mul(&[two, q, var]);
    pool.add2(qx, r)
}

/// `∫ dx/sqrt(b)` for a quadratic `b` whose leading coefficient has a known sign.
pub(super) fn inverse_sqrt(pool: &mut Pool, b: Id, var: Id) -> Option<Id> {
    let (p, r, q) = coefficients(pool, b, var)?;
    match sign_of(pool, q)? {
        Relation::Negative => {
            let d = discriminant(pool, p, r, q);
            let s = slope(pool, r, q, var);
            let minus_s = pool.neg(s);
            let sd = pool.sqrt(d);
            let arg = pool.div(minus_s, sd);
            let a = pool.call(Func::Asin, &[arg]);
            let nq = pool.neg(q);
            let sq = pool.sqrt(nq);
            Some(pool.div(a, sq))
        }
        Relation::Positive => {
            let sq = pool.sqrt(q);
            let two = pool.int(2);
            let root = pool.sqrt(b);
            let lead = pool.mul(&[two, sq, root]);
            let s = slope(pool, r, q, var);
            let sum = pool.add2(lead, s);
            let ab = pool.call(Func::Abs, &[sum]);
            let l = pool.call(Func::Log, &[ab]);
            Some(pool.div(l, sq))
        }
        Relation::Zero => None,
    }
}

/// `∫ dx/b` for a quadratic `b` whose discriminant has a known sign.
pub(super) fn inverse(pool: &mut Pool, b: Id, var: Id) -> Option<Id> {
    let (p, r, q) = coefficients(pool, b, var)?;
    let d = discriminant(pool, p, r, q);
    let s = slope(pool, r, q, var);
    match sign_of(pool, d)? {
        Relation::Negative => {
            let nd = pool.neg(d);
            let sd = pool.sqrt(nd);
            let arg = pool.div(s, sd);
            let at = pool.call(Func::Atan, &[arg]);
            let two = pool.int(2);
            let num = pool.mul2(two, at);
            Some(pool.div(num, sd))
        }
        Relation::Positive => {
            let sd = pool.sqrt(d);
            let lo = pool.sub(s, sd);
            let hi = pool.add2(s, sd);
            let ratio = pool.div(lo, hi);
            let ab = pool.call(Func::Abs, &[ratio]);
            let l = pool.call(Func::Log, &[ab]);
            Some(pool.div(l, sd))
        }
        Relation::Zero => {
            let m2 = pool.int(-2);
            Some(pool.div(m2, s))
        }
    }
}

/// Highest power `n` of `x` in `x^n (α x + β)^k` integrated by substitution (the expansion has
/// `n + 1` terms).
const MAX_POWER: i64 = 6;

/// `∫ x^n (α x + β)^k dx` (`factors` multiply to the integrand, without constant factors):
/// with `u = α x + β`, `x = (u - β)/α` and `dx = du/α`.
pub(super) fn power_times_linear(
    pool: &mut Pool,
    factors: &[Id],
    var: Id,
    steps: &mut usize,
    depth: usize,
) -> Option<Id> {
    let mut n = 0i64;
    let mut base: Option<(Id, Id)> = None;
    for &f in factors {
        if f == var {
            n += 1;
            continue;
        }
        match pool.node(f).clone() {
            Node::Pow(b, k) if b == var => {
                n += pool.as_num(k)?.as_integer().filter(|&k| k > 0)?;
            }
            Node::Pow(b, k) if base.is_none() && free_of(pool, k, var) => {
                linear(pool, b, var)?;
                base = Some((b, k));
            }
            _ if base.is_none() && linear(pool, f, var).is_some() => base = Some((f, Pool::ONE)),
            _ => return None,
        }
    }
    let (b, k) = base?;
    if n == 0 || n > MAX_POWER {
        return None;
    }
    let (alpha, beta) = linear(pool, b, var)?;
    // A dummy that no law names: the rules' own dummy is τ.
    let u = pool.var("ς");
    let shifted = pool.sub(u, beta);
    let x_of_u = pool.div(shifted, alpha);
    let xn = pool.powi(x_of_u, n);
    let uk = pool.pow(u, k);
    let integrand = pool.mul(&[xn, uk]);
    let integrand = pool.div(integrand, alpha);
    let integrand = pool.expand(integrand);
    let f = integrate_rec(pool, integrand, u, steps, depth + 1)?;
    Some(pool.subs1(f, u, b))
}

/// `∫ x dx/b` for a quadratic `b` whose discriminant has a known sign (`factors` multiply to
/// the integrand, without constant factors).
pub(super) fn linear_over_quadratic(pool: &mut Pool, factors: &[Id], var: Id) -> Option<Id> {
    let [f1, f2] = factors else { return None };
    let b = match (pool.node(*f1).clone(), pool.node(*f2).clone()) {
        (_, Node::Pow(b, k)) if *f1 == var && k == Pool::MINUS_ONE => b,
        (Node::Pow(b, k), _) if *f2 == var && k == Pool::MINUS_ONE => b,
        _ => return None,
    };
    let (_, r, q) = coefficients(pool, b, var)?;
    let rest = inverse(pool, b, var)?;
    let two = pool.int(2);
    let twice_q = pool.mul2(two, q);
    let ab = pool.call(Func::Abs, &[b]);
    let l = pool.call(Func::Log, &[ab]);
    let log_part = pool.div(l, twice_q);
    let coef = pool.div(r, twice_q);
    let inv_part = pool.mul2(coef, rest);
    Some(pool.sub(log_part, inv_part))
}
