//! The damped Newton (Levenberg–Marquardt) iteration of [`crate::equilibrium::solve`] and
//! [`crate::sparse_statics::solve`], written once over the linear algebra each path uses
//! ([`NewtonSystem`]: dense LU, or the envelope `L D Lᵀ` of the symmetric part).
//!
//! Each step solves `(K + μ·ratio·D) δq = f`; a step is taken where it lowers `|f|` or, for
//! conservative forces (`K` symmetric), where it lowers the potential energy (see
//! [`ENERGY_STALL`]). `μ` starts at 0 (Newton's step), grows tenfold (from 1e-6) while the step
//! is not taken, and shrinks tenfold after a step that is (to 0 below 1e-12); a refused step
//! along which `K` vanishes is the damping's alone, and is scaled for the next `μ` rather than
//! factored again ([`DAMPING_ALONE`]). Where `μ` must grow past 1e12, no nearby state lowers
//! the out-of-balance force: the caller names the free directions (a mechanism) or reports no
//! convergence.
//!
//! Why the energy: a net released flat and slack must travel far (it sags by its own size)
//! before its springs take the load, and on the way `|f|` rises and falls. Requiring `|f|` to
//! fall at every step kept the steps short: 111 steps and 219 factorizations for the 20 × 20
//! hanging net. The energy falls along the whole way down, and steps that lower it take the
//! net there in 18 steps and 26 factorizations, to the same equilibrium (the minimum of the
//! energy that damped motion from the start settles in). The energy itself is not available
//! (only `f = −∂V/∂q`): its change along a step `δq` is `−∫₀¹ f(q + s δq)·δq ds`, integrated
//! by three-point Gauss–Legendre from the forces alone.

use crate::equilibrium::{EquilibriumError, EquilibriumOptions, FreeDirection};

/// A linearization that damped Newton can step with.
///
/// A trial step is judged by `f` at its end (and, while the energy guides, by `f` along it):
/// the matrices there are needed only when the step is taken. So a trial computes what
/// [`NewtonSystem::trial`] gives (`f` alone where the linearization computes it apart from
/// the matrices, the whole linearization otherwise), and [`NewtonSystem::taken`] completes it
/// for a step taken: on the 20 × 20 hanging net 8 of 27 trial steps are refused, and the
/// matrices at one cost as much as some twenty evaluations of `f`.
pub(crate) trait NewtonSystem {
    /// The linearization at a state (`f`, `K`, ... and whatever the solves reuse).
    type At;
    /// What a trial step's end holds: at least `f`.
    type Trial;
    /// The end `q` of a trial step.
    fn trial(&self, q: &[f64]) -> Self::Trial;
    /// `|f|` at a trial's end: the same number [`NewtonSystem::residual`] gives of the
    /// linearization it completes to (the same norm of the same `f`).
    fn trial_residual(&self, trial: &Self::Trial) -> f64;
    /// The linearization at `q`, the end of a step taken, from its trial.
    fn taken(&self, q: &[f64], trial: Self::Trial) -> Self::At;
    /// `|f|` at `at` (each path's own norm, so that its results stay bit for bit).
    fn residual(&self, at: &Self::At) -> f64;
    /// `δq` solving `(K + diag(damping)) δq = f` at `at`, or `None` when it cannot be factored.
    fn step(&self, at: &Self::At, damping: &[f64]) -> Option<Vec<f64>>;
    /// The directions along which the stiffness at `at` is singular.
    fn free_directions(&self, at: &Self::At) -> Vec<FreeDirection>;
    /// `f` alone at `q` (for the work along a step).
    fn force(&self, q: &[f64]) -> Vec<f64>;
    /// `K v` at `at`, with the `K` that [`NewtonSystem::step`] solves with.
    fn stiffness_mul(&self, at: &Self::At, v: &[f64]) -> Vec<f64>;
    /// Whether `K` at `at` is symmetric (to round-off): the forces derive from a potential
    /// energy near there, whose change along a step is minus their work.
    fn conservative(&self, at: &Self::At) -> bool;
}

/// A trial step's end as both paths hold it: `f` alone where the linearization computes it
/// apart from the matrices ([`crate::linearization::Linearize::force_alone`]), the whole
/// linearization `A` otherwise (then nothing is computed twice for a step taken).
pub(crate) enum TrialEnd<A> {
    /// `f` at the end.
    Force(Vec<f64>),
    /// The linearization at the end.
    Whole(A),
}

/// Steps in a row without a new smallest `|f|` after which only steps lowering `|f|` are
/// taken. A load that a mechanism cannot hold (a free chain under gravity) lowers the energy
/// without end while `|f|` stays: after this many steps the iteration falls back to the
/// residual alone, and `μ` grows until the caller names the free directions. The nets of
/// issue 33 (5 × 5 to 30 × 30) go at most 9 steps without a new smallest `|f|`.
pub(crate) const ENERGY_STALL: usize = 20;

/// `|K δq|` relative to `|f|` below which a refused step `δq` of damping `μ` is taken to be
/// the damping's alone, and the step of `μ' > μ` is `(μ/μ') δq` without a factorization: it
/// solves `(K + μ'D) δq' = f` up to `(1 − μ/μ') K δq`, a relative residual below this.
///
/// Why: a net released flat has springs at their rest lengths, no stiffness across its plane,
/// and its weight across it: `K δq = 0` along the damped step, whose length is then `∝ 1/μ`.
/// Damped Newton refused the steps of `μ` = 10⁻⁶ to 10⁻³ (hundreds of metres to tens of
/// centimetres of sag for a net of 2 m) before it took that of 10⁻²: on the 20 × 20 net
/// four of its 28 factorizations were these scalings of the first.
pub(crate) const DAMPING_ALONE: f64 = 1e-8;

/// Most Newton steps taken after convergence to bring `|f|` down to round-off.
const POLISH: usize = 3;

/// Three-point Gauss–Legendre nodes and weights on `[0, 1]` (exact for polynomials of degree 5).
const GAUSS: [(f64, f64); 3] = [
    (0.112_701_665_379_258_31, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

/// The work of the forces along the straight step from `q` to `q + dq`, `∫₀¹ f(q + s dq)·dq ds`:
/// minus the change of the potential energy when the forces have one.
fn work<S: NewtonSystem>(system: &S, q: &[f64], dq: &[f64]) -> f64 {
    let mut at = vec![0.0; q.len()];
    GAUSS
        .iter()
        .map(|&(s, w)| {
            for ((a, x), d) in at.iter_mut().zip(q).zip(dq) {
                *a = x + s * d;
            }
            let f = system.force(&at);
            w * f.iter().zip(dq).map(|(f, d)| f * d).sum::<f64>()
        })
        .sum()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
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
    let (mut best, mut stall) = (residual, 0usize);
    while residual > target {
        if steps >= opts.max_steps {
            return Err(EquilibriumError::NotConverged { steps, residual });
        }
        steps += 1;
        let mut improved = false;
        // A refused step of damping alone, and its `μ` ([`DAMPING_ALONE`]).
        let mut alone: Option<(f64, Vec<f64>)> = None;
        // Try the step with the current μ, raising it until |f| decreases.
        for _ in 0..40 {
            let got = match alone.take() {
                Some((before, dq)) => {
                    let s = before / mu;
                    Some(dq.iter().map(|x| x * s).collect())
                }
                None => {
                    let damping: Vec<f64> = diag.iter().map(|d| mu * ratio * d).collect();
                    system.step(&at, &damping)
                }
            };
            if let Some(dq) = got {
                let trial: Vec<f64> = q.iter().zip(&dq).map(|(a, b)| a + b).collect();
                let end = system.trial(&trial);
                let r = system.trial_residual(&end);
                // Lower |f|, or a lower energy while the energy is still a guide.
                let take = r.is_finite()
                    && (r < residual
                        || (stall < ENERGY_STALL
                            && system.conservative(&at)
                            && work(system, &q, &dq) > 0.0));
                if take {
                    at = system.taken(&trial, end);
                    q = trial;
                    residual = r;
                    improved = true;
                    break;
                }
                // Refused: the next μ's step is this one scaled if it is the damping's alone
                // (and so are the scaled ones: `K (s δq) = s K δq`).
                if mu > 0.0 && norm(&system.stiffness_mul(&at, &dq)) <= DAMPING_ALONE * residual {
                    alone = Some((mu, dq));
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
        if residual < best {
            (best, stall) = (residual, 0);
        } else {
            stall += 1;
        }
    }
    // Converged: Newton's own steps while each at least halves |f| (at most
    // `POLISH`), down to round-off. The tolerance is met wherever the path there ended; the
    // steps after it make the result independent of that path (of how far inside the
    // tolerance the last step happened to land), so that the modes about the equilibrium are
    // the same to round-off whichever steps led to it.
    let zero = vec![0.0; diag.len()];
    for _ in 0..POLISH {
        let Some(dq) = system.step(&at, &zero) else {
            break;
        };
        let trial: Vec<f64> = q.iter().zip(&dq).map(|(a, b)| a + b).collect();
        let end = system.trial(&trial);
        let r = system.trial_residual(&end);
        if !(r.is_finite() && r <= 0.5 * residual) {
            break;
        }
        at = system.taken(&trial, end);
        q = trial;
        residual = r;
        steps += 1;
    }
    Ok(Converged {
        q,
        at,
        residual,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    /// One coordinate under a load `g` held by a stiffening spring: `V = g q + q⁴/4 + c q²/2`,
    /// `f = −g − q³ − c q`, `K = 3q² + c`. For `c = 0` the start `q = 0` has no stiffness (as
    /// a net released flat has none across its plane). Records the damping of every
    /// factorization (`step`) made at the start.
    struct Stiffening {
        g: f64,
        c: f64,
        at_start: RefCell<Vec<f64>>,
    }

    impl Stiffening {
        fn force(&self, q: f64) -> f64 {
            -self.g - q * q * q - self.c * q
        }
    }

    impl NewtonSystem for Stiffening {
        /// `(q, f, K)`.
        type At = (f64, f64, f64);
        type Trial = f64;
        fn trial(&self, q: &[f64]) -> f64 {
            self.force(q[0])
        }
        fn trial_residual(&self, trial: &f64) -> f64 {
            trial.abs()
        }
        fn taken(&self, q: &[f64], f: f64) -> Self::At {
            (q[0], f, 3.0 * q[0] * q[0] + self.c)
        }
        fn residual(&self, at: &Self::At) -> f64 {
            at.1.abs()
        }
        fn step(&self, at: &Self::At, damping: &[f64]) -> Option<Vec<f64>> {
            if at.0 == 0.0 {
                self.at_start.borrow_mut().push(damping[0]);
            }
            let a = at.2 + damping[0];
            (a != 0.0).then(|| vec![at.1 / a])
        }
        fn free_directions(&self, _: &Self::At) -> Vec<FreeDirection> {
            Vec::new()
        }
        fn force(&self, q: &[f64]) -> Vec<f64> {
            vec![self.force(q[0])]
        }
        fn stiffness_mul(&self, at: &Self::At, v: &[f64]) -> Vec<f64> {
            vec![at.2 * v[0]]
        }
        fn conservative(&self, _: &Self::At) -> bool {
            true
        }
    }

    /// The real root of `q³ + c q + g = 0` (`c ≥ 0`, `g > 0`: one, in `[−g − 1, 0]`), by
    /// bisection: the equilibrium, found without Newton.
    fn root(c: f64, g: f64) -> f64 {
        let (mut lo, mut hi) = (-g - 1.0, 0.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid * mid * mid + c * mid + g > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    fn settle(system: &Stiffening) -> Converged<(f64, f64, f64)> {
        let at = system.taken(&[0.0], system.force(0.0));
        let opts = EquilibriumOptions::default();
        solve(system, vec![0.0], at, &[1.0], 1.0, 1e-13, &opts).unwrap()
    }

    #[test]
    fn steps_of_the_damping_alone_are_scaled_not_factored_again() {
        // c = 0: K = 0 at the start, every damped step there is g/μ. Newton's own (μ = 0) is
        // singular; the steps of μ = 10⁻⁶ to 1 overshoot (the energy rises) and μ = 10 is
        // taken (δq = −0.3): of these eight only the first is factored. The equilibrium is
        // the root of q³ + g = 0.
        let system = Stiffening {
            g: 3.0,
            c: 0.0,
            at_start: RefCell::new(Vec::new()),
        };
        let end = settle(&system);
        assert_eq!(*system.at_start.borrow(), vec![0.0, 1e-6]);
        let exact = root(0.0, 3.0);
        assert!((end.q[0] - exact).abs() <= 1e-13, "{} vs {exact}", end.q[0]);
    }

    #[test]
    fn steps_with_stiffness_along_them_are_factored_for_every_damping() {
        // c = 0.1: K δq = f/(1 + μ/c) is not small beside f: each μ is factored
        // (Newton's step −20 and those of μ = 10⁻⁶ to 10⁻¹ overshoot, μ = 1 is taken). The
        // equilibrium is the root of q³ + 0.1 q + 2 = 0.
        let system = Stiffening {
            g: 2.0,
            c: 0.1,
            at_start: RefCell::new(Vec::new()),
        };
        let end = settle(&system);
        let dampings = system.at_start.borrow().clone();
        assert_eq!(dampings.len(), 8, "{dampings:?}");
        let exact = root(0.1, 2.0);
        assert!((end.q[0] - exact).abs() <= 1e-13, "{} vs {exact}", end.q[0]);
    }
}
