//! Maxwell–Boltzmann velocities: each component `v ~ N(0, k_B T/m)`, then the centre-of-mass
//! velocity is removed and velocities are scaled so that the instantaneous temperature
//! `T = 2K/(N_f k_B)`, `N_f = 3N − 3`, is exactly `T` (as LAMMPS `velocity create`).

use crate::{MdError, Rng};
use pdyn_particles::Particles;

/// Draws velocities at temperature `t` (with Boltzmann constant `kb`) from seed `seed`.
pub fn maxwell_boltzmann(p: &mut Particles, t: f64, kb: f64, seed: u64) -> Result<(), MdError> {
    if !(t.is_finite() && t >= 0.0) {
        return Err(MdError::InvalidParameter {
            name: "temperature",
            value: t,
        });
    }
    let mut rng = Rng::new(seed);
    for i in 0..p.len() {
        let s = if p.m[i] > 0.0 {
            (kb * t / p.m[i]).sqrt()
        } else {
            0.0
        };
        p.vx[i] = s * rng.normal();
        p.vy[i] = s * rng.normal();
        p.vz[i] = s * rng.normal();
    }
    if let Some((_, vcm)) = p.center_of_mass() {
        for i in 0..p.len() {
            p.vx[i] -= vcm.0[0];
            p.vy[i] -= vcm.0[1];
            p.vz[i] -= vcm.0[2];
        }
    }
    let nf = (3 * p.len()).saturating_sub(3) as f64;
    let ke = p.kinetic_energy();
    if ke > 0.0 && nf > 0.0 {
        let s = (0.5 * nf * kb * t / ke).sqrt();
        for v in [&mut p.vx, &mut p.vy, &mut p.vz] {
            v.iter_mut().for_each(|c| *c *= s);
        }
    }
    Ok(())
}
