//! Pair forces from the cluster-pair list (`neighbor.rs`), with Newton's third law.
//!
//! For every entry `(i, s)` of the list (an `i` cluster of four particles under a periodic
//! shift `s`, and its `j` clusters) the kernel takes the 4 × 4 particle pairs of each `(i, j)`
//! cluster pair at once: one row per particle `a` of `i`, the four particles of `j` in the
//! lanes of a `[f64; 4]`, loaded whole from the list's cluster-ordered positions (no gather).
//! Pairs beyond the cutoff (and empty slots, which sit far away) are evaluated at `r_c` and
//! masked to zero, so the rows run branch-free on packed registers; on the diagonal entry
//! (`j = i`, no shift) only the pairs `a < b` count. The force on `j` is summed over the four
//! rows and subtracted from `j`'s cluster in the segment's buffer once per cluster pair; the
//! forces on `i` stay in per-lane sums until the entry ends.
//!
//! One kernel source, compiled twice: with AVX2 enabled (chosen at run time when the CPU has
//! it) and for the baseline target. Neither uses fused multiply-add (Rust never contracts
//! `a * b + c`, and FMA is not enabled), and the sums run in the same order, so both give
//! the same bits on every machine; FMA would change the bits between the two, and
//! `f64::mul_add` without hardware FMA is a slow library call.
//!
//! Determinism: the `i` clusters are cut into segments fixed by the particle count (see
//! [`crate::NeighborList`]); each segment adds into a buffer of its own, and the buffers are
//! added in segment order. Energies and virials are summed per lane within a segment, then
//! over segments in order. Results are bitwise identical for any number of threads, which
//! only decide which segments run at the same time. Species: each particle has a type `t`,
//! and a symmetric table holds one potential per pair of types.

use crate::neighbor::{ClusterVec, IEntry, Segment, CL, EMPTY};
use crate::potential::PairPotential;
use crate::{MdError, NeighborList};
use rayon::prelude::*;

/// Buffers the force loop reuses from step to step.
#[derive(Debug, Clone, Default)]
pub(crate) struct ForceScratch {
    /// One buffer per segment: its own clusters, then its foreign ones.
    bufs: Vec<Vec<ClusterVec>>,
    /// Total force per cluster.
    total: Vec<ClusterVec>,
    /// Type of every slot (only with several types; 0 for empty slots).
    types_c: Vec<[u32; CL]>,
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
    /// pair energy and virial `Σ (f/r)·r²`. With `energy` false a kernel may skip the two
    /// sums (the dedicated Lennard-Jones one does, LAMMPS's `eflag`/`vflag`) and return
    /// anything for them; the forces are the same bits either way.
    pub(crate) fn compute(
        &self,
        nl: &NeighborList,
        types: &[u32],
        scratch: &mut ForceScratch,
        forces: &mut [[f64; 3]],
        energy: bool,
    ) -> (f64, f64) {
        const ZERO: ClusterVec = [[0.0; CL]; 3];
        let segments = &nl.segments[..];
        scratch.bufs.resize_with(segments.len(), Vec::new);
        for (seg, b) in segments.iter().zip(scratch.bufs.iter_mut()) {
            b.clear();
            b.resize(seg.hi - seg.lo + seg.foreign.len(), ZERO);
        }
        let list = ListView {
            xc: &nl.xc,
            entries: &nl.entries,
            jglobal: &nl.jglobal,
            jlocal: &nl.jlocal,
        };
        let sums: Vec<(f64, f64)> = if self.ntypes == 1 {
            let p = &self.table[0];
            let rc2 = p.cutoff() * p.cutoff();
            if p.prefers_batch() {
                scratch
                    .bufs
                    .par_iter_mut()
                    .zip(segments)
                    .map(|(buf, seg)| segment_batched(list, seg, buf, p, rc2))
                    .collect()
            } else {
                match avx2_lennard_jones(p) {
                    #[cfg(target_arch = "x86_64")]
                    Some(c) => scratch
                        .bufs
                        .par_iter_mut()
                        .zip(segments)
                        // SAFETY: the CPU has AVX2 (`avx2_lennard_jones`)
                        .map(|(buf, seg)| unsafe {
                            if energy {
                                crate::lj_avx2::kernel::<true>(list, seg, buf, c)
                            } else {
                                crate::lj_avx2::kernel::<false>(list, seg, buf, c)
                            }
                        })
                        .collect(),
                    _ => {
                        let eval = OneType { p, rc2 };
                        scratch
                            .bufs
                            .par_iter_mut()
                            .zip(segments)
                            .map(|(buf, seg)| run_segment(list, seg, buf, &eval))
                            .collect()
                    }
                }
            }
        } else {
            let nt = self.ntypes;
            let tc = &mut scratch.types_c;
            tc.clear();
            tc.extend(
                nl.slot
                    .chunks_exact(CL)
                    .map(|c| c.map_or_zero(|k| types.get(k as usize).copied().unwrap_or(0))),
            );
            let eval = TypeTable {
                tc: &scratch.types_c,
                table: &self.table,
                nt,
            };
            scratch
                .bufs
                .par_iter_mut()
                .zip(segments)
                .map(|(buf, seg)| run_segment(list, seg, buf, &eval))
                .collect()
        };
        let (mut u, mut w) = (0.0, 0.0);
        for (e, v) in sums {
            u += e;
            w += v;
        }
        // the buffers in segment order: each segment's own clusters, then its foreign ones
        let total = &mut scratch.total;
        total.clear();
        total.resize(nl.xc.len(), ZERO);
        for (seg, b) in segments.iter().zip(&scratch.bufs) {
            let own = seg.hi - seg.lo;
            for (t, v) in total[seg.lo..seg.hi].iter_mut().zip(&b[..own]) {
                add_into(t, v);
            }
            for (&c, v) in seg.foreign.iter().zip(&b[own..]) {
                add_into(&mut total[c as usize], v);
            }
        }
        for (t, slots) in total.iter().zip(nl.slot.chunks_exact(CL)) {
            for (l, &k) in slots.iter().enumerate() {
                if k != EMPTY {
                    forces[k as usize] = [t[0][l], t[1][l], t[2][l]];
                }
            }
        }
        (u, w)
    }
}

/// `map` over the four slots of a cluster, with 0 for empty ones.
trait SlotMap {
    fn map_or_zero(&self, f: impl Fn(u32) -> u32) -> [u32; CL];
}

impl SlotMap for [u32] {
    fn map_or_zero(&self, f: impl Fn(u32) -> u32) -> [u32; CL] {
        let mut t = [0; CL];
        for (t, &k) in t.iter_mut().zip(self) {
            *t = if k == EMPTY { 0 } else { f(k) };
        }
        t
    }
}

fn add_into(t: &mut ClusterVec, v: &ClusterVec) {
    for k in 0..3 {
        for l in 0..CL {
            t[k][l] += v[k][l];
        }
    }
}

/// `(u, f/r)` of one row of a cluster pair: particle `a` of cluster `ci` and the four of
/// `cj` at squared distances `r2`, zero outside the cutoff. A trait rather than a closure so
/// that `#[inline(always)]` puts it inside the AVX2 kernel.
trait RowEval: Sync {
    fn row(&self, ci: usize, a: usize, cj: usize, r2: [f64; CL]) -> ([f64; CL], [f64; CL]);
}

/// One potential for every pair: pairs beyond the cutoff are evaluated at `r_c` and masked
/// to zero, so the four lanes run branch-free.
struct OneType<'a, P> {
    p: &'a P,
    rc2: f64,
}

impl<P: PairPotential> RowEval for OneType<'_, P> {
    #[inline(always)]
    fn row(&self, _: usize, _: usize, _: usize, r2: [f64; CL]) -> ([f64; CL], [f64; CL]) {
        let rc2 = self.rc2;
        let r2m = r2.map(|s| if s < rc2 { s } else { rc2 });
        let (mut u, mut fr) = self.p.energy_force4(r2m);
        for l in 0..CL {
            let inside = r2[l] < rc2;
            u[l] = if inside { u[l] } else { 0.0 };
            fr[l] = if inside { fr[l] } else { 0.0 };
        }
        (u, fr)
    }
}

/// A potential per pair of types, looked up lane by lane.
struct TypeTable<'a, P> {
    tc: &'a [[u32; CL]],
    table: &'a [P],
    nt: usize,
}

impl<P: PairPotential> RowEval for TypeTable<'_, P> {
    #[inline(always)]
    fn row(&self, ci: usize, a: usize, cj: usize, r2: [f64; CL]) -> ([f64; CL], [f64; CL]) {
        let row = self.tc[ci][a] as usize * self.nt;
        let mut u = [0.0; CL];
        let mut fr = [0.0; CL];
        for l in 0..CL {
            let p = &self.table[row + self.tc[cj][l] as usize];
            let rc = p.cutoff();
            if r2[l] < rc * rc {
                (u[l], fr[l]) = p.energy_force(r2[l]);
            }
        }
        (u, fr)
    }
}

/// The parts of the list the kernel reads.
#[derive(Clone, Copy)]
pub(crate) struct ListView<'a> {
    pub xc: &'a [ClusterVec],
    pub entries: &'a [IEntry],
    pub jglobal: &'a [u32],
    pub jlocal: &'a [u32],
}

/// Forces the kernel on the portable path even where AVX2 exists (tests compare the two).
pub(crate) static PORTABLE_ONLY: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

fn use_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !PORTABLE_ONLY.load(std::sync::atomic::Ordering::Relaxed)
            && std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The constants of the dedicated AVX2 Lennard-Jones kernel, when the CPU has AVX2 and `p` is
/// a Lennard-Jones it covers.
fn avx2_lennard_jones<P: PairPotential>(p: &P) -> Option<crate::potential::LjConstants> {
    if use_avx2() {
        p.lennard_jones()
    } else {
        None
    }
}

/// [`kernel`] compiled for AVX2 when the CPU has it, else for the baseline target (the same
/// bits either way, see the module documentation).
fn run_segment<E: RowEval>(
    v: ListView,
    seg: &Segment,
    buf: &mut [ClusterVec],
    eval: &E,
) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if use_avx2() {
        // SAFETY: the CPU supports AVX2 (checked at run time just above)
        return unsafe { kernel_avx2(v, seg, buf, eval) };
    }
    kernel(v, seg, buf, eval)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn kernel_avx2<E: RowEval>(
    v: ListView,
    seg: &Segment,
    buf: &mut [ClusterVec],
    eval: &E,
) -> (f64, f64) {
    kernel(v, seg, buf, eval)
}

/// The `i` positions of an entry, shifted.
#[inline(always)]
fn shifted(x: &ClusterVec, s: &[f64; 3]) -> ClusterVec {
    let mut y = *x;
    for (row, sk) in y.iter_mut().zip(s) {
        for v in row.iter_mut() {
            *v += sk;
        }
    }
    y
}

/// Squared distances from particle `a` of `xi` to the four of `xj`.
#[inline(always)]
fn row_r2(xi: &ClusterVec, a: usize, xj: &ClusterVec) -> [f64; CL] {
    let mut r2 = [0.0; CL];
    for l in 0..CL {
        let d0 = xi[0][a] - xj[0][l];
        let d1 = xi[1][a] - xj[1][l];
        let d2 = xi[2][a] - xj[2][l];
        r2[l] = d0 * d0 + d1 * d1 + d2 * d2;
    }
    r2
}

/// Zeroes the lanes `b ≤ a` of row `a` (the diagonal cluster pair counts only `a < b`).
#[inline(always)]
fn mask_diagonal(a: usize, u: &mut [f64; CL], fr: &mut [f64; CL]) {
    for l in 0..CL {
        let keep = l > a;
        u[l] = if keep { u[l] } else { 0.0 };
        fr[l] = if keep { fr[l] } else { 0.0 };
    }
}

/// Row `a` of a cluster pair with `(u, f/r)` (zero where the pair does not count): `(f/r)·d`
/// into `a`'s lane sums `fi` and `j`'s sums `fj`, `u` and the virial `(f/r)·r²` into `ew`.
/// Shared by [`kernel`] and [`segment_batched`], so the two add the same numbers in the same
/// order.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn accumulate(
    xi: &ClusterVec,
    a: usize,
    xj: &ClusterVec,
    r2: &[f64; CL],
    u: &[f64; CL],
    fr: &[f64; CL],
    fi: &mut [[f64; CL]; 3],
    fj: &mut ClusterVec,
    ew: &mut [[f64; CL]; 2],
) {
    for k in 0..3 {
        for l in 0..CL {
            let f = fr[l] * (xi[k][a] - xj[k][l]);
            fi[k][l] += f;
            fj[k][l] += f;
        }
    }
    for l in 0..CL {
        ew[0][l] += u[l];
        ew[1][l] += fr[l] * r2[l];
    }
}

/// Subtracts `fj` from `j`'s buffer slot and, at the end of an entry, adds the lane sums of
/// the `i` forces to `i`'s.
#[inline(always)]
fn store_j(b: &mut ClusterVec, fj: &ClusterVec) {
    for k in 0..3 {
        for l in 0..CL {
            b[k][l] -= fj[k][l];
        }
    }
}

#[inline(always)]
fn store_i(b: &mut ClusterVec, fi: &[[[f64; CL]; 3]; CL]) {
    for (a, f) in fi.iter().enumerate() {
        for k in 0..3 {
            b[k][a] += (f[k][0] + f[k][1]) + (f[k][2] + f[k][3]);
        }
    }
}

/// The entries of one segment into `buf` (zeroed by the caller); returns the segment's
/// energy and virial. `eval(ci, a, cj, r2)` gives `(u, f/r)` for particle `a` of cluster `ci`
/// and the four of `cj`, zero outside the cutoff.
#[inline(always)]
fn kernel<E: RowEval>(v: ListView, seg: &Segment, buf: &mut [ClusterVec], eval: &E) -> (f64, f64) {
    let mut ew = [[0.0; CL]; 2];
    for e in &v.entries[seg.entries.clone()] {
        let ci = e.ci as usize;
        let xi = shifted(&v.xc[ci], &e.shift);
        let mut fi = [[[0.0; CL]; 3]; CL];
        let (j0, j1) = (e.js.0 as usize, e.js.1 as usize);
        for jj in j0..j1 {
            let cj = v.jglobal[jj] as usize;
            let xj = &v.xc[cj];
            let diag = e.diag && jj == j0;
            let mut fj = [[0.0; CL]; 3];
            // the four rows written out, so that each is compiled with its `a` a constant
            macro_rules! row {
                ($a:literal) => {{
                    let r2 = row_r2(&xi, $a, xj);
                    let (mut u, mut fr) = eval.row(ci, $a, cj, r2);
                    if diag {
                        mask_diagonal($a, &mut u, &mut fr);
                    }
                    accumulate(&xi, $a, xj, &r2, &u, &fr, &mut fi[$a], &mut fj, &mut ew);
                }};
            }
            const _: () = assert!(CL == 4);
            row!(0);
            row!(1);
            row!(2);
            row!(3);
            store_j(&mut buf[v.jlocal[jj] as usize], &fj);
        }
        store_i(&mut buf[ci - seg.lo], &fi);
    }
    let lanes = |x: &[f64; CL]| (x[0] + x[1]) + (x[2] + x[3]);
    (lanes(&ew[0]), lanes(&ew[1]))
}

/// [`kernel`] for one potential that is cheaper called once per batch
/// ([`PairPotential::prefers_batch`], a compiled formula): the squared distances of up to
/// `G` cluster pairs of an entry (16 pairs each) are gathered, evaluated by one
/// [`PairPotential::energy_force_batch`], and summed exactly as in [`kernel`], so the two
/// give the same bits for the same `(u, f/r)`.
fn segment_batched<P: PairPotential>(
    v: ListView,
    seg: &Segment,
    buf: &mut [ClusterVec],
    p: &P,
    rc2: f64,
) -> (f64, f64) {
    const G: usize = 16;
    const M: usize = CL * CL;
    let mut r2b = [0.0; G * M];
    let mut ub = [0.0; G * M];
    let mut fb = [0.0; G * M];
    let mut ew = [[0.0; CL]; 2];
    for e in &v.entries[seg.entries.clone()] {
        let ci = e.ci as usize;
        let xi = shifted(&v.xc[ci], &e.shift);
        let mut fi = [[[0.0; CL]; 3]; CL];
        let (j0, j1) = (e.js.0 as usize, e.js.1 as usize);
        let mut g0 = j0;
        while g0 < j1 {
            let g1 = (g0 + G).min(j1);
            let m = (g1 - g0) * M;
            for (jj, r2g) in (g0..g1).zip(r2b.chunks_exact_mut(M)) {
                let xj = &v.xc[v.jglobal[jj] as usize];
                for (a, r2r) in r2g.chunks_exact_mut(CL).enumerate() {
                    let r2 = row_r2(&xi, a, xj);
                    for l in 0..CL {
                        r2r[l] = if r2[l] < rc2 { r2[l] } else { rc2 };
                    }
                }
            }
            p.energy_force_batch(&r2b[..m], &mut ub[..m], &mut fb[..m]);
            for (k, jj) in (g0..g1).enumerate() {
                let xj = &v.xc[v.jglobal[jj] as usize];
                let diag = e.diag && jj == j0;
                let mut fj = [[0.0; CL]; 3];
                for (a, fa) in fi.iter_mut().enumerate() {
                    let r2 = row_r2(&xi, a, xj);
                    let o = k * M + a * CL;
                    let mut u = [0.0; CL];
                    let mut fr = [0.0; CL];
                    for l in 0..CL {
                        let inside = r2[l] < rc2;
                        u[l] = if inside { ub[o + l] } else { 0.0 };
                        fr[l] = if inside { fb[o + l] } else { 0.0 };
                    }
                    if diag {
                        mask_diagonal(a, &mut u, &mut fr);
                    }
                    accumulate(&xi, a, xj, &r2, &u, &fr, fa, &mut fj, &mut ew);
                }
                store_j(&mut buf[v.jlocal[jj] as usize], &fj);
            }
            g0 = g1;
        }
        store_i(&mut buf[ci - seg.lo], &fi);
    }
    let lanes = |x: &[f64; CL]| (x[0] + x[1]) + (x[2] + x[3]);
    (lanes(&ew[0]), lanes(&ew[1]))
}

#[cfg(test)]
mod tests {
    use super::PORTABLE_ONLY;
    use crate::potential::{CutoffMode, LennardJones};
    use crate::thermostat::Thermostat;
    use crate::*;
    use std::sync::atomic::Ordering;

    /// 2,048 LJ atoms (two segments), 40 steps, with the kernel the CPU selects and with the
    /// portable one.
    fn run_both(mode: CutoffMode) -> [(Particles, ThermoRecord); 2] {
        [false, true].map(|portable| {
            PORTABLE_ONLY.store(portable, Ordering::Relaxed);
            let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [8; 3], 1.0, 1 << 20).unwrap();
            maxwell_boltzmann(&mut p, 1.44, 1.0, 11).unwrap();
            let lj = LennardJones::new(1.0, 1.0).truncated(2.5, mode);
            let mut sim = Simulation::new(
                System::new(p, bx),
                ForceField::single(lj),
                Thermostat::None,
                SimParams {
                    thermo_every: 7,
                    ..SimParams::default()
                },
            )
            .unwrap();
            sim.run(40, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
            PORTABLE_ONLY.store(false, Ordering::Relaxed);
            (sim.system.particles.clone(), sim.thermo())
        })
    }

    /// The AVX2 Lennard-Jones kernel (where the CPU has AVX2) and the portable kernel give
    /// the same bits: positions, velocities, energy and pressure after 40 steps.
    #[test]
    fn avx2_and_portable_kernels_agree_bit_for_bit() {
        #[cfg(target_arch = "x86_64")]
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2 on this CPU: both runs take the portable kernel");
        }
        for mode in [CutoffMode::Plain, CutoffMode::ShiftedEnergy] {
            let [a, b] = run_both(mode);
            assert_eq!(a.0, b.0, "{mode:?}");
            assert_eq!(a.1, b.1, "{mode:?}");
        }
    }
}
