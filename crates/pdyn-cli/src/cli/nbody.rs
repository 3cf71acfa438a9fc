//! `pdyn run FILE` for an N-body model (a file with a top-level `[nbody]` table): the flags
//! handed to `pdyn::nbody::request` (which resolves them against the table and builds), the
//! run, then the files and the report.

use super::run::RunArgs;
use super::{numeric_pairs, Outcome};
use pdyn::nbody::{self, output};
use pdyn::Error;

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
pub fn run(a: RunArgs, file: pdyn::model_file::ModelFile) -> Result<Outcome, Error> {
    if a.method.as_deref() == Some("help") {
        return Ok(Outcome::text(HELP.into()));
    }
    let (source, origin) = (file.source, file.origin);
    let set = numeric_pairs(&a.set, "--set")?;
    let request = nbody::request::Request {
        method: a.method.clone(),
        dt: a.dt,
        t_end: a.t_end,
        drift_tolerance: a.drift_tolerance,
        points: a.points,
        output_dt: a.output_dt,
        t_eval: a.t_eval.clone(),
        rtol: a.rtol,
        atol: a.atol,
        max_step: a.max_step,
        max_steps: a.max_steps,
    };
    let planned = nbody::request::plan(&source, &origin, &set, &request)?;
    let trajectory = planned.trajectory;
    let (spec, info, res) = planned.execute()?;

    let (sum, failure) = output::outcome(&spec, &info, &res);
    if let Some(dir) = &a.out {
        output::write_files(dir, &res, &sum, trajectory)?;
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
