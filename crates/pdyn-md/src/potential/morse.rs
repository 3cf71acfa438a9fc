//! Morse: `u(r) = D[(1 − e^{−a(r−r₀)})² − 1]` (Morse, Phys. Rev. 34, 57 (1929)); minimum `−D`
//! at `r₀`. `u'(r) = 2aD(e^{−a(r−r₀)} − e^{−2a(r−r₀)})`, and the kernel returns
//! `f/r = −u'(r)/r`.

use super::{CutoffMode, RawPair, Truncated};
use crate::MdError;

/// Morse parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Morse {
    /// Well depth D (energy units).
    pub depth: f64,
    /// Stiffness a (1/length).
    pub alpha: f64,
    /// Equilibrium distance r₀.
    pub r0: f64,
}

impl Morse {
    /// Morse with depth `D`, stiffness `a`, equilibrium distance `r₀`.
    pub fn new(depth: f64, alpha: f64, r0: f64) -> Self {
        Morse { depth, alpha, r0 }
    }

    /// Morse with every parameter checked finite and > 0, else `MdError::InvalidParameter`
    /// naming the field.
    pub fn try_new(depth: f64, alpha: f64, r0: f64) -> Result<Self, MdError> {
        crate::thermostat::positive("depth", depth)?;
        crate::thermostat::positive("alpha", alpha)?;
        crate::thermostat::positive("r0", r0)?;
        Ok(Self::new(depth, alpha, r0))
    }

    /// Truncated at `rc` with the given cutoff mode.
    pub fn truncated(self, rc: f64, mode: CutoffMode) -> Truncated<Self> {
        Truncated::new(self, rc, mode)
    }
}

impl RawPair for Morse {
    #[inline]
    fn raw(&self, r2: f64) -> (f64, f64) {
        let r = r2.sqrt();
        let e = libm::exp(-self.alpha * (r - self.r0));
        let u = self.depth * ((1.0 - e) * (1.0 - e) - 1.0);
        let du = 2.0 * self.alpha * self.depth * (e - e * e);
        (u, -du / r)
    }
}
