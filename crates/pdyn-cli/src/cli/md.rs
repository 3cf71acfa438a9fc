//! `pdyn run FILE` for a molecular-dynamics model (a file with a top-level `[md]` table):
//! flags → `pdyn::md::request::plan` (resolved against the table) → `pdyn::md::{build, run}`
//! → live thermo table, progress bar, files, summary.

use super::run::RunArgs;
use super::{io_error, numeric_pairs, Outcome};
use pdyn::md::{self, Progress, RunOptions};
use pdyn::Error;
use pdyn_mech::ModelError;
use std::io::IsTerminal;
use std::path::Path;

/// Steps × atoms above which a progress bar is shown (when stderr is a terminal).
const PROGRESS_WORK: u64 = 20_000_000;

fn model_err(error: ModelError, source: &str) -> Error {
    Error::Model {
        error,
        source: source.into(),
    }
}

/// `pdyn run` on an `[md]` model.
pub fn run(a: RunArgs, source: String) -> Result<Outcome, Error> {
    let origin = a.model.display().to_string();
    let sets = numeric_pairs(&a.set, "--set")?;
    let request = md::request::Request {
        dt: a.dt,
        t_end: a.t_end,
        drift_tolerance: a.drift_tolerance,
        method: a.method.clone(),
        rtol: a.rtol,
        atol: a.atol,
        max_step: a.max_step,
        max_steps: a.max_steps,
        points: a.points,
        output_dt: a.output_dt,
        t_eval: a.t_eval.clone(),
    };
    let (spec, drift_tolerance) = md::request::plan(&source, &origin, &sets, &request)?;
    if a.plot && a.out.is_none() {
        return Err(Error::argument(
            "--plot",
            "--plot needs --out DIR to write the images into",
        ));
    }
    let base = a.model.parent().unwrap_or(Path::new("."));
    let mut prep = md::build(&spec, base, a.jit()).map_err(|e| model_err(e, &source))?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, "create", e))?;
    }
    let n = md::build::atoms(&prep) as u64;
    let work = n.saturating_mul(spec.steps);
    let bar = if work >= PROGRESS_WORK && std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(spec.steps);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{spinner} md [{bar:40}] {pos}/{len} steps, {per_sec}, eta {eta}",
        ) {
            b.set_style(style.progress_chars("=> "));
        }
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let live = !a.json;
    if live {
        eprintln!(
            "{}: {n} atoms, {} steps of dt = {}, {}",
            spec.name,
            spec.steps,
            spec.dt.value,
            md::output::ensemble_name(&spec.thermostat.ensemble)
        );
        if let Some(m) = &prep.minimized {
            eprintln!(
                "minimised (FIRE): {} iterations, U = {:.6}, max |F| = {:.3e}{}",
                m.iterations,
                m.energy,
                m.max_force,
                if m.converged { "" } else { " (not converged)" }
            );
        }
        bar.suspend(|| {
            eprintln!(
                "{:>10} {:>12} {:>14} {:>14} {:>14} {:>12}",
                "step", "T", "KE", "PE", "E", "P"
            )
        });
    }
    let opts = RunOptions {
        out: a.out.clone(),
        drift_tolerance,
    };
    let mut progress = |p: Progress| match p {
        Progress::Record(r) if live => bar.suspend(|| {
            eprintln!(
                "{:>10} {:>12.6} {:>14.6} {:>14.6} {:>14.6} {:>12.6}",
                r.step, r.temperature, r.kinetic, r.potential, r.total, r.pressure
            )
        }),
        Progress::Step(s) => bar.set_position(s),
        _ => {}
    };
    let res = md::run(&mut prep, &opts, &mut progress)?;
    bar.finish_and_clear();
    let (sum, failure) = md::output::outcome(&prep, &res, drift_tolerance, &origin);
    if let Some(dir) = &a.out {
        md::output::write_all(&res, &sum, dir)?;
        if a.plot {
            md::output::write_plots(&prep, &res, dir)?;
        }
    }
    let mut stderr = String::new();
    for w in &res.warnings {
        stderr += &format!("warning: {w}\n");
    }
    if a.out.is_none() {
        let files: Vec<&str> = [
            (spec.dump_every > 0, "traj.xyz (dump_every)"),
            (spec.rdf, "rdf.csv (rdf = true)"),
            (spec.msd, "msd.csv (msd = true)"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, f)| *f)
        .collect();
        if !files.is_empty() {
            stderr += &format!("warning: no --out DIR: {} not written\n", files.join(", "));
        }
    }
    let stdout = if a.json {
        format!("{sum:#}\n")
    } else {
        text_report(&prep, &res, a.out.as_deref())
    };
    Ok(Outcome {
        stdout,
        stderr,
        failure,
    })
}

fn text_report(prep: &md::Prepared, res: &md::MdResult, out: Option<&Path>) -> String {
    let n = res.atoms.max(1) as f64;
    let mut s = format!("{}\n", prep.spec.name);
    s += &format!(
        "{} atoms, {} steps ({} neighbour-list builds) in {:.3} s, {:.3e} atom-steps/s\n",
        res.atoms,
        res.steps,
        res.builds,
        res.seconds,
        if res.seconds > 0.0 {
            n * res.steps as f64 / res.seconds
        } else {
            0.0
        }
    );
    if let Some(r) = res.records.last() {
        s += &format!(
            "final: step {}  T = {:.6}  E/N = {:.8}  PE/N = {:.8}  P = {:.6}\n",
            r.step,
            r.temperature,
            r.total / n,
            r.potential / n,
            r.pressure
        );
    }
    let fmt = |name: &str, a: Option<md::run::Average>| match a {
        Some(md::run::Average {
            mean,
            error: Some(e),
            ..
        }) => format!("  {name:<12} {mean:.6} ± {e:.2e}\n"),
        Some(a) => format!("  {name:<12} {:.6}\n", a.mean),
        None => String::new(),
    };
    let avg = fmt("T", res.average(|r| r.temperature))
        + &fmt("P", res.average(|r| r.pressure))
        + &fmt("E/N", res.average(|r| r.total / n));
    if !avg.is_empty() {
        s += "averages (block error bars):\n";
        s += &avg;
    }
    if let Some(d) = &res.drift {
        s += &format!(
            "energy drift: {:.3e} of the mean kinetic energy, slope {:.3e} per atom per time unit\n",
            d.relative, d.slope_per_atom
        );
    }
    if let Some(dir) = out {
        s += &format!("wrote {}/thermo.csv and summary.json", dir.display());
        if res.frames > 0 {
            s += &format!(", traj.xyz ({} frames)", res.frames);
        }
        if res.rdf.is_some() {
            s += ", rdf.csv";
        }
        if !res.msd.is_empty() {
            s += ", msd.csv";
        }
        s += "\n";
    }
    s
}
