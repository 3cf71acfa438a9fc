//! Typed errors. A failure during a run carries the step, the offending particles and the
//! records computed so far ([`RunFailure`]).

use crate::RunReport;
use pdyn_particles::ParticleError;
use std::fmt;

/// Why a simulation could not be set up or continued.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MdError {
    /// A box edge that is not finite and positive.
    InvalidBox {
        /// The edges given.
        lengths: [f64; 3],
    },
    /// A box edge shorter than twice the interaction range (cutoff plus skin): the minimum
    /// image would miss interactions.
    BoxTooSmall {
        /// Axis (0, 1, 2).
        axis: usize,
        /// Edge length.
        length: f64,
        /// Required minimum `2 (r_c + skin)`.
        required: f64,
    },
    /// A parameter outside its domain (`name` says which).
    InvalidParameter {
        /// Field name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// Two particles closer than the overlap distance at the start of a run.
    Overlap {
        /// First particle.
        i: usize,
        /// Second particle.
        j: usize,
        /// Their (minimum-image) distance.
        distance: f64,
        /// The threshold (see `SimParams::overlap_distance`); `minimize_fire` can resolve it.
        threshold: f64,
    },
    /// The time step is too large: the energy or a displacement exploded.
    Unstable {
        /// Step at which it was detected.
        step: u64,
        /// Particle that moved furthest (or whose state became non-finite).
        atom: usize,
        /// Its closest neighbour at detection, if any.
        neighbor: Option<usize>,
        /// Displacement of `atom` in the failing step (length units).
        displacement: f64,
        /// `|E − E₀|/N` at detection (energy units per particle).
        energy_change_per_atom: f64,
    },
    /// A FENE bond stretched to or beyond its maximum extension `R₀`.
    BondBroken {
        /// Step.
        step: u64,
        /// Bond index.
        bond: usize,
        /// Particles of the bond.
        atoms: [usize; 2],
        /// Length reached.
        length: f64,
        /// Maximum extension.
        max: f64,
    },
    /// A particle index (in a bond, a type table) out of range.
    IndexOutOfRange {
        /// What held the index.
        what: &'static str,
        /// The index.
        index: usize,
        /// The number of items.
        len: usize,
    },
    /// A thermostat that needs a temperature was given none (or a non-positive one).
    MissingTemperature {
        /// Thermostat name.
        thermostat: &'static str,
    },
    /// A particle could not be stored.
    Particle(ParticleError),
    /// A malformed input file.
    Parse {
        /// Format (`"xyz"`, `"lammps-data"`).
        format: &'static str,
        /// 1-based line number.
        line: usize,
        /// What was expected there.
        expected: &'static str,
    },
    /// Invalid content of an input file, with what would be valid there.
    InvalidInput {
        /// Format (`"lammps-data"`).
        format: &'static str,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what would be valid.
        message: String,
    },
    /// An I/O failure (message of the underlying error).
    Io {
        /// Kind of the underlying error.
        kind: std::io::ErrorKind,
    },
    /// A snapshot (a checkpoint's state) that does not fit the simulation it is restored
    /// into: another number of particles, another thermostat, another chain length.
    SnapshotMismatch {
        /// What differs.
        what: &'static str,
        /// The simulation's count (or kind index).
        expected: usize,
        /// The snapshot's.
        found: usize,
    },
}

impl From<ParticleError> for MdError {
    fn from(e: ParticleError) -> Self {
        MdError::Particle(e)
    }
}

impl From<std::io::Error> for MdError {
    fn from(e: std::io::Error) -> Self {
        MdError::Io { kind: e.kind() }
    }
}

impl fmt::Display for MdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use MdError::*;
        match self {
            InvalidBox { lengths } => {
                write!(f, "box edges must be finite and > 0 (got {lengths:?})")
            }
            BoxTooSmall {
                axis,
                length,
                required,
            } => write!(
                f,
                "box edge {axis} is {length}, shorter than 2·(cutoff + skin) = {required}"
            ),
            InvalidParameter { name, value } => write!(f, "invalid {name} = {value}"),
            Overlap {
                i,
                j,
                distance,
                threshold,
            } => write!(
                f,
                "particles {i} and {j} overlap at the start (distance {distance} < {threshold}); \
                 run an energy minimisation (minimize_fire) first"
            ),
            Unstable {
                step,
                atom,
                neighbor,
                displacement,
                energy_change_per_atom,
            } => {
                write!(f, "unstable at step {step}: particle {atom}")?;
                if let Some(j) = neighbor {
                    write!(f, " (nearest particle {j})")?;
                }
                write!(
                    f,
                    " moved {displacement:.4} in one step, |ΔE|/N = {energy_change_per_atom:.4e}; \
                     reduce the time step"
                )
            }
            BondBroken {
                step,
                bond,
                atoms,
                length,
                max,
            } => write!(
                f,
                "step {step}: FENE bond {bond} {atoms:?} stretched to {length} ≥ R0 = {max}"
            ),
            IndexOutOfRange { what, index, len } => {
                write!(f, "{what} index {index} out of range (len {len})")
            }
            MissingTemperature { thermostat } => {
                write!(
                    f,
                    "thermostat {thermostat} needs a positive target temperature"
                )
            }
            Particle(e) => write!(f, "{e}"),
            Parse {
                format,
                line,
                expected,
            } => {
                write!(f, "{format} line {line}: expected {expected}")
            }
            InvalidInput {
                format,
                line,
                message,
            } => write!(f, "{format} line {line}: {message}"),
            Io { kind } => write!(f, "I/O error: {kind}"),
            SnapshotMismatch {
                what,
                expected,
                found,
            } => write!(
                f,
                "the saved state does not fit this simulation: {what} {found}, this simulation has {expected}"
            ),
        }
    }
}

impl std::error::Error for MdError {}

/// A run that stopped early: the error and everything recorded before it.
#[derive(Debug, Clone, PartialEq)]
pub struct RunFailure {
    /// What went wrong.
    pub error: MdError,
    /// Records and counters up to the failure.
    pub partial: RunReport,
}

impl fmt::Display for RunFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({} thermo records kept)",
            self.error,
            self.partial.records.len()
        )
    }
}

impl std::error::Error for RunFailure {}
