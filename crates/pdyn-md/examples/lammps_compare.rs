//! Same-initial-state comparison with LAMMPS: writes the in.lj system (fcc ρ* = 0.8442,
//! T* = 1.44, `cells³·4` atoms) as a LAMMPS data file, runs `steps` NVE steps, and writes the
//! final state as extended XYZ, for `bench/md/compare_lammps.py` to check against LAMMPS
//! started from the same data file.
//!
//! `cargo run --release -p pdyn-md --example lammps_compare -- OUT_DIR [cells=10] [steps=100]`

use pdyn_md::io::{write_lammps_data, write_xyz};
use pdyn_md::potential::{CutoffMode, LennardJones};
use pdyn_md::thermostat::Thermostat;
use pdyn_md::*;
use std::fs::File;
use std::io::BufWriter;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(args.first().map_or(".", |s| s.as_str()));
    let cells: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10);
    let steps: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [cells; 3], 1.0, 1 << 24)?;
    maxwell_boltzmann(&mut p, 1.44, 1.0, 87287)?;
    let system = System::new(p, bx);
    write_lammps_data(
        &mut BufWriter::new(File::create(dir.join("init.data"))?),
        &system,
    )?;
    let ff = ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain));
    let params = SimParams {
        thermo_every: steps,
        ..SimParams::default()
    };
    let mut sim = Simulation::new(system, ff, Thermostat::None, params)?;
    let rep = sim.run(steps, &mut |_: &ThermoRecord, _: &System| {})?;
    let last = rep
        .records
        .last()
        .ok_or("the run recorded no thermo line")?;
    println!(
        "{},{},{},{}",
        last.step, last.temperature, last.total, last.pressure
    );
    write_xyz(
        &mut BufWriter::new(File::create(dir.join("final.xyz"))?),
        &sim.system,
        &["Ar"],
        sim.step,
        last.time,
    )?;
    Ok(())
}
