//! Truncation of a raw pair potential at `r_c` (Allen & Tildesley §5.2.3):
//!
//! * plain: `u_c(r) = u(r)` for `r < r_c` (energy jumps at `r_c`; what LAMMPS `lj/cut` does
//!   without `pair_modify shift yes`);
//! * shifted energy: `u_c(r) = u(r) − u(r_c)` (continuous energy, same forces);
//! * shifted force: `u_c(r) = u(r) − u(r_c) − (r − r_c) u'(r_c)` (continuous energy and force).

use super::{LjConstants, PairPotential, RawPair};
use crate::MdError;

/// How the potential is cut at `r_c`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CutoffMode {
    /// No shift.
    Plain,
    /// Energy shifted to zero at the cutoff.
    ShiftedEnergy,
    /// Energy and force both go to zero at the cutoff.
    ShiftedForce,
}

/// A raw potential cut at `rc` in a given mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truncated<P> {
    /// The untruncated potential.
    pub inner: P,
    rc: f64,
    mode: CutoffMode,
    u_c: f64,
    f_c: f64,
}

impl<P: RawPair> Truncated<P> {
    /// `inner` cut at `rc` in `mode`.
    pub fn new(inner: P, rc: f64, mode: CutoffMode) -> Self {
        let (u, fr) = inner.raw(rc * rc);
        let (u_c, f_c) = match mode {
            CutoffMode::Plain => (0.0, 0.0),
            CutoffMode::ShiftedEnergy => (u, 0.0),
            CutoffMode::ShiftedForce => (u, fr * rc),
        };
        Truncated {
            inner,
            rc,
            mode,
            u_c,
            f_c,
        }
    }

    /// `inner` cut at `rc`, checked: `rc` finite and > 0, and the potential and force finite
    /// at `rc` (a shift by a non-finite value would poison every pair), else
    /// `MdError::InvalidParameter` (`cutoff`, or `u(cutoff)` with the offending value).
    pub fn try_new(inner: P, rc: f64, mode: CutoffMode) -> Result<Self, MdError> {
        crate::thermostat::positive("cutoff", rc)?;
        let (u, fr) = inner.raw(rc * rc);
        for (name, v) in [("u(cutoff)", u), ("f(cutoff)/cutoff", fr)] {
            if !v.is_finite() {
                return Err(MdError::InvalidParameter { name, value: v });
            }
        }
        Ok(Self::new(inner, rc, mode))
    }

    /// The cutoff mode.
    pub fn mode(&self) -> CutoffMode {
        self.mode
    }
}

impl<P: RawPair> PairPotential for Truncated<P> {
    fn cutoff(&self) -> f64 {
        self.rc
    }

    #[inline(always)]
    fn energy_force(&self, r2: f64) -> (f64, f64) {
        let (u, fr) = self.inner.raw(r2);
        if self.mode == CutoffMode::ShiftedForce {
            let r = r2.sqrt();
            // F_sf(r) = F(r) − F(r_c);  u_sf = u − u_c + (r − r_c)·F(r_c)
            (u - self.u_c + (r - self.rc) * self.f_c, fr - self.f_c / r)
        } else {
            (u - self.u_c, fr)
        }
    }

    #[inline(always)]
    fn energy_force4(&self, r2: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        // the mode is tested once per block, and the parameters are copied into locals, so
        // the four lanes vectorise
        let (u_c, f_c, rc) = (self.u_c, self.f_c, self.rc);
        let (mut u, mut f) = self.inner.raw4(r2);
        if self.mode == CutoffMode::ShiftedForce {
            let r = r2.map(f64::sqrt);
            for l in 0..4 {
                u[l] = u[l] - u_c + (r[l] - rc) * f_c;
                f[l] -= f_c / r[l];
            }
        } else {
            for v in u.iter_mut() {
                *v -= u_c;
            }
        }
        (u, f)
    }

    #[inline]
    fn energy_force_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        let m = r2.len().min(u.len()).min(fr.len());
        let (r2, u, fr) = (&r2[..m], &mut u[..m], &mut fr[..m]);
        self.inner.raw_batch(r2, u, fr);
        // the same operations, in the same order, as `energy_force`
        let (u_c, f_c, rc) = (self.u_c, self.f_c, self.rc);
        if self.mode == CutoffMode::ShiftedForce {
            for ((&s, u), f) in r2.iter().zip(u).zip(fr) {
                let r = s.sqrt();
                *u = *u - u_c + (r - rc) * f_c;
                *f -= f_c / r;
            }
        } else if u_c != 0.0 {
            // (`x − 0 = x` bit for bit, −0 included: plain cutoffs skip the pass)
            u.iter_mut().for_each(|u| *u -= u_c);
        }
    }

    fn prefers_batch(&self) -> bool {
        self.inner.prefers_batch()
    }

    fn lennard_jones(&self) -> Option<LjConstants> {
        if self.mode == CutoffMode::ShiftedForce {
            return None;
        }
        self.inner.lennard_jones().map(|c| LjConstants {
            u_c: self.u_c,
            rc: self.rc,
            ..c
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{LennardJones, Morse};
    use super::*;

    /// `f/r` is `−u'(r)/r` by central differences, for each kind and mode.
    #[test]
    fn force_is_minus_derivative_of_energy() {
        let modes = [
            CutoffMode::Plain,
            CutoffMode::ShiftedEnergy,
            CutoffMode::ShiftedForce,
        ];
        for mode in modes {
            let lj = LennardJones::new(1.3, 0.9).truncated(2.5, mode);
            let mo = Morse::new(0.8, 1.7, 1.1).truncated(3.0, mode);
            for r in [0.85, 1.0, 1.3, 2.2] {
                let h = 1e-6;
                for p in [&lj as &dyn PairPotential, &mo] {
                    let du = (p.energy_force((r + h) * (r + h)).0
                        - p.energy_force((r - h) * (r - h)).0)
                        / (2.0 * h);
                    let fr = p.energy_force(r * r).1;
                    assert!(
                        (fr * r + du).abs() < 1e-6 * (1.0 + du.abs()),
                        "{mode:?} r={r}"
                    );
                }
            }
            assert!(LennardJones::try_new(1.0, 1.0).is_ok());
            for (e, s) in [(0.0, 1.0), (-1.0, 1.0), (1.0, f64::NAN), (1.0, 0.0)] {
                assert!(LennardJones::try_new(e, s).is_err(), "{e} {s}");
            }
            for (d, a, r0) in [(0.0, 1.0, 1.0), (1.0, -1.0, 1.0), (1.0, 1.0, f64::NAN)] {
                assert!(Morse::try_new(d, a, r0).is_err());
            }
            assert!(Truncated::try_new(LennardJones::new(1.0, 1.0), 0.0, mode).is_err());
            assert!(Truncated::try_new(Morse::new(1.0, 1.0, 1.0), f64::INFINITY, mode).is_err());
            if mode == CutoffMode::ShiftedForce {
                let e = 2.5 * (1.0 - 1e-9);
                let (u, f) = lj.energy_force(e * e);
                assert!(u.abs() < 1e-9 && f.abs() < 1e-8);
            }
        }
    }
}
