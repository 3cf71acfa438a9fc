//! Nosé–Hoover chain (Martyna, Klein & Tuckerman, J. Chem. Phys. 97, 2635 (1992)), integrated
//! by the Trotter factorisation of Martyna, Tuckerman, Tobias & Klein, Mol. Phys. 87, 1117
//! (1996): a half step of the chain before and after the velocity-Verlet step.
//!
//! Chain of `M` thermostats with positions `ξₖ`, velocities `vₖ`, masses `Q₁ = N_f k_B T τ²`,
//! `Qₖ = k_B T τ²`. Forces `G₁ = (2K − N_f k_B T)/Q₁`, `Gₖ = (Q_{k−1} v²_{k−1} − k_B T)/Qₖ`.
//! Conserved: `H = K + U + Σ ½ Qₖ vₖ² + N_f k_B T ξ₁ + k_B T Σ_{k≥2} ξₖ`.

use super::{positive, scale_velocities, target};
use crate::MdError;
use pdyn_particles::Particles;

/// Nosé–Hoover chain parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoseHooverParams {
    /// Target temperature (required; default `None`).
    pub temperature: Option<f64>,
    /// Relaxation time τ (default 0.5 time units = 100 steps of 0.005, as LAMMPS advises).
    pub tau: f64,
    /// Chain length M (default 3, as LAMMPS `fix nvt`).
    pub chain: usize,
}

impl Default for NoseHooverParams {
    fn default() -> Self {
        NoseHooverParams {
            temperature: None,
            tau: 0.5,
            chain: 3,
        }
    }
}

/// Nosé–Hoover chain state.
#[derive(Debug, Clone)]
pub struct NoseHooverChain {
    /// Target temperature.
    pub temperature: f64,
    tau: f64,
    xi: Vec<f64>,
    v: Vec<f64>,
    q: Vec<f64>,
}

impl NoseHooverChain {
    /// Checks the parameters.
    pub fn new(p: NoseHooverParams) -> Result<Self, MdError> {
        if p.chain == 0 || p.chain > 64 {
            return Err(MdError::InvalidParameter {
                name: "chain",
                value: p.chain as f64,
            });
        }
        Ok(NoseHooverChain {
            temperature: target(p.temperature, "nose-hoover")?,
            tau: positive("tau", p.tau)?,
            xi: vec![0.0; p.chain],
            v: vec![0.0; p.chain],
            q: vec![0.0; p.chain],
        })
    }

    /// The chain's positions `ξₖ` and velocities `vₖ` (the masses follow from the target).
    pub(crate) fn chain(&self) -> (&[f64], &[f64]) {
        (&self.xi, &self.v)
    }

    /// Sets the chain's positions and velocities (of its length: else an error).
    pub(crate) fn set_chain(&mut self, xi: &[f64], v: &[f64]) -> Result<(), MdError> {
        for given in [xi.len(), v.len()] {
            if given != self.xi.len() {
                return Err(MdError::SnapshotMismatch {
                    what: "Nosé–Hoover chain length",
                    expected: self.xi.len(),
                    found: given,
                });
            }
        }
        self.xi.copy_from_slice(xi);
        self.v.copy_from_slice(v);
        Ok(())
    }

    fn masses(&mut self, nf: f64, kt: f64) {
        let t2 = self.tau * self.tau;
        for (k, q) in self.q.iter_mut().enumerate() {
            *q = if k == 0 { nf * kt * t2 } else { kt * t2 };
        }
    }

    /// Half step `h/2` of the chain; scales velocities; returns the new kinetic energy.
    pub(crate) fn half_step(
        &mut self,
        p: &mut Particles,
        h: f64,
        ke: f64,
        nf: f64,
        kb: f64,
    ) -> f64 {
        let kt = kb * self.temperature;
        self.masses(nf, kt);
        let m = self.v.len();
        let (h2, h4, h8) = (0.5 * h, 0.25 * h, 0.125 * h);
        let g = |k: usize, v: &[f64], q: &[f64], ke: f64| {
            if k == 0 {
                (2.0 * ke - nf * kt) / q[0]
            } else {
                (q[k - 1] * v[k - 1] * v[k - 1] - kt) / q[k]
            }
        };
        let mut ke = ke;
        self.v[m - 1] += g(m - 1, &self.v, &self.q, ke) * h4;
        for k in (0..m - 1).rev() {
            let a = libm::exp(-self.v[k + 1] * h8);
            self.v[k] = (self.v[k] * a + g(k, &self.v, &self.q, ke) * h4) * a;
        }
        let s = libm::exp(-self.v[0] * h2);
        scale_velocities(p, s);
        ke *= s * s;
        for k in 0..m {
            self.xi[k] += self.v[k] * h2;
        }
        for k in 0..m - 1 {
            let a = libm::exp(-self.v[k + 1] * h8);
            self.v[k] = (self.v[k] * a + g(k, &self.v, &self.q, ke) * h4) * a;
        }
        self.v[m - 1] += g(m - 1, &self.v, &self.q, ke) * h4;
        ke
    }

    /// Thermostat energy `Σ ½ Qₖ vₖ² + N_f k_B T ξ₁ + k_B T Σ_{k≥2} ξₖ`.
    pub fn energy(&self, nf: f64, kb: f64) -> f64 {
        let kt = kb * self.temperature;
        let t2 = self.tau * self.tau;
        let mut e = 0.0;
        for k in 0..self.v.len() {
            let q = if k == 0 { nf * kt * t2 } else { kt * t2 };
            e += 0.5 * q * self.v[k] * self.v[k] + if k == 0 { nf * kt } else { kt } * self.xi[k];
        }
        e
    }
}
