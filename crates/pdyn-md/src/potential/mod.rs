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

pub use lj::{LennardJones, LjConstants};
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

    /// `(u, f/r)` for a batch: `u[k], fr[k]` at `r2[k]` (each `< cutoff()²`; the three slices
    /// have the same length). The default takes blocks of four
    /// ([`PairPotential::energy_force4`]), then the rest one by one; a compiled formula
    /// overrides it to run its program once per batch instead of once per pair.
    #[inline(always)]
    fn energy_force_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        let m = r2.len().min(u.len()).min(fr.len());
        let (r2, u, fr) = (&r2[..m], &mut u[..m], &mut fr[..m]);
        let mut k = 0;
        while k + 4 <= m {
            let (a, b) = self.energy_force4([r2[k], r2[k + 1], r2[k + 2], r2[k + 3]]);
            u[k..k + 4].copy_from_slice(&a);
            fr[k..k + 4].copy_from_slice(&b);
            k += 4;
        }
        for k in k..m {
            (u[k], fr[k]) = self.energy_force(r2[k]);
        }
    }

    /// The constants of a Lennard-Jones with a plain or energy-shifted cutoff, for the
    /// dedicated SIMD kernel; `None` (default) for anything else.
    fn lennard_jones(&self) -> Option<LjConstants> {
        None
    }

    /// Whether the force loop should gather a particle's neighbours and call
    /// [`PairPotential::energy_force_batch`] once for them (a compiled formula, whose cost is
    /// per call), rather than [`PairPotential::energy_force4`] per block of four (default).
    fn prefers_batch(&self) -> bool {
        false
    }
}

/// The untruncated potential: `(u(r), −u'(r)/r)` at `r² = r2`, for any `r > 0`.
pub trait RawPair: Send + Sync {
    /// `(u, f/r)` at squared distance `r2`.
    fn raw(&self, r2: f64) -> (f64, f64);

    /// The untruncated Lennard-Jones constants (`u_c = 0`, `rc = ∞`), if this is one.
    fn lennard_jones(&self) -> Option<LjConstants> {
        None
    }

    /// [`RawPair::raw`] at four squared distances. The default calls `raw` per lane; kernels
    /// override it with lane-wise array arithmetic (one operation for all four lanes at a
    /// time), which the compiler turns into packed instructions, giving the same bits as
    /// `raw` lane by lane.
    #[inline(always)]
    fn raw4(&self, r2: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        let mut u = [0.0; 4];
        let mut f = [0.0; 4];
        for l in 0..4 {
            (u[l], f[l]) = self.raw(r2[l]);
        }
        (u, f)
    }

    /// [`RawPair::raw`] for a batch (slices of the same length); the default calls `raw` for
    /// each element, a compiled formula evaluates its program once for the whole batch.
    #[inline]
    fn raw_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        for ((&r, u), f) in r2.iter().zip(u).zip(fr) {
            (*u, *f) = self.raw(r);
        }
    }

    /// Whether [`RawPair::raw_batch`] is much cheaper per pair than `raw` (see
    /// [`PairPotential::prefers_batch`]).
    fn prefers_batch(&self) -> bool {
        false
    }
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
    #[inline]
    fn energy_force_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        (**self).energy_force_batch(r2, u, fr)
    }
    fn prefers_batch(&self) -> bool {
        (**self).prefers_batch()
    }
    fn lennard_jones(&self) -> Option<LjConstants> {
        (**self).lennard_jones()
    }
}
