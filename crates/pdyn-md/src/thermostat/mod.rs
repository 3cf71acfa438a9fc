//! Thermostats coupled to velocity Verlet.
//!
//! A step is `C(h/2) · B(h/2) · A(h/2) · O(h) · A(h/2) · [forces] · B(h/2) · C(h/2)` where `B`
//! is a kick, `A` a drift, `O` the Langevin Ornstein–Uhlenbeck step (absent otherwise, and then
//! the two drifts are one), and `C` the Nosé–Hoover-chain half step (or, at the end only, the
//! Berendsen rescaling). Langevin's opt-in LAMMPS scheme has no `O` step: its friction and
//! noise join the forces (see [`LangevinScheme::Lammps`]). Each thermostat lives in its own
//! file.

mod berendsen;
mod langevin;
mod nose_hoover;

pub use berendsen::{Berendsen, BerendsenParams};
pub use langevin::{Langevin, LangevinNoise, LangevinParams, LangevinScheme};
pub use nose_hoover::{NoseHooverChain, NoseHooverParams};

use crate::MdError;

/// The thermostat of a run (or none: NVE).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Thermostat {
    /// Constant energy.
    None,
    /// Langevin dynamics (BAOAB, or LAMMPS's scheme: [`LangevinScheme`]).
    Langevin(Langevin),
    /// Nosé–Hoover chain.
    NoseHooverChain(NoseHooverChain),
    /// Berendsen weak coupling (equilibration only: not a canonical ensemble).
    Berendsen(Berendsen),
}

pub(crate) fn target(t: Option<f64>, thermostat: &'static str) -> Result<f64, MdError> {
    match t {
        Some(t) if t.is_finite() && t > 0.0 => Ok(t),
        _ => Err(MdError::MissingTemperature { thermostat }),
    }
}

pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, MdError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(MdError::InvalidParameter { name, value })
    }
}

pub(crate) fn scale_velocities(p: &mut pdyn_particles::Particles, s: f64) {
    for v in [&mut p.vx, &mut p.vy, &mut p.vz] {
        v.iter_mut().for_each(|c| *c *= s);
    }
}
