//! Cluster-pair neighbour list (GROMACS style: Páll & Hess, Comput. Phys. Commun. 184, 2641
//! (2013)) over particles in a spatially sorted internal order.
//!
//! At a build every particle is wrapped into the box (image counters keep the unwrapped
//! trajectory) and the particles are put into *clusters* of [`CL`] = 4: the box is cut into
//! columns along z (square in x and y, of the edge that holds four particles in a cube at the
//! mean density), the particles of a column are sorted by z, and each run of four consecutive
//! particles of a column is a cluster (the last one of a column padded with empty slots). The
//! particles themselves are not permuted: the list keeps the particle index of every slot and
//! its own positions, cluster by cluster, component by component (`[[f64; 4]; 3]`), so that
//! the force kernel loads the four particles of a cluster as one packed vector per component.
//!
//! The list holds pairs of clusters `(i, j, s)` whose bounding boxes, `i`'s shifted by the
//! periodic image `s ∈ {−1, 0, 1}³` (times the box), come within `r_s = r_c + δ`, and at least
//! one of whose 16 particle pairs is within `r_s` at the build. Each pair of particles appears
//! once: `(i, j, s)` is kept for `j > i`, and for `j = i` only for `s = 0` (the *diagonal*
//! entry, of which the kernel takes the particle pairs `a < b`) or `s` lexicographically
//! positive. Periodic images are handled by the shift of the entry, so there are no ghost
//! particles and every force lands on a real cluster (Newton's third law in the kernel). The
//! box must be at least `2 r_s` long so that one image per pair suffices.
//!
//! Empty slots sit far away from everything and from each other (at distinct points more than
//! `r_s` apart), so that every pair involving one falls outside the cutoff without a mask.
//!
//! The entries are sorted by `i`, built in fixed chunks of `i` clusters, and cut into a fixed
//! number of *segments* (a function of the number of particles only): the force loop gives
//! each segment a buffer of its own clusters plus the clusters beyond it that its entries
//! touch (`Segment::foreign`), and adds the buffers in segment order. Every sum is therefore
//! taken in an order fixed by the particles alone: results do not depend on the number of
//! threads. The list stays exact while the two largest displacements since the build add up
//! to at most `δ` (a pair approaches by at most the sum of its two displacements);
//! [`NeighborList::needs_rebuild`] checks that.

use crate::{MdError, SimBox};
use pdyn_particles::Particles;
use rayon::prelude::*;
use std::ops::Range;

/// Particles per cluster (the SIMD width of the kernel over `j`, four `f64` in AVX2).
pub(crate) const CL: usize = 4;

/// Positions (or forces) of one cluster: component, then slot.
pub(crate) type ClusterVec = [[f64; CL]; 3];

/// Slot without a particle.
pub(crate) const EMPTY: u32 = u32::MAX;

/// Clusters per task when the list is built: a fixed size, so that the concatenated list is
/// the same for any number of threads.
const BUILD_CHUNK: usize = 64;

/// Most segments the force loop is cut into (and so the most threads it can use).
const MAX_SEGMENTS: usize = 4;
/// Fewest particles per segment: below that a buffer costs more than the parallelism gains.
const MIN_SEGMENT: usize = 1000;

/// The `j` clusters of one `i` cluster under one periodic shift.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct IEntry {
    /// The `i` cluster.
    pub ci: u32,
    /// Added to the positions of `i` (a multiple of the box lengths).
    pub shift: [f64; 3],
    /// The first `j` is `i` itself with no shift: only its pairs `a < b` count.
    pub diag: bool,
    /// Range of the `j` clusters in `NeighborList::jglobal` / `jlocal`.
    pub js: (u32, u32),
}

/// A range of `i` clusters whose forces go into one buffer.
#[derive(Debug, Clone, Default)]
pub(crate) struct Segment {
    /// First `i` cluster.
    pub lo: usize,
    /// One past the last `i` cluster.
    pub hi: usize,
    /// Its entries in `NeighborList::entries`.
    pub entries: Range<usize>,
    /// Clusters `≥ hi` that its entries touch, ascending: buffer slot `hi − lo + k` is
    /// cluster `foreign[k]`.
    pub foreign: Vec<u32>,
}

/// Cluster-pair list (periodic shifts, internal spatial order) and the buffers it is rebuilt
/// in.
#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    cutoff: f64,
    skin: f64,
    n_local: usize,
    /// Positions by cluster (empty slots far away, see the module documentation).
    pub(crate) xc: Vec<ClusterVec>,
    /// Particle index of every slot `4c + l` ([`EMPTY`] for padding).
    pub(crate) slot: Vec<u32>,
    /// Cluster pairs, by `i` cluster, then shift.
    pub(crate) entries: Vec<IEntry>,
    /// `j` cluster of every `j` entry.
    pub(crate) jglobal: Vec<u32>,
    /// Buffer slot of every `j` entry in its segment's buffer.
    pub(crate) jlocal: Vec<u32>,
    pub(crate) segments: Vec<Segment>,
    bbox: Vec<[[f64; 3]; 2]>,
    col_start: Vec<u32>,
    order: Vec<u32>,
    x0: Vec<[f64; 3]>,
    /// Number of builds so far.
    pub builds: u64,
}

/// Columns along z over the box, square in x and y.
#[derive(Debug, Clone, Copy)]
struct Columns {
    n: [usize; 2],
    scale: [f64; 2],
}

impl Columns {
    /// Columns of edge about `(4/ρ)^{1/3}`: a cluster of four is then about a cube.
    fn new(l: [f64; 3], n_particles: usize) -> Columns {
        let rho = n_particles.max(1) as f64 / (l[0] * l[1] * l[2]);
        let edge = libm::cbrt(CL as f64 / rho);
        let mut n = [1usize; 2];
        let mut scale = [0.0; 2];
        for k in 0..2 {
            let m = (l[k] / edge).floor();
            // at most ~2^16 per axis: far more than any density needs, and no overflow
            n[k] = if m.is_finite() {
                (m as usize).clamp(1, 65_536)
            } else {
                1
            };
            scale[k] = n[k] as f64 / l[k];
        }
        Columns { n, scale }
    }

    fn len(&self) -> usize {
        self.n[0] * self.n[1]
    }

    /// Column coordinate along axis `k` of coordinate `x`, clamped into the grid (a NaN
    /// lands in column 0).
    #[inline]
    fn coord(&self, k: usize, x: f64) -> usize {
        // truncation is the floor for v ≥ 0, and below 0 both clamp to 0: no call to `floor`
        let v = x * self.scale[k];
        (v.max(0.0) as usize).min(self.n[k] - 1)
    }

    #[inline]
    fn index(&self, q: &[f64; 3]) -> usize {
        self.coord(0, q[0]) * self.n[1] + self.coord(1, q[1])
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

    /// Number of clusters (each of [`CL`] slots).
    pub fn clusters(&self) -> usize {
        self.xc.len()
    }

    /// Number of cluster pairs in the list (each costs `CL²` pair evaluations).
    pub fn cluster_pairs(&self) -> usize {
        self.jglobal.len()
    }

    /// Calls `f(a, b, r²)` for every pair of particles `a ≠ b` listed (each pair once, in
    /// list order) whose distance (nearest listed image) is below `sqrt(r2_max)`, at the
    /// current positions.
    pub fn for_each_pair(&self, r2_max: f64, mut f: impl FnMut(usize, usize, f64)) {
        for e in &self.entries {
            let ci = e.ci as usize;
            for (n, &cj) in self.jglobal[e.js.0 as usize..e.js.1 as usize]
                .iter()
                .enumerate()
            {
                let cj = cj as usize;
                for a in 0..CL {
                    let pa = self.slot[ci * CL + a];
                    if pa == EMPTY {
                        continue;
                    }
                    let start = if e.diag && n == 0 { a + 1 } else { 0 };
                    for b in start..CL {
                        let pb = self.slot[cj * CL + b];
                        if pb == EMPTY {
                            continue;
                        }
                        let mut r2 = 0.0;
                        for k in 0..3 {
                            let d = self.xc[ci][k][a] + e.shift[k] - self.xc[cj][k][b];
                            r2 += d * d;
                        }
                        if r2 < r2_max {
                            f(pa as usize, pb as usize, r2);
                        }
                    }
                }
            }
        }
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

    /// Copies the particles' positions into the clusters (between builds).
    pub fn update_positions(&mut self, p: &Particles) {
        for (q, slots) in self.xc.iter_mut().zip(self.slot.chunks_exact(CL)) {
            for (l, &k) in slots.iter().enumerate() {
                if k != EMPTY {
                    let k = k as usize;
                    q[0][l] = p.x[k];
                    q[1][l] = p.y[k];
                    q[2][l] = p.z[k];
                }
            }
        }
    }

    /// Wraps particles into the box (updating `images`), sorts them into clusters and builds
    /// the cluster-pair list.
    pub fn build(&mut self, p: &mut Particles, images: &mut [[i32; 3]], bx: &SimBox) {
        let n = p.len();
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
        self.index_reference(bx.l);
        self.builds += 1;
    }

    /// Clusters, pairs and segments from the reference positions `x0` (a function of them,
    /// the box and the cutoffs only).
    fn index_reference(&mut self, l: [f64; 3]) {
        let rs = self.cutoff + self.skin;
        let cols = Columns::new(l, self.x0.len());
        self.sort_into_clusters(&cols);
        self.fill_clusters(l, rs);
        self.pair_search(&cols, l, rs);
        self.cut_segments();
    }

    /// The positions of the last build (wrapped into the box): with [`NeighborList::builds`],
    /// what [`NeighborList::restore`] needs to make the same list again.
    pub fn reference(&self) -> &[[f64; 3]] {
        &self.x0
    }

    /// The list a build at `reference` (the positions [`NeighborList::reference`] returned)
    /// made, `builds` builds counted, holding the particles' current positions `p`: the same
    /// clusters, pairs and segments, so the same order of the force sums, as the list that
    /// was saved. `reference` must have one entry per particle of `p`.
    pub fn restore(&mut self, reference: &[[f64; 3]], builds: u64, p: &Particles, bx: &SimBox) {
        self.n_local = reference.len();
        self.x0.clear();
        self.x0.extend_from_slice(reference);
        self.index_reference(bx.l);
        self.builds = builds;
        self.update_positions(p);
    }

    /// Internal order: by column (x-major), then by z (ties by particle index); each column
    /// padded to a multiple of [`CL`]. Fills `slot` and `col_start` (first cluster of each
    /// column).
    fn sort_into_clusters(&mut self, cols: &Columns) {
        let x0 = &self.x0;
        let ncol = cols.len();
        let col_of: Vec<u32> = x0.iter().map(|q| cols.index(q) as u32).collect();
        let mut count = vec![0u32; ncol + 1];
        for &c in &col_of {
            count[c as usize + 1] += 1;
        }
        for c in 0..ncol {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        self.order.clear();
        self.order.resize(x0.len(), 0);
        for (a, &c) in col_of.iter().enumerate() {
            self.order[fill[c as usize] as usize] = a as u32;
            fill[c as usize] += 1;
        }
        self.col_start.clear();
        self.col_start.push(0);
        self.slot.clear();
        for c in 0..ncol {
            let members = &mut self.order[count[c] as usize..count[c + 1] as usize];
            // stable: equal z keeps the particle order
            members.sort_by(|&a, &b| x0[a as usize][2].total_cmp(&x0[b as usize][2]));
            self.slot.extend_from_slice(members);
            while self.slot.len() % CL != 0 {
                self.slot.push(EMPTY);
            }
            self.col_start.push((self.slot.len() / CL) as u32);
        }
    }

    /// Positions and bounding boxes of the clusters; empty slots at distinct far points.
    fn fill_clusters(&mut self, l: [f64; 3], rs: f64) {
        let nc = self.slot.len() / CL;
        // farther than rs from any particle (in [0, L) at the build, shifted by at most L,
        // moving by at most δ/2 before the next build) and from each other
        let far = 4.0 * (l[0].max(l[1]).max(l[2]) + rs) + 1.0;
        self.xc.clear();
        self.xc.resize(nc, [[0.0; CL]; 3]);
        self.bbox.clear();
        self.bbox
            .resize(nc, [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]]);
        for c in 0..nc {
            for lane in 0..CL {
                let s = c * CL + lane;
                let k = self.slot[s];
                let q = if k == EMPTY {
                    let v = -far * (1.0 + s as f64);
                    [v, v, v]
                } else {
                    let q = self.x0[k as usize];
                    let b = &mut self.bbox[c];
                    for d in 0..3 {
                        b[0][d] = b[0][d].min(q[d]);
                        b[1][d] = b[1][d].max(q[d]);
                    }
                    q
                };
                for (row, v) in self.xc[c].iter_mut().zip(q) {
                    row[lane] = v;
                }
            }
        }
    }

    /// The cluster pairs within `rs` (see the module documentation), by `i` cluster, in
    /// fixed chunks.
    fn pair_search(&mut self, cols: &Columns, l: [f64; 3], rs: f64) {
        let nc = self.xc.len();
        let rs2 = rs * rs;
        let (xc, bbox, col_start) = (&self.xc, &self.bbox, &self.col_start);
        let pieces: Vec<(Vec<IEntry>, Vec<u32>)> = (0..nc.div_ceil(BUILD_CHUNK))
            .into_par_iter()
            .map(|chunk| {
                let lo = chunk * BUILD_CHUNK;
                let hi = (lo + BUILD_CHUNK).min(nc);
                let mut entries = vec![];
                let mut js = Vec::with_capacity((hi - lo) * 64);
                let mut found = vec![];
                for ci in lo..hi {
                    let bi = bbox[ci];
                    if bi[0][0] > bi[1][0] {
                        continue; // no particle (cannot happen: columns pad only their end)
                    }
                    // shifts in a fixed order; an image of i is needed only near a face
                    let allowed = |k: usize, s: i32| match s {
                        0 => true,
                        1 => bi[0][k] < rs,
                        _ => bi[1][k] > l[k] - rs,
                    };
                    for sx in -1i32..=1 {
                        for sy in -1i32..=1 {
                            for sz in -1i32..=1 {
                                let s = [sx, sy, sz];
                                if !(0..3).all(|k| allowed(k, s[k])) {
                                    continue;
                                }
                                let positive = s.iter().find(|&&v| v != 0).is_some_and(|&v| v > 0);
                                let zero = s == [0, 0, 0];
                                let shift = [sx as f64 * l[0], sy as f64 * l[1], sz as f64 * l[2]];
                                let lo_b = [0, 1, 2].map(|k| bi[0][k] + shift[k]);
                                let hi_b = [0, 1, 2].map(|k| bi[1][k] + shift[k]);
                                found.clear();
                                let mut diag = false;
                                let xr = cols.coord(0, lo_b[0] - rs)..=cols.coord(0, hi_b[0] + rs);
                                for cx in xr {
                                    let yr =
                                        cols.coord(1, lo_b[1] - rs)..=cols.coord(1, hi_b[1] + rs);
                                    for cy in yr {
                                        let col = cx * cols.n[1] + cy;
                                        // clusters below i are listed from their side;
                                        // the column's clusters are sorted by z, so those
                                        // entirely below i's reach are skipped at once
                                        let (c0, c1) =
                                            (col_start[col] as usize, col_start[col + 1] as usize);
                                        let c0 = c0.max(ci).min(c1);
                                        let zlo = lo_b[2] - rs;
                                        let first =
                                            c0 + bbox[c0..c1].partition_point(|b| b[1][2] < zlo);
                                        for cj in first..c1 {
                                            if cj == ci && !zero && !positive {
                                                continue;
                                            }
                                            let bj = bbox[cj];
                                            if bj[0][2] > hi_b[2] + rs {
                                                break; // sorted by z within the column
                                            }
                                            let mut d2 = 0.0;
                                            for k in 0..3 {
                                                let g = (bj[0][k] - hi_b[k])
                                                    .max(lo_b[k] - bj[1][k])
                                                    .max(0.0);
                                                d2 += g * g;
                                            }
                                            if d2 >= rs2 {
                                                continue;
                                            }
                                            if cj == ci && zero {
                                                diag = true;
                                            } else if any_pair_within(&xc[ci], &shift, &xc[cj], rs2)
                                            {
                                                found.push(cj as u32);
                                            }
                                        }
                                    }
                                }
                                if !diag && found.is_empty() {
                                    continue;
                                }
                                let start = js.len() as u32;
                                if diag {
                                    js.push(ci as u32);
                                }
                                js.extend_from_slice(&found);
                                entries.push(IEntry {
                                    ci: ci as u32,
                                    shift,
                                    diag,
                                    js: (start, js.len() as u32),
                                });
                            }
                        }
                    }
                }
                (entries, js)
            })
            .collect();
        self.entries.clear();
        self.jglobal.clear();
        for (entries, js) in pieces {
            let base = self.jglobal.len() as u32;
            self.entries.extend(entries.into_iter().map(|mut e| {
                e.js = (e.js.0 + base, e.js.1 + base);
                e
            }));
            self.jglobal.extend_from_slice(&js);
        }
    }

    /// Cuts the `i` clusters into segments (their number a function of the particle count
    /// only) and maps every `j` entry to its slot in its segment's buffer.
    fn cut_segments(&mut self) {
        let nc = self.xc.len();
        let nseg = (self.n_local / MIN_SEGMENT).clamp(1, MAX_SEGMENTS);
        let entries = &self.entries;
        let jglobal = &self.jglobal;
        let segs: Vec<(Segment, Vec<u32>)> = (0..nseg)
            .into_par_iter()
            .map(|s| {
                let (lo, hi) = (s * nc / nseg, (s + 1) * nc / nseg);
                let e0 = entries.partition_point(|e| (e.ci as usize) < lo);
                let e1 = entries.partition_point(|e| (e.ci as usize) < hi);
                let jr = if e0 < e1 {
                    entries[e0].js.0 as usize..entries[e1 - 1].js.1 as usize
                } else {
                    0..0
                };
                let mut foreign: Vec<u32> = jglobal[jr.clone()]
                    .iter()
                    .copied()
                    .filter(|&c| c as usize >= hi)
                    .collect();
                foreign.sort_unstable();
                foreign.dedup();
                let own = (hi - lo) as u32;
                let local: Vec<u32> = jglobal[jr]
                    .iter()
                    .map(|&c| {
                        if (c as usize) < hi {
                            c - lo as u32
                        } else {
                            // present by construction
                            own + foreign.binary_search(&c).unwrap_or(0) as u32
                        }
                    })
                    .collect();
                (
                    Segment {
                        lo,
                        hi,
                        entries: e0..e1,
                        foreign,
                    },
                    local,
                )
            })
            .collect();
        self.segments.clear();
        self.jlocal.clear();
        for (seg, local) in segs {
            self.segments.push(seg);
            self.jlocal.extend_from_slice(&local);
        }
    }
}

/// Whether any of the 16 pairs of cluster `a` (shifted by `shift`) and cluster `b` is closer
/// than `sqrt(r2)` (empty slots are far away, so they never are). Branch-free over the four
/// lanes of `b`, so that it runs on packed registers.
#[inline]
#[allow(clippy::needless_range_loop)] // `i` picks one particle across the three component rows
fn any_pair_within(a: &ClusterVec, shift: &[f64; 3], b: &ClusterVec, r2: f64) -> bool {
    let mut near = [false; CL];
    for i in 0..CL {
        let q = [a[0][i] + shift[0], a[1][i] + shift[1], a[2][i] + shift[2]];
        for l in 0..CL {
            let d = [q[0] - b[0][l], q[1] - b[1][l], q[2] - b[2][l]];
            near[l] |= d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < r2;
        }
    }
    near.iter().any(|&x| x)
}
