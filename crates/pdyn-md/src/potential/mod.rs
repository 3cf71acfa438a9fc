//! Pair potentials `u(r)` with a cutoff.
//!
//! The engine calls [`PairPotential::energy_force`] with the squared distance `r²` (never `r`,
//! so no square root is needed for most kernels) and receives the pair energy `u` and
//! `f/r = −u'(r)/r`; the force on `i` from `j` is then `(f/r)·(rᵢ − rⱼ)`, and the pair's virial
//! contribution is `(f/r)·r²`. A potential given as a formula in `r` and compiled by the
//! symbolic engine implements [`RawPair`] and gets the cutoff modes from [`Truncated`].
//!
//! Built in: [`LennardJones`], [`Morse`].

mod lj;
mod morse;
mod truncated;

pub use lj::LennardJones;
pub use morse::Morse;
pub use truncated::{CutoffMode, Truncated};

/// A pair interaction as the force loop sees it (truncation already applied).
pub trait PairPotential: Send + Sync {
    /// Interaction range: pairs with `r ≥ cutoff()` do not interact.
    fn cutoff(&self) -> f64;
    /// `(u, f/r)` at squared distance `r2 < cutoff()²`, where `f/r = −u'(r)/r`.
    fn energy_force(&self, r2: f64) -> (f64, f64);

    /// `(u, f/r)` for four squared distances at once (each `< cutoff()²`). The default calls
    /// [`PairPotential::energy_force`] four times; kernels override it so that the four lanes
    /// are computed with packed arithmetic.
    #[inline(always)]
    fn energy_force4(&self, r2: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        let mut u = [0.0; 4];
        let mut f = [0.0; 4];
        for l in 0..4 {
            (u[l], f[l]) = self.energy_force(r2[l]);
        }
        (u, f)
    }
}

/// The untruncated potential: `(u(r), −u'(r)/r)` at `r² = r2`, for any `r > 0`.
pub trait RawPair: Send + Sync {
    /// `(u, f/r)` at squared distance `r2`.
    fn raw(&self, r2: f64) -> (f64, f64);
}

impl<P: PairPotential + ?Sized> PairPotential for Box<P> {
    fn cutoff(&self) -> f64 {
        (**self).cutoff()
    }
    #[inline]
    fn energy_force(&self, r2: f64) -> (f64, f64) {
        (**self).energy_force(r2)
    }
    #[inline]
    fn energy_force4(&self, r2: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        (**self).energy_force4(r2)
    }
}
