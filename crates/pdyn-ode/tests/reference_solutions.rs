//! Reference problems reach their published solutions within the requested tolerance
//! (global error ≤ a documented multiple of the tolerance: the tolerances bound local errors).
mod common;
use common::*;
use pdyn_ode::{solve, MassKind, Method, OdeSystem, Options};

fn end(method: Method, sys: &dyn OdeSystem, t1: f64, y0: &[f64], opts: &Options) -> Vec<f64> {
    let sol = solve(method, sys, (0.0, t1), y0, opts).unwrap();
    let (t, y) = sol.last().unwrap();
    assert_eq!(t, t1);
    eprintln!("{method}: {:?}", sol.stats);
    y.to_vec()
}

#[test]
fn pleiades_explicit_methods() {
    for (m, tol, bound) in [
        (Method::Dopri5, 1e-10, 1e-7),
        (Method::Tsit5, 1e-10, 1e-7),
        (Method::Dop853, 1e-12, 1e-9),
        (Method::Vern9, 1e-12, 1e-9),
    ] {
        let y = end(m, &pleiades(), 3.0, &PLEI_Y0, &Options::with_tol(tol));
        let e = max_err(&y, &PLEI_Y3);
        eprintln!("{m} pleiades err {e:e}");
        assert!(e < bound, "{m}: error {e:e}");
    }
}

#[test]
fn brusselator_explicit_and_implicit() {
    for (m, tol, bound) in [
        (Method::Dopri5, 1e-10, 1e-8),
        (Method::Dop853, 1e-12, 1e-10),
        (Method::Radau5, 1e-10, 1e-7),
    ] {
        let y = end(
            m,
            &brusselator(),
            20.0,
            &[1.5, 3.0],
            &Options::with_tol(tol),
        );
        let e = max_err(&y, &BRUSS_Y20);
        eprintln!("{m} brusselator err {e:e}");
        assert!(e < bound, "{m}: error {e:e}");
    }
}

#[test]
fn stiff_van_der_pol_radau5() {
    for (tol, bound) in [(1e-6, 1e-3), (1e-9, 1e-6)] {
        let y = end(
            Method::Radau5,
            &van_der_pol(1e-6),
            2.0,
            &[2.0, 0.0],
            &Options::with_tol(tol),
        );
        let e = max_err(&y, &VDP_STIFF_Y2);
        eprintln!("vdp stiff tol {tol:e}: err {e:e} {y:?}");
        assert!(e < bound, "error {e:e}");
    }
}

#[test]
fn robertson_to_1e11_radau5() {
    let opts = Options {
        rtol: 1e-8.into(),
        atol: 1e-14.into(),
        h0: Some(1e-6),
        ..Default::default()
    };
    let y = end(Method::Radau5, &robertson(), 1e11, &[1.0, 0.0, 0.0], &opts);
    for i in 0..3 {
        let rel = (y[i] - ROBER_Y1E11[i]).abs() / ROBER_Y1E11[i];
        eprintln!("robertson component {i}: rel err {rel:e}");
        assert!(rel < 1e-4, "component {i}: {y:?}");
    }
}

#[test]
fn robertson_as_dae_with_singular_mass_matrix() {
    // y1' = f1, y2' = f2, 0 = y1 + y2 + y3 − 1  (index 1).
    struct RoberDae;
    impl OdeSystem for RoberDae {
        fn dim(&self) -> usize {
            3
        }
        fn rhs(&self, _t: f64, y: &[f64], f: &mut [f64]) {
            f[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
            f[1] = 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] * y[1];
            f[2] = y[0] + y[1] + y[2] - 1.0;
        }
        fn mass_kind(&self) -> MassKind {
            MassKind::Constant
        }
        fn mass_matrix(&self, _t: f64, _y: &[f64], m: &mut [f64]) {
            m.fill(0.0);
            m[0] = 1.0;
            m[4] = 1.0;
        }
    }
    let opts = Options {
        rtol: 1e-8.into(),
        atol: 1e-12.into(),
        ..Default::default()
    };
    let y = end(Method::Radau5, &RoberDae, 0.3, &[1.0, 0.0, 0.0], &opts);
    let ode = end(Method::Radau5, &robertson(), 0.3, &[1.0, 0.0, 0.0], &opts);
    assert!(max_err(&y, &ode) < 1e-9, "{y:?} vs {ode:?}");
    assert!(max_err(&y, &ROBER_Y03) < 1e-6, "{y:?}");
    // explicit methods refuse a mass matrix
    assert!(solve(
        Method::Dopri5,
        &RoberDae,
        (0.0, 1.0),
        &[1.0, 0.0, 0.0],
        &opts
    )
    .is_err());
}

#[test]
fn auto_switches_to_radau5_on_stiff_problem() {
    let opts = Options {
        rtol: 1e-6.into(),
        atol: 1e-10.into(),
        stiffness_check_interval: 50,
        ..Default::default()
    };
    let sol = solve(
        Method::Auto,
        &robertson(),
        (0.0, 1e3),
        &[1.0, 0.0, 0.0],
        &opts,
    )
    .unwrap();
    eprintln!("{:?}", sol.stats);
    assert_eq!(sol.method, Method::Radau5);
    let ts = sol.stats.stiffness_detected_at.expect("stiffness detected");
    assert!(ts < 1.0, "switched at {ts}");
    assert!(sol.stats.accepted < 2000, "{:?}", sol.stats);
    let (t, y) = sol.last().unwrap();
    assert_eq!(t, 1e3);
    let reference = end(
        Method::Radau5,
        &robertson(),
        1e3,
        &[1.0, 0.0, 0.0],
        &Options {
            rtol: 1e-10.into(),
            atol: 1e-14.into(),
            ..Default::default()
        },
    );
    for i in 0..3 {
        assert!((y[i] - reference[i]).abs() <= 1e-4 * reference[i].abs() + 1e-10);
    }
    // outputs are strictly increasing across the switch
    assert!(sol.t.windows(2).all(|w| w[1] > w[0]));
    // DOPRI5 alone does not get there in 100 times as many steps.
    let capped = Options {
        max_steps: 100 * sol.stats.steps,
        ..opts.clone()
    };
    let d = solve(
        Method::Dopri5,
        &robertson(),
        (0.0, 1e3),
        &[1.0, 0.0, 0.0],
        &capped,
    );
    assert!(matches!(d, Err(pdyn_ode::OdeError::MaxSteps { .. })));
}

#[test]
fn radau5_with_finite_difference_jacobian_on_stiff_van_der_pol() {
    let plain = pdyn_ode::FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
        f[0] = y[1];
        f[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / 1e-6;
    });
    let y = end(
        Method::Radau5,
        &plain,
        2.0,
        &[2.0, 0.0],
        &Options::with_tol(1e-7),
    );
    assert!(max_err(&y, &VDP_STIFF_Y2) < 1e-4, "{y:?}");
}

#[test]
fn state_dependent_mass_matrix() {
    // (1 + y²) y' = −y (1 + y²)  ⇔  y' = −y: exact e^{−t}.
    struct S;
    impl OdeSystem for S {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, _t: f64, y: &[f64], f: &mut [f64]) {
            f[0] = -y[0] * (1.0 + y[0] * y[0]);
        }
        fn mass_kind(&self) -> MassKind {
            MassKind::StateDependent
        }
        fn mass_matrix(&self, _t: f64, y: &[f64], m: &mut [f64]) {
            m[0] = 1.0 + y[0] * y[0];
        }
    }
    for m in [Method::Dopri5, Method::Radau5] {
        let y = end(m, &S, 2.0, &[1.5], &Options::with_tol(1e-10));
        assert!((y[0] - 1.5 * libm::exp(-2.0f64)).abs() < 1e-8, "{m}: {y:?}");
    }
}

/// The Kepler problem (μ = 1) in the plane, `y = (x, y, vx, vy)`.
fn kepler_rhs(_t: f64, y: &[f64], f: &mut [f64]) {
    let r3 = libm::pow(y[0] * y[0] + y[1] * y[1], 1.5);
    f[0] = y[2];
    f[1] = y[3];
    f[2] = -y[0] / r3;
    f[3] = -y[1] / r3;
}

fn oscillator_rhs(_t: f64, y: &[f64], f: &mut [f64]) {
    f[0] = y[1];
    f[1] = -y[0];
}

/// A right-hand side as a plain function.
type Rhs = fn(f64, &[f64], &mut [f64]);

/// A problem with a closed-form end state, and how many times fewer f-evaluations than
/// DOPRI5 `auto` must use at rtol 1e-9.
struct Case {
    sys: pdyn_ode::FnSystem<Rhs>,
    t1: f64,
    y0: Vec<f64>,
    exact: Vec<f64>,
    factor: f64,
}

#[test]
fn auto_picks_the_order_from_rtol_and_halves_the_work_at_tight_tolerances() {
    // A Kepler ellipse of eccentricity 0.7 (a = 1) from pericentre: period 2π, so after two
    // periods the state is the initial one again.
    let e: f64 = 0.7;
    let k0 = vec![1.0 - e, 0.0, 0.0, ((1.0 + e) / (1.0 - e)).sqrt()];
    let t1: f64 = 100.0;
    let cases = [
        Case {
            sys: pdyn_ode::FnSystem::new(2, oscillator_rhs as Rhs),
            t1,
            y0: vec![1.0, 0.0],
            exact: vec![libm::cos(t1), -libm::sin(t1)],
            factor: 2.0,
        },
        Case {
            sys: pdyn_ode::FnSystem::new(4, kepler_rhs as Rhs),
            t1: 4.0 * std::f64::consts::PI,
            y0: k0.clone(),
            exact: k0,
            factor: 1.5,
        },
    ];
    for Case {
        sys,
        t1,
        y0,
        exact,
        factor,
    } in &cases
    {
        let (t1, factor) = (*t1, *factor);
        let opts = Options {
            rtol: 1e-9.into(),
            atol: 1e-12.into(),
            ..Default::default()
        };
        let auto = solve(Method::Auto, sys, (0.0, t1), y0, &opts).unwrap();
        let dopri = solve(Method::Dopri5, sys, (0.0, t1), y0, &opts).unwrap();
        assert_eq!(auto.method, Method::Dop853);
        assert_eq!(Method::auto_explicit(&opts.rtol), Method::Dop853);
        eprintln!("auto {} / dopri5 {}", auto.stats.fevals, dopri.stats.fevals);
        assert!(
            factor * auto.stats.fevals as f64 <= dopri.stats.fevals as f64,
            "auto {} vs dopri5 {} f-evaluations",
            auto.stats.fevals,
            dopri.stats.fevals
        );
        // The cheaper run is as accurate as DOPRI5's against the closed form (global errors
        // are a few hundred rtol over these periods: the tolerance bounds local errors).
        let e = max_err(auto.last().unwrap().1, exact);
        let e_dopri = max_err(dopri.last().unwrap().1, exact);
        eprintln!("errors: auto {e:e}, dopri5 {e_dopri:e}");
        assert!(
            e < 1e-6 && e <= 2.0 * e_dopri,
            "auto error {e:e}, dopri5's {e_dopri:e}"
        );
        // Loose tolerance: DOPRI5 exactly, step for step.
        let loose = Options::with_tol(1e-5);
        let a = solve(Method::Auto, sys, (0.0, t1), y0, &loose).unwrap();
        let d = solve(Method::Dopri5, sys, (0.0, t1), y0, &loose).unwrap();
        assert_eq!(a.method, Method::Dopri5);
        assert_eq!((a.stats.fevals, &a.y), (d.stats.fevals, &d.y));
    }
    // The tightest component decides.
    let mixed = pdyn_ode::Tolerance::from(vec![1e-3, 1e-9]);
    assert_eq!(Method::auto_explicit(&mixed), Method::Dop853);
    // The default rtol 1e-6 takes DOP853; anything looser DOPRI5.
    assert_eq!(Method::auto_explicit(&1e-6.into()), Method::Dop853);
    assert_eq!(Method::auto_explicit(&1.01e-6.into()), Method::Dopri5);
}

#[test]
fn auto_at_tight_tolerance_still_switches_to_radau5_when_stiff() {
    // DOP853's own stiffness detector (h|λ| > 6.1) makes the switch at rtol 1e-9.
    let opts = Options {
        rtol: 1e-9.into(),
        atol: 1e-12.into(),
        stiffness_check_interval: 50,
        ..Default::default()
    };
    let sol = solve(
        Method::Auto,
        &robertson(),
        (0.0, 1e3),
        &[1.0, 0.0, 0.0],
        &opts,
    )
    .unwrap();
    assert_eq!(sol.method, Method::Radau5);
    let ts = sol.stats.stiffness_detected_at.expect("stiffness detected");
    assert!(ts < 1.0, "switched at {ts}");
    let (t, y) = sol.last().unwrap();
    assert_eq!(t, 1e3);
    let reference = end(
        Method::Radau5,
        &robertson(),
        1e3,
        &[1.0, 0.0, 0.0],
        &Options {
            rtol: 1e-12.into(),
            atol: 1e-16.into(),
            ..Default::default()
        },
    );
    for i in 0..3 {
        assert!((y[i] - reference[i]).abs() <= 1e-6 * reference[i].abs() + 1e-12);
    }
}
