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
                    *o = kernel_single(pos, nl.neighbors(i), i, p, rc2);
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
    // Neighbours are taken in blocks of `B`: gathered, then evaluated branch-free (pairs in
    // the skin shell r_c ≤ r < r_c + δ are evaluated at r_c and masked), which lets the
    // compiler use packed arithmetic. Each lane sums a fixed subsequence of the list, and the
    // lanes are added in a fixed order: the result is independent of the thread count.
    const B: usize = 4;
    let ri = pos[i];
    let mut acc = [[0.0f64; B]; 5];
    let mut blocks = list.chunks_exact(B);
    for blk in &mut blocks {
        let mut d = [[0.0f64; B]; 3];
        let mut r2 = [0.0f64; B];
        let mut rc2 = [0.0f64; B];
        let mut pp: [Option<&P>; B] = [None; B];
        for l in 0..B {
            let j = blk[l] as usize;
            let q = pos[j];
            d[0][l] = ri[0] - q[0];
            d[1][l] = ri[1] - q[1];
            d[2][l] = ri[2] - q[2];
            r2[l] = d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l];
            let (p, c) = pot(j);
            pp[l] = Some(p);
            rc2[l] = c;
        }
        for l in 0..B {
            let inside = r2[l] < rc2[l];
            let (u, fr) = match pp[l] {
                Some(p) => p.energy_force(if inside { r2[l] } else { rc2[l] }),
                None => (0.0, 0.0),
            };
            let fr = if inside { fr } else { 0.0 };
            acc[0][l] += fr * d[0][l];
            acc[1][l] += fr * d[1][l];
            acc[2][l] += fr * d[2][l];
            acc[3][l] += if inside { u } else { 0.0 };
            acc[4][l] += fr * r2[l];
        }
    }
    let mut t = [0.0f64; 5];
    for (tk, a) in t.iter_mut().zip(&acc) {
        *tk = (a[0] + a[1]) + (a[2] + a[3]);
    }
    for &j in blocks.remainder() {
        let q = pos[j as usize];
        let dx = ri[0] - q[0];
        let dy = ri[1] - q[1];
        let dz = ri[2] - q[2];
        let r2 = dx * dx + dy * dy + dz * dz;
        let (p, rc2) = pot(j as usize);
        if r2 < rc2 {
            let (u, fr) = p.energy_force(r2);
            t[0] += fr * dx;
            t[1] += fr * dy;
            t[2] += fr * dz;
            t[3] += u;
            t[4] += fr * r2;
        }
    }
    PairOut {
        f: [t[0], t[1], t[2]],
        e: 0.5 * t[3],
        w: 0.5 * t[4],
    }
}

/// [`kernel`] for one potential: its parameters stay in registers and the blocks vectorise.
#[inline(always)]
fn kernel_single<P: PairPotential>(
    pos: &[[f64; 3]],
    list: &[u32],
    i: usize,
    p: &P,
    rc2: f64,
) -> PairOut {
    const B: usize = 4;
    let ri = pos[i];
    let mut acc = [[0.0f64; B]; 5];
    let mut blocks = list.chunks_exact(B);
    for blk in &mut blocks {
        let mut d = [[0.0f64; B]; 3];
        let mut r2 = [0.0f64; B];
        for l in 0..B {
            let q = pos[blk[l] as usize];
            d[0][l] = ri[0] - q[0];
            d[1][l] = ri[1] - q[1];
            d[2][l] = ri[2] - q[2];
        }
        for l in 0..B {
            r2[l] = d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l];
        }
        let mut r2m = [0.0f64; B];
        for l in 0..B {
            r2m[l] = if r2[l] < rc2 { r2[l] } else { rc2 };
        }
        let (mut u, mut fr) = p.energy_force4(r2m);
        for l in 0..B {
            let inside = r2[l] < rc2;
            u[l] = if inside { u[l] } else { 0.0 };
            fr[l] = if inside { fr[l] } else { 0.0 };
        }
        for l in 0..B {
            acc[0][l] += fr[l] * d[0][l];
            acc[1][l] += fr[l] * d[1][l];
            acc[2][l] += fr[l] * d[2][l];
            acc[3][l] += u[l];
            acc[4][l] += fr[l] * r2[l];
        }
    }
    let mut t = [0.0f64; 5];
    for (tk, a) in t.iter_mut().zip(&acc) {
        *tk = (a[0] + a[1]) + (a[2] + a[3]);
    }
    for &j in blocks.remainder() {
        let q = pos[j as usize];
        let dx = ri[0] - q[0];
        let dy = ri[1] - q[1];
        let dz = ri[2] - q[2];
        let r2 = dx * dx + dy * dy + dz * dz;
        if r2 < rc2 {
            let (u, fr) = p.energy_force(r2);
            t[0] += fr * dx;
            t[1] += fr * dy;
            t[2] += fr * dz;
            t[3] += u;
            t[4] += fr * r2;
        }
    }
    PairOut {
        f: [t[0], t[1], t[2]],
        e: 0.5 * t[3],
        w: 0.5 * t[4],
    }
}
