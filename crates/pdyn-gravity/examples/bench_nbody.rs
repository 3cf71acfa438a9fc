//! Timing runs for `bench/nbody/run.py` (which runs REBOUND on the same problems).
//!
//! ```text
//! cargo run --release -p pdyn-gravity --example bench_nbody -- whfast STEPS
//! cargo run --release -p pdyn-gravity --example bench_nbody -- ias15 YEARS
//! cargo run --release -p pdyn-gravity --example bench_nbody -- whfast-positions YEARS
//! cargo run --release -p pdyn-gravity --example bench_nbody -- plummer-ics N SEED FILE
//! cargo run --release -p pdyn-gravity --example bench_nbody -- leapfrog-direct FILE STEPS DT EPS
//! cargo run --release -p pdyn-gravity --example bench_nbody -- leapfrog-tree FILE STEPS DT EPS THETA QUAD
//! ```
//!
//! Each timing run prints one JSON object. Threads: `RAYON_NUM_THREADS`.

use std::io::Write;
use std::time::Instant;

use pdyn_gravity::plummer::plummer;
use pdyn_gravity::systems::outer_solar_system;
use pdyn_gravity::{
    Gravity, Ias15Params, Integrator, Particle, Primary, Simulation, TreeParams, Units, Vec3,
    WhFastParams,
};

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn arg<T: std::str::FromStr>(args: &[String], i: usize, what: &str) -> Result<T> {
    args.get(i)
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| format!("argument {i} ({what}) missing or invalid").into())
}

fn load(path: &str) -> Result<Simulation> {
    let bytes =
        std::fs::read(path).map_err(|e| format!("cannot read initial conditions {path}: {e}"))?;
    let mut v: Vec<f64> = Vec::with_capacity(bytes.len() / 8);
    for c in bytes.chunks_exact(8) {
        v.push(f64::from_le_bytes(c.try_into()?));
    }
    let mut sim = Simulation::new(Units::GEqualsOne);
    for r in v.chunks_exact(7) {
        sim.add(Particle {
            mass: r[0],
            pos: Vec3::new(r[1], r[2], r[3]),
            vel: Vec3::new(r[4], r[5], r[6]),
        })?;
    }
    Ok(sim)
}

/// The JSON line of a timing run.
fn report(case: &str, sim: &Simulation, secs: f64, de: Option<f64>) -> String {
    // JSON has no NaN: an energy error that was not computed is `null`.
    let de = de.map_or("null".to_string(), |de| format!("{de:.3e}"));
    format!(
        "{{\"case\": \"{case}\", \"steps\": {}, \"seconds\": {secs:.6}, \"per_step_us\": {:.4}, \"rel_energy_error\": {de}, \"threads\": {}}}",
        sim.steps(),
        1e6 * secs / sim.steps() as f64,
        rayon::current_num_threads()
    )
}

/// A timed leapfrog run of `steps` steps of `dt`: the wall-clock seconds of `integrate`
/// alone and, when `energy` is set, the relative energy error `(E − E₀)/|E₀|` (both energies
/// are O(N²) direct sums, computed outside the timed interval).
fn timed_leapfrog(
    sim: &mut Simulation,
    steps: u64,
    dt: f64,
    energy: bool,
) -> Result<(f64, Option<f64>)> {
    let e0 = energy.then(|| sim.energy());
    let t0 = Instant::now();
    sim.integrate(steps as f64 * dt)?;
    let secs = t0.elapsed().as_secs_f64();
    Ok((secs, e0.map(|e0| (sim.energy() - e0) / e0.abs())))
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let out = run(&args)?;
    if !out.is_empty() {
        println!("{out}");
    }
    Ok(())
}

/// One case of the command line (`args[0]` is the program); returns what it prints.
fn run(args: &[String]) -> Result<String> {
    let case = args.get(1).map(String::as_str).unwrap_or("");
    match case {
        "whfast" => {
            let steps: u64 = arg(args, 2, "steps")?;
            let mut sim = outer_solar_system();
            let dt = sim.orbit(1, Primary::Interior)?.period / 20.0;
            sim.set_dt(dt)?;
            sim.set_integrator(Integrator::WhFast(WhFastParams {
                corrector: 17,
                ..WhFastParams::default()
            }))?;
            let e0 = sim.energy();
            let t0 = Instant::now();
            sim.integrate(steps as f64 * dt)?;
            let secs = t0.elapsed().as_secs_f64();
            Ok(report(case, &sim, secs, Some((sim.energy() - e0) / e0)))
        }
        "whfast-positions" => {
            // The benchmark's WHFast run, to a given time; prints the positions (for the
            // agreement check against REBOUND in bench/nbody/run.py).
            let years: f64 = arg(args, 2, "years")?;
            let mut sim = outer_solar_system();
            let dt = sim.orbit(1, Primary::Interior)?.period / 20.0;
            sim.set_dt(dt)?;
            sim.set_integrator(Integrator::WhFast(WhFastParams {
                corrector: 17,
                ..WhFastParams::default()
            }))?;
            sim.integrate(years * 365.25)?;
            let p = sim.particles();
            let pos: Vec<String> = (0..p.len())
                .map(|i| format!("[{:e}, {:e}, {:e}]", p.x[i], p.y[i], p.z[i]))
                .collect();
            Ok(format!(
                "{{\"case\": \"{case}\", \"t\": {:e}, \"dt\": {dt:e}, \"positions\": [{}]}}",
                sim.t(),
                pos.join(", ")
            ))
        }
        "ias15" => {
            let years: f64 = arg(args, 2, "years")?;
            let mut sim = outer_solar_system();
            sim.set_dt(10.0)?;
            sim.set_integrator(Integrator::Ias15(Ias15Params::default()))?;
            let e0 = sim.energy();
            let t0 = Instant::now();
            sim.integrate(years * 365.25)?;
            let secs = t0.elapsed().as_secs_f64();
            Ok(report(case, &sim, secs, Some((sim.energy() - e0) / e0)))
        }
        "plummer-ics" => {
            let n: usize = arg(args, 2, "n")?;
            let seed: u64 = arg(args, 3, "seed")?;
            let path: String = arg(args, 4, "file")?;
            let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
            for p in plummer(n, seed, 1 << 24)? {
                for v in [
                    p.mass, p.pos.0[0], p.pos.0[1], p.pos.0[2], p.vel.0[0], p.vel.0[1], p.vel.0[2],
                ] {
                    f.write_all(&v.to_le_bytes())?;
                }
            }
            Ok(String::new())
        }
        "leapfrog-direct" | "leapfrog-tree" => {
            let path: String = arg(args, 2, "file")?;
            let steps: u64 = arg(args, 3, "steps")?;
            let dt: f64 = arg(args, 4, "dt")?;
            let eps: f64 = arg(args, 5, "softening")?;
            let mut sim = load(&path)?;
            sim.set_softening(eps)?;
            sim.set_integrator(Integrator::Leapfrog)?;
            sim.set_dt(dt)?;
            if case == "leapfrog-tree" {
                let theta: f64 = arg(args, 6, "theta")?;
                let quadrupole: u8 = arg(args, 7, "quadrupole 0/1")?;
                sim.set_gravity(Gravity::Tree(TreeParams {
                    theta,
                    quadrupole: quadrupole == 1,
                }))?;
            }
            // The energy of N = 10^5 by direct summation would take far longer than the
            // tree run itself: only the direct case reports the energy error.
            let (secs, de) = timed_leapfrog(&mut sim, steps, dt, case == "leapfrog-direct")?;
            Ok(report(case, &sim, secs, de))
        }
        _ => Err("usage: see the file's doc comment".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(a: &[&str]) -> Vec<String> {
        std::iter::once("bench_nbody")
            .chain(a.iter().copied())
            .map(String::from)
            .collect()
    }

    /// The direct-summation case reports a finite, small energy error (it printed NaN): the
    /// command line of `bench/nbody/run.py`, on N = 300.
    #[test]
    fn leapfrog_direct_reports_its_energy_error() {
        let dir = std::env::temp_dir().join(format!("bench_nbody_test_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("p300.bin");
        let file = file.to_str().unwrap();
        run(&args(&["plummer-ics", "300", "1", file])).unwrap();
        let out = run(&args(&["leapfrog-direct", file, "10", "0.001", "0.01"])).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        let field = "\"rel_energy_error\": ";
        let start = out.find(field).expect("energy field") + field.len();
        let value = out[start..].split(',').next().unwrap();
        let de: f64 = value.parse().unwrap_or(f64::NAN);
        assert!(out.contains("\"steps\": 10,"), "{out}");
        assert!(de.is_finite() && de != 0.0 && de.abs() < 1e-6, "{out}");
    }
}
