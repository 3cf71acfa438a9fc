//! `pdyn run MODEL`: simulate a model file.

use super::{io_error, load_model, set_parameters, Outcome};
use clap::Args;
use pdyn::model_file::Kind;
use pdyn::output::{summary, write_csv};
use pdyn::sim::{self, RunSettings, SimError};
use pdyn::Error;
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

/// The run options the flags give (the library merges them with `[simulate]`).
pub fn request(a: &RunArgs) -> sim::request::Request {
    sim::request::Request {
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
    }
}

/// Derives and compiles the model as the options ask.
pub(crate) fn prepare(model: &mut pdyn_mech::Model, a: &RunArgs) -> Result<sim::Prepared, Error> {
    sim::request::prepare(model, a.jit())
}

/// Merges `[simulate]` and the command line.
pub fn settings(model: &pdyn_mech::Model, a: &RunArgs) -> Result<RunSettings, Error> {
    sim::request::settings(model, &request(a))
}

pub(crate) use sim::request::located as sim_error;

/// `pdyn run MODEL`.
pub fn run(a: RunArgs) -> Result<Outcome, Error> {
    // Read once, told apart once; each kind has its own engine (and its own `--method help`).
    let file = pdyn::model_file::ModelFile::read(&a.model)?;
    match file.kind {
        Kind::Nbody => return super::nbody::run(a, file),
        _ if a.method.as_deref() == Some("help") => return Ok(Outcome::text(sim::methods_help())),
        Kind::Md => return super::md::run(a, file.source),
        Kind::Mechanics => {}
    }
    let mut model = file.mechanics()?;
    set_parameters(&mut model, &a.set)?;
    let mut set = settings(&model, &a)?;
    if a.plot && set.points.is_none() && set.output_dt.is_none() && set.t_eval.is_none() {
        // Plots read better from evenly spaced dense output than from raw steps.
        set.points = Some(2001);
    }
    let prep = prepare(&mut model, &a)?;
    let (res, failure) = sim::request::execute(&mut model, &prep, &set)?;
    let mut stderr = String::new();
    for w in &res.warnings {
        stderr += &format!("warning: {w}\n");
    }
    let mut sum = summary(&res, &model.name, &prep.state_names, set.drift_tolerance);
    if let Some(f) = &failure {
        sum["error"] = f.to_json()["error"].clone();
        // A table with NaN is a failure too, though the integration finished.
        sum["ok"] = false.into();
        if sum["failure"].is_null() {
            sum["failure"] = f.to_string().into();
        }
    }
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).map_err(|e| io_error(dir, "create", e))?;
        let csv = dir.join("trajectory.csv");
        write_csv(&res, &csv).map_err(|e| io_error(&csv, "write", e))?;
        let js = dir.join("summary.json");
        let text = pdyn::output::summary_text(&sum, res.hybrid.as_ref());
        std::fs::write(&js, text).map_err(|e| io_error(&js, "write", e))?;
        if a.plot {
            pdyn::plots::write_run_plots(&model, &prep, &res, dir)?;
        }
    } else if a.plot {
        return Err(Error::argument(
            "--plot",
            "--plot needs --out DIR to write the images into",
        ));
    }
    let stdout = if a.json {
        pdyn::output::summary_text(&sum, res.hybrid.as_ref())
    } else {
        text_report(&model, &res, &set, a.out.as_ref())
    };
    // The process ends after printing: the pool's nodes, the compiled programs and the table
    // are returned by the exit; freeing them one by one was measurable on large models (as
    // in `pdyn derive`).
    std::mem::forget((model, prep, res));
    Ok(Outcome {
        stdout,
        stderr,
        failure,
    })
}

fn text_report(
    model: &pdyn_mech::Model,
    res: &sim::RunResult,
    set: &RunSettings,
    out: Option<&PathBuf>,
) -> String {
    let mut s = format!("{}\n", model.name);
    s += &format!(
        "method {}, t = 0..{}, {} accepted / {} rejected steps, {} f-evaluations, {} output rows\n",
        res.method,
        set.t_end,
        res.stats.accepted,
        res.stats.rejected,
        res.stats.fevals,
        res.rows.len()
    );
    if let Some(last) = res.rows.last() {
        s += "\nfinal values:\n";
        for (c, v) in res.columns.iter().zip(last) {
            s += &format!("  {c:<20} {v:.10e}\n");
        }
    }
    if !res.events.is_empty() {
        s += "\nevents:\n";
        for e in &res.events {
            s += &format!(
                "  {:<16} t = {:.12e} ({})\n",
                e.name,
                e.t,
                if e.rising { "rising" } else { "falling" }
            );
        }
    }
    if let Some(h) = &res.hybrid {
        s += &hybrid_text(h);
    }
    if !res.monitors.is_empty() {
        s += "\nconserved quantities:\n";
        for m in &res.monitors {
            let ok = m.drift <= set.drift_tolerance;
            s += &format!(
                "  {:<20} initial {:.10e}, drift {:.3e} ({}) {}\n",
                m.name,
                m.initial,
                m.drift,
                if m.relative { "relative" } else { "absolute" },
                if ok { "ok" } else { "DRIFTING" }
            );
        }
    }
    if let Some(dir) = out {
        s += &format!(
            "\nwrote {}/trajectory.csv and summary.json\n",
            dir.display()
        );
    }
    s
}

/// Most lines of each list (mode intervals, switches, impacts) in the text report; the whole
/// lists are in `summary.json`.
const HYBRID_LINES: usize = 12;

/// The mode timeline, impacts, Zeno accumulations, event actions and energy accounting of a
/// hybrid run.
fn hybrid_text(h: &sim::hybrid::HybridReport) -> String {
    let mut s = String::new();
    let more = |s: &mut String, total: usize| {
        if total > HYBRID_LINES {
            *s += &format!("  ... {} more in summary.json\n", total - HYBRID_LINES);
        }
    };
    if !h.timeline.is_empty() {
        s += "\ncontact modes:\n";
        for iv in h.timeline.iter().take(HYBRID_LINES) {
            let modes: Vec<String> = iv.modes.iter().map(|(c, m)| format!("{c} {m}")).collect();
            s += &format!(
                "  t = {:.9e} .. {:.9e}  {}\n",
                iv.t_from,
                iv.t_to,
                modes.join(", ")
            );
        }
        more(&mut s, h.timeline.len());
    }
    if !h.switches.is_empty() {
        s += "\nswitches:\n";
        for sw in h.switches.iter().take(HYBRID_LINES) {
            s += &format!(
                "  t = {:.12e}  {}: {} -> {} ({})\n",
                sw.t, sw.contact, sw.from, sw.to, sw.reason
            );
        }
        more(&mut s, h.switches.len());
    }
    if !h.impacts.is_empty() {
        s += &format!("\nimpacts ({}):\n", h.impacts.len());
        for im in h.impacts.iter().take(HYBRID_LINES) {
            s += &format!(
                "  t = {:.12e}  {}: normal speed {:.6e} -> {:.6e}, impulse {:.6e}, energy lost {:.6e}\n",
                im.t, im.contact, im.normal_speed_before, im.normal_speed_after, im.impulse, im.energy_lost
            );
        }
        more(&mut s, h.impacts.len());
    }
    for z in &h.zeno {
        s += &format!(
            "\nZeno: the bounces at `{}` accumulate at t = {:.12e} (ratio {:.9}, {} bounces integrated): resting contact from there\n",
            z.contact, z.t_accumulation, z.ratio, z.bounces
        );
    }
    if !h.actions.is_empty() {
        s += "\nevent actions:\n";
        for a in h.actions.iter().take(HYBRID_LINES) {
            s += &format!("  t = {:.12e}  {}: {}\n", a.t, a.event, a.set.join("; "));
        }
        more(&mut s, h.actions.len());
    }
    s += &format!(
        "\nenergy: work of the contact forces {:.9e}, dissipated by friction {:.9e}, lost in impacts {:.9e}",
        h.work_contacts, h.dissipated_friction, h.dissipated_impacts
    );
    if h.energy_actions != 0.0 {
        s += &format!(", added by event actions {:.9e}", h.energy_actions);
    }
    s += "\n";
    s
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
    let mut model = load_model(&a.model)?;
    set_parameters(&mut model, &a.set)?;
    let set = settings(&model, &a)?;
    let exact = sim::exact::closed_form(&mut model).map_err(|e| {
        sim_error(
            &model,
            "no exact solution to check against: ",
            SimError::NoClosedForm(e),
        )
    })?;
    let prep = prepare(&mut model, &a)?;
    let rep = sim::exact::check(&prep, &exact, &set).map_err(|e| sim_error(&model, "", e))?;
    let (scales, relative) = (rep.scales(), rep.relative_errors());
    let worst = relative.iter().copied().fold(0.0, f64::max);
    if a.json {
        let v = serde_json::json!({
            "model": model.name,
            "method": rep.run.method.to_string(),
            "rows": rep.run.rows.len(),
            "errors": rep.errors.iter().zip(scales.iter().zip(&relative)).map(|((n, e, s), (scale, rel))| serde_json::json!({"name": n, "max_abs_error": e, "max_abs_value": s, "scale": scale, "relative_error": rel})).collect::<Vec<_>>(),
            "max_relative_error": worst,
            "formula_relative_gap": rep.formula_gap,
        });
        let failure = rep.run.failure.clone().map(|failure| Error::Integration {
            origin: model.origin.clone(),
            failure: Box::new(failure),
        });
        return Ok(Outcome {
            stdout: format!("{v:#}\n"),
            stderr: String::new(),
            failure,
        });
    }
    let mut out = format!(
        "{}\n{} vs the closed form at {} times (t = 0..{}):\n",
        model.name,
        rep.run.method,
        rep.run.rows.len(),
        set.t_end
    );
    for ((n, e, s), rel) in rep.errors.iter().zip(&relative) {
        out += &format!(
            "  {n:<12} max |error| {e:.3e}   (max |value| {s:.3e})   relative {rel:.3e}\n"
        );
    }
    out += &format!(
        "largest error relative to the size of the solution: {worst:.3e}\n\
         (each column against the largest max |value| of its order: coordinates together, rates together)\n"
    );
    if let Some(gap) = rep.formula_gap {
        out += &format!(
            "the exact solution is evaluated stably (matrix exponential); the printed formula \
             evaluated in floating point differs from it by {gap:.3e} relative{}\n",
            if gap > sim::exact::EXACT_AGREEMENT {
                " — near a resonance its terms cancel: do not evaluate it as printed"
            } else {
                ""
            }
        );
    }
    let failure = rep.run.failure.clone().map(|failure| Error::Integration {
        origin: model.origin.clone(),
        failure: Box::new(failure),
    });
    Ok(Outcome {
        stdout: out,
        stderr: String::new(),
        failure,
    })
}
