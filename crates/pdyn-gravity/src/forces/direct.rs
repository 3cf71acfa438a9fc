//! Direct summation of Newtonian gravity, `O(N²)`.
//!
//! `aᵢ = −G Σ_{j≠i} mⱼ (rᵢ − rⱼ) / (|rᵢ − rⱼ|² + ε²)^{3/2}` with Plummer softening `ε`
//! (zero by default).
//!
//! Two kernels, chosen by `N` alone (so a result never depends on the thread count):
//! - `N < PARALLEL_MIN`: the symmetric pair loop (each pair once, Newton's third law), serial,
//!   in the fixed order `i < j`;
//! - otherwise each particle's sum is computed by one thread over all `j` in index order,
//!   with four fixed accumulator lanes (so the loop vectorises) added in a fixed order at
//!   the end; rayon distributes particles over threads. Every particle's acceleration is
//!   the same bit pattern whatever the number of threads.

use pdyn_particles::Particles;
use rayon::prelude::*;

/// Below this many particles the serial pair loop is used.
pub const PARALLEL_MIN: usize = 256;

/// Overwrites `ax, ay, az` with the gravitational accelerations of all particles.
/// `skip_01` omits the interaction of particles 0 and 1 (WHFast's Jacobi splitting moves it
/// into the Kepler drift); it only takes effect in the serial kernel, and the function
/// returns whether it did.
pub fn accelerations(p: &mut Particles, g: f64, eps2: f64, skip_01: bool) -> bool {
    if p.len() < PARALLEL_MIN {
        pairwise(p, g, eps2, skip_01);
        skip_01
    } else {
        per_particle(p, g, eps2);
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

/// `Σ_j m_j (r_j − r_i)/(|r_j − r_i|² + ε²)^{3/2}` over the given slices, in four lanes.
#[inline]
#[allow(clippy::too_many_arguments)]
fn lane_sum(
    xi: f64,
    yi: f64,
    zi: f64,
    x: &[f64],
    y: &[f64],
    z: &[f64],
    m: &[f64],
    eps2: f64,
) -> [f64; 3] {
    let mut lx = [0.0f64; 4];
    let mut ly = [0.0f64; 4];
    let mut lz = [0.0f64; 4];
    let n4 = x.len() / 4 * 4;
    let (xc, yc, zc, mc) = (
        x[..n4].chunks_exact(4),
        y[..n4].chunks_exact(4),
        z[..n4].chunks_exact(4),
        m[..n4].chunks_exact(4),
    );
    for (((cx, cy), cz), cm) in xc.zip(yc).zip(zc).zip(mc) {
        // Fixed-size views: no bounds checks, so the four lanes become one vector operation.
        // (`chunks_exact(4)` only yields chunks of 4, so the `else` is never taken.)
        let (Ok(cx), Ok(cy), Ok(cz), Ok(cm)) = (
            <&[f64; 4]>::try_from(cx),
            <&[f64; 4]>::try_from(cy),
            <&[f64; 4]>::try_from(cz),
            <&[f64; 4]>::try_from(cm),
        ) else {
            continue;
        };
        let mut f = [0.0f64; 4];
        let mut dx = [0.0f64; 4];
        let mut dy = [0.0f64; 4];
        let mut dz = [0.0f64; 4];
        for l in 0..4 {
            dx[l] = cx[l] - xi;
            dy[l] = cy[l] - yi;
            dz[l] = cz[l] - zi;
            let r2 = dx[l] * dx[l] + dy[l] * dy[l] + dz[l] * dz[l] + eps2;
            f[l] = cm[l] / (r2 * r2.sqrt());
        }
        for l in 0..4 {
            lx[l] += f[l] * dx[l];
            ly[l] += f[l] * dy[l];
            lz[l] += f[l] * dz[l];
        }
    }
    let mut s = [
        (lx[0] + lx[1]) + (lx[2] + lx[3]),
        (ly[0] + ly[1]) + (ly[2] + ly[3]),
        (lz[0] + lz[1]) + (lz[2] + lz[3]),
    ];
    for j in n4..x.len() {
        let dx = x[j] - xi;
        let dy = y[j] - yi;
        let dz = z[j] - zi;
        let r2 = dx * dx + dy * dy + dz * dz + eps2;
        let f = m[j] / (r2 * r2.sqrt());
        s[0] += f * dx;
        s[1] += f * dy;
        s[2] += f * dz;
    }
    s
}

fn per_particle(p: &mut Particles, g: f64, eps2: f64) {
    let (x, y, z, m) = (&p.x, &p.y, &p.z, &p.m);
    p.ax.par_iter_mut()
        .zip(p.ay.par_iter_mut())
        .zip(p.az.par_iter_mut())
        .enumerate()
        .with_min_len(32)
        .for_each(|(i, ((ax, ay), az))| {
            let (xi, yi, zi) = (x[i], y[i], z[i]);
            let lo = lane_sum(xi, yi, zi, &x[..i], &y[..i], &z[..i], &m[..i], eps2);
            let hi = lane_sum(
                xi,
                yi,
                zi,
                &x[i + 1..],
                &y[i + 1..],
                &z[i + 1..],
                &m[i + 1..],
                eps2,
            );
            *ax = g * (lo[0] + hi[0]);
            *ay = g * (lo[1] + hi[1]);
            *az = g * (lo[2] + hi[2]);
        });
}

/// Potential energy `−G Σ_{i<j} mᵢ mⱼ / (|rᵢ − rⱼ|² + ε²)^{1/2}`, summed in a fixed order
/// (per particle in parallel for large `N`, then the per-particle sums in index order).
pub fn potential_energy(p: &Particles, g: f64, eps2: f64) -> f64 {
    let n = p.len();
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
    let total: f64 = if n < PARALLEL_MIN {
        (0..n).map(row).sum()
    } else {
        let rows: Vec<f64> = (0..n).into_par_iter().map(row).collect();
        rows.iter().sum()
    };
    -g * total
}
