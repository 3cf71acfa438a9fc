//! Kinematics on the chapter's examples (Bower, *Dynamics*, 3.1), checked against the closed
//! forms worked by hand and against finite differences.

use pdyn_expr::{FreeScope, Id, Pool, Program, Value};
use pdyn_mech::kinematics::{analyze, maximize, solve_time, Motion};

fn parse(pool: &mut Pool, src: &str, positive: &[&str]) -> Id {
    let mut scope = FreeScope {
        positive: positive.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    let ast = pdyn_expr::syntax::parse(src).unwrap();
    scope.learn(&ast);
    match pdyn_expr::lower::lower(pool, &ast, &mut scope).unwrap() {
        Value::Scalar(s) => s,
        Value::Vector(_) => panic!("vector"),
    }
}

fn num(pool: &mut Pool, e: Id, inputs: &[Id], vals: &[f64]) -> f64 {
    let prog = Program::compile(pool, inputs, &[e])
        .unwrap_or_else(|err| panic!("{}: {err}", pool.to_text(e)));
    let mut ws = prog.workspace();
    let mut o = [0.0];
    prog.eval(vals, &mut ws, &mut o);
    o[0]
}

fn close(a: f64, b: f64) {
    assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()), "{a} vs {b}");
}

#[test]
fn polar_example_at_theta_pi() {
    let mut p = Pool::new();
    let r = parse(&mut p, "t/sqrt(pi)", &[]);
    let th = parse(&mut p, "t^2", &[]);
    let k = analyze(
        &mut p,
        Motion::Polar {
            r,
            theta: th,
            z: Pool::ZERO,
        },
    )
    .unwrap();
    let pi = p.constant(pdyn_expr::Constant::Pi);
    let (exact, tv) = solve_time(&mut p, th, pi).unwrap();
    let t_exact = exact.expect("t^2 = pi solves exactly");
    assert_eq!(p.to_text(t_exact), "sqrt(pi)");
    close(tv, std::f64::consts::PI.sqrt());
    let t = p.time();
    let at = |p: &mut Pool, e: Id| {
        let s = p.subs1(e, t, t_exact);
        let s = p.expand(s);
        p.simplify(s)
    };
    let text = |p: &mut Pool, v: [Id; 3]| -> Vec<String> {
        v.iter()
            .map(|&c| {
                let s = at(p, c);
                p.to_text(s)
            })
            .collect()
    };
    assert_eq!(text(&mut p, k.position), ["-1", "0", "0"]);
    assert_eq!(
        text(&mut p, k.velocity),
        ["-1/sqrt(pi)", "-2*sqrt(pi)", "0"]
    );
    assert_eq!(
        text(&mut p, k.polar.acceleration),
        ["-4*pi", "6", "0"],
        "a = -4 pi e_r + 6 e_theta"
    );
    let pi_f = std::f64::consts::PI;
    let s = (1.0 + 4.0 * pi_f * pi_f).sqrt();
    let at_t = at(&mut p, k.a_t);
    close(num(&mut p, at_t, &[], &[]), 8.0 * pi_f / s);
    let at_n = at(&mut p, k.a_n);
    close(num(&mut p, at_n, &[], &[]), (8.0 * pi_f * pi_f + 6.0) / s);
    // n: unit, normal to v, and a = a_t t + a_n n.
    let n: Vec<f64> = k
        .normal
        .iter()
        .map(|&c| {
            let e = at(&mut p, c);
            num(&mut p, e, &[], &[])
        })
        .collect();
    let a: Vec<f64> = k
        .acceleration
        .iter()
        .map(|&c| {
            let e = at(&mut p, c);
            num(&mut p, e, &[], &[])
        })
        .collect();
    let tt: Vec<f64> = k
        .tangent
        .iter()
        .map(|&c| {
            let e = at(&mut p, c);
            num(&mut p, e, &[], &[])
        })
        .collect();
    close(n.iter().map(|x| x * x).sum::<f64>(), 1.0);
    close(
        n.iter().zip(&tt).map(|(x, y)| x * y).sum::<f64>() + 1.0,
        1.0,
    );
    for i in 0..3 {
        close(
            a[i],
            8.0 * pi_f / s * tt[i] + (8.0 * pi_f * pi_f + 6.0) / s * n[i],
        );
    }
}

#[test]
fn circular_motion_constant_and_general() {
    let mut p = Pool::new();
    let r = parse(&mut p, "R", &["R", "omega"]);
    let th = parse(&mut p, "omega*t", &["R", "omega"]);
    let k = analyze(
        &mut p,
        Motion::Polar {
            r,
            theta: th,
            z: Pool::ZERO,
        },
    )
    .unwrap();
    assert_eq!(p.to_text(k.speed), "R*omega");
    assert_eq!(p.to_text(k.radius), "R");
    assert_eq!(p.to_text(k.a_n), "R*omega^2");
    assert_eq!(p.to_text(k.a_t), "0");
    assert_eq!(p.to_text(k.polar.acceleration[0]), "-R*omega^2");
    // The normal points to the centre: n = -e_r.
    for i in 0..3 {
        let s = p.add2(k.normal[i], k.polar.e_r[i]);
        assert_eq!(p.simplify(s), Pool::ZERO, "n = -e_r");
    }
    // General: theta(t) a coordinate.
    let mut p = Pool::new();
    let r = parse(&mut p, "R", &["R"]);
    let th = parse(&mut p, "theta(t)", &["R"]);
    let k = analyze(
        &mut p,
        Motion::Polar {
            r,
            theta: th,
            z: Pool::ZERO,
        },
    )
    .unwrap();
    assert_eq!(p.to_text(k.polar.velocity[1]), "R*theta'");
    assert_eq!(p.to_text(k.polar.acceleration[0]), "-R*theta'^2");
    assert_eq!(p.to_text(k.polar.acceleration[1]), "R*theta''");
    assert_eq!(p.to_text(k.radius), "R");
}

#[test]
fn cartesian_helix_against_finite_differences() {
    let mut p = Pool::new();
    let x = parse(&mut p, "2*cos(3*t)", &[]);
    let y = parse(&mut p, "2*sin(3*t)", &[]);
    let z = parse(&mut p, "t^2", &[]);
    let k = analyze(&mut p, Motion::Cartesian([x, y, z])).unwrap();
    let t = p.time();
    let pos = |tt: f64| -> [f64; 3] {
        [
            2.0 * libm::cos(3.0 * tt),
            2.0 * libm::sin(3.0 * tt),
            tt * tt,
        ]
    };
    let h = 1e-4;
    for tt in [0.3, 1.2] {
        let (a, b, c) = (pos(tt - h), pos(tt), pos(tt + h));
        let v: Vec<f64> = (0..3).map(|i| (c[i] - a[i]) / (2.0 * h)).collect();
        let acc: Vec<f64> = (0..3)
            .map(|i| (c[i] - 2.0 * b[i] + a[i]) / (h * h))
            .collect();
        for i in 0..3 {
            let vi = num(&mut p, k.velocity[i], &[t], &[tt]);
            assert!((vi - v[i]).abs() < 1e-6);
            let ai = num(&mut p, k.acceleration[i], &[t], &[tt]);
            assert!((ai - acc[i]).abs() < 1e-4);
        }
        // R from the osculating circle: |v|^3/|v x a|.
        let vv: f64 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let cr = [
            v[1] * acc[2] - v[2] * acc[1],
            v[2] * acc[0] - v[0] * acc[2],
            v[0] * acc[1] - v[1] * acc[0],
        ];
        let crn = cr.iter().map(|x| x * x).sum::<f64>().sqrt();
        let rr = num(&mut p, k.radius, &[t], &[tt]);
        assert!((rr - vv.powi(3) / crn).abs() < 1e-4 * rr, "{rr}");
        // n is a unit vector normal to t, and a = a_t t + a_n n.
        let vec3 = |p: &mut Pool, w: [Id; 3]| -> Vec<f64> {
            w.iter().map(|&c| num(p, c, &[t], &[tt])).collect()
        };
        let (n, tg, acc_e) = (
            vec3(&mut p, k.normal),
            vec3(&mut p, k.tangent),
            vec3(&mut p, k.acceleration),
        );
        let (at, an) = (
            num(&mut p, k.a_t, &[t], &[tt]),
            num(&mut p, k.a_n, &[t], &[tt]),
        );
        close(n.iter().map(|x| x * x).sum::<f64>(), 1.0);
        close(
            n.iter().zip(&tg).map(|(x, y)| x * y).sum::<f64>() + 1.0,
            1.0,
        );
        for i in 0..3 {
            close(acc_e[i], at * tg[i] + an * n[i]);
        }
    }
}

#[test]
fn curvy_road_maximum_acceleration_and_speed_limit() {
    let mut p = Pool::new();
    let pos = ["A", "L", "V", "g"];
    let y = parse(&mut p, "A*sin(2*pi*x/L)", &pos);
    let x = p.var("x");
    let v = parse(&mut p, "V", &pos);
    let k = analyze(
        &mut p,
        Motion::Path {
            x,
            y,
            parameter: x,
            speed: v,
        },
    )
    .unwrap();
    let norm_a = {
        let d = pdyn_expr::vector::dot(&mut p, k.acceleration, k.acceleration);
        let s = p.sqrt(d);
        p.simplify(s)
    };
    // Numeric maximum for A = 2, L = 50, V = 10: at x = L/4, value A (2 pi V / L)^2.
    let (a_s, l_s, v_s) = (p.var("A"), p.var("L"), p.var("V"));
    let mut f = norm_a;
    for (s, val) in [(a_s, 2.0), (l_s, 50.0), (v_s, 10.0)] {
        let n = p.num(pdyn_expr::Number::Float(val));
        f = p.subs1(f, s, n);
    }
    let ext = maximize(&mut p, f, x, 0.0, 50.0).unwrap();
    let expect = 2.0 * (2.0 * std::f64::consts::PI * 10.0 / 50.0f64).powi(2);
    assert!((ext.at - 12.5).abs() < 1e-6, "{ext:?}");
    assert!((ext.value - expect).abs() < 1e-9 * expect, "{ext:?}");
    // Symbolically at x = L/4.
    let quarter = p.parse_scalar("L/4").unwrap();
    let amax = p.subs1(norm_a, x, quarter);
    let amax = p.simplify(amax);
    let expect = parse(&mut p, "A*(2*pi*V/L)^2", &pos);
    assert!(p.provably_equal(amax, expect), "{}", p.to_text(amax));
    // The speed limit V = (L/2 pi) sqrt(0.2 g / A) gives a_max = 0.2 g.
    let limit = parse(&mut p, "L/(2*pi)*sqrt(0.2*g/A)", &pos);
    let at_limit = p.subs1(amax, v_s, limit);
    let fifth_g = parse(&mut p, "g/5", &pos);
    assert!(
        p.provably_equal(at_limit, fifth_g),
        "{}",
        p.to_text(at_limit)
    );
}

#[test]
fn vehicle_on_a_circular_path_minimum_time() {
    // Starting from rest with constant tangential acceleration, half a lap (s = pi R) in time T:
    // theta = pi t^2/T^2. |a| is largest at t = T; |a(T)| <= mu g gives
    // T >= sqrt(2 pi R/(mu g)) (1 + 4 pi^2)^(1/4).
    let mut p = Pool::new();
    let pos = ["R", "T", "mu", "g"];
    let r = parse(&mut p, "R", &pos);
    let th = parse(&mut p, "pi*t^2/T^2", &pos);
    let k = analyze(
        &mut p,
        Motion::Polar {
            r,
            theta: th,
            z: Pool::ZERO,
        },
    )
    .unwrap();
    let t = p.time();
    let tt = p.var("T");
    let amag = {
        let d = pdyn_expr::vector::dot(&mut p, k.acceleration, k.acceleration);
        let s = p.sqrt(d);
        p.simplify(s)
    };
    let at_end = p.subs1(amag, t, tt);
    let expect = parse(&mut p, "2*pi*R*sqrt(1 + 4*pi^2)/T^2", &pos);
    let (sq_a, sq_b) = (p.powi(at_end, 2), p.powi(expect, 2));
    assert!(p.provably_equal(sq_a, sq_b), "{}", p.to_text(at_end));
    // At T_min the peak acceleration equals mu g.
    let tmin = parse(&mut p, "sqrt(2*pi*R/(mu*g))*(1 + 4*pi^2)^(1/4)", &pos);
    let peak = p.subs1(at_end, tt, tmin);
    let mug = parse(&mut p, "mu*g", &pos);
    let (rs, mus, gs) = (p.var("R"), p.var("mu"), p.var("g"));
    let d = p.sub(peak, mug);
    close(num(&mut p, d, &[rs, mus, gs], &[30.0, 0.8, 9.81]), 0.0);
    // And it is the maximum over the manoeuvre (numerically, R = 30, T = 20).
    let mut f = amag;
    for (s, v) in [(rs, 30.0), (tt, 20.0)] {
        let n = p.num(pdyn_expr::Number::Float(v));
        f = p.subs1(f, s, n);
    }
    let ext = maximize(&mut p, f, t, 0.0, 20.0).unwrap();
    assert!((ext.at - 20.0).abs() < 1e-9, "{ext:?}");
}

#[test]
fn robotic_manipulator_maximum_extension_rate() {
    // Arm turning at constant rate omega, gripper extending at constant rate c from r = 0 to
    // r = R: a = -c t omega^2 e_r + 2 c omega e_theta (the Coriolis term carries the factor 2).
    // |a|^2 = r^2 omega^4 + 4 c^2 omega^2 grows with r, so the limit |a| <= a_max binds at full
    // extension: c_max = sqrt(a_max^2 - R^2 omega^4)/(2 omega).
    let mut p = Pool::new();
    let pos = ["c", "omega", "a_max", "R"];
    let r = parse(&mut p, "c*t", &pos);
    let th = parse(&mut p, "omega*t", &pos);
    let k = analyze(
        &mut p,
        Motion::Polar {
            r,
            theta: th,
            z: Pool::ZERO,
        },
    )
    .unwrap();
    assert_eq!(p.to_text(k.polar.acceleration[1]), "2*c*omega");
    assert_eq!(p.to_text(k.polar.acceleration[0]), "-c*omega^2*t");
    let t = p.time();
    let a2 = pdyn_expr::vector::dot(&mut p, k.acceleration, k.acceleration);
    let a2 = p.simplify(a2);
    // At full extension t = R/c.
    let t_end = parse(&mut p, "R/c", &pos);
    let a2_end = p.subs1(a2, t, t_end);
    let expect = parse(&mut p, "R^2*omega^4 + 4*c^2*omega^2", &pos);
    assert!(p.provably_equal(a2_end, expect), "{}", p.to_text(a2_end));
    let cmax = parse(&mut p, "sqrt(a_max^2 - R^2*omega^4)/(2*omega)", &pos);
    let cs = p.var("c");
    let at = p.subs1(a2_end, cs, cmax);
    let amax2 = parse(&mut p, "a_max^2", &pos);
    assert!(p.provably_equal(at, amax2), "{}", p.to_text(at));
    // Numerically (omega = 2, R = 0.5, a_max = 3): the largest |a| over the stroke is at the end
    // and equals a_max at c = c_max.
    let (om, rr, am): (f64, f64, f64) = (2.0, 0.5, 3.0);
    let c_val = (am * am - rr * rr * om * om * om * om).sqrt() / (2.0 * om);
    let mut f = p.sqrt(a2);
    for (name, v) in [("c", c_val), ("omega", om)] {
        let s = p.var(name);
        let n = p.num(pdyn_expr::Number::Float(v));
        f = p.subs1(f, s, n);
    }
    let ext = maximize(&mut p, f, t, 0.0, rr / c_val).unwrap();
    assert!((ext.at - rr / c_val).abs() < 1e-9, "{ext:?}");
    assert!((ext.value - am).abs() < 1e-9, "{ext:?}");
}

#[test]
fn instants_by_numeric_root_when_not_exact() {
    let mut p = Pool::new();
    let th = parse(&mut p, "t + sin(t)", &[]);
    let two = p.int(2);
    let (exact, tv) = solve_time(&mut p, th, two).unwrap();
    assert!(exact.is_none());
    assert!((tv + libm::sin(tv) - 2.0).abs() < 1e-12);
    let never = parse(&mut p, "sin(t)", &[]);
    assert!(solve_time(&mut p, never, two).is_err());
}
