//! The temperature's degrees of freedom: `3N − 3` when the total momentum is conserved, as
//! LAMMPS's `compute temp` (`dof = 3N − extra_dof`, `extra_dof = 3` by default), `3N` under
//! Langevin. Expected values are computed here from the velocities, not from pdyn's record.

mod common;
use common::*;
use pdyn_md::thermostat::*;
use pdyn_md::*;

/// `Σ mᵢ vᵢ²` from the particles' velocities.
fn twice_kinetic(p: &Particles) -> f64 {
    (0..p.len())
        .map(|i| p.m[i] * (p.vx[i].powi(2) + p.vy[i].powi(2) + p.vz[i].powi(2)))
        .sum()
}

#[test]
fn nve_temperature_counts_3n_minus_3_degrees_of_freedom_as_lammps() {
    let mut sim = lj_liquid(4, 87287, 0.005);
    let n = sim.system.particles.len();
    assert_eq!(sim.dof(), (3 * n - 3) as f64);
    // LAMMPS's `velocity all create 1.44 87287` then `thermo`: Temp = 1.44 at step 0
    let r0 = sim.thermo();
    assert!((r0.temperature - 1.44).abs() < 1e-12, "{}", r0.temperature);
    let mut last = None;
    sim.run(30, &mut |r: &ThermoRecord, _: &System| last = Some(*r))
        .unwrap();
    let r = last.unwrap();
    let expected = twice_kinetic(&sim.system.particles) / (3 * n - 3) as f64;
    assert!(
        (r.temperature - expected).abs() < 1e-12 * expected,
        "T = {} expected {expected}",
        r.temperature
    );
    assert_eq!(r.temperature, r.full_step_temperature);
    assert_eq!(sim.kinetic_estimator(), KineticEstimator::FullStep);
}

#[test]
fn langevin_temperature_counts_3n_degrees_of_freedom_from_half_step_velocities() {
    let mut sim = lj_liquid(4, 4, 0.005);
    let th = Langevin::new(LangevinParams {
        temperature: Some(1.0),
        damping: 1.0,
        seed: 2,
    })
    .unwrap();
    sim.thermostat = Thermostat::Langevin(th);
    let n = sim.system.particles.len();
    assert_eq!(sim.dof(), (3 * n) as f64);
    assert_eq!(sim.kinetic_estimator(), KineticEstimator::HalfStep);
    let mut last = None;
    sim.run(10, &mut |r: &ThermoRecord, _: &System| last = Some(*r))
        .unwrap();
    let r = last.unwrap();
    // the full-step column is the velocities now; the reported one is not (it is halfway
    // through the last step)
    let full = twice_kinetic(&sim.system.particles) / (3 * n) as f64;
    assert!((r.full_step_temperature - full).abs() < 1e-12 * full);
    assert_ne!(r.temperature, r.full_step_temperature);
    assert!((r.kinetic - 0.5 * r.temperature * (3 * n) as f64).abs() < 1e-9 * r.kinetic);
}
