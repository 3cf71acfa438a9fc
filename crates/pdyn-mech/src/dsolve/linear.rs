//! Recognition of linear constant-coefficient equations, and the split of the forcing into
//! groups `e^{at} t^j cos bt`, `e^{at} t^j sin bt`.

use super::{no_closed_form, DsolveError};
use pdyn_expr::{Func, Id, Node, Pool, SymId};

/// Highest derivative order accepted per coordinate (keeps every step bounded).
pub(crate) const MAX_ORDER: usize = 12;
/// Highest power of `t` accepted in the forcing.
const MAX_FORCING_POWER: u32 = 12;

/// A square linear system `Σ_k A_k q^(k) = f(t)` with constant `A_k`.
#[derive(Clone, Debug)]
pub struct LinearOde {
    /// The coordinates (columns).
    pub coords: Vec<SymId>,
    /// Highest derivative of each coordinate over all equations.
    pub orders: Vec<usize>,
    /// `coeffs[i][j][k]`: coefficient of `q_j^(k)` in equation `i`.
    pub coeffs: Vec<Vec<Vec<Id>>>,
    /// Right-hand side `f_i(t)` of each equation.
    pub forcing: Vec<Id>,
}

/// Highest derivative order of coordinate `s` appearing in `e`.
pub(crate) fn max_order(pool: &Pool, e: Id, s: SymId) -> Option<usize> {
    pool.topo_order(&[e])
        .into_iter()
        .filter_map(|n| match pool.node(n) {
            Node::Coord(c, k) if *c == s => Some(*k as usize),
            _ => None,
        })
        .max()
}

fn has_coord(pool: &Pool, e: Id) -> bool {
    pool.any_node(e, &|n| matches!(n, Node::Coord(..)))
}

fn has_time(pool: &Pool, e: Id) -> bool {
    pool.any_node(e, &|n| matches!(n, Node::Time))
}

fn leaf_name(pool: &Pool, s: SymId, k: usize) -> String {
    format!("{}{}", pool.name(s), "'".repeat(k))
}

/// `what` quoted when it is short (`its coefficient `cos(x)``), else named with its size
/// (`its coefficient, 1012 characters,`): a message never carries a long expression (the
/// double pendulum's coefficient is 1,000 characters, the figure-eight's 40 KB).
pub(crate) fn quoted(pool: &Pool, what: &str, e: Id) -> String {
    match pool.to_text_within(e, false, pdyn_expr::budget::QUOTE_CHARS) {
        Ok(text) => format!("{what} `{text}`"),
        Err(size) => format!("{what}, {size},"),
    }
}

/// Writes `equations` (each `= 0`) as `Σ_k A_k q^(k) = f(t)`, checking that they are linear in
/// the coordinates with coefficients free of `t`.
pub fn analyze(
    pool: &mut Pool,
    equations: &[Id],
    coords: &[SymId],
) -> Result<LinearOde, DsolveError> {
    if equations.is_empty() {
        return Err(DsolveError::Invalid("no equation given".into()));
    }
    if equations.len() != coords.len() {
        return Err(DsolveError::Invalid(format!(
            "{} equation(s) for {} unknown function(s) ({}): give one equation per coordinate",
            equations.len(),
            coords.len(),
            coords
                .iter()
                .map(|&c| pool.name(c).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    for (i, &eq) in equations.iter().enumerate() {
        for n in pool.topo_order(&[eq]) {
            if let Node::Coord(s, _) = pool.node(n) {
                if !coords.contains(s) {
                    return Err(DsolveError::Invalid(format!(
                        "equation {}: `{}` is a function of time but not one of the coordinates solved for",
                        i + 1,
                        pool.name(*s)
                    )));
                }
            }
        }
    }
    let mut orders = vec![0usize; coords.len()];
    for &eq in equations {
        for (j, &c) in coords.iter().enumerate() {
            if let Some(k) = max_order(pool, eq, c) {
                orders[j] = orders[j].max(k);
            }
        }
    }
    for (j, &o) in orders.iter().enumerate() {
        if o > MAX_ORDER {
            return Err(no_closed_form(format!(
                "`{}` appears differentiated {o} times (at most {MAX_ORDER} supported)",
                pool.name(coords[j])
            )));
        }
    }
    let mut coeffs = Vec::with_capacity(equations.len());
    let mut forcing = Vec::with_capacity(equations.len());
    for (i, &eq) in equations.iter().enumerate() {
        let mut row = Vec::with_capacity(coords.len());
        let mut rest = eq;
        for (j, &c) in coords.iter().enumerate() {
            let mut col = Vec::with_capacity(orders[j] + 1);
            for k in 0..=orders[j] {
                let leaf = pool.coord(c, k as u8);
                let a = pool.diff(eq, leaf);
                let a = pool.expand(a);
                if has_coord(pool, a) {
                    return Err(no_closed_form(format!(
                        "equation {} is not linear in `{}` ({} depends on the coordinates)",
                        i + 1,
                        leaf_name(pool, c, k),
                        quoted(pool, "its coefficient", a)
                    )));
                }
                if has_time(pool, a) {
                    return Err(no_closed_form(format!(
                        "equation {} has a variable coefficient: {} which depends on t",
                        i + 1,
                        quoted(
                            pool,
                            &format!("the factor multiplying `{}` is", leaf_name(pool, c, k)),
                            a
                        )
                    )));
                }
                rest = pool.subs1(rest, leaf, Pool::ZERO);
                col.push(pool.simplify(a));
            }
            row.push(col);
        }
        if has_coord(pool, rest) {
            return Err(no_closed_form(format!(
                "equation {} is not linear in the coordinates",
                i + 1
            )));
        }
        if row.iter().all(|col| col.iter().all(|&a| a == Pool::ZERO)) {
            return Err(DsolveError::Invalid(format!(
                "equation {} does not involve any coordinate",
                i + 1
            )));
        }
        coeffs.push(row);
        let f = pool.neg(rest);
        forcing.push(pool.expand(f));
    }
    Ok(LinearOde {
        coords: coords.to_vec(),
        orders,
        coeffs,
        forcing,
    })
}

/// One term `coeff * t^power * e^{rate t} * (cos | sin)(freq t)` of a forcing function.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ForcingTerm {
    pub rate: Id,
    pub freq: Id,
    pub power: u32,
    pub sine: bool,
    pub coeff: Id,
}

/// Forcing terms sharing `e^{rate t}` and frequency `freq`, per equation:
/// `cos[i][j]`, `sin[i][j]` multiply `t^j e^{rate t} cos(freq t)` (resp. `sin`) in equation `i`.
#[derive(Clone, Debug)]
pub(crate) struct ForcingGroup {
    pub rate: Id,
    pub freq: Id,
    pub cos: Vec<Vec<Id>>,
    pub sin: Vec<Vec<Id>>,
}

impl ForcingGroup {
    /// Highest power of `t`.
    pub fn degree(&self) -> usize {
        self.cos
            .iter()
            .chain(&self.sin)
            .map(|p| p.len().saturating_sub(1))
            .max()
            .unwrap_or(0)
    }
}

/// `u = r t + c` with `r`, `c` free of `t`: returns `(r, c)`.
fn linear_in_t(pool: &mut Pool, u: Id) -> Option<(Id, Id)> {
    let t = pool.time();
    let r = pool.diff(u, t);
    if has_time(pool, r) {
        return None;
    }
    let c = pool.subs1(u, t, Pool::ZERO);
    Some((r, c))
}

/// Rewrites `sinh`, `cosh` as exponentials so they split into exponential groups.
fn hyperbolic_to_exp(pool: &mut Pool, e: Id) -> Id {
    let nodes = pool.topo_order(&[e]);
    let mut out = e;
    for n in nodes.into_iter().rev() {
        if let Node::Call(f @ (Func::Sinh | Func::Cosh), args) = pool.node(n).clone() {
            let u = args[0];
            let ep = pool.call(Func::Exp, &[u]);
            let nu = pool.neg(u);
            let em = pool.call(Func::Exp, &[nu]);
            let half = pool.num(pdyn_expr::Number::ratio(1, 2));
            let s = if f == Func::Sinh {
                pool.sub(ep, em)
            } else {
                pool.add2(ep, em)
            };
            let r = pool.mul2(half, s);
            out = pool.subs1(out, n, r);
        }
    }
    out
}

fn unsupported(pool: &Pool, term: Id) -> DsolveError {
    no_closed_form(format!(
        "{} is not a sum of products of powers of t, exponentials and sines/cosines of a linear function of t",
        quoted(pool, "the forcing term", term)
    ))
}

fn trig_arg(pool: &Pool, f: Id) -> Option<(Func, Id)> {
    match pool.node(f) {
        Node::Call(g @ (Func::Sin | Func::Cos), args) => Some((*g, args[0])),
        _ => None,
    }
}

/// `A(u) B(v)` for sines and cosines as a sum (product-to-sum identities).
fn product_to_sum(pool: &mut Pool, a: (Func, Id), b: (Func, Id)) -> Id {
    let (fa, u) = a;
    let (fb, v) = b;
    let diff = pool.sub(u, v);
    let sum = pool.add2(u, v);
    let half = pool.num(pdyn_expr::Number::ratio(1, 2));
    let r = match (fa, fb) {
        (Func::Sin, Func::Sin) => {
            let c1 = pool.call(Func::Cos, &[diff]);
            let c2 = pool.call(Func::Cos, &[sum]);
            pool.sub(c1, c2)
        }
        (Func::Cos, Func::Cos) => {
            let c1 = pool.call(Func::Cos, &[diff]);
            let c2 = pool.call(Func::Cos, &[sum]);
            pool.add2(c1, c2)
        }
        (Func::Sin, _) => {
            let s1 = pool.call(Func::Sin, &[sum]);
            let s2 = pool.call(Func::Sin, &[diff]);
            pool.add2(s1, s2)
        }
        _ => {
            let s1 = pool.call(Func::Sin, &[sum]);
            let s2 = pool.call(Func::Sin, &[diff]);
            pool.sub(s1, s2)
        }
    };
    pool.mul2(half, r)
}

/// Rewrites products and small powers of sines and cosines as sums (`sin t cos t =
/// sin(2t)/2`, `cos² t = (1 + cos 2t)/2`), so each term has at most one trigonometric factor.
/// Gives up (returns the input) beyond a fixed amount of work.
fn linearize_trig(pool: &mut Pool, e: Id) -> Id {
    let mut cur = pool.expand(e);
    for _ in 0..24 {
        let terms: Vec<Id> = match pool.node(cur) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![cur],
        };
        if terms.len() > 400 {
            return cur;
        }
        let mut changed = false;
        let mut out = Vec::with_capacity(terms.len());
        for term in terms {
            let factors: Vec<Id> = match pool.node(term) {
                Node::Mul(fs) => fs.to_vec(),
                _ => vec![term],
            };
            let mut trig = Vec::new();
            let mut other = Vec::new();
            for f in factors {
                if let Some(ta) = trig_arg(pool, f) {
                    trig.push(ta);
                    continue;
                }
                if let Node::Pow(b, n) = pool.node(f).clone() {
                    let k = pool.as_num(n).and_then(|x| x.as_integer());
                    if let (Some(ta), Some(k @ 2..=8)) = (trig_arg(pool, b), k) {
                        trig.extend(std::iter::repeat_n(ta, k as usize));
                        continue;
                    }
                }
                other.push(f);
            }
            if trig.len() >= 2 {
                let (a, b) = (trig[0], trig[1]);
                other.push(product_to_sum(pool, a, b));
                for &(g, u) in &trig[2..] {
                    other.push(pool.call(g, &[u]));
                }
                out.push(pool.mul(&other));
                changed = true;
            } else {
                out.push(term);
            }
        }
        let next = pool.add(&out);
        cur = pool.expand(next);
        if !changed {
            break;
        }
    }
    cur
}

/// Splits `f(t)` into terms `coeff t^p e^{rate t} cos|sin(freq t)`.
pub(crate) fn forcing_terms(pool: &mut Pool, f: Id) -> Result<Vec<ForcingTerm>, DsolveError> {
    let f = hyperbolic_to_exp(pool, f);
    let f = linearize_trig(pool, f);
    if f == Pool::ZERO {
        return Ok(Vec::new());
    }
    let terms: Vec<Id> = match pool.node(f) {
        Node::Add(ts) => ts.to_vec(),
        _ => vec![f],
    };
    let t = pool.time();
    let mut out = Vec::new();
    for term in terms {
        let factors: Vec<Id> = match pool.node(term) {
            Node::Mul(fs) => fs.to_vec(),
            _ => vec![term],
        };
        let mut coeff = Pool::ONE;
        let mut power = 0u32;
        let mut rate = Pool::ZERO;
        // (freq, phase, is_sine) of the one trigonometric factor allowed.
        let mut trig: Option<(Id, Id, bool)> = None;
        for fac in factors {
            if !has_time(pool, fac) {
                coeff = pool.mul2(coeff, fac);
                continue;
            }
            match pool.node(fac).clone() {
                Node::Time => power += 1,
                Node::Pow(b, e) if b == t => match pool.as_num(e).and_then(|n| n.as_integer()) {
                    Some(n) if (1..=MAX_FORCING_POWER as i64).contains(&n) => power += n as u32,
                    _ => return Err(unsupported(pool, term)),
                },
                Node::Call(Func::Exp, args) => {
                    let (r, c) =
                        linear_in_t(pool, args[0]).ok_or_else(|| unsupported(pool, term))?;
                    rate = pool.add2(rate, r);
                    let ec = pool.call(Func::Exp, &[c]);
                    coeff = pool.mul2(coeff, ec);
                }
                Node::Call(f @ (Func::Sin | Func::Cos), args) if trig.is_none() => {
                    let (r, c) =
                        linear_in_t(pool, args[0]).ok_or_else(|| unsupported(pool, term))?;
                    trig = Some((r, c, f == Func::Sin));
                }
                _ => return Err(unsupported(pool, term)),
            }
        }
        if power > MAX_FORCING_POWER {
            return Err(unsupported(pool, term));
        }
        match trig {
            None => out.push(ForcingTerm {
                rate,
                freq: Pool::ZERO,
                power,
                sine: false,
                coeff,
            }),
            Some((mut freq, phase, sine)) => {
                let mut coeff = coeff;
                if pool.looks_negative(freq) {
                    freq = pool.neg(freq);
                    if sine {
                        coeff = pool.neg(coeff);
                    }
                }
                // sin(bt + c) = cos c sin bt + sin c cos bt; cos(bt + c) = cos c cos bt - sin c sin bt.
                let cc = pool.call(Func::Cos, &[phase]);
                let sc = pool.call(Func::Sin, &[phase]);
                let (on_sin, on_cos) = if sine { (cc, sc) } else { (pool.neg(sc), cc) };
                for (k, is_sine) in [(on_sin, true), (on_cos, false)] {
                    if k == Pool::ZERO {
                        continue;
                    }
                    let c = pool.mul2(coeff, k);
                    out.push(ForcingTerm {
                        rate,
                        freq,
                        power,
                        sine: is_sine,
                        coeff: c,
                    });
                }
            }
        }
    }
    // sin(0 t) = 0 and cos(0 t) = 1.
    out.retain(|ft| !(ft.sine && ft.freq == Pool::ZERO));
    Ok(out)
}

/// Groups the forcing of every equation by `(rate, freq)`.
pub(crate) fn forcing_groups(
    pool: &mut Pool,
    forcing: &[Id],
) -> Result<Vec<ForcingGroup>, DsolveError> {
    let n = forcing.len();
    let mut groups: Vec<ForcingGroup> = Vec::new();
    for (i, &f) in forcing.iter().enumerate() {
        for ft in forcing_terms(pool, f)? {
            let rate = pool.simplify(ft.rate);
            let freq = pool.simplify(ft.freq);
            let g = match groups.iter().position(|g| g.rate == rate && g.freq == freq) {
                Some(g) => g,
                None => {
                    groups.push(ForcingGroup {
                        rate,
                        freq,
                        cos: vec![Vec::new(); n],
                        sin: vec![Vec::new(); n],
                    });
                    groups.len() - 1
                }
            };
            let poly = if ft.sine {
                &mut groups[g].sin[i]
            } else {
                &mut groups[g].cos[i]
            };
            let p = ft.power as usize;
            if poly.len() <= p {
                poly.resize(p + 1, Pool::ZERO);
            }
            poly[p] = pool.add2(poly[p], ft.coeff);
        }
    }
    for g in &mut groups {
        for poly in g.cos.iter_mut().chain(g.sin.iter_mut()) {
            for c in poly.iter_mut() {
                *c = pool.simplify(*c);
            }
        }
    }
    Ok(groups)
}
