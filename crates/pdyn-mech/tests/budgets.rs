//! Symbolic work under budgets: inputs found by fuzzing or by hostile use that once made a
//! kinematics analysis run for minutes must finish (with a result or a typed error).
//! Deterministic: the assertions are on results and error kinds, never on wall time.

use pdyn_expr::{Pool, Value};
use pdyn_mech::kinematics::{analyze, maximum, Motion, Quantity};

/// A pool with the symbols `pdyn kin` declares positive, and the polar motion `r = R`,
/// `theta = src`.
fn polar_motion(src: &str) -> (Pool, Motion) {
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
    (p, motion)
}

/// The fuzz `kin` time-out (docs/reliability.md): this polar angle, with symbols not declared
/// positive, stalled `simplify` -> `contract_trig` on the unit tangent.
#[test]
fn fuzz_kin_timeout_polar_angle_finishes() {
    let src = "p000-AppU---pix/u-pp-U1-t-te";
    let (mut p, motion) = polar_motion(src);
    assert!(analyze(&mut p, motion).is_ok());
    let t = p.time();
    let target = p.parse_scalar("1").unwrap();
    let _ = maximum(&mut p, target, t, Pool::ZERO, Pool::ONE);
    // The work shows in the pool: 2,908 nodes when this test was written (the trig
    // contraction is bounded; a regression to unbounded rewriting would show here).
    assert!(p.len() < 20_000, "{} nodes", p.len());
}

/// The second fuzz `kin` time-out (docs/reliability.md): `theta` a sum of seven terms, so the
/// unit normal holds powers of sums of sines and cosines of that angle. With `sin`/`cos` of the
/// sum expanded, `simplify` multiplied out powers of 64-term sums (1.5 s natively, 40 s under
/// ASAN, in `RationalForm::power`). Powers whose expansion would exceed a term bound are now
/// kept whole (an atom: exact, only less cancelled) and each attempt's budget is smaller; the
/// polynomial work is counted by the pool, so the bound is asserted, not a time.
#[test]
fn fuzz_kin_timeout_powers_of_expanded_sums_stay_cheap() {
    let src = "gj1X-togj1X-t-+t+tt'+X-t-+tp+u*-x";
    let (mut p, motion) = polar_motion(src);
    let k = analyze(&mut p, motion).unwrap();
    // `pdyn kin` then expands and simplifies every printed quantity.
    for (_, q) in k.named() {
        let comps = match q {
            Quantity::Scalar(e) => vec![e],
            Quantity::Vector(v) => v.to_vec(),
        };
        for e in comps {
            let x = p.expand(e);
            p.simplify(x);
        }
    }
    let work = p.simplify_work();
    eprintln!("simplify work: {work} units, {} nodes", p.len());
    // 11,174 units with the bounds; 1,092,046 with only the smaller budget (about 1 s).
    assert!(work < 50_000, "simplify spent {work} units");
}
