//! The 1-D rules of straight-line motion (section 3.1.3), in closed form when the integrals are
//! elementary and by quadrature (with an error estimate) otherwise.
//!
//! With `x(0) = x0`, `v(0) = v0`:
//! - `a = f(t)`: `v(t) = v0 + ∫_0^t f`, `x(t) = x0 + v0 t + ∫_0^t (t - u) f(u) du` (Cauchy's
//!   formula: one integral instead of two);
//! - `v = f(t)`: `x(t) = x0 + ∫_0^t f`, `a(t) = f'(t)`;
//! - `a = f(v)`: `dt = dv/f(v)` and `dx = v dv/f(v)`, so `t(v) = ∫_{v0}^v du/f(u)` and
//!   `x(v) = x0 + ∫_{v0}^v u du/f(u)`;
//! - `a = f(x)`: `v dv = f dx`, so `v(x)^2 = v0^2 + 2 ∫_{x0}^x f` and
//!   `t(x) = ∫_{x0}^x du / v(u)` (moving towards increasing `x`).
//!
//! [`antiderivative`] integrates sums and constant multiples of powers, exponentials, sines,
//! cosines and hyperbolic functions of linear arguments, `1/(p + q u^2)`, and anything of the
//! form `c g'(u) h(g(u))` for those `h` (substitution); and, for the laws whose initial values
//! are symbols (the `quadratic` submodule), `1/sqrt(p + r u + q u^2)` and `1/(p + r u + q u^2)`
//! with a linear term or a constant of unknown sign, `u/(p + r u + q u^2)`, and
//! `u^n (α u + β)^k`. Every antiderivative is checked by
//! differentiating it back; an unchecked one is discarded and quadrature is used instead.

mod quadratic;

use super::exact::sign_of;
use super::quad::integrate;
use super::{DsolveError, Relation};
use pdyn_expr::{Func, Id, Node, Number, Pool, Program};

/// Which quantity the rule is given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Given {
    /// `a = f(t)`.
    AccelerationOfTime,
    /// `v = f(t)`.
    VelocityOfTime,
    /// `a = f(v)`.
    AccelerationOfSpeed,
    /// `a = f(x)`.
    AccelerationOfPosition,
}

impl Given {
    /// Name of the independent variable of the law (`t`, `v` or `x`).
    pub fn variable(self) -> &'static str {
        match self {
            Given::AccelerationOfTime | Given::VelocityOfTime => "t",
            Given::AccelerationOfSpeed => "v",
            Given::AccelerationOfPosition => "x",
        }
    }
}

/// How a quantity is computed numerically: `post(base + ∫_from^s integrand(u, s) du)`.
#[derive(Clone, Copy, Debug)]
enum Numeric {
    /// `base + ∫_from^s integrand du` (`integrand` may involve `s` too).
    Integral { base: Id, integrand: Id, from: Id },
    /// `∫_from^s du / sqrt(v0^2 + 2 ∫_from^u f)` (time along a position law).
    TimeAlongPosition { v0: Id, law: Id, from: Id },
    /// A closed form, always available.
    Closed(Id),
}

/// One derived relation, e.g. `v(t)`.
#[derive(Clone, Debug)]
pub struct Quantity {
    /// Its name, e.g. `x(t)` or `v(x)^2`.
    pub name: String,
    /// The closed form in the independent variable, when the integrals are elementary.
    pub closed: Option<Id>,
    numeric: Numeric,
    /// The independent variable (`t`, or the symbol `v` or `x`).
    pub variable: Id,
    dummy: Id,
}

impl Quantity {
    /// The defining integral in words, for output when there is no closed form.
    pub fn describe(&self, pool: &Pool) -> String {
        let s = pool.to_text(self.variable);
        let u = pool.to_text(self.dummy);
        match self.numeric {
            Numeric::Integral {
                base,
                integrand,
                from,
            } => format!(
                "{} + ∫_{}^{s} ({}) d{u}",
                pool.to_text(base),
                pool.to_text(from),
                pool.to_text(integrand)
            ),
            Numeric::TimeAlongPosition { v0, law, from } => format!(
                "∫_{}^{s} d{u} / sqrt(({})^2 + 2 ∫ ({}) d{s})",
                pool.to_text(from),
                pool.to_text(v0),
                pool.to_text(law)
            ),
            Numeric::Closed(c) => pool.to_text(c),
        }
    }
}

/// The relations implied by a rule.
#[derive(Clone, Debug)]
pub struct RuleSolution {
    /// What was given.
    pub given: Given,
    /// The derived quantities.
    pub quantities: Vec<Quantity>,
}

/// A value with its estimated absolute error (0 for a closed form).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Estimated absolute error (quadrature), 0 for closed forms.
    pub error: f64,
}

/// Derives the rule's relations. `law` is an expression in `t` (time laws) or in the symbol
/// `v` or `x` (speed and position laws).
pub fn solve_rule(
    pool: &mut Pool,
    given: Given,
    law: Id,
    x0: Id,
    v0: Id,
) -> Result<RuleSolution, DsolveError> {
    let var = match given {
        Given::AccelerationOfTime | Given::VelocityOfTime => pool.time(),
        _ => pool.var(given.variable()),
    };
    if pool.any_node(law, &|n| matches!(n, Node::Coord(..))) {
        return Err(DsolveError::Invalid(
            "the law must be written in t, v or x, without primes".into(),
        ));
    }
    let other_vars: &[&str] = match given {
        Given::AccelerationOfTime | Given::VelocityOfTime => &["v", "x"],
        Given::AccelerationOfSpeed => &["x"],
        Given::AccelerationOfPosition => &["v"],
    };
    for name in other_vars {
        if let Some(s) = pool.find_symbol(name) {
            let sy = pool.sym(s);
            if pool.contains(law, sy) {
                return Err(DsolveError::Invalid(format!(
                    "the law is given as a function of {}, but it involves `{name}`",
                    given.variable()
                )));
            }
        }
    }
    let u = pool.var("τ");
    let law_u = pool.subs1(law, var, u);
    let mut qs = Vec::new();
    let mut push = |name: &str, closed: Option<Id>, numeric: Numeric| {
        qs.push(Quantity {
            name: name.to_string(),
            closed,
            numeric,
            variable: var,
            dummy: u,
        });
    };
    let zero = Pool::ZERO;
    match given {
        Given::AccelerationOfTime => {
            // Integrate the unsimplified v again: simplification may trade cos(2t) for cos(t)^2.
            let v_raw = definite(pool, law, var, zero, var).map(|i| pool.add2(v0, i));
            let v = v_raw.map(|e| pool.simplify(e));
            push(
                "v(t)",
                v,
                Numeric::Integral {
                    base: v0,
                    integrand: law_u,
                    from: zero,
                },
            );
            let x = match v_raw {
                Some(v) => definite(pool, v, var, zero, var).map(|i| {
                    let e = pool.add2(x0, i);
                    pool.simplify(e)
                }),
                None => None,
            };
            let v0t = pool.mul2(v0, var);
            let base = pool.add2(x0, v0t);
            let tu = pool.sub(var, u);
            let integrand = pool.mul2(tu, law_u);
            push(
                "x(t)",
                x,
                Numeric::Integral {
                    base,
                    integrand,
                    from: zero,
                },
            );
        }
        Given::VelocityOfTime => {
            let x = definite(pool, law, var, zero, var).map(|i| {
                let e = pool.add2(x0, i);
                pool.simplify(e)
            });
            push(
                "x(t)",
                x,
                Numeric::Integral {
                    base: x0,
                    integrand: law_u,
                    from: zero,
                },
            );
            let a = pool.dt(law);
            let a = pool.simplify(a);
            push("a(t)", Some(a), Numeric::Closed(a));
        }
        Given::AccelerationOfSpeed => {
            let inv = pool.powi(law, -1);
            let t = definite(pool, inv, var, v0, var).map(|e| pool.simplify(e));
            let inv_u = pool.powi(law_u, -1);
            push(
                "t(v)",
                t,
                Numeric::Integral {
                    base: zero,
                    integrand: inv_u,
                    from: v0,
                },
            );
            let vf = pool.mul2(var, inv);
            let x = definite(pool, vf, var, v0, var).map(|i| {
                let e = pool.add2(x0, i);
                pool.simplify(e)
            });
            let uf = pool.mul2(u, inv_u);
            push(
                "x(v)",
                x,
                Numeric::Integral {
                    base: x0,
                    integrand: uf,
                    from: v0,
                },
            );
        }
        Given::AccelerationOfPosition => {
            let two = pool.int(2);
            let v0sq = pool.powi(v0, 2);
            let vsq = definite(pool, law, var, x0, var).map(|i| {
                let twice = pool.mul2(two, i);
                let e = pool.add2(v0sq, twice);
                pool.simplify(e)
            });
            let twice_law = pool.mul2(two, law_u);
            push(
                "v(x)^2",
                vsq,
                Numeric::Integral {
                    base: v0sq,
                    integrand: twice_law,
                    from: x0,
                },
            );
            let t = match vsq {
                Some(vsq) => {
                    let r = pool.sqrt(vsq);
                    let inv = pool.powi(r, -1);
                    definite(pool, inv, var, x0, var).map(|e| pool.simplify(e))
                }
                None => None,
            };
            push(
                "t(x)",
                t,
                Numeric::TimeAlongPosition {
                    v0,
                    law: law_u,
                    from: x0,
                },
            );
        }
    }
    Ok(RuleSolution {
        given,
        quantities: qs,
    })
}

/// `F(hi) - F(lo)` for a checked antiderivative `F` of `e` in `var`.
fn definite(pool: &mut Pool, e: Id, var: Id, lo: Id, hi: Id) -> Option<Id> {
    let f = antiderivative(pool, e, var)?;
    let a = pool.subs1(f, var, lo);
    // An antiderivative singular at the lower limit (log(0), 1/0) means an improper integral:
    // leave it to quadrature, which reports divergence.
    if !pool.any_node(a, &|n| {
        matches!(n, Node::Sym(_) | Node::Time | Node::Coord(..))
    }) && !pool.eval_const(a).ok()?.is_finite()
    {
        return None;
    }
    let b = pool.subs1(f, var, hi);
    Some(pool.sub(b, a))
}

/// Most recursion steps for one antiderivative (bounds the work).
const MAX_STEPS: usize = 200;

/// A checked antiderivative of `e` with respect to the leaf `var`, or `None`.
pub fn antiderivative(pool: &mut Pool, e: Id, var: Id) -> Option<Id> {
    let mut steps = 0;
    let f = integrate_rec(pool, e, var, &mut steps, 0).or_else(|| {
        let ex = pool.expand(e);
        if ex == e {
            return None;
        }
        steps = 0;
        integrate_rec(pool, ex, var, &mut steps, 0)
    })?;
    let f = pool.simplify(f);
    verify(pool, f, e, var).then_some(f)
}

/// `d/dvar F = e`, proven symbolically or, failing that, checked numerically at points where
/// both sides are finite.
fn verify(pool: &mut Pool, f: Id, e: Id, var: Id) -> bool {
    let d = pool.diff(f, var);
    if pool.provably_equal(d, e) {
        return true;
    }
    let mut leaves = Vec::new();
    for n in pool.topo_order(&[d, e]) {
        if matches!(pool.node(n), Node::Sym(_) | Node::Time) && !leaves.contains(&n) {
            leaves.push(n);
        }
    }
    let Ok(prog) = Program::compile(pool, &leaves, &[d, e]) else {
        return false;
    };
    let mut ws = prog.workspace();
    let mut out = [0.0; 2];
    let mut good = 0;
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..12 {
        let vals: Vec<f64> = leaves
            .iter()
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                0.3 + 1.7 * (seed % 10_000) as f64 / 10_000.0
            })
            .collect();
        prog.eval(&vals, &mut ws, &mut out);
        if !out[0].is_finite() || !out[1].is_finite() {
            continue;
        }
        if (out[0] - out[1]).abs() > 1e-9 * (1.0 + out[1].abs()) {
            return false;
        }
        good += 1;
    }
    good >= 4
}

fn free_of(pool: &Pool, e: Id, var: Id) -> bool {
    !pool.contains(e, var)
}

/// `(α, β)` with `e = α var + β`, α ≠ 0 free of `var`.
fn linear(pool: &mut Pool, e: Id, var: Id) -> Option<(Id, Id)> {
    let a = pool.diff(e, var);
    if a == Pool::ZERO || !free_of(pool, a, var) {
        return None;
    }
    let b = pool.subs1(e, var, Pool::ZERO);
    Some((a, b))
}

fn integrate_rec(pool: &mut Pool, e: Id, var: Id, steps: &mut usize, depth: usize) -> Option<Id> {
    *steps += 1;
    if *steps > MAX_STEPS || depth > 12 {
        return None;
    }
    if free_of(pool, e, var) {
        return Some(pool.mul2(e, var));
    }
    if e == var {
        let h = pool.num(Number::ratio(1, 2));
        let v2 = pool.powi(var, 2);
        return Some(pool.mul2(h, v2));
    }
    match pool.node(e).clone() {
        Node::Add(ts) => {
            let mut out = Vec::with_capacity(ts.len());
            for t in ts.iter() {
                out.push(integrate_rec(pool, *t, var, steps, depth + 1)?);
            }
            Some(pool.add(&out))
        }
        Node::Mul(fs) => {
            let (consts, rest): (Vec<Id>, Vec<Id>) =
                fs.iter().partition(|&&f| free_of(pool, f, var));
            if !consts.is_empty() {
                let c = pool.mul(&consts);
                let r = pool.mul(&rest);
                let i = integrate_rec(pool, r, var, steps, depth + 1)?;
                return Some(pool.mul2(c, i));
            }
            substitution(pool, e, &rest, var)
                .or_else(|| quadratic::power_times_linear(pool, &rest, var, steps, depth))
                .or_else(|| quadratic::linear_over_quadratic(pool, &rest, var))
        }
        Node::Pow(b, x) if free_of(pool, x, var) => {
            if let Some((alpha, _)) = linear(pool, b, var) {
                return Some(power_rule(pool, b, x, alpha));
            }
            // The centred forms first (their output is the textbook's), then the general
            // quadratic with a linear term or a constant of unknown sign (symbolic x0, v0).
            if x == Pool::MINUS_ONE {
                if let Some(f) = inverse_quadratic(pool, b, var) {
                    return Some(f);
                }
                if let Some(f) = quadratic::inverse(pool, b, var) {
                    return Some(f);
                }
            }
            let minus_half = pool.num(Number::ratio(-1, 2));
            if x == minus_half {
                if let Some(f) = inverse_sqrt_quadratic(pool, b, var) {
                    return Some(f);
                }
                if let Some(f) = quadratic::inverse_sqrt(pool, b, var) {
                    return Some(f);
                }
            }
            // Power reduction: sin(u)^2 = (1 - cos 2u)/2, cos(u)^2 = (1 + cos 2u)/2.
            if x == pool.int(2) {
                if let Node::Call(f @ (Func::Sin | Func::Cos), args) = pool.node(b).clone() {
                    let two = pool.int(2);
                    let u2 = pool.mul2(two, args[0]);
                    let c2 = pool.call(Func::Cos, &[u2]);
                    let c2 = if f == Func::Sin { pool.neg(c2) } else { c2 };
                    let s = pool.add2(Pool::ONE, c2);
                    let half = pool.num(Number::ratio(1, 2));
                    let r = pool.mul2(half, s);
                    let r = pool.expand(r);
                    return integrate_rec(pool, r, var, steps, depth + 1);
                }
            }
            None
        }
        Node::Call(f, args) => {
            let (alpha, _) = linear(pool, args[0], var)?;
            let u = args[0];
            let g = elementary(pool, f, u)?;
            Some(pool.div(g, alpha))
        }
        _ => None,
    }
}

/// `∫ b^x` for `b` linear with slope `alpha`.
fn power_rule(pool: &mut Pool, b: Id, x: Id, alpha: Id) -> Id {
    if x == Pool::MINUS_ONE {
        let ab = pool.call(Func::Abs, &[b]);
        let l = pool.call(Func::Log, &[ab]);
        return pool.div(l, alpha);
    }
    let x1 = pool.add2(x, Pool::ONE);
    let p = pool.pow(b, x1);
    let d = pool.mul2(x1, alpha);
    pool.div(p, d)
}

/// `∫ h(u) du` for the elementary `h`.
fn elementary(pool: &mut Pool, f: Func, u: Id) -> Option<Id> {
    Some(match f {
        Func::Exp => pool.call(Func::Exp, &[u]),
        Func::Sin => {
            let c = pool.call(Func::Cos, &[u]);
            pool.neg(c)
        }
        Func::Cos => pool.call(Func::Sin, &[u]),
        Func::Sinh => pool.call(Func::Cosh, &[u]),
        Func::Cosh => pool.call(Func::Sinh, &[u]),
        _ => return None,
    })
}

/// `∫ dx/sqrt(p + q x^2)` for `p > 0`: `asin(x sqrt(-q/p))/sqrt(-q)` when `q < 0`,
/// `log(sqrt(q) x + sqrt(p + q x^2))/sqrt(q)` when `q > 0`.
fn inverse_sqrt_quadratic(pool: &mut Pool, b: Id, var: Id) -> Option<Id> {
    let d1 = pool.diff(b, var);
    let d2 = pool.diff(d1, var);
    if !free_of(pool, d2, var) || pool.subs1(d1, var, Pool::ZERO) != Pool::ZERO {
        return None;
    }
    let half = pool.num(Number::ratio(1, 2));
    let q = pool.mul2(half, d2);
    let q = pool.simplify(q);
    let p = pool.subs1(b, var, Pool::ZERO);
    let p = pool.simplify(p);
    if sign_of(pool, p)? != Relation::Positive {
        return None;
    }
    match sign_of(pool, q)? {
        Relation::Negative => {
            let nq = pool.neg(q);
            let r = pool.div(nq, p);
            let k = pool.sqrt(r);
            let arg = pool.mul2(var, k);
            let a = pool.call(Func::Asin, &[arg]);
            let s = pool.sqrt(nq);
            Some(pool.div(a, s))
        }
        Relation::Positive => {
            let sq = pool.sqrt(q);
            let lin = pool.mul2(sq, var);
            let root = pool.sqrt(b);
            let sum = pool.add2(lin, root);
            let l = pool.call(Func::Log, &[sum]);
            Some(pool.div(l, sq))
        }
        Relation::Zero => None,
    }
}

/// `∫ dx/(p + q x^2)` when the signs of `p`, `q` are known.
fn inverse_quadratic(pool: &mut Pool, b: Id, var: Id) -> Option<Id> {
    let d1 = pool.diff(b, var);
    let d2 = pool.diff(d1, var);
    if !free_of(pool, d2, var) || pool.subs1(d1, var, Pool::ZERO) != Pool::ZERO {
        return None;
    }
    let half = pool.num(Number::ratio(1, 2));
    let q = pool.mul2(half, d2);
    let q = pool.simplify(q);
    let p = pool.subs1(b, var, Pool::ZERO);
    let p = pool.simplify(p);
    let (sp, sq) = (sign_of(pool, p)?, sign_of(pool, q)?);
    // Normalise to p > 0.
    let (p, q, flip) = match sp {
        Relation::Positive => (p, q, false),
        Relation::Negative => (pool.neg(p), pool.neg(q), true),
        Relation::Zero => return None,
    };
    let sq = if flip {
        match sq {
            Relation::Positive => Relation::Negative,
            Relation::Negative => Relation::Positive,
            Relation::Zero => Relation::Zero,
        }
    } else {
        sq
    };
    let r = match sq {
        Relation::Positive => {
            // atan(x sqrt(q/p)) / sqrt(p q)
            let qp = pool.div(q, p);
            let k = pool.sqrt(qp);
            let arg = pool.mul2(var, k);
            let at = pool.call(Func::Atan, &[arg]);
            let pq = pool.mul2(p, q);
            let s = pool.sqrt(pq);
            pool.div(at, s)
        }
        Relation::Negative => {
            // atanh(z)/sqrt(-p q), z = x sqrt(-q/p), atanh z = log((1+z)/(1-z))/2
            let nq = pool.neg(q);
            let qp = pool.div(nq, p);
            let k = pool.sqrt(qp);
            let z = pool.mul2(var, k);
            let one_p = pool.add2(Pool::ONE, z);
            let one_m = pool.sub(Pool::ONE, z);
            let ratio = pool.div(one_p, one_m);
            let ab = pool.call(Func::Abs, &[ratio]);
            let l = pool.call(Func::Log, &[ab]);
            let pq = pool.mul2(p, nq);
            let s = pool.sqrt(pq);
            let two = pool.int(2);
            let den = pool.mul2(two, s);
            pool.div(l, den)
        }
        Relation::Zero => return None,
    };
    Some(if flip { pool.neg(r) } else { r })
}

/// `H` of a substitution: the antiderivative of the outer function at `g`.
type Outer = Box<dyn Fn(&mut Pool, Id) -> Option<Id>>;

/// `∫ c g'(x) h(g(x)) dx = c H(g(x))` for a factor `h(g)` of the product.
fn substitution(pool: &mut Pool, e: Id, factors: &[Id], var: Id) -> Option<Id> {
    for &f in factors {
        let (inner, outer): (Id, Outer) = match pool.node(f).clone() {
            Node::Pow(b, x) if free_of(pool, x, var) => (
                b,
                Box::new(move |p: &mut Pool, g: Id| {
                    let one = p.diff(g, g);
                    Some(power_rule(p, g, x, one))
                }),
            ),
            Node::Call(func, args) => (
                args[0],
                Box::new(move |p: &mut Pool, g: Id| elementary(p, func, g)),
            ),
            _ => (
                f,
                Box::new(|p: &mut Pool, g: Id| {
                    let h = p.num(Number::ratio(1, 2));
                    let g2 = p.powi(g, 2);
                    Some(p.mul2(h, g2))
                }),
            ),
        };
        let dg = pool.diff(inner, var);
        if dg == Pool::ZERO {
            continue;
        }
        let denom = pool.mul2(f, dg);
        let ratio = pool.div(e, denom);
        let ratio = pool.simplify(ratio);
        if free_of(pool, ratio, var) {
            let h = outer(pool, inner)?;
            return Some(pool.mul2(ratio, h));
        }
    }
    None
}

/// Evaluates quantity `q` at `s` (all parameters must be numbers by now).
pub fn evaluate(pool: &mut Pool, q: &Quantity, s: f64) -> Result<Estimate, DsolveError> {
    let est = evaluate_raw(pool, q, s)?;
    let var = pool.to_text(q.variable);
    if !est.value.is_finite() {
        return Err(DsolveError::Invalid(format!(
            "{} is not defined at {var} = {s} (a singular integral, or a point the motion does not reach)",
            q.name
        )));
    }
    if est.error > 1e-6 * (1.0 + est.value.abs()) {
        return Err(DsolveError::Invalid(format!(
            "{} at {var} = {s}: quadrature did not converge (estimated error {:.1e}); the integral may diverge",
            q.name, est.error
        )));
    }
    if q.name == "v(x)^2" && est.value < 0.0 {
        return Err(DsolveError::Invalid(format!(
            "v(x)^2 = {} < 0 at x = {s}: the particle turns back before reaching it",
            est.value
        )));
    }
    Ok(est)
}

fn evaluate_raw(pool: &mut Pool, q: &Quantity, s: f64) -> Result<Estimate, DsolveError> {
    let need = |e: String| {
        DsolveError::Invalid(format!(
            "{}: {e}; give the parameters values with {}",
            q.name,
            crate::options::RunOption::Set
        ))
    };
    if let Some(c) = q.closed {
        let prog = Program::compile(pool, &[q.variable], &[c]).map_err(|e| need(e.to_string()))?;
        let mut ws = prog.workspace();
        let mut out = [0.0];
        prog.eval(&[s], &mut ws, &mut out);
        return Ok(Estimate {
            value: out[0],
            error: 0.0,
        });
    }
    let max_evals = 40_000;
    match q.numeric {
        Numeric::Closed(c) => {
            let prog =
                Program::compile(pool, &[q.variable], &[c]).map_err(|e| need(e.to_string()))?;
            let mut ws = prog.workspace();
            let mut out = [0.0];
            prog.eval(&[s], &mut ws, &mut out);
            Ok(Estimate {
                value: out[0],
                error: 0.0,
            })
        }
        Numeric::Integral {
            base,
            integrand,
            from,
        } => {
            let prog = Program::compile(pool, &[q.dummy, q.variable], &[integrand, base, from])
                .map_err(|e| need(e.to_string()))?;
            let mut ws = prog.workspace();
            let mut out = [0.0; 3];
            prog.eval(&[0.0, s], &mut ws, &mut out);
            let (b, a) = (out[1], out[2]);
            let mut f = |u: f64| {
                let mut o = [0.0; 3];
                prog.eval(&[u, s], &mut ws, &mut o);
                o[0]
            };
            let r = integrate(&mut f, a, s, 1e-10 * (1.0 + b.abs()), max_evals);
            Ok(Estimate {
                value: b + r.value,
                error: r.error,
            })
        }
        Numeric::TimeAlongPosition { v0, law, from } => {
            let prog = Program::compile(pool, &[q.dummy], &[law, v0, from])
                .map_err(|e| need(e.to_string()))?;
            let mut ws = prog.workspace();
            let mut out = [0.0; 3];
            prog.eval(&[0.0], &mut ws, &mut out);
            let (v0v, x0v) = (out[1], out[2]);
            let mut inner_err = 0.0f64;
            let mut law_at = |u: f64| {
                let mut o = [0.0; 3];
                prog.eval(&[u], &mut ws, &mut o);
                o[0]
            };
            let mut outer = |u: f64| {
                let r = integrate(&mut law_at, x0v, u, 1e-12, 2_000);
                inner_err = inner_err.max(r.error);
                let vsq = v0v * v0v + 2.0 * r.value;
                if vsq <= 0.0 {
                    f64::NAN
                } else {
                    1.0 / vsq.sqrt()
                }
            };
            let r = integrate(&mut outer, x0v, s, 1e-9, 2_000);
            if !r.value.is_finite() {
                return Err(DsolveError::Invalid(format!(
                    "t(x): the particle does not reach x = {s} (its speed vanishes before)"
                )));
            }
            Ok(Estimate {
                value: r.value,
                error: r.error + inner_err * (s - x0v).abs(),
            })
        }
    }
}
