//! **BDF** — variable-order (1–5), variable-step backward differentiation formulas in
//! quasi-constant step-size form, with the numerical differentiation formula (NDF)
//! coefficients of MATLAB's `ode15s`: the algorithm of SciPy's `BDF` solver. Implicit,
//! adaptive, for stiff problems. Not symplectic.
//!
//! L. F. Shampine, M. W. Reichelt, "The MATLAB ODE Suite", SIAM J. Sci. Comput. 18(1), 1997,
//! §2 (the NDFs and their implementation with backward differences); SciPy's
//! `scipy.integrate.BDF` documentation.
//!
//! * The solution is carried as backward differences `D[0] = y_n`, `D[j] = ∇^j y_n` (scaled to
//!   the current step `h`). The predictor is `Σ_{j≤k} D[j]`; the order-`k` NDF
//!   `Σ_{j=1..k} γ_j ∇^j y_{n+1} − κ γ_k (y_{n+1} − y⁽⁰⁾) = h f(t_{n+1}, y_{n+1})`, with
//!   `γ_j = Σ_{i≤j} 1/i`, `α_k = (1 − κ_k) γ_k` and `κ = (0, −0.1850, −1/9, −0.0823, −0.0415)`,
//!   is solved for the correction `d = y_{n+1} − y⁽⁰⁾` by simplified Newton with the iteration
//!   matrix `I − h/α_k · J` (at most 4 iterations, stopped on the contraction rate as SciPy
//!   does, with tolerance `max(10ε/rtol, min(0.03, √rtol))`).
//! * Jacobian and LU reuse: `J` is kept across steps and recomputed only when Newton fails to
//!   converge with a `J` that is not current; the LU of `I − cJ` is kept while `c` is
//!   unchanged (a step-size or order change refactors). `J` is analytic when
//!   [`OdeSystem::has_jacobian`], else forward differences ([`crate::jacobian`], grouped by
//!   [`Options::jac_sparsity`] when given). `I − cJ` is factored densely, or by the sparse
//!   LU when the pattern is known and the system large ([`crate::LinearSolver`], as Radau5
//!   and SciPy's `BDF` with `jac_sparsity`): `methods/bdf_linear.rs`.
//! * A change of step size by `ρ` rescales the differences (`D ← (R(ρ) U)ᵀ D`, with
//!   `R(ρ)_{ij} = Π_{m≤i} (m − 1 − ρ j)/m`, `U = R(1)`): the same interpolating polynomial on
//!   the new grid. Newton failure halves the step.
//! * Error `‖C_k d‖` with `C_k = κ_k γ_k + 1/(k + 1)`, in the RMS norm over components of
//!   `err_i / (atol_i + rtol_i |y_{n+1,i}|)` (SciPy's); a rejected step shrinks by
//!   `max(0.2, safety · err^{−1/(k+1)})`, `safety = 0.9 (2·4 + 1)/(2·4 + iterations)`.
//!   After `k + 1` steps of equal size, orders `k − 1`, `k`, `k + 1` are compared by their
//!   estimated errors and the step grows by at most 10.
//! * The first step is SciPy's `select_initial_step` (RMS norms, exponent 1/2), not Hairer's
//!   `HINIT` (sums, exponent 1 at order 1): on a smooth stiff decay Hairer's started 10⁷ times
//!   smaller and took 15 more steps than SciPy to grow back.
//! * Dense output: the method's own interpolating polynomial through the last `k + 1`
//!   solution values (`D` after the step), evaluated as SciPy's `BdfDenseOutput`.
//!
//! Statistics: `steps` counts attempts (accepted, rejected by the error test, and those
//! abandoned because Newton did not converge), `rejected` the error-test rejections,
//! `jacobians` the Jacobian evaluations (one at the start), `lu_decompositions` the
//! factorizations, `linear_solves` the Newton iterations, `fevals` every evaluation of `f`
//! (the first-step estimate's and the finite-difference Jacobians' included).

use super::bdf_linear::BdfMatrix;
use crate::controller::scipy_initial_step;
use crate::dense::{DenseSolution, Interpolant};
use crate::error::{point, OdeError};
use crate::events::{DenseOutput, Event, EventState, Output};
use crate::explicit::setup;
use crate::jacobian::FdJacobian;
use crate::options::Options;
use crate::problem::OdeSystem;
use crate::solution::{Solution, Status};
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "variable-order (1-5) variable-step BDF in quasi-constant step-size \
form with the NDF coefficients of MATLAB's ode15s (SciPy's BDF): simplified Newton, Jacobian \
and LU reused across steps; for stiff problems. Shampine & Reichelt 1997.";

/// Highest order.
const MAX_ORDER: usize = 5;
/// Newton iterations per attempt.
const NEWTON_MAXITER: usize = 4;
/// Smallest factor a rejected step shrinks by.
const MIN_FACTOR: f64 = 0.2;
/// Largest factor a step grows by at an order decision.
const MAX_FACTOR: f64 = 10.0;
/// Newton failures with a singular iteration matrix in a row before giving up.
const MAX_SINGULAR: usize = 5;

/// The NDF coefficients κ_k (Shampine & Reichelt 1997, Table 1; κ_5 = 0: plain BDF5).
const KAPPA: [f64; MAX_ORDER + 1] = [0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0];

/// `γ_k`, `α_k` and the error constants `C_k` of orders 0..=5.
struct Coefficients {
    gamma: [f64; MAX_ORDER + 1],
    alpha: [f64; MAX_ORDER + 1],
    error_const: [f64; MAX_ORDER + 1],
}

impl Coefficients {
    fn new() -> Self {
        let mut gamma = [0.0; MAX_ORDER + 1];
        for k in 1..=MAX_ORDER {
            gamma[k] = gamma[k - 1] + 1.0 / k as f64;
        }
        let mut alpha = [0.0; MAX_ORDER + 1];
        let mut error_const = [0.0; MAX_ORDER + 1];
        for k in 0..=MAX_ORDER {
            alpha[k] = (1.0 - KAPPA[k]) * gamma[k];
            error_const[k] = KAPPA[k] * gamma[k] + 1.0 / (k + 1) as f64;
        }
        Coefficients {
            gamma,
            alpha,
            error_const,
        }
    }
}

/// `R(ρ)` of order `k` ((k+1) × (k+1), row-major): `R_00 = 1`, row 0 ones, and below
/// `R_ij = Π_{m=1..i} (m − 1 − ρ j)/m`.
fn step_change_matrix(order: usize, factor: f64, r: &mut [f64]) {
    let m = order + 1;
    for j in 0..m {
        r[j] = 1.0;
    }
    for i in 1..m {
        for j in 0..m {
            let term = if j == 0 {
                0.0
            } else {
                (i as f64 - 1.0 - factor * j as f64) / i as f64
            };
            r[i * m + j] = r[(i - 1) * m + j] * term;
        }
    }
}

/// The backward differences and the scratch space of their rescaling.
struct Differences {
    n: usize,
    /// `MAX_ORDER + 3` rows of `n`: `D[0..=k]` the interpolant, `D[k+1]`, `D[k+2]` the last
    /// correction and its difference (for the order decision).
    d: Vec<f64>,
    r: Vec<f64>,
    u: Vec<f64>,
    ru: Vec<f64>,
    tmp: Vec<f64>,
}

impl Differences {
    fn new(n: usize) -> Self {
        let m = MAX_ORDER + 1;
        Differences {
            n,
            d: vec![0.0; (MAX_ORDER + 3) * n],
            r: vec![0.0; m * m],
            u: vec![0.0; m * m],
            ru: vec![0.0; m * m],
            tmp: vec![0.0; m * n],
        }
    }

    fn row(&self, j: usize) -> &[f64] {
        &self.d[j * self.n..(j + 1) * self.n]
    }

    fn row_mut(&mut self, j: usize) -> &mut [f64] {
        &mut self.d[j * self.n..(j + 1) * self.n]
    }

    /// Rescales `D[0..=order]` for a step multiplied by `factor`: `D ← (R U)ᵀ D`.
    fn change_step(&mut self, order: usize, factor: f64) {
        let m = order + 1;
        let n = self.n;
        step_change_matrix(order, factor, &mut self.r);
        step_change_matrix(order, 1.0, &mut self.u);
        for i in 0..m {
            for j in 0..m {
                self.ru[i * m + j] = (0..m).map(|l| self.r[i * m + l] * self.u[l * m + j]).sum();
            }
        }
        // new D[j] = Σ_i (RU)_{ij} D[i]
        for j in 0..m {
            let out = &mut self.tmp[j * n..(j + 1) * n];
            out.fill(0.0);
            for i in 0..m {
                let c = self.ru[i * m + j];
                let di = &self.d[i * n..(i + 1) * n];
                for (o, x) in out.iter_mut().zip(di) {
                    *o += c * x;
                }
            }
        }
        self.d[..m * n].copy_from_slice(&self.tmp[..m * n]);
    }
}

/// The interpolating polynomial of the last step: `D[0..=order]` after it, the step's end
/// `t` and its size `h` (SciPy's `BdfDenseOutput`).
struct BdfDense {
    n: usize,
    order: usize,
    t: f64,
    h: f64,
    /// `D[0..=order]`, `(order + 1) · n` values.
    coeffs: Vec<f64>,
}

impl DenseOutput for BdfDense {
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        eval_cont(&self.coeffs, self.n, self.order, (t - self.t) / self.h, out);
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut DenseSolution) {
        let kind = Interpolant::Bdf {
            order: self.order as u8,
        };
        let m = (self.order + 1) * self.n;
        into.push(t_from, t_to, kind, self.t, self.h, &[&self.coeffs[..m]]);
    }
}

/// The interpolant at `s = (t − t_n)/h`: `D[0] + Σ_{j=1..k} D[j] Π_{m<j} (s + m)/(m + 1)`
/// (the Newton form on the points `t_n, t_n − h, …`), `c` holding `D[0..=k]`.
#[inline]
pub(crate) fn eval_cont(c: &[f64], n: usize, order: usize, s: f64, out: &mut [f64]) {
    out.copy_from_slice(&c[..n]);
    let mut p = 1.0;
    for j in 1..=order {
        p *= (s + (j - 1) as f64) / j as f64;
        let dj = &c[j * n..(j + 1) * n];
        for (o, x) in out.iter_mut().zip(dj) {
            *o += p * x;
        }
    }
}

/// The RMS norm of `v_i / scale_i`.
fn norm(v: &[f64], scale: &[f64]) -> f64 {
    let s: f64 = v.iter().zip(scale).map(|(a, b)| (a / b) * (a / b)).sum();
    (s / v.len() as f64).sqrt()
}

/// The iteration matrix's factors, valid for one `c = h/α_k`.
struct IterationMatrix {
    /// `J` and the factors of `I − c·J`, dense or sparse.
    matrix: BdfMatrix,
    valid: bool,
}

/// Result of one Newton solve.
struct Newton {
    converged: bool,
    iterations: usize,
}

/// Integrates with BDF.
pub(crate) fn integrate<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    y_init: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let su = setup(sys, t0, tf, y_init, opts)?;
    let n = su.n;
    // Checks the pattern against the system before anything is evaluated.
    let matrix = BdfMatrix::new(sys, opts, n)?;
    let dir = su.dir;
    let (atol, rtol) = (&su.atol, &su.rtol);
    let co = Coefficients::new();
    let rtol_min = rtol.iter().copied().fold(f64::INFINITY, f64::min);
    let newton_tol = (10.0 * f64::EPSILON / rtol_min).max(0.03f64.min(rtol_min.sqrt()));
    let hmax = su.hmax;

    let mut sol = Solution::new(Method::Bdf, n);
    sol.stats.sparse_lu = matrix.is_sparse();
    if opts.dense_output {
        sol.dense = Some(DenseSolution::new(n));
    }
    let mut out = Output::new(opts, dir);
    out.start(&mut sol, t0, y_init);
    if t0 == tf {
        return Ok(sol);
    }
    let mut ev = EventState::new(events, n, t0, y_init);

    let mut t = t0;
    let mut y = y_init.to_vec();
    let mut f = vec![0.0; n];
    sys.rhs(t, &y, &mut f);
    sol.stats.fevals += 1;
    let mut h_abs = match opts.h0 {
        Some(h0) => h0.abs().min(hmax).min((tf - t0).abs()),
        None => {
            let (mut y1, mut f1) = (vec![0.0; n], vec![0.0; n]);
            sol.stats.fevals += 1;
            // SciPy's estimate, as SciPy's BDF takes it (error estimator of order 1).
            scipy_initial_step(
                sys,
                t0,
                &y,
                &f,
                dir,
                1,
                (tf - t0).abs(),
                hmax,
                atol,
                rtol,
                &mut y1,
                &mut f1,
            )
        }
    };
    let mut d = Differences::new(n);
    d.row_mut(0).copy_from_slice(&y);
    for (x, fi) in d.row_mut(1).iter_mut().zip(&f) {
        *x = fi * h_abs * dir;
    }
    let mut order = 1usize;
    let mut n_equal_steps = 0usize;

    let mut fd = FdJacobian::default();
    let mut jacobian = |m: &mut BdfMatrix, t: f64, y: &[f64], f0: &[f64], sol: &mut Solution| {
        sol.stats.jacobians += 1;
        m.jacobian(sys, opts, &mut fd, t, y, f0, &mut sol.stats);
    };
    let mut itm = IterationMatrix {
        matrix,
        valid: false,
    };
    jacobian(&mut itm.matrix, t, &y, &f, &mut sol);

    let mut y_predict = vec![0.0; n];
    let mut y_new = vec![0.0; n];
    let mut scale = vec![0.0; n];
    let mut psi = vec![0.0; n];
    let mut corr = vec![0.0; n];
    let mut dy = vec![0.0; n];
    let mut ytmp = vec![0.0; n];
    let mut dense = BdfDense {
        n,
        order,
        t,
        h: h_abs * dir,
        coeffs: vec![0.0; (MAX_ORDER + 1) * n],
    };
    let mut nstep = 0usize;
    let mut singular_in_row = 0usize;
    // A step of size min_step was tried since the last accepted step.
    let mut tried_min = false;

    loop {
        // The smallest step that still moves t: ten units in the last place of t (SciPy's).
        let ulp_step = 10.0 * (next_toward(t, dir * f64::INFINITY) - t).abs();
        let min_step = ulp_step.max(su.hmin);
        if h_abs > hmax {
            d.change_step(order, hmax / h_abs);
            h_abs = hmax;
            n_equal_steps = 0;
            itm.valid = false;
        } else if h_abs < min_step {
            d.change_step(order, min_step / h_abs);
            h_abs = min_step;
            n_equal_steps = 0;
            itm.valid = false;
        }
        // The Jacobian is current while it was evaluated at this step's predicted state.
        let mut current_jac = false;
        let (t_new, safety, error_norm) = loop {
            if opts.interrupted() {
                return Err(OdeError::Interrupted {
                    at: point(t, &y, &mut sol),
                });
            }
            if nstep >= opts.max_steps {
                return Err(OdeError::MaxSteps {
                    max_steps: opts.max_steps,
                    at: point(t, &y, &mut sol),
                });
            }
            if h_abs < min_step * (1.0 - 1e-12) || !h_abs.is_finite() {
                if su.hmin > ulp_step {
                    return Err(OdeError::MinStep {
                        min_step: su.hmin,
                        at: point(t, &y, &mut sol),
                    });
                }
                return Err(OdeError::StepSizeUnderflow {
                    h: h_abs * dir,
                    at: point(t, &y, &mut sol),
                });
            }
            nstep += 1;
            sol.stats.steps += 1;
            let mut t_new = t + h_abs * dir;
            if dir * (t_new - tf) > 0.0 || (tf - t_new).abs() <= ulp_step {
                t_new = tf;
                d.change_step(order, (t_new - t).abs() / h_abs);
                n_equal_steps = 0;
                itm.valid = false;
            }
            let h = t_new - t;
            h_abs = h.abs();
            y_predict.fill(0.0);
            for j in 0..=order {
                for (p, x) in y_predict.iter_mut().zip(d.row(j)) {
                    *p += x;
                }
            }
            for i in 0..n {
                scale[i] = atol[i] + rtol[i] * y_predict[i].abs();
            }
            psi.fill(0.0);
            for j in 1..=order {
                let g = co.gamma[j];
                for (p, x) in psi.iter_mut().zip(d.row(j)) {
                    *p += g * x;
                }
            }
            let alpha = co.alpha[order];
            for p in psi.iter_mut() {
                *p /= alpha;
            }
            let c = h / alpha;
            let newton = loop {
                if !itm.valid {
                    sol.stats.lu_decompositions += 1;
                    if !itm.matrix.factor(c) {
                        singular_in_row += 1;
                        if singular_in_row >= MAX_SINGULAR {
                            return Err(OdeError::SingularMatrix {
                                at: point(t, &y, &mut sol),
                            });
                        }
                        break Newton {
                            converged: false,
                            iterations: 0,
                        };
                    }
                    singular_in_row = 0;
                    itm.valid = true;
                }
                let nw = solve_corrector(
                    sys,
                    t_new,
                    &y_predict,
                    c,
                    &psi,
                    &mut itm.matrix,
                    &scale,
                    newton_tol,
                    (&mut y_new, &mut corr, &mut f, &mut dy),
                    &mut sol,
                );
                if nw.converged || current_jac {
                    break nw;
                }
                // Newton failed with an old Jacobian: a fresh one at the predicted state.
                if !sys.has_jacobian() {
                    sys.rhs(t_new, &y_predict, &mut ytmp);
                    sol.stats.fevals += 1;
                }
                jacobian(&mut itm.matrix, t_new, &y_predict, &ytmp, &mut sol);
                itm.valid = false;
                current_jac = true;
            };
            if !newton.converged {
                let factor = 0.5;
                if h_abs * factor < su.hmin && su.hmin > ulp_step {
                    if tried_min {
                        return Err(OdeError::MinStep {
                            min_step: su.hmin,
                            at: point(t, &y, &mut sol),
                        });
                    }
                    tried_min = true;
                    d.change_step(order, su.hmin / h_abs);
                    h_abs = su.hmin;
                } else {
                    h_abs *= factor;
                    d.change_step(order, factor);
                }
                n_equal_steps = 0;
                itm.valid = false;
                continue;
            }
            let safety = 0.9 * (2 * NEWTON_MAXITER + 1) as f64
                / (2 * NEWTON_MAXITER + newton.iterations) as f64;
            for i in 0..n {
                scale[i] = atol[i] + rtol[i] * y_new[i].abs();
            }
            let ec = co.error_const[order];
            let error_norm = norm_scaled(&corr, ec, &scale);
            if error_norm > 1.0 {
                sol.stats.rejected += 1;
                let mut factor =
                    MIN_FACTOR.max(safety * libm::pow(error_norm, -1.0 / (order + 1) as f64));
                if h_abs * factor < su.hmin && su.hmin > ulp_step {
                    if tried_min {
                        return Err(OdeError::MinStep {
                            min_step: su.hmin,
                            at: point(t, &y, &mut sol),
                        });
                    }
                    tried_min = true;
                    factor = su.hmin / h_abs;
                }
                h_abs *= factor;
                d.change_step(order, factor);
                n_equal_steps = 0;
                // Newton converged: the factors stay (as SciPy keeps them).
                continue;
            }
            break (t_new, safety, error_norm);
        };
        tried_min = false;
        sol.stats.accepted += 1;
        n_equal_steps += 1;
        let t_old = t;
        t = t_new;
        y.copy_from_slice(&y_new);
        if y.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite {
                at: point(t_old, &y, &mut sol),
            });
        }
        // The differences of the new point: D[k+2] = d − D[k+1], D[k+1] = d, and
        // D[j] += D[j+1] from j = k down to 0.
        for i in 0..n {
            let dk1 = d.d[(order + 1) * n + i];
            d.d[(order + 2) * n + i] = corr[i] - dk1;
            d.d[(order + 1) * n + i] = corr[i];
        }
        for j in (0..=order).rev() {
            for i in 0..n {
                d.d[j * n + i] += d.d[(j + 1) * n + i];
            }
        }
        // After k + 1 steps of equal size:
        if n_equal_steps > order {
            // Orders k − 1, k, k + 1 by their estimated errors, in the norm of this step.
            let error_m = if order > 1 {
                norm_scaled(d.row(order), co.error_const[order - 1], &scale)
            } else {
                f64::INFINITY
            };
            let error_p = if order < MAX_ORDER {
                norm_scaled(d.row(order + 2), co.error_const[order + 1], &scale)
            } else {
                f64::INFINITY
            };
            let factors = [
                factor_of(error_m, order),
                factor_of(error_norm, order + 1),
                factor_of(error_p, order + 2),
            ];
            // The first largest, as NumPy's argmax.
            let mut best = 0;
            for (k, &v) in factors.iter().enumerate() {
                if v > factors[best] {
                    best = k;
                }
            }
            order = order + best - 1;
            let factor = MAX_FACTOR.min(safety * factors[best]);
            h_abs *= factor;
            d.change_step(order, factor);
            n_equal_steps = 0;
            itm.valid = false;
        }
        dense.order = order;
        dense.t = t;
        dense.h = h_abs * dir;
        dense.coeffs[..(order + 1) * n].copy_from_slice(&d.d[..(order + 1) * n]);
        let crossed = !events.is_empty() && ev.check(t, &y);
        let stop = if crossed {
            ev.locate(&dense, t_old, t, &mut sol.events)
        } else {
            None
        };
        if let Some(ds) = sol.dense.as_mut() {
            dense.record(t_old, stop.map_or(t, |s| s.0), ds);
        }
        ev.drain_suspects(&mut sol.possible_misses);
        out.emit(&mut sol, &dense, t, &y, stop.map(|s| s.0), &mut ytmp);
        if let Some((_, idx)) = stop {
            sol.status = Status::TerminalEvent(idx);
            return Ok(sol);
        }
        if t == tf {
            return Ok(sol);
        }
    }
}

/// `‖c · v‖` in the RMS norm with `scale`.
fn norm_scaled(v: &[f64], c: f64, scale: &[f64]) -> f64 {
    let s: f64 = v
        .iter()
        .zip(scale)
        .map(|(a, b)| (c * a / b) * (c * a / b))
        .sum();
    (s / v.len() as f64).sqrt()
}

/// The step factor an error norm allows at an order: `err^{−1/(order)}`, infinite for a
/// zero error (NumPy's `0 ** −x`), zero for an infinite one.
fn factor_of(err: f64, exponent: usize) -> f64 {
    if err == 0.0 {
        f64::INFINITY
    } else {
        libm::pow(err, -1.0 / exponent as f64)
    }
}

/// The next representable number after `x` toward `to`.
fn next_toward(x: f64, to: f64) -> f64 {
    if x.is_nan() || x == to {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1).copysign(to);
    }
    let bits = x.to_bits();
    let up = (to > x) == (x > 0.0);
    f64::from_bits(if up { bits + 1 } else { bits - 1 })
}

/// Simplified Newton on `c f(t_new, y_pred + d) − ψ − d = 0` for the correction `d` (`corr`),
/// the new state in `y_new`; stops when the predicted remaining error is below `tol` or the
/// iteration diverges (SciPy's test on the contraction rate).
#[allow(clippy::too_many_arguments)]
fn solve_corrector<S: OdeSystem + ?Sized>(
    sys: &S,
    t_new: f64,
    y_predict: &[f64],
    c: f64,
    psi: &[f64],
    matrix: &mut BdfMatrix,
    scale: &[f64],
    tol: f64,
    (y_new, corr, f, dy): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
    sol: &mut Solution,
) -> Newton {
    y_new.copy_from_slice(y_predict);
    corr.fill(0.0);
    let mut dy_norm_old: Option<f64> = None;
    let mut k = 0;
    while k < NEWTON_MAXITER {
        sys.rhs(t_new, y_new, f);
        sol.stats.fevals += 1;
        if f.iter().any(|v| !v.is_finite()) {
            break;
        }
        for i in 0..dy.len() {
            dy[i] = c * f[i] - psi[i] - corr[i];
        }
        matrix.solve_in_place(dy);
        sol.stats.linear_solves += 1;
        let dy_norm = norm(dy, scale);
        let rate = dy_norm_old.map(|old| dy_norm / old);
        if let Some(r) = rate {
            if r >= 1.0 || libm::pow(r, (NEWTON_MAXITER - k) as f64) / (1.0 - r) * dy_norm > tol {
                break;
            }
        }
        for i in 0..dy.len() {
            y_new[i] += dy[i];
            corr[i] += dy[i];
        }
        if dy_norm == 0.0 || rate.is_some_and(|r| r / (1.0 - r) * dy_norm < tol) {
            return Newton {
                converged: true,
                iterations: k + 1,
            };
        }
        dy_norm_old = Some(dy_norm);
        k += 1;
    }
    Newton {
        converged: false,
        iterations: k + 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_are_the_ndf_ones() {
        let co = Coefficients::new();
        // γ_k = Σ 1/j; α_1 = 1 − κ_1 = 1.185; C_1 = κ_1 + 1/2 = 0.315 (Shampine & Reichelt).
        assert!((co.gamma[3] - (1.0 + 0.5 + 1.0 / 3.0)).abs() < 1e-15);
        assert!((co.alpha[1] - 1.185).abs() < 1e-15);
        assert!((co.error_const[1] - 0.315).abs() < 1e-15);
        // BDF5 (κ_5 = 0): the classical error constant 1/6.
        assert!((co.error_const[5] - 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn rescaling_the_differences_keeps_the_polynomial() {
        // Differences of the cubic p(t) = 1 + 2t − t² + 0.5t³ sampled at t = 0, −h, −2h, −3h.
        let (n, order, h) = (1, 3, 0.1);
        let p = |t: f64| 1.0 + 2.0 * t - t * t + 0.5 * t * t * t;
        let vals: Vec<f64> = (0..=order).map(|j| p(-(j as f64) * h)).collect();
        let mut d = Differences::new(n);
        // Backward differences ∇^j p(0).
        let mut cur = vals.clone();
        for j in 0..=order {
            d.d[j] = cur[0];
            cur = cur.windows(2).map(|w| w[0] - w[1]).collect();
        }
        let mut before = [0.0];
        let mut after = [0.0];
        let coeffs = d.d[..=order].to_vec();
        d.change_step(order, 0.37);
        let rescaled = d.d[..=order].to_vec();
        for &t in &[-0.25, -0.1, 0.0, 0.05] {
            eval_cont(&coeffs, n, order, t / h, &mut before);
            eval_cont(&rescaled, n, order, t / (0.37 * h), &mut after);
            assert!((before[0] - p(t)).abs() < 1e-12, "{t}");
            assert!((after[0] - p(t)).abs() < 1e-12, "{t}");
        }
    }

    #[test]
    fn next_toward_steps_one_ulp() {
        assert_eq!(next_toward(1.0, 2.0), 1.0 + f64::EPSILON);
        assert_eq!(next_toward(-1.0, f64::INFINITY), -1.0 + f64::EPSILON / 2.0);
        assert!(next_toward(0.0, -1.0) < 0.0);
    }
}
