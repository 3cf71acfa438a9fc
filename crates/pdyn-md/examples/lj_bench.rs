//! LAMMPS `bench/in.lj` in pdyn-md: fcc at ρ* = 0.8442 (4·n³ atoms), T* = 1.44, LJ cut at 2.5σ,
//! skin 0.3σ, dt = 0.005τ, NVE.
//!
//! `cargo run --release -p pdyn-md --example lj_bench -- [cells=20] [steps=100] [threads=1]
//! [every=20]` prints one CSV line: `atoms,steps,threads,setup_s,loop_s,atom_steps_per_s,pairs_per_s,builds,
//! final_T,final_E_per_atom,final_P,loop_cpu_s`; `pairs_per_s` counts pair interactions inside the cutoff
//! (each pair once) per second. `every = N > 1` rebuilds the neighbour list unconditionally every
//! N steps, as in.lj's `neigh_modify delay 0 every 20 check no` (the same work as LAMMPS);
//! `every = 1` rebuilds when pdyn-md's exact displacement test asks for it, checked every step.
//! `loop_cpu_s` is the CPU time all threads of the process spent in the loop (Linux
//! `/proc/self/task/*/schedstat`; -1 elsewhere): on a machine shared with other jobs it measures
//! the work done, where the wall time also counts the waits for a core.

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
    let every = args.get(3).copied().unwrap_or(20) as u64;
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()?;
    let t0 = Instant::now();
    let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [cells; 3], 1.0, 1 << 26)?;
    maxwell_boltzmann(&mut p, 1.44, 1.0, 87287)?;
    let ff = ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain));
    let params = SimParams {
        thermo_every: 50,
        neighbor_every: every,
        neighbor_check: every <= 1,
        ..SimParams::default()
    };
    let mut sim = Simulation::new(System::new(p, bx), ff, Thermostat::None, params)?;
    let setup = t0.elapsed().as_secs_f64();
    let c1 = cpu_seconds();
    let t1 = Instant::now();
    let rep = sim.run(steps, &mut |_: &ThermoRecord, _: &System| {})?;
    let dt = t1.elapsed().as_secs_f64();
    let cpu = match (c1, cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => -1.0,
    };
    let n = sim.system.particles.len();
    let pairs = sim.pairs_within_cutoff() as f64;
    let last = sim.thermo();
    let nl = sim.neighbor_list();
    eprintln!(
        "clusters {}, cluster pairs {} ({} pair evaluations, {:.1} % of them inside the cutoff)",
        nl.clusters(),
        nl.cluster_pairs(),
        16 * nl.cluster_pairs(),
        100.0 * pairs / (16.0 * nl.cluster_pairs() as f64)
    );
    println!(
        "{n},{steps},{threads},{setup:.4},{dt:.4},{:.4e},{:.4e},{},{:.5},{:.5},{:.5},{cpu:.4}",
        n as f64 * steps as f64 / dt,
        pairs * steps as f64 / dt,
        rep.builds,
        last.temperature,
        last.total / n as f64,
        last.pressure
    );
    Ok(())
}

/// CPU time of every thread of this process so far, in seconds (the first field of each
/// thread's `schedstat`, in nanoseconds); `None` where `/proc` does not have it.
fn cpu_seconds() -> Option<f64> {
    let mut ns = 0u64;
    for t in std::fs::read_dir("/proc/self/task").ok()? {
        let text = std::fs::read_to_string(t.ok()?.path().join("schedstat")).ok()?;
        ns += text.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(ns as f64 * 1e-9)
}
