//! The 1-D rules of section 3.1.3: closed forms where the integrals are elementary (checked
//! against formulas worked by hand), quadrature with an error estimate otherwise.

use pdyn_expr::{Pool, Program};
use pdyn_mech::dsolve::rules::{antiderivative, evaluate, solve_rule, Given};

fn law(pool: &mut Pool, src: &str, positive: &[&str]) -> pdyn_expr::Id {
    let mut scope = pdyn_expr::FreeScope {
        positive: positive.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    match pool.parse_in(src, &mut scope).unwrap() {
        pdyn_expr::Value::Scalar(s) => s,
        _ => panic!(),
    }
}

fn value_at(pool: &mut Pool, e: pdyn_expr::Id, var: pdyn_expr::Id, s: f64) -> f64 {
    let prog = Program::compile(pool, &[var], &[e]).unwrap();
    let mut ws = prog.workspace();
    let mut out = [0.0];
    prog.eval(&[s], &mut ws, &mut out);
    out[0]
}

#[test]
fn acceleration_of_time_sinusoidal() {
    let mut pool = Pool::new();
    let a = law(&mut pool, "3*sin(2*t)", &[]);
    let (x0, v0) = (pool.int(1), pool.int(-2));
    let sol = solve_rule(&mut pool, Given::AccelerationOfTime, a, x0, v0).unwrap();
    let t = pool.time();
    for (q, f) in sol.quantities.iter().zip([
        Box::new(|t: f64| -2.0 + 1.5 * (1.0 - libm::cos(2.0 * t))) as Box<dyn Fn(f64) -> f64>,
        Box::new(|t: f64| 1.0 - 2.0 * t + 1.5 * t - 0.75 * libm::sin(2.0 * t)),
    ]) {
        let c = q.closed.expect("elementary");
        for s in [0.0, 0.4, 2.5] {
            let v = value_at(&mut pool, c, t, s);
            assert!(
                (v - f(s)).abs() < 1e-12,
                "{} at {s}: {v} vs {}",
                q.name,
                f(s)
            );
        }
    }
}

#[test]
fn quadratic_drag_speed_law() {
    // a = -c v^2: t(v) = (1/v - 1/v0)/c, x(v) = log(v0/v)/c.
    let mut pool = Pool::new();
    let a = law(&mut pool, "-c*v^2", &["c"]);
    let x0 = Pool::ZERO;
    let v0 = pool.var("v0");
    let sol = solve_rule(&mut pool, Given::AccelerationOfSpeed, a, x0, v0).unwrap();
    let t_v = sol.quantities[0].closed.unwrap();
    let x_v = sol.quantities[1].closed.unwrap();
    let expect_t = pool.parse_scalar("(1/v - 1/v0)/c").unwrap();
    assert!(pool.provably_equal(t_v, expect_t), "{}", pool.to_text(t_v));
    let (c, v0s, v) = (pool.var("c"), pool.var("v0"), pool.var("v"));
    let prog = Program::compile(&mut pool, &[c, v0s, v], &[x_v]).unwrap();
    let mut ws = prog.workspace();
    let mut out = [0.0];
    prog.eval(&[0.5, 10.0, 4.0], &mut ws, &mut out);
    assert!((out[0] - libm::log(10.0f64 / 4.0) / 0.5).abs() < 1e-12);
}

#[test]
fn drag_with_gravity_gives_arctangent() {
    let mut pool = Pool::new();
    let a = law(&mut pool, "-g - c*v^2", &["g", "c"]);
    let t = pool.time();
    let f = antiderivative(&mut pool, pdyn_expr::Pool::ONE, t).unwrap();
    assert_eq!(pool.to_text(f), "t");
    let inv = pool.powi(a, -1);
    let v = pool.var("v");
    let anti = antiderivative(&mut pool, inv, v).expect("atan form");
    assert!(
        pool.to_text(anti).contains("atan"),
        "{}",
        pool.to_text(anti)
    );
}

#[test]
fn no_elementary_antiderivative_uses_quadrature_with_error_estimate() {
    let mut pool = Pool::new();
    let a = law(&mut pool, "exp(-t^2)", &[]);
    let sol = solve_rule(
        &mut pool,
        Given::AccelerationOfTime,
        a,
        Pool::ZERO,
        Pool::ZERO,
    )
    .unwrap();
    assert!(sol.quantities[0].closed.is_none());
    let est = evaluate(&mut pool, &sol.quantities[0], 1.0).unwrap();
    // sqrt(pi)/2 erf(1)
    assert!(
        (est.value - 0.746_824_132_812_427_1).abs() < 1e-12,
        "{est:?}"
    );
    assert!(est.error < 1e-9 && est.error > 0.0);
    // x(1) = ∫_0^1 (1 - u) e^{-u^2} du = sqrt(pi)/2 erf(1) - (1 - e^{-1})/2
    let est = evaluate(&mut pool, &sol.quantities[1], 1.0).unwrap();
    let expect = 0.746_824_132_812_427_1 - 0.5 * (1.0 - libm::exp(-1.0f64));
    assert!((est.value - expect).abs() < 1e-11, "{est:?} vs {expect}");
}

#[test]
fn spring_position_law_time_in_closed_form() {
    // a = -4x, x0 = 0, v0 = 2: x = sin(2t), so t(x) = asin(x)/2 and t(1/2) = pi/12.
    let mut pool = Pool::new();
    let a = law(&mut pool, "-4*x", &[]);
    let v0 = pool.int(2);
    let sol = solve_rule(&mut pool, Given::AccelerationOfPosition, a, Pool::ZERO, v0).unwrap();
    let vsq = sol.quantities[0].closed.unwrap();
    let expect = pool.parse_scalar("4 - 4*x^2").unwrap();
    assert!(pool.provably_equal(vsq, expect), "{}", pool.to_text(vsq));
    let t_x = sol.quantities[1].closed.expect("asin form");
    assert_eq!(pool.to_text(t_x), "asin(x)/2");
    let est = evaluate(&mut pool, &sol.quantities[1], 0.5).unwrap();
    assert!((est.value - std::f64::consts::PI / 12.0).abs() < 1e-14);
}

#[test]
fn quartic_position_law_time_by_nested_quadrature() {
    // a = -4x^3, v0 = 2: v^2 = 4 - 2x^4, t(x) = ∫ dx/sqrt(4 - 2x^4) is elliptic (no
    // elementary form); reference values from mpmath.quad.
    let mut pool = Pool::new();
    let a = law(&mut pool, "-4*x^3", &[]);
    let v0 = pool.int(2);
    let sol = solve_rule(&mut pool, Given::AccelerationOfPosition, a, Pool::ZERO, v0).unwrap();
    assert!(sol.quantities[1].closed.is_none());
    for (x, reference) in [(0.5, 0.250_791_609_849_273), (1.0, 0.532_515_451_849_903)] {
        let est = evaluate(&mut pool, &sol.quantities[1], x).unwrap();
        assert!((est.value - reference).abs() < 1e-9, "{est:?}");
        assert!(est.error < 1e-6, "{est:?}");
    }
    // Beyond the turning point 2^(1/4) the particle never arrives.
    assert!(evaluate(&mut pool, &sol.quantities[1], 1.3).is_err());
}

#[test]
fn velocity_of_time() {
    let mut pool = Pool::new();
    let v = law(&mut pool, "V*(1 - exp(-t/tau))", &["V", "tau"]);
    let sol = solve_rule(&mut pool, Given::VelocityOfTime, v, Pool::ZERO, Pool::ZERO).unwrap();
    let x = sol.quantities[0].closed.unwrap();
    let expect = pool.parse_scalar("V*t - V*tau*(1 - exp(-t/tau))").unwrap();
    assert!(pool.provably_equal(x, expect), "{}", pool.to_text(x));
    let acc = sol.quantities[1].closed.unwrap();
    let expect = pool.parse_scalar("V*exp(-t/tau)/tau").unwrap();
    assert!(pool.provably_equal(acc, expect), "{}", pool.to_text(acc));
}
