//! NVE energy conservation of the LJ liquid of LAMMPS's bench/in.lj (fcc, ρ = 0.8442, T = 1.44,
//! r_c = 2.5σ plain cutoff, skin 0.3σ, dt = 0.005τ): the total energy fluctuates without drift,
//! and halving dt divides the fluctuation by about 4 (velocity Verlet is second order).

mod common;
use common::*;
use pdyn_md::potential::CutoffMode;
use pdyn_md::*;

/// Runs `steps` steps from the state `sim` and returns (times, total energy per atom).
fn energies<P: potential::PairPotential>(
    sim: &mut Simulation<P>,
    steps: u64,
) -> (Vec<f64>, Vec<f64>) {
    let n = sim.system.particles.len() as f64;
    let (mut t, mut e) = (vec![], vec![]);
    sim.run(steps, &mut |r: &ThermoRecord, _: &System| {
        t.push(r.time);
        e.push(r.total / n);
    })
    .unwrap();
    (t, e)
}

/// Equilibrates, then measures drift and fluctuation at dt and dt/2 from the same state.
fn drift_and_scaling(cells: usize, steps: u64, mode: CutoffMode) -> (f64, f64, f64) {
    let mut sim = lj_liquid_mode(cells, 12345, 0.005, mode);
    sim.run(500, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    let start = sim.clone();
    sim.params.thermo_every = 10;
    let (t1, e1) = energies(&mut sim, steps);
    let mut half = start;
    half.params.dt = 0.0025;
    half.params.thermo_every = 20;
    let (t2, e2) = energies(&mut half, 2 * steps);
    // fluctuation about the fitted line, so that a slow drift does not count as fluctuation
    let (s1, s2) = (detrended_std(&t1, &e1), detrended_std(&t2, &e2));
    let drift = slope(&t1, &e1);
    println!(
        "{mode:?} N = {}: slope {drift:.3e} ε/τ per atom, std(E/N) {s1:.3e} at dt=0.005, {s2:.3e} at dt=0.0025, ratio {:.2}",
        sim.system.particles.len(),
        s1 / s2
    );
    (drift, s1, s2)
}

/// 500 atoms × 2000 steps (10 τ), energy shifted at r_c (the same forces, hence the same
/// trajectory, as in.lj's plain cutoff, but without the energy jumps of pairs crossing r_c).
/// Measured: slope 1.6e-5 ε/τ per atom, detrended std(E/N) 8.6e-5 → 2.1e-5, ratio 4.04.
/// Bounds: |slope| < 5e-5 ε/τ per atom; ratio in [3, 5].
#[test]
fn nve_energy_does_not_drift_and_fluctuation_scales_as_dt_squared() {
    let (drift, s1, s2) = drift_and_scaling(5, 2000, CutoffMode::ShiftedEnergy);
    assert!(drift.abs() < 5e-5, "drift {drift}");
    let ratio = s1 / s2;
    assert!((3.0..5.0).contains(&ratio), "ratio {ratio}");
}

/// in.lj exactly (plain cutoff): energy jumps by u(r_c) = −0.0163ε whenever a pair crosses r_c,
/// so the fluctuation does not scale with dt (measured ratio 1.22, std 1.1e-3 per atom), but
/// there is no systematic drift: measured slope 9.4e-5; bound 2e-4 ε/τ per atom.
#[test]
fn nve_plain_cutoff_does_not_drift() {
    let (drift, _, _) = drift_and_scaling(5, 2000, CutoffMode::Plain);
    assert!(drift.abs() < 2e-4, "drift {drift}");
}

/// The full bench/in.lj-sized check: 4000 atoms × 10⁴ steps (50 τ), energy shifted at r_c.
/// Measured (release, 2026-11-23): slope 4.5e-7 ε/τ per atom, detrended std(E/N) 3.1e-5 at
/// dt = 0.005 and 1.0e-5 at 0.0025, ratio 3.04: below 4 because the force still jumps at r_c
/// (by F(r_c) = 0.039 ε/σ), which adds a dt-independent part to the energy error over long runs.
/// Run: `cargo test --release -p pdyn-md --test nve -- --ignored --nocapture`
#[test]
#[ignore]
fn nve_4000_atoms_10k_steps() {
    let (drift, s1, s2) = drift_and_scaling(10, 10_000, CutoffMode::ShiftedEnergy);
    assert!(drift.abs() < 2e-5, "drift {drift}");
    assert!((3.0..5.0).contains(&(s1 / s2)));
}
