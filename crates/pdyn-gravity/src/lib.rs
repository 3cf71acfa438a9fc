//! Many-body Newtonian gravity: forces, integrators, orbital elements, events.
//!
//! The system is `N` point masses with `r̈ᵢ = −G Σ_{j≠i} mⱼ (rᵢ − rⱼ)/|rᵢ − rⱼ|³`, stored in
//! structure-of-arrays form ([`pdyn_particles::Particles`]). A [`Simulation`] holds the bodies,
//! the units (the value of `G`, [`Units`]), the force computation ([`Gravity`]: direct
//! summation, or the Barnes–Hut tree for large `N`) and the integrator ([`Integrator`]):
//!
//! - **WHFast** (Rein & Tamayo 2015): Wisdom–Holman map in Jacobi coordinates with an exact
//!   universal-variable Kepler drift and symplectic correctors, for planetary systems;
//! - **IAS15** (Rein & Spiegel 2015): adaptive 15th-order Gauss–Radau, machine-precision
//!   energy error, for close encounters and high eccentricities;
//! - **leapfrog**: second-order drift–kick–drift for large `N` with the tree.
//!
//! Orbital elements convert to and from Cartesian relative to a primary ([`orbit`]).
//! Collisions and escapes end an integration as an [`Outcome`]; invalid input is a typed
//! [`GravityError`], never a panic. Results never depend on the number of threads: every
//! parallel loop splits its work into pieces fixed by `N` alone, each summed in a fixed order
//! on one thread, and combines the pieces in a fixed order.
//!
//! This crate knows nothing of symbols or model files.
//!
//! ```
//! use pdyn_gravity::{Elements, Integrator, Particle, Primary, Simulation, Units, Vec3, WhFastParams};
//!
//! // The Sun and a Jupiter-mass planet at 5.2 AU, e = 0.05, in AU, years and solar masses.
//! let mut sim = Simulation::new(Units::AuYearSolarMass);
//! sim.add(Particle { mass: 1.0, pos: Vec3::ZERO, vel: Vec3::ZERO })?;
//! let orbit = Elements { e: 0.05, ..Elements::circular(5.2) };
//! sim.add_orbit(9.5e-4, &orbit, Primary::Interior)?;
//! sim.move_to_center_of_mass()?;
//! sim.set_integrator(Integrator::WhFast(WhFastParams { corrector: 11, ..Default::default() }))?;
//! sim.set_dt(0.5)?; // years, ≈ P/24
//! let e0 = sim.energy();
//! sim.integrate(1000.0)?;
//! let a = sim.orbit(1, Primary::Interior)?.a;
//! assert!((a - 5.2).abs() < 1e-9 && ((sim.energy() - e0) / e0).abs() < 1e-12);
//! # Ok::<(), pdyn_gravity::GravityError>(())
//! ```
#![warn(missing_docs)]

pub mod error;
pub mod forces;
pub mod integrators;
pub mod kepler;
mod kepler_lanes;
pub mod orbit;
pub mod plummer;
/// The seeded generators (shared with the MD engine).
pub use pdyn_particles::rng;
mod simulation;
pub mod systems;
pub mod units;

pub use error::{GravityError, Warning};
pub use forces::{Gravity, TreeParams};
pub use integrators::{Ias15Params, Integrator, WhFastParams};
pub use orbit::{Anomaly, Elements, Orbit};
pub use pdyn_particles::{Particle, Particles, Vec3};
pub use simulation::{
    EventParams, Outcome, Primary, Simulation, Snapshot, MAX_CRAWL_STEPS, MIN_RELATIVE_STEP,
};
pub use units::Units;
