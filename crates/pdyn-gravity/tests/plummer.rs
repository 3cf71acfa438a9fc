//! The Plummer generator gives each realization in standard Hénon units: `E = −1/4` and
//! virial ratio `2T/|W| = 1`, measured here from the positions and velocities by direct sums
//! written out in the test (not the library's energy functions); `Scaling::Natural` is the
//! same sample unscaled.

use pdyn_gravity::plummer::{plummer, plummer_scaled, Scaling};
use pdyn_gravity::Particle;

/// (T, W, total mass, centre of mass, its velocity) by the definitions, `G = 1`, no softening.
fn measure(ps: &[Particle]) -> (f64, f64, f64, [f64; 3], [f64; 3]) {
    let mut t = 0.0;
    let mut w = 0.0;
    let mut m = 0.0;
    let (mut rc, mut vc) = ([0.0; 3], [0.0; 3]);
    for (i, a) in ps.iter().enumerate() {
        let v = [a.vel.0[0], a.vel.0[1], a.vel.0[2]];
        t += 0.5 * a.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        m += a.mass;
        let r = [a.pos.0[0], a.pos.0[1], a.pos.0[2]];
        for k in 0..3 {
            rc[k] += a.mass * r[k];
            vc[k] += a.mass * v[k];
        }
        for b in &ps[i + 1..] {
            let d = [
                a.pos.0[0] - b.pos.0[0],
                a.pos.0[1] - b.pos.0[1],
                a.pos.0[2] - b.pos.0[2],
            ];
            w -= a.mass * b.mass / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        }
    }
    (t, w, m, rc, vc)
}

#[test]
fn every_realization_is_in_standard_henon_units() {
    for n in [2usize, 3, 10, 100, 1000] {
        for seed in 1..=24u64 {
            let ps = plummer(n, seed, 1 << 20).unwrap();
            assert_eq!(ps.len(), n);
            let (t, w, m, rc, vc) = measure(&ps);
            let e = t + w;
            assert!((m - 1.0).abs() < 1e-12, "n {n} seed {seed}: M = {m}");
            assert!((e + 0.25).abs() < 1e-12, "n {n} seed {seed}: E = {e}");
            assert!(
                (2.0 * t / -w - 1.0).abs() < 1e-12,
                "n {n} seed {seed}: 2T/|W| = {}",
                2.0 * t / -w
            );
            for k in 0..3 {
                assert!(
                    rc[k].abs() < 1e-12 && vc[k].abs() < 1e-12,
                    "n {n} seed {seed}: {rc:?} {vc:?}"
                );
            }
        }
    }
}

/// The default is the natural sample rescaled: positions in a constant ratio, velocities in
/// another; and the natural sample is what the cut at 10 b makes it (bound, not in standard
/// units: over 24 seeds of 1,000 stars its mean energy is below −1/4).
#[test]
fn natural_scaling_is_the_same_sample_unscaled() {
    let (mut e_sum, mut q_sum) = (0.0, 0.0);
    for seed in 1..=24u64 {
        let h = plummer_scaled(1000, seed, 1 << 20, Scaling::Henon).unwrap();
        let n = plummer_scaled(1000, seed, 1 << 20, Scaling::Natural).unwrap();
        let rp = h[0].pos.0[0] / n[0].pos.0[0];
        let rv = h[0].vel.0[0] / n[0].vel.0[0];
        for (a, b) in h.iter().zip(&n) {
            for (x, y) in [
                (a.pos.0[0], b.pos.0[0]),
                (a.pos.0[1], b.pos.0[1]),
                (a.pos.0[2], b.pos.0[2]),
            ] {
                assert!((x - rp * y).abs() <= 1e-12 * (1.0 + x.abs()), "seed {seed}");
            }
            for (x, y) in [
                (a.vel.0[0], b.vel.0[0]),
                (a.vel.0[1], b.vel.0[1]),
                (a.vel.0[2], b.vel.0[2]),
            ] {
                assert!((x - rv * y).abs() <= 1e-12 * (1.0 + x.abs()), "seed {seed}");
            }
        }
        let (t, w, ..) = measure(&n);
        e_sum += t + w;
        q_sum += 2.0 * t / -w;
    }
    let (e, q) = (e_sum / 24.0, q_sum / 24.0);
    eprintln!("natural scaling, 24 seeds of 1000 stars: mean E = {e:.5}, mean 2T/|W| = {q:.5}");
    assert!(e < -0.25 && e > -0.28, "mean natural E = {e}");
}
