//! `dsolve` on the chapter's cases and a 6-DOF spring–mass chain: median wall time per solve
//! (parsing included, fresh pool each time), and each solution evaluated at t = 1.3 with fixed
//! parameter values so that `bench/sympy_dsolve.py` can check SymPy's answers against ours.
//!
//! Output: one JSON object per line, `{"case", "seconds", "values"}`.
//! Run: `cargo bench -p pdyn-mech --bench dsolve` (or through `bench/sympy_dsolve.py`).

use pdyn_expr::{FreeScope, Id, Pool, Program, SymId, Value};
use pdyn_mech::dsolve::solve_system;
use std::time::Instant;

/// Parameter values used for the cross-check (shared with the Python script).
const PARAMS: [(&str, f64); 14] = [
    ("m", 2.0),
    ("k", 50.0),
    ("L0", 0.4),
    ("g", 9.81),
    ("L", 0.3),
    ("mu", 0.3),
    ("omega", 2.0),
    ("V", 1.5),
    ("alpha", std::f64::consts::FRAC_PI_4),
    ("h", 71.0),
    ("zeta", 0.3),
    ("wn", 3.0),
    ("x0", 0.5),
    ("v0", -1.0),
];

struct Case {
    name: &'static str,
    eqs: Vec<String>,
    ics: Vec<(String, String)>,
    positive: Vec<&'static str>,
}

fn case(name: &'static str, eqs: &[&str], ics: &[(&str, &str)], positive: &[&'static str]) -> Case {
    Case {
        name,
        eqs: eqs.iter().map(|s| s.to_string()).collect(),
        ics: ics
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect(),
        positive: positive.to_vec(),
    }
}

fn chain(n: usize) -> Case {
    let mut eqs = Vec::new();
    let mut ics = Vec::new();
    for i in 1..=n {
        let left = if i == 1 {
            format!("-100*q{i}")
        } else {
            format!("-100*(q{i} - q{})", i - 1)
        };
        let right = if i == n {
            String::new()
        } else {
            format!(" - 100*(q{i} - q{})", i + 1)
        };
        eqs.push(format!("{i}*q{i}'' = {left}{right}"));
        ics.push((
            format!("q{i}"),
            if i == 1 { "1/10" } else { "0" }.to_string(),
        ));
        ics.push((format!("q{i}'"), "0".to_string()));
    }
    Case {
        name: "chain6",
        eqs,
        ics,
        positive: Vec::new(),
    }
}

fn cases() -> Vec<Case> {
    vec![
        case(
            "suspension",
            &["m*x'' = -k*(x - L0) - m*g"],
            &[("x", "L"), ("x'", "0")],
            &["m", "k"],
        ),
        case(
            "rotating_rod",
            &["r'' + 2*mu*omega*r' - omega^2*r = 0"],
            &[("r", "0"), ("r'", "V")],
            &["mu", "omega"],
        ),
        case(
            "projectile",
            &["x'' = 0", "y'' = -g"],
            &[
                ("x", "0"),
                ("x'", "V*cos(alpha)"),
                ("y", "h"),
                ("y'", "V*sin(alpha)"),
            ],
            &["g"],
        ),
        case(
            "damped_symbolic",
            &["x'' + 2*zeta*wn*x' + wn^2*x = 0"],
            &[("x", "x0"), ("x'", "v0")],
            &["zeta", "wn"],
        ),
        case(
            "damped_under",
            &["x'' + 2*(1/10)*3*x' + 9*x = 0"],
            &[("x", "1"), ("x'", "0")],
            &[],
        ),
        case(
            "damped_critical",
            &["x'' + 6*x' + 9*x = 0"],
            &[("x", "1"), ("x'", "0")],
            &[],
        ),
        case(
            "damped_over",
            &["x'' + 12*x' + 9*x = 0"],
            &[("x", "1"), ("x'", "0")],
            &[],
        ),
        case(
            "resonance",
            &["x'' + 4*x = sin(2*t)"],
            &[("x", "0"), ("x'", "0")],
            &[],
        ),
        case(
            "building2",
            &[
                "2000*x1'' = -400000*(x1 - sin(5*t)/100) - 300000*(x1 - x2) - 800*x1'",
                "1500*x2'' = -300000*(x2 - x1)",
            ],
            &[("x1", "1/50"), ("x1'", "0"), ("x2", "0"), ("x2'", "1/10")],
            &[],
        ),
        chain(6),
    ]
}

fn solve(c: &Case) -> (Pool, Vec<Id>) {
    let mut pool = Pool::new();
    let mut scope = FreeScope {
        positive: c.positive.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    for e in &c.eqs {
        let (l, r) = pdyn_expr::syntax::parse_equation(e).expect("parse");
        scope.learn(&l);
        if let Some(r) = &r {
            scope.learn(r);
        }
    }
    let mut names: Vec<String> = scope.coordinates.iter().cloned().collect();
    names.sort();
    let coords: Vec<SymId> = names.iter().map(|n| pool.symbol(n, false)).collect();
    let scalar = |v: Value| match v {
        Value::Scalar(s) => s,
        Value::Vector(_) => panic!("vector"),
    };
    let eqs: Vec<Id> = c
        .eqs
        .iter()
        .map(|e| {
            let v = pool.parse_equation_in(e, &mut scope).expect("lower");
            scalar(v)
        })
        .collect();
    let ics: Vec<(Id, Id)> = c
        .ics
        .iter()
        .map(|(l, v)| {
            let l = pool.parse_in(l, &mut scope).expect("ic");
            let v = pool.parse_in(v, &mut scope).expect("ic");
            (scalar(l), scalar(v))
        })
        .collect();
    let cf = solve_system(&mut pool, &eqs, &coords, &ics).expect("solve");
    let sol = cf.cases[0].solution.clone();
    (pool, sol)
}

fn values_at(pool: &mut Pool, sol: &[Id], t: f64) -> Vec<f64> {
    let mut inputs = vec![pool.time()];
    let mut vals = vec![t];
    for (n, v) in PARAMS {
        inputs.push(pool.var(n));
        vals.push(v);
    }
    let prog = Program::compile(pool, &inputs, sol).expect("compile");
    let mut ws = prog.workspace();
    let mut out = vec![0.0; sol.len()];
    prog.eval(&vals, &mut ws, &mut out);
    out
}

fn main() {
    let quick = std::env::args().any(|a| a == "--test");
    for c in cases() {
        let mut times = Vec::new();
        let start = Instant::now();
        while times.len() < 5 || (start.elapsed().as_secs_f64() < 0.5 && times.len() < 200) {
            let t0 = Instant::now();
            let r = solve(&c);
            times.push(t0.elapsed().as_secs_f64());
            drop(r);
            if quick {
                break;
            }
        }
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        let (mut pool, sol) = solve(&c);
        let vals = values_at(&mut pool, &sol, 1.3);
        println!(
            "{{\"case\": \"{}\", \"seconds\": {median:e}, \"values\": [{}]}}",
            c.name,
            vals.iter()
                .map(|v| format!("{v:e}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}
