//! Levenberg–Marquardt with bounds: minimises `½ |r(x)|²` over the box `lo ≤ x ≤ hi`.
//!
//! Each iteration solves the damped linear least-squares problem
//! `min |J δ + r|² + λ |D δ|²` (Levenberg 1944, Marquardt 1963), with Moré's (1978) scaling
//! `D = diag(max over iterations of the column norms of J)`, by the SVD of `J D⁻¹`
//! ([`Svd::damped_solve`]). The step is projected onto the box (a bound that would be crossed
//! stops the parameter at it), and a parameter at a bound that the gradient pushes outward is
//! held there (left out of the step: an active set). The gain ratio `ρ = actual / predicted reduction` accepts the
//! step when `ρ > 10⁻⁴` and updates `λ` by Nielsen's rule (1999): `λ ← λ max(1/3,
//! 1 − (2ρ − 1)³)` after a success, `λ ← ν λ, ν ← 2ν` after a failure. A residual that cannot be
//! evaluated (an integration that fails at a wild trial point) counts as a failed step.
//!
//! Stopping, as MINPACK and SciPy's `least_squares` state it: `gtol` on the largest cosine
//! between `r` and a column of `J` (components pushing out of the box at an active bound left
//! out), `ftol` on the relative reduction of the cost (actual and predicted), `xtol` on the
//! scaled step relative to the scaled parameters.

use super::svd::Svd;

/// The settings of [`minimize`]; defaults in one `impl Default`.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Stop when the relative reduction of the cost, actual and predicted, is below this.
    pub ftol: f64,
    /// Stop when the scaled step is below `xtol` (|D x| + xtol).
    pub xtol: f64,
    /// Stop when every column of `J` is within this cosine of orthogonal to `r`.
    pub gtol: f64,
    /// At most this many evaluations of `r` and `J`.
    pub max_evaluations: usize,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            ftol: 1e-12,
            xtol: 1e-12,
            gtol: 1e-12,
            max_evaluations: 200,
        }
    }
}

/// Why the minimisation stopped (SciPy's `status` codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// The evaluation budget ran out (0).
    MaxEvaluations,
    /// `gtol` satisfied (1).
    Gradient,
    /// `ftol` satisfied (2).
    Cost,
    /// `xtol` satisfied (3).
    Step,
}

impl Status {
    /// SciPy's code.
    pub fn code(self) -> i32 {
        match self {
            Status::MaxEvaluations => 0,
            Status::Gradient => 1,
            Status::Cost => 2,
            Status::Step => 3,
        }
    }

    /// SciPy's message.
    pub fn message(self) -> &'static str {
        match self {
            Status::MaxEvaluations => "The maximum number of function evaluations is exceeded.",
            Status::Gradient => "`gtol` termination condition is satisfied.",
            Status::Cost => "`ftol` termination condition is satisfied.",
            Status::Step => "`xtol` termination condition is satisfied.",
        }
    }

    /// Whether the minimum was reached (not the budget).
    pub fn converged(self) -> bool {
        self != Status::MaxEvaluations
    }
}

/// Residuals and their Jacobian evaluated together (the sensitivity equations give both from
/// one integration).
pub trait Residuals {
    /// The error of an evaluation that cannot be done.
    type Error;
    /// Number of residuals `m`.
    fn n_residuals(&self) -> usize;
    /// Writes `r(x)` (length `m`) and `J(x)` column-major (`m × n`).
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: &mut [f64]) -> Result<(), Self::Error>;
}

/// The minimum found.
#[derive(Clone, Debug)]
pub struct Minimum {
    /// The parameters.
    pub x: Vec<f64>,
    /// The residuals there.
    pub r: Vec<f64>,
    /// The Jacobian there, column-major.
    pub jac: Vec<f64>,
    /// `½ |r|²`.
    pub cost: f64,
    /// Why it stopped.
    pub status: Status,
    /// Evaluations of `r` and `J`.
    pub evaluations: usize,
    /// Iterations (accepted steps).
    pub iterations: usize,
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

/// Minimises `½ |f(x)|²` from `x0` within `[lo, hi]` (each may be infinite). An error of the
/// first evaluation is returned; later ones reject the trial step.
pub fn minimize<F: Residuals>(
    f: &mut F,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    s: &Settings,
) -> Result<Minimum, F::Error> {
    let n = x0.len();
    let m = f.n_residuals();
    let clamp = |x: &mut [f64]| {
        for i in 0..n {
            x[i] = x[i].max(lo[i]).min(hi[i]);
        }
    };
    let mut x = x0.to_vec();
    clamp(&mut x);
    let mut r = vec![0.0; m];
    let mut jac = vec![0.0; m * n];
    f.eval(&x, &mut r, &mut jac)?;
    let mut evaluations = 1;
    let (mut r_new, mut jac_new) = (r.clone(), jac.clone());
    let mut d = vec![0.0f64; n];
    let mut lambda = -1.0;
    let mut nu = 2.0;
    let mut iterations = 0;
    let mut scaled = vec![0.0; m * n];
    let status = 'outer: loop {
        let rr = norm2(&r);
        for k in 0..n {
            let c = norm2(&jac[k * m..(k + 1) * m]).sqrt();
            d[k] = d[k].max(c);
            if d[k] == 0.0 {
                d[k] = 1.0;
            }
        }
        // gtol: the cosine between r and each column of J, at an active bound only inward.
        let mut gmax: f64 = 0.0;
        for k in 0..n {
            let col = &jac[k * m..(k + 1) * m];
            let g: f64 = col.iter().zip(&r).map(|(a, b)| a * b).sum();
            let blocked = (x[k] <= lo[k] && g > 0.0) || (x[k] >= hi[k] && g < 0.0);
            let cn = norm2(col).sqrt();
            if !blocked && cn > 0.0 && rr > 0.0 {
                gmax = gmax.max(g.abs() / (cn * rr.sqrt()));
            }
        }
        if gmax <= s.gtol {
            break Status::Gradient;
        }
        // A parameter at a bound that the gradient pushes outward is held there: its column
        // is left out of the step (the active set).
        for k in 0..n {
            let col = &jac[k * m..(k + 1) * m];
            let g: f64 = col.iter().zip(&r).map(|(a, b)| a * b).sum();
            let held = (x[k] <= lo[k] && g > 0.0) || (x[k] >= hi[k] && g < 0.0);
            for i in 0..m {
                scaled[k * m + i] = if held { 0.0 } else { jac[k * m + i] / d[k] };
            }
        }
        let svd = Svd::new(&scaled, m, n);
        if lambda < 0.0 {
            lambda = 1e-3 * svd.max().powi(2);
        }
        loop {
            if evaluations >= s.max_evaluations {
                break 'outer Status::MaxEvaluations;
            }
            let ds = svd.damped_solve(&r, lambda, 0.0);
            let mut x_new: Vec<f64> = (0..n).map(|k| x[k] + ds[k] / d[k]).collect();
            clamp(&mut x_new);
            let step: Vec<f64> = (0..n).map(|k| x_new[k] - x[k]).collect();
            let step_norm = (0..n).map(|k| (d[k] * step[k]).powi(2)).sum::<f64>().sqrt();
            let x_norm = (0..n).map(|k| (d[k] * x[k]).powi(2)).sum::<f64>().sqrt();
            if step_norm <= s.xtol * (x_norm + s.xtol) {
                break 'outer Status::Step;
            }
            // |r + J step|²
            let mut lin = r.clone();
            for k in 0..n {
                for i in 0..m {
                    lin[i] += jac[k * m + i] * step[k];
                }
            }
            let predicted = rr - norm2(&lin);
            evaluations += 1;
            let ok = f.eval(&x_new, &mut r_new, &mut jac_new).is_ok();
            let rr_new = norm2(&r_new);
            let actual = if ok && rr_new.is_finite() {
                rr - rr_new
            } else {
                f64::NEG_INFINITY
            };
            let rho = if predicted > 0.0 {
                actual / predicted
            } else {
                -1.0
            };
            if rho > 1e-4 {
                x = x_new;
                std::mem::swap(&mut r, &mut r_new);
                std::mem::swap(&mut jac, &mut jac_new);
                iterations += 1;
                lambda *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
                nu = 2.0;
                if actual <= s.ftol * rr && predicted <= s.ftol * rr {
                    break 'outer Status::Cost;
                }
                continue 'outer;
            }
            if predicted <= s.ftol * rr && actual.abs() <= s.ftol * rr {
                break 'outer Status::Cost;
            }
            lambda *= nu;
            nu *= 2.0;
        }
    };
    let cost = 0.5 * norm2(&r);
    Ok(Minimum {
        x,
        r,
        jac,
        cost,
        status,
        evaluations,
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as least squares: r = (10 (x₂ − x₁²), 1 − x₁), minimum at (1, 1).
    struct Rosenbrock;
    impl Residuals for Rosenbrock {
        type Error = ();
        fn n_residuals(&self) -> usize {
            2
        }
        fn eval(&mut self, x: &[f64], r: &mut [f64], j: &mut [f64]) -> Result<(), ()> {
            r[0] = 10.0 * (x[1] - x[0] * x[0]);
            r[1] = 1.0 - x[0];
            j[0] = -20.0 * x[0];
            j[1] = -1.0;
            j[2] = 10.0;
            j[3] = 0.0;
            Ok(())
        }
    }

    #[test]
    fn finds_the_rosenbrock_minimum() {
        let inf = f64::INFINITY;
        let m = minimize(
            &mut Rosenbrock,
            &[-1.2, 1.0],
            &[-inf, -inf],
            &[inf, inf],
            &Settings::default(),
        )
        .unwrap();
        assert!(m.status.converged(), "{:?}", m.status);
        assert!(
            (m.x[0] - 1.0).abs() < 1e-10 && (m.x[1] - 1.0).abs() < 1e-10,
            "{:?}",
            m.x
        );
    }

    #[test]
    fn stops_at_an_active_bound() {
        // With x₁ ≤ 0.5 the minimum of the Rosenbrock cost is on the bound: x₁ = 0.5,
        // x₂ = 0.25 (the valley floor x₂ = x₁²).
        let inf = f64::INFINITY;
        let m = minimize(
            &mut Rosenbrock,
            &[-1.2, 1.0],
            &[-inf, -inf],
            &[0.5, inf],
            &Settings::default(),
        )
        .unwrap();
        assert!((m.x[0] - 0.5).abs() < 1e-12, "{:?}", m.x);
        assert!((m.x[1] - 0.25).abs() < 1e-8, "{:?}", m.x);
    }
}
