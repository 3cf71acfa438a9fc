//! Plummer-sphere initial conditions (Aarseth, Hénon & Wielen 1974, A&A 37, 183).
//!
//! Density `ρ ∝ (1 + r²/b²)^{−5/2}`. Radii by inverting the cumulative mass
//! `M(r)/M = r³/(1 + r²)^{3/2}`: `r = (X^{−2/3} − 1)^{−1/2}` for `X` uniform; speeds
//! `v = q v_esc`, `v_esc = √2 (1 + r²)^{−1/4}`, with `q` drawn from `g(q) ∝ q² (1 − q²)^{7/2}`
//! by rejection; isotropic directions. Lengths are then scaled by `3π/16` and velocities by
//! `(3π/16)^{−1/2}` to Hénon units (`G = M = 1`, `E = −1/4` for the untruncated model), and
//! the system is moved to its centre of mass. Radii beyond `10 b` are redrawn (a 1% mass cut,
//! as is customary).
//!
//! That alone leaves each realization off standard units: the cut removes the loosest mass
//! (24 seeds of 1,000 stars: mean `E = −0.259`, virial ratio 0.990), and a finite sample
//! fluctuates around the model. So by default ([`Scaling::Henon`]) each realization is then
//! rescaled exactly to standard Hénon units, as N-body codes do: velocities by
//! `√(|W|/2T)` (virial ratio `2T/|W| = 1`), then lengths by `s = −2W` and velocities by
//! `1/√s`, which gives `W = −1/2`, `T = 1/4`, `E = −1/4` (`W` the unsoftened potential energy
//! with `G = 1`, summed directly). [`Scaling::Natural`] keeps the sample as drawn.

use std::f64::consts::PI;

use pdyn_particles::{Particle, Vec3};

use crate::rng::SplitMix64;
use crate::GravityError;

/// How a Plummer realization is scaled once drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scaling {
    /// Rescaled exactly to standard Hénon units: `E = −1/4`, `2T/|W| = 1` (the default).
    #[default]
    Henon,
    /// As drawn: the model's units, with the sample's fluctuations and the bias of the cut
    /// at `10 b`.
    Natural,
}

/// `n` equal-mass particles (total mass 1) of a Plummer sphere in standard Hénon units
/// (`G = M = 1`, `E = −1/4`, virial ratio 1, centre of mass at rest at the origin),
/// reproducible from `seed`. `limit` bounds `n` before anything is allocated.
pub fn plummer(n: usize, seed: u64, limit: usize) -> Result<Vec<Particle>, GravityError> {
    plummer_scaled(n, seed, limit, Scaling::Henon)
}

/// [`plummer`] with the choice of [`Scaling`].
pub fn plummer_scaled(
    n: usize,
    seed: u64,
    limit: usize,
    scaling: Scaling,
) -> Result<Vec<Particle>, GravityError> {
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
            len * sin_t * libm::cos(phi),
            len * sin_t * libm::sin(phi),
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
            let r = 1.0 / (libm::pow(x, -2.0 / 3.0) - 1.0).sqrt();
            if r < 10.0 {
                break r;
            }
        };
        let q = loop {
            let q = rng.uniform();
            let y = 0.1 * rng.uniform();
            if y < q * q * libm::pow(1.0 - q * q, 3.5) {
                break q;
            }
        };
        let ve = 2f64.sqrt() * libm::pow(1.0 + r * r, -0.25);
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
    if scaling == Scaling::Henon {
        to_standard_units(&mut out);
    }
    Ok(out)
}

/// Rescales particles (total mass 1, centre of mass at the origin, at rest) to standard Hénon
/// units: `2T/|W| = 1` by the velocities, then `W = −1/2` by the lengths (velocities as
/// `1/√length`, which keeps the virial ratio), so `E = −1/4`. Nothing to do for fewer than
/// two particles or a sample at rest.
fn to_standard_units(out: &mut [Particle]) {
    if out.len() < 2 {
        return;
    }
    let mut store = pdyn_particles::Particles::new();
    for p in out.iter() {
        if store.push(*p).is_err() {
            return; // not finite: left as drawn (cannot happen for a drawn sphere)
        }
    }
    let t = store.kinetic_energy();
    let w = crate::forces::direct::potential_energy(&store, 1.0, 0.0);
    if !(t > 0.0 && w < 0.0 && w.is_finite()) {
        return;
    }
    let q = (-w / (2.0 * t)).sqrt();
    let s = -2.0 * w;
    let (pos, vel) = (s, q / s.sqrt());
    for p in out.iter_mut() {
        p.pos = pos * p.pos;
        p.vel = vel * p.vel;
    }
}
