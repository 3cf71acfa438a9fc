//! One entry for running a model file of any kind: [`run`] takes the file (read once, its kind
//! told once: [`ModelFile`]) and a kind-neutral [`Request`], resolves the request against the
//! kind's own table in the library, runs the kind's engine, writes the files the request asks
//! for, and returns a typed [`RunOutput`]. The command line and Python render that output;
//! progress comes back through a callback ([`Progress`]), never drawn here.
//!
//! ```text
//! pdyn run / Model.run ─► engine::run ─┬─ Mechanics: sim::request::{settings, prepare, execute}
//!                                      ├─ Nbody:     nbody::request::plan → Planned::execute
//!                                      └─ Md:        md::request::plan → md::build → md::run
//! ```

pub use crate::checkpoint::LongRun;
use crate::model_file::{Kind, ModelFile};
use crate::options::RunOption;
use crate::sim::{self, Prepared, RunResult, RunSettings};
use crate::{md, nbody, output, Error, Request};
use pdyn_mech::Model;
use serde_json::Value;
use std::path::Path;

/// What a run reports while it goes.
#[derive(Debug)]
#[non_exhaustive]
pub enum Progress<'a> {
    /// The run is built and starts: `steps` in all, `work` an estimate of its cost (steps ×
    /// particles) for deciding whether a progress bar is worth drawing.
    Started {
        /// Steps the run will take.
        steps: u64,
        /// Steps × particles.
        work: u64,
    },
    /// Steps completed so far.
    Step(u64),
    /// A line of the run's log (what is simulated, a live thermo row), for a front end that
    /// shows the run as it goes.
    Log(&'a str),
    /// The particles' positions at `time` (an MD run's frames: `Request::frame_every`, else
    /// `dump_every`), for a front end that animates them; coordinates in the model's units.
    Frame {
        /// The time of the frame.
        time: f64,
        /// x of each particle.
        x: &'a [f64],
        /// y of each particle.
        y: &'a [f64],
        /// z of each particle.
        z: &'a [f64],
    },
}

/// A finished mechanics run (or one that stopped early: `failure`).
pub struct MechanicsRun {
    /// The model, with the request's parameters.
    pub model: Model,
    /// Its compiled equations.
    pub prepared: Prepared,
    /// The settings the run used (`[simulate]` merged with the request).
    pub settings: RunSettings,
    /// The table, events, monitors, statistics.
    pub result: RunResult,
    /// `summary.json`.
    pub summary: Value,
    /// The integration's failure, or output columns that hold NaN or infinity.
    pub failure: Option<Error>,
}

/// A finished N-body run.
pub struct NbodyRun {
    /// The model, with the request applied.
    pub spec: nbody::spec::NbodySpec,
    /// What the report prints about the run.
    pub info: nbody::output::RunInfo,
    /// Trajectories, elements, conservation.
    pub result: nbody::run::NbodyResult,
    /// `summary.json`.
    pub summary: Value,
    /// A collision, an escape or a failed step that stopped the run.
    pub failure: Option<Error>,
}

/// A finished molecular-dynamics run.
pub struct MdRun {
    /// The built system (its final state).
    pub prepared: md::Prepared,
    /// Thermo records, RDF, MSD, drift.
    pub result: md::MdResult,
    /// The drift tolerance the verdicts used.
    pub drift_tolerance: f64,
    /// `summary.json`.
    pub summary: Value,
    /// A step that failed (lost atoms, non-finite forces).
    pub failure: Option<Error>,
}

/// The result of [`run`], by kind.
pub enum RunOutput {
    /// Derived equations of motion, integrated.
    Mechanics(Box<MechanicsRun>),
    /// Many-body gravity.
    Nbody(Box<NbodyRun>),
    /// Molecular dynamics.
    Md(Box<MdRun>),
}

impl RunOutput {
    /// `summary.json` (the schema every kind shares: `docs/summary.md`).
    pub fn summary(&self) -> &Value {
        match self {
            RunOutput::Mechanics(r) => &r.summary,
            RunOutput::Nbody(r) => &r.summary,
            RunOutput::Md(r) => &r.summary,
        }
    }

    /// `summary.json` as written.
    pub fn summary_text(&self) -> String {
        match self {
            RunOutput::Mechanics(r) => output::summary_text(&r.summary, r.result.hybrid.as_ref()),
            RunOutput::Nbody(r) => format!("{:#}\n", r.summary),
            RunOutput::Md(r) => format!("{:#}\n", r.summary),
        }
    }

    /// The failure of a run that produced output but stopped early or went non-finite.
    pub fn failure(&self) -> Option<&Error> {
        match self {
            RunOutput::Mechanics(r) => r.failure.as_ref(),
            RunOutput::Nbody(r) => r.failure.as_ref(),
            RunOutput::Md(r) => r.failure.as_ref(),
        }
    }

    /// Takes the failure out (the command line turns it into its exit code).
    pub fn take_failure(&mut self) -> Option<Error> {
        match self {
            RunOutput::Mechanics(r) => r.failure.take(),
            RunOutput::Nbody(r) => r.failure.take(),
            RunOutput::Md(r) => r.failure.take(),
        }
    }

    /// Warnings: drift beyond tolerance, missed crossings, bias.
    pub fn warnings(&self) -> &[String] {
        match self {
            RunOutput::Mechanics(r) => &r.result.warnings,
            RunOutput::Nbody(r) => &r.result.warnings,
            RunOutput::Md(r) => &r.result.warnings,
        }
    }

    /// The text report (`out`: where the files were written, named in its last line).
    pub fn report(&self, out: Option<&Path>) -> String {
        match self {
            RunOutput::Mechanics(r) => {
                sim::report::text_report(&r.model, &r.result, &r.settings, out)
            }
            RunOutput::Nbody(r) => nbody::output::text_report(&r.spec, &r.info, &r.result, out),
            RunOutput::Md(r) => md::report::text_report(&r.prepared, &r.result, out),
        }
    }

    /// Files the model asks for that exist only when written to a directory (MD frames, RDF,
    /// MSD), with the key that asks for each: a run without an output directory loses them.
    pub fn files_needing_a_directory(&self) -> Vec<&'static str> {
        let RunOutput::Md(r) = self else {
            return Vec::new();
        };
        let spec = &r.prepared.spec;
        [
            (spec.dump_every > 0, "traj.xyz (dump_every)"),
            (spec.rdf, "rdf.csv (rdf = true)"),
            (spec.msd, "msd.csv (msd = true)"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, f)| *f)
        .collect()
    }
}

/// The list of methods a kind's `method` takes, with their papers.
pub fn methods_help(kind: Kind) -> String {
    match kind {
        Kind::Mechanics => sim::methods_help(),
        Kind::Nbody => nbody::METHODS_HELP.to_string(),
        Kind::Md => md::METHODS_HELP.to_string(),
    }
}

/// Runs the model `file` as `req` asks: options resolved against the kind's table (refused by
/// name where they have no meaning), the engine run, the files written into `req.out`.
/// A run that stops early is an `Ok` output with its failure set; an `Err` means nothing ran.
pub fn run(
    file: &ModelFile,
    req: &Request,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunOutput, Error> {
    run_long(file, req, &LongRun::default(), progress)
}

/// [`run`] with the options of long runs (issue 29): rows kept only in the files
/// (`stream_only`), checkpoints, a restart from one.
pub fn run_long(
    file: &ModelFile,
    req: &Request,
    long: &LongRun,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunOutput, Error> {
    plots_available(req)?;
    if req.plots && req.out.is_none() {
        return Err(Error::argument(
            RunOption::Plot.name(),
            format!(
                "{} needs {} DIR to write the images into",
                RunOption::Plot,
                RunOption::Out
            ),
        ));
    }
    // Every kind writes checkpoints; what a kind cannot checkpoint (a hybrid mechanics
    // model, an implicit method) it refuses itself, by name.
    Ok(match file.kind {
        Kind::Mechanics => {
            let mut model = file.mechanics_deferring()?;
            crate::params::set_parameter_values(&mut model, &req.params, RunOption::Set.name())?;
            RunOutput::Mechanics(Box::new(run_mechanics_long(model, Some(file), req, long)?))
        }
        Kind::Nbody => RunOutput::Nbody(Box::new(run_nbody(file, req, long, progress)?)),
        Kind::Md => RunOutput::Md(Box::new(run_md(file, req, long, progress)?)),
    })
}

/// Runs a mechanics model already loaded (with its parameters set): Python's `Model` holds
/// one.
pub fn run_mechanics(model: Model, req: &Request) -> Result<MechanicsRun, Error> {
    run_mechanics_long(model, None, req, &LongRun::default())
}

/// [`run_mechanics`] with the options of long runs (`file`: the model's file, which a
/// checkpoint names): the table streamed into `--out`, checkpoints, a restart
/// ([`sim::long_run`]).
fn run_mechanics_long(
    mut model: Model,
    file: Option<&ModelFile>,
    req: &Request,
    long: &LongRun,
) -> Result<MechanicsRun, Error> {
    let mut settings = sim::request::settings(&model, req)?;
    if settings.method == "exact" {
        // The closed form derives the model symbolically: every load.
        sim::net::expand_deferred(&mut model).map_err(|e| sim::request::located(&model, "", e))?;
    }
    if req.plots
        && settings.points.is_none()
        && settings.output_dt.is_none()
        && settings.t_eval.is_none()
    {
        // Plots read better from evenly spaced dense output than from raw steps.
        settings.points = Some(2001);
    }
    let prepared = sim::request::prepare(&mut model, req.jit)?;
    let streamed = sim::long_run::plan(&prepared, &settings, file, req, long)?;
    if let Some(dir) = &req.out {
        // Before the run: a run stopped early still has its directory.
        create_dir(dir)?;
    }
    let (result, failure, long_fields) = match streamed {
        Some(plan) => {
            let s = sim::long_run::execute(&mut model, &prepared, &settings, plan)?;
            (s.result, s.failure, Some((s.checkpoint, s.restarted_from)))
        }
        None => {
            let (result, failure) = sim::request::execute(&mut model, &prepared, &settings)?;
            (result, failure, None)
        }
    };
    let mut summary = output::summary(
        &result,
        &model.name,
        &prepared.state_names,
        settings.drift_tolerance,
    );
    // A run stopped by the front end's interrupt (a signal) is not a numerical failure.
    let failure = match failure {
        Some(Error::Integration { origin, failure })
            if matches!(failure.error, pdyn_ode::OdeError::Interrupted { .. }) =>
        {
            Some(crate::summary::interrupted(
                &mut summary,
                &origin,
                failure.t,
            ))
        }
        f => f,
    };
    if let Some(f) = failure
        .as_ref()
        .filter(|f| !matches!(f, Error::Interrupted { .. }))
    {
        summary["error"] = f.to_json()["error"].clone();
        // A table with NaN is a failure too, though the integration finished.
        summary["ok"] = false.into();
        if summary["failure"].is_null() {
            summary["failure"] = f.to_string().into();
        }
    }
    if let Some((checkpoint, restarted_from)) = &long_fields {
        for (key, value) in [
            ("checkpoint", checkpoint),
            ("restarted_from", restarted_from),
        ] {
            if !value.is_null() {
                summary[key] = value.clone();
            }
        }
    }
    if let Some(dir) = &req.out {
        create_dir(dir)?;
        if long_fields.is_none() {
            let csv = dir.join("trajectory.csv");
            output::write_csv(&result, &csv).map_err(|e| Error::io(&csv, "write", e))?;
        }
        let js = dir.join("summary.json");
        let text = output::summary_text(&summary, result.hybrid.as_ref());
        std::fs::write(&js, text).map_err(|e| Error::io(&js, "write", e))?;
        if req.plots {
            #[cfg(feature = "plots")]
            crate::plots::write_run_plots(&model, &prepared, &result, dir)?;
        }
    }
    Ok(MechanicsRun {
        model,
        prepared,
        settings,
        result,
        summary,
        failure,
    })
}

fn run_nbody(
    file: &ModelFile,
    req: &Request,
    long: &LongRun,
    progress: &mut dyn FnMut(Progress),
) -> Result<NbodyRun, Error> {
    let streaming = long.stream_only && !req.plots;
    let restart = match &long.restart {
        Some(path) => {
            if req.out.is_none() || !streaming {
                return Err(Error::argument(
                    "--restart",
                    "--restart continues the files of --out DIR (and draws no plots: --plot needs the whole history)",
                ));
            }
            Some(crate::checkpoint::read(path, "nbody", file, req)?)
        }
        None => None,
    };
    let planned = nbody::request::plan_with(&file.source, &file.origin, req, streaming)?;
    let trajectory = planned.trajectory;
    // The files are written as the run goes: the directory exists before it starts.
    let mut stream = match (&req.out, &restart) {
        (Some(dir), None) => {
            create_dir(dir)?;
            Some(nbody::output::Stream::create(dir, trajectory, !streaming)?)
        }
        (Some(dir), Some(r)) => {
            let len = |k: usize| r.files.get(k).and_then(serde_json::Value::as_u64);
            Some(nbody::output::Stream::resume(
                dir,
                [len(0), len(1), len(2)],
                false,
            )?)
        }
        (None, _) => None,
    };
    let every = match long.checkpoint_every {
        Some(e) => e,
        None => crate::checkpoint::Every::Seconds(crate::checkpoint::DEFAULT_SECONDS),
    };
    let mut checkpoints = match &req.out {
        Some(dir) if every != crate::checkpoint::Every::Off && long.stream_only => Some(
            crate::checkpoint::Checkpointer::new(dir, every, "nbody", file, req)
                .starting_at(restart.as_ref().map_or(0, |r| r.steps)),
        ),
        _ => None,
    };
    let steps = planned.estimated_steps();
    progress(Progress::Started {
        steps,
        work: steps.saturating_mul(planned.info.n_bodies as u64),
    });
    let (spec, info, result) = planned
        .execute_with(
            stream.as_mut(),
            &mut |s| progress(Progress::Step(s)),
            checkpoints.as_mut(),
            restart.as_ref().map(|r| &r.state),
        )
        .map_err(|e| {
            stopped_writing(
                e,
                req,
                checkpoints
                    .as_ref()
                    .map(|cp| (cp.path().to_path_buf(), cp.last_time)),
            )
        })?;
    let (mut summary, failure) = nbody::output::outcome(&spec, &info, &result);
    crate::checkpoint::add_summary_fields(&mut summary, checkpoints.as_ref(), restart.as_ref());
    if let Some(dir) = &req.out {
        nbody::output::write_summary(dir, &summary)?;
        if req.plots {
            #[cfg(feature = "plots")]
            nbody::plots::write(&spec.name, &result, &spec.units, dir)?;
        }
    }
    Ok(NbodyRun {
        spec,
        info,
        result,
        summary,
        failure,
    })
}

/// An I/O error from an engine that streams its files into `--out`: a write that failed
/// mid-run (a full disk), not bad input ([`Error::WriteDuringRun`], with the checkpoint to
/// continue from, if the run writes them).
fn stopped_writing(
    e: Error,
    req: &Request,
    checkpoint: Option<(std::path::PathBuf, Option<f64>)>,
) -> Error {
    match e {
        Error::Io { .. } if req.out.is_some() => Error::WriteDuringRun {
            error: Box::new(e),
            checkpoint,
        },
        e => e,
    }
}

fn run_md(
    file: &ModelFile,
    req: &Request,
    long: &LongRun,
    progress: &mut dyn FnMut(Progress),
) -> Result<MdRun, Error> {
    let restart = match &long.restart {
        Some(path) => {
            if req.out.is_none() {
                return Err(Error::argument(
                    "--restart",
                    "--restart continues the files of --out DIR",
                ));
            }
            Some(crate::checkpoint::read(path, "md", file, req)?)
        }
        None => None,
    };
    let every = long
        .checkpoint_every
        .unwrap_or(crate::checkpoint::Every::Seconds(
            crate::checkpoint::DEFAULT_SECONDS,
        ));
    let mut checkpoints = match &req.out {
        Some(dir) if every != crate::checkpoint::Every::Off && long.stream_only => Some(
            crate::checkpoint::Checkpointer::new(dir, every, "md", file, req)
                .starting_at(restart.as_ref().map_or(0, |r| r.steps)),
        ),
        _ => None,
    };
    let (spec, drift_tolerance) = md::request::plan(&file.source, &file.origin, req)?;
    // Files named in the model (a lattice, a data file) are relative to the model file.
    let base = Path::new(&file.origin).parent().unwrap_or(Path::new("."));
    let mut prepared = md::build(&spec, base, req.jit).map_err(|error| Error::Model {
        error,
        source: file.source.as_str().into(),
    })?;
    if let Some(dir) = &req.out {
        // Frames are streamed into it as the run goes.
        create_dir(dir)?;
    }
    let atoms = md::build::atoms(&prepared) as u64;
    progress(Progress::Started {
        steps: spec.steps,
        work: atoms.saturating_mul(spec.steps),
    });
    for line in md::report::start_lines(&prepared) {
        progress(Progress::Log(&line));
    }
    let opts = md::RunOptions {
        out: req.out.clone(),
        drift_tolerance,
        interrupt: req.interrupt.clone(),
        frame_every: req.frame_every.unwrap_or(0),
    };
    let result = md::run_with(
        &mut prepared,
        &opts,
        &mut |p| match p {
            md::Progress::Record(r) => progress(Progress::Log(&md::report::thermo_line(r))),
            md::Progress::Step(s) => progress(Progress::Step(s)),
            md::Progress::Frame { step, system } => {
                let p = &system.particles;
                progress(Progress::Frame {
                    time: step as f64 * spec.dt.value,
                    x: &p.x,
                    y: &p.y,
                    z: &p.z,
                })
            }
        },
        checkpoints.as_mut(),
        restart.as_ref(),
    )
    .map_err(|e| {
        stopped_writing(
            e,
            req,
            checkpoints
                .as_ref()
                .map(|cp| (cp.path().to_path_buf(), cp.last_time)),
        )
    })?;
    let (mut summary, failure) =
        md::output::outcome(&prepared, &result, drift_tolerance, &file.origin);
    crate::checkpoint::add_summary_fields(&mut summary, checkpoints.as_ref(), restart.as_ref());
    if let Some(dir) = &req.out {
        md::output::write_all(&result, &summary, dir)?;
        if req.plots {
            #[cfg(feature = "plots")]
            md::output::write_plots(&prepared, &result, dir)?;
        }
    }
    Ok(MdRun {
        prepared,
        result,
        drift_tolerance,
        summary,
        failure,
    })
}

/// A request for plot files is refused by a build without them (WebAssembly), never ignored.
pub(crate) fn plots_available(req: &Request) -> Result<(), Error> {
    if req.plots && !cfg!(feature = "plots") {
        return Err(Error::argument(
            RunOption::Plot.name(),
            "this build of pdyn draws no plot files (built without the `plots` feature)",
        ));
    }
    Ok(())
}

fn create_dir(dir: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create", e))
}
