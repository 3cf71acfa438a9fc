//! Unknowns that enter only through a power: a conical pendulum's rate `ω` appears in
//! `F = m a` only as `ω²` (the centripetal acceleration `L sin α ω²`), so the equations are
//! linear in `W = ω²` though not in `ω`.
//!
//! Each unknown `u` whose exponents in the expanded equations are all multiples of some
//! `g ≥ 2` is replaced by `U = u^g`; when the equations are then linear in the new unknowns
//! they are solved exactly as a linear system would be, and `u = U^(1/g)`. For an even `g` that
//! root has two signs (odd powers are left to the numeric solve): which one is kept (a declared range, a coordinate's rate) is the
//! caller's choice ([`super::solve_forces`]), made on the numbers.

use pdyn_expr::{Id, Node, Number, Pool};

/// An unknown solved through its power.
#[derive(Clone, Copy, Debug)]
pub(super) struct Power {
    /// Index of the unknown.
    pub index: usize,
    /// `g` in `U = u^g`, even: the root has two signs.
    pub degree: i64,
    /// The exact value of `u^g`.
    pub value: Id,
}

/// The exact solution with the non-negative root `U^(1/g)` of each power, and the powers; `None`
/// when no unknown enters only through a power, or the equations are not linear in the powers.
pub(super) fn solve(
    p: &mut Pool,
    residuals: &[Id],
    unknowns: &[Id],
) -> Option<(Vec<Id>, Vec<Power>)> {
    let expanded: Vec<Vec<Id>> = residuals
        .iter()
        .map(|&r| {
            let e = p.expand(r);
            match p.node(e) {
                Node::Add(ts) => ts.to_vec(),
                _ => vec![e],
            }
        })
        .collect();
    // The common degree of each unknown: the gcd of its exponents over every term.
    let mut degrees = vec![0i64; unknowns.len()];
    for terms in &expanded {
        for &t in terms {
            for (d, &u) in degrees.iter_mut().zip(unknowns) {
                // An unknown inside a function (sin(u)) has no power to substitute.
                let k = super::power_of(p, t, u)?;
                *d = super::gcd(*d, k);
            }
        }
    }
    if !degrees.iter().any(|&g| g >= 2 && g % 2 == 0) {
        return None;
    }
    // Every term rewritten with `U = u^g` for the unknowns of degree ≥ 2.
    let mut powered: Vec<Id> = unknowns.to_vec();
    let mut symbols = Vec::new();
    for (i, &g) in degrees.iter().enumerate() {
        // An odd power has one real root but no sign to choose; it stays nonlinear (numeric).
        if g >= 2 && g % 2 == 0 {
            let name = format!("{}^{g}", p.to_text(unknowns[i]));
            let s = p.symbol(&name, false);
            powered[i] = p.sym(s);
            symbols.push(i);
        }
    }
    let mut eqs = Vec::with_capacity(expanded.len());
    for terms in &expanded {
        let mut out = Vec::with_capacity(terms.len());
        for &t in terms {
            let mut term = t;
            for &i in &symbols {
                let k = super::power_of(p, term, unknowns[i])?;
                if k != 0 {
                    let uk = p.powi(unknowns[i], k);
                    let rest = p.div(term, uk);
                    let big = p.powi(powered[i], k / degrees[i]);
                    term = p.mul2(rest, big);
                }
            }
            out.push(term);
        }
        eqs.push(p.add(&out));
    }
    let sys = p.linear_system(&eqs, &powered).ok()?;
    let sol = p.solve_linear(&sys).ok()?;
    let mut exact = sol.clone();
    let mut powers = Vec::new();
    for &i in &symbols {
        let value = p.simplify(sol[i]);
        let g = degrees[i];
        let root = if g == 2 {
            p.sqrt(value)
        } else {
            let e = p.num(Number::ratio(1, g));
            p.pow(value, e)
        };
        // Not simplified: that would split sqrt(g/(L*cos(alpha))) into a product of roots.
        exact[i] = root;
        powers.push(Power {
            index: i,
            degree: g,
            value,
        });
    }
    Some((exact, powers))
}
