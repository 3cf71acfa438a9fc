//! The exact solver for one coordinate: roots by the quadratic formula (after exact rational
//! roots), particular solutions by undetermined coefficients, constants from the initial
//! conditions. See the module documentation of [`super`] for the mathematics.

use super::linear::{forcing_groups, ForcingGroup, LinearOde};
use super::roots::rational_roots;
use super::{
    no_closed_form, Case, ClosedForm, Condition, DsolveError, InitialCondition, Method, Relation,
};
use pdyn_expr::{Func, Id, Node, Number, Pool};

/// Part of the homogeneous solution contributed by a root (or a pair of roots).
#[derive(Clone, Copy, Debug)]
enum Mode {
    /// `t^j e^{rate t}`, `j < mult`.
    Exp { rate: Id, mult: usize },
    /// `e^{rate t} cosh(freq t)`, `e^{rate t} sinh(freq t)`: the real pair `rate ± freq`.
    Hyperbolic { rate: Id, freq: Id },
    /// `t^j e^{rate t} cos(freq t)`, `t^j e^{rate t} sin(freq t)`: the pair `rate ± i freq`.
    Oscillatory { rate: Id, freq: Id, mult: usize },
}

/// Exact solution of a single equation, `Ok(None)` when its characteristic polynomial needs
/// numeric roots (degree ≥ 3 without enough rational roots).
pub(crate) fn solve_scalar(
    pool: &mut Pool,
    ode: &LinearOde,
    ics: &[InitialCondition],
    t0: Id,
    first_constant: usize,
) -> Result<Option<ClosedForm>, DsolveError> {
    let a = &ode.coeffs[0][0];
    let n = ode.orders[0];
    if n == 0 {
        return Err(DsolveError::Invalid(format!(
            "the equation has no derivative of `{}`: it is algebraic, solve it with `pdyn solve`",
            pool.name(ode.coords[0])
        )));
    }
    let lead = a[n];
    // Monic characteristic polynomial.
    let c: Vec<Id> = a
        .iter()
        .map(|&ak| {
            let q = pool.div(ak, lead);
            pool.simplify(q)
        })
        .collect();
    let forcing = pool.div(ode.forcing[0], lead);
    let forcing = pool.expand(forcing);
    let groups = forcing_groups(pool, &[forcing])?;

    let mut cases_modes: Vec<(Option<Condition>, Vec<Mode>)> = Vec::new();
    let exact: Option<Vec<pdyn_expr::Rational>> = c
        .iter()
        .map(|&x| pool.as_num(x).and_then(|n| n.as_rational().cloned()))
        .collect();
    let mut base_modes = Vec::new();
    let rest: Vec<Id> = if let Some(rc) = exact {
        let (roots, rest) = rational_roots(&rc);
        for (r, m) in roots {
            let rate = pool.num(Number::Rat(r));
            base_modes.push(Mode::Exp { rate, mult: m });
        }
        rest.into_iter().map(|r| pool.num(Number::Rat(r))).collect()
    } else {
        // Remove the root λ = 0 (equations missing the lowest derivatives).
        let mut k = 0;
        while k < c.len() - 1 && c[k] == Pool::ZERO {
            k += 1;
        }
        if k > 0 {
            base_modes.push(Mode::Exp {
                rate: Pool::ZERO,
                mult: k,
            });
        }
        c[k..].to_vec()
    };
    match rest.len() {
        0 | 1 => cases_modes.push((None, base_modes)),
        2 => {
            // Monic up to a constant: rest[1] λ + rest[0].
            let q = pool.div(rest[0], rest[1]);
            let q = pool.neg(q);
            let rate = pool.simplify(q);
            let mut m = base_modes;
            push_exp(&mut m, rate, 1);
            cases_modes.push((None, m));
        }
        3 => {
            let (c1, c0) = {
                let c1 = pool.div(rest[1], rest[2]);
                let c0 = pool.div(rest[0], rest[2]);
                (pool.simplify(c1), pool.simplify(c0))
            };
            for (cond, modes) in quadratic_modes(pool, c1, c0) {
                let mut m = base_modes.clone();
                m.extend(modes);
                cases_modes.push((cond, m));
            }
        }
        5 if rest[1] == Pool::ZERO
            && rest[3] == Pool::ZERO
            && !c.iter().all(|&x| pool.as_num(x).is_some()) =>
        {
            // Biquadratic (undamped two-degree-of-freedom systems): a quadratic in λ².
            let b = pool.div(rest[2], rest[4]);
            let b = pool.simplify(b);
            let c0 = pool.div(rest[0], rest[4]);
            let c0 = pool.simplify(c0);
            let Some(cases) = biquadratic_modes(pool, b, c0) else {
                let params = symbols_of(pool, &c);
                return Err(no_closed_form(format!(
                    "the characteristic polynomial λ^4 + ({})λ^2 + {} has coefficients of unknown sign (in {params}); give numeric values",
                    pool.to_text(b),
                    pool.to_text(c0)
                )));
            };
            for (cond, modes) in cases {
                let mut m = base_modes.clone();
                m.extend(modes);
                cases_modes.push((cond, m));
            }
        }
        _ => {
            if c.iter().all(|&x| pool.as_num(x).is_some()) {
                return Ok(None);
            }
            // Symbolic coefficients: the numeric solver would ask for values, but say why here.
            let params = symbols_of(pool, &c);
            return Err(no_closed_form(format!(
                "the characteristic polynomial has degree {} with symbolic coefficients ({}) and does not factor by this method; give numeric values",
                rest.len() - 1,
                params
            )));
        }
    }

    let t = pool.time();
    let mut cases = Vec::new();
    for (cond, modes) in cases_modes {
        // Under an exhausted simplification budget the result would be discarded.
        if pool.simplify_budget_exhausted() {
            return Ok(None);
        }
        let mut particular = Pool::ZERO;
        for g in &groups {
            let m = resonance(pool, &modes, g.rate, g.freq);
            let yp = particular_solution(pool, &c, g, m)?;
            particular = pool.add2(particular, yp);
        }
        let basis = basis_functions(pool, &modes, t);
        let roots = describe_roots(pool, &modes);
        let (solution, constants) =
            fit_constants(pool, &basis, particular, ics, ode, t0, first_constant)?;
        // Critical case at a threshold `s = v`: write the solution with `v` for `s`.
        let solution = match cond {
            Some(Condition {
                expr,
                relation: Relation::Zero,
            }) => match pool.node(expr).clone() {
                Node::Add(ts) if ts.len() == 2 && matches!(pool.node(ts[1]), Node::Sym(_)) => {
                    let v = pool.neg(ts[0]);
                    let y = pool.subs1(solution, ts[1], v);
                    if const_value(pool, y).is_some_and(|x| !x.is_finite()) {
                        solution
                    } else {
                        collect_like(pool, y)
                    }
                }
                _ => solution,
            },
            _ => solution,
        };
        cases.push(Case {
            condition: cond,
            solution: vec![solution],
            roots,
            constants,
        });
    }
    Ok(Some(ClosedForm {
        coords: ode.coords.clone(),
        cases,
        method: Method::Exact,
        residual: None,
    }))
}

fn symbols_of(pool: &Pool, es: &[Id]) -> String {
    let mut names: Vec<String> = Vec::new();
    for n in pool.topo_order(es) {
        if let Node::Sym(s) = pool.node(n) {
            let name = pool.name(*s).to_string();
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    names.join(", ")
}

fn push_exp(modes: &mut Vec<Mode>, rate: Id, mult: usize) {
    for m in modes.iter_mut() {
        if let Mode::Exp { rate: r, mult: k } = m {
            if *r == rate {
                *k += mult;
                return;
            }
        }
    }
    modes.push(Mode::Exp { rate, mult });
}

/// The sign of `e`, when it can be decided.
pub(crate) fn sign_of(pool: &mut Pool, e: Id) -> Option<Relation> {
    if e == Pool::ZERO {
        return Some(Relation::Zero);
    }
    if let Some(n) = pool.as_num(e) {
        return Some(if n.is_positive() {
            Relation::Positive
        } else if n.is_negative() {
            Relation::Negative
        } else {
            Relation::Zero
        });
    }
    if let Some(v) = const_value(pool, e) {
        if v.abs() > 1e-12 * (1.0 + v.abs()) {
            return Some(if v > 0.0 {
                Relation::Positive
            } else {
                Relation::Negative
            });
        }
    }
    for form in [e, pool.simplify(e), pool.expand(e)] {
        if pool.is_positive(form) {
            return Some(Relation::Positive);
        }
        let ne = pool.neg(form);
        if pool.is_positive(ne) {
            return Some(Relation::Negative);
        }
    }
    None
}

/// Re-simplifies a sum term by term (keeps the collected form of [`fit_constants`]).
fn collect_like(pool: &mut Pool, y: Id) -> Id {
    match pool.node(y).clone() {
        Node::Add(ts) => {
            let parts: Vec<Id> = ts.iter().map(|&t| pool.simplify(t)).collect();
            pool.add(&parts)
        }
        _ => pool.simplify(y),
    }
}

/// Numeric value of an expression free of symbols (π, √2...).
pub(crate) fn const_value(pool: &mut Pool, e: Id) -> Option<f64> {
    pool.eval_const(e).ok().filter(|v| v.is_finite())
}

/// Drops positive factors from a product, so that `4 wn^2 (zeta^2 - 1)` reads `zeta^2 - 1`.
fn essential_sign_factor(pool: &mut Pool, e: Id) -> Id {
    let s = pool.simplify(e);
    match pool.node(s).clone() {
        Node::Mul(fs) => {
            let mut neg = false;
            let mut keep = Vec::new();
            for f in fs.iter() {
                if let Some(n) = pool.as_num(*f) {
                    neg ^= n.is_negative();
                } else if !pool.is_positive(*f) {
                    keep.push(*f);
                }
            }
            let k = pool.mul(&keep);
            if neg {
                pool.neg(k)
            } else {
                k
            }
        }
        Node::Add(_) => {
            // `wn^2 zeta^2 - wn^2` becomes `zeta^2 - 1`.
            let (cur, _) = shed_positive_factors(pool, s);
            match pool.add_content(cur) {
                Some((c, prim)) if c.is_positive() => prim,
                Some((_, prim)) => pool.neg(prim),
                None => cur,
            }
        }
        _ => s,
    }
}

/// Modes of `λ² + c1 λ + c0`, one set per sign of the discriminant when it is unknown.
fn quadratic_modes(pool: &mut Pool, c1: Id, c0: Id) -> Vec<(Option<Condition>, Vec<Mode>)> {
    let half = pool.num(Number::ratio(-1, 2));
    let rate = pool.mul2(half, c1);
    let rate = pool.simplify(rate);
    let c1sq = pool.powi(c1, 2);
    let quarter = pool.num(Number::ratio(1, 4));
    let q = pool.mul2(quarter, c1sq);
    let disc = pool.sub(q, c0);
    let disc = pool.expand(disc);
    let disc = pool.simplify(disc);
    let modes_for = |pool: &mut Pool, rel: Relation| -> Vec<Mode> {
        match rel {
            Relation::Zero => vec![Mode::Exp { rate, mult: 2 }],
            Relation::Positive => {
                // A perfect square gives two rational exponentials.
                if let Some(r) = pool
                    .as_num(disc)
                    .and_then(|n| n.as_rational().and_then(|r| r.exact_root(2)))
                {
                    let rn = pool.num(Number::Rat(r));
                    let r1 = pool.add2(rate, rn);
                    let r2 = pool.sub(rate, rn);
                    return vec![
                        Mode::Exp { rate: r1, mult: 1 },
                        Mode::Exp { rate: r2, mult: 1 },
                    ];
                }
                let freq = nice_sqrt(pool, disc);
                vec![Mode::Hyperbolic { rate, freq }]
            }
            Relation::Negative => {
                let nd = pool.neg(disc);
                let freq = nice_sqrt(pool, nd);
                vec![Mode::Oscillatory {
                    rate,
                    freq,
                    mult: 1,
                }]
            }
        }
    };
    match sign_of(pool, disc) {
        Some(rel) => vec![(None, modes_for(pool, rel))],
        None => {
            let key = essential_sign_factor(pool, disc);
            // `zeta^2 - 1` with zeta > 0 has the sign of `zeta - 1`: state that, and
            // substitute zeta = 1 in the critical case.
            let threshold = threshold(pool, key);
            let expr = match threshold {
                Some((s, v)) => pool.sub(s, v),
                None => key,
            };
            [Relation::Negative, Relation::Zero, Relation::Positive]
                .into_iter()
                .map(|rel| {
                    let modes = match (rel, threshold) {
                        (Relation::Zero, Some((s, v))) => {
                            let r = pool.subs1(rate, s, v);
                            let r = pool.simplify(r);
                            vec![Mode::Exp { rate: r, mult: 2 }]
                        }
                        _ => modes_for(pool, rel),
                    };
                    (
                        Some(Condition {
                            expr,
                            relation: rel,
                        }),
                        modes,
                    )
                })
                .collect()
        }
    }
}

/// `(s, v)` when `key = c1 s^n + c0` with `s` a positive symbol, `c1 > 0` and `v = (-c0/c1)^(1/n)`
/// positive: then `key` has the sign of `s - v`.
fn threshold(pool: &mut Pool, key: Id) -> Option<(Id, Id)> {
    let Node::Add(ts) = pool.node(key).clone() else {
        return None;
    };
    let [a, b] = ts[..] else { return None };
    let c0 = pool.as_num(a)?;
    let (c1, rest) = pool.split_coeff(b);
    let (base, n) = match pool.node(rest).clone() {
        Node::Sym(_) => (rest, Number::ONE),
        Node::Pow(base, e) if matches!(pool.node(base), Node::Sym(_)) => (base, pool.as_num(e)?),
        _ => return None,
    };
    if !pool.is_positive(base) || !c1.is_positive() || !n.is_positive() {
        return None;
    }
    let ratio = c0.neg().mul(&c1.recip());
    if !ratio.is_positive() {
        return None;
    }
    let r = pool.num(ratio);
    let e = pool.num(n.recip());
    let v = pool.pow(r, e);
    Some((base, pool.simplify(v)))
}

/// Modes of `λ⁴ + b λ² + c` for `b, c > 0` (`None` when their signs are unknown). With
/// `Δ = b² - 4c`: `Δ > 0` gives two frequencies `ω = sqrt((b ∓ √Δ)/2)`; `Δ = 0` a double one
/// `sqrt(b/2)`; `Δ < 0` the roots `±α ± iβ`, `α = sqrt((√c - b/2)/2)`, `β = sqrt((√c + b/2)/2)`.
fn biquadratic_modes(pool: &mut Pool, b: Id, c: Id) -> Option<Vec<(Option<Condition>, Vec<Mode>)>> {
    if sign_of(pool, b)? != Relation::Positive || sign_of(pool, c)? != Relation::Positive {
        return None;
    }
    let b2 = pool.powi(b, 2);
    let four = pool.int(4);
    let c4 = pool.mul2(four, c);
    let disc = pool.sub(b2, c4);
    let disc = pool.expand(disc);
    let disc = pool.simplify(disc);
    let half = pool.num(Number::ratio(1, 2));
    let modes_for = |pool: &mut Pool, rel: Relation| -> Vec<Mode> {
        match rel {
            Relation::Positive => {
                let r = nice_sqrt(pool, disc);
                let mut out = Vec::new();
                for sign in [-1, 1] {
                    let sr = if sign < 0 { pool.neg(r) } else { r };
                    let s = pool.add2(b, sr);
                    let s = pool.mul2(half, s);
                    let f = pool.sqrt(s);
                    out.push(Mode::Oscillatory {
                        rate: Pool::ZERO,
                        freq: pool.simplify(f),
                        mult: 1,
                    });
                }
                out
            }
            Relation::Zero => {
                let s = pool.mul2(half, b);
                let f = pool.sqrt(s);
                vec![Mode::Oscillatory {
                    rate: Pool::ZERO,
                    freq: pool.simplify(f),
                    mult: 2,
                }]
            }
            Relation::Negative => {
                let rc = pool.sqrt(c);
                let hb = pool.mul2(half, b);
                let a_in = pool.sub(rc, hb);
                let a_in = pool.mul2(half, a_in);
                let alpha = pool.sqrt(a_in);
                let alpha = pool.simplify(alpha);
                let b_in = pool.add2(rc, hb);
                let b_in = pool.mul2(half, b_in);
                let beta = pool.sqrt(b_in);
                let beta = pool.simplify(beta);
                let nalpha = pool.neg(alpha);
                vec![
                    Mode::Oscillatory {
                        rate: alpha,
                        freq: beta,
                        mult: 1,
                    },
                    Mode::Oscillatory {
                        rate: nalpha,
                        freq: beta,
                        mult: 1,
                    },
                ]
            }
        }
    };
    Some(match sign_of(pool, disc) {
        Some(rel) => vec![(None, modes_for(pool, rel))],
        None => {
            let key = essential_sign_factor(pool, disc);
            [Relation::Positive, Relation::Zero, Relation::Negative]
                .into_iter()
                .map(|rel| {
                    (
                        Some(Condition {
                            expr: key,
                            relation: rel,
                        }),
                        modes_for(pool, rel),
                    )
                })
                .collect()
        }
    })
}

/// Multiplicity of `rate + i freq` among the characteristic roots.
fn resonance(pool: &mut Pool, modes: &[Mode], rate: Id, freq: Id) -> usize {
    let mut m = 0;
    for &mode in modes {
        match mode {
            Mode::Exp { rate: r, mult } if freq == Pool::ZERO && pool.provably_equal(r, rate) => {
                m += mult;
            }
            Mode::Hyperbolic { rate: r, freq: f } if freq == Pool::ZERO => {
                let r1 = pool.add2(r, f);
                let r2 = pool.sub(r, f);
                if pool.provably_equal(r1, rate) || pool.provably_equal(r2, rate) {
                    m += 1;
                }
            }
            Mode::Oscillatory {
                rate: r,
                freq: f,
                mult,
            } if freq != Pool::ZERO
                && pool.provably_equal(r, rate)
                && pool.provably_equal(f, freq) =>
            {
                m += mult;
            }
            _ => {}
        }
    }
    m
}

fn exp_of(pool: &mut Pool, rate: Id, t: Id) -> Id {
    let u = pool.mul2(rate, t);
    pool.call(Func::Exp, &[u])
}

fn basis_functions(pool: &mut Pool, modes: &[Mode], t: Id) -> Vec<Id> {
    let mut out = Vec::new();
    for &mode in modes {
        match mode {
            Mode::Exp { rate, mult } => {
                let e = exp_of(pool, rate, t);
                for j in 0..mult {
                    let tj = pool.powi(t, j as i64);
                    out.push(pool.mul2(tj, e));
                }
            }
            Mode::Hyperbolic { rate, freq } => {
                let e = exp_of(pool, rate, t);
                let u = pool.mul2(freq, t);
                for f in [Func::Cosh, Func::Sinh] {
                    let h = pool.call(f, &[u]);
                    out.push(pool.mul2(e, h));
                }
            }
            Mode::Oscillatory { rate, freq, mult } => {
                let e = exp_of(pool, rate, t);
                let u = pool.mul2(freq, t);
                for j in 0..mult {
                    let tj = pool.powi(t, j as i64);
                    for f in [Func::Cos, Func::Sin] {
                        let h = pool.call(f, &[u]);
                        out.push(pool.mul(&[tj, e, h]));
                    }
                }
            }
        }
    }
    out
}

fn describe_roots(pool: &mut Pool, modes: &[Mode]) -> Vec<String> {
    let mut out = Vec::new();
    let times = |m: usize| {
        if m > 1 {
            format!(" (×{m})")
        } else {
            String::new()
        }
    };
    for &mode in modes {
        match mode {
            Mode::Exp { rate, mult } => out.push(format!("{}{}", pool.to_text(rate), times(mult))),
            Mode::Hyperbolic { rate, freq } => {
                let r = if rate == Pool::ZERO {
                    String::new()
                } else {
                    format!("{} ", pool.to_text(rate))
                };
                out.push(format!("{r}± {}", pool.to_text(freq)));
            }
            Mode::Oscillatory { rate, freq, mult } => {
                let r = if rate == Pool::ZERO {
                    String::new()
                } else {
                    format!("{} ", pool.to_text(rate))
                };
                let f = if freq == Pool::ONE {
                    "i".to_string()
                } else {
                    format!("{}*i", pool.to_text(freq))
                };
                out.push(format!("{r}± {f}{}", times(mult)));
            }
        }
    }
    out
}

fn binomial(n: usize, k: usize) -> i64 {
    let mut r: i64 = 1;
    for i in 0..k {
        r = r * (n - i) as i64 / (i + 1) as i64;
    }
    r
}

/// Particular solution for one forcing group by undetermined coefficients, `m` the multiplicity
/// of `rate + i freq` as a characteristic root (monic coefficients `c`).
fn particular_solution(
    pool: &mut Pool,
    c: &[Id],
    g: &ForcingGroup,
    m: usize,
) -> Result<Id, DsolveError> {
    let t = pool.time();
    let n = c.len() - 1;
    let a = g.rate;
    // L[e^{at} w] = e^{at} Σ_i s_i w^(i), s_i = Σ_{k≥i} c_k C(k,i) a^(k-i).
    let mut s = Vec::with_capacity(n + 1);
    for i in 0..=n {
        let mut terms = Vec::new();
        for (k, &ck) in c.iter().enumerate().skip(i) {
            let b = pool.int(binomial(k, i));
            let ap = pool.powi(a, (k - i) as i64);
            terms.push(pool.mul(&[b, ck, ap]));
        }
        let si = pool.add(&terms);
        s.push(pool.expand(si));
    }
    let deg = g.degree();
    let oscillating = g.freq != Pool::ZERO;
    let u = pool.mul2(g.freq, t);
    let (cos_bt, sin_bt) = if oscillating {
        (pool.call(Func::Cos, &[u]), pool.call(Func::Sin, &[u]))
    } else {
        (Pool::ONE, Pool::ZERO)
    };
    let mut unknowns = Vec::new();
    let mut trial_terms = Vec::new();
    for j in 0..=deg {
        let tj = pool.powi(t, (j + m) as i64);
        let p = pool.symbol(&format!("__dsolve_p{j}"), false);
        let p = pool.sym(p);
        unknowns.push(p);
        trial_terms.push(pool.mul(&[p, tj, cos_bt]));
        if oscillating {
            let q = pool.symbol(&format!("__dsolve_q{j}"), false);
            let q = pool.sym(q);
            unknowns.push(q);
            trial_terms.push(pool.mul(&[q, tj, sin_bt]));
        }
    }
    let w = pool.add(&trial_terms);
    let mut lw = Vec::new();
    let mut d = w;
    for (i, &si) in s.iter().enumerate() {
        if i > 0 {
            d = pool.dt(d);
        }
        lw.push(pool.mul2(si, d));
    }
    let mut target = Vec::new();
    for (j, &pj) in g.cos[0].iter().enumerate() {
        let tj = pool.powi(t, j as i64);
        target.push(pool.mul(&[pj, tj, cos_bt]));
    }
    for (j, &qj) in g.sin[0].iter().enumerate() {
        let tj = pool.powi(t, j as i64);
        target.push(pool.mul(&[qj, tj, sin_bt]));
    }
    let lhs = pool.add(&lw);
    let rhs = pool.add(&target);
    let resid = pool.sub(lhs, rhs);
    let resid = pool.expand(resid);
    // Coefficients of t^j cos(bt) and t^j sin(bt) must vanish.
    let cs = pool.symbol("__dsolve_cos", false);
    let cs = pool.sym(cs);
    let ss = pool.symbol("__dsolve_sin", false);
    let ss = pool.sym(ss);
    let mut parts = vec![resid];
    if oscillating {
        let r = pool.subs1(resid, cos_bt, cs);
        let r = pool.subs1(r, sin_bt, ss);
        if pool.contains(r, u) {
            return Err(no_closed_form(
                "the particular solution could not be separated into sine and cosine parts",
            ));
        }
        parts = vec![pool.diff(r, cs), pool.diff(r, ss)];
    }
    let mut eqs = Vec::new();
    for part in parts {
        let mut p = part;
        let mut fact = 1i64;
        for j in 0..=(deg + m + n) {
            if j > 0 {
                fact *= j as i64;
                p = pool.diff(p, t);
            }
            let at0 = pool.subs1(p, t, Pool::ZERO);
            if at0 != Pool::ZERO {
                let f = pool.int(fact);
                let e = pool.div(at0, f);
                eqs.push(pool.expand(e));
            }
            if p == Pool::ZERO {
                break;
            }
        }
    }
    let sys = pool
        .linear_system(&eqs, &unknowns)
        .map_err(|e| DsolveError::Invalid(format!("particular solution: {e}")))?;
    let sol = pool.solve_linear(&sys).map_err(|e| {
        no_closed_form(format!(
            "undetermined coefficients failed for the forcing with rate {} and frequency {} ({e})",
            pool.to_text(g.rate),
            pool.to_text(g.freq)
        ))
    })?;
    let mut yp = w;
    for (&u, &v) in unknowns.iter().zip(&sol) {
        yp = pool.subs1(yp, u, v);
    }
    let e = exp_of(pool, a, t);
    Ok(pool.mul2(e, yp))
}

/// `y = Σ C_i φ_i + y_p` with the constants fixed by the initial conditions (all of them or
/// none: without conditions the constants stay as `C1, C2, ...`).
fn fit_constants(
    pool: &mut Pool,
    basis: &[Id],
    particular: Id,
    ics: &[InitialCondition],
    ode: &LinearOde,
    t0: Id,
    first_constant: usize,
) -> Result<(Id, Vec<Id>), DsolveError> {
    let t = pool.time();
    let consts: Vec<Id> = (first_constant..first_constant + basis.len())
        .map(|i| {
            let s = pool.symbol(&format!("C{i}"), false);
            pool.sym(s)
        })
        .collect();
    let mut terms: Vec<Id> = consts
        .iter()
        .zip(basis)
        .map(|(&c, &b)| pool.mul2(c, b))
        .collect();
    terms.push(particular);
    let general = pool.add(&terms);
    if ics.is_empty() {
        let e = pool.expand(general);
        return Ok((pool.simplify(e), consts));
    }
    let n = ode.orders[0];
    if ics.len() != n {
        return Err(DsolveError::Invalid(format!(
            "{} initial condition(s) given, the equation needs {n} (`{}` and its derivatives up to order {}), or none",
            ics.len(),
            pool.name(ode.coords[0]),
            n - 1
        )));
    }
    let mut eqs = Vec::new();
    for ic in ics {
        let d = pool.dt_n(general, ic.order as usize);
        let at = pool.subs1(d, t, t0);
        let e = pool.sub(at, ic.value);
        eqs.push(pool.expand(e));
    }
    let sys = pool
        .linear_system(&eqs, &consts)
        .map_err(|e| DsolveError::Invalid(format!("initial conditions: {e}")))?;
    let sol = pool.solve_linear(&sys).map_err(|e| {
        DsolveError::Invalid(format!(
            "the initial conditions do not determine the solution ({e})"
        ))
    })?;
    // Collected on the basis: `x0 e^{-ζωt} cos(ωd t) + (v0 + ζω x0)/ωd e^{-ζωt} sin(ωd t)`.
    let mut terms = Vec::with_capacity(basis.len() + 1);
    for (&phi, &v) in basis.iter().zip(&sol) {
        let v = pool.expand(v);
        let v = pool.simplify(v);
        terms.push(pool.mul2(v, phi));
    }
    let yp = pool.expand(particular);
    terms.push(pool.simplify(yp));
    Ok((pool.add(&terms), Vec::new()))
}

/// Divides positive factors out of a sum while that shortens it (at most 8 of them, each a
/// factor of the first term): `wn^2 zeta^2 - wn^2` gives `(zeta^2 - 1, [wn^2])`.
fn shed_positive_factors(pool: &mut Pool, e: Id) -> (Id, Vec<Id>) {
    let mut cur = pool.expand(e);
    let mut shed = Vec::new();
    for _ in 0..8 {
        let first = match pool.node(cur) {
            Node::Add(ts) => ts[0],
            _ => break,
        };
        let cands: Vec<Id> = match pool.node(first) {
            Node::Mul(fs) => fs.to_vec(),
            _ => vec![first],
        };
        let size = pool.tree_size(cur, usize::MAX);
        let shorter = cands.into_iter().find_map(|f| {
            if pool.as_num(f).is_some() || !pool.is_positive(f) {
                return None;
            }
            let q = pool.div(cur, f);
            let q = pool.expand(q);
            (pool.tree_size(q, size) < size).then_some((f, q))
        });
        match shorter {
            Some((f, q)) => {
                cur = q;
                shed.push(f);
            }
            None => break,
        }
    }
    (cur, shed)
}

/// `sqrt(d)` with positive square factors taken out: `sqrt(wn^2 - wn^2 zeta^2)` becomes
/// `wn sqrt(1 - zeta^2)`.
pub(crate) fn nice_sqrt(pool: &mut Pool, d: Id) -> Id {
    let (cur, outside) = shed_positive_factors(pool, d);
    let inner = pool.simplify(cur);
    let mut factors: Vec<Id> = outside.iter().map(|&f| pool.sqrt(f)).collect();
    factors.push(pool.sqrt(inner));
    let r = pool.mul(&factors);
    let plain = pool.sqrt(d);
    let plain = pool.simplify(plain);
    if pool.tree_size(r, usize::MAX) <= pool.tree_size(plain, usize::MAX) {
        r
    } else {
        plain
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsolve::solve_system;
    use pdyn_expr::{Program, SymId};

    fn setup(positive: &[&str]) -> (Pool, SymId) {
        let mut p = Pool::new();
        for s in positive {
            p.symbol(s, true);
        }
        let x = p.symbol("x", false);
        (p, x)
    }

    /// Solves `eq = 0` with x(0) = x0, x'(0) = v0 and checks every case numerically: the
    /// residual of the equation at several times, and the initial conditions.
    fn solve_and_verify(
        p: &mut Pool,
        x: SymId,
        eq: &str,
        x0: &str,
        v0: &str,
        params: &[(&str, f64)],
    ) -> ClosedForm {
        let e = p.parse_scalar(eq).unwrap();
        let (c0, c1, c2) = (p.coord(x, 0), p.coord(x, 1), p.coord(x, 2));
        let (a, b) = (p.parse_scalar(x0).unwrap(), p.parse_scalar(v0).unwrap());
        let cf = solve_system(p, &[e], &[x], &[(c0, a), (c1, b)]).unwrap();
        let leaves: Vec<Id> = params.iter().map(|(n, _)| p.var(n)).collect();
        let values: Vec<f64> = params.iter().map(|(_, v)| *v).collect();
        for case in &cf.cases {
            // Only the case whose condition holds for these values (e.g. zeta < 1) applies.
            if let Some(c) = case.condition {
                let prog = Program::compile(p, &leaves, &[c.expr]).unwrap();
                let mut ws = prog.workspace();
                let mut v = [0.0];
                prog.eval(&values, &mut ws, &mut v);
                let holds = match c.relation {
                    Relation::Positive => v[0] > 1e-12,
                    Relation::Negative => v[0] < -1e-12,
                    Relation::Zero => v[0].abs() <= 1e-12,
                };
                if !holds {
                    continue;
                }
            }
            let s = case.solution[0];
            let (s1, s2) = (p.dt(s), p.dt_n(s, 2));
            let mut map = rustc_hash::FxHashMap::default();
            map.insert(c0, s);
            map.insert(c1, s1);
            map.insert(c2, s2);
            let residual = p.subs(e, &map);
            let t = p.time();
            let mut inputs = vec![t];
            inputs.extend(&leaves);
            let prog = Program::compile(p, &inputs, &[residual, s, s1, a, b]).unwrap();
            let mut ws = prog.workspace();
            let mut out = [0.0; 5];
            for k in 0..5 {
                let mut input = vec![0.37 * k as f64];
                input.extend(&values);
                prog.eval(&input, &mut ws, &mut out);
                assert!(
                    out[0].abs() < 1e-9,
                    "{eq}: residual {} at t = {}",
                    out[0],
                    input[0]
                );
                if k == 0 {
                    assert!((out[1] - out[3]).abs() < 1e-12, "{eq}: x(0)");
                    assert!((out[2] - out[4]).abs() < 1e-12, "{eq}: x'(0)");
                }
            }
        }
        cf
    }

    #[test]
    fn binomial_coefficients() {
        assert_eq!(
            (0..=5).map(|k| binomial(5, k)).collect::<Vec<_>>(),
            [1, 5, 10, 10, 5, 1]
        );
    }

    #[test]
    fn signs_of_numbers_constants_and_positive_symbols() {
        let (mut p, _) = setup(&["k", "m"]);
        let cases = [
            ("3", Some(Relation::Positive)),
            ("-2/7", Some(Relation::Negative)),
            ("pi - 3", Some(Relation::Positive)),
            ("sqrt(2) - 2", Some(Relation::Negative)),
            ("k/m + 1", Some(Relation::Positive)),
            ("-k*m", Some(Relation::Negative)),
            ("k - m", None),
        ];
        for (src, want) in cases {
            let e = p.parse_scalar(src).unwrap();
            assert_eq!(sign_of(&mut p, e), want, "{src}");
        }
    }

    #[test]
    fn square_roots_take_positive_squares_outside() {
        let (mut p, _) = setup(&["wn", "zeta"]);
        let d = p.parse_scalar("wn^2 - wn^2*zeta^2").unwrap();
        let s = nice_sqrt(&mut p, d);
        assert_eq!(p.to_text(s), "wn*sqrt(1 - zeta^2)");
    }

    #[test]
    fn distinct_real_repeated_and_complex_roots_satisfy_the_equation() {
        let (mut p, x) = setup(&[]);
        solve_and_verify(&mut p, x, "x'' - 3*x' + 2*x", "1", "0", &[]);
        let cf = solve_and_verify(&mut p, x, "x'' + 2*x' + x", "1", "2", &[]);
        assert!(p.to_text(cf.cases[0].solution[0]).contains("exp(-t)"));
        solve_and_verify(&mut p, x, "x'' + 2*x' + 5*x", "0", "1", &[]);
    }

    #[test]
    fn forcing_and_resonance_by_undetermined_coefficients() {
        let (mut p, x) = setup(&[]);
        // Off resonance, polynomial and exponential forcing.
        solve_and_verify(&mut p, x, "x'' + x - t^2 - exp(2*t)", "0", "0", &[]);
        // At resonance the particular solution grows like t sin(2t).
        let cf = solve_and_verify(&mut p, x, "x'' + 4*x - sin(2*t)", "0", "0", &[]);
        let text = p.to_text(cf.cases[0].solution[0]);
        assert!(text.contains("t*cos(2*t)"), "{text}");
    }

    #[test]
    fn a_symbolic_damping_ratio_gives_three_verified_cases() {
        let (mut p, x) = setup(&["wn", "zeta"]);
        let eq = "x'' + 2*zeta*wn*x' + wn^2*x";
        for zeta in [0.3, 1.0, 2.5] {
            let cf = solve_and_verify(&mut p, x, eq, "1", "0", &[("wn", 3.0), ("zeta", zeta)]);
            assert_eq!(cf.cases.len(), 3, "under-, critically and over-damped");
        }
    }

    #[test]
    fn an_algebraic_equation_is_refused() {
        let (mut p, x) = setup(&[]);
        let e = p.parse_scalar("x(t) - 1").unwrap();
        let err = solve_system(&mut p, &[e], &[x], &[]).unwrap_err();
        assert!(err.to_string().contains("algebraic"), "{err}");
    }
}
