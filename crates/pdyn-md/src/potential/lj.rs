//! Lennard-Jones 12-6: `u(r) = 4ε[(σ/r)¹² − (σ/r)⁶]` (Jones, Proc. R. Soc. A 106, 463 (1924)).
//!
//! `f/r = 24ε[2(σ/r)¹² − (σ/r)⁶]/r²`. Long-range (tail) corrections for a plain cutoff `r_c`
//! at number density `ρ` (Allen & Tildesley §2.8):
//! `U_tail/N = (8/3)πρεσ³[(1/3)(σ/r_c)⁹ − (σ/r_c)³]`,
//! `P_tail = (16/3)πρ²εσ³[(2/3)(σ/r_c)⁹ − (σ/r_c)³]`.

use super::{CutoffMode, RawPair, Truncated};
use crate::MdError;
use std::f64::consts::PI;

/// Lennard-Jones parameters (well depth `ε`, diameter `σ`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LennardJones {
    /// Well depth ε (energy units).
    pub epsilon: f64,
    /// Zero-crossing distance σ (length units).
    pub sigma: f64,
    sigma2: f64,
    eps4: f64,
    eps24: f64,
}

impl LennardJones {
    /// LJ with `ε` and `σ`.
    pub fn new(epsilon: f64, sigma: f64) -> Self {
        LennardJones {
            epsilon,
            sigma,
            sigma2: sigma * sigma,
            eps4: 4.0 * epsilon,
            eps24: 24.0 * epsilon,
        }
    }

    /// LJ with `ε` and `σ` checked: both must be finite and > 0 (a zero or negative `σ` or
    /// `ε` gives no repulsive core or an attractive one, and NaN poisons every force), else
    /// `MdError::InvalidParameter` naming the field.
    pub fn try_new(epsilon: f64, sigma: f64) -> Result<Self, MdError> {
        crate::thermostat::positive("epsilon", epsilon)?;
        crate::thermostat::positive("sigma", sigma)?;
        Ok(Self::new(epsilon, sigma))
    }

    /// Truncated at `rc` with the given cutoff mode.
    pub fn truncated(self, rc: f64, mode: CutoffMode) -> Truncated<Self> {
        Truncated::new(self, rc, mode)
    }

    /// Tail correction to the energy per particle at density `rho` for a plain cutoff `rc`.
    pub fn energy_tail_per_particle(&self, rho: f64, rc: f64) -> f64 {
        let s3 = (self.sigma / rc).powi(3);
        8.0 / 3.0 * PI * rho * self.epsilon * self.sigma.powi(3) * (s3 * s3 * s3 / 3.0 - s3)
    }

    /// Tail correction to the pressure at density `rho` for a plain cutoff `rc`.
    pub fn pressure_tail(&self, rho: f64, rc: f64) -> f64 {
        let s3 = (self.sigma / rc).powi(3);
        16.0 / 3.0
            * PI
            * rho
            * rho
            * self.epsilon
            * self.sigma.powi(3)
            * (2.0 / 3.0 * s3 * s3 * s3 - s3)
    }
}

/// Lennard-Jones constants of the kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LjConstants {
    /// `σ²`.
    pub sigma2: f64,
    /// `4ε`.
    pub eps4: f64,
    /// `24ε`.
    pub eps24: f64,
    /// Energy shift `u(r_c)` (0 for a plain cutoff).
    pub u_c: f64,
    /// Cutoff `r_c`.
    pub rc: f64,
}

impl RawPair for LennardJones {
    fn lennard_jones(&self) -> Option<LjConstants> {
        Some(LjConstants {
            sigma2: self.sigma2,
            eps4: self.eps4,
            eps24: self.eps24,
            u_c: 0.0,
            rc: f64::INFINITY,
        })
    }

    #[inline(always)]
    fn raw(&self, r2: f64) -> (f64, f64) {
        let inv = 1.0 / r2;
        let sr2 = self.sigma2 * inv;
        let sr6 = sr2 * sr2 * sr2;
        (
            self.eps4 * sr6 * (sr6 - 1.0),
            self.eps24 * sr6 * (2.0 * sr6 - 1.0) * inv,
        )
    }

    #[inline(always)]
    fn raw4(&self, r2: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        // the operations of `raw`, in its order, one array at a time
        let inv = r2.map(|s| 1.0 / s);
        let sr2 = inv.map(|i| self.sigma2 * i);
        let sr6 = sr2.map(|s| s * s * s);
        let mut u = [0.0; 4];
        let mut f = [0.0; 4];
        for l in 0..4 {
            u[l] = self.eps4 * sr6[l] * (sr6[l] - 1.0);
        }
        for l in 0..4 {
            f[l] = self.eps24 * sr6[l] * (2.0 * sr6[l] - 1.0) * inv[l];
        }
        (u, f)
    }
}
