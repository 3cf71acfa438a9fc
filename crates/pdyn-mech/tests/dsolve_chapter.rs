//! `dsolve` on the chapter's examples (Bower, *Dynamics*, 3.3.2) and on checks that can fail:
//! every solution is substituted back into its equation and initial conditions, and the
//! 2-storey building is compared with a step-by-step RK4 integration.

use pdyn_expr::{FreeScope, Id, Pool, Program, SymId, Value};
use pdyn_mech::dsolve::{solve_system, ClosedForm, DsolveError, Method, Relation};

struct Problem {
    pool: Pool,
    eqs: Vec<Id>,
    coords: Vec<SymId>,
    ics: Vec<(Id, Id)>,
}

/// Parses equations and `name(0)=value` / `name'(0)=value` initial conditions.
fn problem(eqs: &[&str], ics: &[(&str, &str)], positive: &[&str]) -> Problem {
    let mut pool = Pool::new();
    let mut scope = FreeScope {
        positive: positive.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    for e in eqs {
        let (l, r) = pdyn_expr::syntax::parse_equation(e).unwrap();
        scope.learn(&l);
        if let Some(r) = &r {
            scope.learn(r);
        }
    }
    let mut names: Vec<&String> = scope.coordinates.iter().collect();
    names.sort();
    let coords: Vec<SymId> = names.iter().map(|n| pool.symbol(n, false)).collect();
    let parsed: Vec<Id> = eqs
        .iter()
        .map(|e| match pool.parse_equation_in(e, &mut scope).unwrap() {
            Value::Scalar(s) => s,
            Value::Vector(_) => panic!("vector"),
        })
        .collect();
    let ics = ics
        .iter()
        .map(|(l, v)| {
            let lhs = match pool.parse_in(l, &mut scope).unwrap() {
                Value::Scalar(s) => s,
                _ => panic!(),
            };
            let val = match pool.parse_in(v, &mut scope).unwrap() {
                Value::Scalar(s) => s,
                _ => panic!(),
            };
            (lhs, val)
        })
        .collect();
    Problem {
        pool,
        eqs: parsed,
        coords,
        ics,
    }
}

fn solve(p: &mut Problem) -> Result<ClosedForm, DsolveError> {
    solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics)
}

/// Evaluates `e` with `t` and the named parameters set.
fn eval(pool: &mut Pool, e: Id, t: f64, params: &[(&str, f64)]) -> f64 {
    let mut inputs = vec![pool.time()];
    let mut vals = vec![t];
    for (n, v) in params {
        inputs.push(pool.var(n));
        vals.push(*v);
    }
    let prog = Program::compile(pool, &inputs, &[e]).unwrap_or_else(|err| {
        panic!("compile {}: {err}", pool.to_text(e));
    });
    let mut ws = prog.workspace();
    let mut out = [0.0];
    prog.eval(&vals, &mut ws, &mut out);
    out[0]
}

/// Substitutes the solution into the equations and the initial conditions at sample points.
fn assert_satisfies(p: &mut Problem, sol: &[Id], params: &[(&str, f64)]) {
    let pool = &mut p.pool;
    let mut residuals = Vec::new();
    for &eq in &p.eqs {
        let mut e = eq;
        for (j, &c) in p.coords.iter().enumerate() {
            for k in (0..=6u8).rev() {
                let leaf = pool.coord(c, k);
                let d = pool.dt_n(sol[j], k as usize);
                e = pool.subs1(e, leaf, d);
            }
        }
        residuals.push(e);
    }
    for &r in &residuals {
        for t in [0.0, 0.37, 1.1, 2.9] {
            let v = eval(pool, r, t, params);
            assert!(v.abs() < 1e-8, "residual {} at t={t}: {v}", pool.to_text(r));
        }
    }
    for &(lhs, val) in &p.ics {
        let pdyn_expr::Node::Coord(s, k) = *pool.node(lhs) else {
            panic!()
        };
        let j = p.coords.iter().position(|&c| c == s).unwrap();
        let d = pool.dt_n(sol[j], k as usize);
        let got = eval(pool, d, 0.0, params);
        let want = eval(pool, val, 0.0, params);
        assert!(
            (got - want).abs() < 1e-9,
            "IC {}: {got} vs {want}",
            pool.to_text(lhs)
        );
    }
}

fn assert_same(pool: &mut Pool, a: Id, b: &str, params: &[(&str, f64)]) {
    let b = pool.parse_scalar(b).unwrap();
    for t in [0.0, 0.3, 1.7] {
        let (x, y) = (eval(pool, a, t, params), eval(pool, b, t, params));
        assert!(
            (x - y).abs() < 1e-9 * (1.0 + y.abs()),
            "{} vs {} at t={t}: {x} vs {y}",
            pool.to_text(a),
            pool.to_text(b)
        );
    }
}

#[test]
fn suspension_matches_the_chapter() {
    let mut p = problem(
        &["m*x'' = -k*(x - L0) - m*g"],
        &[("x", "L"), ("x'", "0")],
        &["m", "k"],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Exact);
    let x = cf.unique().unwrap()[0];
    let params = [
        ("m", 2.0),
        ("k", 50.0),
        ("L0", 0.4),
        ("g", 9.81),
        ("L", 0.3),
    ];
    assert_same(
        &mut p.pool,
        x,
        "(L - L0 + m*g/k)*cos(sqrt(k/m)*t) + L0 - m*g/k",
        &params,
    );
    // Symbolically identical, too.
    let expected = p
        .pool
        .parse_scalar("(L - L0 + m*g/k)*cos(sqrt(k/m)*t) + L0 - m*g/k")
        .unwrap();
    let e = p.pool.expand(expected);
    assert!(p.pool.provably_equal(x, e), "{}", p.pool.to_text(x));
    assert_satisfies(&mut p, &[x], &params);
}

#[test]
fn rotating_rod_pushing_a_block() {
    let mut p = problem(
        &["r'' + 2*mu*omega*r' - omega^2*r = 0"],
        &[("r", "0"), ("r'", "V")],
        &["mu", "omega"],
    );
    let cf = solve(&mut p).unwrap();
    let r = cf.unique().unwrap()[0];
    let params = [("mu", 0.3), ("omega", 2.0), ("V", 1.5)];
    assert_same(
        &mut p.pool,
        r,
        "V*exp(-mu*omega*t)*sinh(sqrt(1+mu^2)*omega*t)/(omega*sqrt(1+mu^2))",
        &params,
    );
    let text = p.pool.to_text(r);
    assert!(text.contains("sinh"), "{text}");
    assert_satisfies(&mut p, &[r], &params);
}

#[test]
fn projectile_and_the_kremlin_stone() {
    let mut p = problem(
        &["x'' = 0", "y'' = -g"],
        &[
            ("x", "0"),
            ("x'", "V*cos(alpha)"),
            ("y", "h"),
            ("y'", "V*sin(alpha)"),
        ],
        &["g"],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Exact);
    let sol = cf.unique().unwrap().to_vec();
    let mph = 0.44704;
    let params = [
        ("g", 9.81),
        ("V", 25.0 * mph),
        ("alpha", std::f64::consts::FRAC_PI_4),
        ("h", 71.0),
    ];
    assert_same(&mut p.pool, sol[0], "V*cos(alpha)*t", &params);
    assert_same(&mut p.pool, sol[1], "h + V*sin(alpha)*t - g*t^2/2", &params);
    assert_satisfies(&mut p, &sol, &params);
    // Range: the positive root of y(t) = 0, by bisection on the closed form.
    let (mut lo, mut hi) = (0.0, 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if eval(&mut p.pool, sol[1], mid, &params) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let range = eval(&mut p.pool, sol[0], lo, &params);
    assert!((range - 37.1).abs() < 0.05, "range {range}");
}

#[test]
fn nanoparticle_maximum_height_is_kt_over_mg() {
    let mut p = problem(
        &["y'' = -g"],
        &[("y", "0"), ("y'", "sqrt(2*k*T/m)")],
        &["g", "k", "T", "m"],
    );
    let cf = solve(&mut p).unwrap();
    let y = cf.unique().unwrap()[0];
    let pool = &mut p.pool;
    // Highest point: y'(t*) = 0, linear in t.
    let v = pool.dt(y);
    let t = pool.time();
    let sys = pool.linear_system(&[v], &[t]).unwrap();
    let tstar = pool.solve_linear(&sys).unwrap()[0];
    let h = pool.subs1(y, t, tstar);
    let expected = pool.parse_scalar("k*T/(m*g)").unwrap();
    assert!(
        pool.provably_equal(h, expected),
        "max height {}",
        pool.to_text(h)
    );
}

#[test]
fn damped_oscillator_symbolic_gives_each_case() {
    let mut p = problem(
        &["x'' + 2*zeta*wn*x' + wn^2*x = 0"],
        &[("x", "x0"), ("x'", "v0")],
        &["zeta", "wn"],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.cases.len(), 3);
    let rels: Vec<Relation> = cf
        .cases
        .iter()
        .map(|c| c.condition.unwrap().relation)
        .collect();
    assert_eq!(
        rels,
        [Relation::Negative, Relation::Zero, Relation::Positive]
    );
    let cond = cf.cases[0].condition.unwrap().expr;
    let expected = p.pool.parse_scalar("zeta - 1").unwrap();
    assert_eq!(cond, expected, "{}", p.pool.to_text(cond));
    for (case, zeta) in cf.cases.clone().iter().zip([0.2, 1.0, 2.5]) {
        let params = [("zeta", zeta), ("wn", 3.0), ("x0", 0.5), ("v0", -1.0)];
        assert_satisfies(&mut p, &case.solution, &params);
    }
    let critical = p.pool.to_text(cf.cases[1].solution[0]);
    assert!(
        !critical.contains("zeta"),
        "zeta = 1 substituted: {critical}"
    );
    let under = p.pool.to_text(cf.cases[0].solution[0]);
    assert!(under.contains("cos") && under.contains("sin"), "{under}");
    let over = p.pool.to_text(cf.cases[2].solution[0]);
    assert!(over.contains("cosh") || over.contains("sinh"), "{over}");
}

#[test]
fn damped_oscillator_numeric_picks_the_case() {
    for (zeta, form) in [("1/10", "cos"), ("1", "t"), ("2", "exp")] {
        let eq = format!("x'' + 2*{zeta}*3*x' + 9*x = 0");
        let mut p = problem(&[&eq], &[("x", "1"), ("x'", "0")], &[]);
        let cf = solve(&mut p).unwrap();
        assert_eq!(cf.cases.len(), 1, "{eq}");
        assert!(cf.cases[0].condition.is_none());
        let x = cf.cases[0].solution[0];
        let text = p.pool.to_text(x);
        assert!(text.contains(form), "{eq}: {text}");
        assert_satisfies(&mut p, &[x], &[]);
    }
    // Critically damped: x = (1 + 3t) e^{-3t} exactly.
    let mut p = problem(&["x'' + 6*x' + 9*x = 0"], &[("x", "1"), ("x'", "0")], &[]);
    let x = solve(&mut p).unwrap().cases[0].solution[0];
    let e = p.pool.parse_scalar("(1 + 3*t)*exp(-3*t)").unwrap();
    let e = p.pool.expand(e);
    assert!(p.pool.provably_equal(x, e), "{}", p.pool.to_text(x));
}

#[test]
fn forcing_polynomial_exponential_trig_and_resonance() {
    let cases: [(&str, &str, &str); 6] = [
        ("x'' + 3*x' + 2*x = 4*t^2", "x(0)", "1"),
        ("x'' + x = t*exp(2*t)", "x(0)", "0"),
        ("x'' + 4*x = sin(2*t)", "x(0)", "0"), // resonance
        ("x'' - x = exp(t)", "x(0)", "1"),     // resonance with a real root
        ("x'' + 2*x' + 5*x = exp(-t)*cos(2*t) + 3", "x(0)", "2"), // resonance, complex
        ("x''' - x' = t", "x(0)", "1"),        // root 0: polynomial resonance
    ];
    for (eq, _, x0) in cases {
        let order = if eq.contains("x'''") { 3 } else { 2 };
        let mut ics = vec![("x", x0), ("x'", "0")];
        if order == 3 {
            ics.push(("x''", "1"));
        }
        let mut p = problem(&[eq], &ics, &[]);
        let cf = solve(&mut p).unwrap_or_else(|e| panic!("{eq}: {e}"));
        assert_eq!(cf.method, Method::Exact, "{eq}");
        let x = cf.unique().unwrap()[0];
        assert_satisfies(&mut p, &[x], &[]);
    }
    // Products and powers of sines and cosines are rewritten as sums.
    for eq in [
        "x'' + x = sin(t)*cos(t)",
        "x'' + 4*x = cos(t)^2",
        "x'' + x' + x = sin(3*t)*sin(t)*exp(-t)",
    ] {
        let mut p = problem(&[eq], &[("x", "1"), ("x'", "0")], &[]);
        let cf = solve(&mut p).unwrap_or_else(|e| panic!("{eq}: {e}"));
        let x = cf.unique().unwrap()[0];
        assert_satisfies(&mut p, &[x], &[]);
    }
    // The resonant response grows like t: x = (sin 2t - 2t cos 2t)/8.
    let mut p = problem(&["x'' + 4*x = sin(2*t)"], &[("x", "0"), ("x'", "0")], &[]);
    let x = solve(&mut p).unwrap().cases[0].solution[0];
    assert_same(&mut p.pool, x, "(sin(2*t) - 2*t*cos(2*t))/8", &[]);
}

#[test]
fn symbolic_forcing_with_symbolic_frequency() {
    let mut p = problem(
        &["m*x'' + k*x = F*cos(Omega*t)"],
        &[("x", "0"), ("x'", "0")],
        &["m", "k"],
    );
    let cf = solve(&mut p).unwrap();
    let x = cf.unique().unwrap()[0];
    let params = [("m", 1.5), ("k", 6.0), ("F", 2.0), ("Omega", 1.3)];
    assert_satisfies(&mut p, &[x], &params);
    assert_same(
        &mut p.pool,
        x,
        "F/(k - m*Omega^2)*(cos(Omega*t) - cos(sqrt(k/m)*t))",
        &params,
    );
}

#[test]
fn missing_initial_conditions_leave_constants() {
    let mut p = problem(&["x'' + 4*x = 0"], &[], &[]);
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.cases[0].constants.len(), 2);
    let text = p.pool.to_text(cf.cases[0].solution[0]);
    assert!(text.contains("C1") && text.contains("C2"), "{text}");
}

#[test]
fn third_order_with_irrational_roots_goes_numeric() {
    // λ^3 + λ + 1 has one real and two complex roots, none rational.
    let mut p = problem(
        &["x''' + x' + x = 1"],
        &[("x", "0"), ("x'", "1"), ("x''", "0")],
        &[],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Numeric);
    let x = cf.cases[0].solution[0];
    assert_satisfies(&mut p, &[x], &[]);
}

/// RK4 on `M q'' + K q = 0` (and the state's first-order form) for the comparison.
fn rk4(f: &dyn Fn(f64, &[f64]) -> Vec<f64>, y0: &[f64], t0: f64, span: f64, h: f64) -> Vec<f64> {
    let mut y = y0.to_vec();
    let n = (span / h).round() as usize;
    let mut t = t0;
    for _ in 0..n {
        let k1 = f(t, &y);
        let y2: Vec<f64> = y.iter().zip(&k1).map(|(a, b)| a + 0.5 * h * b).collect();
        let k2 = f(t + 0.5 * h, &y2);
        let y3: Vec<f64> = y.iter().zip(&k2).map(|(a, b)| a + 0.5 * h * b).collect();
        let k3 = f(t + 0.5 * h, &y3);
        let y4: Vec<f64> = y.iter().zip(&k3).map(|(a, b)| a + h * b).collect();
        let k4 = f(t + h, &y4);
        for i in 0..y.len() {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        t += h;
    }
    y
}

#[test]
fn two_storey_building_agrees_with_rk4() {
    // Floors of mass m1, m2 on columns of stiffness k1, k2, damping c, ground shaking
    // A sin(w t): m1 x1'' = -k1 (x1 - u) - k2 (x1 - x2) - c x1',  m2 x2'' = -k2 (x2 - x1).
    let eqs = [
        "2000*x1'' = -4e5*(x1 - 0.01*sin(5*t)) - 3e5*(x1 - x2) - 800*x1'",
        "1500*x2'' = -3e5*(x2 - x1)",
    ];
    let mut p = problem(
        &eqs,
        &[("x1", "0.02"), ("x1'", "0"), ("x2", "0"), ("x2'", "0.1")],
        &[],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Numeric);
    assert!(cf.residual.unwrap() < 1e-9);
    let sol = cf.unique().unwrap().to_vec();
    assert_satisfies(&mut p, &sol, &[]);
    let prog = cf.compile(&mut p.pool, 0, &[]).unwrap();
    let mut ws = prog.workspace();
    let mut out = vec![0.0; 4];
    let rhs = |t: f64, y: &[f64]| {
        let u = 0.01 * libm::sin(5.0 * t);
        vec![
            y[1],
            (-4e5 * (y[0] - u) - 3e5 * (y[0] - y[2]) - 800.0 * y[1]) / 2000.0,
            y[3],
            -3e5 * (y[2] - y[0]) / 1500.0,
        ]
    };
    let mut y = vec![0.02, 0.0, 0.0, 0.1];
    let mut t = 0.0;
    for _ in 0..4 {
        y = rk4(&rhs, &y, t, 0.5, 1e-4);
        t += 0.5;
        prog.eval(&[t], &mut ws, &mut out);
        for i in 0..4 {
            assert!(
                (out[i] - y[i]).abs() < 1e-6 * (1.0 + y[i].abs()),
                "t={t} component {i}: exact {} vs RK4 {}",
                out[i],
                y[i]
            );
        }
    }
}

#[test]
fn six_dof_chain_satisfies_its_equations() {
    let n = 6;
    let mut eqs = Vec::new();
    for i in 1..=n {
        let left = if i == 1 {
            format!("-{}*q{i}", 100)
        } else {
            format!("-100*(q{i} - q{})", i - 1)
        };
        let right = if i == n {
            String::new()
        } else {
            format!(" - 100*(q{i} - q{})", i + 1)
        };
        eqs.push(format!("{}*q{i}'' = {left}{right}", i));
    }
    let eq_refs: Vec<&str> = eqs.iter().map(String::as_str).collect();
    let names: Vec<String> = (1..=n)
        .flat_map(|i| [format!("q{i}"), format!("q{i}'")])
        .collect();
    let ics: Vec<(&str, &str)> = names
        .iter()
        .enumerate()
        .map(|(k, s)| (s.as_str(), if k == 0 { "0.1" } else { "0" }))
        .collect();
    let mut p = problem(&eq_refs, &ics, &[]);
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.cases[0].roots.len(), 6, "{:?}", cf.cases[0].roots);
    let sol = cf.unique().unwrap().to_vec();
    assert_satisfies(&mut p, &sol, &[]);
}

#[test]
fn nonlinear_and_variable_coefficients_are_refused_with_advice() {
    for (eq, ic) in [
        ("x'' + sin(x) = 0", vec![("x", "1"), ("x'", "0")]),
        ("x'' + t*x = 0", vec![("x", "1"), ("x'", "0")]),
        ("x'' + x*x' + x = 0", vec![("x", "1"), ("x'", "0")]),
        ("x'' + x = 1/t", vec![("x", "1"), ("x'", "0")]),
        ("x'' + k*x''' + x = 0", vec![]),
    ] {
        let mut p = problem(&[eq], &ic, &[]);
        let err = solve(&mut p).unwrap_err();
        assert!(matches!(err, DsolveError::NoClosedForm(_)), "{eq}: {err:?}");
        assert!(err.to_string().contains("pdyn run"), "{err}");
    }
}

#[test]
fn inconsistent_input_is_reported() {
    let mut p = problem(&["x'' + x = 0"], &[("x", "1")], &[]);
    let err = solve(&mut p).unwrap_err();
    assert!(err.to_string().contains("initial condition"), "{err}");
    let mut p = problem(&["x'' + y' = 0"], &[], &[]);
    assert!(solve(&mut p).is_err());
}

#[test]
fn numeric_path_repeated_and_defective_roots() {
    // (λ² + 1)² : double complex pair, t cos t and t sin t terms.
    let mut p = problem(
        &["x'''' + 2*x'' + x = 0"],
        &[("x", "1"), ("x'", "0"), ("x''", "0"), ("x'''", "1")],
        &[],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Numeric);
    let x = cf.cases[0].solution[0];
    assert!(p.pool.to_text(x).contains("t*"), "{}", p.pool.to_text(x));
    assert_satisfies(&mut p, &[x], &[]);
    // A defective first-order system (critical damping): double root -1, one eigenvector.
    let mut p = problem(&["x' = y", "y' = -x - 2*y"], &[("x", "1"), ("y", "0")], &[]);
    let cf = solve(&mut p).unwrap();
    let sol = cf.unique().unwrap().to_vec();
    assert_satisfies(&mut p, &sol, &[]);
    assert_same(&mut p.pool, sol[0], "(1 + t)*exp(-t)", &[]);
    // Resonant forcing in the numeric path.
    let mut p = problem(
        &["x' = y", "y' = -x + cos(t)"],
        &[("x", "0"), ("y", "0")],
        &[],
    );
    let cf = solve(&mut p).unwrap();
    let sol = cf.unique().unwrap().to_vec();
    assert_satisfies(&mut p, &sol, &[]);
    assert_same(&mut p.pool, sol[0], "t*sin(t)/2", &[]);
}

#[test]
fn bounded_time_on_large_inputs() {
    let start = std::time::Instant::now();
    // 12th-order numeric equation with polynomial-exponential-trig forcing.
    let mut p = problem(
        &["x'''''''''''' + 3*x'''''' + x = t^3*exp(-t)*cos(3*t) + t^5"],
        &[],
        &[],
    );
    let _ = solve(&mut p);
    // Symbolic 4th order that does not factor: refused quickly.
    let mut p = problem(&["x'''' + a*x''' + b*x'' + c*x' + d*x = 0"], &[], &[]);
    assert!(matches!(solve(&mut p), Err(DsolveError::NoClosedForm(_))));
    assert!(
        start.elapsed().as_secs_f64() < 20.0,
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn small_symbolic_systems_by_elimination() {
    // First-order form of the damped oscillator: the three cases, each satisfying the system.
    let mut p = problem(
        &["x' = v", "m*v' = -k*x - c*v"],
        &[("x", "x0"), ("v", "0")],
        &["m", "k", "c"],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Exact);
    assert_eq!(cf.cases.len(), 3);
    for (case, c) in cf.cases.clone().iter().zip([1.0, 4.0, 6.0]) {
        // c^2 - 4 k m with k = 2, m = 2: 1 - 16 < 0, 16 - 16 = 0, 36 - 16 > 0.
        let params = [("m", 2.0), ("k", 2.0), ("c", c), ("x0", 0.3)];
        assert_satisfies(&mut p, &case.solution, &params);
    }
    // Two free masses joined by a spring: rigid drift plus vibration.
    let mut p = problem(
        &["m*x1'' = k*(x2 - x1)", "m*x2'' = k*(x1 - x2) + F*sin(w*t)"],
        &[("x1", "0"), ("x1'", "V"), ("x2", "0"), ("x2'", "0")],
        &["m", "k"],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Exact);
    let sol = cf.unique().unwrap().to_vec();
    let params = [("m", 1.5), ("k", 20.0), ("V", 0.7), ("F", 2.0), ("w", 1.9)];
    assert_satisfies(&mut p, &sol, &params);
}

#[test]
fn undamped_two_dof_symbolic_normal_modes() {
    // Symmetric chain: modes sqrt(k/m) and sqrt(3k/m), exactly.
    let mut p = problem(
        &["m*x1'' = -2*k*x1 + k*x2", "m*x2'' = k*x1 - 2*k*x2"],
        &[("x1", "a"), ("x1'", "0"), ("x2", "0"), ("x2'", "0")],
        &["m", "k"],
    );
    let cf = solve(&mut p).unwrap();
    let sol = cf.unique().unwrap().to_vec();
    assert_same(
        &mut p.pool,
        sol[0],
        "a/2*(cos(sqrt(k/m)*t) + cos(sqrt(3*k/m)*t))",
        &[("m", 1.3), ("k", 7.0), ("a", 0.2)],
    );
    assert_satisfies(&mut p, &sol, &[("m", 1.3), ("k", 7.0), ("a", 0.2)]);
    // The 2-storey building with symbolic masses and stiffnesses: the physical case (distinct
    // real frequencies) satisfies the equations; forcing included.
    let mut p = problem(
        &[
            "m1*x1'' = -k1*x1 - k2*(x1 - x2) + F*cos(w*t)",
            "m2*x2'' = -k2*(x2 - x1)",
        ],
        &[("x1", "a"), ("x1'", "0"), ("x2", "0"), ("x2'", "b")],
        &["m1", "m2", "k1", "k2"],
    );
    let cf = solve(&mut p).unwrap();
    assert_eq!(cf.method, Method::Exact);
    let physical = cf
        .cases
        .iter()
        .find(|c| c.condition.map(|k| k.relation) == Some(Relation::Positive))
        .expect("distinct-frequency case")
        .solution
        .clone();
    let params = [
        ("m1", 2.0),
        ("m2", 1.5),
        ("k1", 40.0),
        ("k2", 30.0),
        ("F", 3.0),
        ("w", 2.2),
        ("a", 0.1),
        ("b", -0.4),
    ];
    assert_satisfies(&mut p, &physical, &params);
}
