//! Cubic lattices filling a periodic box: simple cubic (1 site per cell), body-centred (2),
//! face-centred (4). At reduced number density `ρ` the cell edge is `a = (n_basis/ρ)^{1/3}`
//! (as LAMMPS `lattice fcc 0.8442` in LJ units).

use crate::{MdError, SimBox};
use pdyn_particles::{Particle, Particles, Vec3};

/// Lattice kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Lattice {
    /// Simple cubic.
    Sc,
    /// Body-centred cubic.
    Bcc,
    /// Face-centred cubic.
    Fcc,
}

impl Lattice {
    /// Basis in units of the cell edge.
    pub fn basis(self) -> &'static [[f64; 3]] {
        match self {
            Lattice::Sc => &[[0.0; 3]],
            Lattice::Bcc => &[[0.0; 3], [0.5, 0.5, 0.5]],
            Lattice::Fcc => &[[0.0; 3], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]],
        }
    }
}

/// `cells[0]×cells[1]×cells[2]` unit cells of `kind` at number density `rho`, all of mass
/// `mass` and at rest, at most `limit` particles (checked before allocating). Returns the
/// particles and the periodic box they fill.
pub fn lattice(
    kind: Lattice,
    rho: f64,
    cells: [usize; 3],
    mass: f64,
    limit: usize,
) -> Result<(Particles, SimBox), MdError> {
    if !(rho.is_finite() && rho > 0.0) {
        return Err(MdError::InvalidParameter {
            name: "rho",
            value: rho,
        });
    }
    let basis = kind.basis();
    let n = cells
        .iter()
        .try_fold(basis.len(), |a, &c| a.checked_mul(c))
        .unwrap_or(usize::MAX);
    let a = libm::cbrt(basis.len() as f64 / rho);
    let bx = SimBox::new(
        cells[0] as f64 * a,
        cells[1] as f64 * a,
        cells[2] as f64 * a,
    )?;
    let mut p = Particles::with_capacity(n, limit)?;
    for i in 0..cells[0] {
        for j in 0..cells[1] {
            for k in 0..cells[2] {
                for b in basis {
                    let pos = Vec3::new(
                        (i as f64 + b[0]) * a,
                        (j as f64 + b[1]) * a,
                        (k as f64 + b[2]) * a,
                    );
                    p.push(Particle {
                        mass,
                        pos,
                        vel: Vec3::ZERO,
                    })?;
                }
            }
        }
    }
    Ok((p, bx))
}
