//! LAMMPS `bench/in.lj` in pdyn-md: fcc at ρ* = 0.8442 (4·n³ atoms), T* = 1.44, LJ cut at 2.5σ,
//! skin 0.3σ, dt = 0.005τ, NVE.
//!
//! `cargo run --release -p pdyn-md --example lj_bench -- [cells=20] [steps=100] [threads=1]`
//! prints one CSV line: `atoms,steps,threads,setup_s,loop_s,atom_steps_per_s,pairs_per_s,builds,
//! final_T,final_E_per_atom,final_P`; `pairs_per_s` counts pair interactions inside the cutoff
//! (each pair once) per second.

use pdyn_md::potential::{CutoffMode, LennardJones};
use pdyn_md::thermostat::Thermostat;
use pdyn_md::*;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let cells = args.first().copied().unwrap_or(20);
    let steps = args.get(1).copied().unwrap_or(100) as u64;
    let threads = args.get(2).copied().unwrap_or(1);
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()?;
    let t0 = Instant::now();
    let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [cells; 3], 1.0, 1 << 26)?;
    maxwell_boltzmann(&mut p, 1.44, 1.0, 87287)?;
    let ff = ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain));
    let params = SimParams {
        thermo_every: 50,
        ..SimParams::default()
    };
    let mut sim = Simulation::new(System::new(p, bx), ff, Thermostat::None, params)?;
    let setup = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let rep = sim.run(steps, &mut |_: &ThermoRecord, _: &System| {})?;
    let dt = t1.elapsed().as_secs_f64();
    let n = sim.system.particles.len();
    let pairs = sim.pairs_within_cutoff() as f64;
    let last = sim.thermo();
    println!(
        "{n},{steps},{threads},{setup:.4},{dt:.4},{:.4e},{:.4e},{},{:.5},{:.5},{:.5}",
        n as f64 * steps as f64 / dt,
        pairs * steps as f64 / dt,
        rep.builds,
        last.temperature,
        last.total / n as f64,
        last.pressure
    );
    Ok(())
}
