//! Pair forces from the half neighbour list, with Newton's third law.
//!
//! The internal particles `0..n` (spatially sorted, see [`NeighborList`]) are cut into `S`
//! contiguous *segments*, `S` a function of `n` only. A segment walks its particles `i` in
//! order and, for each pair `(i, j)` of the half list, adds `(f/r)·(rᵢ − rⱼ)` to `i` and
//! subtracts it from `j` in a force buffer of its own (LAMMPS's `newton_pair on`, with
//! per-task arrays as in its OPENMP package). The buffers are then added in segment order,
//! and ghost forces are folded into their owners in ghost order. Every sum is thus taken in
//! an order fixed by the particles and the list alone: results are bitwise identical for any
//! number of threads, which only decide which segments run at the same time.
//!
//! Each pair's energy `u` and virial `(f/r)·r²` are summed per segment (four lanes, in list
//! order), then over segments in order. Species: each particle has a type `t`, and a
//! symmetric table holds one potential per pair of types.

use crate::potential::PairPotential;
use crate::{MdError, NeighborList};
use rayon::prelude::*;

/// Most segments the force loop is cut into (and so the most threads it can use): each costs
/// one force buffer, zeroed and summed every step.
const MAX_SEGMENTS: usize = 4;
/// Fewest particles per segment: below that a buffer costs more than the parallelism gains.
const MIN_SEGMENT: usize = 1000;

/// Buffers the force loop reuses from step to step.
#[derive(Debug, Clone, Default)]
pub(crate) struct ForceScratch {
    /// One buffer per segment, covering extended indices from the segment's first particle.
    bufs: Vec<Vec<[f64; 3]>>,
    /// Total force per internal index.
    total: Vec<[f64; 3]>,
    /// Type of every extended index (only with several types).
    types_ext: Vec<u32>,
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

    /// Pair forces on every particle into `forces` (particle order, overwritten); returns the
    /// pair energy and virial `Σ (f/r)·r²`.
    pub(crate) fn compute(
        &self,
        nl: &NeighborList,
        types: &[u32],
        scratch: &mut ForceScratch,
        forces: &mut [[f64; 3]],
    ) -> (f64, f64) {
        let n = nl.len();
        let n_ext = nl.pos.len();
        let nseg = (n / MIN_SEGMENT).clamp(1, MAX_SEGMENTS);
        let bounds: Vec<usize> = (0..=nseg).map(|s| s * n / nseg).collect();
        scratch.bufs.resize_with(nseg, Vec::new);
        for (s, b) in scratch.bufs.iter_mut().enumerate() {
            b.resize(n_ext - bounds[s], [0.0; 3]);
        }
        let (pos, offsets, neigh) = (&nl.pos[..], &nl.offsets[..], &nl.neigh[..]);
        // the bounds invariant of `segment::<true>`; buffers are sized to it just above
        let unchecked = nl.verified;
        let sums: Vec<(f64, f64)> = if self.ntypes == 1 {
            let p = &self.table[0];
            let rc2 = p.cutoff() * p.cutoff();
            let batched = p.prefers_batch();
            let e4 = |_: usize, _: [usize; 4], r2: [f64; 4]| {
                let mut r2m = [0.0f64; 4];
                for l in 0..4 {
                    r2m[l] = if r2[l] < rc2 { r2[l] } else { rc2 };
                }
                let (mut u, mut fr) = p.energy_force4(r2m);
                for l in 0..4 {
                    let inside = r2[l] < rc2;
                    u[l] = if inside { u[l] } else { 0.0 };
                    fr[l] = if inside { fr[l] } else { 0.0 };
                }
                (u, fr)
            };
            let e1 = |_: usize, _: usize, r2: f64| {
                if r2 < rc2 {
                    p.energy_force(r2)
                } else {
                    (0.0, 0.0)
                }
            };
            scratch
                .bufs
                .par_iter_mut()
                .enumerate()
                .map(|(s, buf)| {
                    let range = bounds[s]..bounds[s + 1];
                    if batched {
                        return if unchecked {
                            segment_batched::<true, _>(pos, offsets, neigh, range, buf, p, rc2)
                        } else {
                            segment_batched::<false, _>(pos, offsets, neigh, range, buf, p, rc2)
                        };
                    }
                    if unchecked {
                        segment::<true>(pos, offsets, neigh, range, buf, e4, e1)
                    } else {
                        segment::<false>(pos, offsets, neigh, range, buf, e4, e1)
                    }
                })
                .collect()
        } else {
            let nt = self.ntypes;
            let te = &mut scratch.types_ext;
            te.clear();
            te.extend(
                nl.owner
                    .iter()
                    .map(|&o| types[nl.perm[o as usize] as usize]),
            );
            let te = &scratch.types_ext[..];
            let table = &self.table[..];
            let pair = move |i: usize, j: usize, r2: f64| -> (f64, f64) {
                let p = &table[te[i] as usize * nt + te[j] as usize];
                let rc2 = p.cutoff() * p.cutoff();
                if r2 < rc2 {
                    p.energy_force(r2)
                } else {
                    (0.0, 0.0)
                }
            };
            scratch
                .bufs
                .par_iter_mut()
                .enumerate()
                .map(|(s, buf)| {
                    segment::<false>(
                        pos,
                        offsets,
                        neigh,
                        bounds[s]..bounds[s + 1],
                        buf,
                        |i, js, r2| {
                            let mut u = [0.0; 4];
                            let mut fr = [0.0; 4];
                            for l in 0..4 {
                                (u[l], fr[l]) = pair(i, js[l], r2[l]);
                            }
                            (u, fr)
                        },
                        pair,
                    )
                })
                .collect()
        };
        let (mut u, mut w) = (0.0, 0.0);
        for (e, v) in sums {
            u += e;
            w += v;
        }
        // real particles: buffers in segment order (segment s covers indices ≥ bounds[s])
        let total = &mut scratch.total;
        total.clear();
        total.resize(n, [0.0; 3]);
        let bufs = &scratch.bufs;
        const CHUNK: usize = 4096;
        total
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, out)| {
                for (m, t) in out.iter_mut().enumerate() {
                    let k = c * CHUNK + m;
                    let mut f = [0.0; 3];
                    for (b, &lo) in bufs.iter().zip(&bounds) {
                        if k >= lo {
                            let v = b[k - lo];
                            f = [f[0] + v[0], f[1] + v[1], f[2] + v[2]];
                        }
                    }
                    *t = f;
                }
            });
        // ghosts, in ghost order, onto their owners
        for g in n..n_ext {
            let o = nl.owner[g] as usize;
            for (b, &lo) in bufs.iter().zip(&bounds) {
                let v = b[g - lo];
                for k in 0..3 {
                    total[o][k] += v[k];
                }
            }
        }
        for (t, &k) in total.iter().zip(&nl.perm) {
            forces[k as usize] = *t;
        }
        (u, w)
    }
}

/// Forces of the pairs of internal particles `range` into `buf` (zeroed first; `buf[k]` is
/// extended index `range.start + k`); returns the segment's energy and virial. `eval4` gives
/// `(u, f/r)` for four neighbours of `i` at squared distances `r2`, zero outside the cutoff
/// (branch-free, so that the four lanes use packed arithmetic); `eval1` the same for one.
#[inline(always)]
fn segment<const UNCHECKED: bool>(
    pos: &[[f64; 3]],
    offsets: &[u32],
    neigh: &[u32],
    range: std::ops::Range<usize>,
    buf: &mut [[f64; 3]],
    eval4: impl Fn(usize, [usize; 4], [f64; 4]) -> ([f64; 4], [f64; 4]),
    eval1: impl Fn(usize, usize, f64) -> (f64, f64),
) -> (f64, f64) {
    const B: usize = 4;
    buf.iter_mut().for_each(|b| *b = [0.0; 3]);
    let base = range.start;
    // UNCHECKED is true only when the caller has verified (`NeighborList::verified`) that
    // every neighbour `j` of a particle `i` has `i < j < pos.len()`, and `buf` covers
    // `base..pos.len()`: then `pos[j]` and `buf[j - base]` are in bounds for `i ≥ base`.
    debug_assert!(!UNCHECKED || buf.len() == pos.len() - base);
    // Per-lane energy and virial sums: each lane adds a fixed subsequence of the pairs.
    let mut ew = [[0.0f64; B]; 2];
    let mut tail = [0.0f64; 2];
    for i in range {
        let ri = pos[i];
        let list = &neigh[offsets[i] as usize..offsets[i + 1] as usize];
        let mut fa = [[0.0f64; B]; 3];
        let mut blocks = list.chunks_exact(B);
        for blk in &mut blocks {
            let js = [
                blk[0] as usize,
                blk[1] as usize,
                blk[2] as usize,
                blk[3] as usize,
            ];
            let mut d = [[0.0f64; B]; 3];
            for l in 0..B {
                let q = if UNCHECKED {
                    // SAFETY: j < pos.len() (see UNCHECKED above)
                    unsafe { *pos.get_unchecked(js[l]) }
                } else {
                    pos[js[l]]
                };
                d[0][l] = ri[0] - q[0];
                d[1][l] = ri[1] - q[1];
                d[2][l] = ri[2] - q[2];
            }
            let mut r2 = [0.0f64; B];
            for l in 0..B {
                r2[l] = d[0][l] * d[0][l] + d[1][l] * d[1][l] + d[2][l] * d[2][l];
            }
            let (u, fr) = eval4(i, js, r2);
            add_block::<UNCHECKED>(&d, &r2, &u, &fr, js, base, buf, &mut fa, &mut ew);
        }
        let mut fi = [0.0f64; 3];
        for (f, a) in fi.iter_mut().zip(&fa) {
            *f = (a[0] + a[1]) + (a[2] + a[3]);
        }
        for &j in blocks.remainder() {
            let j = j as usize;
            let q = pos[j];
            let d = [ri[0] - q[0], ri[1] - q[1], ri[2] - q[2]];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let (u, fr) = eval1(i, j, r2);
            let fd = [fr * d[0], fr * d[1], fr * d[2]];
            let b = &mut buf[j - base];
            for k in 0..3 {
                fi[k] += fd[k];
                b[k] -= fd[k];
            }
            tail[0] += u;
            tail[1] += fr * r2;
        }
        let b = &mut buf[i - base];
        for k in 0..3 {
            b[k] += fi[k];
        }
    }
    let lanes = |a: &[f64; B]| (a[0] + a[1]) + (a[2] + a[3]);
    (lanes(&ew[0]) + tail[0], lanes(&ew[1]) + tail[1])
}

/// One block of four pairs `(i, js[l])` with separations `d`, squared distances `r2` and
/// `(u, f/r)`: `(f/r)·d` is added to `i`'s lane sums `fa` and subtracted from each `j` in `buf`
/// (Newton's third law: every `j` of `i`'s half list has owner > i ≥ `base`), `u` and the
/// virial `(f/r)·r²` to the lane sums `ew`. Shared by [`segment`] and [`segment_batched`], so
/// the two add the same numbers in the same order. `UNCHECKED` as in [`segment`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn add_block<const UNCHECKED: bool>(
    d: &[[f64; 4]; 3],
    r2: &[f64; 4],
    u: &[f64; 4],
    fr: &[f64; 4],
    js: [usize; 4],
    base: usize,
    buf: &mut [[f64; 3]],
    fa: &mut [[f64; 4]; 3],
    ew: &mut [[f64; 4]; 2],
) {
    let mut fd = [[0.0f64; 4]; 3];
    for l in 0..4 {
        fd[0][l] = fr[l] * d[0][l];
        fd[1][l] = fr[l] * d[1][l];
        fd[2][l] = fr[l] * d[2][l];
    }
    for l in 0..4 {
        fa[0][l] += fd[0][l];
        fa[1][l] += fd[1][l];
        fa[2][l] += fd[2][l];
        ew[0][l] += u[l];
        ew[1][l] += fr[l] * r2[l];
    }
    for l in 0..4 {
        let b = if UNCHECKED {
            // SAFETY: base ≤ i < j < pos.len() = base + buf.len() (see UNCHECKED in `segment`)
            unsafe { buf.get_unchecked_mut(js[l] - base) }
        } else {
            &mut buf[js[l] - base]
        };
        b[0] -= fd[0][l];
        b[1] -= fd[1][l];
        b[2] -= fd[2][l];
    }
}

/// [`segment`] for one potential that is cheaper called once per batch
/// ([`PairPotential::prefers_batch`], a compiled formula): each particle's neighbours are
/// gathered, up to `CH` at a time, and evaluated by one [`PairPotential::energy_force_batch`].
/// Pairs are summed exactly as in [`segment`] (lanes by position modulo 4, the last
/// `len % 4` one by one after the lanes), so the two loops give the same bits for the same
/// `(u, f/r)`. `UNCHECKED` as in [`segment`].
fn segment_batched<const UNCHECKED: bool, P: PairPotential>(
    pos: &[[f64; 3]],
    offsets: &[u32],
    neigh: &[u32],
    range: std::ops::Range<usize>,
    buf: &mut [[f64; 3]],
    p: &P,
    rc2: f64,
) -> (f64, f64) {
    const B: usize = 4;
    const CH: usize = 64; // a multiple of B: blocks of four never straddle two batches
    buf.iter_mut().for_each(|b| *b = [0.0; 3]);
    let base = range.start;
    debug_assert!(!UNCHECKED || buf.len() == pos.len() - base);
    let mut ew = [[0.0f64; B]; 2];
    let mut tail = [0.0f64; 2];
    let mut d = [[0.0f64; CH]; 3];
    let mut r2 = [0.0f64; CH];
    let mut r2m = [0.0f64; CH];
    let mut u = [0.0f64; CH];
    let mut fr = [0.0f64; CH];
    for i in range {
        let ri = pos[i];
        let list = &neigh[offsets[i] as usize..offsets[i + 1] as usize];
        let mut fa = [[0.0f64; B]; 3];
        let mut rest = 0..0; // the last len % 4 pairs, within the last batch
        for chunk in list.chunks(CH) {
            let m = chunk.len();
            for (k, &j) in chunk.iter().enumerate() {
                let q = if UNCHECKED {
                    // SAFETY: j < pos.len() (see UNCHECKED in `segment`)
                    unsafe { *pos.get_unchecked(j as usize) }
                } else {
                    pos[j as usize]
                };
                d[0][k] = ri[0] - q[0];
                d[1][k] = ri[1] - q[1];
                d[2][k] = ri[2] - q[2];
                r2[k] = d[0][k] * d[0][k] + d[1][k] * d[1][k] + d[2][k] * d[2][k];
                // pairs in the skin shell are evaluated at r_c and masked below
                r2m[k] = if r2[k] < rc2 { r2[k] } else { rc2 };
            }
            p.energy_force_batch(&r2m[..m], &mut u[..m], &mut fr[..m]);
            let full = m / B * B;
            for k0 in (0..full).step_by(B) {
                // fixed-size blocks (one bounds check each), so the lanes use packed arithmetic
                let blk = |a: &[f64; CH]| -> [f64; B] {
                    let mut o = [0.0; B];
                    o.copy_from_slice(&a[k0..k0 + B]);
                    o
                };
                let db = [blk(&d[0]), blk(&d[1]), blk(&d[2])];
                let (r2b, ub, frb) = (blk(&r2), blk(&u), blk(&fr));
                let mut uk = [0.0f64; B];
                let mut fk = [0.0f64; B];
                let mut js = [0usize; B];
                for l in 0..B {
                    let inside = r2b[l] < rc2;
                    uk[l] = if inside { ub[l] } else { 0.0 };
                    fk[l] = if inside { frb[l] } else { 0.0 };
                    js[l] = chunk[k0 + l] as usize;
                }
                add_block::<UNCHECKED>(&db, &r2b, &uk, &fk, js, base, buf, &mut fa, &mut ew);
            }
            for k in full..m {
                let inside = r2[k] < rc2;
                u[k] = if inside { u[k] } else { 0.0 };
                fr[k] = if inside { fr[k] } else { 0.0 };
            }
            rest = full..m;
        }
        let mut fi = [0.0f64; 3];
        for (f, a) in fi.iter_mut().zip(&fa) {
            *f = (a[0] + a[1]) + (a[2] + a[3]);
        }
        let last = &list[list.len() - rest.len()..];
        for (k, &j) in rest.zip(last) {
            let fd = [fr[k] * d[0][k], fr[k] * d[1][k], fr[k] * d[2][k]];
            let b = &mut buf[j as usize - base];
            for c in 0..3 {
                fi[c] += fd[c];
                b[c] -= fd[c];
            }
            tail[0] += u[k];
            tail[1] += fr[k] * r2[k];
        }
        let b = &mut buf[i - base];
        for k in 0..3 {
            b[k] += fi[k];
        }
    }
    let lanes = |a: &[f64; B]| (a[0] + a[1]) + (a[2] + a[3]);
    (lanes(&ew[0]) + tail[0], lanes(&ew[1]) + tail[1])
}
