//! Verlet neighbour list with a skin, built through a cell list over the box and its periodic
//! ghost images.
//!
//! At a build every particle is wrapped into the box (image counters keep the unwrapped
//! trajectory), and every periodic image lying within `r_s = r_c + δ` of the box is added as a
//! *ghost* with a fixed shift (as in LAMMPS's ghost atoms). The extended set is binned into
//! cells of edge `≥ r_s` (counting sort), and each real particle `i` gets the *full* list of
//! extended indices `j ≠ i` with `|rᵢ − rⱼ| < r_s`, scanning the 27 surrounding cells in a fixed
//! order. Between builds ghosts follow their owners (`r_g = r_owner + shift`), so the force loop
//! needs no minimum image. The list stays exact while the two largest displacements since
//! the build add up to at most `δ` (a pair approaches by at most the sum of its two
//! displacements); [`NeighborList::needs_rebuild`] checks that after every drift.

use crate::{MdError, SimBox};
use pdyn_particles::Particles;
use rayon::prelude::*;

/// Verlet list (full, with ghosts) and the buffers it is rebuilt in.
#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    cutoff: f64,
    skin: f64,
    n_local: usize,
    /// Extended positions: `n_local` real particles, then ghosts.
    pub(crate) pos: Vec<[f64; 3]>,
    /// Real particle of every extended index.
    pub(crate) owner: Vec<u32>,
    shift: Vec<[f64; 3]>,
    stride: usize,
    count: Vec<u32>,
    neigh: Vec<u32>,
    cell_of: Vec<u32>,
    cell_start: Vec<u32>,
    cell_atoms: Vec<u32>,
    /// Positions in cell order (`cell_pos[k] = pos[cell_atoms[k]]`), scanned contiguously.
    cell_pos: Vec<[f64; 3]>,
    cell_fill: Vec<u32>,
    x0: Vec<[f64; 3]>,
    /// Number of builds so far.
    pub builds: u64,
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
            stride: 64,
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

    /// Extended indices of the neighbours of real particle `i` (within `r_c + δ` at the build).
    pub fn neighbors(&self, i: usize) -> &[u32] {
        &self.neigh[i * self.stride..i * self.stride + self.count[i] as usize]
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

    /// Copies real positions into the extended array and moves ghosts with their owners.
    pub fn update_ghosts(&mut self, p: &Particles) {
        let n = self.n_local;
        for i in 0..n {
            self.pos[i] = [p.x[i], p.y[i], p.z[i]];
        }
        for g in n..self.pos.len() {
            let o = self.owner[g] as usize;
            let s = self.shift[g - n];
            self.pos[g] = [p.x[o] + s[0], p.y[o] + s[1], p.z[o] + s[2]];
        }
    }

    /// Wraps particles into the box (updating `images`), makes ghosts, bins and builds the list.
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
        self.pos.clear();
        self.pos.extend_from_slice(&self.x0);
        self.owner.clear();
        self.owner.extend(0..n as u32);
        self.shift.clear();
        let l = bx.l;
        for i in 0..n {
            let r = self.x0[i];
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
        // cells over [-rs, L + rs)
        let mut nc = [1usize; 3];
        let mut size = [0.0; 3];
        for k in 0..3 {
            let ext = l[k] + 2.0 * rs;
            nc[k] = ((ext / rs).floor() as usize).max(1);
            size[k] = ext / nc[k] as f64;
        }
        let ncell = nc[0] * nc[1] * nc[2];
        let cell_index = |q: &[f64; 3]| -> [usize; 3] {
            let mut c = [0; 3];
            for k in 0..3 {
                let v = ((q[k] + rs) / size[k]).floor();
                c[k] = (v.max(0.0) as usize).min(nc[k] - 1);
            }
            c
        };
        self.cell_of.clear();
        self.cell_of.extend(self.pos.iter().map(|q| {
            let c = cell_index(q);
            ((c[0] * nc[1] + c[1]) * nc[2] + c[2]) as u32
        }));
        self.cell_start.clear();
        self.cell_start.resize(ncell + 1, 0);
        for &c in &self.cell_of {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..ncell {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.cell_atoms.clear();
        self.cell_atoms.resize(self.pos.len(), 0);
        self.cell_fill.clear();
        self.cell_fill.extend_from_slice(&self.cell_start[..ncell]);
        for (a, &c) in self.cell_of.iter().enumerate() {
            self.cell_atoms[self.cell_fill[c as usize] as usize] = a as u32;
            self.cell_fill[c as usize] += 1;
        }
        self.cell_pos.clear();
        let pos = &self.pos;
        self.cell_pos
            .extend(self.cell_atoms.iter().map(|&a| pos[a as usize]));
        // full lists, rebuilt with a larger stride if some particle overflows
        let rs2 = rs * rs;
        self.count.clear();
        self.count.resize(n, 0);
        loop {
            if self.neigh.len() < n * self.stride {
                self.neigh.resize(n * self.stride, 0);
            }
            let stride = self.stride;
            let (pos, cs, ca, cp) = (
                &self.pos,
                &self.cell_start,
                &self.cell_atoms,
                &self.cell_pos,
            );
            let max = self.neigh[..n * stride]
                .par_chunks_mut(stride)
                .zip(self.count.par_iter_mut())
                .enumerate()
                .with_min_len(64)
                .map(|(i, (list, cnt))| {
                    let ri = pos[i];
                    let c = cell_index(&ri);
                    let mut m = 0usize;
                    for cx in c[0].saturating_sub(1)..=(c[0] + 1).min(nc[0] - 1) {
                        for cy in c[1].saturating_sub(1)..=(c[1] + 1).min(nc[1] - 1) {
                            for cz in c[2].saturating_sub(1)..=(c[2] + 1).min(nc[2] - 1) {
                                let cell = (cx * nc[1] + cy) * nc[2] + cz;
                                let range = cs[cell] as usize..cs[cell + 1] as usize;
                                for (&j, q) in ca[range.clone()].iter().zip(&cp[range]) {
                                    let d = [ri[0] - q[0], ri[1] - q[1], ri[2] - q[2]];
                                    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                                    if r2 < rs2 && j as usize != i {
                                        if m < stride {
                                            list[m] = j;
                                        }
                                        m += 1;
                                    }
                                }
                            }
                        }
                    }
                    *cnt = m.min(stride) as u32;
                    m
                })
                .max()
                .unwrap_or(0);
            if max <= self.stride {
                break;
            }
            self.stride = max + max / 4 + 8;
        }
        self.builds += 1;
    }
}
