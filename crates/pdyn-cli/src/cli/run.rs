//! `pdyn run MODEL`: simulate a model file.

use super::{load_model, numeric_pairs, set_parameters, Outcome};
use clap::Args;
use pdyn::sim;
use pdyn::{Error, Progress};
use std::io::IsTerminal;
use std::path::PathBuf;

/// `pdyn run`.
#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// The model file (TOML), e.g. examples/satellite.toml.
    pub model: PathBuf,
    /// Integration method (`auto`, `dopri5`/`ode45`, `tsit5`, `dop853`, `radau5`, `rk4`,
    /// `symplectic`, `verlet`, `yoshida4`, `kahanli6`, `kahanli8`, `gauss4`, `gauss6`, or
    /// `exact`: the closed-form solution when the equations are linear with constant coefficients);
    /// `--method help` lists them with their papers.
    #[arg(long)]
    pub method: Option<String>,
    /// Relative tolerance (default 1e-6).
    #[arg(long, allow_negative_numbers = true)]
    pub rtol: Option<f64>,
    /// Absolute tolerance (default 1e-9).
    #[arg(long, allow_negative_numbers = true)]
    pub atol: Option<f64>,
    /// End time (overrides [simulate] t_end).
    #[arg(long = "t-end", alias = "t_end", allow_negative_numbers = true)]
    pub t_end: Option<f64>,
    /// Fixed step (symplectic and RK4 methods), or first step.
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    /// Largest step.
    #[arg(long = "max-step", alias = "max_step", allow_negative_numbers = true)]
    pub max_step: Option<f64>,
    /// Step limit.
    #[arg(long = "max-steps", alias = "max_steps")]
    pub max_steps: Option<usize>,
    /// Output at this many equally spaced times (default: every step).
    #[arg(long)]
    pub points: Option<usize>,
    /// Output every OUTPUT_DT (default: every step).
    #[arg(long = "output-dt", alias = "t_eval_dt", allow_negative_numbers = true)]
    pub output_dt: Option<f64>,
    /// Output exactly at these times, e.g. `--t-eval 0,0.5,1` (SciPy's `t_eval`).
    #[arg(
        long = "t-eval",
        alias = "t_eval",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub t_eval: Vec<f64>,
    /// Warn when a conserved quantity drifts more than this (relative; default 5e-3).
    #[arg(long = "drift-tolerance", allow_negative_numbers = true)]
    pub drift_tolerance: Option<f64>,
    /// Directory for trajectory.csv and summary.json (and plots with --plot).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write plots (SVG and PNG) into --out.
    #[arg(long)]
    pub plot: bool,
    /// Print the JSON summary instead of text.
    #[arg(long)]
    pub json: bool,
    /// Override parameter values, e.g. `--set omega=8.7,d0=0.05`.
    #[arg(long, value_delimiter = ',')]
    pub set: Vec<String>,
    /// Evaluate the equations with the interpreter instead of native code (same results,
    /// slower; for platforms without the JIT or to rule it out).
    #[arg(long = "no-jit")]
    pub no_jit: bool,
    /// Write DIR/checkpoint.json this often: a wall time (`15min`, `30s`, `2h`), a number of
    /// steps (`500steps`), or `off`; default 15min with --out (N-body, MD, and mechanics runs
    /// by an explicit pair such as dopri5 or dop853; see docs/long-runs.md). Also written when
    /// SIGINT/SIGTERM stops the run.
    #[arg(long = "checkpoint-every", value_name = "WHEN")]
    pub checkpoint_every: Option<String>,
    /// Continue the run of this checkpoint bit for bit, appending to the files of --out
    /// (the same model file and options; a foreign or damaged checkpoint is refused, exit 2).
    #[arg(long, value_name = "CHECKPOINT")]
    pub restart: Option<PathBuf>,
}

impl RunArgs {
    /// Native code unless `--no-jit`.
    pub fn jit(&self) -> sim::JitMode {
        if self.no_jit {
            sim::JitMode::Off
        } else {
            sim::JitMode::Auto
        }
    }
}

/// The run options the flags give (the library resolves them against the model file).
pub fn request(a: &RunArgs) -> Result<pdyn::Request, Error> {
    Ok(pdyn::Request {
        method: a.method.clone(),
        rtol: a.rtol,
        atol: a.atol,
        t_end: a.t_end,
        dt: a.dt,
        max_step: a.max_step,
        max_steps: a.max_steps,
        points: a.points,
        output_dt: a.output_dt,
        t_eval: (!a.t_eval.is_empty()).then(|| a.t_eval.clone()),
        drift_tolerance: a.drift_tolerance,
        params: numeric_pairs(&a.set, "--set")?,
        jit: a.jit(),
        out: a.out.clone(),
        plots: a.plot,
        // `run` installs the signal handler and sets it (SIGINT/SIGTERM: a clean stop).
        interrupt: None,
        frame_every: None,
    })
}

/// Steps × particles above which a progress bar is drawn (when stderr is a terminal).
const PROGRESS_WORK: u64 = 20_000_000;

/// `pdyn run MODEL`: the file read once, the request run by `pdyn::run` on the file's kind,
/// the output rendered.
pub fn run(a: RunArgs) -> Result<Outcome, Error> {
    let file = pdyn::model_file::ModelFile::read(&a.model)?;
    if a.method.as_deref() == Some("help") {
        return Ok(Outcome::text(pdyn::engine::methods_help(file.kind)));
    }
    let mut req = request(&a)?;
    req.interrupt = super::interrupt::install();
    // The run's log (an MD run's thermo table) goes live to stderr unless --json.
    let live = !a.json;
    let mut bar = indicatif::ProgressBar::hidden();
    let mut progress = |p: Progress| match p {
        Progress::Started { steps, work }
            if work >= PROGRESS_WORK && std::io::stderr().is_terminal() =>
        {
            bar = indicatif::ProgressBar::new(steps);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{spinner} [{bar:40}] {pos}/{len} steps, {per_sec}, eta {eta}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
        }
        Progress::Step(s) => bar.set_position(s),
        Progress::Log(line) if live => bar.suspend(|| eprintln!("{line}")),
        _ => {}
    };
    let long = pdyn::engine::LongRun {
        // Rows go only to the files as the run goes; plots need the history in memory.
        stream_only: true,
        checkpoint_every: match &a.checkpoint_every {
            Some(text) => Some(pdyn::checkpoint::Every::parse(text).map_err(|m| {
                Error::argument("--checkpoint-every", format!("--checkpoint-every {m}"))
            })?),
            None => None,
        },
        restart: a.restart.clone(),
    };
    let mut output = pdyn::engine::run_long(&file, &req, &long, &mut progress)?;
    bar.finish_and_clear();
    let mut stderr: String = output
        .warnings()
        .iter()
        .map(|w| format!("warning: {w}\n"))
        .collect();
    let unwritten = output.files_needing_a_directory();
    if a.out.is_none() && !unwritten.is_empty() {
        stderr += &format!(
            "warning: no --out DIR: {} not written\n",
            unwritten.join(", ")
        );
    }
    let stdout = if a.json {
        output.summary_text()
    } else {
        output.report(a.out.as_deref())
    };
    let failure = output.take_failure();
    // The process ends after printing: the pool's nodes, the compiled programs and the table
    // are returned by the exit; freeing them one by one was measurable on large models (as
    // in `pdyn derive`).
    std::mem::forget(output);
    Ok(Outcome {
        stdout,
        stderr,
        failure,
    })
}

/// `pdyn check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    #[command(flatten)]
    run: RunArgs,
}

/// `pdyn check MODEL`: integrate numerically and compare with the closed-form solution.
pub fn check(a: CheckArgs) -> Result<Outcome, Error> {
    let a = a.run;
    // The flags are shared with `pdyn run`; these two mean nothing for a check: refused, not
    // ignored.
    for (flag, given) in [
        ("--checkpoint-every", a.checkpoint_every.is_some()),
        ("--restart", a.restart.is_some()),
    ] {
        if given {
            return Err(Error::argument(
                flag,
                format!("{flag} is for `pdyn run`: `pdyn check` writes no checkpoints and continues none"),
            ));
        }
    }
    let mut model = load_model(&a.model)?;
    set_parameters(&mut model, &a.set)?;
    let rep = pdyn::report::check::report(model, &request(&a)?, a.json)?;
    Ok(Outcome {
        stdout: rep.stdout,
        stderr: rep.stderr,
        failure: rep.failure,
    })
}
