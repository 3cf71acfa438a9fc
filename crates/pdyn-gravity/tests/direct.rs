//! The blocked direct-summation kernel (`N ≥ PARALLEL_MIN`: Newton's third law over a fixed
//! block triangle) against a naive reference; its independence of the thread count and of
//! the workspace's history; the potential energy against a naive sum.

use pdyn_gravity::forces::direct::{self, DirectWorkspace, PARALLEL_MIN};
use pdyn_gravity::plummer::plummer;
use pdyn_gravity::{Particles, Vec3};

fn sphere(n: usize, seed: u64) -> Particles {
    let mut p = Particles::new();
    for q in plummer(n, seed, 1 << 20).unwrap() {
        p.push(q).unwrap();
    }
    // Unequal masses, so that a swapped mᵢ/mⱼ in the pair kernel shows.
    for i in 0..n {
        p.m[i] *= 1.0 + (i % 7) as f64 / 3.0;
    }
    p
}

/// `aᵢ = G Σ_{j≠i} mⱼ (rⱼ − rᵢ)/(|rⱼ − rᵢ|² + ε²)^{3/2}` term by term, and the scale
/// `G Σ_{j≠i} mⱼ/(|rⱼ − rᵢ|² + ε²)` its round-off is relative to.
fn naive(p: &Particles, i: usize, g: f64, eps2: f64) -> (Vec3, f64) {
    let mut a = Vec3::ZERO;
    let mut scale = 0.0;
    for j in 0..p.len() {
        if j != i {
            let d = p.pos(j) - p.pos(i);
            let r2 = d.norm().powi(2) + eps2;
            a += (g * p.m[j] / (r2 * r2.sqrt())) * d;
            scale += g * p.m[j] / r2;
        }
    }
    (a, scale)
}

/// Every particle, several `N` (one block, a short last block, `N` not a multiple of four,
/// more particles than `MAX_BLOCKS` blocks of `BLOCK_MIN`), with and without softening.
#[test]
fn blocked_kernel_matches_naive_sum() {
    for (n, eps2) in [
        (PARALLEL_MIN, 0.0),
        (257, 1e-4),
        (1001, 0.0),
        (1003, 1e-4),
        (2300, 0.0),
    ] {
        let p = sphere(n, n as u64);
        let mut a = p.clone();
        assert!(!direct::accelerations(&mut a, 0.7, eps2, false));
        let mut worst = 0.0f64;
        for i in 0..n {
            let (exact, scale) = naive(&p, i, 0.7, eps2);
            worst = worst.max((a.acc(i) - exact).norm() / scale);
        }
        assert!(worst < 1e-13, "N = {n}, ε² = {eps2}: error {worst:e}");
    }
}

/// Momentum is conserved by the pair kernel: `Σ mᵢ aᵢ = 0` to round-off.
#[test]
fn blocked_kernel_conserves_momentum() {
    let p = sphere(1001, 5);
    let mut a = p.clone();
    direct::accelerations(&mut a, 1.0, 0.0, false);
    let mut total = Vec3::ZERO;
    let mut scale = 0.0;
    for i in 0..p.len() {
        total += p.m[i] * a.acc(i);
        scale += p.m[i] * a.acc(i).norm();
    }
    assert!(total.norm() < 1e-14 * scale, "{total:?} vs {scale}");
}

/// The same bits on one, two and three threads, and from a workspace that last served a
/// different `N`.
#[test]
fn blocked_kernel_is_deterministic() {
    let p = sphere(1003, 9);
    let run = |threads: usize, ws: &mut DirectWorkspace| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut a = p.clone();
            direct::accelerations_in(ws, &mut a, 1.0, 1e-4, false);
            a
        })
    };
    let mut ws = DirectWorkspace::new();
    let one = run(1, &mut ws);
    for threads in [2, 3] {
        let mut used = DirectWorkspace::new();
        let mut other = sphere(2300, 1);
        direct::accelerations_in(&mut used, &mut other, 1.0, 0.0, false);
        let a = run(threads, &mut used);
        assert_eq!(one.ax, a.ax, "{threads} threads");
        assert_eq!(one.ay, a.ay, "{threads} threads");
        assert_eq!(one.az, a.az, "{threads} threads");
    }
}

/// The potential energy (lanes for `N ≥ PARALLEL_MIN`) against a naive pair sum.
#[test]
fn potential_energy_matches_naive_sum() {
    for n in [100, 1001] {
        let p = sphere(n, 3);
        let mut naive = 0.0;
        let mut scale = 0.0;
        for i in 0..n {
            for j in i + 1..n {
                let r = ((p.pos(i) - p.pos(j)).norm().powi(2) + 1e-4).sqrt();
                naive -= 0.7 * p.m[i] * p.m[j] / r;
                scale += 0.7 * p.m[i] * p.m[j] / r;
            }
        }
        let v = direct::potential_energy(&p, 0.7, 1e-4);
        assert!((v - naive).abs() < 1e-12 * scale, "N = {n}: {v} vs {naive}");
    }
}
