//! Physical validity of parameter values, checked wherever values arrive: the model file,
//! `--set`, each run of a sweep, a Python call.
//!
//! Derivations assume what the physics requires — every particle's mass is positive — and
//! results computed from values that break it are silently wrong (a negative mass falls up).
//! [`ValueChecks`] compiles each requirement over the parameters once, so that checking a new
//! set of values costs one program evaluation.

use crate::Model;
use pdyn_expr::compile::CompileError;
use pdyn_expr::{Id, Program};
use std::fmt;

/// A value that breaks a physical requirement.
#[derive(Clone, Debug, PartialEq)]
pub struct InvalidValue {
    /// What it is the value of: ``mass of particle `bob` (m)``.
    pub what: String,
    /// The value.
    pub value: f64,
    /// What it must be.
    pub requirement: &'static str,
}

impl fmt::Display for InvalidValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the {} must be {}, but the parameter values give {}",
            self.what, self.requirement, self.value
        )
    }
}

impl std::error::Error for InvalidValue {}

/// The physical requirements of a model, compiled over its parameters (in model order).
#[derive(Clone, Debug)]
pub struct ValueChecks {
    program: Program,
    what: Vec<String>,
}

impl ValueChecks {
    /// Compiles the requirements: every particle's mass is finite and > 0.
    pub fn compile(model: &mut Model) -> Result<ValueChecks, CompileError> {
        let params: Vec<Id> = model.parameters.iter().map(|p| p.id).collect();
        let masses: Vec<Id> = model.particles.iter().map(|p| p.mass).collect();
        let what = model
            .particles
            .iter()
            .map(|p| {
                format!(
                    "mass of particle `{}` ({})",
                    p.name,
                    model.pool.to_text(p.mass)
                )
            })
            .collect();
        let program = Program::compile(&mut model.pool, &params, &masses)?;
        Ok(ValueChecks { program, what })
    }

    /// Checks parameter values (in model order).
    pub fn check(&self, params: &[f64]) -> Result<(), InvalidValue> {
        let mut ws = self.program.workspace();
        let mut out = vec![0.0; self.what.len()];
        self.program.eval(params, &mut ws, &mut out);
        match out.iter().position(|m| !(m.is_finite() && *m > 0.0)) {
            None => Ok(()),
            Some(i) => Err(InvalidValue {
                what: self.what[i].clone(),
                value: out[i],
                requirement: "finite and > 0",
            }),
        }
    }
}

/// Checks the model's current parameter values (e.g. after `--set`).
pub fn check_parameter_values(model: &mut Model) -> Result<(), InvalidValue> {
    let values: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
    match ValueChecks::compile(model) {
        Ok(checks) => checks.check(&values),
        // A mass that depends on more than parameters (a coordinate) is checked when run.
        Err(_) => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = r#"
name = "bob"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
rho = 1000
a = 0.1
m = "4/3*pi*a^3*rho"
[coordinates]
y = { initial = 0, rate = 0 }
[particles.bob]
mass = "m"
position = "[0, y, 0]"
"#;

    #[test]
    fn negative_or_zero_masses_are_refused_with_the_particle_named() {
        let mut m = crate::load(SRC, "<test>").unwrap();
        assert_eq!(check_parameter_values(&mut m), Ok(()));
        let checks = ValueChecks::compile(&mut m).unwrap();
        let mut values: Vec<f64> = m.parameters.iter().map(|p| p.value).collect();
        let im = m.parameters.iter().position(|p| p.name == "m").unwrap();
        values[im] = -2.0;
        let e = checks.check(&values).unwrap_err();
        assert_eq!(e.value, -2.0);
        assert!(
            e.to_string()
                .contains("mass of particle `bob` (m) must be finite and > 0"),
            "{e}"
        );
        values[im] = 0.0;
        assert!(checks.check(&values).is_err());
        values[im] = f64::NAN;
        assert!(checks.check(&values).is_err());
    }
}
