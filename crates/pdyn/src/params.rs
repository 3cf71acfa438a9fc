//! Setting a model's parameter values (`pdyn run --set`, Python's `params=`): one
//! implementation for the command and the bindings, on top of
//! [`pdyn_mech::parameters::set_values`] (derived parameters and initial values follow).

use crate::Error;
use pdyn_mech::parameters::{set_values, SetError};

/// Sets parameter values by name, recomputes the derived parameters and initial values that
/// depend on them, and checks the model's physical requirements (masses > 0). `option` names
/// the source in messages (`--set`, `params`). An unknown name is an [`Error::Argument`]; a
/// value the model refuses an [`Error::Value`].
pub fn set_parameter_values(
    model: &mut pdyn_mech::Model,
    values: &[(String, f64)],
    option: &str,
) -> Result<(), Error> {
    set_values(model, values).map_err(|e| match e {
        SetError::Invalid(error) => Error::Value {
            origin: model.origin.clone(),
            option: option.into(),
            error,
        },
        other => Error::argument(option, format!("{option}: {other}")),
    })
}
