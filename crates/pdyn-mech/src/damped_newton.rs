//! The damped Newton (Levenberg–Marquardt) iteration of [`crate::equilibrium::solve`] and
//! [`crate::sparse_statics::solve`], written once over the linear algebra each path uses
//! ([`NewtonSystem`]: dense LU, or the envelope `L D Lᵀ` of the symmetric part).
//!
//! Each step solves `(K + μ·ratio·D) δq = f`; a step is taken only where it lowers `|f|`. `μ`
//! starts at 0 (Newton's step), grows tenfold (from 1e-6) while the step does not lower `|f|`,
//! and shrinks tenfold after a step that does (to 0 below 1e-12). Where `μ` must grow past
//! 1e12, no nearby state lowers the out-of-balance force: the caller names the free
//! directions (a mechanism) or reports no convergence.

use crate::equilibrium::{EquilibriumError, EquilibriumOptions, FreeDirection};

/// A linearization that damped Newton can step with.
pub(crate) trait NewtonSystem {
    /// The linearization at a state (`f`, `K`, ... and whatever the solves reuse).
    type At;
    /// The linearization at `q`.
    fn at(&self, q: &[f64]) -> Self::At;
    /// `|f|` at `at` (each path's own norm, so that its results stay bit for bit).
    fn residual(&self, at: &Self::At) -> f64;
    /// `δq` solving `(K + diag(damping)) δq = f` at `at`, or `None` when it cannot be factored.
    fn step(&self, at: &Self::At, damping: &[f64]) -> Option<Vec<f64>>;
    /// The directions along which the stiffness at `at` is singular.
    fn free_directions(&self, at: &Self::At) -> Vec<FreeDirection>;
}

/// Where the iteration ended.
pub(crate) struct Converged<A> {
    pub q: Vec<f64>,
    pub at: A,
    pub residual: f64,
    pub steps: usize,
}

/// Damped Newton from `q` (with `at` its linearization) until `|f| ≤ target`: `diag` is the
/// damping's diagonal `D`, `ratio` makes `μ = 1` weigh `K` and `D` alike.
pub(crate) fn solve<S: NewtonSystem>(
    system: &S,
    mut q: Vec<f64>,
    mut at: S::At,
    diag: &[f64],
    ratio: f64,
    target: f64,
    opts: &EquilibriumOptions,
) -> Result<Converged<S::At>, EquilibriumError> {
    let mut mu = 0.0f64;
    let mut steps = 0;
    let mut residual = system.residual(&at);
    while residual > target {
        if steps >= opts.max_steps {
            return Err(EquilibriumError::NotConverged { steps, residual });
        }
        steps += 1;
        let mut improved = false;
        // Try the step with the current μ, raising it until |f| decreases.
        for _ in 0..40 {
            let damping: Vec<f64> = diag.iter().map(|d| mu * ratio * d).collect();
            if let Some(dq) = system.step(&at, &damping) {
                let trial: Vec<f64> = q.iter().zip(&dq).map(|(a, b)| a + b).collect();
                let next = system.at(&trial);
                let r = system.residual(&next);
                if r.is_finite() && r < residual {
                    q = trial;
                    at = next;
                    residual = r;
                    improved = true;
                    break;
                }
            }
            mu = if mu == 0.0 { 1e-6 } else { mu * 10.0 };
            if mu > 1e12 {
                break;
            }
        }
        if !improved {
            let directions = system.free_directions(&at);
            return Err(if directions.is_empty() {
                EquilibriumError::NotConverged { steps, residual }
            } else {
                EquilibriumError::Mechanism {
                    residual,
                    directions,
                }
            });
        }
        mu /= 10.0;
        if mu < 1e-12 {
            mu = 0.0;
        }
    }
    Ok(Converged {
        q,
        at,
        residual,
        steps,
    })
}
