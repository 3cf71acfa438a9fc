//! Parameter values that change after loading (`--set`, a sweep, a Python call): everything
//! computed from them at load time is recomputed, so that no number shown or used is stale.
//!
//! Today that is the coordinates' initial values and rates (`x = { initial = "d" }`): the
//! equations keep them as expressions ([`Model::initial_exprs`]), and the numeric copies in
//! [`CoordinateKind::Free`] are refreshed here.

use crate::model::CoordinateKind;
use crate::Model;
use pdyn_expr::{Id, Program};

/// Recomputes every coordinate's numeric initial value and rate from its expression with the
/// current parameter values. An expression that cannot be evaluated keeps its old value.
pub fn refresh_initial_values(model: &mut Model) {
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
