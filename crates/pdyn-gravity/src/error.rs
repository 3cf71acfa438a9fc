//! Typed errors and warnings of the gravity engine.
//!
//! Errors stop the operation that raised them and leave the simulation in its last valid
//! state; warnings are recorded in [`crate::Simulation::warnings`] and the run continues.

use std::fmt;

use pdyn_particles::ParticleError;

/// Why a gravity operation failed.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum GravityError {
    /// A particle was refused by the storage (negative or non-finite mass, non-finite state).
    Particle(ParticleError),
    /// A body was placed exactly on another one (their mutual force would be infinite).
    Coincident {
        /// Index the new body would have had.
        index: usize,
        /// The body already at that position.
        other: usize,
    },
    /// A radius that is negative or not finite.
    InvalidRadius {
        /// Index of the body.
        index: usize,
        /// The offending radius.
        radius: f64,
    },
    /// Orbital elements that do not describe a Kepler orbit.
    InvalidElements {
        /// Which condition failed, e.g. `"a <= 0 for e < 1"`.
        reason: &'static str,
        /// Semi-major axis given.
        a: f64,
        /// Eccentricity given.
        e: f64,
    },
    /// A body index that does not exist.
    NoSuchBody {
        /// The index asked for.
        index: usize,
        /// Number of bodies.
        len: usize,
    },
    /// A primary with zero total mass (no Kepler problem to solve), or a body equal to its
    /// primary.
    InvalidPrimary {
        /// The body.
        index: usize,
    },
    /// A time step that is zero, negative or not finite.
    InvalidTimeStep {
        /// The offending step.
        dt: f64,
    },
    /// An end time that is before the current time or not finite.
    InvalidEndTime {
        /// Current time.
        t: f64,
        /// Requested end time.
        t_end: f64,
    },
    /// A parameter outside its documented range.
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// WHFast needs a massive central body (particle 0) to define Jacobi coordinates.
    MasslessPrimary,
    /// A [`crate::Snapshot`] that does not fit the simulation it is restored into.
    BadSnapshot {
        /// What does not fit.
        what: &'static str,
    },
    /// The universal-variable Kepler solver did not converge.
    KeplerNotConverged {
        /// Simulation time at the start of the failed drift.
        t: f64,
        /// Jacobi index of the body.
        body: usize,
    },
    /// A close encounter that WHFast's splitting cannot resolve: the perturbation on a body
    /// exceeded the given fraction of its Kepler acceleration. Use IAS15 instead.
    CloseEncounter {
        /// Simulation time.
        t: f64,
        /// Jacobi index of the body most perturbed.
        body: usize,
        /// |a_interaction| / |a_Kepler| for that body.
        ratio: f64,
    },
    /// IAS15's step size fell below its minimum (a singularity or collision).
    StepSizeUnderflow {
        /// Simulation time.
        t: f64,
        /// The step it wanted.
        dt: f64,
    },
    /// Positions or velocities became NaN or infinite.
    NonFinite {
        /// Simulation time.
        t: f64,
        /// The first offending particle.
        index: usize,
    },
}

impl From<ParticleError> for GravityError {
    fn from(e: ParticleError) -> Self {
        GravityError::Particle(e)
    }
}

impl fmt::Display for GravityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use GravityError::*;
        match self {
            Particle(e) => write!(f, "{e}"),
            Coincident { index, other } => {
                write!(f, "body {index} placed exactly on body {other}")
            }
            InvalidRadius { index, radius } => {
                write!(
                    f,
                    "body {index}: radius must be finite and >= 0 (got {radius})"
                )
            }
            InvalidElements { reason, a, e } => {
                write!(f, "elements a = {a}, e = {e} describe no orbit: {reason}")
            }
            NoSuchBody { index, len } => write!(f, "no body {index} (there are {len})"),
            InvalidPrimary { index } => {
                write!(
                    f,
                    "body {index}: primary has zero mass or is the body itself"
                )
            }
            InvalidTimeStep { dt } => write!(f, "time step must be finite and > 0 (got {dt})"),
            InvalidEndTime { t, t_end } => {
                write!(f, "end time {t_end} is not after the current time {t}")
            }
            InvalidParameter { name, value } => {
                write!(f, "parameter {name} = {value} out of range")
            }
            MasslessPrimary => write!(f, "WHFast needs a massive body 0 (the primary)"),
            BadSnapshot { what } => {
                write!(f, "the saved state does not fit this simulation: {what}")
            }
            KeplerNotConverged { t, body } => {
                write!(
                    f,
                    "t = {t}: Kepler solver did not converge for Jacobi body {body}"
                )
            }
            CloseEncounter { t, body, ratio } => write!(
                f,
                "t = {t}: close encounter of body {body} (perturbation/Kepler = {ratio:.3}); \
                 WHFast cannot resolve it, use IAS15"
            ),
            StepSizeUnderflow { t, dt } => write!(
                f,
                "t = {}: the IAS15 step size fell to {dt:e}, too small to advance the time \
                 (the integration would not end): usually a body far outside the others' scale \
                 (a speed or distance many orders of magnitude larger: check the initial \
                 state) or an unresolved close encounter (use collisions, softening or \
                 escape_distance)",
                if *t == 0.0 || (1e-4..1e7).contains(&t.abs()) {
                    t.to_string()
                } else {
                    format!("{t:e}")
                }
            ),
            NonFinite { t, index } => write!(f, "t = {t}: body {index} has a non-finite state"),
        }
    }
}

impl std::error::Error for GravityError {}

/// A condition worth reporting that does not stop the integration.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// The WHFast step is longer than the given fraction of the shortest orbital period
    /// (accuracy degrades quickly; the usual choice is below 1/20).
    LongWhFastStep {
        /// The step.
        dt: f64,
        /// The shortest Jacobi orbital period found.
        shortest_period: f64,
        /// Jacobi index of that body.
        body: usize,
    },
    /// IAS15's predictor-corrector loop hit its iteration limit (step probably too long).
    PredictorCorrectorNotConverged {
        /// Simulation time.
        t: f64,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::LongWhFastStep {
                dt,
                shortest_period,
                body,
            } => write!(
                f,
                "WHFast step {dt} is long compared with the period {shortest_period} of body {body}"
            ),
            Warning::PredictorCorrectorNotConverged { t } => {
                write!(f, "t = {t}: IAS15 predictor-corrector did not converge")
            }
        }
    }
}
