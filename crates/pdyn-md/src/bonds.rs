//! Bonded interactions between particle pairs (minimum image).
//!
//! * Harmonic: `u(r) = ½ k (r − r₀)²`.
//! * FENE (Kremer & Grest, J. Chem. Phys. 92, 5057 (1990)): `u(r) = −½ K R₀² ln(1 − (r/R₀)²)`,
//!   `r < R₀`. Kremer–Grest bead-spring chains use `K = 30 ε/σ²`, `R₀ = 1.5 σ` together with a
//!   WCA pair potential (LJ cut at `2^{1/6} σ`, shifted) acting on *all* pairs including bonded
//!   ones; this crate applies pair forces to every pair, so FENE here is the pure logarithmic
//!   term (LAMMPS's `bond_style fene` includes the WCA term and excludes bonded pairs instead —
//!   the same total force).

/// Kind and parameters of a bond.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum BondKind {
    /// `½ k (r − r₀)²`.
    Harmonic {
        /// Spring constant k.
        k: f64,
        /// Rest length r₀.
        r0: f64,
    },
    /// `−½ K R₀² ln(1 − (r/R₀)²)`.
    Fene {
        /// Stiffness K.
        k: f64,
        /// Maximum extension R₀.
        r_max: f64,
    },
}

/// A bond between particles `i` and `j`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bond {
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Kind and parameters.
    pub kind: BondKind,
}

impl BondKind {
    /// `(u, f/r)` at squared length `r2`, or `None` if a FENE bond is at or beyond `R₀`.
    #[inline]
    pub fn energy_force(&self, r2: f64) -> Option<(f64, f64)> {
        match *self {
            BondKind::Harmonic { k, r0 } => {
                let r = r2.sqrt();
                let d = r - r0;
                Some((0.5 * k * d * d, -k * d / r))
            }
            BondKind::Fene { k, r_max } => {
                let x = r2 / (r_max * r_max);
                if x >= 1.0 {
                    return None;
                }
                Some((-0.5 * k * r_max * r_max * (1.0 - x).ln(), -k / (1.0 - x)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bond_forces_are_minus_derivatives() {
        for kind in [
            BondKind::Harmonic { k: 3.0, r0: 1.1 },
            BondKind::Fene {
                k: 30.0,
                r_max: 1.5,
            },
        ] {
            for r in [0.8f64, 1.0, 1.3] {
                let h = 1e-6;
                let u = |r: f64| kind.energy_force(r * r).unwrap().0;
                let du = (u(r + h) - u(r - h)) / (2.0 * h);
                let fr = kind.energy_force(r * r).unwrap().1;
                assert!((fr * r + du).abs() < 1e-6 * (1.0 + du.abs()));
            }
        }
        assert!(BondKind::Fene {
            k: 30.0,
            r_max: 1.5
        }
        .energy_force(2.25)
        .is_none());
    }
}
