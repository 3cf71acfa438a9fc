//! The 1-D rules of section 3.1.3 with symbolic initial values `x(0) = x0`, `v(0) = v0`
//! (issue 34, item 5): every rule class whose integrals are elementary gets a closed form, each
//! checked here against a formula worked by hand, or against the motion `x(t)` solved by hand
//! (the time `t(x)` a rule gives must bring that motion to `x`).

use pdyn_expr::{Id, Pool, Program};
use pdyn_mech::dsolve::rules::{solve_rule, Given, RuleSolution};

fn law(pool: &mut Pool, src: &str, positive: &[&str]) -> Id {
    let mut scope = pdyn_expr::FreeScope {
        positive: positive.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    pool.parse_in(src, &mut scope).unwrap().scalar().unwrap()
}

fn rule(pool: &mut Pool, given: Given, src: &str, positive: &[&str]) -> RuleSolution {
    let a = law(pool, src, positive);
    let (x0, v0) = (pool.var("x0"), pool.var("v0"));
    solve_rule(pool, given, a, x0, v0).unwrap()
}

/// The closed form of quantity `k`, evaluated with the named values.
fn closed_at(pool: &mut Pool, sol: &RuleSolution, k: usize, values: &[(&str, f64)]) -> f64 {
    let q = &sol.quantities[k];
    let c = q
        .closed
        .unwrap_or_else(|| panic!("{} has no closed form", q.name));
    let leaves: Vec<Id> = values.iter().map(|(n, _)| pool.var(n)).collect();
    let prog = Program::compile(pool, &leaves, &[c])
        .unwrap_or_else(|e| panic!("{}: {e}", pool.to_text(c)));
    let mut ws = prog.workspace();
    let mut out = [0.0];
    let input: Vec<f64> = values.iter().map(|v| v.1).collect();
    prog.eval(&input, &mut ws, &mut out);
    out[0]
}

fn close(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-10 * want.abs().max(1.0),
        "{what}: got {got}, want {want}"
    );
}

/// a = -k x: x(t) = x0 cos ωt + (v0/ω) sin ωt with ω = √k (solved by hand). Moving towards
/// larger x (v0 > 0) up to the turning point, t(x) must put that motion at x.
#[test]
fn spring_time_of_position_with_symbolic_start() {
    let mut pool = Pool::new();
    let sol = rule(&mut pool, Given::AccelerationOfPosition, "-k*x", &["k"]);
    for (k, x0, v0) in [(4.0f64, 0.3f64, 1.0f64), (2.5, -0.7, 0.4), (9.0, 0.0, 3.0)] {
        let w = k.sqrt();
        let amplitude = (x0 * x0 + v0 * v0 / (w * w)).sqrt();
        for frac in [0.1, 0.5, 0.9] {
            let x = x0 + frac * (amplitude - x0);
            let vals = [("k", k), ("x0", x0), ("v0", v0), ("x", x)];
            close(
                closed_at(&mut pool, &sol, 0, &vals),
                v0 * v0 + k * (x0 * x0 - x * x),
                "v(x)^2",
            );
            let t = closed_at(&mut pool, &sol, 1, &vals);
            let by_hand = (libm::asin(x / amplitude) - libm::asin(x0 / amplitude)) / w;
            close(t, by_hand, "t(x)");
            close(
                x0 * libm::cos(w * t) + v0 / w * libm::sin(w * t),
                x,
                "x(t(x))",
            );
        }
    }
}

/// a = g - k x (a spring under gravity): x(t) = g/k + (x0 - g/k) cos ωt + (v0/ω) sin ωt.
#[test]
fn spring_under_gravity_time_of_position() {
    let mut pool = Pool::new();
    let sol = rule(
        &mut pool,
        Given::AccelerationOfPosition,
        "g - k*x",
        &["g", "k"],
    );
    for (g, k, x0, v0) in [(9.81f64, 4.0f64, 0.0f64, 1.0f64), (2.0, 1.0, 3.0, 0.5)] {
        let w = k.sqrt();
        let c = g / k;
        let amplitude = ((x0 - c).powi(2) + (v0 / w).powi(2)).sqrt();
        let top = c + amplitude;
        for frac in [0.2, 0.6, 0.95] {
            let x = x0 + frac * (top - x0);
            let vals = [("g", g), ("k", k), ("x0", x0), ("v0", v0), ("x", x)];
            let t = closed_at(&mut pool, &sol, 1, &vals);
            close(
                c + (x0 - c) * libm::cos(w * t) + v0 / w * libm::sin(w * t),
                x,
                "x(t(x))",
            );
        }
    }
}

/// a = k x (a repulsion, an inverted pendulum near the top): x(t) = x0 cosh ωt + (v0/ω) sinh ωt.
#[test]
fn repulsion_time_of_position() {
    let mut pool = Pool::new();
    let sol = rule(&mut pool, Given::AccelerationOfPosition, "k*x", &["k"]);
    for (k, x0, v0) in [(4.0f64, 0.5f64, 1.0f64), (1.0, -1.0, 3.0)] {
        let w = k.sqrt();
        for x in [x0 + 0.1, x0 + 1.0, x0 + 5.0] {
            let vals = [("k", k), ("x0", x0), ("v0", v0), ("x", x)];
            let t = closed_at(&mut pool, &sol, 1, &vals);
            close(
                x0 * libm::cosh(w * t) + v0 / w * libm::sinh(w * t),
                x,
                "x(t(x))",
            );
        }
    }
}

/// a = -g - c v (a stone thrown up against linear drag). By hand: dt = dv/a gives
/// t(v) = ln((g + c v0)/(g + c v))/c, and dx = v dv/a gives
/// x(v) = x0 + (v0 - v)/c + (g/c²) ln((g + c v)/(g + c v0)).
#[test]
fn linear_drag_with_gravity_distance_of_speed() {
    let mut pool = Pool::new();
    let sol = rule(
        &mut pool,
        Given::AccelerationOfSpeed,
        "-g - c*v",
        &["g", "c"],
    );
    for (g, c, x0, v0) in [(9.81f64, 0.5f64, 0.0f64, 20.0f64), (1.0, 2.0, -3.0, 4.0)] {
        for v in [v0 * 0.9, v0 * 0.3, 0.0, -0.2 * g / c] {
            let vals = [("g", g), ("c", c), ("x0", x0), ("v0", v0), ("v", v)];
            close(
                closed_at(&mut pool, &sol, 0, &vals),
                libm::log((g + c * v0) / (g + c * v)) / c,
                "t(v)",
            );
            close(
                closed_at(&mut pool, &sol, 1, &vals),
                x0 + (v0 - v) / c + g / (c * c) * libm::log((g + c * v) / (g + c * v0)),
                "x(v)",
            );
        }
    }
}

/// a = -b v - c v² - g with numbers for b, c, g (the sign of the discriminant b² - 4 c g picks
/// the form) and v0, x0 symbolic. With P(v) = c v² + b v + g:
/// t(v) = ∫_v^v0 du/P and x(v) = x0 + ∫_v^v0 u du/P, where, with s = 2 c u + b,
/// ∫ du/P = 2 atan(s/√(-D))/√(-D) for D = b² - 4cg < 0, ln|(s - √D)/(s + √D)|/√D for D > 0,
/// and ∫ u du/P = ln P/(2c) - (b/(2c)) ∫ du/P.
#[test]
fn quadratic_drag_with_a_linear_term() {
    for (b, c, g) in [(1.0f64, 3.0f64, 2.0f64), (5.0, 3.0, 2.0)] {
        let mut pool = Pool::new();
        let src = format!("-{g} - {b}*v - {c}*v^2");
        let sol = rule(&mut pool, Given::AccelerationOfSpeed, &src, &[]);
        let d = b * b - 4.0 * c * g;
        let inv = |u: f64| {
            let s = 2.0 * c * u + b;
            if d < 0.0 {
                2.0 * libm::atan(s / (-d).sqrt()) / (-d).sqrt()
            } else {
                libm::log(((s - d.sqrt()) / (s + d.sqrt())).abs()) / d.sqrt()
            }
        };
        let lin = |u: f64| libm::log(c * u * u + b * u + g) / (2.0 * c) - b / (2.0 * c) * inv(u);
        let (x0, v0) = (0.25, 3.0);
        for v in [2.0, 0.5, 0.0] {
            let vals = [("x0", x0), ("v0", v0), ("v", v)];
            close(
                closed_at(&mut pool, &sol, 0, &vals),
                inv(v0) - inv(v),
                "t(v)",
            );
            close(
                closed_at(&mut pool, &sol, 1, &vals),
                x0 + lin(v0) - lin(v),
                "x(v)",
            );
        }
    }
}

/// The chapter's rule classes with symbolic x0, v0: each elementary one has a closed form for
/// every quantity (not quadrature). The quartic spring's time is elliptic and stays quadrature.
#[test]
fn every_elementary_rule_class_is_closed_with_symbolic_initial_values() {
    let classes: &[(Given, &str, &[&str])] = &[
        (Given::AccelerationOfTime, "sqrt(t)", &[]),
        (Given::AccelerationOfTime, "A*sin(w*t)", &["A", "w"]),
        (Given::AccelerationOfTime, "a0*exp(-t/tau)", &["a0", "tau"]),
        (Given::VelocityOfTime, "V*(1 - exp(-t/tau))", &["V", "tau"]),
        (Given::AccelerationOfSpeed, "-k*v", &["k"]),
        (Given::AccelerationOfSpeed, "-c*v^2", &["c"]),
        (Given::AccelerationOfSpeed, "-g - c*v", &["g", "c"]),
        (Given::AccelerationOfSpeed, "g - c*v", &["g", "c"]),
        (Given::AccelerationOfSpeed, "-g - c*v^2", &["g", "c"]),
        (Given::AccelerationOfSpeed, "g - c*v^2", &["g", "c"]),
        (Given::AccelerationOfPosition, "-g", &["g"]),
        (Given::AccelerationOfPosition, "-k*x", &["k"]),
        (Given::AccelerationOfPosition, "g - k*x", &["g", "k"]),
        (Given::AccelerationOfPosition, "k*x", &["k"]),
        (Given::AccelerationOfPosition, "-w^2*x", &["w"]),
    ];
    for &(given, src, positive) in classes {
        let mut pool = Pool::new();
        let sol = rule(&mut pool, given, src, positive);
        for q in &sol.quantities {
            assert!(
                q.closed.is_some(),
                "{src}: {} fell back to quadrature: {}",
                q.name,
                q.describe(&pool)
            );
        }
    }
    let mut pool = Pool::new();
    let sol = rule(&mut pool, Given::AccelerationOfPosition, "-k*x^3", &["k"]);
    assert!(
        sol.quantities[1].closed.is_none(),
        "elliptic: no elementary t(x)"
    );
}
