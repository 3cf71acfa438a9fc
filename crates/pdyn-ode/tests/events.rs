//! Event location on the dense output: accuracy against closed forms, terminal stops,
//! directions, several events in one step, no re-trigger at t0; output at `t_eval`.
use pdyn_ode::{
    solve, solve_second_order_with_events, solve_with_events, Direction, Event, FnSecondOrder,
    FnSystem, Method, Options, Status,
};
use std::f64::consts::PI;

const G: f64 = 9.81;
const K: f64 = 0.3; // linear drag coefficient
const Z0: f64 = 2.0;
const VX0: f64 = 12.0;
const VZ0: f64 = 15.0;

/// Projectile with linear drag: x'' = −k x', z'' = −g − k z'. State (x, z, x', z').
fn projectile() -> impl pdyn_ode::OdeSystem {
    FnSystem::new(4, |_t, y: &[f64], f: &mut [f64]| {
        f[0] = y[2];
        f[1] = y[3];
        f[2] = -K * y[2];
        f[3] = -G - K * y[3];
    })
}

/// Closed form z(t) = z0 + (vz0 + g/k)(1 − e^{−kt})/k − g t/k and its derivative.
fn z_exact(t: f64) -> (f64, f64) {
    let a = VZ0 + G / K;
    let one_minus = -libm::expm1(-K * t);
    (
        Z0 + a * one_minus / K - G * t / K,
        a * libm::exp(-K * t) - G / K,
    )
}

/// Impact time from the closed form (Newton's method to machine precision).
fn impact_time() -> f64 {
    let mut t = 3.5;
    for _ in 0..50 {
        let (z, dz) = z_exact(t);
        let step = z / dz;
        t -= step;
        if step.abs() < 1e-16 * t {
            break;
        }
    }
    t
}

fn ground(_t: f64, y: &[f64]) -> f64 {
    y[1]
}

#[test]
fn projectile_impact_time_matches_closed_form_and_stops_there() {
    let t_star = impact_time();
    assert!(z_exact(t_star).0.abs() < 1e-13);
    let g = ground;
    let ev = [Event::new(&g).direction(Direction::Falling).terminal(1)];
    for (m, tol, rel) in [
        (Method::Dopri5, 1e-13, 1e-10),
        (Method::Tsit5, 1e-13, 1e-10),
        (Method::Dop853, 1e-13, 1e-10),
        (Method::Radau5, 1e-10, 1e-7),
        (Method::Auto, 1e-13, 1e-10),
    ] {
        let y0 = [0.0, Z0, VX0, VZ0];
        let opts = Options::with_tol(tol);
        let sol = solve_with_events(m, &projectile(), (0.0, 10.0), &y0, &opts, &ev).unwrap();
        assert_eq!(sol.status, Status::TerminalEvent(0), "{m}");
        assert_eq!(sol.events.len(), 1, "{m}");
        let hit = &sol.events[0];
        let err = (hit.t - t_star).abs() / t_star;
        assert!(
            err < rel,
            "{m}: impact {} vs {t_star}, rel err {err:e}",
            hit.t
        );
        assert_eq!(hit.direction, Direction::Falling);
        // the solution ends exactly at the event, with the event state
        let (t_end, y_end) = sol.last().unwrap();
        assert_eq!(t_end, hit.t, "{m}");
        assert_eq!(y_end, &hit.y[..], "{m}");
        assert!(y_end[1].abs() < 10.0 * rel, "{m}: z at impact {}", y_end[1]);
    }
}

#[test]
fn fixed_step_methods_locate_events_with_hermite_interpolation() {
    let t_star = impact_time();
    let g = ground;
    let ev = [Event::new(&g).direction(Direction::Falling).terminal(1)];
    let opts = Options {
        h0: Some(1e-3),
        ..Default::default()
    };
    let y0 = [0.0, Z0, VX0, VZ0];
    let sol = solve_with_events(Method::Rk4, &projectile(), (0.0, 10.0), &y0, &opts, &ev).unwrap();
    assert_eq!(sol.status, Status::TerminalEvent(0));
    let rel = (sol.events[0].t - t_star).abs() / t_star;
    assert!(rel < 1e-10, "rk4 rel err {rel:e}");
}

fn oscillator() -> impl pdyn_ode::SecondOrderSystem {
    FnSecondOrder::new(1, true, |_t, q: &[f64], _v: &[f64], a: &mut [f64]| {
        a[0] = -q[0]
    })
}

fn zeros(dir: Direction, method: Method, opts: &Options) -> Vec<(f64, Direction)> {
    let g = |_t: f64, y: &[f64]| y[0];
    let ev = [Event::new(&g).direction(dir)];
    let sol = solve_second_order_with_events(
        method,
        &oscillator(),
        (0.0, 10.0),
        &[1.0],
        &[0.0],
        opts,
        &ev,
    )
    .unwrap();
    assert_eq!(sol.status, Status::Finished);
    sol.events.iter().map(|e| (e.t, e.direction)).collect()
}

#[test]
fn directions_are_honoured() {
    // q = cos t: falling zeros at π/2, 5π/2; rising at 3π/2 (within [0, 10]).
    for (m, opts, tol) in [
        (Method::Dopri5, Options::with_tol(1e-12), 1e-10),
        (Method::Dop853, Options::with_tol(1e-12), 1e-10),
        (
            Method::VelocityVerlet,
            Options {
                h0: Some(1e-4),
                ..Default::default()
            },
            1e-8,
        ),
        (
            Method::Gauss6,
            Options {
                h0: Some(1e-2),
                ..Default::default()
            },
            1e-8,
        ),
    ] {
        let rising = zeros(Direction::Rising, m, &opts);
        let falling = zeros(Direction::Falling, m, &opts);
        let both = zeros(Direction::Both, m, &opts);
        assert_eq!(rising.len(), 1, "{m}: {rising:?}");
        assert!((rising[0].0 - 1.5 * PI).abs() < tol, "{m}: {rising:?}");
        assert_eq!(falling.len(), 2, "{m}: {falling:?}");
        assert!((falling[0].0 - 0.5 * PI).abs() < tol && (falling[1].0 - 2.5 * PI).abs() < tol);
        assert!(falling.iter().all(|e| e.1 == Direction::Falling));
        let times: Vec<f64> = both.iter().map(|e| e.0).collect();
        assert_eq!(times.len(), 3, "{m}");
        assert!(times.windows(2).all(|w| w[1] > w[0]), "time order");
    }
}

#[test]
fn terminal_at_nth_occurrence() {
    let g = |_t: f64, y: &[f64]| y[0];
    let ev = [Event::new(&g).direction(Direction::Falling).terminal(2)];
    let opts = Options::with_tol(1e-12);
    let sol = solve_second_order_with_events(
        Method::Dopri5,
        &oscillator(),
        (0.0, 10.0),
        &[1.0],
        &[0.0],
        &opts,
        &ev,
    )
    .unwrap();
    assert_eq!(sol.status, Status::TerminalEvent(0));
    assert_eq!(sol.events.len(), 2);
    let (t, _) = sol.last().unwrap();
    assert!((t - 2.5 * PI).abs() < 1e-10);
}

#[test]
fn event_at_initial_time_is_not_retriggered() {
    // q = sin t starts on the zero of g = q.
    let g = |_t: f64, y: &[f64]| y[0];
    let ev = [Event::new(&g).terminal(1)];
    let sol = solve_second_order_with_events(
        Method::Dopri5,
        &oscillator(),
        (0.0, 10.0),
        &[0.0],
        &[1.0],
        &Options::with_tol(1e-12),
        &ev,
    )
    .unwrap();
    assert_eq!(sol.events.len(), 1);
    assert!(
        (sol.events[0].t - PI).abs() < 1e-10,
        "{:?}",
        sol.events[0].t
    );
}

#[test]
fn several_events_in_one_step_are_reported_in_time_order() {
    // y' = 0 lets DOPRI5 cross [0, 1] in one step (h0 = 1); three events inside it.
    let sys = FnSystem::new(1, |_t, _y: &[f64], f: &mut [f64]| f[0] = 0.0);
    let g1 = |t: f64, _y: &[f64]| t - 0.7;
    let g2 = |t: f64, _y: &[f64]| t - 0.2;
    let g3 = |t: f64, _y: &[f64]| 0.45 - t;
    let ev = [Event::new(&g1), Event::new(&g2), Event::new(&g3)];
    let opts = Options {
        h0: Some(1.0),
        ..Default::default()
    };
    let sol = solve_with_events(Method::Dopri5, &sys, (0.0, 1.0), &[1.0], &opts, &ev).unwrap();
    assert_eq!(sol.stats.accepted, 1);
    let got: Vec<(usize, f64, Direction)> = sol
        .events
        .iter()
        .map(|e| (e.index, e.t, e.direction))
        .collect();
    assert_eq!(got.len(), 3);
    assert_eq!((got[0].0, got[1].0, got[2].0), (1, 2, 0));
    assert!((got[0].1 - 0.2).abs() < 1e-15 && (got[1].1 - 0.45).abs() < 1e-15);
    assert!((got[2].1 - 0.7).abs() < 1e-15);
    assert_eq!(got[1].2, Direction::Falling);
    assert_eq!(got[0].2, Direction::Rising);
}

#[test]
fn t_eval_uses_dense_output() {
    let sys = FnSystem::new(1, |_t, y: &[f64], f: &mut [f64]| f[0] = y[0]);
    let t_eval: Vec<f64> = (0..=400).map(|k| k as f64 * 0.005).collect();
    for m in [
        Method::Dopri5,
        Method::Tsit5,
        Method::Dop853,
        Method::Radau5,
    ] {
        let opts = Options {
            t_eval: Some(t_eval.clone()),
            ..Options::with_tol(1e-10)
        };
        let sol = solve(m, &sys, (0.0, 2.0), &[1.0], &opts).unwrap();
        assert_eq!(sol.t, t_eval, "{m}");
        assert!(
            sol.stats.accepted < t_eval.len(),
            "{m}: fewer steps than outputs"
        );
        for (k, &t) in sol.t.iter().enumerate() {
            let rel = (sol.y_at(k)[0] - libm::exp(t)).abs() / libm::exp(t);
            assert!(rel < 1e-8, "{m} at t={t}: rel err {rel:e}");
        }
    }
}

#[test]
fn t_eval_with_terminal_event_stops_at_event() {
    let t_star = impact_time();
    let g = ground;
    let ev = [Event::new(&g).direction(Direction::Falling).terminal(1)];
    let opts = Options {
        t_eval: Some((0..=100).map(|k| k as f64 * 0.1).collect()),
        ..Options::with_tol(1e-12)
    };
    let y0 = [0.0, Z0, VX0, VZ0];
    let sol =
        solve_with_events(Method::Dopri5, &projectile(), (0.0, 10.0), &y0, &opts, &ev).unwrap();
    let n_before = (t_star / 0.1).floor() as usize + 1;
    assert_eq!(sol.len(), n_before + 1);
    assert_eq!(*sol.t.last().unwrap(), sol.events[0].t);
    for (k, &t) in sol.t.iter().take(n_before).enumerate() {
        assert!((sol.y_at(k)[1] - z_exact(t).0).abs() < 1e-9);
    }
}

#[test]
fn backward_integration_locates_events() {
    // integrate q = cos t backwards from 10 to 0
    let g = |_t: f64, y: &[f64]| y[0];
    let ev = [Event::new(&g)];
    let (c, s) = (libm::cos(10f64), libm::sin(10f64));
    let sol = solve_second_order_with_events(
        Method::Dop853,
        &oscillator(),
        (10.0, 0.0),
        &[c],
        &[-s],
        &Options::with_tol(1e-12),
        &ev,
    )
    .unwrap();
    let times: Vec<f64> = sol.events.iter().map(|e| e.t).collect();
    assert_eq!(times.len(), 3);
    assert!((times[0] - 2.5 * PI).abs() < 1e-9 && (times[2] - 0.5 * PI).abs() < 1e-9);
}

/// `y' = 1` is integrated exactly, so the adaptive methods take ever longer steps; the two
/// zeros of `g = (y − 1)² − 1e-6`, at 0.999 and 1.001, end up inside one step where `g` has
/// the same sign at both ends. MATLAB and SciPy report nothing there.
#[test]
fn two_zeros_inside_one_step_are_found() {
    let sys = FnSystem::new(1, |_t, _y: &[f64], f: &mut [f64]| f[0] = 1.0);
    let g = |_t: f64, y: &[f64]| (y[0] - 1.0).powi(2) - 1e-6;
    for method in [Method::Dopri5, Method::Dop853, Method::Radau5] {
        let ev = [Event::new(&g)];
        let sol =
            solve_with_events(method, &sys, (0.0, 3.0), &[0.0], &Options::default(), &ev).unwrap();
        // Steps are longer than the 0.002 between the zeros (else this tests nothing).
        assert!(sol.stats.accepted < 40, "{method}: {:?}", sol.stats);
        let ts: Vec<f64> = sol.events.iter().map(|e| e.t).collect();
        assert_eq!(
            ts.len(),
            2,
            "{method}: {ts:?} {:?} {:?}",
            sol.possible_misses,
            sol.t
        );
        assert!(
            (ts[0] - 0.999).abs() < 1e-9 && (ts[1] - 1.001).abs() < 1e-9,
            "{method}: {ts:?}"
        );
        assert_eq!(sol.events[0].direction, Direction::Falling);
        assert_eq!(sol.events[1].direction, Direction::Rising);
    }
}

/// A dip too narrow for the samples is reported as a possible miss, not ignored.
#[test]
fn a_dip_narrower_than_the_samples_is_reported() {
    let sys = FnSystem::new(1, |_t, _y: &[f64], f: &mut [f64]| f[0] = 1.0);
    // Zeros at 1 ± 1e-7: between two of the eight samples of a step of length ~1.
    let g = |_t: f64, y: &[f64]| (y[0] - 1.0).powi(2) - 1e-14;
    let ev = [Event::new(&g)];
    let sol = solve_with_events(
        Method::Dopri5,
        &sys,
        (0.0, 3.0),
        &[0.0],
        &Options::default(),
        &ev,
    )
    .unwrap();
    let found = sol.events.len() == 2;
    let reported = sol
        .possible_misses
        .iter()
        .any(|m| m.index == 0 && m.t_from < 1.0 && 1.0 < m.t_to);
    assert!(
        found || reported,
        "{:?} {:?}",
        sol.events,
        sol.possible_misses
    );
}
