//! `pdyn run FILE` for an N-body model (a file with a top-level `[nbody]` table): the
//! options mapped onto the table, then load → build → run → write (`pdyn::nbody`).

use super::run::{io_error, RunArgs};
use super::{numeric_pairs, Outcome};
use pdyn::nbody::{self, output, run::Sampling, spec::IntegratorKind};
use pdyn::Error;
use std::path::Path;

/// Most per-body rows a run keeps for `trajectory.csv` (about 1 GB in memory).
const MAX_TRAJECTORY_ROWS: usize = 10_000_000;

/// Most steps a fixed-step run may ask for (days of computing at a microsecond a step).
const MAX_FIXED_STEPS: f64 = 1e11;

/// Whether the file at `path` is an N-body model. A file that cannot be read or is not TOML
/// is not (the mechanics loader then reports why, as for any model).
pub fn is_nbody_file(path: &Path) -> bool {
    std::fs::read_to_string(path).is_ok_and(|s| nbody::spec::is_nbody_source(&s))
}

const HELP: &str = "N-body integrators (integrator = \"...\" in [nbody], or --method):
  whfast    Wisdom-Holman map in Jacobi coordinates with symplectic correctors (Rein & Tamayo
            2015, MNRAS 452, 376); fixed step dt, corrector = 0, 3, 5, 7, 11 or 17. Planetary
            systems dominated by one mass; stops at close encounters (use ias15).
  ias15     Adaptive 15th-order Gauss-Radau (Rein & Spiegel 2015, MNRAS 446, 1424); dt is the
            first trial step, epsilon the accuracy (default 1e-9). Close encounters, high
            eccentricities, machine-precision energy.
  leapfrog  Drift-kick-drift, second order, symplectic, fixed step dt; with gravity = \"tree\"
            (Barnes-Hut, theta) for large N.
";

/// `pdyn run` on an N-body model.
pub fn run(a: RunArgs) -> Result<Outcome, Error> {
    if a.method.as_deref() == Some("help") {
        return Ok(Outcome::text(HELP.into()));
    }
    for (given, option, instead) in [
        (
            a.rtol.is_some(),
            "--rtol",
            "IAS15's accuracy is `epsilon` in [nbody]",
        ),
        (
            a.atol.is_some(),
            "--atol",
            "IAS15's accuracy is `epsilon` in [nbody]",
        ),
        (
            a.max_step.is_some(),
            "--max-step",
            "the fixed-step integrators take --dt",
        ),
        (
            a.max_steps.is_some(),
            "--max-steps",
            "shorten the run with --t-end",
        ),
    ] {
        if given {
            return Err(Error::argument(
                option,
                format!("{option} does not apply to N-body models ({instead})"),
            ));
        }
    }
    let source = Error::read_model_file(&a.model)?;
    let origin = a.model.display().to_string();
    let set = numeric_pairs(&a.set, "--set")?;
    let mut spec = nbody::load(&source, &origin, &set)?;

    if let Some(m) = &a.method {
        spec.integrator = IntegratorKind::from_name(m).ok_or_else(|| {
            Error::argument(
                "--method",
                format!(
                    "--method {m}: N-body models take whfast, ias15 or leapfrog (--method help)"
                ),
            )
        })?;
        if spec.integrator == IntegratorKind::WhFast && spec.tree.is_some() {
            return Err(Error::argument(
                "--method",
                "--method whfast: WHFast with the tree (gravity = \"tree\") is not supported; use leapfrog",
            ));
        }
    }
    if let Some(dt) = a.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::argument(
                "--dt",
                format!("--dt must be > 0 (got {dt})"),
            ));
        }
        spec.dt = Some((dt, 0..0));
    }
    if let Some(t) = a.t_end {
        if !(t.is_finite() && t > 0.0) {
            return Err(Error::argument(
                "--t-end",
                format!("--t-end must be > 0 (got {t})"),
            ));
        }
        spec.t_end = Some(t);
    }
    let drift_tolerance = match a.drift_tolerance {
        Some(d) if !(d.is_finite() && d > 0.0) => {
            return Err(Error::argument(
                "--drift-tolerance",
                format!("--drift-tolerance must be > 0 (got {d})"),
            ))
        }
        Some(d) => d,
        None => spec
            .drift_tolerance
            .unwrap_or(pdyn::sim::DEFAULT_DRIFT_TOLERANCE),
    };
    let Some(t_end) = spec.t_end else {
        return Err(Error::Model {
            error: pdyn_mech::ModelError::new(&origin, spec.table_span.clone(), "no end time")
                .help("t_end = ... in [nbody], or --t-end"),
            source: source.into(),
        });
    };
    let given = [
        (a.points.is_some(), "--points"),
        (a.output_dt.is_some(), "--output-dt"),
        (!a.t_eval.is_empty(), "--t-eval"),
    ];
    if given.iter().filter(|g| g.0).count() > 1 {
        return Err(Error::argument(
            "",
            "give only one of --points, --output-dt and --t-eval",
        ));
    }
    let (sampling, option) = if let Some(n) = a.points {
        (Sampling::Points(n), "--points")
    } else if let Some(dt) = a.output_dt {
        (Sampling::Every(dt), "--output-dt")
    } else if !a.t_eval.is_empty() {
        (Sampling::Times(a.t_eval.clone()), "--t-eval")
    } else if let Some(dt) = spec.output_dt {
        (Sampling::Every(dt), "output_dt")
    } else {
        (Sampling::Points(spec.points.unwrap_or(201)), "points")
    };
    let n_outputs = nbody::run::output_times(t_end, &sampling)
        .map_err(|m| Error::argument(option, format!("{option}: {m}")))?
        .len();

    // A fixed step absurdly small for the span would run for days: say so instead.
    if let (Some((dt, span)), true) = (&spec.dt, spec.integrator != IntegratorKind::Ias15) {
        let steps = t_end / dt;
        if steps > MAX_FIXED_STEPS {
            let message = format!(
                "t_end/dt = {steps:.3e} steps, more than {MAX_FIXED_STEPS:.0e}: dt = {dt} is far too small for t_end = {t_end}"
            );
            return Err(if span.is_empty() {
                Error::argument("--dt", format!("--dt: {message}"))
            } else {
                Error::Model {
                    error: pdyn_mech::ModelError::new(&origin, span.clone(), message),
                    source: source.into(),
                }
            });
        }
    }
    let built = nbody::build(&spec, &source)?;
    let n_bodies = built.sim.len();
    let trajectory = spec
        .trajectory
        .unwrap_or(n_bodies <= nbody::run::TRAJECTORY_LIMIT);
    // Trajectories are kept in memory until written: refuse what would not fit.
    if trajectory && n_bodies.saturating_mul(n_outputs) > MAX_TRAJECTORY_ROWS {
        return Err(Error::argument(
            option,
            format!(
                "{option}: {n_outputs} outputs of {n_bodies} bodies are more than {MAX_TRAJECTORY_ROWS} trajectory rows; \
                 ask for fewer outputs (or trajectory = false)"
            ),
        ));
    }
    let info = output::RunInfo {
        integrator: spec.integrator.name(),
        dt: built.config.dt,
        t_end,
        gravity: match spec.tree {
            None => "direct".into(),
            Some(t) => format!(
                "tree (theta = {}, {})",
                t.theta,
                if t.quadrupole {
                    "quadrupole"
                } else {
                    "monopole"
                }
            ),
        },
        n_bodies,
        drift_tolerance,
    };
    let options = nbody::run::RunOptions {
        t_end,
        sampling,
        drift_tolerance,
        trajectory,
        integrator: spec.integrator,
        collisions: spec.collisions,
        escape: spec
            .escape
            .map_or(nbody::spec::EscapeMode::Stop, |(_, m)| m),
    };
    let res =
        nbody::run::run(built, &options).map_err(|m| Error::argument(option, m.to_string()))?;

    let failure = res.failure.clone().map(|error| Error::Gravity {
        origin: origin.clone(),
        error,
    });
    let mut sum = output::summary(&spec, &info, &res);
    if let Some(f) = &failure {
        sum["error"] = f.to_json()["error"].clone();
    }
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, "create", e))?;
        let write = |name: &str, f: &dyn Fn(&Path) -> std::io::Result<()>| {
            let path = dir.join(name);
            f(&path).map_err(|e| io_error(&path, "write", e))
        };
        if trajectory {
            write("trajectory.csv", &|p| output::write_trajectory(&res, p))?;
            write("elements.csv", &|p| output::write_elements(&res, p))?;
        }
        write("conservation.csv", &|p| output::write_conservation(&res, p))?;
        write("summary.json", &|p| std::fs::write(p, format!("{sum:#}\n")))?;
        if a.plot {
            nbody::plots::write(&spec.name, &res, &spec.units, dir)?;
        }
    } else if a.plot {
        return Err(Error::argument(
            "--plot",
            "--plot needs --out DIR to write the images into",
        ));
    }
    let stdout = if a.json {
        format!("{sum:#}\n")
    } else {
        output::text_report(&spec, &info, &res, a.out.as_deref())
    };
    let stderr: String = res
        .warnings
        .iter()
        .map(|w| format!("warning: {w}\n"))
        .collect();
    Ok(Outcome {
        stdout,
        stderr,
        failure,
    })
}
