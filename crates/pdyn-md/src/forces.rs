//! Pair forces from the neighbour list, one particle per task.
//!
//! For every real particle `i`: `Fᵢ = Σⱼ (f/r)(r²ᵢⱼ)·(rᵢ − rⱼ)` over its full neighbour list in
//! list order, `eᵢ = ½ Σⱼ u(rᵢⱼ)`, `wᵢ = ½ Σⱼ (f/r)·r²ᵢⱼ` (each pair is seen from both ends).
//! Totals `U = Σ eᵢ`, `W = Σ wᵢ` are summed afterwards in index order, so results do not depend
//! on the number of threads. Species: each particle has a type `t`, and a symmetric table holds
//! one potential per pair of types.

use crate::potential::PairPotential;
use crate::{MdError, NeighborList};
use rayon::prelude::*;

/// Per-particle force, energy and virial from pair interactions.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PairOut {
    pub f: [f64; 3],
    pub e: f64,
    pub w: f64,
}

/// One pair potential per pair of particle types (symmetric).
#[derive(Debug, Clone)]
pub struct ForceField<P> {
    ntypes: usize,
    table: Vec<P>,
}

impl<P: PairPotential + Clone> ForceField<P> {
    /// Every pair of every type interacts through `p` (types are then only labels).
    pub fn single(p: P) -> Self {
        ForceField {
            ntypes: 1,
            table: vec![p],
        }
    }

    /// `ntypes` types, every pair initialised with `p`; refine with [`ForceField::set`].
    pub fn uniform(ntypes: usize, p: P) -> Result<Self, MdError> {
        if ntypes == 0 || ntypes > 1024 {
            return Err(MdError::InvalidParameter {
                name: "ntypes",
                value: ntypes as f64,
            });
        }
        Ok(ForceField {
            ntypes,
            table: vec![p; ntypes * ntypes],
        })
    }

    /// Sets the potential between types `a` and `b` (and `b`, `a`).
    pub fn set(&mut self, a: usize, b: usize, p: P) -> Result<(), MdError> {
        for t in [a, b] {
            if t >= self.ntypes {
                return Err(MdError::IndexOutOfRange {
                    what: "type",
                    index: t,
                    len: self.ntypes,
                });
            }
        }
        self.table[a * self.ntypes + b] = p.clone();
        self.table[b * self.ntypes + a] = p;
        Ok(())
    }
}

impl<P: PairPotential> ForceField<P> {
    /// Number of particle types.
    pub fn ntypes(&self) -> usize {
        self.ntypes
    }

    /// Potential between types `a` and `b`.
    pub fn get(&self, a: usize, b: usize) -> &P {
        &self.table[a * self.ntypes + b]
    }

    /// Largest cutoff in the table.
    pub fn max_cutoff(&self) -> f64 {
        self.table.iter().map(|p| p.cutoff()).fold(0.0, f64::max)
    }

    /// Fills `out[i]` for every real particle.
    pub(crate) fn compute(&self, nl: &NeighborList, types: &[u32], out: &mut [PairOut]) {
        let pos = &nl.pos;
        let owner = &nl.owner;
        if self.ntypes == 1 {
            let p = &self.table[0];
            let rc2 = p.cutoff() * p.cutoff();
            out.par_iter_mut()
                .enumerate()
                .with_min_len(128)
                .for_each(|(i, o)| {
                    *o = kernel(pos, nl.neighbors(i), i, |_| (p, rc2));
                });
        } else {
            let nt = self.ntypes;
            out.par_iter_mut()
                .enumerate()
                .with_min_len(128)
                .for_each(|(i, o)| {
                    let ti = types[i] as usize * nt;
                    *o = kernel(pos, nl.neighbors(i), i, |j| {
                        let p = &self.table[ti + types[owner[j] as usize] as usize];
                        (p, p.cutoff() * p.cutoff())
                    });
                });
        }
    }
}

#[inline(always)]
fn kernel<'a, P: PairPotential + 'a>(
    pos: &[[f64; 3]],
    list: &[u32],
    i: usize,
    pot: impl Fn(usize) -> (&'a P, f64),
) -> PairOut {
    let ri = pos[i];
    let (mut fx, mut fy, mut fz, mut e, mut w) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &j in list {
        let q = pos[j as usize];
        let dx = ri[0] - q[0];
        let dy = ri[1] - q[1];
        let dz = ri[2] - q[2];
        let r2 = dx * dx + dy * dy + dz * dz;
        let (p, rc2) = pot(j as usize);
        if r2 < rc2 {
            let (u, fr) = p.energy_force(r2);
            fx += fr * dx;
            fy += fr * dy;
            fz += fr * dz;
            e += u;
            w += fr * r2;
        }
    }
    PairOut {
        f: [fx, fy, fz],
        e: 0.5 * e,
        w: 0.5 * w,
    }
}
