//! [`Pair`]: the potential between two species, whichever way the file gave it.
//!
//! One enum rather than a trait object so that the force table stays `Clone` and the match is
//! taken once per block of four neighbours (`energy_force4`), which keeps each kernel's packed
//! arithmetic. A model whose only potential is Lennard-Jones skips the enum altogether (see
//! [`super::build::Engine`]).

use super::formula::FormulaPair;
use pdyn_md::potential::{LennardJones, Morse, PairPotential, Truncated};

/// A truncated pair potential: a built-in kernel or a compiled formula.
#[derive(Debug, Clone)]
pub enum Pair {
    /// Built-in Lennard-Jones.
    Lj(Truncated<LennardJones>),
    /// Built-in Morse.
    Morse(Truncated<Morse>),
    /// A formula in `r`.
    Formula(Truncated<FormulaPair>),
}

impl PairPotential for Pair {
    fn cutoff(&self) -> f64 {
        match self {
            Pair::Lj(p) => p.cutoff(),
            Pair::Morse(p) => p.cutoff(),
            Pair::Formula(p) => p.cutoff(),
        }
    }

    #[inline]
    fn energy_force(&self, r2: f64) -> (f64, f64) {
        match self {
            Pair::Lj(p) => p.energy_force(r2),
            Pair::Morse(p) => p.energy_force(r2),
            Pair::Formula(p) => p.energy_force(r2),
        }
    }

    #[inline]
    fn energy_force4(&self, r2: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        match self {
            Pair::Lj(p) => p.energy_force4(r2),
            Pair::Morse(p) => p.energy_force4(r2),
            Pair::Formula(p) => p.energy_force4(r2),
        }
    }

    #[inline]
    fn energy_force_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        match self {
            Pair::Lj(p) => p.energy_force_batch(r2, u, fr),
            Pair::Morse(p) => p.energy_force_batch(r2, u, fr),
            Pair::Formula(p) => p.energy_force_batch(r2, u, fr),
        }
    }

    fn prefers_batch(&self) -> bool {
        match self {
            Pair::Lj(p) => p.prefers_batch(),
            Pair::Morse(p) => p.prefers_batch(),
            Pair::Formula(p) => p.prefers_batch(),
        }
    }
}
