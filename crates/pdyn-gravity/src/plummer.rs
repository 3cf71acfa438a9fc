//! Plummer-sphere initial conditions (Aarseth, Hénon & Wielen 1974, A&A 37, 183).
//!
//! Density `ρ ∝ (1 + r²/b²)^{−5/2}`. Radii by inverting the cumulative mass
//! `M(r)/M = r³/(1 + r²)^{3/2}`: `r = (X^{−2/3} − 1)^{−1/2}` for `X` uniform; speeds
//! `v = q v_esc`, `v_esc = √2 (1 + r²)^{−1/4}`, with `q` drawn from `g(q) ∝ q² (1 − q²)^{7/2}`
//! by rejection; isotropic directions. Lengths are then scaled by `3π/16` and velocities by
//! `(3π/16)^{−1/2}` to Hénon units (`G = M = 1`, `E = −1/4`), and the system is moved to its
//! centre of mass. Radii beyond `10 b` are redrawn (a 1% mass cut, as is customary).

use std::f64::consts::PI;

use pdyn_particles::{Particle, Vec3};

use crate::rng::SplitMix64;
use crate::GravityError;

/// `n` equal-mass particles (total mass 1) of a Plummer sphere in Hénon units, reproducible
/// from `seed`. `limit` bounds `n` before anything is allocated.
pub fn plummer(n: usize, seed: u64, limit: usize) -> Result<Vec<Particle>, GravityError> {
    if n > limit {
        return Err(GravityError::Particle(
            pdyn_particles::ParticleError::TooMany {
                requested: n,
                limit,
            },
        ));
    }
    let mut rng = SplitMix64::new(seed);
    let scale = 3.0 * PI / 16.0;
    let vscale = 1.0 / scale.sqrt();
    let iso = |rng: &mut SplitMix64, len: f64| {
        let cos_t = rng.uniform_in(-1.0, 1.0);
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        let phi = rng.uniform_in(0.0, 2.0 * PI);
        Vec3::new(
            len * sin_t * phi.cos(),
            len * sin_t * phi.sin(),
            len * cos_t,
        )
    };
    let mut out = Vec::with_capacity(n);
    let m = 1.0 / n as f64;
    for _ in 0..n {
        let r = loop {
            let x = rng.uniform();
            if x <= 0.0 {
                continue;
            }
            let r = 1.0 / (x.powf(-2.0 / 3.0) - 1.0).sqrt();
            if r < 10.0 {
                break r;
            }
        };
        let q = loop {
            let q = rng.uniform();
            let y = 0.1 * rng.uniform();
            if y < q * q * (1.0 - q * q).powf(3.5) {
                break q;
            }
        };
        let ve = 2f64.sqrt() * (1.0 + r * r).powf(-0.25);
        let pos = iso(&mut rng, r * scale);
        let vel = iso(&mut rng, q * ve * vscale);
        out.push(Particle { mass: m, pos, vel });
    }
    let (mut rc, mut vc) = (Vec3::ZERO, Vec3::ZERO);
    for p in &out {
        rc += p.mass * p.pos;
        vc += p.mass * p.vel;
    }
    for p in &mut out {
        p.pos -= rc;
        p.vel -= vc;
    }
    Ok(out)
}
