//! The modal solver: `M q'' + C q' + K q = f(t)` with numeric, symmetric (or symmetrisable)
//! `M`, `K` and `M` positive definite — spring–mass chains, shear buildings, any number of
//! degrees of freedom — by the eigen-decomposition every vibration textbook uses.
//!
//! With `M = L Lᵀ` (Cholesky) and `L⁻¹ K L⁻ᵀ = U Λ Uᵀ` (symmetric eigenproblem, nalgebra's
//! `SymmetricEigen`), the mass-normalised modes `Φ = L⁻ᵀ U` satisfy `Φᵀ M Φ = I` and
//! `Φᵀ K Φ = Λ`. When the damping is classical (`Φᵀ C Φ` diagonal: none, or Rayleigh's
//! `αM + βK`), the modal coordinates `η = Φᵀ M q` obey uncoupled scalar equations
//! `η_k'' + c_k η_k' + λ_k η_k = (Φᵀ f)_k`, each solved in closed form (undetermined
//! coefficients in complex arithmetic, resonance included), and `q = Φ η`.
//!
//! Equations written as accelerations (`x1'' = -(k1 + k2)/m1 x1 + k2/m1 x2`) have a
//! non-symmetric `K`; scaling each equation by a positive factor `d_i` (found along the
//! couplings, `d_j = d_i K_ij / K_ji`) makes it symmetric again when the system is physical.
//!
//! Unlike the characteristic polynomial of degree `2n`, whose coefficients span
//! `(k/m)^n` and lose every digit by n ≈ 20, the eigen-decomposition is backward stable: the
//! modes come out to about `n ε` relative to the largest frequency, for any n.

use super::exact::const_value;
use super::linear::{forcing_groups, LinearOde};
use super::roots::C64;
use super::{Case, ClosedForm, DsolveError, InitialCondition, Method};
use nalgebra::{DMatrix, SymmetricEigen};
use pdyn_expr::{Func, Id, Number, Pool};

/// Largest number of coordinates (the eigenproblem is O(n³); the printed solution O(n²)).
const MAX_COORDS: usize = 400;

/// Largest accepted relative residual of `K Φ = M Φ Λ`, equation by equation.
const RESIDUAL_LIMIT: f64 = 1e-9;

/// Floor of the residual check's scale, relative to a mode's largest component (see
/// `solve_modal`): with `RESIDUAL_LIMIT`, an equation may be off by 1e-12 of its coefficients
/// times that component. A normwise-accurate eigenvector of a 50-mass chain of unequal masses
/// was off by 1.3e-9 of the terms in an equation where its components were 1e-7 of the
/// largest (1e-13 of the coefficients times the largest); a mass of 1e300 beside masses of 1
/// loses its coupling entirely, off by the whole size of the terms, far above the floor.
const MODE_FLOOR: f64 = 1e-3;

/// Relative tolerance for "symmetric" and "diagonal".
const SYMMETRY_TOLERANCE: f64 = 1e-10;

/// Solves the system by modes, or `Ok(None)` when it is not of the form this solver handles
/// (another order than 2, symbolic coefficients, non-classical damping, `M` not positive
/// definite...); then the general numeric solver is tried.
pub(crate) fn solve_modal(
    pool: &mut Pool,
    ode: &LinearOde,
    ics: &[InitialCondition],
    t0: Id,
) -> Result<Option<ClosedForm>, DsolveError> {
    let n = ode.coords.len();
    if !(2..=MAX_COORDS).contains(&n) || ode.orders.iter().any(|&o| o != 2) {
        return Ok(None);
    }
    let Some([m, c, k]) = matrices(pool, ode) else {
        return Ok(None);
    };
    let Some(scale) = symmetrising_scale(&m, &k, &c) else {
        return Ok(None);
    };
    let rows = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(scale.clone()));
    let (m, c, k) = (&rows * m, &rows * c, &rows * k);
    let Some(chol) = m.clone().cholesky() else {
        return Ok(None);
    };
    let Some(l_inv) = chol.l().try_inverse() else {
        return Ok(None);
    };
    let s = &l_inv * &k * l_inv.transpose();
    let s = (&s + s.transpose()) * 0.5;
    let eig = SymmetricEigen::new(s);
    let phi = l_inv.transpose() * &eig.eigenvectors;
    let modal_c = phi.transpose() * &c * &phi;
    let lam_max = eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let c_max = modal_c.amax();
    for i in 0..n {
        for j in 0..n {
            if i != j && modal_c[(i, j)].abs() > 1e-8 * c_max.max(lam_max.sqrt()) {
                return Ok(None); // non-classical damping: the general solver
            }
        }
    }
    // The check reported with the result, equation by equation and mode by mode:
    // |(K Φ - M Φ Λ)_ik| against the size of its terms. A global norm would miss badly scaled
    // systems (a mass of 1e300 beside masses of 1): their small eigenvector components are
    // lost to round-off, the coupling vanishes and the answer is silently wrong; row by row
    // that shows as a relative error of order 1, and the general solver is used instead.
    // The size has a floor of `MODE_FLOOR` times the row's coefficients times the mode's
    // largest component: where a mode's components are small against its largest one (a
    // 50-mass chain of unequal masses), they are accurate to the eigenvector's normwise
    // round-off, not to their own size, and that is no loss of coupling.
    let kphi = &k * &phi;
    let mphi = &m * &phi;
    let mut residual = 0.0f64;
    for mode in 0..n {
        let lam = eig.eigenvalues[mode];
        let largest = phi.column(mode).amax();
        for i in 0..n {
            let row = |j: usize| k[(i, j)].abs() + m[(i, j)].abs() * lam.abs();
            let size: f64 = (0..n).map(|j| row(j) * phi[(j, mode)].abs()).sum::<f64>()
                + MODE_FLOOR * largest * (0..n).map(row).sum::<f64>();
            if size > 0.0 {
                let r = (kphi[(i, mode)] - mphi[(i, mode)] * lam).abs() / size;
                residual = residual.max(r);
            }
        }
    }
    if residual.is_nan() || residual > RESIDUAL_LIMIT {
        return Ok(None);
    }
    // Modal initial conditions η = Φᵀ M q.
    let Some((q0, v0)) = initial_values(pool, ode, ics) else {
        return Ok(None);
    };
    let pm = phi.transpose() * &m;
    let eta0 = &pm * nalgebra::DVector::from_vec(q0);
    let deta0 = &pm * nalgebra::DVector::from_vec(v0);

    let Some(groups) = numeric_groups(pool, ode) else {
        return Ok(None);
    };
    let float = |pool: &mut Pool, x: f64| pool.num(Number::Float(x));
    let snap = |x: f64, scale: f64| if x.abs() <= 1e-12 * scale { 0.0 } else { x };
    let mut etas = Vec::with_capacity(n);
    let mut roots = Vec::new();
    for mode in 0..n {
        let lam = snap(eig.eigenvalues[mode], lam_max);
        let damp = snap(modal_c[(mode, mode)], c_max.max(lam_max.sqrt()));
        let w: Vec<f64> = (0..n).map(|i| phi[(i, mode)] * scale[i]).collect();
        let particular = particular_solution(pool, &groups, &w, lam, damp);
        let Some((eta, root)) =
            mode_solution(pool, lam, damp, particular, eta0[mode], deta0[mode], t0)
        else {
            return Ok(None);
        };
        etas.push(eta);
        roots.push(root);
    }
    let solution = (0..n)
        .map(|j| {
            let terms: Vec<Id> = (0..n)
                .filter(|&mode| etas[mode] != Pool::ZERO && phi[(j, mode)] != 0.0)
                .map(|mode| {
                    let w = float(pool, phi[(j, mode)]);
                    pool.mul2(w, etas[mode])
                })
                .collect();
            pool.add(&terms)
        })
        .collect();
    Ok(Some(ClosedForm {
        coords: ode.coords.clone(),
        cases: vec![Case {
            condition: None,
            solution,
            roots,
            constants: Vec::new(),
        }],
        method: Method::Numeric,
        residual: Some(residual),
    }))
}

/// The forcing of every equation grouped as `e^{at} (P_i(t) cos bt + Q_i(t) sin bt)`, with
/// numeric polynomial coefficients.
struct Group {
    rate: Id,
    freq: Id,
    z: C64,
    cos: Vec<Vec<f64>>,
    sin: Vec<Vec<f64>>,
}

/// The forcing's groups, when every coefficient is a number.
fn numeric_groups(pool: &mut Pool, ode: &LinearOde) -> Option<Vec<Group>> {
    let groups = forcing_groups(pool, &ode.forcing).ok()?;
    let mut out = Vec::with_capacity(groups.len());
    for g in groups {
        let mut numbers = |polys: &[Vec<Id>]| -> Option<Vec<Vec<f64>>> {
            polys
                .iter()
                .map(|p| {
                    p.iter()
                        .map(|&c| const_value(pool, c).filter(|v| v.is_finite()))
                        .collect()
                })
                .collect()
        };
        let (cos, sin) = (numbers(&g.cos)?, numbers(&g.sin)?);
        let z = C64::new(const_value(pool, g.rate)?, const_value(pool, g.freq)?);
        out.push(Group {
            rate: g.rate,
            freq: g.freq,
            z,
            cos,
            sin,
        });
    }
    Some(out)
}

/// A particular solution of `η'' + c η' + λ η = Σ_i w_i f_i(t)` by undetermined coefficients,
/// in complex form: for each group, `η_p = Re(e^{zt} R(t))` with `z = a + ib` and
/// `R'' + (2z + c) R' + p(z) R = P - iQ`, `p(r) = r² + c r + λ`; when `z` is a root of `p`
/// (resonance), `R` starts at `t^m`, `m` its multiplicity, and the recurrence skips a level.
fn particular_solution(pool: &mut Pool, groups: &[Group], w: &[f64], lam: f64, damp: f64) -> Id {
    let t = pool.time();
    let mut terms = Vec::new();
    for g in groups {
        let combine = |polys: &[Vec<f64>]| -> Vec<f64> {
            let len = polys.iter().map(Vec::len).max().unwrap_or(0);
            (0..len)
                .map(|j| {
                    polys
                        .iter()
                        .zip(w)
                        .map(|(p, wi)| wi * p.get(j).copied().unwrap_or(0.0))
                        .sum()
                })
                .collect()
        };
        let (p_cos, q_sin) = (combine(&g.cos), combine(&g.sin));
        let deg = p_cos.len().max(q_sin.len());
        if deg == 0 || p_cos.iter().chain(&q_sin).all(|&x| x == 0.0) {
            continue;
        }
        let f: Vec<C64> = (0..deg)
            .map(|j| {
                C64::new(
                    p_cos.get(j).copied().unwrap_or(0.0),
                    -q_sin.get(j).copied().unwrap_or(0.0),
                )
            })
            .collect();
        let z = g.z;
        let c = C64::new(damp, 0.0);
        let p = z.mul(z).add(c.mul(z)).add(C64::new(lam, 0.0));
        let q = z.scale(2.0).add(c);
        let scale = z.abs().powi(2) + damp.abs() * z.abs() + lam.abs() + f64::MIN_POSITIVE;
        let m = if p.abs() > 1e-10 * scale {
            0
        } else if q.abs() > 1e-10 * scale.sqrt() {
            1
        } else {
            2
        };
        let top = deg - 1 + m;
        let mut r = vec![C64::default(); top + 3];
        for i in (0..deg).rev() {
            let fi = f[i];
            let (i1, i2) = ((i + 1) as f64, ((i + 2) * (i + 1)) as f64);
            match m {
                0 => {
                    r[i] = fi
                        .sub(q.mul(r[i + 1]).scale(i1))
                        .sub(r[i + 2].scale(i2))
                        .div(p)
                }
                1 => r[i + 1] = fi.sub(r[i + 2].scale(i2)).div(q.scale(i1)),
                _ => r[i + 2] = fi.scale(1.0 / i2),
            }
        }
        let envelope = if g.rate == Pool::ZERO {
            pool.int(1)
        } else {
            let arg = pool.mul2(g.rate, t);
            pool.call(Func::Exp, &[arg])
        };
        let (cos, sin) = if g.freq == Pool::ZERO {
            (pool.int(1), Pool::ZERO)
        } else {
            let arg = pool.mul2(g.freq, t);
            (pool.call(Func::Cos, &[arg]), pool.call(Func::Sin, &[arg]))
        };
        for (j, rj) in r.iter().enumerate().take(top + 1) {
            if rj.re == 0.0 && rj.im == 0.0 {
                continue;
            }
            let tj = pool.powi(t, j as i64);
            let re = pool.num(Number::Float(rj.re));
            let im = pool.num(Number::Float(-rj.im));
            let wave = [pool.mul2(re, cos), pool.mul2(im, sin)];
            let wave = pool.add(&wave);
            terms.push(pool.mul(&[tj, envelope, wave]));
        }
    }
    pool.add(&terms)
}

/// `η = A φ1 + B φ2 + η_p` with `η(t0) = a`, `η'(t0) = b`, on the basis of the roots of
/// `r² + c r + λ` written in `s = t - t0`; and the roots as text.
fn mode_solution(
    pool: &mut Pool,
    lam: f64,
    damp: f64,
    particular: Id,
    a: f64,
    b: f64,
    t0: Id,
) -> Option<(Id, String)> {
    let t = pool.time();
    let (p0, p1) = if particular == Pool::ZERO {
        (0.0, 0.0)
    } else {
        let at = pool.subs1(particular, t, t0);
        let rate = pool.dt(particular);
        let rate_at = pool.subs1(rate, t, t0);
        (pool.eval_const(at).ok()?, pool.eval_const(rate_at).ok()?)
    };
    let (a, b) = (a - p0, b - p1);
    let s = pool.sub(t, t0);
    let float = |pool: &mut Pool, x: f64| pool.num(Number::Float(x));
    let exp = |pool: &mut Pool, rate: f64| {
        if rate == 0.0 {
            return pool.int(1);
        }
        let r = float(pool, rate);
        let arg = pool.mul2(r, s);
        pool.call(pdyn_expr::Func::Exp, &[arg])
    };
    let disc = damp * damp - 4.0 * lam;
    // `+ 0.0` turns -0 (undamped) into 0 for the printed roots.
    let alpha = -damp / 2.0 + 0.0;
    let scale = damp * damp + 4.0 * lam.abs();
    let (phi1, phi2, ca, cb, root) = if disc.abs() <= 1e-12 * scale {
        // Double root α (a rigid-body mode when λ = c = 0): e^{αs}, s e^{αs}.
        let e = exp(pool, alpha);
        let se = pool.mul2(s, e);
        (e, se, a, b - alpha * a, format!("{alpha} (×2)"))
    } else if disc < 0.0 {
        let omega = (-disc).sqrt() / 2.0;
        let w = float(pool, omega);
        let arg = pool.mul2(w, s);
        let e = exp(pool, alpha);
        let cos = pool.call(pdyn_expr::Func::Cos, &[arg]);
        let sin = pool.call(pdyn_expr::Func::Sin, &[arg]);
        let (c1, c2) = (pool.mul2(e, cos), pool.mul2(e, sin));
        (
            c1,
            c2,
            a,
            (b - alpha * a) / omega,
            format!("{alpha} ± {omega}i"),
        )
    } else {
        let root = disc.sqrt() / 2.0;
        let (r1, r2) = (alpha + root, alpha - root);
        let (e1, e2) = (exp(pool, r1), exp(pool, r2));
        let cb = (b - r1 * a) / (r2 - r1);
        (e1, e2, a - cb, cb, format!("{r1}, {r2}"))
    };
    if !(ca.is_finite() && cb.is_finite()) {
        return None;
    }
    let (ca, cb) = (float(pool, ca), float(pool, cb));
    let terms = [pool.mul2(ca, phi1), pool.mul2(cb, phi2), particular];
    Some((pool.add(&terms), root))
}

/// `[M, C, K]` (coefficients of q'', q', q), when every one is a number.
fn matrices(pool: &mut Pool, ode: &LinearOde) -> Option<[DMatrix<f64>; 3]> {
    let n = ode.coords.len();
    let mut out = [
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
    ];
    for i in 0..n {
        for j in 0..n {
            for (order, &e) in ode.coeffs[i][j].iter().enumerate() {
                let v = const_value(pool, e)?;
                if !v.is_finite() {
                    return None;
                }
                out[2 - order][(i, j)] = v;
            }
        }
    }
    Some(out)
}

/// Positive factors `d_i`, one per equation, that make `diag(d) K` and `diag(d) M` symmetric;
/// `None` when there are none.
fn symmetrising_scale(m: &DMatrix<f64>, k: &DMatrix<f64>, c: &DMatrix<f64>) -> Option<Vec<f64>> {
    let n = m.nrows();
    let mut d = vec![0.0f64; n];
    // The couplings of each equation, through whichever matrix has them.
    let coupling = |i: usize, j: usize| -> Option<f64> {
        [k, m, c]
            .iter()
            .map(|a| (a[(i, j)], a[(j, i)]))
            .find(|(a, b)| *a != 0.0 || *b != 0.0)
            .map(|(a, b)| if b == 0.0 { f64::NAN } else { a / b })
    };
    for start in 0..n {
        if d[start] != 0.0 {
            continue;
        }
        d[start] = 1.0;
        let mut stack = vec![start];
        while let Some(i) = stack.pop() {
            for j in 0..n {
                if j == i {
                    continue;
                }
                if let Some(ratio) = coupling(i, j) {
                    // d_i a_ij = d_j a_ji.
                    let dj = d[i] * ratio;
                    if !(dj.is_finite() && dj > 0.0) {
                        return None;
                    }
                    if d[j] == 0.0 {
                        d[j] = dj;
                        stack.push(j);
                    }
                }
            }
        }
    }
    for a in [m, k, c] {
        let big = a.amax();
        for i in 0..n {
            for j in i + 1..n {
                if (d[i] * a[(i, j)] - d[j] * a[(j, i)]).abs()
                    > SYMMETRY_TOLERANCE * big * d[i].max(d[j])
                {
                    return None;
                }
            }
        }
    }
    Some(d)
}

/// Every coordinate's value and rate at `t0`, when all are given as numbers.
fn initial_values(
    pool: &mut Pool,
    ode: &LinearOde,
    ics: &[InitialCondition],
) -> Option<(Vec<f64>, Vec<f64>)> {
    let mut q0 = Vec::with_capacity(ode.coords.len());
    let mut v0 = Vec::with_capacity(ode.coords.len());
    for &c in &ode.coords {
        for (order, out) in [(0u8, &mut q0), (1u8, &mut v0)] {
            let ic = ics.iter().find(|ic| ic.coord == c && ic.order == order)?;
            out.push(const_value(pool, ic.value)?);
        }
    }
    Some((q0, v0))
}
