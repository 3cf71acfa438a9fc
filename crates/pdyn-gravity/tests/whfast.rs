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
    /// Osculating Jacobi semi-major axes of Jupiter and Saturn averaged over the first and
    /// the last `window` of the run: `[start, end]` for each planet (empty without windows).
    mean_a: Vec<[f64; 2]>,
}

/// Steps between samples of `a` inside the averaging windows: 8 × P_J/20 ≈ 4.7 years, more
/// than two samples per period of the shortest large term in `a` (half the Jupiter–Saturn
/// synodic period, ≈ 10 years), so no term aliases to a period near the window's length.
const WINDOW_STRIDE: u64 = 8;

/// Outer Solar System under WHFast (corrector 17) for `years`, sampled at `samples` equally
/// spaced times, and every [`WINDOW_STRIDE`] steps within the first and the last
/// `window_years` (0: no windows).
fn outer_solar_system_run(
    years: f64,
    samples: u64,
    steps_per_orbit: f64,
    window_years: f64,
) -> EnergyRun {
    let mut sim = common::outer_solar_system();
    let p_jupiter = sim.orbit(1, Primary::Interior).unwrap().period;
    let dt = p_jupiter / steps_per_orbit;
    sim.set_dt(dt).unwrap();
    sim.set_integrator(whfast(17)).unwrap();
    let e0 = sim.energy();
    let a0 = [1, 2].map(|i| sim.orbit(i, Primary::Interior).unwrap().a);
    let n_steps = (years * 365.25 / dt).round() as u64;
    let window = (window_years * 365.25 / dt).round() as u64;
    // Output on multiples of dt: the same sequence of full steps however often it samples.
    let mut at: Vec<u64> = (1..=samples).map(|k| n_steps * k / samples).collect();
    if window > 0 {
        at.extend((0..=window / WINDOW_STRIDE).map(|j| j * WINDOW_STRIDE));
        at.extend((0..=window / WINDOW_STRIDE).map(|j| n_steps - window + j * WINDOW_STRIDE));
    }
    at.sort_unstable();
    at.dedup();
    let (mut max_err, mut early, mut late) = (0.0f64, 0.0f64, 0.0f64);
    let mut da: [f64; 2] = [0.0; 2];
    // Per window (start, end): Σ w·a for each planet and Σ w.
    let mut sums = [[0.0f64; 2]; 2];
    let mut weights = [0.0f64; 2];
    for n in at {
        sim.integrate(n as f64 * dt).unwrap();
        let err = ((sim.energy() - e0) / e0).abs();
        max_err = max_err.max(err);
        if n <= n_steps / 5 {
            early = early.max(err);
        }
        if n >= n_steps - n_steps / 5 {
            late = late.max(err);
        }
        let a = [1, 2].map(|i| sim.orbit(i, Primary::Interior).unwrap().a);
        for j in 0..2 {
            da[j] = da[j].max(((a[j] - a0[j]) / a0[j]).abs());
        }
        // Window samples (offsets from the window's start that are multiples of the stride):
        // Hann-weighted, so that the great inequality's partial cycle at the window's edges
        // leaks ~(P/W)³ instead of ~P/W (a plain mean) into the mean.
        for (w, offset) in [Some(n), (n + window).checked_sub(n_steps)]
            .into_iter()
            .enumerate()
        {
            if let Some(k) = offset.filter(|&k| window > 0 && k <= window && k % WINDOW_STRIDE == 0)
            {
                let weight = libm::sin(std::f64::consts::PI * k as f64 / window as f64).powi(2);
                weights[w] += weight;
                for j in 0..2 {
                    sums[w][j] += weight * a[j];
                }
            }
        }
    }
    assert!(sim.warnings().is_empty());
    let mean_a = if window > 0 {
        (0..2)
            .map(|j| [sums[0][j] / weights[0], sums[1][j] / weights[1]])
            .collect()
    } else {
        Vec::new()
    };
    EnergyRun {
        max_err,
        early,
        late,
        da_jupiter: da[0],
        da_saturn: da[1],
        mean_a,
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
    check_energy_run(&outer_solar_system_run(1e4, 200, 20.0, 0.0), 3e-9);
}

/// dt = P_Jupiter/40: the error falls as h² to below 1e-9.
#[test]
fn outer_solar_system_energy_at_half_step() {
    check_energy_run(&outer_solar_system_run(2e3, 100, 40.0, 0.0), 1e-9);
}

/// The full 10^5-year run of issue 14 (≈ 170 000 steps, well under a second even in the
/// dev profile): the energy error stays at its initial 2.2e-9 envelope; and the mean
/// semi-major axes of Jupiter and Saturn stay within 1e-4 of their start.
///
/// The osculating Jacobi `a` swing by 6e-4 (Jupiter) and 2e-3 (Saturn), mostly with the
/// great inequality (near 5:2, period ≈ 900 yr). Averaged with a Hann window over the
/// first and the last 5000 years (a sample every 8 steps, 4.7 yr), the means move by
/// −4.6e-6 (Jupiter) and +2.8e-5 (Saturn); 2500- and 10000-year windows give −4.5e-6 / +2.7e-5
/// and −5.7e-6 / +3.5e-5, plain (unweighted) 5000-year means −8.9e-6 / +5.3e-5. What remains
/// is not drift but a slow exchange of orbital energy between the two planets (terms longer
/// than the windows): the changes of `m/ā` cancel, `Δ(m_J/ā_J) = −Δ(m_S/ā_S)` to 0.4 %
/// (0.02 % and 0.2 % for the other windows), as the total energy is conserved to 2e-9;
/// Laplace–Lagrange theory has no secular change of `a`.
#[test]
fn outer_solar_system_1e5_years() {
    let r = outer_solar_system_run(1e5, 1000, 20.0, 5000.0);
    check_energy_run(&r, 3e-9);
    let sim = common::outer_solar_system();
    let mut d_m_over_a = [0.0; 2];
    for (j, [start, end]) in r.mean_a.into_iter().enumerate() {
        let rel = (end - start) / start;
        let m = sim.particles().get(j + 1).mass;
        d_m_over_a[j] = m / end - m / start;
        eprintln!(
            "body {}: mean a over the first 5000 yr {start:.10}, over the last {end:.10}: relative change {rel:.2e}",
            j + 1
        );
        assert!(rel.abs() <= 1e-4);
    }
    let imbalance = (d_m_over_a[0] + d_m_over_a[1]) / d_m_over_a[0].abs();
    eprintln!(
        "Δ(m/ā): Jupiter {:.3e}, Saturn {:.3e}, imbalance {imbalance:.1e}",
        d_m_over_a[0], d_m_over_a[1]
    );
    assert!(imbalance.abs() < 0.05);
}

/// Landing on an end time that is not a multiple of dt takes one shortened step, corrected
/// like the others (as REBOUND's): the outer Solar System after 1 year (1.69 steps of
/// P_J/20) and after 0.3 years (one step of 0.51 dt) against IAS15. The largest relative
/// position difference is 1.9e-9 and 4.7e-11; with the shortened step uncorrected (before)
/// it was 4.2e-7 after 1 year, and REBOUND's WHFast then differed from ours by as much
/// (bench/nbody/agreement.py; now 1e-14).
#[test]
fn a_shortened_last_step_is_corrected() {
    for (years, bound) in [(1.0, 5e-9), (0.3, 1e-9)] {
        let t = years * 365.25;
        let mut wh = common::outer_solar_system();
        let dt = wh.orbit(1, Primary::Interior).unwrap().period / 20.0;
        wh.set_dt(dt).unwrap();
        wh.set_integrator(whfast(17)).unwrap();
        wh.integrate(t).unwrap();
        let mut reference = common::outer_solar_system();
        reference
            .set_integrator(Integrator::Ias15(pdyn_gravity::Ias15Params::default()))
            .unwrap();
        reference.set_dt(10.0).unwrap();
        reference.integrate(t).unwrap();
        let (p, q) = (wh.particles(), reference.particles());
        let worst = (0..5)
            .map(|i| (p.pos(i) - q.pos(i)).norm() / q.pos(i).norm())
            .fold(0.0, f64::max);
        eprintln!(
            "{years} yr ({:.2} steps): WHFast vs IAS15 positions {worst:.2e}",
            t / dt
        );
        assert!(worst < bound, "{years} yr: {worst:e}");
    }
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

/// Looking at a WHFast run does not change it: the outputs synchronise a copy (REBOUND's
/// `keep_unsynchronized`), so the outer Solar System with the 11th-order corrector, stopped
/// at every other step for output, ends bit for bit where one call to `integrate` ends; and
/// each output equals the state of a run that stops there and synchronises for real.
#[test]
fn outputs_do_not_perturb_the_run() {
    let dt = 4332.59 / 20.0;
    let start = || {
        let mut sim = common::outer_solar_system();
        sim.set_dt(dt).unwrap();
        sim.set_integrator(whfast(11)).unwrap();
        sim
    };
    let steps = 400;
    let t_end = steps as f64 * dt;
    let mut direct = start();
    direct.integrate(t_end).unwrap();
    let mut watched = start();
    for k in 1..=steps / 2 {
        watched.integrate(2.0 * k as f64 * dt).unwrap();
        if k == 50 {
            // A run that ends here has synchronised for real (nothing after it).
            let mut alone = start();
            alone.integrate(100.0 * dt).unwrap();
            for i in 0..5 {
                assert_eq!(watched.particles().pos(i).0, alone.particles().pos(i).0);
                assert_eq!(watched.particles().vel(i).0, alone.particles().vel(i).0);
            }
        }
    }
    assert_eq!(watched.steps(), direct.steps());
    for i in 0..5 {
        assert_eq!(
            watched.particles().pos(i).0,
            direct.particles().pos(i).0,
            "body {i}"
        );
        assert_eq!(
            watched.particles().vel(i).0,
            direct.particles().vel(i).0,
            "body {i}"
        );
    }
}
