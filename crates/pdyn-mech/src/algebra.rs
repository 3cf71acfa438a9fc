//! Systems of algebraic equations that are not linear: `pdyn solve` and the instants of
//! `--when` / `--at theta=...`.
//!
//! # The method
//! Equations mean `= 0`. Three rules, tried in order, each under a budget:
//! 1. **Linear**: the whole system is linear in the unknowns → exact elimination
//!    ([`Pool::solve_linear`]).
//! 2. **Substitution**: some equation is linear in some unknown `u`, `c(…) u + r(…) = 0`
//!    with `c` not identically zero → `u = −r/c` (valid where `c ≠ 0`), substituted into
//!    the others, which are solved recursively; back-substitution gives `u`. This is how the
//!    chapter solves its takeoff kinematics (`v = a t`, `d = a t²/2` for `a` and `t`).
//! 3. **One polynomial in one unknown**: `Σ cₖ uᵏ = 0`. Degree 2: the quadratic formula, both
//!    roots (one when the discriminant is identically zero). Any degree with numeric
//!    coefficients: every real root, numerically (companion roots polished by Newton), and the
//!    number of real roots certified by a Sturm sequence.
//!
//! Anything else is refused with [`AlgebraError::NoClosedForm`]: the system is solved
//! numerically elsewhere (`pdyn forces` has a multistart Newton).

use pdyn_expr::linsolve::LinearError;
use pdyn_expr::{Id, Node, Number, Pool};
use std::fmt;

/// Highest polynomial degree examined in one unknown.
const MAX_DEGREE: usize = 12;

/// Largest number of solutions returned (branches multiply under substitution).
const MAX_SOLUTIONS: usize = 64;

/// Why a system was not solved.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum AlgebraError {
    /// Fewer independent equations than unknowns.
    Underdetermined {
        /// The unknowns left free.
        free: Vec<String>,
    },
    /// The equations contradict each other.
    Inconsistent,
    /// Outside the three rules (see the module documentation).
    NoClosedForm {
        /// Why.
        reason: String,
    },
}

impl fmt::Display for AlgebraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AlgebraError::Underdetermined { free } => write!(
                f,
                "the equations do not determine {}: add an equation (a constraint?) involving them",
                free.join(", ")
            ),
            AlgebraError::Inconsistent => f.write_str("the equations contradict each other"),
            AlgebraError::NoClosedForm { reason } => write!(f, "{reason}"),
        }
    }
}

impl std::error::Error for AlgebraError {}

/// One solution: a value for each unknown, in the order given.
pub type Solution = Vec<Id>;

/// Solves `equations` (each `= 0`) for `unknowns`: every solution the rules find.
pub fn solve(
    pool: &mut Pool,
    equations: &[Id],
    unknowns: &[Id],
) -> Result<Vec<Solution>, AlgebraError> {
    let mut out = solve_rec(pool, equations, unknowns, 0)?;
    out.truncate(MAX_SOLUTIONS);
    Ok(out)
}

fn names(pool: &Pool, ids: &[Id]) -> Vec<String> {
    ids.iter().map(|&u| pool.to_text(u)).collect()
}

fn is_zero(pool: &mut Pool, e: Id) -> bool {
    e == Pool::ZERO || pool.provably_equal(e, Pool::ZERO)
}

/// Numerator of `e` over a common denominator (an equation `= 0` keeps its roots, except
/// where the denominator vanishes).
fn numerator(pool: &mut Pool, e: Id) -> Id {
    let s = pool.simplify(e);
    let negative_power = |pool: &Pool, f: Id| match pool.node(f) {
        Node::Pow(_, x) => pool.as_num(*x).is_some_and(|n| n.is_negative()),
        _ => false,
    };
    let n = match pool.node(s).clone() {
        Node::Mul(fs) => {
            let kept: Vec<Id> = fs
                .iter()
                .copied()
                .filter(|&f| !negative_power(pool, f))
                .collect();
            pool.mul(&kept)
        }
        _ if negative_power(pool, s) => Pool::ONE,
        _ => s,
    };
    pool.expand(n)
}

fn solve_rec(
    pool: &mut Pool,
    equations: &[Id],
    unknowns: &[Id],
    depth: usize,
) -> Result<Vec<Solution>, AlgebraError> {
    let equations: Vec<Id> = equations
        .iter()
        .map(|&e| numerator(pool, e))
        .filter(|&e| e != Pool::ZERO)
        .collect();
    if unknowns.is_empty() {
        return if equations.iter().all(|&e| is_zero(pool, e)) {
            Ok(vec![Vec::new()])
        } else {
            Err(AlgebraError::Inconsistent)
        };
    }
    if equations.is_empty() || depth > 8 {
        return Err(AlgebraError::Underdetermined {
            free: names(pool, unknowns),
        });
    }
    // 1. Linear.
    match pool.linear_system(&equations, unknowns) {
        Ok(sys) => {
            return match pool.solve_linear(&sys) {
                Ok(sol) => Ok(vec![sol.into_iter().map(|x| pool.simplify(x)).collect()]),
                Err(LinearError::Underdetermined { free }) => Err(AlgebraError::Underdetermined {
                    free: names(pool, &free),
                }),
                Err(LinearError::Inconsistent { .. }) => Err(AlgebraError::Inconsistent),
                Err(e) => Err(AlgebraError::NoClosedForm {
                    reason: e.to_string(),
                }),
            }
        }
        Err(LinearError::NotLinear { .. }) => {}
        Err(e) => {
            return Err(AlgebraError::NoClosedForm {
                reason: e.to_string(),
            })
        }
    }
    // 2. Substitution: an equation linear in one unknown; prefer a coefficient free of the
    //    other unknowns (no case split hidden in `c ≠ 0`), then the shortest.
    let mut best: Option<(bool, usize, usize, usize)> = None;
    for (i, &e) in equations.iter().enumerate() {
        for (j, &u) in unknowns.iter().enumerate() {
            if !pool.contains(e, u) {
                continue;
            }
            let c = pool.diff(e, u);
            if pool.contains(c, u) || is_zero(pool, c) {
                continue;
            }
            let free_coef = !unknowns.iter().any(|&w| pool.contains(c, w));
            let size = pool.tree_size(e, 10_000);
            let key = (!free_coef, size, i, j);
            if best.is_none_or(|b| key < b) {
                best = Some(key);
            }
        }
    }
    if let Some((_, _, i, j)) = best {
        let (e, u) = (equations[i], unknowns[j]);
        let c = pool.diff(e, u);
        let r = pool.subs1(e, u, Pool::ZERO);
        let nr = pool.neg(r);
        let value = pool.div(nr, c);
        let value = pool.simplify(value);
        let rest: Vec<Id> = equations
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != i)
            .map(|(_, &x)| pool.subs1(x, u, value))
            .collect();
        let others: Vec<Id> = unknowns.iter().copied().filter(|&w| w != u).collect();
        let subs = solve_rec(pool, &rest, &others, depth + 1)?;
        let mut out = Vec::new();
        for s in subs {
            let mut v = value;
            for (&w, &x) in others.iter().zip(&s) {
                v = pool.subs1(v, w, x);
            }
            let v = pool.simplify(v);
            let mut full = Vec::with_capacity(unknowns.len());
            let mut it = s.into_iter();
            for &w in unknowns {
                full.push(if w == u { v } else { it.next().unwrap_or(v) });
            }
            out.push(full);
        }
        return Ok(out);
    }
    // 3. One polynomial in one unknown.
    if let ([e], [u]) = (equations.as_slice(), unknowns) {
        return polynomial_roots(pool, *e, *u).map(|rs| rs.into_iter().map(|r| vec![r]).collect());
    }
    Err(AlgebraError::NoClosedForm {
        reason: format!(
            "no equation is linear in one of {} and the system is not one polynomial in one unknown",
            names(pool, unknowns).join(", ")
        ),
    })
}

/// Coefficients `c₀ … c_n` of `e` as a polynomial in `u` (`None` when it is not one of degree
/// at most [`MAX_DEGREE`]).
fn coefficients(pool: &mut Pool, e: Id, u: Id) -> Option<Vec<Id>> {
    let mut coeffs = Vec::new();
    let mut d = e;
    let mut factorial = 1i64;
    for k in 0..=MAX_DEGREE + 1 {
        if k > 0 {
            factorial = factorial.checked_mul(k as i64)?;
        }
        let at0 = pool.subs1(d, u, Pool::ZERO);
        let f = pool.num(Number::int(factorial));
        let c = pool.div(at0, f);
        let c = pool.simplify(c);
        if !pool.contains(d, u) {
            coeffs.push(c);
            while coeffs.len() > 1 && coeffs.last().is_some_and(|&x| x == Pool::ZERO) {
                coeffs.pop();
            }
            return Some(coeffs);
        }
        if k == MAX_DEGREE + 1 {
            return None;
        }
        coeffs.push(c);
        d = pool.diff(d, u);
        d = pool.expand(d);
    }
    None
}

/// Roots of one polynomial equation in `u`.
fn polynomial_roots(pool: &mut Pool, e: Id, u: Id) -> Result<Vec<Id>, AlgebraError> {
    let Some(c) = coefficients(pool, e, u) else {
        return Err(AlgebraError::NoClosedForm {
            reason: format!(
                "the equation is not a polynomial in {} of degree at most {MAX_DEGREE}",
                pool.to_text(u)
            ),
        });
    };
    let numeric: Option<Vec<f64>> = c.iter().map(|&x| pool.eval_const(x).ok()).collect();
    if c.len() == 3 {
        // c2 u² + c1 u + c0 = 0.
        let (c0, c1, c2) = (c[0], c[1], c[2]);
        let b2 = pool.mul2(c1, c1);
        let four = pool.num(Number::int(4));
        let ac = pool.mul(&[four, c2, c0]);
        let disc = pool.sub(b2, ac);
        let disc = pool.simplify(disc);
        if let Some(v) = pool.eval_const(disc).ok().filter(|v| v.is_finite()) {
            if v < 0.0 {
                return Ok(Vec::new());
            }
        }
        let two = pool.num(Number::int(2));
        let den = pool.mul2(two, c2);
        let mb = pool.neg(c1);
        if is_zero(pool, disc) {
            let r = pool.div(mb, den);
            return Ok(vec![pool.simplify(r)]);
        }
        let sq = pool.sqrt(disc);
        let mut roots = Vec::new();
        for sign in [-1, 1] {
            let s = pool.num(Number::int(sign));
            let t = pool.mul2(s, sq);
            let n = pool.add2(mb, t);
            let r = pool.div(n, den);
            roots.push(pool.simplify(r));
        }
        return Ok(roots);
    }
    match numeric {
        Some(coeffs) if coeffs.iter().all(|x| x.is_finite()) => {
            let roots = real_roots(&coeffs);
            // A root is only reported when the polynomial vanishes there relative to the size
            // of its terms (floating point fails on extreme coefficients: refuse, never guess).
            let trustworthy = roots.iter().all(|&r| {
                let size: f64 = coeffs
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (c * r.powi(k as i32)).abs())
                    .sum();
                size.is_finite() && eval(&coeffs, r).abs() <= 1e-9 * size.max(f64::MIN_POSITIVE)
            });
            if !trustworthy {
                return Err(AlgebraError::NoClosedForm {
                    reason: format!(
                        "the real roots of this polynomial in {} cannot be found reliably in floating point (coefficients of very different sizes); rescale the unknown",
                        pool.to_text(u)
                    ),
                });
            }
            Ok(roots
                .into_iter()
                .map(|r| pool.num(Number::Float(r)))
                .collect())
        }
        _ => Err(AlgebraError::NoClosedForm {
            reason: format!(
                "a polynomial of degree {} in {} with symbolic coefficients has no formula here; give the parameters values",
                c.len() - 1,
                pool.to_text(u)
            ),
        }),
    }
}

/// Every real root of `Σ cₖ xᵏ` (ascending coefficients), sorted; their number is certified
/// by a Sturm sequence (a debug assertion checks the count).
pub fn real_roots(coeffs: &[f64]) -> Vec<f64> {
    let mut c = coeffs.to_vec();
    while c.len() > 1 && c.last() == Some(&0.0) {
        c.pop();
    }
    if c.len() <= 1 {
        return Vec::new();
    }
    // Cauchy bound on the roots' magnitude.
    let lead = *c.last().unwrap_or(&1.0);
    let bound = 1.0
        + c[..c.len() - 1]
            .iter()
            .map(|x| (x / lead).abs())
            .fold(0.0, f64::max);
    let count = sturm_count(&c, -bound, bound);
    // Isolate by bisection on the Sturm count, then refine each interval by bisection on sign.
    let mut roots = Vec::new();
    isolate(&c, -bound, bound, count, &mut roots, 0);
    roots.sort_by(f64::total_cmp);
    roots
}

fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * x + k)
}

fn derivative(c: &[f64]) -> Vec<f64> {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(k, &v)| k as f64 * v)
        .collect()
}

/// Remainder of `a / b` (ascending coefficients).
fn remainder(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut r = a.to_vec();
    let db = b.len() - 1;
    let lb = b[db];
    while r.len() > db && r.len() > 1 {
        let q = r[r.len() - 1] / lb;
        let shift = r.len() - 1 - db;
        for (k, &bk) in b.iter().enumerate() {
            r[shift + k] -= q * bk;
        }
        r.pop();
    }
    let scale = a.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
    while r.len() > 1 && r.last().is_some_and(|x| x.abs() <= 1e-12 * scale) {
        r.pop();
    }
    r
}

/// Number of distinct real roots in `(lo, hi]` by Sturm's theorem.
fn sturm_count(c: &[f64], lo: f64, hi: f64) -> usize {
    let mut seq = vec![c.to_vec(), derivative(c)];
    while seq.last().is_some_and(|p| p.len() > 1) {
        let n = seq.len();
        let r: Vec<f64> = remainder(&seq[n - 2], &seq[n - 1])
            .iter()
            .map(|x| -x)
            .collect();
        if r.iter().all(|&x| x == 0.0) {
            break;
        }
        seq.push(r);
    }
    let changes = |x: f64| {
        let signs: Vec<f64> = seq
            .iter()
            .map(|p| eval(p, x))
            .filter(|v| *v != 0.0)
            .collect();
        signs.windows(2).filter(|w| w[0] * w[1] < 0.0).count()
    };
    changes(lo).saturating_sub(changes(hi))
}

fn isolate(c: &[f64], lo: f64, hi: f64, count: usize, out: &mut Vec<f64>, depth: usize) {
    if count == 0 {
        return;
    }
    if count == 1 || depth > 200 || hi - lo <= 1e-14 * (1.0 + lo.abs().max(hi.abs())) {
        out.push(refine(c, lo, hi));
        return;
    }
    let mid = 0.5 * (lo + hi);
    let left = sturm_count(c, lo, mid);
    isolate(c, lo, mid, left, out, depth + 1);
    isolate(c, mid, hi, count.saturating_sub(left), out, depth + 1);
}

/// The root in `(lo, hi]`: bisection where the sign changes, else the smallest |p| (a double root).
fn refine(c: &[f64], mut lo: f64, mut hi: f64) -> f64 {
    let (mut flo, fhi) = (eval(c, lo), eval(c, hi));
    if flo * fhi > 0.0 {
        // Even multiplicity: minimise |p| by golden-section search.
        let d = derivative(c);
        return refine_derivative(&d, lo, hi).unwrap_or(0.5 * (lo + hi));
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let fm = eval(c, mid);
        if fm == 0.0 {
            return mid;
        }
        if (fm < 0.0) == (flo < 0.0) {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-16 * (1.0 + mid.abs()) {
            break;
        }
    }
    0.5 * (lo + hi)
}

fn refine_derivative(d: &[f64], lo: f64, hi: f64) -> Option<f64> {
    let (fl, fh) = (eval(d, lo), eval(d, hi));
    (fl * fh <= 0.0).then(|| refine(d, lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup(positive: &[&str]) -> Pool {
        let mut p = Pool::new();
        for s in positive {
            p.symbol(s, true);
        }
        p
    }

    fn eqs(p: &mut Pool, src: &[&str]) -> Vec<Id> {
        src.iter()
            .map(|s| {
                let (l, r) = s.split_once('=').unwrap();
                let (l, r) = (p.parse_scalar(l).unwrap(), p.parse_scalar(r).unwrap());
                p.sub(l, r)
            })
            .collect()
    }

    /// The chapter's takeoff kinematics: v_t = a t and d = a t²/2, for a and t.
    #[test]
    fn takeoff_kinematics_by_substitution() {
        let mut p = setup(&["v_t", "d"]);
        let e = eqs(&mut p, &["v_t = a*t", "d = a*t^2/2"]);
        let (a, t) = (p.var("a"), p.time());
        let sols = solve(&mut p, &e, &[a, t]).unwrap();
        assert_eq!(sols.len(), 1);
        assert_eq!(p.to_text(sols[0][0]), "v_t^2/(2*d)");
        assert_eq!(p.to_text(sols[0][1]), "2*d/v_t");
    }

    #[test]
    fn quadratic_with_symbolic_coefficients_gives_both_roots() {
        // A ball thrown up at v0 from h: h + v0 t - g t²/2 = 0.
        let mut p = setup(&["h", "v0", "g"]);
        let e = eqs(&mut p, &["h + v0*T - g*T^2/2 = 0"]);
        let t = p.var("T");
        let sols = solve(&mut p, &e, &[t]).unwrap();
        assert_eq!(sols.len(), 2);
        // Check numerically: h = 1, v0 = 3, g = 9.81.
        let vals = [("h", 1.0), ("v0", 3.0), ("g", 9.81)];
        let mut roots: Vec<f64> = sols
            .iter()
            .map(|s| {
                let mut x = s[0];
                for (n, v) in vals {
                    let (sym, num) = (p.var(n), p.num(Number::Float(v)));
                    x = p.subs1(x, sym, num);
                }
                p.eval_const(x).unwrap()
            })
            .collect();
        roots.sort_by(f64::total_cmp);
        let disc = (9.0f64 + 2.0 * 9.81).sqrt();
        assert!((roots[0] - (3.0 - disc) / 9.81).abs() < 1e-12, "{roots:?}");
        assert!((roots[1] - (3.0 + disc) / 9.81).abs() < 1e-12, "{roots:?}");
    }

    #[test]
    fn real_roots_of_numeric_polynomials_are_all_found() {
        // (x - 1)(x + 2)(x - 3)(x^2 + 1) = x^5 - 2x^4 - 4x^3 + 4x^2 - 5x + 6
        let r = real_roots(&[6.0, -5.0, 4.0, -4.0, -2.0, 1.0]);
        assert_eq!(r.len(), 3, "{r:?}");
        for (got, want) in r.iter().zip([-2.0, 1.0, 3.0]) {
            assert!((got - want).abs() < 1e-12, "{r:?}");
        }
        assert!(real_roots(&[1.0, 0.0, 1.0]).is_empty());
        // A double root: (x - 2)^2.
        let d = real_roots(&[4.0, -4.0, 1.0]);
        assert_eq!(d.len(), 1);
        assert!((d[0] - 2.0).abs() < 1e-7, "{d:?}");
    }

    #[test]
    fn quartic_in_one_unknown_with_numbers() {
        let mut p = setup(&[]);
        let e = eqs(&mut p, &["x^4 - 5*x^2 + 4 = 0"]);
        let x = p.var("x");
        let sols = solve(&mut p, &e, &[x]).unwrap();
        let mut v: Vec<f64> = sols.iter().map(|s| p.eval_const(s[0]).unwrap()).collect();
        v.sort_by(f64::total_cmp);
        for (got, want) in v.iter().zip([-2.0, -1.0, 1.0, 2.0]) {
            assert!((got - want).abs() < 1e-12, "{v:?}");
        }
    }

    #[test]
    fn extreme_coefficients_are_refused_not_guessed() {
        let mut p = setup(&[]);
        let e = eqs(&mut p, &["x^3 = 1e308*x"]);
        let x = p.var("x");
        match solve(&mut p, &e, &[x]) {
            Err(AlgebraError::NoClosedForm { .. }) => {}
            Ok(sols) => {
                // If solved, every root must be right.
                for s in sols {
                    let v = p.eval_const(s[0]).unwrap();
                    assert!(v == 0.0 || (v.abs() / 1e154 - 1.0).abs() < 1e-6, "{v}");
                }
            }
            Err(other) => panic!("{other}"),
        }
    }

    #[test]
    fn contradictions_and_missing_equations_are_named() {
        let mut p = setup(&[]);
        let e = eqs(&mut p, &["x*y = 1"]);
        let (x, y) = (p.var("x"), p.var("y"));
        assert!(matches!(
            solve(&mut p, &e, &[x, y]),
            Err(AlgebraError::Underdetermined { .. })
        ));
    }
}
