//! # pdyn-mech — particles, kinematics, equations of motion
//!
//! The textbook's procedure (Bower, *Dynamics*, ch. 3), automated on top of `pdyn-expr`:
//! - [`kinematics`]: position → velocity, acceleration, normal–tangential and polar components,
//!   radius of curvature;
//! - [`dsolve`]: closed-form solutions of linear constant-coefficient equations of motion, and
//!   the 1-D integration rules of section 3.1.3.
#![warn(missing_docs)]

pub mod dsolve;
pub mod kinematics;
