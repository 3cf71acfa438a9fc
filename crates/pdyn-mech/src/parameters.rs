//! Parameter values that change after loading (`--set`, a sweep, a Python call): everything
//! computed from them at load time is recomputed, so that no number shown or used is stale.
//!
//! Two things are computed from parameters at load time:
//! - derived parameters (`m = "4/3*pi*a^3*rho"`), which keep their definition
//!   ([`crate::model::Parameter::definition`]) and are recomputed in file order
//!   ([`DerivedParameters`]) — a value given for a derived parameter itself replaces its
//!   definition;
//! - the coordinates' initial values and rates (`x = { initial = "d" }`): the equations keep
//!   them as expressions ([`Model::initial_exprs`]), and the numeric copies in
//!   [`CoordinateKind::Free`] are refreshed here.
//!
//! [`set_values`] is the one entry point for `--set`, the Python `params=` and anything else
//! that changes values after loading; sweeps over a compiled system use [`DerivedParameters`].

use crate::model::CoordinateKind;
use crate::validity::{check_parameter_values, InvalidValue};
use crate::Model;
use pdyn_expr::{Id, Program};

/// Why new parameter values were refused.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SetError {
    /// A name that is not a parameter of the model.
    Unknown {
        /// The name given.
        name: String,
        /// The model's parameters, in file order.
        known: Vec<String>,
    },
    /// A value (given or derived) that breaks a physical requirement, e.g. a mass ≤ 0.
    Invalid(InvalidValue),
}

impl std::fmt::Display for SetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SetError::Unknown { name, known } => write!(
                f,
                "`{name}` is not a parameter (parameters: {})",
                known.join(", ")
            ),
            SetError::Invalid(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for SetError {}

/// Sets parameter values, then recomputes everything that depends on them (derived
/// parameters, initial conditions) and checks the physical requirements (masses > 0,
/// assumed signs). On error the model may hold some of the new values: callers work on a copy
/// or stop.
pub fn set_values(model: &mut Model, values: &[(String, f64)]) -> Result<(), SetError> {
    for (name, value) in values {
        let Some(p) = model.parameters.iter_mut().find(|p| &p.name == name) else {
            return Err(SetError::Unknown {
                name: name.clone(),
                known: model.parameters.iter().map(|p| p.name.clone()).collect(),
            });
        };
        p.value = *value;
        // An explicit value wins over the formula it was defined by.
        p.definition = None;
    }
    if values.is_empty() {
        return Ok(());
    }
    let derived = DerivedParameters::compile(model);
    let mut current: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
    derived.apply(&mut current, &[]);
    for (p, v) in model.parameters.iter_mut().zip(current) {
        p.value = v;
    }
    refresh_initial_values(model);
    check_parameter_values(model).map_err(SetError::Invalid)
}

/// The derived parameters of a model compiled for repeated evaluation (one per sweep run).
#[derive(Clone, Debug, Default)]
pub struct DerivedParameters {
    /// `(parameter index, its definition over all parameters)`, in file order — a definition
    /// only uses parameters declared before it, so one pass in this order is enough.
    steps: Vec<(usize, Program)>,
}

impl DerivedParameters {
    /// Compiles every parameter that has a definition.
    pub fn compile(model: &mut Model) -> DerivedParameters {
        let inputs: Vec<Id> = model.parameters.iter().map(|p| p.id).collect();
        let mut steps = Vec::new();
        for (i, p) in model.parameters.iter().enumerate() {
            let Some(def) = p.definition else { continue };
            // A definition was evaluated at load time from parameters only, so it compiles.
            if let Ok(prog) = Program::compile(&mut model.pool, &inputs, &[def]) {
                steps.push((i, prog));
            }
        }
        DerivedParameters { steps }
    }

    /// Whether no parameter is derived.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Recomputes the derived parameters in `values` (all parameters, in model order), except
    /// those listed in `given` (set explicitly, e.g. the swept parameter itself).
    pub fn apply(&self, values: &mut [f64], given: &[usize]) {
        let mut out = [0.0];
        for (i, prog) in &self.steps {
            if given.contains(i) || *i >= values.len() {
                continue;
            }
            let mut ws = prog.workspace();
            prog.eval(values, &mut ws, &mut out);
            values[*i] = out[0];
        }
    }
}

/// Recomputes every coordinate's numeric initial value and rate from its expression with the
/// current parameter values. An expression that cannot be evaluated keeps its old value.
pub fn refresh_initial_values(model: &mut Model) {
    model.refresh_family_initials();
    let params: Vec<Id> = model.parameters.iter().map(|p| p.id).collect();
    let values: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
    for &(ci, initial, rate) in &model.initial_exprs {
        let Ok(prog) = Program::compile(&mut model.pool, &params, &[initial, rate]) else {
            continue;
        };
        let mut ws = prog.workspace();
        let mut out = [0.0; 2];
        prog.eval(&values, &mut ws, &mut out);
        if let Some(CoordinateKind::Free { initial, rate }) =
            model.coordinates.get_mut(ci).map(|c| &mut c.kind)
        {
            *initial = out[0];
            *rate = out[1];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BALL: &str = r#"
name = "a ball of given radius and density"
[parameters]
rho = 1000
a = 0.1
m = "4/3*pi*a^3*rho"
h = "2*a"
[coordinates]
y = { initial = "h", rate = 0 }
[particles.ball]
mass = "m"
position = "[0, y, 0]"
"#;

    fn value(m: &Model, name: &str) -> f64 {
        m.parameters.iter().find(|p| p.name == name).unwrap().value
    }

    #[test]
    fn derived_parameters_follow_what_they_are_defined_by() {
        let mut m = crate::load(BALL, "<test>").unwrap();
        set_values(&mut m, &[("a".into(), 0.2)]).unwrap();
        let expect = 4.0 / 3.0 * std::f64::consts::PI * 0.008 * 1000.0;
        assert!((value(&m, "m") - expect).abs() < 1e-12 * expect);
        assert_eq!(value(&m, "h"), 0.4);
        match m.coordinates[0].kind {
            CoordinateKind::Free { initial, .. } => assert_eq!(initial, 0.4),
            _ => panic!("free coordinate expected"),
        }
    }

    #[test]
    fn a_value_given_for_a_derived_parameter_replaces_its_definition() {
        let mut m = crate::load(BALL, "<test>").unwrap();
        set_values(&mut m, &[("m".into(), 2.0), ("a".into(), 0.3)]).unwrap();
        assert_eq!(value(&m, "m"), 2.0);
        assert!((value(&m, "h") - 0.6).abs() < 1e-15);
    }

    #[test]
    fn derived_values_are_checked_and_unknown_names_refused() {
        let mut m = crate::load(BALL, "<test>").unwrap();
        // rho < 0 makes the derived mass negative: refused, naming the particle.
        let e = set_values(&mut m, &[("rho".into(), -1.0)]).unwrap_err();
        assert!(matches!(e, SetError::Invalid(_)), "{e:?}");
        let e = set_values(&mut m, &[("radius".into(), 1.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "`radius` is not a parameter (parameters: rho, a, m, h)"
        );
    }

    #[test]
    fn compiled_derived_parameters_skip_the_given_ones() {
        let mut m = crate::load(BALL, "<test>").unwrap();
        let d = DerivedParameters::compile(&mut m);
        let mut v = vec![1000.0, 0.5, 0.0, 0.0];
        d.apply(&mut v, &[3]);
        assert!((v[2] - 4.0 / 3.0 * std::f64::consts::PI * 0.125 * 1000.0).abs() < 1e-9);
        assert_eq!(v[3], 0.0);
    }

    #[test]
    fn initial_values_follow_the_parameters_they_are_written_in() {
        let src = r#"
name = "x starts at d"
[parameters]
d = 200
v = 3
[coordinates]
x = { initial = "d", rate = "2*v" }
[particles.p]
mass = 1
position = "[x, 0, 0]"
"#;
        let mut m = crate::load(src, "<test>").unwrap();
        let i = m.parameters.iter().position(|p| p.name == "d").unwrap();
        m.parameters[i].value = 90.0;
        refresh_initial_values(&mut m);
        match m.coordinates[0].kind {
            CoordinateKind::Free { initial, rate } => assert_eq!((initial, rate), (90.0, 6.0)),
            _ => panic!("free coordinate expected"),
        }
    }
}
