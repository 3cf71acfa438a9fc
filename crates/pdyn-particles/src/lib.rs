//! Structure-of-arrays particle storage shared by pdyn's many-particle engines.
//!
//! The gravity engine (orbits, clusters) and the molecular-dynamics engine (pair potentials in a
//! periodic box) both move many point masses with `x' = v`, `v' = a`. What they share lives here
//! and nowhere else: the storage (one contiguous `Vec<f64>` per component, so force loops
//! vectorise and split across threads), the validated construction of a particle, the
//! kick and drift half-steps of every splitting integrator, and the invariants of a
//! system of particles — kinetic energy `T = ½ Σ mᵢ |vᵢ|²`, linear momentum `P = Σ mᵢ vᵢ`,
//! angular momentum `L = Σ mᵢ rᵢ × vᵢ`, centre of mass.
//!
//! The seeded generators of their initial conditions live here too ([`rng`]).
//!
//! This crate knows nothing of symbols, integrators' step-size control, or forces.
#![warn(missing_docs)]

mod error;
pub mod rng;
mod store;
mod vec3;

pub use error::ParticleError;
pub use store::{Particle, Particles};
pub use vec3::Vec3;
