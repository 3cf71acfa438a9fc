//! Molecular dynamics of particle ensembles with short-range interactions.
//!
//! Particles live in an orthorhombic periodic box (`SimBox`, minimum image); pair forces with a
//! cutoff `r_c` are found through a half Verlet neighbour list with a skin `δ` (built from a
//! bin list over particles sorted by bin, rebuilt automatically once the two largest
//! displacements since the last build exceed `δ`, or on a fixed schedule as LAMMPS's
//! `neigh_modify every N check no`; Verlet 1967; Allen & Tildesley, *Computer Simulation of
//! Liquids*, 2nd ed., §5.3).
//! Equations of motion `ẋ = v`, `m v̇ = F = −∇U` are integrated by velocity Verlet (Swope et
//! al., J. Chem. Phys. 76, 637 (1982)), optionally coupled to a thermostat (Langevin BAOAB,
//! Nosé–Hoover chain, Berendsen).
//! Pair interactions between bonded neighbours can be scaled or excluded (`special`, LAMMPS's
//! `special_bonds lj`).
//!
//! Determinism: each pair is computed once (Newton's third law) by one of a fixed number of
//! segments of particles, into the segment's own force buffer; the buffers, energies and
//! virials are summed in segment order (`forces.rs`). Results are bitwise identical for any
//! number of rayon threads.
//!
//! Particle storage (`Particles`, kick, drift, kinetic energy, momentum) is shared with the
//! gravity engine through `pdyn-particles`.
#![warn(missing_docs)]

pub mod analysis;
mod bonds;
mod error;
mod forces;
pub mod io;
mod lattice;
#[cfg(target_arch = "x86_64")]
mod lj_avx2;
mod minimize;
mod neighbor;
pub mod potential;
mod sim_box;
mod simulation;
pub mod special;
mod thermo;
pub mod thermostat;
mod velocities;

pub use bonds::{Bond, BondKind};
pub use error::{MdError, RunFailure};
pub use forces::ForceField;
pub use lattice::{lattice, Lattice};
pub use minimize::{minimize_fire, FireParams, MinimizeReport};
pub use neighbor::NeighborList;
pub use pdyn_particles::rng::Rng;
pub use pdyn_particles::{Particle, Particles, Vec3};
pub use sim_box::SimBox;
pub use simulation::{
    Observer, RunReport, SimParams, Simulation, Snapshot, System, ThermostatState,
    ENERGY_CHECK_EVERY,
};
pub use thermo::{KineticEstimator, ThermoRecord, THERMO_CSV_HEADER};
pub use velocities::maxwell_boltzmann;
