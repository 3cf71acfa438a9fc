//! Verlet neighbour list (half, with ghosts) built through a bin list, with particles in a
//! spatially sorted internal order.
//!
//! At a build every particle is wrapped into the box (image counters keep the unwrapped
//! trajectory), and the particles are given an *internal* order: sorted by bin (bins of edge
//! `≥ r_s/2`, `r_s = r_c + δ`, x-major), so that neighbours in space are neighbours in memory
//! (LAMMPS `atom_modify sort`). The particles themselves are not permuted: [`NeighborList`]
//! keeps `perm` (internal → particle index) and its own position array. Every periodic image
//! lying within `r_s` of the box is added as a *ghost* with a fixed shift (as LAMMPS's ghost
//! atoms); between builds ghosts follow their owners (`r_g = r_owner + shift`), so the force
//! loop needs no minimum image.
//!
//! The list is *half*: internal particle `i` lists the extended indices `j` with
//! `owner(j) > i` and `|rᵢ − rⱼ| < r_s`, so each pair appears once (Newton's third law in the
//! force loop). Bins are scanned in a fixed order (a 5×5×5 stencil of half-`r_s` bins), so the
//! list, and every sum over it, does not depend on the number of threads. It stays exact while
//! the two largest displacements since the build add up to at most `δ` (a pair approaches by
//! at most the sum of its two displacements); [`NeighborList::needs_rebuild`] checks that.

use crate::{MdError, SimBox};
use pdyn_particles::Particles;
use rayon::prelude::*;

/// Atoms per task when the list is built: a fixed size, so that the concatenated list is the
/// same for any number of threads.
const BUILD_CHUNK: usize = 512;

/// Verlet list (half, with ghosts, internal spatial order) and the buffers it is rebuilt in.
#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    cutoff: f64,
    skin: f64,
    n_local: usize,
    /// Extended positions: `n_local` real particles in internal order, then ghosts.
    pub(crate) pos: Vec<[f64; 3]>,
    /// Internal index of the real particle of every extended index.
    pub(crate) owner: Vec<u32>,
    /// Particle index of every internal index (`perm[k]` is the particle stored at `pos[k]`).
    pub(crate) perm: Vec<u32>,
    shift: Vec<[f64; 3]>,
    /// Neighbours of internal particle `i`: `neigh[offsets[i]..offsets[i + 1]]` (CSR).
    pub(crate) offsets: Vec<u32>,
    pub(crate) neigh: Vec<u32>,
    bin_of: Vec<u32>,
    bin_start: Vec<u32>,
    bin_fill: Vec<u32>,
    /// Extended indices in bin order, with their positions and owners (scanned contiguously).
    bin_atoms: Vec<u32>,
    bin_pos: Vec<[f64; 3]>,
    bin_owner: Vec<u32>,
    x0: Vec<[f64; 3]>,
    /// Verified at the last build: every neighbour `j` of every `i` has `i < j < pos.len()`
    /// (true by construction; the force loop skips its bounds checks only when this holds).
    pub(crate) verified: bool,
    /// Number of builds so far.
    pub builds: u64,
}

/// Bin grid over `[-r_s, L + r_s)` per axis, bins of edge `≥ r_s / 2`.
#[derive(Debug, Clone, Copy)]
struct Grid {
    rs: f64,
    nb: [usize; 3],
    inv: [f64; 3],
}

impl Grid {
    fn new(l: [f64; 3], rs: f64) -> Grid {
        let mut nb = [1usize; 3];
        let mut inv = [0.0; 3];
        for k in 0..3 {
            let ext = l[k] + 2.0 * rs;
            nb[k] = ((ext / (0.5 * rs)).floor() as usize).max(1);
            inv[k] = nb[k] as f64 / ext;
        }
        Grid { rs, nb, inv }
    }

    fn len(&self) -> usize {
        self.nb[0] * self.nb[1] * self.nb[2]
    }

    /// Bin coordinates of `q` (clamped: a NaN or far-away position lands in an edge bin rather
    /// than out of range).
    #[inline]
    fn coords(&self, q: &[f64; 3]) -> [usize; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            let v = ((q[k] + self.rs) * self.inv[k]).floor();
            c[k] = (v.max(0.0) as usize).min(self.nb[k] - 1);
        }
        c
    }

    #[inline]
    fn index(&self, c: [usize; 3]) -> usize {
        (c[0] * self.nb[1] + c[1]) * self.nb[2] + c[2]
    }
}

impl NeighborList {
    /// A list for interaction range `cutoff` with skin `skin` (both lengths, skin ≥ 0).
    pub fn new(cutoff: f64, skin: f64) -> Result<Self, MdError> {
        if !(cutoff.is_finite() && cutoff > 0.0) {
            return Err(MdError::InvalidParameter {
                name: "cutoff",
                value: cutoff,
            });
        }
        if !(skin.is_finite() && skin >= 0.0) {
            return Err(MdError::InvalidParameter {
                name: "skin",
                value: skin,
            });
        }
        Ok(NeighborList {
            cutoff,
            skin,
            ..Default::default()
        })
    }

    /// Interaction cutoff.
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }

    /// Skin.
    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// Checks that the box is at least `2 (r_c + δ)` along every axis.
    pub fn check_box(&self, bx: &SimBox) -> Result<(), MdError> {
        let required = 2.0 * (self.cutoff + self.skin);
        for (axis, &length) in bx.l.iter().enumerate() {
            if length < required {
                return Err(MdError::BoxTooSmall {
                    axis,
                    length,
                    required,
                });
            }
        }
        Ok(())
    }

    /// Number of real particles at the last build.
    pub fn len(&self) -> usize {
        self.n_local
    }

    /// True before the first build or for an empty system.
    pub fn is_empty(&self) -> bool {
        self.n_local == 0
    }

    /// Half list of internal particle `i`: extended indices `j` with owner index `> i`, within
    /// `r_c + δ` at the build (see [`NeighborList::particle`] and
    /// [`NeighborList::owner_particle`] for particle indices).
    pub fn neighbors(&self, i: usize) -> &[u32] {
        &self.neigh[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Particle index of internal index `i`.
    pub fn particle(&self, i: usize) -> usize {
        self.perm[i] as usize
    }

    /// Particle index of the owner of extended index `j` (a real particle or a ghost).
    pub fn owner_particle(&self, j: usize) -> usize {
        self.perm[self.owner[j] as usize] as usize
    }

    /// Position of extended index `j` (ghosts at their shifted place).
    pub fn position(&self, j: usize) -> [f64; 3] {
        self.pos[j]
    }

    /// Whether the list may have become inexact: the two largest displacements since the last
    /// build add up to more than `δ` (two particles approach by at most `dᵢ + dⱼ`), or no build
    /// was made yet.
    pub fn needs_rebuild(&self, p: &Particles) -> bool {
        if self.x0.len() != p.len() || self.builds == 0 {
            return true;
        }
        let (mut d1, mut d2) = (0.0f64, 0.0f64); // largest and second largest squared
        for i in 0..p.len() {
            let a = self.x0[i];
            let d = [p.x[i] - a[0], p.y[i] - a[1], p.z[i] - a[2]];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if r2 > d2 || r2.is_nan() {
                if r2 > d1 || r2.is_nan() {
                    d2 = d1;
                    d1 = r2;
                } else {
                    d2 = r2;
                }
            }
        }
        let total = d1.sqrt() + d2.sqrt();
        total > self.skin || total.is_nan()
    }

    /// Copies real positions into the extended array (internal order) and moves ghosts with
    /// their owners.
    pub fn update_ghosts(&mut self, p: &Particles) {
        let n = self.n_local;
        let (real, ghosts) = self.pos.split_at_mut(n);
        for (q, &k) in real.iter_mut().zip(&self.perm) {
            let k = k as usize;
            *q = [p.x[k], p.y[k], p.z[k]];
        }
        for ((q, &o), s) in ghosts.iter_mut().zip(&self.owner[n..]).zip(&self.shift) {
            let r = real[o as usize];
            *q = [r[0] + s[0], r[1] + s[1], r[2] + s[2]];
        }
    }

    /// Wraps particles into the box (updating `images`), sorts them by bin, makes ghosts, bins
    /// and builds the half list.
    pub fn build(&mut self, p: &mut Particles, images: &mut [[i32; 3]], bx: &SimBox) {
        let n = p.len();
        let rs = self.cutoff + self.skin;
        self.n_local = n;
        for i in 0..n {
            for (k, c) in [&mut p.x, &mut p.y, &mut p.z].into_iter().enumerate() {
                let (w, m) = bx.wrap(k, c[i]);
                c[i] = w;
                images[i][k] += m;
            }
        }
        self.x0.clear();
        self.x0.extend((0..n).map(|i| [p.x[i], p.y[i], p.z[i]]));
        let l = bx.l;
        let grid = Grid::new(l, rs);
        let nbin = grid.len();

        // internal order: real particles by bin (counting sort, stable in particle index)
        let x0 = &self.x0;
        self.bin_of.clear();
        self.bin_of
            .extend(x0.iter().map(|q| grid.index(grid.coords(q)) as u32));
        counting_sort(
            &self.bin_of,
            nbin,
            &mut self.bin_start,
            &mut self.bin_fill,
            &mut self.perm,
        );
        self.pos.clear();
        self.pos.extend(self.perm.iter().map(|&k| x0[k as usize]));
        self.owner.clear();
        self.owner.extend(0..n as u32);

        // ghosts: every image within r_s of the box, in internal order of their owners
        self.shift.clear();
        for i in 0..n {
            let r = self.pos[i];
            for sx in -1i32..=1 {
                for sy in -1i32..=1 {
                    for sz in -1i32..=1 {
                        if sx == 0 && sy == 0 && sz == 0 {
                            continue;
                        }
                        let s = [sx as f64 * l[0], sy as f64 * l[1], sz as f64 * l[2]];
                        let q = [r[0] + s[0], r[1] + s[1], r[2] + s[2]];
                        if (0..3).all(|k| q[k] >= -rs && q[k] < l[k] + rs) {
                            self.pos.push(q);
                            self.owner.push(i as u32);
                            self.shift.push(s);
                        }
                    }
                }
            }
        }

        // bin the extended set; positions and owners copied in bin order
        let pos = &self.pos;
        self.bin_of.clear();
        self.bin_of
            .extend(pos.iter().map(|q| grid.index(grid.coords(q)) as u32));
        counting_sort(
            &self.bin_of,
            nbin,
            &mut self.bin_start,
            &mut self.bin_fill,
            &mut self.bin_atoms,
        );
        self.bin_pos.clear();
        self.bin_pos
            .extend(self.bin_atoms.iter().map(|&a| pos[a as usize]));
        self.bin_owner.clear();
        let owner = &self.owner;
        self.bin_owner
            .extend(self.bin_atoms.iter().map(|&a| owner[a as usize]));

        // half lists, built in fixed chunks of internal indices and concatenated in order
        let rs2 = rs * rs;
        let (bs, ba, bp, bo) = (
            &self.bin_start,
            &self.bin_atoms,
            &self.bin_pos,
            &self.bin_owner,
        );
        let pieces: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(BUILD_CHUNK))
            .into_par_iter()
            .map(|c| {
                let lo = c * BUILD_CHUNK;
                let hi = (lo + BUILD_CHUNK).min(n);
                let mut list = Vec::with_capacity((hi - lo) * 48);
                let mut counts = Vec::with_capacity(hi - lo);
                for (i, &ri) in pos.iter().enumerate().take(hi).skip(lo) {
                    let c = grid.coords(&ri);
                    let before = list.len();
                    let range = |k: usize| c[k].saturating_sub(2)..=(c[k] + 2).min(grid.nb[k] - 1);
                    for cx in range(0) {
                        for cy in range(1) {
                            let row = grid.index([cx, cy, 0]);
                            let zr = range(2);
                            // bins (cx, cy, z) for z in zr are contiguous
                            let a = bs[row + *zr.start()] as usize;
                            let b = bs[row + *zr.end() + 1] as usize;
                            for ((&j, q), &o) in ba[a..b].iter().zip(&bp[a..b]).zip(&bo[a..b]) {
                                let d = [ri[0] - q[0], ri[1] - q[1], ri[2] - q[2]];
                                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                                if r2 < rs2 && o as usize > i {
                                    list.push(j);
                                }
                            }
                        }
                    }
                    counts.push((list.len() - before) as u32);
                }
                (list, counts)
            })
            .collect();
        self.neigh.clear();
        self.offsets.clear();
        self.offsets.push(0);
        let mut total = 0u32;
        for (list, counts) in &pieces {
            self.neigh.extend_from_slice(list);
            for &c in counts {
                total += c;
                self.offsets.push(total);
            }
        }
        self.verified = (0..n).all(|i| {
            self.neigh[self.offsets[i] as usize..self.offsets[i + 1] as usize]
                .iter()
                .all(|&j| i < j as usize && (j as usize) < self.pos.len())
        });
        self.builds += 1;
    }
}

/// Stable counting sort of indices `0..key.len()` by `key` (< `nbin`): fills `order` and
/// `start` (`start[b]..start[b + 1]` are the positions of bin `b` in `order`).
fn counting_sort(
    key: &[u32],
    nbin: usize,
    start: &mut Vec<u32>,
    fill: &mut Vec<u32>,
    order: &mut Vec<u32>,
) {
    start.clear();
    start.resize(nbin + 1, 0);
    for &b in key {
        start[b as usize + 1] += 1;
    }
    for b in 0..nbin {
        start[b + 1] += start[b];
    }
    fill.clear();
    fill.extend_from_slice(&start[..nbin]);
    order.clear();
    order.resize(key.len(), 0);
    for (a, &b) in key.iter().enumerate() {
        order[fill[b as usize] as usize] = a as u32;
        fill[b as usize] += 1;
    }
}
