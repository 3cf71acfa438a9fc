//! # pdyn-mech — particles, kinematics, equations of motion
//!
//! The textbook's procedure (Bower, *Dynamics*, ch. 3), automated on top of `pdyn-expr`:
//! - [`kinematics`]: position → velocity, acceleration, normal–tangential and polar components,
//!   radius of curvature;
//! - [`model`]: model files (TOML) → particles, coordinates, loads, reactions, constraints;
//! - [`derive`]: F = ma (and ΣM = 0 for massless frames), constraints at acceleration level,
//!   eliminated to `q'' = f(q, q', t)` with the reactions as functions of state;
//! - [`matrix_form`]: `M(q) q'' = f` with collected, factored entries, for reading;
//! - [`dsolve`]: closed-form solutions of linear constant-coefficient equations of motion, and
//!   the 1-D integration rules of section 3.1.3;
//! - [`linearization`], [`equilibrium`], [`modes`]: `M`, `K`, `C` at a state at rest, static
//!   equilibrium by Newton's method, natural frequencies and mode shapes.
#![warn(missing_docs)]

pub mod algebra;
pub mod classical_damping;
pub mod conservation;
mod constraint_rank;
pub mod damped;
mod damped_newton;
pub mod derive;
pub mod dimensions;
pub mod dsolve;
pub mod equilibrium;
pub mod hybrid;
pub mod kinematics;
pub mod lanczos;
pub mod linearization;
pub mod matrix_form;
pub mod model;
pub mod modes;
pub mod numeric_roots;
pub mod options;
pub mod parameters;
pub mod prescribed;
mod projection;
pub mod shifted_factor;
pub mod sparse;
pub mod sparse_statics;
pub mod statics;
pub mod tree;
pub mod units;
pub mod validity;

pub use derive::{derive, Derivation, DeriveError, DeriveOptions};
pub use model::{load, load_file, Model, ModelError};
