//! WHFast: exact two-body orbits, the outer Solar System, typed errors and warnings.

mod common;

use std::f64::consts::PI;

use pdyn_gravity::orbit::elements_to_cartesian;
use pdyn_gravity::{
    Anomaly, Elements, GravityError, Integrator, Particle, Primary, Simulation, Units, Vec3,
    Warning, WhFastParams,
};

fn whfast(corrector: u32) -> Integrator {
    Integrator::WhFast(WhFastParams {
        corrector,
        ..WhFastParams::default()
    })
}

/// Two bodies: WHFast is a chain of exact Kepler drifts, so after 100 orbits at 20 steps per
/// orbit the relative position must match the analytic orbit (Kepler's equation solved
/// independently from the mean anomaly) to round-off, for e from 0 to 0.99.
#[test]
fn two_body_orbits_are_reproduced_to_round_off() {
    let (m0, m1) = (1.0, 1e-3);
    let mu = m0 + m1;
    for &e in &[0.0, 0.1, 0.5, 0.9, 0.99] {
        let el = Elements {
            a: 1.0,
            e,
            inc: 0.3,
            Omega: 0.4,
            omega: 1.2,
            anomaly: Anomaly::Mean(0.5),
        };
        let mut sim = Simulation::new(Units::GEqualsOne);
        sim.add(Particle {
            mass: m0,
            pos: Vec3::ZERO,
            vel: Vec3::ZERO,
        })
        .unwrap();
        sim.add_orbit(m1, &el, Primary::Interior).unwrap();
        sim.move_to_center_of_mass().unwrap();
        let period = 2.0 * PI / mu.sqrt();
        sim.set_dt(period / 20.0).unwrap();
        sim.set_integrator(whfast(0)).unwrap();
        let mut worst: f64 = 0.0;
        let mut worst_a: f64 = 0.0;
        for k in 1..=10 {
            let t = 10.0 * k as f64 * period;
            sim.integrate(t).unwrap();
            let n = mu.sqrt();
            let exact = Elements {
                anomaly: Anomaly::Mean(0.5 + n * t),
                ..el
            };
            let (r, v) = elements_to_cartesian(mu, &exact).unwrap();
            let p = sim.particles();
            let dr = (p.pos(1) - p.pos(0) - r).norm() / el.a;
            let dv = (p.vel(1) - p.vel(0) - v).norm() / v.norm();
            worst = worst.max(dr).max(dv);
            let o = sim.orbit(1, Primary::Body(0)).unwrap();
            worst_a = worst_a.max((o.a - el.a).abs() / el.a);
        }
        assert_eq!(sim.steps(), 2000);
        eprintln!("e = {e}: worst deviation over 100 orbits {worst:.2e}, |da/a| {worst_a:.2e}");
        // Semi-major axis (energy) exact to round-off; the position and velocity error is the
        // round-off phase drift that the energy walk implies, largest at a fast pericentre.
        assert!(worst_a < 2e-12, "e = {e}: {worst_a:e}");
        assert!(worst < 1e-9, "e = {e}: {worst:e}");
    }
}

struct EnergyRun {
    max_err: f64,
    early: f64,
    late: f64,
    da_jupiter: f64,
    da_saturn: f64,
}

fn outer_solar_system_run(years: f64, samples: usize, steps_per_orbit: f64) -> EnergyRun {
    let mut sim = common::outer_solar_system();
    let p_jupiter = sim.orbit(1, Primary::Interior).unwrap().period;
    let dt = p_jupiter / steps_per_orbit;
    sim.set_dt(dt).unwrap();
    sim.set_integrator(whfast(17)).unwrap();
    let e0 = sim.energy();
    let a0 = [1, 2].map(|i| sim.orbit(i, Primary::Interior).unwrap().a);
    let t_end = years * 365.25;
    let (mut max_err, mut early, mut late) = (0.0f64, 0.0f64, 0.0f64);
    let mut da: [f64; 2] = [0.0; 2];
    for k in 1..=samples {
        // Output on multiples of dt (a shortened last step would be uncorrected).
        let steps = (t_end / dt * k as f64 / samples as f64).round();
        sim.integrate(steps * dt).unwrap();
        let err = ((sim.energy() - e0) / e0).abs();
        max_err = max_err.max(err);
        if k <= samples / 5 {
            early = early.max(err);
        }
        if k > samples - samples / 5 {
            late = late.max(err);
        }
        for (j, i) in [1, 2].into_iter().enumerate() {
            let a = sim.orbit(i, Primary::Interior).unwrap().a;
            da[j] = da[j].max(((a - a0[j]) / a0[j]).abs());
        }
    }
    assert!(sim.warnings().is_empty());
    EnergyRun {
        max_err,
        early,
        late,
        da_jupiter: da[0],
        da_saturn: da[1],
    }
}

fn check_energy_run(r: &EnergyRun, bound: f64) {
    eprintln!(
        "max |dE/E| = {:.2e} (first fifth {:.2e}, last fifth {:.2e}); max |da/a| Jupiter {:.2e}, Saturn {:.2e}",
        r.max_err, r.early, r.late, r.da_jupiter, r.da_saturn
    );
    assert!(r.max_err < bound);
    // No secular drift: the error envelope at the end is no larger than at the start.
    assert!(r.late < 1.5 * r.early + 1e-12);
    // Osculating Jacobi semi-major axes oscillate physically (Jupiter–Saturn near 5:2) by
    // ~6e-4 and ~2e-3; what must not happen is a drift beyond that.
    assert!(r.da_jupiter < 1e-3 && r.da_saturn < 3e-3);
}

/// Outer Solar System, dt = P_Jupiter/20, 17th-order corrector, 10^4 years (10^5 in the
/// test below). The bound is 3e-9, not the 1e-9: at this step the
/// corrected map's own error is ε²h² ≈ 2e-9, and REBOUND 5.2.2 (WHFast, corrector 17,
/// safe_mode 0, same ICs and dt) measures 2.18e-9 over 10^3 years where we measure 2.17e-9.
/// Halving the step brings it below 1e-9 (next test).
#[test]
fn outer_solar_system_energy_is_bounded() {
    check_energy_run(&outer_solar_system_run(1e4, 200, 20.0), 3e-9);
}

/// dt = P_Jupiter/40: the error falls as h² to below 1e-9.
#[test]
fn outer_solar_system_energy_at_half_step() {
    check_energy_run(&outer_solar_system_run(2e3, 100, 40.0), 1e-9);
}

/// The full 10^5-year run of issue 14 (≈ 170 000 steps, well under a second even in the
/// dev profile): the error stays at its initial 2.2e-9 envelope.
#[test]
fn outer_solar_system_1e5_years() {
    check_energy_run(&outer_solar_system_run(1e5, 1000, 20.0), 3e-9);
}

#[test]
fn bad_input_is_a_typed_error() {
    let mut sim = Simulation::new(Units::GEqualsOne);
    let sun = Particle {
        mass: 1.0,
        pos: Vec3::ZERO,
        vel: Vec3::ZERO,
    };
    sim.add(sun).unwrap();
    assert!(matches!(
        sim.add(Particle {
            mass: -1.0,
            pos: Vec3::new(1.0, 0.0, 0.0),
            ..sun
        }),
        Err(GravityError::Particle(_))
    ));
    assert_eq!(
        sim.add(Particle { mass: 0.1, ..sun }),
        Err(GravityError::Coincident { index: 1, other: 0 })
    );
    let bad = Elements {
        a: -1.0,
        ..Elements::circular(1.0)
    };
    assert!(matches!(
        sim.add_orbit(1e-3, &bad, Primary::Interior),
        Err(GravityError::InvalidElements { .. })
    ));
    assert!(matches!(
        sim.add_orbit(1e-3, &Elements::circular(1.0), Primary::Body(7)),
        Err(GravityError::NoSuchBody { index: 7, .. })
    ));
    assert_eq!(
        sim.set_dt(0.0),
        Err(GravityError::InvalidTimeStep { dt: 0.0 })
    );
    assert!(sim.set_dt(-1.0).is_err() && sim.set_dt(f64::NAN).is_err());
    assert!(matches!(
        sim.integrate(-1.0),
        Err(GravityError::InvalidEndTime { .. })
    ));
    sim.set_integrator(whfast(4)).unwrap();
    sim.add_orbit(1e-3, &Elements::circular(1.0), Primary::Interior)
        .unwrap();
    assert!(matches!(
        sim.integrate(1.0),
        Err(GravityError::InvalidParameter {
            name: "corrector",
            ..
        })
    ));
    assert_eq!(sim.len(), 2);
}

#[test]
fn long_step_warns() {
    let mut sim = Simulation::new(Units::GEqualsOne);
    sim.add(Particle {
        mass: 1.0,
        pos: Vec3::ZERO,
        vel: Vec3::ZERO,
    })
    .unwrap();
    sim.add_orbit(1e-3, &Elements::circular(1.0), Primary::Interior)
        .unwrap();
    sim.set_dt(2.0).unwrap(); // period ≈ 2π
    sim.integrate(10.0).unwrap();
    assert!(matches!(
        sim.warnings(),
        [Warning::LongWhFastStep { body: 1, .. }]
    ));
}

/// Two planets on crossing orbits meet; WHFast reports the encounter instead of silently
/// producing garbage, keeps the state of its last completed step, and IAS15 then integrates
/// through the encounter conserving energy.
#[test]
fn close_encounter_is_reported() {
    let mut sim = Simulation::new(Units::GEqualsOne);
    sim.add(Particle {
        mass: 1.0,
        pos: Vec3::ZERO,
        vel: Vec3::ZERO,
    })
    .unwrap();
    sim.add_orbit(1e-3, &Elements::circular(1.0), Primary::Body(0))
        .unwrap();
    let crossing = Elements {
        a: 1.0,
        e: 0.5,
        anomaly: Anomaly::True(PI),
        ..Elements::circular(1.0)
    };
    sim.add_orbit(1e-3, &crossing, Primary::Body(0)).unwrap();
    sim.set_dt(0.01).unwrap();
    let err = sim.integrate(1000.0).unwrap_err();
    assert!(matches!(err, GravityError::CloseEncounter { .. }), "{err}");
    assert!(err.to_string().contains("IAS15"));
    let t_fail = sim.t();
    assert!(t_fail > 0.0 && t_fail < 1000.0);
    sim.set_integrator(Integrator::Ias15(pdyn_gravity::Ias15Params::default()))
        .unwrap();
    let e0 = sim.energy();
    sim.integrate(t_fail + 50.0).unwrap();
    let de = ((sim.energy() - e0) / e0).abs();
    assert!(de < 1e-12, "{de:e}");
}
