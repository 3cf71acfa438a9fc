//! Berendsen weak coupling (Berendsen et al., J. Chem. Phys. 81, 3684 (1984)): after each step
//! velocities are scaled by `λ = √(1 + (h/τ)(T₀/T − 1))`, relaxing `T` to `T₀` with time
//! constant `τ`. It does not sample the canonical ensemble: use it to equilibrate only.

use super::{positive, scale_velocities, target};
use crate::MdError;
use pdyn_particles::Particles;

/// Berendsen parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BerendsenParams {
    /// Target temperature (required; default `None`).
    pub temperature: Option<f64>,
    /// Coupling time τ (default 0.5 time units = 100 steps of 0.005).
    pub tau: f64,
}

impl Default for BerendsenParams {
    fn default() -> Self {
        BerendsenParams {
            temperature: None,
            tau: 0.5,
        }
    }
}

/// Berendsen thermostat.
#[derive(Debug, Clone)]
pub struct Berendsen {
    /// Target temperature.
    pub temperature: f64,
    tau: f64,
}

impl Berendsen {
    /// Checks the parameters.
    pub fn new(p: BerendsenParams) -> Result<Self, MdError> {
        Ok(Berendsen {
            temperature: target(p.temperature, "berendsen")?,
            tau: positive("tau", p.tau)?,
        })
    }

    pub(crate) fn rescale(&self, p: &mut Particles, h: f64, t: f64) {
        if t > 0.0 {
            let l2 = 1.0 + h / self.tau * (self.temperature / t - 1.0);
            scale_velocities(p, l2.max(0.0).sqrt());
        }
    }
}
