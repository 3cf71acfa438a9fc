//! Direct summation of Newtonian gravity, `O(N²)`.
//!
//! `aᵢ = −G Σ_{j≠i} mⱼ (rᵢ − rⱼ) / (|rᵢ − rⱼ|² + ε²)^{3/2}` with Plummer softening `ε`
//! (zero by default).
//!
//! Both kernels use Newton's third law: each pair `i < j` is evaluated once,
//! `fᵢⱼ = 1/(|rᵢ − rⱼ|² + ε²)^{3/2}` (one square root, one division), and gives
//! `+mⱼ fᵢⱼ (rⱼ − rᵢ)` to `i` and `−mᵢ fᵢⱼ (rⱼ − rᵢ)` to `j`. Which kernel runs, and every
//! summation order, depend on `N` alone, so a result never depends on the thread count:
//! - `N < PARALLEL_MIN`: the symmetric pair loop, serial, in the fixed order `i < j`;
//! - otherwise the particles are cut into `B ≤ MAX_BLOCKS` blocks of equal size (fixed by
//!   `N`). Row `I` of the block triangle (the pairs within block `I`, then those of block `I`
//!   with each later block `J`, in order) is one task; it writes every contribution it makes,
//!   to its own block and to the later ones, into its own buffer. Rayon spreads the rows over
//!   the threads; then `aᵢ = G Σ_{I ≤ block(i)} bufᵢ[I]`, summed in row order. Within a tile,
//!   `i` against the block `J` is a map over `j` (which the compiler vectorises: it updates
//!   `j`'s sums and stores `i`'s terms), then `i`'s terms added in four fixed lanes, the lanes
//!   in a fixed order at the end.
//!
//! On x86-64 CPUs with AVX the rows run in a copy of the kernel compiled for AVX (256-bit
//! vectors; square roots and divisions bound the kernel). It performs the same IEEE
//! operations in the same order (no fused multiply–add), so results are the same bits with
//! and without AVX as well.

use pdyn_particles::Particles;
use rayon::prelude::*;

/// Below this many particles the serial pair loop is used.
pub const PARALLEL_MIN: usize = 256;

/// Smallest block of the parallel kernel (a tile of two blocks stays in the L1 cache).
pub const BLOCK_MIN: usize = 64;

/// Most blocks of the parallel kernel (the workspace holds `B N` accelerations).
pub const MAX_BLOCKS: usize = 32;

/// Workspace of the parallel kernel: one row of partial accelerations per block, so that no
/// force evaluation allocates.
#[derive(Debug, Clone, Default)]
pub struct DirectWorkspace {
    bx: Vec<f64>,
    by: Vec<f64>,
    bz: Vec<f64>,
}

impl DirectWorkspace {
    /// An empty workspace (it grows to the system on first use).
    pub fn new() -> Self {
        Self::default()
    }
}

/// `(block size, number of blocks)` for `n ≥ 1` particles: a function of `n` only.
fn blocks(n: usize) -> (usize, usize) {
    let count = n.div_ceil(BLOCK_MIN).clamp(1, MAX_BLOCKS);
    let size = n.div_ceil(count).next_multiple_of(4);
    (size, n.div_ceil(size))
}

/// Overwrites `ax, ay, az` with the gravitational accelerations of all particles.
/// `skip_01` omits the interaction of particles 0 and 1 (WHFast's Jacobi splitting moves it
/// into the Kepler drift); it only takes effect in the serial kernel, and the function
/// returns whether it did. Allocates a workspace; see [`accelerations_in`] for repeated calls.
pub fn accelerations(p: &mut Particles, g: f64, eps2: f64, skip_01: bool) -> bool {
    accelerations_in(&mut DirectWorkspace::new(), p, g, eps2, skip_01)
}

/// [`accelerations`] with a reusable workspace (no allocation once it has grown to `N`).
pub fn accelerations_in(
    ws: &mut DirectWorkspace,
    p: &mut Particles,
    g: f64,
    eps2: f64,
    skip_01: bool,
) -> bool {
    if p.len() < PARALLEL_MIN {
        pairwise(p, g, eps2, skip_01);
        skip_01
    } else {
        blocked(ws, p, g, eps2);
        false
    }
}

fn pairwise(p: &mut Particles, g: f64, eps2: f64, skip_01: bool) {
    let n = p.len();
    p.clear_acc();
    let (x, y, z, m) = (&p.x, &p.y, &p.z, &p.m);
    let (ax, ay, az) = (&mut p.ax, &mut p.ay, &mut p.az);
    for i in 0..n {
        let (xi, yi, zi, mi) = (x[i], y[i], z[i], m[i]);
        let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
        let start = if skip_01 && i == 0 { 2 } else { i + 1 };
        for j in start..n {
            let dx = xi - x[j];
            let dy = yi - y[j];
            let dz = zi - z[j];
            let r2 = dx * dx + dy * dy + dz * dz + eps2;
            let inv3 = g / (r2 * r2.sqrt());
            let fj = m[j] * inv3;
            let fi = mi * inv3;
            sx -= fj * dx;
            sy -= fj * dy;
            sz -= fj * dz;
            ax[j] += fi * dx;
            ay[j] += fi * dy;
            az[j] += fi * dz;
        }
        ax[i] += sx;
        ay[i] += sy;
        az[i] += sz;
    }
}

/// Positions and masses of a run of particles.
#[derive(Clone, Copy)]
struct Src<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
    m: &'a [f64],
}

impl<'a> Src<'a> {
    fn range(&self, r: std::ops::Range<usize>) -> Src<'a> {
        Src {
            x: &self.x[r.clone()],
            y: &self.y[r.clone()],
            z: &self.z[r.clone()],
            m: &self.m[r],
        }
    }
}

/// `xs` as arrays of four (fixed size: no bounds checks, the lanes become vector operations)
/// and the remainder. (`<[T]>::as_chunks` is newer than the crate's minimum Rust.)
#[inline(always)]
fn quads(xs: &[f64]) -> (impl Iterator<Item = &[f64; 4]>, &[f64]) {
    let n4 = xs.len() / 4 * 4;
    let chunks = xs[..n4]
        .chunks_exact(4)
        .filter_map(|c| <&[f64; 4]>::try_from(c).ok());
    (chunks, &xs[n4..])
}

/// Length of the stack arrays of [`sweep`]'s two passes.
const PASS: usize = 64;

/// `i`'s terms `m_j f (r_j − r_i)` of one pass of [`sweep`].
struct Scratch {
    wx: [f64; PASS],
    wy: [f64; PASS],
    wz: [f64; PASS],
}

impl Scratch {
    fn new() -> Self {
        Scratch {
            wx: [0.0; PASS],
            wy: [0.0; PASS],
            wz: [0.0; PASS],
        }
    }
}

/// Particle `(xi, yi, zi, mi)` against the particles `s` (all of index above it): returns
/// `Σ_j m_j f (r_j − r_i)` and subtracts `m_i f (r_j − r_i)` from `(bx, by, bz)[j]`, with
/// `f = 1/(|r_j − r_i|² + ε²)^{3/2}`.
///
/// In runs of [`PASS`] particles, two passes: first a plain map over `j` (the compiler
/// vectorises it), which updates `j`'s sums and stores `i`'s terms; then `i`'s terms summed
/// in four fixed lanes.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sweep(
    xi: f64,
    yi: f64,
    zi: f64,
    mi: f64,
    s: Src<'_>,
    bx: &mut [f64],
    by: &mut [f64],
    bz: &mut [f64],
    eps2: f64,
    scratch: &mut Scratch,
) -> [f64; 3] {
    let mut lx = [0.0f64; 4];
    let mut ly = [0.0f64; 4];
    let mut lz = [0.0f64; 4];
    let mut rest = [0.0f64; 3];
    let Scratch { wx, wy, wz } = scratch;
    let n = s.x.len();
    let mut lo = 0;
    while lo < n {
        let len = (n - lo).min(PASS);
        let (x, y, z, m) = (
            &s.x[lo..lo + len],
            &s.y[lo..lo + len],
            &s.z[lo..lo + len],
            &s.m[lo..lo + len],
        );
        let (bx, by, bz) = (
            &mut bx[lo..lo + len],
            &mut by[lo..lo + len],
            &mut bz[lo..lo + len],
        );
        let (wx, wy, wz) = (&mut wx[..len], &mut wy[..len], &mut wz[..len]);
        for j in 0..len {
            let dx = x[j] - xi;
            let dy = y[j] - yi;
            let dz = z[j] - zi;
            let r2 = dx * dx + dy * dy + dz * dz + eps2;
            let f = 1.0 / (r2 * r2.sqrt());
            let fi = mi * f;
            bx[j] -= fi * dx;
            by[j] -= fi * dy;
            bz[j] -= fi * dz;
            let fj = m[j] * f;
            wx[j] = fj * dx;
            wy[j] = fj * dy;
            wz[j] = fj * dz;
        }
        let ((cx, tx), (cy, ty), (cz, tz)) = (quads(wx), quads(wy), quads(wz));
        for ((cx, cy), cz) in cx.zip(cy).zip(cz) {
            for l in 0..4 {
                lx[l] += cx[l];
                ly[l] += cy[l];
                lz[l] += cz[l];
            }
        }
        for ((tx, ty), tz) in tx.iter().zip(ty).zip(tz) {
            rest[0] += tx;
            rest[1] += ty;
            rest[2] += tz;
        }
        lo += len;
    }
    [
        ((lx[0] + lx[1]) + (lx[2] + lx[3])) + rest[0],
        ((ly[0] + ly[1]) + (ly[2] + ly[3])) + rest[1],
        ((lz[0] + lz[1]) + (lz[2] + lz[3])) + rest[2],
    ]
}

/// Row `r` of the block triangle into its buffers (`bx` etc. cover all `N` particles; the
/// row writes from its own block on).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn row(
    r: usize,
    size: usize,
    src: Src<'_>,
    eps2: f64,
    bx: &mut [f64],
    by: &mut [f64],
    bz: &mut [f64],
) {
    let n = src.x.len();
    let lo = r * size;
    let hi = (lo + size).min(n);
    let (bx, by, bz) = (&mut bx[lo..], &mut by[lo..], &mut bz[lo..]);
    bx.fill(0.0);
    by.fill(0.0);
    bz.fill(0.0);
    let (own_x, rest_x) = bx.split_at_mut(hi - lo);
    let (own_y, rest_y) = by.split_at_mut(hi - lo);
    let (own_z, rest_z) = bz.split_at_mut(hi - lo);
    let scratch = &mut Scratch::new();
    // The pairs within the block.
    for i in lo..hi {
        let k = i - lo;
        let (xi, yi, zi, mi) = (src.x[i], src.y[i], src.z[i], src.m[i]);
        let (hx, tx) = own_x.split_at_mut(k + 1);
        let (hy, ty) = own_y.split_at_mut(k + 1);
        let (hz, tz) = own_z.split_at_mut(k + 1);
        let s = sweep(
            xi,
            yi,
            zi,
            mi,
            src.range(i + 1..hi),
            tx,
            ty,
            tz,
            eps2,
            scratch,
        );
        hx[k] += s[0];
        hy[k] += s[1];
        hz[k] += s[2];
    }
    // The block against each later block, in order.
    let mut j_lo = hi;
    while j_lo < n {
        let j_hi = (j_lo + size).min(n);
        let (o, e) = (j_lo - hi, j_hi - hi);
        let tile = src.range(j_lo..j_hi);
        for i in lo..hi {
            let k = i - lo;
            let (xi, yi, zi, mi) = (src.x[i], src.y[i], src.z[i], src.m[i]);
            let s = sweep(
                xi,
                yi,
                zi,
                mi,
                tile,
                &mut rest_x[o..e],
                &mut rest_y[o..e],
                &mut rest_z[o..e],
                eps2,
                scratch,
            );
            own_x[k] += s[0];
            own_y[k] += s[1];
            own_z[k] += s[2];
        }
        j_lo = j_hi;
    }
}

/// [`row`] compiled for AVX (256-bit vectors: on AMD Zen 3 they raise the throughput of
/// the square roots and divisions that bound the kernel). The same IEEE operations in the
/// same order as the baseline build (no fused multiply–add), so the same bits.
///
/// # Safety
///
/// The CPU must support AVX. (An `unsafe fn`: a safe `#[target_feature]` function needs
/// Rust 1.86, above the crate's minimum.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn row_avx(
    r: usize,
    size: usize,
    src: Src<'_>,
    eps2: f64,
    bx: &mut [f64],
    by: &mut [f64],
    bz: &mut [f64],
) {
    row(r, size, src, eps2, bx, by, bz);
}

/// [`row`] in the widest vectors the CPU has.
fn row_dispatch(
    r: usize,
    size: usize,
    src: Src<'_>,
    eps2: f64,
    bx: &mut [f64],
    by: &mut [f64],
    bz: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: `row_avx` only needs the AVX instructions, which the CPU was just found
        // to support.
        unsafe { row_avx(r, size, src, eps2, bx, by, bz) };
        return;
    }
    row(r, size, src, eps2, bx, by, bz);
}

fn blocked(ws: &mut DirectWorkspace, p: &mut Particles, g: f64, eps2: f64) {
    let n = p.len();
    let (size, count) = blocks(n);
    for b in [&mut ws.bx, &mut ws.by, &mut ws.bz] {
        b.resize(count * n, 0.0);
    }
    let src = Src {
        x: &p.x,
        y: &p.y,
        z: &p.z,
        m: &p.m,
    };
    ws.bx
        .par_chunks_mut(n)
        .zip(ws.by.par_chunks_mut(n))
        .zip(ws.bz.par_chunks_mut(n))
        .enumerate()
        .with_max_len(1)
        .for_each(|(r, ((bx, by), bz))| row_dispatch(r, size, src, eps2, bx, by, bz));
    // aᵢ = G Σ_{rows r ≤ block(i)} buf_r[i], in row order.
    let (bx, by, bz) = (&ws.bx, &ws.by, &ws.bz);
    p.ax.par_chunks_mut(size)
        .zip(p.ay.par_chunks_mut(size))
        .zip(p.az.par_chunks_mut(size))
        .enumerate()
        .for_each(|(blk, ((ax, ay), az))| {
            let lo = blk * size;
            for (a, b) in [(ax, bx), (ay, by), (az, bz)] {
                let len = a.len();
                a.copy_from_slice(&b[lo..lo + len]);
                for r in 1..=blk {
                    let part = &b[r * n + lo..r * n + lo + len];
                    for (ai, bi) in a.iter_mut().zip(part) {
                        *ai += bi;
                    }
                }
                for ai in a.iter_mut() {
                    *ai *= g;
                }
            }
        });
}

/// `Σ_{j>i} mⱼ / (|rᵢ − rⱼ|² + ε²)^{1/2}` in runs of [`PASS`]: a map over `j` (vectorised),
/// then four fixed lanes.
fn potential_row(p: &Particles, i: usize, eps2: f64) -> f64 {
    let (xi, yi, zi) = (p.x[i], p.y[i], p.z[i]);
    let mut w = [0.0f64; PASS];
    let mut lanes = [0.0f64; 4];
    let mut rest = 0.0;
    let mut lo = i + 1;
    while lo < p.len() {
        let hi = (lo + PASS).min(p.len());
        let len = hi - lo;
        let (x, y, z, m) = (&p.x[lo..hi], &p.y[lo..hi], &p.z[lo..hi], &p.m[lo..hi]);
        let w = &mut w[..len];
        for j in 0..len {
            let dx = x[j] - xi;
            let dy = y[j] - yi;
            let dz = z[j] - zi;
            w[j] = m[j] / (dx * dx + dy * dy + dz * dz + eps2).sqrt();
        }
        let (chunks, tail) = quads(w);
        for c in chunks {
            for l in 0..4 {
                lanes[l] += c[l];
            }
        }
        for t in tail {
            rest += t;
        }
        lo = hi;
    }
    ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) + rest
}

/// Potential energy `−G Σ_{i<j} mᵢ mⱼ / (|rᵢ − rⱼ|² + ε²)^{1/2}`, summed in a fixed order
/// (for `N ≥ PARALLEL_MIN` per particle in parallel, each row in four lanes, then the rows
/// in index order).
pub fn potential_energy(p: &Particles, g: f64, eps2: f64) -> f64 {
    let n = p.len();
    let total: f64 = if n < PARALLEL_MIN {
        let row = |i: usize| -> f64 {
            let mut s = 0.0;
            for j in i + 1..n {
                let dx = p.x[i] - p.x[j];
                let dy = p.y[i] - p.y[j];
                let dz = p.z[i] - p.z[j];
                s += p.m[j] / (dx * dx + dy * dy + dz * dz + eps2).sqrt();
            }
            p.m[i] * s
        };
        (0..n).map(row).sum()
    } else {
        let rows: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|i| p.m[i] * potential_row(p, i, eps2))
            .collect();
        rows.iter().sum()
    };
    -g * total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX build of a row gives the same bits as the baseline one (the tests elsewhere
    /// run whichever the machine picks).
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn avx_rows_equal_baseline_rows() {
        if !std::arch::is_x86_feature_detected!("avx") {
            return;
        }
        let n = 1003;
        let mut p = Particles::new();
        for q in crate::plummer::plummer(n, 4, 1 << 20).unwrap() {
            p.push(q).unwrap();
        }
        let src = Src {
            x: &p.x,
            y: &p.y,
            z: &p.z,
            m: &p.m,
        };
        let (size, count) = blocks(n);
        assert!(count > 1 && n % size != 0);
        for r in [0, count / 2, count - 1] {
            let mut base = vec![vec![0.0; n]; 3];
            let mut avx = vec![vec![0.0; n]; 3];
            if let [bx, by, bz] = &mut base[..] {
                row(r, size, src, 1e-4, bx, by, bz);
            }
            if let [bx, by, bz] = &mut avx[..] {
                // SAFETY: AVX support checked above.
                unsafe { row_avx(r, size, src, 1e-4, bx, by, bz) };
            }
            assert_eq!(base, avx, "row {r}");
            assert!(base[0][r * size..].iter().all(|a| *a != 0.0));
        }
    }
}
