//! Fuzzing of the kinematics (`pdyn kin`): a position from the input, its derivatives,
//! normal–tangential and polar components, an instant, and a maximum over a range.
//! Run: `RUSTC_BOOTSTRAP=1 cargo fuzz run kin -- -max_total_time=1800 -timeout=30`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pdyn_expr::{Pool, Value};
use pdyn_mech::kinematics::{analyze, maximum, solve_time, Motion};

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    if src.len() > 512 {
        return;
    }
    // `position ; target`: a Cartesian position (or r, theta for polar when two items).
    let (pos, target) = src.split_once(';').unwrap_or((src, "1"));
    let mut p = Pool::new();
    for s in ["R", "omega", "c", "A", "L", "V"] {
        p.symbol(s, true);
    }
    let motion = match p.parse_value(pos) {
        Ok(Value::Vector(r)) => Motion::Cartesian(r),
        Ok(Value::Scalar(theta)) => Motion::Polar { r: p.var("R"), theta, z: pdyn_expr::Pool::ZERO },
        Err(_) => return,
    };
    let Ok(k) = analyze(&mut p, motion) else { return };
    let t = p.time();
    if let Ok(target) = p.parse_scalar(target) {
        if let Some(&(_, q)) = k.named().first() {
            if let pdyn_mech::kinematics::Quantity::Scalar(e) = q {
                let _ = solve_time(&mut p, e, target);
            }
        }
        let one = pdyn_expr::Pool::ONE;
        let _ = maximum(&mut p, target, t, pdyn_expr::Pool::ZERO, one);
    }
});
