//! Molecular dynamics of particle ensembles with short-range interactions.
//!
//! Particles live in an orthorhombic periodic box (`SimBox`, minimum image); pair forces with a
//! cutoff `r_c` are found through a Verlet neighbour list with a skin `δ` (built from a cell
//! list, rebuilt automatically once some particle has moved more than `δ/2` since the last
//! build, Verlet 1967; Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed., §5.3).
//! Equations of motion `ẋ = v`, `m v̇ = F = −∇U` are integrated by velocity Verlet (Swope et
//! al., J. Chem. Phys. 76, 637 (1982)), optionally coupled to a thermostat (Langevin BAOAB,
//! Nosé–Hoover chain, Berendsen).
//!
//! Determinism: forces use a *full* neighbour list, so every particle's force is the sum over
//! its own neighbours in list order, computed by one thread; energies and virials are summed
//! per particle, then sequentially in index order. Results are bitwise identical for any
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
mod minimize;
mod neighbor;
pub mod potential;
mod rng;
mod sim_box;
mod simulation;
mod thermo;
pub mod thermostat;
mod velocities;

pub use bonds::{Bond, BondKind};
pub use error::{MdError, RunFailure};
pub use forces::ForceField;
pub use lattice::{lattice, Lattice};
pub use minimize::{minimize_fire, FireParams, MinimizeReport};
pub use neighbor::NeighborList;
pub use pdyn_particles::{Particle, Particles, Vec3};
pub use rng::Rng;
pub use sim_box::SimBox;
pub use simulation::{Observer, RunReport, SimParams, Simulation, System};
pub use thermo::{ThermoRecord, THERMO_CSV_HEADER};
pub use velocities::maxwell_boltzmann;
