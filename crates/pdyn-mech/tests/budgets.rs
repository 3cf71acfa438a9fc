//! Symbolic work under budgets: inputs found by fuzzing or by hostile use that once made a
//! kinematics analysis run for minutes must finish (with a result or a typed error).
//! Deterministic: the assertions are on results and error kinds, never on wall time.

use pdyn_expr::{Pool, Value};
use pdyn_mech::kinematics::{analyze, maximum, Motion};

/// The fuzz `kin` time-out (docs/reliability.md): this polar angle, with symbols not declared
/// positive, stalled `simplify` -> `contract_trig` on the unit tangent.
#[test]
fn fuzz_kin_timeout_polar_angle_finishes() {
    let src = "p000-AppU---pix/u-pp-U1-t-te";
    let mut p = Pool::new();
    for s in ["R", "omega", "c", "A", "L", "V"] {
        p.symbol(s, true);
    }
    let theta = match p.parse_value(src) {
        Ok(Value::Scalar(theta)) => theta,
        other => panic!("{other:?}"),
    };
    let motion = Motion::Polar {
        r: p.var("R"),
        theta,
        z: Pool::ZERO,
    };
    assert!(analyze(&mut p, motion).is_ok());
    let t = p.time();
    let target = p.parse_scalar("1").unwrap();
    let _ = maximum(&mut p, target, t, Pool::ZERO, Pool::ONE);
    // The work shows in the pool: 2,908 nodes when this test was written (the trig
    // contraction is bounded; a regression to unbounded rewriting would show here).
    assert!(p.len() < 20_000, "{} nodes", p.len());
}
