//! `Options::dense_output`: every step's own interpolant, against closed forms.

use pdyn_ode::{solve, solve_with_events, Event, FnSystem, Method, Options, Status};

fn osc() -> FnSystem<impl Fn(f64, &[f64], &mut [f64])> {
    FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
        f[0] = y[1];
        f[1] = -y[0];
    })
}

/// Largest error of the dense output against (cos t, −sin t) on a fine grid of [0, 20].
fn dense_error(method: Method, rtol: f64) -> (f64, usize) {
    let opts = Options {
        dense_output: true,
        ..Options::with_tol(rtol)
    };
    let sol = solve(method, &osc(), (0.0, 20.0), &[1.0, 0.0], &opts).unwrap();
    let d = sol.dense.as_ref().unwrap();
    assert_eq!(d.steps().len(), sol.len(), "{method}: one piece per step");
    let mut out = [0.0; 2];
    let mut worst: f64 = 0.0;
    for k in 0..=4000 {
        let t = k as f64 * 0.005;
        d.eval(t, &mut out);
        worst = worst.max(
            (out[0] - libm::cos(t))
                .abs()
                .max((out[1] + libm::sin(t)).abs()),
        );
    }
    (worst, sol.len())
}

#[test]
fn dense_output_keeps_the_methods_order() {
    // DOP853 at 1e-6 takes steps of ~0.8: a cubic interpolant would err by ~1e-3 there.
    let (e, steps) = dense_error(Method::Dop853, 1e-6);
    assert!(steps < 60 && e < 1e-5, "{e:e} over {steps} outputs");
    // (Vern9 has only a cubic Hermite interpolant between its long steps: not checked here.)
    for m in [Method::Dopri5, Method::Tsit5, Method::Rk23, Method::Radau5] {
        let (e, _) = dense_error(m, 1e-8);
        assert!(e < 1e-5, "{m}: {e:e}");
    }
}

#[test]
fn dense_output_reproduces_t_eval_outputs_and_stops_at_a_terminal_event() {
    let g = |_t: f64, y: &[f64]| y[0] + 0.5; // cos t = −0.5 first at t = 2π/3
    let ev = [Event::new(&g).terminal(1)];
    let te: Vec<f64> = (0..=30).map(|k| k as f64 * 0.1).collect();
    let opts = Options {
        dense_output: true,
        t_eval: Some(te.clone()),
        output_terminal_event: false,
        ..Options::with_tol(1e-10)
    };
    let sol =
        solve_with_events(Method::Dop853, &osc(), (0.0, 3.0), &[1.0, 0.0], &opts, &ev).unwrap();
    assert_eq!(sol.status, Status::TerminalEvent(0));
    let t_hit = 2.0 * std::f64::consts::PI / 3.0;
    assert!((sol.events[0].t - t_hit).abs() < 1e-9);
    // Only t_eval points (those before the event).
    assert_eq!(sol.t, te[..=20].to_vec());
    let d = sol.dense.as_ref().unwrap();
    assert_eq!(*d.steps().last().unwrap(), sol.events[0].t);
    let mut out = [0.0; 2];
    for (k, &t) in sol.t.iter().enumerate() {
        d.eval(t, &mut out);
        assert_eq!(&out[..], sol.y_at(k), "t = {t}");
    }
}

#[test]
fn auto_records_both_parts() {
    // Van der Pol, μ = 1000: DOPRI5 detects stiffness and Radau5 finishes.
    let mu = 1000.0;
    let vdp = FnSystem::new(2, move |_t, y: &[f64], f: &mut [f64]| {
        f[0] = y[1];
        f[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
    });
    let opts = Options {
        dense_output: true,
        stiffness_check_interval: 1,
        ..Options::with_tol(1e-6)
    };
    let sol = solve(Method::Auto, &vdp, (0.0, 100.0), &[2.0, 0.0], &opts).unwrap();
    assert!(sol.stats.stiffness_detected_at.is_some());
    let d = sol.dense.as_ref().unwrap();
    assert_eq!(d.steps(), &sol.t[..]);
    let mut out = [0.0; 2];
    d.eval(100.0, &mut out);
    assert_eq!(&out[..], sol.last().unwrap().1);
}

#[test]
fn min_step_is_kept_and_a_failure_at_it_is_typed() {
    let stiff = FnSystem::new(1, |t: f64, y: &[f64], f: &mut [f64]| {
        f[0] = -1e4 * (y[0] - libm::cos(t));
    });
    let opts = Options {
        min_step: Some(0.01),
        ..Options::with_tol(1e-8)
    };
    let e = solve(Method::Dopri5, &stiff, (0.0, 1.0), &[0.0], &opts).unwrap_err();
    assert!(matches!(e, pdyn_ode::OdeError::MinStep { .. }), "{e}");
    let opts = Options {
        min_step: Some(0.5),
        ..Options::with_tol(1e-3)
    };
    let sol = solve(Method::Dopri5, &osc(), (0.0, 10.0), &[1.0, 0.0], &opts).unwrap();
    for w in sol.t.windows(2).take(sol.len() - 2) {
        assert!(w[1] - w[0] >= 0.5 - 1e-12);
    }
}
