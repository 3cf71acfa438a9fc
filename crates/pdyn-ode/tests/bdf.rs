//! BDF (`Method::Bdf`): closed forms of linear and Prothero–Robinson problems, the published
//! Robertson and stiff Van der Pol solutions, its own dense output, events, and Jacobians by
//! finite differences with and without a sparsity pattern.
mod common;
use common::*;
use pdyn_ode::{
    solve, solve_with_events, Event, FnSystem, Interpolant, Method, OdeSystem, Options, Sparsity,
    Status,
};
use std::sync::Arc;

/// Prothero–Robinson: `y' = −λ (y − cos t) − sin t`, `y(0) = 1`; exact `y = cos t` for any λ
/// (stiff for large λ).
fn prothero_robinson(lambda: f64) -> impl OdeSystem {
    FnSystem::new(1, move |t, y: &[f64], f: &mut [f64]| {
        f[0] = -lambda * (y[0] - libm::cos(t)) - libm::sin(t);
    })
}

fn end(sol: &pdyn_ode::Solution) -> Vec<f64> {
    sol.last().unwrap().1.to_vec()
}

#[test]
fn prothero_robinson_follows_cos_t_and_raises_its_order() {
    for (tol, bound) in [(1e-4, 1e-3), (1e-7, 1e-6), (1e-10, 1e-8)] {
        let opts = Options {
            dense_output: true,
            ..Options::with_tol(tol)
        };
        let sol = solve(
            Method::Bdf,
            &prothero_robinson(1e5),
            (0.0, 10.0),
            &[1.0],
            &opts,
        )
        .unwrap();
        let worst = sol
            .t
            .iter()
            .zip(&sol.y)
            .map(|(t, y)| (y - libm::cos(*t)).abs())
            .fold(0.0, f64::max);
        let d = sol.dense.as_ref().unwrap();
        let top = (0..d.len())
            .map(|k| match d.interpolant(k) {
                Interpolant::Bdf { order } => order,
                other => panic!("not BDF's interpolant: {other:?}"),
            })
            .max()
            .unwrap();
        eprintln!(
            "tol {tol:e}: err {worst:e}, top order {top}, {:?}",
            sol.stats
        );
        assert!(worst < bound, "tol {tol:e}: error {worst:e}");
        // Variable order: tight tolerances climb to the high orders.
        if tol <= 1e-7 {
            assert!(top >= 4, "tol {tol:e}: highest order {top}");
        }
    }
}

#[test]
fn a_stiff_linear_system_matches_its_exponentials() {
    // y' = A y with eigenvalues −1 and −1e4 (coupled): y = P diag(e^{λt}) P⁻¹ y0.
    // A = [[-1, 1], [0, -1e4]] + ... chosen as A = P D P⁻¹ with P = [[1, 1], [0, 1]].
    let (l1, l2) = (-1.0, -1e4);
    let a = [l1, l2 - l1, 0.0, l2]; // P D P⁻¹ for P = [[1, 1], [0, 1]]
    let sys = FnSystem::new(2, move |_t, y: &[f64], f: &mut [f64]| {
        f[0] = a[0] * y[0] + a[1] * y[1];
        f[1] = a[2] * y[0] + a[3] * y[1];
    });
    let y0 = [2.0, 1.0];
    // P⁻¹ y0 = (y0[0] − y0[1], y0[1]).
    let exact = |t: f64| {
        let (c1, c2) = (y0[0] - y0[1], y0[1]);
        let (e1, e2) = (c1 * libm::exp(l1 * t), c2 * libm::exp(l2 * t));
        [e1 + e2, e2]
    };
    for tol in [1e-6, 1e-9] {
        let sol = solve(Method::Bdf, &sys, (0.0, 5.0), &y0, &Options::with_tol(tol)).unwrap();
        for (k, &t) in sol.t.iter().enumerate() {
            let e = max_err(sol.y_at(k), &exact(t));
            assert!(e < 200.0 * tol, "tol {tol:e}, t = {t}: error {e:e}");
        }
        // The finite-difference Jacobian of a linear system is exact: one Jacobian suffices.
        assert_eq!(sol.stats.jacobians, 1, "{:?}", sol.stats);
    }
}

#[test]
fn robertson_to_1e11_reaches_the_bari_reference() {
    let opts = Options {
        rtol: 1e-8.into(),
        atol: 1e-14.into(),
        ..Default::default()
    };
    let sol = solve(
        Method::Bdf,
        &robertson(),
        (0.0, 1e11),
        &[1.0, 0.0, 0.0],
        &opts,
    )
    .unwrap();
    let y = end(&sol);
    eprintln!("bdf robertson: {:?}", sol.stats);
    for i in 0..3 {
        let rel = (y[i] - ROBER_Y1E11[i]).abs() / ROBER_Y1E11[i];
        assert!(rel < 1e-4, "component {i}: {y:?}");
    }
}

#[test]
fn stiff_van_der_pol_reaches_the_reference_with_fewer_evaluations_than_radau5() {
    for (tol, bound) in [(1e-3, 1e-1), (1e-6, 1e-3), (1e-9, 1e-6)] {
        let opts = Options::with_tol(tol);
        let sol = solve(
            Method::Bdf,
            &van_der_pol(1e-6),
            (0.0, 2.0),
            &[2.0, 0.0],
            &opts,
        )
        .unwrap();
        let e = max_err(&end(&sol), &VDP_STIFF_Y2);
        // Radau5 with the error test SciPy's Radau applies at `tol` (RADAU5 reads rtol as
        // 0.1 rtol^(2/3): given (10 tol)^1.5 it tests at tol; pdyn.solve_ivp does the same).
        let rh = libm::pow(10.0 * tol, 1.5);
        let radau = solve(
            Method::Radau5,
            &van_der_pol(1e-6),
            (0.0, 2.0),
            &[2.0, 0.0],
            &Options::with_tol(rh),
        )
        .unwrap();
        let er = max_err(&end(&radau), &VDP_STIFF_Y2);
        eprintln!(
            "tol {tol:e}: bdf err {e:e} {} f, radau5 err {er:e} {} f",
            sol.stats.fevals, radau.stats.fevals
        );
        assert!(e < bound, "tol {tol:e}: error {e:e}");
        // BDF's cheap steps: clearly fewer evaluations than Radau5's three stages per Newton
        // iteration at medium tolerances (SciPy: 3775 against 7257 at 1e-6).
        if tol == 1e-6 {
            assert!(
                (sol.stats.fevals as f64) < 0.7 * radau.stats.fevals as f64,
                "tol {tol:e}: bdf {} f, radau5 {} f",
                sol.stats.fevals,
                radau.stats.fevals
            );
        }
    }
}

#[test]
fn dense_output_is_the_interpolating_polynomial_and_gives_the_t_eval_outputs() {
    let te: Vec<f64> = (0..=100).map(|k| k as f64 * 0.1).collect();
    let opts = Options {
        dense_output: true,
        t_eval: Some(te.clone()),
        ..Options::with_tol(1e-8)
    };
    let sys = prothero_robinson(1e3);
    let sol = solve(Method::Bdf, &sys, (0.0, 10.0), &[1.0], &opts).unwrap();
    assert_eq!(sol.t, te);
    let d = sol.dense.as_ref().unwrap();
    let mut out = [0.0];
    for (k, &t) in te.iter().enumerate() {
        d.eval(t, &mut out);
        // Same code as the outputs: the same bits (an output at a step's end is the state).
        if !d.steps().contains(&t) {
            assert_eq!(out[0].to_bits(), sol.y[k].to_bits(), "t = {t}");
        }
        assert!((out[0] - libm::cos(t)).abs() < 1e-6, "t = {t}");
    }
    // Between the outputs, too.
    for k in 0..=2000 {
        let t = k as f64 * 0.005;
        d.eval(t, &mut out);
        assert!((out[0] - libm::cos(t)).abs() < 1e-6, "t = {t}: {}", out[0]);
    }
}

#[test]
fn a_terminal_event_stops_at_its_closed_form_time() {
    // y = cos t crosses 0 first at π/2.
    let g = |_t: f64, y: &[f64]| y[0];
    let ev = [Event::new(&g).terminal(1)];
    let sys = prothero_robinson(1e4);
    let sol = solve_with_events(
        Method::Bdf,
        &sys,
        (0.0, 5.0),
        &[1.0],
        &Options::with_tol(1e-9),
        &ev,
    )
    .unwrap();
    assert_eq!(sol.status, Status::TerminalEvent(0));
    let hit = &sol.events[0];
    assert!(
        (hit.t - std::f64::consts::FRAC_PI_2).abs() < 1e-7,
        "{}",
        hit.t
    );
}

/// The 1-D heat equation on `n` interior points (method of lines, Dirichlet ends):
/// `y_i' = (y_{i−1} − 2 y_i + y_{i+1})/Δx²`. With `y_i(0) = sin(π x_i)` the exact solution is
/// `e^{λ t} y(0)`, `λ = −4/Δx² sin²(π Δx/2)` (a discrete eigenvector).
fn heat(n: usize) -> (impl OdeSystem, Vec<f64>, f64) {
    let dx = 1.0 / (n + 1) as f64;
    let sys = FnSystem::new(n, move |_t, y: &[f64], f: &mut [f64]| {
        for i in 0..n {
            let l = if i > 0 { y[i - 1] } else { 0.0 };
            let r = if i + 1 < n { y[i + 1] } else { 0.0 };
            f[i] = (l - 2.0 * y[i] + r) / (dx * dx);
        }
    });
    let y0 = (0..n)
        .map(|i| libm::sin(std::f64::consts::PI * (i + 1) as f64 * dx))
        .collect();
    let s = libm::sin(std::f64::consts::PI * dx / 2.0);
    (sys, y0, -4.0 / (dx * dx) * s * s)
}

#[test]
fn jac_sparsity_groups_the_columns_of_finite_differences() {
    let n = 40;
    let (sys, y0, lambda) = heat(n);
    let dense = solve(Method::Bdf, &sys, (0.0, 0.1), &y0, &Options::with_tol(1e-8)).unwrap();
    let opts = Options {
        jac_sparsity: Some(Arc::new(Sparsity::banded(n, 1, 1))),
        ..Options::with_tol(1e-8)
    };
    let sparse = solve(Method::Bdf, &sys, (0.0, 0.1), &y0, &opts).unwrap();
    let decay = libm::exp(lambda * 0.1);
    for sol in [&dense, &sparse] {
        let y = end(sol);
        for i in 0..n {
            assert!((y[i] - decay * y0[i]).abs() < 1e-6, "{i}: {}", y[i]);
        }
    }
    // Three evaluations per Jacobian (three groups of columns) instead of n.
    assert_eq!(sparse.stats.jac_fevals, 3 * sparse.stats.jacobians);
    assert_eq!(dense.stats.jac_fevals, n * dense.stats.jacobians);
    // Radau5 groups them too.
    let radau = solve(Method::Radau5, &sys, (0.0, 0.1), &y0, &opts).unwrap();
    assert_eq!(radau.stats.jac_fevals, 3 * radau.stats.jacobians);
    // A pattern of the wrong size is refused.
    let wrong = Options {
        jac_sparsity: Some(Arc::new(Sparsity::banded(n + 1, 1, 1))),
        ..Options::with_tol(1e-8)
    };
    assert!(solve(Method::Bdf, &sys, (0.0, 0.1), &y0, &wrong).is_err());
}

#[test]
fn backward_in_time_and_interrupted() {
    // y' = −y backward from t = 1 to 0: y(0) = e · y(1).
    let sys = FnSystem::new(1, |_t, y: &[f64], f: &mut [f64]| f[0] = -y[0]);
    let sol = solve(
        Method::Bdf,
        &sys,
        (1.0, 0.0),
        &[1.0],
        &Options::with_tol(1e-10),
    )
    .unwrap();
    let (t, y) = sol.last().unwrap();
    assert_eq!(t, 0.0);
    assert!((y[0] - std::f64::consts::E).abs() < 1e-8, "{}", y[0]);
    let stop: pdyn_ode::Interrupt = Default::default();
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let opts = Options {
        interrupt: Some(stop),
        ..Default::default()
    };
    assert!(matches!(
        solve(Method::Bdf, &sys, (0.0, 1.0), &[1.0], &opts),
        Err(pdyn_ode::OdeError::Interrupted { .. })
    ));
}
