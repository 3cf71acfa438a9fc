//! The numeric solver: systems (and high-order equations) with numeric coefficients. See the
//! module documentation of [`super`] for the method.

use super::exact::const_value;
use super::linear::{forcing_groups, LinearOde};
use super::roots::{numeric_roots, C64};
use super::{no_closed_form, Case, ClosedForm, DsolveError, InitialCondition, Method};
use pdyn_expr::{Func, Id, Number, Pool};

/// Largest state dimension handled (the least-squares system grows as its square).
const MAX_DIM: usize = 40;

/// A family `t^j e^{rate t} cos|sin(freq t)`, `j <= max_power`.
#[derive(Clone, Debug)]
struct Family {
    rate: f64,
    freq: f64,
    max_power: usize,
    /// Exact `(rate, freq)` when the family comes from the forcing (prints `cos(3*t)`).
    exact: Option<(Id, Id)>,
}

#[derive(Clone, Copy, Debug)]
struct BasisFn {
    family: usize,
    power: usize,
    sine: bool,
}

fn value(pool: &mut Pool, e: Id, what: &dyn Fn(&Pool) -> String) -> Result<f64, DsolveError> {
    const_value(pool, e).ok_or_else(|| {
        // Quoted when short, else named with its size (a message never carries a long
        // expression).
        let what = match pool.to_text_within(e, false, pdyn_expr::budget::QUOTE_CHARS) {
            Ok(text) => format!("{} is `{text}`,", what(pool)),
            Err(size) => format!("{} ({size}) is", what(pool)),
        };
        no_closed_form(format!(
            "{what} not a number; systems and equations whose characteristic polynomial has degree ≥ 3 are solved with numeric coefficients only (give values with {})",
            crate::options::RunOption::Set
        ))
    })
}

/// Determinant of a small complex matrix by LU with partial pivoting.
fn det(mut m: Vec<C64>, n: usize) -> C64 {
    let mut d = C64::new(1.0, 0.0);
    for k in 0..n {
        let p = (k..n)
            .max_by(|&a, &b| m[a * n + k].abs().total_cmp(&m[b * n + k].abs()))
            .unwrap_or(k);
        if m[p * n + k].abs() == 0.0 {
            return C64::default();
        }
        if p != k {
            for j in 0..n {
                m.swap(p * n + j, k * n + j);
            }
            d = d.scale(-1.0);
        }
        let piv = m[k * n + k];
        d = d.mul(piv);
        for i in k + 1..n {
            let f = m[i * n + k].div(piv);
            for j in k..n {
                let v = m[k * n + j].mul(f);
                m[i * n + j] = m[i * n + j].sub(v);
            }
        }
    }
    d
}

/// Coefficients of `det Σ_k A_k λ^k` (degree at most `deg`) by interpolation on a circle of
/// radius `rho`.
fn char_poly(a: &[Vec<Vec<f64>>], n: usize, deg: usize, rho: f64) -> Vec<f64> {
    let pts = deg + 1;
    let mut dets = Vec::with_capacity(pts);
    for m in 0..pts {
        let lam = C64::cis(2.0 * std::f64::consts::PI * m as f64 / pts as f64).scale(rho);
        let mut mat = vec![C64::default(); n * n];
        for i in 0..n {
            for j in 0..n {
                let mut acc = C64::default();
                let mut lp = C64::new(1.0, 0.0);
                for &akij in &a[i][j] {
                    acc = acc.add(lp.scale(akij));
                    lp = lp.mul(lam);
                }
                mat[i * n + j] = acc;
            }
        }
        dets.push(det(mat, n));
    }
    (0..pts)
        .map(|k| {
            let mut s = C64::default();
            for (m, d) in dets.iter().enumerate() {
                let w = C64::cis(-2.0 * std::f64::consts::PI * (m * k) as f64 / pts as f64);
                s = s.add(d.mul(w));
            }
            s.re / pts as f64 / rho.powi(k as i32)
        })
        .collect()
}

/// Least squares `min |A x - b|` by Householder QR (`A` row-major, `rows × cols`,
/// `rows >= cols`). Returns `None` when `A` is rank deficient.
fn least_squares(mut a: Vec<f64>, mut b: Vec<f64>, rows: usize, cols: usize) -> Option<Vec<f64>> {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    for k in 0..cols {
        let norm = (k..rows)
            .map(|i| a[i * cols + k].powi(2))
            .sum::<f64>()
            .sqrt();
        if norm <= 1e-13 * scale {
            return None;
        }
        let alpha = if a[k * cols + k] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (k..rows).map(|i| a[i * cols + k]).collect();
        v[0] -= alpha;
        let vn2: f64 = v.iter().map(|x| x * x).sum();
        if vn2 == 0.0 {
            continue;
        }
        for j in k..cols {
            let dot: f64 = (k..rows).map(|i| v[i - k] * a[i * cols + j]).sum();
            let f = 2.0 * dot / vn2;
            for i in k..rows {
                a[i * cols + j] -= f * v[i - k];
            }
        }
        let dot: f64 = (k..rows).map(|i| v[i - k] * b[i]).sum();
        let f = 2.0 * dot / vn2;
        for i in k..rows {
            b[i] -= f * v[i - k];
        }
    }
    let mut x = vec![0.0; cols];
    for k in (0..cols).rev() {
        let mut s = b[k];
        for j in k + 1..cols {
            s -= a[k * cols + j] * x[j];
        }
        let d = a[k * cols + k];
        if d.abs() <= 1e-13 * scale {
            return None;
        }
        x[k] = s / d;
    }
    Some(x)
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-7 * scale.max(a.abs()).max(b.abs()).max(1e-12)
}

// Index arithmetic over several arrays at once reads best as plain index loops.
#[allow(clippy::needless_range_loop)]
pub(crate) fn solve_numeric(
    pool: &mut Pool,
    ode: &LinearOde,
    ics: &[InitialCondition],
    t0: Id,
) -> Result<ClosedForm, DsolveError> {
    let n = ode.coords.len();
    let dim: usize = ode.orders.iter().sum();
    if dim == 0 {
        return Err(DsolveError::Invalid(
            "no derivative of any coordinate: the equations are algebraic; use `pdyn solve`".into(),
        ));
    }
    if dim > MAX_DIM {
        return Err(no_closed_form(format!(
            "state dimension {dim} exceeds the closed-form limit {MAX_DIM}"
        )));
    }
    // Numeric A_k.
    let mut a = vec![vec![Vec::new(); n]; n];
    for i in 0..n {
        for j in 0..n {
            for (k, &e) in ode.coeffs[i][j].iter().enumerate() {
                let name = pool.name(ode.coords[j]).to_string();
                let v = value(pool, e, &|_| {
                    format!(
                        "the coefficient of `{name}{}` in equation {}",
                        "'".repeat(k),
                        i + 1
                    )
                })?;
                a[i][j].push(v);
            }
        }
    }
    // Initial conditions: all of q_j^(k)(t0), k < order_j.
    let t0v = value(pool, t0, &|_| "the initial time".into())?;
    let mut missing = Vec::new();
    let mut ic_vals = Vec::new();
    for (j, &c) in ode.coords.iter().enumerate() {
        for k in 0..ode.orders[j] {
            match ics
                .iter()
                .find(|ic| ic.coord == c && ic.order as usize == k)
            {
                Some(ic) => {
                    let v = value(pool, ic.value, &|p| {
                        format!("the initial value of `{}{}`", p.name(c), "'".repeat(k))
                    })?;
                    ic_vals.push((j, k, v));
                }
                None => missing.push(format!("{}{}", pool.name(c), "'".repeat(k))),
            }
        }
    }
    if !missing.is_empty() {
        return Err(DsolveError::Invalid(format!(
            "the numeric solver needs every initial condition; missing: {}",
            missing
                .iter()
                .map(|m| format!("{m}(0)"))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    // Characteristic polynomial and its roots.
    let mut chi = char_poly(&a, n, dim, 1.0);
    let lead = chi[dim];
    if lead != 0.0 && chi[0] != 0.0 {
        let rho = libm::pow(chi[0].abs() / lead.abs(), 1.0 / dim as f64);
        if rho.is_finite() && rho > 0.0 {
            chi = char_poly(&a, n, dim, rho);
        }
    }
    let cmax = chi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let rho_est = if chi[dim] != 0.0 {
        libm::pow(cmax / chi[dim].abs(), 1.0 / dim as f64).max(1.0)
    } else {
        1.0
    };
    // The highest derivatives are determined when the leading coefficient matrix
    // `L_ij = [q_j^(order_j)] equation i` is regular. Judged on `L` itself, scale-free
    // (|det L| against the product of its column norms, Hadamard's bound), not on
    // `chi[dim] = det L` against the other coefficients of `chi`, which span about
    // (stiffness/mass)^n and made stiff chains look singular.
    let lead: Vec<C64> = (0..n * n)
        .map(|ij| {
            let (i, j) = (ij / n, ij % n);
            C64::new(a[i][j].get(ode.orders[j]).copied().unwrap_or(0.0), 0.0)
        })
        .collect();
    let hadamard: f64 = (0..n)
        .map(|j| {
            (0..n)
                .map(|i| lead[i * n + j].abs().powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .product();
    let lead_det = det(lead, n).abs();
    if chi[dim] == 0.0
        || lead_det.is_nan()
        || lead_det <= 1e-10 * hadamard
        || !chi.iter().all(|x| x.is_finite())
    {
        return Err(no_closed_form(
            "the highest derivatives are not determined by the equations (singular leading coefficient matrix)",
        ));
    }
    // Snap the round-off of interpolation: coefficients below eps relative to the scale.
    // Relative to the largest term |c_k| ρ^k at the root scale ρ (not to `cmax ρ^dim`, which
    // would snap the genuine low-order coefficients of a stiff system).
    let smax = chi
        .iter()
        .enumerate()
        .fold(0.0f64, |m, (k, c)| m.max(c.abs() * rho_est.powi(k as i32)));
    for (k, c) in chi.iter_mut().enumerate() {
        if c.abs() * rho_est.powi(k as i32) <= 1e-13 * smax {
            *c = 0.0;
        }
    }
    let groups = numeric_roots(&chi);
    let root_scale = groups
        .iter()
        .map(|g| libm::hypot(g.re, g.im))
        .fold(0.0f64, f64::max)
        .max(1e-12);
    let mut families: Vec<Family> = Vec::new();
    let mut roots_text = Vec::new();
    for g in &groups {
        let re = if g.re.abs() <= 1e-10 * root_scale {
            0.0
        } else {
            g.re
        };
        families.push(Family {
            rate: re,
            freq: g.im,
            max_power: g.mult - 1,
            exact: None,
        });
        let m = if g.mult > 1 {
            format!(" (×{})", g.mult)
        } else {
            String::new()
        };
        roots_text.push(if g.im == 0.0 {
            format!("{re}{m}")
        } else {
            format!("{re} ± {}i{m}", g.im)
        });
    }
    // Forcing families (resonance extends the power range).
    let fg = forcing_groups(pool, &ode.forcing)?;
    let mut forcing = Vec::new();
    for g in &fg {
        let rate = value(pool, g.rate, &|_| {
            "an exponential rate in the forcing".into()
        })?;
        let freq = value(pool, g.freq, &|_| "a frequency in the forcing".into())?;
        let deg = g.degree();
        let fam = match families
            .iter()
            .position(|f| close(f.rate, rate, root_scale) && close(f.freq, freq, root_scale))
        {
            Some(fi) => {
                let mult = families[fi].max_power + 1;
                families[fi].max_power = families[fi].max_power.max(deg + mult);
                families[fi].exact = Some((g.rate, g.freq));
                fi
            }
            None => {
                families.push(Family {
                    rate,
                    freq,
                    max_power: deg,
                    exact: Some((g.rate, g.freq)),
                });
                families.len() - 1
            }
        };
        let mut cos = vec![Vec::new(); n];
        let mut sin = vec![Vec::new(); n];
        for i in 0..n {
            for (j, &cj) in g.cos[i].iter().enumerate() {
                cos[i].push(value(pool, cj, &|_| {
                    format!("a forcing coefficient of equation {}", i + 1)
                })?);
                let _ = j;
            }
            for &sj in &g.sin[i] {
                sin[i].push(value(pool, sj, &|_| {
                    format!("a forcing coefficient of equation {}", i + 1)
                })?);
            }
        }
        forcing.push((fam, cos, sin));
    }
    // The basis and d/dt on it.
    let mut basis = Vec::new();
    for (fi, f) in families.iter().enumerate() {
        for power in 0..=f.max_power {
            basis.push(BasisFn {
                family: fi,
                power,
                sine: false,
            });
            if f.freq != 0.0 {
                basis.push(BasisFn {
                    family: fi,
                    power,
                    sine: true,
                });
            }
        }
    }
    let nb = basis.len();
    let index = |family: usize, power: usize, sine: bool| {
        basis
            .iter()
            .position(|b| b.family == family && b.power == power && b.sine == sine)
    };
    let mut dm = vec![0.0; nb * nb]; // dm[to * nb + from]
    for (from, b) in basis.iter().enumerate() {
        let f = &families[b.family];
        if b.power > 0 {
            if let Some(to) = index(b.family, b.power - 1, b.sine) {
                dm[to * nb + from] += b.power as f64;
            }
        }
        dm[from * nb + from] += f.rate;
        if f.freq != 0.0 {
            if let Some(to) = index(b.family, b.power, !b.sine) {
                dm[to * nb + from] += if b.sine { f.freq } else { -f.freq };
            }
        }
    }
    let max_order = ode.orders.iter().copied().max().unwrap_or(0);
    let mut dpow = vec![identity(nb)];
    for k in 1..=max_order {
        let next = matmul(&dm, &dpow[k - 1], nb);
        dpow.push(next);
    }
    // Least-squares system: equations projected on the basis, then initial conditions.
    let cols = n * nb;
    let rows = n * nb + ic_vals.len();
    let mut m = vec![0.0; rows * cols];
    let mut rhs = vec![0.0; rows];
    for i in 0..n {
        for bp in 0..nb {
            let r = i * nb + bp;
            for c in 0..n {
                for (k, &akic) in a[i][c].iter().enumerate() {
                    if akic == 0.0 {
                        continue;
                    }
                    for b in 0..nb {
                        m[r * cols + c * nb + b] += akic * dpow[k][bp * nb + b];
                    }
                }
            }
        }
    }
    for (fam, cos, sin) in &forcing {
        for i in 0..n {
            for (j, &v) in cos[i].iter().enumerate() {
                if let Some(b) = index(*fam, j, false) {
                    rhs[i * nb + b] += v;
                }
            }
            for (j, &v) in sin[i].iter().enumerate() {
                if let Some(b) = index(*fam, j, true) {
                    rhs[i * nb + b] += v;
                }
            }
        }
    }
    let phi0: Vec<f64> = basis
        .iter()
        .map(|b| {
            let f = &families[b.family];
            let trig = if b.sine {
                libm::sin(f.freq * t0v)
            } else {
                libm::cos(f.freq * t0v)
            };
            t0v.powi(b.power as i32) * libm::exp(f.rate * t0v) * trig
        })
        .collect();
    for (r_ic, &(j, k, v)) in ic_vals.iter().enumerate() {
        let r = n * nb + r_ic;
        for b in 0..nb {
            let mut s = 0.0;
            for bp in 0..nb {
                s += phi0[bp] * dpow[k][bp * nb + b];
            }
            m[r * cols + j * nb + b] = s;
        }
        rhs[r] = v;
    }
    let x = least_squares(m.clone(), rhs.clone(), rows, cols).ok_or_else(|| {
        no_closed_form(
            "the equations and initial conditions do not determine a unique solution on the quasi-polynomial basis",
        )
    })?;
    // Residual check: the system is consistent, so the fit must be exact to round-off.
    let mut res = 0.0f64;
    let mut bnorm = 0.0f64;
    for r in 0..rows {
        let s: f64 = (0..cols).map(|c| m[r * cols + c] * x[c]).sum();
        res = res.max((s - rhs[r]).abs());
        let rowmax = (0..cols).fold(0.0f64, |acc, c| acc.max((m[r * cols + c] * x[c]).abs()));
        bnorm = bnorm.max(rhs[r].abs()).max(rowmax);
    }
    let rel = res / bnorm.max(1e-300);
    if rel > 1e-6 {
        return Err(no_closed_form(format!(
            "the numeric closed form failed its consistency check (relative residual {rel:.1e})"
        )));
    }
    // Expressions.
    let t = pool.time();
    let xmax = x.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    let mut solution = Vec::with_capacity(n);
    for c in 0..n {
        let mut terms = Vec::new();
        for (fi, f) in families.iter().enumerate() {
            let (rate, freq) = match f.exact {
                Some(ex) => ex,
                None => (num(pool, f.rate), num(pool, f.freq)),
            };
            let ru = pool.mul2(rate, t);
            let e = pool.call(Func::Exp, &[ru]);
            let fu = pool.mul2(freq, t);
            let mut inner = Vec::new();
            for (b, bf) in basis.iter().enumerate() {
                if bf.family != fi {
                    continue;
                }
                let coef = x[c * nb + b];
                if coef.abs() <= 1e-13 * xmax {
                    continue;
                }
                let k = num(pool, coef);
                let tj = pool.powi(t, bf.power as i64);
                let trig = if f.freq == 0.0 {
                    Pool::ONE
                } else {
                    pool.call(if bf.sine { Func::Sin } else { Func::Cos }, &[fu])
                };
                inner.push(pool.mul(&[k, tj, trig]));
            }
            if inner.is_empty() {
                continue;
            }
            let s = pool.add(&inner);
            terms.push(pool.mul2(e, s));
        }
        solution.push(pool.add(&terms));
    }
    Ok(ClosedForm {
        coords: ode.coords.clone(),
        cases: vec![Case {
            condition: None,
            solution,
            roots: roots_text,
            constants: Vec::new(),
        }],
        method: Method::Numeric,
        residual: Some(rel),
    })
}

fn num(pool: &mut Pool, x: f64) -> Id {
    if x == x.round() && x.abs() < 1e15 {
        pool.int(x as i64)
    } else {
        pool.num(Number::Float(x))
    }
}

fn identity(n: usize) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i * n + i] = 1.0;
    }
    m
}

fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut c = vec![0.0; n * n];
    for i in 0..n {
        for k in 0..n {
            let aik = a[i * n + k];
            if aik == 0.0 {
                continue;
            }
            for j in 0..n {
                c[i * n + j] += aik * b[k * n + j];
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use crate::dsolve::solve_system;
    use pdyn_expr::{FreeScope, Pool, Value};

    /// An n-mass spring chain `x_i'' = k (x_{i-1} − 2 x_i + x_{i+1})` (fixed ends), x_1(0) = 1,
    /// solved in closed form and compared with RK4 at t = 0.5. With k = 1000 the
    /// characteristic polynomial's coefficients span ~k^n: its leading coefficient (det M = 1)
    /// used to be judged "singular" relative to the largest one.
    fn chain(n: usize, k: f64) {
        let mut pool = Pool::new();
        let mut scope = FreeScope::default();
        let names: Vec<String> = (1..=n).map(|i| format!("x{i}")).collect();
        for nm in &names {
            scope.coordinates.insert(nm.clone());
        }
        let coords: Vec<_> = names.iter().map(|s| pool.symbol(s, false)).collect();
        let mut eqs = Vec::new();
        for i in 0..n {
            let mut s = format!("{}'' + {} * {}", names[i], 2.0 * k, names[i]);
            if i > 0 {
                s += &format!(" - {k} * {}", names[i - 1]);
            }
            if i + 1 < n {
                s += &format!(" - {k} * {}", names[i + 1]);
            }
            match pool.parse_equation_in(&s, &mut scope).unwrap() {
                Value::Scalar(e) => eqs.push(e),
                Value::Vector(_) => unreachable!(),
            }
        }
        let mut ics = Vec::new();
        for (i, &c) in coords.iter().enumerate() {
            let q = pool.coord(c, 0);
            let v = pool.coord(c, 1);
            ics.push((q, if i == 0 { Pool::ONE } else { Pool::ZERO }));
            ics.push((v, Pool::ZERO));
        }
        let sol = solve_system(&mut pool, &eqs, &coords, &ics)
            .unwrap_or_else(|e| panic!("{n} masses, k = {k}: {e}"));
        let prog = sol.compile(&mut pool, 0, &[]).unwrap();
        let mut ws = prog.workspace();
        let mut out = vec![0.0; 2 * n];
        let t_end = 0.5;
        prog.eval(&[t_end], &mut ws, &mut out);
        // RK4 on y = [x, x'].
        let f = |y: &[f64]| -> Vec<f64> {
            let mut d = vec![0.0; 2 * n];
            for i in 0..n {
                d[i] = y[n + i];
                let l = if i > 0 { y[i - 1] } else { 0.0 };
                let r = if i + 1 < n { y[i + 1] } else { 0.0 };
                d[n + i] = k * (l - 2.0 * y[i] + r);
            }
            d
        };
        let mut y = vec![0.0; 2 * n];
        y[0] = 1.0;
        let steps = 20_000;
        let h = t_end / steps as f64;
        for _ in 0..steps {
            let k1 = f(&y);
            let y2: Vec<f64> = (0..2 * n).map(|i| y[i] + 0.5 * h * k1[i]).collect();
            let k2 = f(&y2);
            let y3: Vec<f64> = (0..2 * n).map(|i| y[i] + 0.5 * h * k2[i]).collect();
            let k3 = f(&y3);
            let y4: Vec<f64> = (0..2 * n).map(|i| y[i] + h * k3[i]).collect();
            let k4 = f(&y4);
            for i in 0..2 * n {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        for i in 0..n {
            assert!(
                (out[2 * i] - y[i]).abs() < 1e-6,
                "{n} masses, k = {k}: x{} = {} closed form vs {} RK4",
                i + 1,
                out[2 * i],
                y[i]
            );
        }
    }

    /// Up to 6 masses. From 7 masses on (degree ≥ 14) the roots of the characteristic
    /// polynomial are no longer accurate enough for the consistency check (residual 5e-6 at
    /// 7, 2e-3 at 8): such chains need the eigen-decomposition of M⁻¹K (issue 12, not done).
    #[test]
    fn stiff_spring_chains_are_not_called_singular() {
        for n in [3, 5, 6] {
            chain(n, 1000.0);
        }
    }
}
