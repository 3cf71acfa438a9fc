//! Small coupled systems with symbolic coefficients, by elimination.
//!
//! For `P(D) q = f` (`D = d/dt`, `P` a 2×2 or 3×3 matrix of polynomials), every coordinate obeys
//! the scalar equation `det P(D) q_j = Σ_i adj P(D)_{ji} f_i`, whose characteristic polynomial is
//! the system's `χ(λ) = det P(λ)`. Its initial conditions `q_j^(k)(t0)`, `k < deg χ`, follow from
//! the given ones: the equations are solved for the highest derivatives, which are then
//! differentiated as often as needed. Each scalar equation goes to the exact solver; when that
//! needs numeric roots, the caller falls back to the numeric solver.

use super::exact::solve_scalar;
use super::linear::LinearOde;
use super::{Case, ClosedForm, DsolveError, InitialCondition, Method};
use pdyn_expr::{Id, Node, Pool};

/// Largest system handled by elimination.
const MAX_COORDS: usize = 3;

/// Coefficients `c_k` of the polynomial `e` in `lam` (degree at most `deg`).
fn coefficients(pool: &mut Pool, e: Id, lam: Id, deg: usize) -> Vec<Id> {
    let mut out = Vec::with_capacity(deg + 1);
    let mut d = e;
    let mut fact: i64 = 1;
    for k in 0..=deg {
        if k > 0 {
            d = pool.diff(d, lam);
            fact = fact.saturating_mul(k as i64);
        }
        let at0 = pool.subs1(d, lam, Pool::ZERO);
        let f = pool.int(fact);
        let c = pool.div(at0, f);
        let c = pool.expand(c);
        out.push(pool.simplify(c));
    }
    out
}

/// Applies the polynomial operator `Σ c_k D^k` to `f`.
fn apply(pool: &mut Pool, coeffs: &[Id], f: Id) -> Id {
    let mut terms = Vec::new();
    let mut d = f;
    for (k, &c) in coeffs.iter().enumerate() {
        if k > 0 {
            d = pool.dt(d);
        }
        if c != Pool::ZERO && d != Pool::ZERO {
            terms.push(pool.mul2(c, d));
        }
    }
    pool.add(&terms)
}

fn det(pool: &mut Pool, m: &[Vec<Id>]) -> Id {
    match m.len() {
        1 => m[0][0],
        2 => {
            let a = pool.mul2(m[0][0], m[1][1]);
            let b = pool.mul2(m[0][1], m[1][0]);
            pool.sub(a, b)
        }
        n => {
            let mut terms = Vec::with_capacity(n);
            for j in 0..n {
                let minor: Vec<Vec<Id>> = m[1..]
                    .iter()
                    .map(|row| {
                        row.iter()
                            .enumerate()
                            .filter(|&(c, _)| c != j)
                            .map(|(_, &x)| x)
                            .collect()
                    })
                    .collect();
                let dm = det(pool, &minor);
                let t = pool.mul2(m[0][j], dm);
                terms.push(if j % 2 == 1 { pool.neg(t) } else { t });
            }
            pool.add(&terms)
        }
    }
}

/// Cofactor `C_ij` of `m`.
fn cofactor(pool: &mut Pool, m: &[Vec<Id>], i: usize, j: usize) -> Id {
    let minor: Vec<Vec<Id>> = m
        .iter()
        .enumerate()
        .filter(|&(r, _)| r != i)
        .map(|(_, row)| {
            row.iter()
                .enumerate()
                .filter(|&(c, _)| c != j)
                .map(|(_, &x)| x)
                .collect()
        })
        .collect();
    let d = det(pool, &minor);
    if (i + j) % 2 == 1 {
        pool.neg(d)
    } else {
        d
    }
}

/// Solves a small coupled system by elimination; `Ok(None)` when it does not apply (too large,
/// missing initial conditions, singular leading terms, or roots that need numbers).
pub(crate) fn solve_by_elimination(
    pool: &mut Pool,
    ode: &LinearOde,
    ics: &[InitialCondition],
    t0: Id,
) -> Result<Option<ClosedForm>, DsolveError> {
    let n = ode.coords.len();
    if !(2..=MAX_COORDS).contains(&n) {
        return Ok(None);
    }
    // All initial conditions q_j^(k), k < o_j, are needed to link the coordinates.
    let mut state_values = Vec::new();
    for (j, &c) in ode.coords.iter().enumerate() {
        for k in 0..ode.orders[j] {
            match ics
                .iter()
                .find(|ic| ic.coord == c && ic.order as usize == k)
            {
                Some(ic) => {
                    let leaf = pool.coord(c, k as u8);
                    state_values.push((leaf, ic.value));
                }
                None => return Ok(None),
            }
        }
    }
    let dim: usize = ode.orders.iter().sum();
    let lam_sym = pool.symbol("__dsolve_lambda", false);
    let lam = pool.sym(lam_sym);
    let p: Vec<Vec<Id>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let terms: Vec<Id> = ode.coeffs[i][j]
                        .iter()
                        .enumerate()
                        .map(|(k, &a)| {
                            let lk = pool.powi(lam, k as i64);
                            pool.mul2(a, lk)
                        })
                        .collect();
                    pool.add(&terms)
                })
                .collect()
        })
        .collect();
    let chi = det(pool, &p);
    let chi = pool.expand(chi);
    let chi_c = coefficients(pool, chi, lam, dim);
    if chi_c[dim] == Pool::ZERO {
        return Ok(None); // singular leading matrix: the numeric solver explains
    }
    // Highest derivatives from the equations, for the initial conditions of the eliminated
    // equations.
    let mut eqs = Vec::with_capacity(n);
    for i in 0..n {
        let mut terms = Vec::new();
        for (j, &c) in ode.coords.iter().enumerate() {
            for (k, &a) in ode.coeffs[i][j].iter().enumerate() {
                let leaf = pool.coord(c, k as u8);
                terms.push(pool.mul2(a, leaf));
            }
        }
        let lhs = pool.add(&terms);
        eqs.push(pool.sub(lhs, ode.forcing[i]));
    }
    let tops: Vec<Id> = (0..n)
        .map(|j| pool.coord(ode.coords[j], ode.orders[j] as u8))
        .collect();
    let Ok(sys) = pool.linear_system(&eqs, &tops) else {
        return Ok(None);
    };
    let Ok(highest) = pool.solve_linear(&sys) else {
        return Ok(None);
    };
    // Expression of q_j^(k) in the state (lower derivatives) and t.
    let reduce = |pool: &mut Pool, mut e: Id| -> Id {
        for _ in 0..dim + 2 {
            let mut changed = false;
            for (j, &c) in ode.coords.iter().enumerate() {
                for extra in (0..=dim).rev() {
                    let leaf = pool.coord(c, (ode.orders[j] + extra) as u8);
                    if !pool.contains(e, leaf) {
                        continue;
                    }
                    // q^(o+extra) = d^extra/dt^extra of the highest-derivative expression.
                    let h = pool.dt_n(highest[j], extra);
                    e = pool.subs1(e, leaf, h);
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        e
    };
    let t = pool.time();
    let mut per_coord: Vec<ClosedForm> = Vec::with_capacity(n);
    for (j, &c) in ode.coords.iter().enumerate() {
        // Under an exhausted simplification budget the result would be discarded.
        if pool.simplify_budget_exhausted() {
            return Ok(None);
        }
        // Right-hand side Σ_i adj(P)_{ji}(D) f_i, adj(P)_{ji} = C_{ij}.
        let mut rhs = Vec::new();
        for i in 0..n {
            if ode.forcing[i] == Pool::ZERO {
                continue;
            }
            let cof = cofactor(pool, &p, i, j);
            let cof = pool.expand(cof);
            let cc = coefficients(pool, cof, lam, dim);
            rhs.push(apply(pool, &cc, ode.forcing[i]));
        }
        let forcing = pool.add(&rhs);
        let forcing = pool.expand(forcing);
        let scalar = LinearOde {
            coords: vec![c],
            orders: vec![dim],
            coeffs: vec![vec![chi_c.clone()]],
            forcing: vec![forcing],
        };
        let mut scalar_ics = Vec::with_capacity(dim);
        let mut d = pool.coord(c, 0);
        for k in 0..dim {
            if k > 0 {
                d = pool.dt(d);
            }
            let e = reduce(pool, d);
            let mut v = pool.subs1(e, t, t0);
            for &(leaf, val) in &state_values {
                v = pool.subs1(v, leaf, val);
            }
            if pool.any_node(v, &|nd| matches!(nd, Node::Coord(..))) {
                return Ok(None);
            }
            let v = pool.expand(v);
            scalar_ics.push(InitialCondition {
                coord: c,
                order: k as u8,
                value: pool.simplify(v),
            });
        }
        match solve_scalar(pool, &scalar, &scalar_ics, t0, 1)? {
            Some(cf) => per_coord.push(cf),
            None => return Ok(None),
        }
    }
    // Same characteristic polynomial, so the same cases in the same order.
    let n_cases = per_coord[0].cases.len();
    if per_coord.iter().any(|cf| cf.cases.len() != n_cases) {
        return Ok(None);
    }
    let cases = (0..n_cases)
        .map(|ci| Case {
            condition: per_coord[0].cases[ci].condition,
            solution: per_coord
                .iter()
                .map(|cf| cf.cases[ci].solution[0])
                .collect(),
            roots: per_coord[0].cases[ci].roots.clone(),
            constants: Vec::new(),
        })
        .collect();
    Ok(Some(ClosedForm {
        coords: ode.coords.clone(),
        cases,
        method: Method::Exact,
        residual: None,
    }))
}
