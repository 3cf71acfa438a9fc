//! A solve watched step by step and resumed from a saved state (`solve_observed`): the
//! observed solve is the plain one, and a solve stopped after any accepted step and resumed
//! from its [`ResumeState`] takes the same steps and gives the same outputs, events and
//! statistics, bit for bit, as the solve that was never stopped. The reference is the plain
//! `solve_with_events`, which knows nothing of observers or saved states.

use pdyn_ode::resume::RESUMABLE;
use pdyn_ode::{
    problems, solve_observed, solve_with_events, Direction, Event, Method, OdeError, Options,
    ResumeState, Solution,
};
use std::ops::ControlFlow;

/// The Arenstorf orbit over one period with outputs at 400 times (dense output).
fn setup() -> (Options, f64) {
    let tf = problems::AREN_T;
    let t_eval: Vec<f64> = (0..400).map(|k| tf * k as f64 / 399.0).collect();
    let opts = Options {
        rtol: 1e-9.into(),
        atol: 1e-9.into(),
        t_eval: Some(t_eval),
        ..Default::default()
    };
    (opts, tf)
}

fn g_cross(_t: f64, y: &[f64]) -> f64 {
    y[1]
}

fn g_half(_t: f64, y: &[f64]) -> f64 {
    y[0] - 0.5
}

/// `y1` crossing zero (both ways), terminal at its `terminal_at`-th zero, and `y0 = 0.5`
/// rising.
fn events(terminal_at: usize) -> Vec<Event<'static>> {
    vec![
        Event::new(&g_cross).terminal(terminal_at),
        Event::new(&g_half).direction(Direction::Rising),
    ]
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Outputs, events and statistics of `got` are those of `want`, bit for bit.
fn assert_same(got: &Solution, want: &Solution, what: &str) {
    assert!(same_bits(&got.t, &want.t), "{what}: output times differ");
    assert!(same_bits(&got.y, &want.y), "{what}: output states differ");
    assert_eq!(got.events.len(), want.events.len(), "{what}: events");
    for (a, b) in got.events.iter().zip(&want.events) {
        assert_eq!(a.index, b.index, "{what}");
        assert_eq!(a.t.to_bits(), b.t.to_bits(), "{what}: event time");
        assert!(same_bits(&a.y, &b.y), "{what}: event state");
    }
    assert_eq!(got.stats, want.stats, "{what}: statistics");
    assert_eq!(got.status, want.status, "{what}: status");
}

/// Solves with `method`, stopping after the `stop_after`-th accepted step and saving the
/// state there, then resumes; returns the two parts joined.
fn stopped_and_resumed(
    method: Method,
    opts: &Options,
    tf: f64,
    terminal_at: usize,
    stop_after: usize,
) -> (Solution, ResumeState) {
    let sys = problems::arenstorf();
    let y0 = problems::AREN_Y0;
    let evs = events(terminal_at);
    let mut saved = None;
    let mut seen = 0;
    let mut stop = |step: &mut pdyn_ode::Accepted<'_>| {
        seen += 1;
        if seen == stop_after {
            saved = Some(step.state());
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    };
    let first = solve_observed(method, &sys, (0.0, tf), &y0, opts, &evs, None, &mut stop);
    let mut first = match first {
        Err(OdeError::Interrupted { at }) => *at.partial,
        other => panic!("expected a stop after step {stop_after}, got {other:?}"),
    };
    let state = saved.expect("a saved state");
    let mut go_on = |_: &mut pdyn_ode::Accepted<'_>| ControlFlow::Continue(());
    let rest = solve_observed(
        method,
        &sys,
        (0.0, tf),
        &y0,
        opts,
        &evs,
        Some(&state),
        &mut go_on,
    )
    .expect("the resumed solve");
    first.t.extend_from_slice(&rest.t);
    first.y.extend_from_slice(&rest.y);
    first.events.extend(rest.events.iter().cloned());
    first
        .possible_misses
        .extend(rest.possible_misses.iter().copied());
    first.stats = rest.stats.clone();
    first.status = rest.status;
    (first, state)
}

#[test]
fn an_observed_solve_is_the_plain_solve() {
    let (opts, tf) = setup();
    let sys = problems::arenstorf();
    let evs = events(50);
    for method in [Method::Dopri5, Method::Dop853] {
        let plain =
            solve_with_events(method, &sys, (0.0, tf), &problems::AREN_Y0, &opts, &evs).unwrap();
        let mut steps = 0;
        let mut count = |_: &mut pdyn_ode::Accepted<'_>| {
            steps += 1;
            ControlFlow::Continue(())
        };
        let observed = solve_observed(
            method,
            &sys,
            (0.0, tf),
            &problems::AREN_Y0,
            &opts,
            &evs,
            None,
            &mut count,
        )
        .unwrap();
        assert_same(&observed, &plain, method.name());
        // Called after every accepted step but the last.
        assert_eq!(steps, plain.stats.accepted - 1, "{method}");
        assert!(!plain.events.is_empty(), "the orbit crosses y1 = 0");
    }
}

#[test]
fn a_solve_resumed_after_any_step_continues_bit_for_bit() {
    let (opts, tf) = setup();
    let sys = problems::arenstorf();
    for method in RESUMABLE {
        let plain = solve_with_events(
            method,
            &sys,
            (0.0, tf),
            &problems::AREN_Y0,
            &opts,
            &events(50),
        )
        .unwrap();
        let n = plain.stats.accepted;
        if method == Method::Dopri5 {
            assert!(plain.stats.rejected > 0, "the test needs rejected steps");
        }
        for stop_after in [1, 2, 3, n / 7, n / 3, n / 2, n - 2] {
            let (joined, state) = stopped_and_resumed(method, &opts, tf, 50, stop_after);
            assert_same(
                &joined,
                &plain,
                &format!("{method} stopped after step {stop_after}"),
            );
            assert_eq!(state.stats.accepted, stop_after);
        }
    }
}

#[test]
fn a_terminal_event_counted_before_the_stop_ends_the_resumed_solve_where_it_should() {
    let (opts, tf) = setup();
    let sys = problems::arenstorf();
    let all = solve_with_events(
        Method::Dopri5,
        &sys,
        (0.0, tf),
        &problems::AREN_Y0,
        &opts,
        &events(50),
    )
    .unwrap();
    let crossings: Vec<f64> = all
        .events
        .iter()
        .filter(|e| e.index == 0)
        .map(|e| e.t)
        .collect();
    assert!(
        crossings.len() >= 2,
        "the orbit crosses y1 = 0: {crossings:?}"
    );
    // Terminal at the last crossing: the count of the ones before must come back with the
    // state.
    let k = crossings.len();
    let evs = events(k);
    let plain = solve_with_events(
        Method::Dopri5,
        &sys,
        (0.0, tf),
        &problems::AREN_Y0,
        &opts,
        &evs,
    )
    .unwrap();
    assert_eq!(plain.status, pdyn_ode::Status::TerminalEvent(0));
    let stop_after = (0..plain.stats.accepted)
        .rev()
        .find(|&s| {
            let (_, st) = stopped_and_resumed(Method::Dopri5, &opts, tf, k, s.max(1));
            st.t > crossings[k - 2] && st.t < crossings[k - 1]
        })
        .expect("a step between the last two crossings");
    let (joined, state) = stopped_and_resumed(Method::Dopri5, &opts, tf, k, stop_after);
    assert_eq!(state.events.counts[0], k - 1);
    assert_same(&joined, &plain, "terminal");
}

#[test]
fn each_part_of_the_saved_state_matters() {
    // Resuming from a state with one part reset changes the continuation: the test above
    // would catch a part that is not saved or not restored.
    let (opts, tf) = setup();
    let sys = problems::arenstorf();
    let plain = solve_with_events(
        Method::Dopri5,
        &sys,
        (0.0, tf),
        &problems::AREN_Y0,
        &opts,
        &events(50),
    )
    .unwrap();
    let n = plain.stats.accepted;
    let (_, state) = stopped_and_resumed(Method::Dopri5, &opts, tf, 50, n / 3);
    type Tweak = fn(&mut ResumeState);
    let tweaks: [(&str, Tweak); 3] = [
        ("the PI controller's memory", |s| s.facold = 1e-4),
        ("the step", |s| s.h *= 1.0 + 1e-12),
        ("the first stage", |s| s.first_stage[0] += 1e-9),
    ];
    for (what, tweak) in tweaks {
        let mut s = state.clone();
        tweak(&mut s);
        let evs = events(50);
        let mut go_on = |_: &mut pdyn_ode::Accepted<'_>| ControlFlow::Continue(());
        let rest = solve_observed(
            Method::Dopri5,
            &sys,
            (0.0, tf),
            &problems::AREN_Y0,
            &opts,
            &evs,
            Some(&s),
            &mut go_on,
        );
        let differs = match rest {
            Err(_) => true,
            Ok(r) => {
                let k = plain.t.len() - r.t.len();
                !same_bits(&r.y, &plain.y[k * 4..])
                    || r.stats != plain.stats
                    || r.possible_misses != plain.possible_misses
            }
        };
        assert!(
            differs,
            "resetting {what} changed nothing: the test cannot see it"
        );
    }
}

#[test]
fn methods_that_cannot_resume_and_foreign_states_are_refused() {
    let (opts, tf) = setup();
    let sys = problems::arenstorf();
    let mut go_on = |_: &mut pdyn_ode::Accepted<'_>| ControlFlow::Continue(());
    for method in [Method::Radau5, Method::Bdf, Method::Rk4] {
        let e = solve_observed(
            method,
            &sys,
            (0.0, tf),
            &problems::AREN_Y0,
            &opts,
            &[],
            None,
            &mut go_on,
        )
        .unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("dopri5") && text.contains(method.name()),
            "{text}"
        );
    }
    let (_, state) = stopped_and_resumed(Method::Dopri5, &opts, tf, 50, 10);
    let evs = events(50);
    let wrong_method = solve_observed(
        Method::Dop853,
        &sys,
        (0.0, tf),
        &problems::AREN_Y0,
        &opts,
        &evs,
        Some(&state),
        &mut go_on,
    );
    assert!(wrong_method
        .unwrap_err()
        .to_string()
        .contains("saved by dopri5"));
    let no_events = solve_observed(
        Method::Dopri5,
        &sys,
        (0.0, tf),
        &problems::AREN_Y0,
        &opts,
        &[],
        Some(&state),
        &mut go_on,
    );
    assert!(no_events
        .unwrap_err()
        .to_string()
        .contains("event functions"));
}

/// `auto` observed is the plain `auto`, and stopped after any step before its switch to
/// Radau5 and resumed, it continues bit for bit, switches at the same step and ends with the
/// same solution: van der Pol at ε = 1e-4 with `rtol` 1e-7 (DOP853 first), which turns stiff
/// on its slow branch (the stiffness test at every step). The rows produced after the switch come back in the solution (Radau5
/// is not observed), the ones before it went to the observer.
#[test]
fn auto_is_observed_and_resumed_until_it_switches_to_radau5() {
    let sys = problems::van_der_pol(1e-4);
    let (y0, tf) = ([2.0, 0.0], 2.0);
    let opts = Options {
        rtol: 1e-7.into(),
        atol: 1e-7.into(),
        stiffness_check_interval: 1,
        t_eval: Some((0..=200).map(|k| tf * k as f64 / 200.0).collect()),
        ..Default::default()
    };
    let plain = solve_with_events(Method::Auto, &sys, (0.0, tf), &y0, &opts, &[]).unwrap();
    let switched = plain
        .stats
        .stiffness_detected_at
        .expect("the test needs a switch");
    assert_eq!(plain.method, Method::Radau5);
    // Observed, the observer taking every output out as a streamed run does.
    let mut seen = Vec::new();
    let mut states = Vec::new();
    let mut take = |step: &mut pdyn_ode::Accepted<'_>| {
        seen.append(&mut step.solution.t);
        step.solution.y.clear();
        states.push(step.state());
        ControlFlow::Continue(())
    };
    let observed = solve_observed(
        Method::Auto,
        &sys,
        (0.0, tf),
        &y0,
        &opts,
        &[],
        None,
        &mut take,
    )
    .unwrap();
    seen.extend_from_slice(&observed.t);
    assert!(same_bits(&seen, &plain.t), "the outputs, observed or not");
    assert_eq!(observed.stats, plain.stats);
    assert_eq!(observed.method, Method::Radau5);
    assert!(states
        .iter()
        .all(|s| s.method == Method::Dop853 && s.t <= switched));
    // Resumed from states before the switch.
    let n = states.len();
    for k in [0, n / 2, n - 1] {
        let mut go_on = |_: &mut pdyn_ode::Accepted<'_>| ControlFlow::Continue(());
        let rest = solve_observed(
            Method::Auto,
            &sys,
            (0.0, tf),
            &y0,
            &opts,
            &[],
            Some(&states[k]),
            &mut go_on,
        )
        .unwrap();
        assert_eq!(rest.stats, plain.stats, "resumed from state {k}");
        let tail = &plain.y[plain.y.len() - 2..];
        assert!(
            same_bits(&rest.y[rest.y.len() - 2..], tail),
            "resumed from state {k}"
        );
        let from = plain.t.len() - rest.t.len();
        assert!(
            same_bits(&rest.t, &plain.t[from..]),
            "resumed from state {k}"
        );
    }
}
