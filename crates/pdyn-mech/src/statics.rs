//! The one error type of the statics commands (`pdyn equilibrium`, `pdyn modes`): a model
//! that cannot be linearized, an equilibrium that cannot be found, modes that cannot be
//! computed.

use crate::derive::DeriveError;
use crate::equilibrium::EquilibriumError;
use crate::linearization::LinearizationError;
use crate::modes::ModesError;

/// Why equilibrium or modes failed.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum StaticsError {
    /// The equations could not be derived.
    Derive(DeriveError),
    /// The equations could not be linearized.
    Linearization(LinearizationError),
    /// No equilibrium was found.
    Equilibrium(EquilibriumError),
    /// The eigenproblem could not be solved.
    Modes(ModesError),
    /// The damped modes could not be computed.
    Damped(crate::damped::DampedError),
}

impl std::fmt::Display for StaticsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StaticsError::Derive(e) => write!(f, "{e}"),
            StaticsError::Linearization(e) => write!(f, "{e}"),
            StaticsError::Equilibrium(e) => write!(f, "{e}"),
            StaticsError::Modes(e) => write!(f, "{e}"),
            StaticsError::Damped(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for StaticsError {}

impl From<DeriveError> for StaticsError {
    fn from(e: DeriveError) -> Self {
        StaticsError::Derive(e)
    }
}
impl From<LinearizationError> for StaticsError {
    fn from(e: LinearizationError) -> Self {
        StaticsError::Linearization(e)
    }
}
impl From<EquilibriumError> for StaticsError {
    fn from(e: EquilibriumError) -> Self {
        StaticsError::Equilibrium(e)
    }
}
impl From<crate::damped::DampedError> for StaticsError {
    fn from(e: crate::damped::DampedError) -> Self {
        StaticsError::Damped(e)
    }
}
impl From<ModesError> for StaticsError {
    fn from(e: ModesError) -> Self {
        StaticsError::Modes(e)
    }
}

/// Derives `model`'s equations as a run does (nothing simplified for printing) and compiles
/// their linearization.
pub fn linearize(
    model: &mut crate::Model,
) -> Result<(crate::Derivation, crate::linearization::Linearizer), StaticsError> {
    let opts = crate::DeriveOptions {
        simplify_printed: false,
        solve_budget: crate::derive::RUN_SOLVE_BUDGET,
        ..crate::DeriveOptions::default()
    };
    let d = crate::derive(model, &opts)?;
    let lin = crate::linearization::Linearizer::new(model, &d)?;
    Ok((d, lin))
}
