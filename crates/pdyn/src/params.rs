//! Setting a model's parameter values (`pdyn run --set`, Python's `params=`): one
//! implementation for the command and the bindings.

use crate::Error;

/// Sets parameter values by name, refreshes the initial values that depend on them, and checks
/// the model's physical requirements (masses > 0). `option` names the source in messages
/// (`--set`, `params`). An unknown name is an [`Error::Argument`]; a value the model refuses an
/// [`Error::Value`].
pub fn set_parameter_values(
    model: &mut pdyn_mech::Model,
    values: &[(String, f64)],
    option: &str,
) -> Result<(), Error> {
    for (k, v) in values {
        match model.parameters.iter_mut().find(|p| &p.name == k) {
            Some(p) => p.value = *v,
            None => {
                let names: Vec<&str> = model.parameters.iter().map(|p| p.name.as_str()).collect();
                return Err(Error::argument(
                    option,
                    format!(
                        "{option}: `{k}` is not a parameter (parameters: {})",
                        names.join(", ")
                    ),
                ));
            }
        }
    }
    if !values.is_empty() {
        pdyn_mech::parameters::refresh_initial_values(model);
        pdyn_mech::validity::check_parameter_values(model).map_err(|error| Error::Value {
            origin: model.origin.clone(),
            option: option.into(),
            error,
        })?;
    }
    Ok(())
}
