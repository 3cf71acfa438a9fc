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
    let start = std::time::Instant::now();
    let k = analyze(&mut p, motion);
    eprintln!("analyze: {:?} in {:?}", k.is_ok(), start.elapsed());
    let t = p.time();
    let target = p.parse_scalar("1").unwrap();
    let _ = maximum(&mut p, target, t, Pool::ZERO, Pool::ONE);
    eprintln!("total {:?}, pool {}", start.elapsed(), p.len());
}
