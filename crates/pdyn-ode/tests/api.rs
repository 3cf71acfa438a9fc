//! Public API behaviour: method listing, bad input gives typed errors (no panics), numerical
//! failures carry the time, the state and the partial solution.
use pdyn_ode::{
    solve, solve_second_order, FnSecondOrder, FnSystem, Method, OdeError, Options, Tolerance,
};

#[test]
fn methods_are_listed_with_docs_and_names_round_trip() {
    assert!(Method::all().len() >= 12);
    for &m in Method::all() {
        assert!(m.doc().len() > 40, "{m}");
        assert_eq!(Method::from_name(m.name()), Some(m));
        assert_eq!(Method::from_name(&m.name().to_uppercase()), Some(m));
    }
    assert_eq!(Method::from_name("ode45"), Some(Method::Dopri5));
    assert_eq!(Method::from_name("nope"), None);
}

fn decay() -> impl pdyn_ode::OdeSystem {
    FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
        f[0] = -y[0];
        f[1] = -2.0 * y[1];
    })
}

fn is_invalid(r: Result<pdyn_ode::Solution, OdeError>) -> bool {
    matches!(r, Err(OdeError::InvalidInput { .. }))
}

#[test]
fn bad_input_is_a_typed_error() {
    let o = Options::default();
    assert!(is_invalid(solve(
        Method::Dopri5,
        &decay(),
        (0.0, 1.0),
        &[1.0],
        &o
    )));
    assert!(is_invalid(solve(
        Method::Dopri5,
        &decay(),
        (0.0, 1.0),
        &[f64::NAN, 1.0],
        &o
    )));
    assert!(is_invalid(solve(
        Method::Dopri5,
        &decay(),
        (0.0, f64::INFINITY),
        &[1.0, 1.0],
        &o
    )));
    let neg = Options {
        rtol: (-1.0).into(),
        ..Default::default()
    };
    assert!(is_invalid(solve(
        Method::Dopri5,
        &decay(),
        (0.0, 1.0),
        &[1.0, 1.0],
        &neg
    )));
    let wrong_len = Options {
        atol: Tolerance::PerComponent(vec![1e-9; 3]),
        ..Default::default()
    };
    assert!(is_invalid(solve(
        Method::Dop853,
        &decay(),
        (0.0, 1.0),
        &[1.0, 1.0],
        &wrong_len
    )));
    let unsorted = Options {
        t_eval: Some(vec![0.5, 0.2]),
        ..Default::default()
    };
    assert!(is_invalid(solve(
        Method::Tsit5,
        &decay(),
        (0.0, 1.0),
        &[1.0, 1.0],
        &unsorted
    )));
    let outside = Options {
        t_eval: Some(vec![2.0]),
        ..Default::default()
    };
    assert!(is_invalid(solve(
        Method::Radau5,
        &decay(),
        (0.0, 1.0),
        &[1.0, 1.0],
        &outside
    )));
    // fixed-step methods need h0
    assert!(is_invalid(solve(
        Method::Rk4,
        &decay(),
        (0.0, 1.0),
        &[1.0, 1.0],
        &o
    )));
    // symplectic compositions need a second-order separable system
    assert!(is_invalid(solve(
        Method::VelocityVerlet,
        &decay(),
        (0.0, 1.0),
        &[1.0, 1.0],
        &o
    )));
    let damped = FnSecondOrder::new(1, false, |_t, q: &[f64], v: &[f64], a: &mut [f64]| {
        a[0] = -q[0] - 0.1 * v[0]
    });
    let fixed = Options {
        h0: Some(0.01),
        ..Default::default()
    };
    let r = solve_second_order(
        Method::Yoshida4,
        &damped,
        (0.0, 1.0),
        &[1.0],
        &[0.0],
        &fixed,
    );
    assert!(is_invalid(r));
    // … but Gauss–Legendre handles non-separable problems
    let r = solve_second_order(Method::Gauss4, &damped, (0.0, 1.0), &[1.0], &[0.0], &fixed);
    assert!(r.is_ok());
}

#[test]
fn max_steps_error_carries_partial_solution() {
    let o = Options {
        max_steps: 5,
        ..Options::with_tol(1e-12)
    };
    let r = solve(Method::Dopri5, &decay(), (0.0, 10.0), &[1.0, 1.0], &o);
    let Err(OdeError::MaxSteps { max_steps, at }) = r else {
        panic!("expected MaxSteps, got {r:?}");
    };
    assert_eq!(max_steps, 5);
    assert!(at.t > 0.0 && at.t < 10.0);
    assert_eq!(at.partial.t.last(), Some(&at.t));
    assert_eq!(at.partial.y_at(at.partial.len() - 1), &at.y[..]);
    assert_eq!(at.partial.stats.steps, 5);
}

#[test]
fn blow_up_gives_step_size_underflow_at_the_singularity() {
    // y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
    let sys = FnSystem::new(1, |_t, y: &[f64], f: &mut [f64]| f[0] = y[0] * y[0]);
    for m in [Method::Dopri5, Method::Dop853, Method::Radau5] {
        let r = solve(m, &sys, (0.0, 2.0), &[1.0], &Options::default());
        let at = match &r {
            Err(OdeError::StepSizeUnderflow { at, .. })
            | Err(OdeError::NonFinite { at })
            | Err(OdeError::MaxSteps { at, .. }) => at,
            other => panic!("{m}: expected a numerical failure, got {other:?}"),
        };
        assert!((at.t - 1.0).abs() < 1e-3, "{m}: failed at t = {}", at.t);
        assert!(!at.partial.is_empty());
        // Display is a one-line message
        let msg = r.unwrap_err().to_string();
        assert!(msg.contains("t ="), "{msg}");
    }
}

#[test]
fn nonfinite_rhs_is_reported() {
    let sys = FnSystem::new(1, |t, _y: &[f64], f: &mut [f64]| {
        f[0] = if t > 0.5 { f64::NAN } else { 1.0 }
    });
    let r = solve(
        Method::Dopri5,
        &sys,
        (0.0, 1.0),
        &[0.0],
        &Options::default(),
    );
    match r {
        Err(OdeError::NonFinite { at }) | Err(OdeError::StepSizeUnderflow { at, .. }) => {
            assert!(at.t <= 0.5 + 1e-9 && at.t > 0.4, "t = {}", at.t)
        }
        other => panic!("{other:?}"),
    }
    let fixed = Options {
        h0: Some(0.1),
        ..Default::default()
    };
    let r = solve(Method::Rk4, &sys, (0.0, 1.0), &[0.0], &fixed);
    assert!(matches!(r, Err(OdeError::NonFinite { .. })), "{r:?}");
}

#[test]
fn zero_length_interval_returns_initial_point() {
    for m in [Method::Dopri5, Method::Radau5] {
        let sol = solve(m, &decay(), (1.0, 1.0), &[1.0, 2.0], &Options::default()).unwrap();
        assert_eq!(sol.t, vec![1.0]);
        assert_eq!(sol.y, vec![1.0, 2.0]);
    }
}

#[test]
fn empty_system_is_invalid() {
    let sys = FnSystem::new(0, |_t, _y: &[f64], _f: &mut [f64]| {});
    let r = solve(Method::Dopri5, &sys, (0.0, 1.0), &[], &Options::default());
    assert!(is_invalid(r));
}

#[test]
fn an_interrupt_stops_every_kind_of_method_at_its_next_step_with_the_partial_solution() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::Arc;
    // The flag is raised by the right-hand side itself after 200 evaluations, as another
    // thread would raise it: the solve must stop at the next step attempt, not at t = 1e6.
    for m in [
        Method::Dopri5,
        Method::Dop853,
        Method::Tsit5,
        Method::Radau5,
        Method::Rk4,
    ] {
        let flag = Arc::new(AtomicBool::new(false));
        let calls = AtomicUsize::new(0);
        let sys = FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
            if calls.fetch_add(1, Ordering::Relaxed) == 200 {
                flag.store(true, Ordering::Relaxed);
            }
            f[0] = y[1];
            f[1] = -y[0];
        });
        let opts = Options {
            interrupt: Some(flag.clone()),
            h0: Some(1e-2),
            max_steps: usize::MAX,
            ..Options::default()
        };
        let r = solve(m, &sys, (0.0, 1e6), &[1.0, 0.0], &opts);
        let Err(OdeError::Interrupted { at }) = &r else {
            panic!("{m}: expected Interrupted, got {:?}", r.map(|s| s.t.len()));
        };
        assert!(at.t > 0.0 && at.t < 1e3, "{m}: stopped at t = {}", at.t);
        assert!(!at.partial.is_empty(), "{m}");
        // Few evaluations after the flag: one step's worth (Radau's Newton iterations).
        let after = calls.load(Ordering::Relaxed) - 201;
        assert!(after < 40, "{m}: {after} evaluations after the interrupt");
        assert!(r.unwrap_err().to_string().contains("interrupted at t ="));
    }
}
