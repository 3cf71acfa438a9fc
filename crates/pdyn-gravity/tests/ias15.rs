//! IAS15: machine-precision energy on Kepler orbits, Brouwer's law, steps through a zero of
//! a body's acceleration, the outer Solar System.

mod common;

use std::f64::consts::PI;

use pdyn_gravity::{
    Anomaly, Elements, Ias15Params, Integrator, Particle, Primary, Simulation, Units, Vec3,
};

fn kepler_at(e: f64, mean_anomaly: f64) -> Simulation {
    let mut sim = Simulation::new(Units::GEqualsOne);
    sim.add(Particle {
        mass: 1.0,
        pos: Vec3::ZERO,
        vel: Vec3::ZERO,
    })
    .unwrap();
    let el = Elements {
        a: 1.0,
        e,
        inc: 0.2,
        Omega: 0.3,
        omega: 0.4,
        anomaly: Anomaly::Mean(mean_anomaly),
    };
    sim.add_orbit(1e-3, &el, Primary::Interior).unwrap();
    sim.move_to_center_of_mass().unwrap();
    sim.set_integrator(Integrator::Ias15(Ias15Params::default()))
        .unwrap();
    sim.set_dt(1e-3).unwrap();
    sim
}

/// Relative energy error sampled once per orbit over `orbits` orbits.
fn energy_errors(e: f64, orbits: usize) -> (Vec<f64>, u64) {
    energy_errors_at(e, 0.0, orbits)
}

fn energy_errors_at(e: f64, mean_anomaly: f64, orbits: usize) -> (Vec<f64>, u64) {
    let mut sim = kepler_at(e, mean_anomaly);
    let period = 2.0 * PI / 1.001f64.sqrt();
    let e0 = sim.energy();
    let errs = (1..=orbits)
        .map(|k| {
            sim.integrate(k as f64 * period).unwrap();
            ((sim.energy() - e0) / e0).abs()
        })
        .collect();
    (errs, sim.steps())
}

/// Two-body orbits e = 0 … 0.99 (m = 1e-3 about 1, G = 1) over 10³ orbits, sampled every
/// orbit. The step counts equal REBOUND 5.2.2's exactly (same PRS23 controller): 36004,
/// 52002, 98000, 159999. Max |dE/E|: ours 1.3e-14, 1.1e-14, 2.4e-14, 8.6e-13; REBOUND's
/// 3.9e-15, 9.5e-15, 2.4e-14, 2.2e-13. The 1e-14 is thus met by neither code for
/// e ≥ 0.9, and by us only to within a factor 1.3 at e ≤ 0.5.
#[test]
fn kepler_energy_error_is_at_machine_precision() {
    let expected_steps = [36004, 52002, 98000, 159999];
    let bounds = [2e-14, 2e-14, 4e-14, 1.5e-12];
    for (k, &e) in [0.0, 0.5, 0.9, 0.99].iter().enumerate() {
        let (errs, steps) = energy_errors(e, 1000);
        let max = errs.iter().cloned().fold(0.0, f64::max);
        eprintln!("e = {e}: {steps} steps, max |dE/E| over 1000 orbits = {max:.2e}");
        assert_eq!(steps, expected_steps[k]);
        assert!(max <= bounds[k], "e = {e}: {max:e}");
    }
}

/// Brouwer's law: round-off makes the energy error a random walk, `⟨ΔE²⟩ ∝ t`. Over an
/// ensemble of 6 circular orbits (different starting phases, 10³ orbits each), the RMS error
/// over orbits 100–1000 is then √10 ≈ 3.2 times that over orbits 10–100; a linear drift
/// would give ≈ 10. We measure 6.8 (REBOUND 5.2.2 on the same ensemble: 4.9), i.e. growth
/// between √t and t (≈ t^0.8): some bias remains in our round-off. The test guards against
/// anything worse (< 8); it does not prove √t.
#[test]
fn energy_error_grows_no_faster_than_sqrt_t() {
    let (mut early, mut late) = (0.0, 0.0);
    for j in 0..6 {
        let (errs, _) = energy_errors_at(0.0, 1.0 * j as f64, 1000);
        early += errs[9..100].iter().map(|x| x * x).sum::<f64>() / 91.0;
        late += errs[99..1000].iter().map(|x| x * x).sum::<f64>() / 901.0;
    }
    let ratio = (late / early).sqrt();
    eprintln!(
        "ensemble RMS |dE/E|: orbits 10-100 {:.2e}, 100-1000 {:.2e}, ratio {ratio:.2}",
        (early / 6.0).sqrt(),
        (late / 6.0).sqrt()
    );
    assert!(ratio < 8.0);
}

/// A body whose acceleration passes through zero: the figure-eight's middle body at every
/// Euler configuration (t = k T/6). PRS23's timescale `√(2 y₂/(y₃ + √(y₂ y₄)))` then
/// shrinks with the distance to the zero, the steps close in on it geometrically and, on the
/// exact orbit, underflow (`StepSizeUnderflow` at t = T/6 before the floor on y₂ in
/// src/integrators/ias15.rs; 955 steps per period from the 8-digit initial conditions,
/// which miss the zero by ~1e-8). Now both take 229 steps per period, at machine-precision
/// energy (the return to the initial state is tests/figure_eight.rs).
#[test]
fn zero_acceleration_does_not_stall_the_steps() {
    for (sim, t) in [
        (
            common::figure_eight_precise(),
            common::FIGURE_EIGHT_PRECISE_PERIOD,
        ),
        (common::figure_eight(), common::FIGURE_EIGHT_PERIOD),
    ] {
        let mut sim = sim;
        sim.set_integrator(Integrator::Ias15(Ias15Params::default()))
            .unwrap();
        sim.set_dt(1e-3).unwrap();
        let e0 = sim.energy();
        sim.integrate(t).unwrap();
        let de = ((sim.energy() - e0) / e0).abs();
        eprintln!(
            "figure-eight: {} steps per period, |dE/E| {de:.1e}",
            sim.steps()
        );
        assert!(sim.steps() < 300, "{}", sim.steps());
        assert!(de < 1e-14);
    }
}

/// IAS15 on the outer Solar System over 1000 years: machine-precision energy; and the
/// osculating Jacobi semi-major axes of Jupiter and Saturn vary by the same ~6e-4 and ~2e-3
/// as under WHFast (tests/whfast.rs), so that variation is the physics (the Great
/// Inequality), not integration error.
#[test]
fn outer_solar_system_energy() {
    let mut sim = common::outer_solar_system();
    sim.set_integrator(Integrator::Ias15(Ias15Params::default()))
        .unwrap();
    sim.set_dt(10.0).unwrap();
    let e0 = sim.energy();
    let a0 = [1, 2].map(|i| sim.orbit(i, Primary::Interior).unwrap().a);
    let mut da = [0.0f64; 2];
    for k in 1..=200 {
        sim.integrate(1000.0 * 365.25 * k as f64 / 200.0).unwrap();
        for (j, i) in [1, 2].into_iter().enumerate() {
            let a = sim.orbit(i, Primary::Interior).unwrap().a;
            da[j] = da[j].max(((a - a0[j]) / a0[j]).abs());
        }
    }
    let de = ((sim.energy() - e0) / e0).abs();
    eprintln!(
        "outer Solar System, IAS15, 1000 yr: {} steps, |dE/E| {de:.1e}, max |da/a| Jupiter {:.2e}, Saturn {:.2e}",
        sim.steps(),
        da[0],
        da[1]
    );
    assert!(de < 1e-14);
    assert!(da[0] > 3e-4 && da[0] < 1e-3, "{da:?}");
    assert!(da[1] > 1e-3 && da[1] < 3e-3, "{da:?}");
}

/// The figure-eight with `vx3 = v` (10¹⁶ … 10³⁰⁰: a binary moving at v/2, its separation of
/// 1 far below the round-off of its position after a moment): IAS15's step collapses to the
/// round-off of `t`. It crawled on at steps of 10⁻²⁴ for minutes (10²⁰); now the run stops
/// with `StepSizeUnderflow` once `MAX_CRAWL_STEPS` steps in a row are below
/// `MIN_RELATIVE_STEP` of the time: a bounded number of steps, at a time before the end. A fast but representable body (10³)
/// still runs to the end.
#[test]
fn a_step_collapsed_to_the_round_off_of_t_stops_the_run() {
    let run = |v: f64| {
        let mut sim = Simulation::new(Units::GEqualsOne);
        // As `--set vx3=v` makes it: the pair moves at −v/2 together, the third at v.
        let (x1, y1, vy3) = (0.97000436, -0.24308753, -0.86473146);
        for (pos, vel) in [
            ([x1, y1], [-v / 2.0, -vy3 / 2.0]),
            ([-x1, -y1], [-v / 2.0, -vy3 / 2.0]),
            ([0.0, 0.0], [v, vy3]),
        ] {
            sim.add(Particle {
                mass: 1.0,
                pos: Vec3::new(pos[0], pos[1], 0.0),
                vel: Vec3::new(vel[0], vel[1], 0.0),
            })
            .unwrap();
        }
        sim.set_integrator(Integrator::Ias15(Ias15Params::default()))
            .unwrap();
        sim.set_dt(1e-3).unwrap();
        let mut result = Ok(pdyn_gravity::Outcome::Reached);
        for k in 1..=100 {
            result = sim.integrate(0.01 * k as f64 / 100.0);
            if result.is_err() {
                break;
            }
        }
        (result, sim.steps())
    };
    for v in [1e16, 1e18, 1e20, 1e50, 1e300] {
        let (result, steps) = run(v);
        match result {
            Err(pdyn_gravity::GravityError::StepSizeUnderflow { t, dt }) => {
                assert!(t < 0.01 && dt <= pdyn_gravity::MIN_RELATIVE_STEP * 0.01);
                // The crawl, and the steps before it (548 for the whole run at v = 1e3).
                let bound = pdyn_gravity::MAX_CRAWL_STEPS + 20_000;
                assert!(steps < bound, "v = {v}: {steps} steps before stopping");
            }
            other => panic!("v = {v}: {other:?} after {steps} steps"),
        }
    }
    let (result, _) = run(1e3);
    assert!(result.is_ok(), "{result:?}");
}
