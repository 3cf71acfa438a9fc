//! Files and the summary of a run: `thermo.csv`, `rdf.csv`, `msd.csv`, `summary.json`, and
//! the energy/temperature plot. (`traj.xyz` is written during the run, by [`super::run`].)

use super::build::Prepared;
use super::run::{Average, MdResult};
use super::spec::{Ensemble, Units};
use crate::output::json_num;
use crate::Error;
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

fn write(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "write",
        error: Arc::new(e),
    })
}

/// Name of the thermostat of a run, as in the file.
pub fn ensemble_name(e: &Ensemble) -> &'static str {
    match e {
        Ensemble::Nve => "nve",
        Ensemble::Langevin { .. } => "langevin",
        Ensemble::NoseHoover { .. } => "nose-hoover",
        Ensemble::Berendsen { .. } => "berendsen",
    }
}

fn avg_json(a: Option<Average>) -> serde_json::Value {
    match a {
        None => serde_json::Value::Null,
        Some(a) => json!({
            "mean": json_num(a.mean),
            "error": a.error.map(json_num),
            "blocks": a.blocks,
        }),
    }
}

/// The names of a unit system's units, for the summary and the axes of the plots.
pub struct UnitNames {
    /// `lj` or `real`.
    pub name: &'static str,
    /// Energy.
    pub energy: &'static str,
    /// Length.
    pub length: &'static str,
    /// Time.
    pub time: &'static str,
    /// Temperature.
    pub temperature: &'static str,
    /// Pressure.
    pub pressure: &'static str,
}

/// The units of `units` by name.
pub fn unit_names(units: Units) -> UnitNames {
    match units {
        Units::Lj => UnitNames {
            name: "lj",
            energy: "ε",
            length: "σ",
            time: "τ",
            temperature: "ε/k_B",
            pressure: "ε/σ³",
        },
        Units::Real => UnitNames {
            name: "real",
            energy: "kcal/mol",
            length: "Å",
            time: "fs",
            temperature: "K",
            pressure: "atm",
        },
    }
}

/// The JSON summary of a run.
pub fn summary(prep: &Prepared, res: &MdResult, drift_tolerance: f64) -> serde_json::Value {
    let spec = &prep.spec;
    let n = res.atoms.max(1) as f64;
    let last = res.records.last();
    let u = unit_names(spec.units);
    let units = json!({"name": u.name, "energy": u.energy, "length": u.length, "time": u.time, "temperature": u.temperature, "pressure": u.pressure});
    // The conserved energy (the extended one under Nosé–Hoover), when the dynamics has one.
    let name = match spec.thermostat.ensemble {
        Ensemble::NoseHoover { .. } => "energy_with_thermostat",
        _ => "energy",
    };
    let monitors: Vec<crate::summary::Conserved<'_>> = res
        .drift
        .iter()
        .map(|d| crate::summary::Conserved {
            name,
            initial: res.records.first().map_or(f64::NAN, |r| r.conserved),
            final_value: last.map(|r| r.conserved),
            drift: d.relative,
            relative: d.scale > 0.0,
            scale: d.scale,
            tolerance: drift_tolerance,
            conserved: true,
        })
        .collect();
    crate::summary::common(
        "md",
        &spec.name,
        res.failure.as_ref().map(|f| f.to_string()),
        &res.warnings,
        &monitors,
        json!({"steps": res.steps, "neighbor_builds": res.builds}),
        json!({
        "units": units,
        "atoms": res.atoms,
        "species": spec.species.iter().map(|s| json!({"name": s.name, "mass": s.mass.value})).collect::<Vec<_>>(),
        "ensemble": ensemble_name(&spec.thermostat.ensemble),
        "dt": spec.dt.value,
        "steps": res.steps,
        "steps_requested": spec.steps,
        "thermo_every": spec.thermo_every,
        "neighbor_builds": res.builds,
        "trajectory_frames": res.frames,
        "rdf_frames": res.rdf.as_ref().map(|_| res.rdf_frames),
        "formula_native": prep.native,
        "minimized": prep.minimized.map(|m| json!({
            "iterations": m.iterations, "energy": json_num(m.energy),
            "max_force": json_num(m.max_force), "converged": m.converged,
        })),
        "loop_seconds": res.seconds,
        "atom_steps_per_second": if res.seconds > 0.0 { json_num(n * res.steps as f64 / res.seconds) } else { serde_json::Value::Null },
        "final": last.map(|r| json!({
            "step": r.step, "time": json_num(r.time), "temperature": json_num(r.temperature),
            "kinetic": json_num(r.kinetic), "potential": json_num(r.potential),
            "total": json_num(r.total), "pressure": json_num(r.pressure),
            "total_per_atom": json_num(r.total / n),
        })),
        "temperature": {
            "degrees_of_freedom": res.temperature_convention.degrees_of_freedom,
            "rule": if res.temperature_convention.momentum_conserved {
                "3N - 3: the total momentum is conserved (as LAMMPS's compute temp)"
            } else {
                "3N: Langevin forces do not conserve the total momentum (LAMMPS counts 3N - 3)"
            },
            "velocities": res.temperature_convention.estimator.name(),
        },
        "averages_from_step": res.average_from.max(1),
        "averages": {
            "temperature": avg_json(res.average(|r| r.temperature)),
            "pressure": avg_json(res.average(|r| r.pressure)),
            "potential_per_atom": avg_json(res.average(|r| r.potential / n)),
            "total_per_atom": avg_json(res.average(|r| r.total / n)),
        },
        "energy_drift": res.drift.as_ref().map(|d| json!({
            "relative": json_num(d.relative),
            "scale": json_num(d.scale),
            "slope_per_atom": json_num(d.slope_per_atom),
        })),
        }),
    )
}

/// The run's failure as an [`Error`] (`origin` names the model file) and the summary with
/// its `error` object, as `pdyn run --json` prints it and Python's `ParticleResult.summary`
/// holds it.
pub fn outcome(
    prep: &Prepared,
    res: &MdResult,
    drift_tolerance: f64,
    origin: &str,
) -> (serde_json::Value, Option<Error>) {
    let failure = res.failure.clone().map(|error| Error::MdRun {
        origin: origin.to_string(),
        error,
    });
    let mut sum = summary(prep, res, drift_tolerance);
    if let Some(f) = &failure {
        sum["error"] = f.to_json()["error"].clone();
    }
    let failure = failure.or_else(|| {
        res.interrupted.then(|| {
            let time = res.records.last().map_or(0.0, |r| r.time);
            crate::summary::interrupted(&mut sum, origin, time)
        })
    });
    (sum, failure)
}

/// [`write_files`] and `summary.json` (`sum`): what `pdyn run --out DIR` writes.
pub fn write_all(res: &MdResult, sum: &serde_json::Value, dir: &Path) -> Result<(), Error> {
    write_files(res, dir)?;
    crate::output::write_atomic(&dir.join("summary.json"), format!("{sum:#}\n").as_bytes())
}

/// `rdf.csv` and `msd.csv` when computed, into `dir` (`thermo.csv` and `traj.xyz` are
/// written during the run).
pub fn write_files(res: &MdResult, dir: &Path) -> Result<(), Error> {
    // thermo.csv was written as the run went.
    if let Some((r, g)) = &res.rdf {
        // `error`: the standard error of g from 5 blocks of frames, when there are two or more
        let mut s = String::from(if res.rdf_error.is_some() {
            "r,g,error\n"
        } else {
            "r,g\n"
        });
        for (k, (a, b)) in r.iter().zip(g).enumerate() {
            match &res.rdf_error {
                Some(e) => writeln!(s, "{a},{b},{}", e[k]),
                None => writeln!(s, "{a},{b}"),
            }
            .ok();
        }
        write(&dir.join("rdf.csv"), &s)?;
    }
    if !res.msd.is_empty() {
        // `error`: the standard error of the MSD from 5 blocks of particles
        let mut s = String::from("step,time,msd,error\n");
        for (m, e) in res.msd.iter().zip(&res.msd_error) {
            let _ = writeln!(s, "{},{},{},{e}", m[0], m[1], m[2]);
        }
        write(&dir.join("msd.csv"), &s)?;
    }
    Ok(())
}

/// `thermo.svg`/`.png`: energies and temperature against the step.
#[cfg(feature = "plots")]
pub fn write_plots(prep: &Prepared, res: &MdResult, dir: &Path) -> Result<(), Error> {
    use pdyn_plot::{save_grid, Figure, Series};
    if res.records.len() < 2 {
        return Err(Error::argument(
            crate::options::RunOption::Plot.name(),
            "too few thermo records to plot (lower thermo_every)",
        ));
    }
    let n = res.atoms.max(1) as f64;
    let step: Vec<f64> = res.records.iter().map(|r| r.step as f64).collect();
    let col = |f: &dyn Fn(&pdyn_md::ThermoRecord) -> f64| -> Vec<f64> {
        res.records.iter().map(f).collect()
    };
    let u = unit_names(prep.spec.units);
    let energy = Figure {
        title: format!("{}: energy per atom", prep.spec.name),
        x_label: "step".into(),
        y_label: format!("energy per atom [{}]", u.energy),
        series: vec![
            Series::new("kinetic", step.clone(), col(&|r| r.kinetic / n)),
            Series::new("potential", step.clone(), col(&|r| r.potential / n)),
            Series::new("total", step.clone(), col(&|r| r.total / n)),
        ],
        ..Default::default()
    };
    let temp = Figure {
        title: "temperature".into(),
        x_label: "step".into(),
        y_label: format!("T [{}]", u.temperature),
        series: vec![Series::new("T", step.clone(), col(&|r| r.temperature))],
        ..Default::default()
    };
    let pressure = Figure {
        title: "pressure".into(),
        x_label: "step".into(),
        y_label: format!("P [{}]", u.pressure),
        series: vec![Series::new("P", step, col(&|r| r.pressure))],
        ..Default::default()
    };
    let figs = [energy, temp, pressure];
    for ext in ["svg", "png"] {
        let path = dir.join(format!("thermo.{ext}"));
        save_grid(&figs, 1, &path).map_err(|e| Error::Plot {
            path: path.clone(),
            error: e.to_string(),
        })?;
    }
    Ok(())
}
