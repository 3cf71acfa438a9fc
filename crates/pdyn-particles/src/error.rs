//! Typed errors raised when particles are added.

use std::fmt;

/// Why a particle could not be stored.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ParticleError {
    /// A mass that is negative, zero where zero is not allowed, or not finite.
    InvalidMass {
        /// Index the particle would have had.
        index: usize,
        /// The offending mass.
        mass: f64,
    },
    /// A position or velocity component that is NaN or infinite.
    NonFinite {
        /// Index the particle would have had.
        index: usize,
        /// `"position"` or `"velocity"`.
        what: &'static str,
        /// The offending vector.
        value: [f64; 3],
    },
    /// More particles than the caller's budget allows (checked before allocating).
    TooMany {
        /// Requested count.
        requested: usize,
        /// The limit in force.
        limit: usize,
    },
}

impl fmt::Display for ParticleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParticleError::InvalidMass { index, mass } => write!(
                f,
                "particle {index}: mass must be finite and >= 0 (got {mass})"
            ),
            ParticleError::NonFinite { index, what, value } => write!(
                f,
                "particle {index}: {what} must be finite (got [{}, {}, {}])",
                value[0], value[1], value[2]
            ),
            ParticleError::TooMany { requested, limit } => {
                write!(f, "{requested} particles requested; the limit is {limit}")
            }
        }
    }
}

impl std::error::Error for ParticleError {}
