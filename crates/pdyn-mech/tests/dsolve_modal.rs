//! Closed forms of many-degree-of-freedom linear systems by modes (`dsolve/modal.rs`): spring
//! chains up to 50 masses, equations written as accelerations, a damped shear building under
//! base shaking. Each solution is checked against its own equations (substituted and
//! differentiated symbolically, evaluated at several instants) and its initial conditions: by
//! uniqueness, that is the solution.

use pdyn_expr::{Id, Node, Pool, Program, SymId};
use pdyn_mech::dsolve::{solve_system, ClosedForm, Method};

struct Problem {
    pool: Pool,
    eqs: Vec<Id>,
    coords: Vec<SymId>,
    ics: Vec<(Id, Id)>,
}

/// Coordinates `q1..qn`, equations as text, `q1(0) = q1_0` and everything else at rest.
fn problem(eqs: &[String], q1_0: f64) -> Problem {
    let mut pool = Pool::new();
    let n = eqs.len();
    let coords: Vec<SymId> = (1..=n)
        .map(|i| pool.symbol(&format!("q{i}"), false))
        .collect();
    let mut scope = pdyn_expr::FreeScope::with_coordinates(
        (1..=n)
            .map(|i| format!("q{i}"))
            .collect::<Vec<_>>()
            .iter()
            .map(String::as_str),
    );
    let eqs: Vec<Id> = eqs
        .iter()
        .map(|e| match pool.parse_equation_in(e, &mut scope).unwrap() {
            pdyn_expr::Value::Scalar(s) => s,
            v => panic!("{v:?}"),
        })
        .collect();
    let mut ics = Vec::new();
    for (j, &c) in coords.iter().enumerate() {
        let v = if j == 0 { q1_0 } else { 0.0 };
        let value = pool.num(pdyn_expr::Number::Float(v));
        ics.push((pool.coord(c, 0), value));
        ics.push((pool.coord(c, 1), Pool::ZERO));
    }
    Problem {
        pool,
        eqs,
        coords,
        ics,
    }
}

fn eval(pool: &mut Pool, e: Id, t: f64) -> f64 {
    let t_leaf = pool.time();
    let prog = Program::compile(pool, &[t_leaf], &[e]).unwrap();
    let mut ws = prog.workspace();
    let mut out = [0.0];
    prog.eval(&[t], &mut ws, &mut out);
    out[0]
}

/// Every equation's residual, relative to `scale`, at several instants, and the initial
/// conditions.
fn assert_solves(p: &mut Problem, cf: &ClosedForm, scale: f64) {
    let sol = cf.unique().unwrap().to_vec();
    let pool = &mut p.pool;
    for &eq in &p.eqs {
        let mut e = eq;
        for (j, &c) in p.coords.iter().enumerate() {
            for k in (0..=2u8).rev() {
                let leaf = pool.coord(c, k);
                if pool.contains(e, leaf) {
                    let d = pool.dt_n(sol[j], k as usize);
                    e = pool.subs1(e, leaf, d);
                }
            }
        }
        for t in [0.0, 0.37, 1.1, 2.9] {
            let r = eval(pool, e, t);
            assert!(r.abs() <= 1e-9 * scale, "residual {r} at t = {t}");
        }
    }
    for &(lhs, val) in &p.ics {
        let Node::Coord(s, k) = *pool.node(lhs) else {
            panic!()
        };
        let j = p.coords.iter().position(|&c| c == s).unwrap();
        let d = pool.dt_n(sol[j], k as usize);
        let (got, want) = (eval(pool, d, 0.0), eval(pool, val, 0.0));
        assert!((got - want).abs() <= 1e-10, "IC: {got} vs {want}");
    }
}

/// `m_i q_i'' = -k (q_i - q_{i-1}) - k (q_i - q_{i+1})`, fixed at the left, free at the right.
fn chain(n: usize, k: f64, mass: impl Fn(usize) -> f64, as_accelerations: bool) -> Vec<String> {
    (1..=n)
        .map(|i| {
            let left = if i == 1 {
                format!("-{k}*q1")
            } else {
                format!("-{k}*(q{i} - q{})", i - 1)
            };
            let right = if i == n {
                String::new()
            } else {
                format!(" - {k}*(q{i} - q{})", i + 1)
            };
            if as_accelerations {
                format!("q{i}'' = ({left}{right})/{}", mass(i))
            } else {
                format!("{}*q{i}'' = {left}{right}", mass(i))
            }
        })
        .collect()
}

#[test]
fn a_fifty_mass_chain_is_solved_by_modes() {
    let eqs = chain(50, 1000.0, |i| 1.0 + i as f64 / 10.0, false);
    let mut p = problem(&eqs, 0.1);
    let cf = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics).unwrap();
    assert_eq!(cf.method, Method::Numeric);
    assert_eq!(cf.cases[0].roots.len(), 50);
    assert!(cf.residual.unwrap() < 1e-10, "{:?}", cf.residual);
    // Forces are k·q ~ 1000 × 0.1.
    assert_solves(&mut p, &cf, 1000.0 * 0.1);
}

#[test]
fn chains_written_as_accelerations_are_symmetrised() {
    // K/m is not symmetric; scaling each equation by its mass makes it so.
    let eqs = chain(12, 10_000.0, |i| [1.0, 2.5, 0.5][i % 3], true);
    let mut p = problem(&eqs, 0.01);
    let cf = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics).unwrap();
    assert_eq!(cf.cases[0].roots.len(), 12);
    assert_solves(&mut p, &cf, 10_000.0 * 0.01 / 0.5);
}

#[test]
fn a_ten_storey_building_with_rayleigh_damping_under_base_shaking() {
    // m q_i'' + C q' + K q = -m a_g sin(Ω t), C = 0.2 M + 0.002 K (classical damping).
    let (n, m, k, alpha, beta) = (10, 2.0e4, 3.0e7, 0.2, 0.002);
    let eqs: Vec<String> = (1..=n)
        .map(|i| {
            let mut kq = vec![format!("{}*q{i}", if i == n { k } else { 2.0 * k })];
            let mut cq = vec![format!(
                "{}*q{i}'",
                alpha * m + beta * if i == n { k } else { 2.0 * k }
            )];
            for j in [i - 1, i + 1] {
                if j >= 1 && j <= n {
                    kq.push(format!("-{k}*q{j}"));
                    cq.push(format!("-{}*q{j}'", beta * k));
                }
            }
            format!(
                "{m}*q{i}'' + {} + {} = -{m}*2*sin(9*t)",
                cq.join(" + "),
                kq.join(" + ")
            )
        })
        .collect();
    let mut p = problem(&eqs, 0.0);
    let cf = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics).unwrap();
    assert_eq!(cf.cases[0].roots.len(), n);
    assert_solves(&mut p, &cf, m * 2.0);
}

#[test]
fn stiff_chains_no_longer_look_singular() {
    // The characteristic polynomial of a 10-mass chain with k = 1e4 spans (k/m)^10 = 1e40.
    let eqs = chain(10, 1.0e4, |_| 1.0, false);
    let mut p = problem(&eqs, 0.1);
    let cf = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics).unwrap();
    assert_solves(&mut p, &cf, 1.0e4 * 0.1);
}

#[test]
fn non_classical_damping_falls_back_to_the_general_solver() {
    // One dashpot on the first mass only: Φᵀ C Φ is not diagonal.
    let eqs = vec![
        "q1'' + 0.5*q1' + 2*q1 - q2 = 0".to_string(),
        "q2'' - q1 + 2*q2 - q3 = 0".to_string(),
        "q3'' - q2 + q3 = 0".to_string(),
    ];
    let mut p = problem(&eqs, 1.0);
    let cf = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics).unwrap();
    assert_solves(&mut p, &cf, 2.0);
}

#[test]
fn resonance_and_repeated_frequencies() {
    // Two identical, separate two-mass systems (eigenvalues 1, 1, 3, 3: repeated modes) with
    // the first driven at its lowest natural frequency: the response grows like t sin t.
    let eqs = vec![
        "q1'' + 2*q1 - q2 = sin(t)".to_string(),
        "q2'' - q1 + 2*q2 = 0".to_string(),
        "q3'' + 2*q3 - q4 = 0".to_string(),
        "q4'' - q3 + 2*q4 = 0".to_string(),
    ];
    let mut p = problem(&eqs, 0.2);
    let cf = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics).unwrap();
    assert_eq!(cf.cases[0].roots.len(), 4);
    let q1 = cf.unique().unwrap()[0];
    assert!(p.pool.to_text(q1).contains("t*"), "{}", p.pool.to_text(q1));
    assert_solves(&mut p, &cf, 3.0);
}

#[test]
fn a_badly_scaled_system_is_refused_not_answered_wrongly() {
    // A mass of 1e300 beside masses of 1: the eigenvectors' small components are lost to
    // round-off, so the modes would drop the coupling to x2 (x2 = 0 at every t, silently).
    // The row-by-row residual of K Φ = M Φ Λ catches it.
    let eqs = vec![
        "1e300*q1'' + 2e300*q1 - q2 = 0".to_string(),
        "q2'' - q1 + 2*q2 - q3 = 0".to_string(),
        "q3'' - q2 + 2*q3 - q4 = 0".to_string(),
        "q4'' - q3 + q4 = 0".to_string(),
    ];
    let mut p = problem(&eqs, 1.0);
    let r = solve_system(&mut p.pool, &p.eqs, &p.coords, &p.ics);
    assert!(r.is_err(), "{:?}", r.map(|cf| cf.residual));
}
