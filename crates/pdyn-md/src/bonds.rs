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
    /// LAMMPS's `bond_style fene` (`bond_coeff K R₀ ε σ`): FENE plus the purely repulsive
    /// Weeks–Chandler–Andersen term `4ε[(σ/r)¹² − (σ/r)⁶] + ε` for `r < 2^{1/6} σ`, meant for
    /// bonded pairs excluded from the pair potential (`special_bonds lj 0 1 1`).
    FeneWca {
        /// Stiffness K.
        k: f64,
        /// Maximum extension R₀.
        r_max: f64,
        /// WCA energy ε.
        epsilon: f64,
        /// WCA length σ.
        sigma: f64,
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
        self.evaluate::<true>(r2)
    }

    /// `f/r` at squared length `r2` (the same bits as [`BondKind::energy_force`]'s), or `None`
    /// if a FENE bond is at or beyond `R₀`; skips the energy, whose logarithm is most of a
    /// FENE bond's cost.
    #[inline]
    pub fn force(&self, r2: f64) -> Option<f64> {
        self.evaluate::<false>(r2).map(|(_, fr)| fr)
    }

    /// `(u, f/r)`, with `u` = 0 unless `ENERGY`.
    #[inline(always)]
    fn evaluate<const ENERGY: bool>(&self, r2: f64) -> Option<(f64, f64)> {
        match *self {
            BondKind::Harmonic { k, r0 } => {
                let r = r2.sqrt();
                let d = r - r0;
                Some((if ENERGY { 0.5 * k * d * d } else { 0.0 }, -k * d / r))
            }
            BondKind::Fene { k, r_max } => fene::<ENERGY>(k, r_max, r2),
            BondKind::FeneWca {
                k,
                r_max,
                epsilon,
                sigma,
            } => {
                let (u, fr) = fene::<ENERGY>(k, r_max, r2)?;
                // (r/σ)² at the WCA cutoff r = 2^{1/6} σ is 2^{1/3} (LAMMPS's MY_CUBEROOT2)
                const CUBE_ROOT_2: f64 = 1.259_921_049_894_873_2;
                if r2 >= CUBE_ROOT_2 * sigma * sigma {
                    return Some((u, fr));
                }
                let s2 = sigma * sigma / r2;
                let s6 = s2 * s2 * s2;
                let wca_fr = 24.0 * epsilon * (2.0 * s6 * s6 - s6) / r2;
                let u = if ENERGY {
                    u + 4.0 * epsilon * (s6 * s6 - s6) + epsilon
                } else {
                    0.0
                };
                Some((u, fr + wca_fr))
            }
        }
    }
}

/// The FENE term `(u, f/r)` (`u` = 0 unless `ENERGY`), `None` at or beyond `R₀`. A function of
/// its own rather than a call of [`BondKind::evaluate`] from the `FeneWca` arm, which being
/// recursive was not inlined.
#[inline(always)]
fn fene<const ENERGY: bool>(k: f64, r_max: f64, r2: f64) -> Option<(f64, f64)> {
    let x = r2 / (r_max * r_max);
    if x >= 1.0 {
        return None;
    }
    let u = if ENERGY {
        -0.5 * k * r_max * r_max * libm::log(1.0 - x)
    } else {
        0.0
    };
    Some((u, -k / (1.0 - x)))
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
            BondKind::FeneWca {
                k: 30.0,
                r_max: 1.5,
                epsilon: 1.0,
                sigma: 1.0,
            },
        ] {
            for r in [0.8f64, 1.0, 1.3] {
                let h = 1e-6;
                let u = |r: f64| kind.energy_force(r * r).unwrap().0;
                let du = (u(r + h) - u(r - h)) / (2.0 * h);
                let fr = kind.energy_force(r * r).unwrap().1;
                // the force-only path gives the same bits
                assert_eq!(kind.force(r * r).unwrap().to_bits(), fr.to_bits());
                assert!((fr * r + du).abs() < 1e-6 * (1.0 + du.abs()));
            }
        }
        assert!(BondKind::Fene {
            k: 30.0,
            r_max: 1.5
        }
        .energy_force(2.25)
        .is_none());
        assert!(BondKind::Fene {
            k: 30.0,
            r_max: 1.5
        }
        .force(2.25)
        .is_none());
    }
}

#[cfg(test)]
mod fene_wca_tests {
    use super::*;

    #[test]
    fn fene_wca_is_fene_plus_shifted_lj_inside_its_cutoff_only() {
        let (k, r_max) = (30.0, 1.5);
        let b = BondKind::FeneWca {
            k,
            r_max,
            epsilon: 1.0,
            sigma: 1.0,
        };
        let fene = |r: f64| -0.5 * k * r_max * r_max * libm::log(1.0 - (r / r_max).powi(2));
        let r: f64 = 0.97;
        let lj = 4.0 * (r.powi(-12) - r.powi(-6)) + 1.0;
        assert!((b.energy_force(r * r).unwrap().0 - (fene(r) + lj)).abs() < 1e-12);
        let r = 1.2; // beyond 2^(1/6)
        assert!((b.energy_force(r * r).unwrap().0 - fene(r)).abs() < 1e-12);
    }
}
