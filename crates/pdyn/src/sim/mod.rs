//! `pdyn run`: integrate a model's equations of motion and check the result.
//!
//! [`prepare`] derives and compiles once (equations, events, output columns, conserved
//! quantities); [`run`] integrates with given settings and returns a table, the events, the
//! drift of every monitored quantity and warnings. Sweeps and ensembles run many times on
//! clones of one [`Prepared`] through [`measured::measure`], which gives what they keep of a
//! run (measures, last point, first event hits, drifts, status) without the table.
//!
//! The First Law of Scientific Computing (chapter 3.3.3): a result that violates a conservation
//! law is flagged. Energy is monitored when every force derives from a potential (or is a
//! reaction) and nothing depends explicitly on time; angular momentum about the origin and
//! linear momentum components when the resultant moment or force vanishes identically.

pub mod compiled;
pub mod ensemble;
mod error;
pub mod exact;
pub mod hybrid;
pub mod linearize;
pub mod long_run;
pub mod measured;
pub mod net;
#[cfg(test)]
mod observer_scales_tests;
pub mod report;
pub mod request;
pub mod sweep;
#[cfg(test)]
mod tree_tests;

pub use error::{ClosedFormError, RunFailure, SimError};

use crate::options::RunOption;
use compiled::{CompiledModel, Observer};
use measured::report;
use pdyn_expr::{Id, Pool};
pub use pdyn_jit::JitMode;
use pdyn_mech::model::spec::{Crossing, SimulateSpec};
use pdyn_mech::parameters::DerivedParameters;
use pdyn_mech::validity::{InvalidValue, ValueChecks};
use pdyn_mech::{derive, DeriveOptions, Model};
use pdyn_ode::{Direction, Event, Method, MethodKind, Options, Solution};
use std::fmt;

/// Settings of one run: the model's `[simulate]` with command-line overrides applied.
#[derive(Clone, Debug)]
pub struct RunSettings {
    /// Method name (`auto`, `dopri5`, `symplectic`, ...).
    pub method: String,
    /// End time.
    pub t_end: f64,
    /// Relative tolerance (pdyn-ode default 1e-6).
    pub rtol: Option<f64>,
    /// Absolute tolerance (pdyn-ode default 1e-9).
    pub atol: Option<f64>,
    /// Fixed step, or first step of an adaptive method.
    pub dt: Option<f64>,
    /// Largest step.
    pub max_step: Option<f64>,
    /// Step limit.
    pub max_steps: Option<usize>,
    /// Equally spaced output points.
    pub points: Option<usize>,
    /// Output interval.
    pub output_dt: Option<f64>,
    /// Output exactly at these times (SciPy's `t_eval`), through dense output.
    pub t_eval: Option<Vec<f64>>,
    /// Relative drift of a conserved quantity that triggers a warning. Default 5e-3 (0.5 %):
    /// DOPRI5 at rtol 1e-3 on the chapter's satellite drifts by 7 (warns), at rtol 1e-5 by 1e-3.
    pub drift_tolerance: f64,
    /// Set by another thread to stop the run at its next step (Ctrl-C in Python): the result
    /// keeps the rows computed, with an `Interrupted` failure.
    pub interrupt: Option<pdyn_ode::Interrupt>,
}

impl RunSettings {
    /// Settings from a model's `[simulate]` (method `auto` unless given); `t_end` is required.
    pub fn from_spec(s: &SimulateSpec) -> Result<RunSettings, SimError> {
        Self::resolve(s, &SimulateSpec::default(), None)
    }

    /// `[simulate]` of the model file with `overrides` (the command line's options, a Python
    /// call's keywords) taking precedence field by field, then the defaults.
    pub fn resolve(
        file: &SimulateSpec,
        overrides: &SimulateSpec,
        t_eval: Option<Vec<f64>>,
    ) -> Result<RunSettings, SimError> {
        let (o, s) = (overrides, file);
        Ok(RunSettings {
            method: o
                .method
                .as_ref()
                .or(s.method.as_ref())
                .map_or("auto".to_string(), |m| m.0.clone()),
            t_end: o.t_end.or(s.t_end).ok_or(SimError::NoEndTime)?,
            rtol: o.rtol.or(s.rtol),
            atol: o.atol.or(s.atol),
            dt: o.dt.or(s.dt),
            max_step: o.max_step.or(s.max_step),
            max_steps: o.max_steps.or(s.max_steps),
            points: o.points.or(s.points),
            output_dt: o.output_dt.or(s.output_dt),
            t_eval,
            drift_tolerance: o
                .drift_tolerance
                .or(s.drift_tolerance)
                .unwrap_or(DEFAULT_DRIFT_TOLERANCE),
            interrupt: None,
        })
    }

    /// The value of column `name` in the last row of a result.
    pub fn final_value(res: &RunResult, name: &str) -> Option<f64> {
        let j = res.columns.iter().position(|c| c == name)?;
        res.rows.last().map(|r| r[j])
    }
}

/// Largest number of output rows a run may produce (`--points`, `t_end/--output-dt`,
/// `--t-eval`): 10⁷ rows of a few columns is already gigabytes of CSV.
pub const MAX_OUTPUT_ROWS: usize = 10_000_000;

/// Largest number of fixed steps a run may be asked to take (`t_end/--dt`).
pub const MAX_FIXED_STEPS: f64 = 1e10;

impl RunSettings {
    /// The output times asked for (`t_eval`, `points` or `output_dt`, in that order), or
    /// `None` for output at every step. Call after [`RunSettings::validate`] (sizes).
    pub fn output_times(&self) -> Option<Vec<f64>> {
        let t_end = self.t_end;
        if let Some(ts) = &self.t_eval {
            Some(ts.clone())
        } else if let Some(n) = self.points {
            Some((0..n).map(|k| t_end * k as f64 / (n - 1) as f64).collect())
        } else {
            self.output_dt.map(|dt| {
                let steps = (t_end / dt).floor() as usize;
                let mut ts: Vec<f64> = (0..=steps).map(|k| k as f64 * dt).collect();
                if ts.last().is_some_and(|&l| l < t_end * (1.0 - 1e-12)) {
                    ts.push(t_end);
                }
                ts
            })
        }
    }

    /// Checks every setting against its valid range, naming the option. Sizes are checked
    /// here, before anything is allocated.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |option: RunOption, value: f64, requirement: &str| {
            let value = if value != 0.0 && !(1e-4..1e7).contains(&value.abs()) {
                format!("{value:e}")
            } else {
                value.to_string()
            };
            Err(SimError::InvalidOption {
                option,
                value,
                requirement: requirement.to_string(),
            })
        };
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return Err(SimError::InvalidEndTime(self.t_end));
        }
        for (option, v) in [(RunOption::Rtol, self.rtol), (RunOption::Atol, self.atol)] {
            if let Some(v) = v {
                if !(v.is_finite() && v >= 0.0) {
                    return bad(option, v, "a finite number >= 0");
                }
            }
        }
        if self.rtol == Some(0.0) && self.atol == Some(0.0) {
            return bad(
                RunOption::Atol,
                0.0,
                &format!("> 0 when {} is 0", RunOption::Rtol),
            );
        }
        for (option, v) in [
            (RunOption::Dt, self.dt),
            (RunOption::MaxStep, self.max_step),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return bad(option, v, "a finite time > 0");
                }
            }
        }
        if let Some(dt) = self.dt {
            if self.t_end / dt > MAX_FIXED_STEPS {
                return bad(
                    RunOption::Dt,
                    dt,
                    &format!(
                        "at least t_end/{MAX_FIXED_STEPS:e} = {:e}",
                        self.t_end / MAX_FIXED_STEPS
                    ),
                );
            }
        }
        if let Some(n) = self.points {
            if !(2..=MAX_OUTPUT_ROWS).contains(&n) {
                return bad(
                    RunOption::Points,
                    n as f64,
                    &format!("between 2 and {MAX_OUTPUT_ROWS}"),
                );
            }
        }
        if let Some(h) = self.output_dt {
            if !(h.is_finite() && h > 0.0) {
                return bad(RunOption::OutputDt, h, "a finite time > 0");
            }
            if self.t_end / h > MAX_OUTPUT_ROWS as f64 {
                return bad(
                    RunOption::OutputDt,
                    h,
                    &format!(
                        "at least t_end/{MAX_OUTPUT_ROWS} = {:e} (at most {MAX_OUTPUT_ROWS} output rows)",
                        self.t_end / MAX_OUTPUT_ROWS as f64
                    ),
                );
            }
        }
        if let Some(ts) = &self.t_eval {
            if ts.len() > MAX_OUTPUT_ROWS {
                return bad(
                    RunOption::TEval,
                    ts.len() as f64,
                    &format!("at most {MAX_OUTPUT_ROWS} times"),
                );
            }
            if ts.iter().any(|&x| !(0.0..=self.t_end).contains(&x))
                || ts.windows(2).any(|w| w[1] <= w[0])
            {
                return Err(SimError::InvalidTEval { t_end: self.t_end });
            }
        }
        if !(self.drift_tolerance.is_finite() && self.drift_tolerance > 0.0) {
            return bad(
                RunOption::DriftTolerance,
                self.drift_tolerance,
                "a finite number > 0",
            );
        }
        Ok(())
    }
}

/// Default [`RunSettings::drift_tolerance`].
pub const DEFAULT_DRIFT_TOLERANCE: f64 = 5e-3;

/// A model compiled for running.
#[derive(Clone)]
pub struct Prepared {
    /// The equations as an ODE system.
    pub system: CompiledModel,
    /// Output columns after `t` and the state: positions, reactions, monitors.
    pub observer: Observer,
    /// Which observer outputs are conserved quantities (checked for drift).
    pub conserved: Vec<bool>,
    /// The physical scale of each conserved quantity, in the order they appear among the
    /// observer outputs (see [`pdyn_mech::conservation::Conserved::scale`]).
    pub scales: Observer,
    /// Names of the state components.
    pub state_names: Vec<String>,
    /// Physical requirements on the parameter values (masses > 0), checked before each run.
    pub value_checks: Option<ValueChecks>,
    /// Initial state.
    pub y0: Vec<f64>,
    /// `y0` was set from outside the model file ([`request::set_initial`]): the closed form,
    /// which solves for the file's initial conditions, does not apply.
    pub initial_overridden: bool,
    /// The model's `[[events]]`, compiled.
    pub events: Vec<PreparedEvent>,
    /// Sweep measures: observer over the same inputs.
    pub measures: Option<Observer>,
    /// Notes from the derivation.
    pub notes: Vec<String>,
    /// Initial state as a function of the parameters (for sweeps).
    pub initial_conditions: Observer,
    /// Parameter names, in model order.
    pub parameter_names: Vec<String>,
    /// Parameters defined by others (`m = "4/3*pi*a^3*rho"`), recomputed for each sweep run.
    pub derived: DerivedParameters,
    /// `(F·v_slip, |F| |v_slip|)` of each sliding friction drawn with `opposes`, over the
    /// observation inputs: a run warns when one does positive work on the slip.
    pub friction_power: Option<Observer>,
    /// Reactions declared `one_sided`: name and index among the output columns after `t`
    /// and the state.
    pub one_sided: Vec<(String, usize)>,
    /// Contacts and event actions: the run switches between modes ([`hybrid`]); `system`
    /// and `observer` are then those of one reference mode, for the names and initial state.
    pub hybrid: Option<Box<hybrid::Hybrid>>,
}

impl Prepared {
    /// Output columns, conservation scales, measures and events as native code (the
    /// right-hand side already is, from [`prepare`]): a sweep or an ensemble evaluates them at
    /// every output point of every run, and compiling them once pays there. The same results
    /// bit for bit. Both front ends call it before a sweep or an ensemble.
    pub fn make_observers_native(&mut self) {
        self.observer.make_native();
        self.scales.make_native();
        if let Some(m) = self.measures.as_mut() {
            m.make_native();
        }
        for e in &mut self.events {
            e.function.make_native();
        }
    }

    /// The columns of a run's table ([`RunResult::columns`]): `t`, the state, the output
    /// columns.
    pub fn columns(&self) -> Vec<String> {
        let mut columns = vec!["t".to_string()];
        columns.extend(self.state_names.iter().cloned());
        match &self.hybrid {
            Some(h) => columns.extend(h.column_names.iter().cloned()),
            None => columns.extend(self.observer.names.iter().cloned()),
        }
        columns
    }

    /// Sets every parameter value (in model order, as [`Prepared::parameter_names`]) and
    /// recomputes the initial state from them, in place: one run of an ensemble. The values
    /// are taken as given: recompute the derived ones first with [`Prepared::derived`]. They
    /// are checked (masses > 0) when the model runs.
    pub fn set_parameters(&mut self, values: &[f64]) {
        self.system.set_parameters(values);
        let mut y0 = std::mem::take(&mut self.y0);
        self.initial_conditions.eval(values, &mut y0);
        self.y0 = y0;
    }

    /// Checks parameter values (in model order) against the model's physical requirements
    /// (every mass finite and > 0) without running anything.
    pub fn check_parameters(&self, values: &[f64]) -> Result<(), InvalidValue> {
        match &self.value_checks {
            Some(c) => c.check(values),
            None => Ok(()),
        }
    }

    /// A copy with the parameters `(index, value)` set, the derived parameters that depend on
    /// them and the initial conditions recomputed.
    pub fn with_parameters(&self, given: &[(usize, f64)]) -> Prepared {
        let mut p = self.clone();
        let mut params = p.system.parameters();
        for &(index, value) in given {
            if let Some(x) = params.get_mut(index) {
                *x = value;
            }
        }
        let fixed: Vec<usize> = given.iter().map(|g| g.0).collect();
        p.derived.apply(&mut params, &fixed);
        p.system.set_parameters(&params);
        let mut y0 = vec![0.0; p.y0.len()];
        p.initial_conditions.eval(&params, &mut y0);
        p.y0 = y0;
        p
    }
}

/// An `[[events]]` entry compiled for running: `g(t, y)`, whose zeros are the events.
#[derive(Clone)]
pub struct PreparedEvent {
    /// Name.
    pub name: String,
    /// `g` over `[t, q, q', parameters]`, or over the observation inputs (with accelerations
    /// and reactions) when `needs_unknowns`.
    pub function: Observer,
    /// Whether `g` needs accelerations or reactions (costlier to evaluate).
    pub needs_unknowns: bool,
    /// Which sign changes count.
    pub direction: Crossing,
    /// Stop the run at this occurrence.
    pub terminal: Option<usize>,
}

/// What produced a run's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solver {
    /// A pdyn-ode integrator.
    Ode(Method),
    /// The closed-form solution, evaluated (`--method exact`).
    Exact,
    /// `--method auto`: the explicit pair it chose from `rtol`
    /// ([`Method::auto_explicit`]), and where it switched to Radau5 if the problem became
    /// stiff. Shown as `auto → dop853 (rtol 1e-9)` so that a reader knows what ran.
    Auto {
        /// DOPRI5 or DOP853.
        explicit: Method,
        /// The tightest relative tolerance, which made the choice.
        rtol: f64,
        /// The time from which Radau5 integrated, when stiffness was detected.
        radau5_from: Option<f64>,
    },
}

impl Solver {
    /// What produced `sol` when it was solved with `method` at relative tolerance `rtol`.
    pub fn of(method: Method, rtol: &pdyn_ode::Tolerance, sol: &Solution) -> Solver {
        if method != Method::Auto {
            return Solver::Ode(sol.method);
        }
        Solver::Auto {
            explicit: Method::auto_explicit(rtol),
            rtol: rtol.tightest(),
            radau5_from: if sol.method == Method::Radau5 {
                sol.stats.stiffness_detected_at
            } else {
                None
            },
        }
    }
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Solver::Ode(m) => f.write_str(m.name()),
            Solver::Exact => f.write_str("exact"),
            Solver::Auto {
                explicit,
                rtol,
                radau5_from,
            } => {
                write!(f, "auto → {}", explicit.name())?;
                if let Some(t) = radau5_from {
                    write!(f, " → radau5 from t = {t:.6e}")?;
                }
                write!(f, " (rtol {rtol:e})")
            }
        }
    }
}

/// A recorded event.
#[derive(Clone, Debug)]
pub struct EventReport {
    /// Name.
    pub name: String,
    /// Time.
    pub t: f64,
    /// State at the event.
    pub state: Vec<f64>,
    /// Crossing direction.
    pub rising: bool,
}

/// Drift of a monitored quantity over a run.
#[derive(Clone, Debug)]
pub struct MonitorReport {
    /// Name.
    pub name: String,
    /// Value at the first output.
    pub initial: f64,
    /// `max |Q - Q0|`, divided by `scale` when `relative`.
    pub drift: f64,
    /// Whether `drift` is relative to `scale` (false only when the scale is zero: nothing
    /// moves and nothing acts).
    pub relative: bool,
    /// The quantity's physical scale over the run: the larger of its value at the start and
    /// its median along the run (see [`pdyn_mech::conservation::Conserved::scale`]).
    pub scale: f64,
    /// Whether the quantity should be conserved.
    pub conserved: bool,
}

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Column names: `t`, state, observer outputs.
    pub columns: Vec<String>,
    /// Output rows produced: `rows.len()`, unless the table was streamed into a file (a long
    /// run, [`long_run`]): `rows` then holds only the last.
    pub outputs: usize,
    /// One row per output time.
    pub rows: Vec<Vec<f64>>,
    /// Events in time order.
    pub events: Vec<EventReport>,
    /// Drift of each monitor.
    pub monitors: Vec<MonitorReport>,
    /// Loud warnings (drifting conserved quantities...).
    pub warnings: Vec<String>,
    /// Solver statistics.
    pub stats: pdyn_ode::Stats,
    /// The method that produced the result.
    pub method: Solver,
    /// Why the integration stopped early, with time and state.
    pub failure: Option<RunFailure>,
    /// How the run ended (SciPy's `status`: 0, 1, -1).
    pub status: RunStatus,
    /// The mode timeline, switches, impacts and energy balance of a hybrid run.
    pub hybrid: Option<hybrid::HybridReport>,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunStatus {
    /// Reached `t_end`.
    Finished,
    /// A terminal event stopped it; the index of the event in [`Prepared::events`].
    TerminalEvent(usize),
    /// The integration failed ([`RunResult::failure`] says where and why); the result holds
    /// everything computed up to there.
    Failed,
}

impl RunStatus {
    /// SciPy's `OdeResult.status`: 0 end reached, 1 terminal event, -1 failed.
    pub fn code(self) -> i32 {
        match self {
            RunStatus::Finished => 0,
            RunStatus::TerminalEvent(_) => 1,
            RunStatus::Failed => -1,
        }
    }
}

/// Derives, compiles, and sets up monitors and events.
pub fn prepare(model: &mut Model) -> Result<Prepared, SimError> {
    prepare_with(model, &run_options())
}

/// What a run needs from the derivation: everything but the printed form of the equations.
/// Nothing is simplified for printing either: the particles' velocities and forces are only
/// evaluated. Simplifying them (rational normal forms, polynomial gcds) was half the set-up of
/// a 98-particle net and did not change a bit of any example's run (all 29 mechanics
/// examples' `--json` results are identical with and without it; the net's 8 s run is faster
/// unsimplified).
pub fn run_options() -> DeriveOptions {
    DeriveOptions {
        simplify: false,
        simplify_printed: false,
        solve_budget: pdyn_mech::derive::RUN_SOLVE_BUDGET,
        ..DeriveOptions::default()
    }
}

/// [`prepare`] with explicit derivation options (e.g. `symbolic_limit = 0` to solve `A x = b`
/// numerically at every evaluation).
pub fn prepare_with(model: &mut Model, opts: &DeriveOptions) -> Result<Prepared, SimError> {
    prepare_with_jit(model, opts, JitMode::Auto)
}

/// [`prepare_with`], choosing native code or the interpreter for the right-hand side
/// (`--no-jit` is [`JitMode::Off`]).
pub fn prepare_with_jit(
    model: &mut Model,
    opts: &DeriveOptions,
    jit: JitMode,
) -> Result<Prepared, SimError> {
    prepare_on(model, opts, jit, NetPath::Auto)
}

/// Whether [`prepare_on`] evaluates a model of free particles in Cartesian coordinates by
/// per-template kernels ([`net`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NetPath {
    /// From [`net::NET_FROM`] particles on (what [`prepare`] does).
    Auto,
    /// Never: the symbolic derivation of the whole model (to compare with).
    Never,
    /// Whatever the number of particles (to compare small models).
    Always,
}

/// [`prepare_with_jit`], choosing when free particles take the per-template kernels.
pub fn prepare_on(
    model: &mut Model,
    opts: &DeriveOptions,
    jit: JitMode,
    path: NetPath,
) -> Result<Prepared, SimError> {
    // A rate left to `pdyn forces` (`rate = "omega"`, an unknown) has no number to start from.
    if let Some(e) = model.unknown_initial_error() {
        return Err(SimError::UnknownInitialCondition(Box::new(e)));
    }
    // A hybrid model is prepared in a reference mode (its held contacts touching, the others
    // open); the run derives the other modes as it meets them.
    let mut hybrid = None;
    let mut reference_model;
    // Force families left unexpanded (`pdyn_mech::model::load_deferring`) serve the path of
    // free particles below; every other path reads each load.
    if model.has_deferred()
        && (pdyn_mech::hybrid::is_hybrid(model)
            || opts.form != pdyn_mech::derive::Form::Auto
            || matches!(path, NetPath::Never))
    {
        net::expand_deferred(model)?;
    }
    let model = if pdyn_mech::hybrid::is_hybrid(model) {
        let h = hybrid::Hybrid::new(model, jit)?;
        reference_model = pdyn_mech::hybrid::reference_model(model).0;
        hybrid = Some(Box::new(h));
        &mut reference_model
    } else {
        model
    };
    // A tree of links (a chain) is solved link by link in O(n) per evaluation, from
    // `TREE_FROM` links on unless the caller chose (`tree_from: Some(usize::MAX)` keeps the
    // dense M). Not for a hybrid model: its contact modes' impulse form reads the matrix.
    let tree_opts;
    let opts = if hybrid.is_none() && opts.tree_from.is_none() {
        tree_opts = DeriveOptions {
            tree_from: Some(pdyn_mech::derive::TREE_FROM),
            ..opts.clone()
        };
        &tree_opts
    } else {
        opts
    };
    // Many free particles in Cartesian coordinates: each load family's template compiled
    // once and evaluated over its members, instead of the symbolic derivation below.
    let from = match path {
        NetPath::Auto => net::NET_FROM,
        NetPath::Never => usize::MAX,
        NetPath::Always => 0,
    };
    let net = match (&hybrid, opts.form) {
        (None, pdyn_mech::derive::Form::Auto) => net::derive_and_compile(model, jit, from),
        _ => None,
    };
    let (d, system) = match net {
        Some((d, kernels)) => {
            let system = CompiledModel::for_net(model, &d, kernels);
            (d, system)
        }
        None => {
            net::expand_deferred(model)?;
            // The chapter's steps: equations of motion, solved for the accelerations...
            let d = derive(model, opts).map_err(SimError::Derive)?;
            // ... as a first-order system the integrators can step...
            let system = CompiledModel::with_jit(model, &d, jit)
                .map_err(|error| compile_error("", error))?;
            (d, system)
        }
    };
    // ... what to tabulate and which laws the result must obey...
    let (observer, conserved, scales) = observations(model, &d, &system)?;
    // ... when to stop or record, what a sweep measures, and where it starts.
    let events = compile_events(model, &system)?;
    let measures = compile_measures(model, &system)?;
    let friction_power = compile_friction_power(model, &system)?;
    let initial_conditions = compile_initial_conditions(model, &d)?;
    let values: Vec<f64> = model.parameters.iter().map(|q| q.value).collect();
    let mut y0 = vec![0.0; d.state.len()];
    initial_conditions.eval(&values, &mut y0);
    if hybrid.is_none() {
        check_constraints_at_start(model, &system, &y0)?;
    }
    let one_sided = {
        let names = match &hybrid {
            Some(h) => &h.column_names,
            None => &observer.names,
        };
        model
            .one_sided
            .iter()
            .filter_map(|n| Some((n.clone(), names.iter().position(|c| c == n)?)))
            .collect()
    };
    Ok(Prepared {
        system,
        observer,
        conserved,
        scales,
        state_names: d.state_names.clone(),
        value_checks: ValueChecks::compile(model).ok(),
        y0,
        initial_overridden: false,
        events,
        measures,
        notes: d.notes.clone(),
        initial_conditions,
        parameter_names: model.parameters.iter().map(|q| q.name.clone()).collect(),
        derived: DerivedParameters::compile(model),
        friction_power,
        one_sided,
        hybrid,
    })
}

/// Relative size of a constraint's residual at t = 0, against its terms, above which the
/// initial state is refused.
pub const CONSTRAINT_TOLERANCE: f64 = 1e-8;

/// Every constraint `f(q, t) = 0` and its rate `df/dt = 0` must hold at t = 0: an initial
/// state off the constraint makes the integrator follow a different motion, and the only
/// symptom would be a drift warning that blames the tolerance.
pub(crate) fn check_constraints_at_start(
    model: &mut Model,
    system: &CompiledModel,
    y0: &[f64],
) -> Result<(), SimError> {
    if model.constraints.is_empty() {
        return Ok(());
    }
    let p = &mut model.pool;
    let mut labels = Vec::new();
    let mut exprs = Vec::new();
    for c in &model.constraints {
        for (level, f) in [("position", c.equation), ("velocity", p.dt(c.equation))] {
            // The size of the terms: |a| + |b| + ... for f = a + b + ...
            let terms: Vec<Id> = match p.node(f).clone() {
                pdyn_expr::Node::Add(ts) => ts.to_vec(),
                _ => vec![f],
            };
            let abs: Vec<Id> = terms
                .iter()
                .map(|&t| p.call(pdyn_expr::Func::Abs, &[t]))
                .collect();
            labels.push((level, c.label.clone()));
            exprs.push(f);
            exprs.push(p.add(&abs));
        }
    }
    let names = (0..exprs.len()).map(|k| format!("c{k}")).collect();
    // A constraint that is not a function of the state (it involves accelerations or
    // reactions) is not checked here.
    let Ok(obs) = Observer::new(p, &system.observation_inputs, names, &exprs) else {
        return Ok(());
    };
    let mut input = Vec::new();
    system.observation_input(0.0, y0, &mut input);
    let mut out = vec![0.0; exprs.len()];
    obs.eval(&input, &mut out);
    for (k, (level, label)) in labels.into_iter().enumerate() {
        let (residual, scale) = (out[2 * k], out[2 * k + 1]);
        let holds = residual.abs() <= CONSTRAINT_TOLERANCE * scale;
        if !holds {
            return Err(SimError::InitialStateViolatesConstraint {
                label,
                level,
                residual,
                scale,
            });
        }
    }
    Ok(())
}

/// Output columns after `t` and the state — particle positions, reactions (recovered ones in
/// the projected form), conserved quantities, the model's `[monitors]` — and which of them
/// must be conserved.
fn observations(
    model: &mut Model,
    d: &pdyn_mech::Derivation,
    system: &CompiledModel,
) -> Result<(Observer, Vec<bool>, Observer), SimError> {
    let mut names = Vec::new();
    let mut exprs = Vec::new();
    let mut conserved = Vec::new();
    // A net's positions that are coordinates are the coordinates' columns already.
    let net = net::positions_are_coordinates(model);
    for (pk, part) in d.particles.iter().zip(&model.particles) {
        for (axis, &c) in ["x", "y", "z"].iter().zip(&part.position) {
            let repeated = net && matches!(model.pool.node(c), pdyn_expr::Node::Coord(_, 0));
            if c != Pool::ZERO && !repeated {
                names.push(format!("{}.{axis}", pk.name));
                exprs.push(c);
                conserved.push(false);
            }
        }
    }
    for r in &model.reactions {
        names.push(r.name.clone());
        // Reactions the projected form eliminated come back as functions of the state.
        let e = d
            .recovered
            .iter()
            .find(|(n, _)| *n == r.name)
            .map_or(r.id, |x| x.1);
        exprs.push(e);
        conserved.push(false);
    }
    let (mut scale_names, mut scale_exprs) = (Vec::new(), Vec::new());
    for c in net::conserved_quantities(model, d, system) {
        scale_names.push(c.name.clone());
        scale_exprs.push(c.scale);
        names.push(c.name);
        exprs.push(c.expr);
        conserved.push(true);
    }
    for m in &model.run.monitors {
        names.push(m.name.clone());
        exprs.push(m.expr);
        conserved.push(false);
    }
    let scales = Observer::new(
        &mut model.pool,
        &system.observation_inputs,
        scale_names,
        &scale_exprs,
    )
    .map_err(|error| compile_error("conservation scale", error))?;
    // The scales again after the columns, in the columns' program: a table's rows evaluate
    // both at every output point, and the scales' terms are the energy's.
    let observer = Observer::with_trailing(
        &mut model.pool,
        &system.observation_inputs,
        names,
        &exprs,
        &scale_exprs,
    )
    .map_err(|error| compile_error("", error))?;
    Ok((observer, conserved, scales))
}

/// The model's `[[events]]`, each over the cheapest inputs it can be evaluated from.
fn compile_events(
    model: &mut Model,
    system: &CompiledModel,
) -> Result<Vec<PreparedEvent>, SimError> {
    let p = &mut model.pool;
    let mut events = Vec::new();
    for ev in &model.run.events {
        let needs_unknowns = !compiled::depends_only_on(p, ev.when, &system.inputs);
        let inputs = if needs_unknowns {
            &system.observation_inputs
        } else {
            &system.inputs
        };
        let function = Observer::new(p, inputs, vec![ev.name.clone()], &[ev.when])
            .map_err(|error| compile_error(&format!("event `{}`", ev.name), error))?;
        events.push(PreparedEvent {
            name: ev.name.clone(),
            function,
            needs_unknowns,
            direction: ev.direction,
            terminal: ev.terminal,
        });
    }
    Ok(events)
}

/// The power of each sliding friction drawn with `opposes` on the slip, and its size.
fn compile_friction_power(
    model: &mut Model,
    system: &CompiledModel,
) -> Result<Option<Observer>, SimError> {
    if model.friction_power.is_empty() {
        return Ok(None);
    }
    let mut names = Vec::new();
    let mut exprs = Vec::new();
    for (label, power, size) in &model.friction_power {
        names.push(label.clone());
        names.push(label.clone());
        exprs.push(*power);
        exprs.push(*size);
    }
    Observer::new(&mut model.pool, &system.observation_inputs, names, &exprs)
        .map(Some)
        .map_err(|error| compile_error("friction power", error))
}

/// Watches the power of hand-directed sliding friction along a run: friction must take
/// energy out of the slip, and a sliding direction drawn by hand (`opposes`) that turns out
/// wrong makes it drive the motion instead, silently (issue 31: a crate at rest pushed 4 m
/// backwards by its own friction).
#[derive(Default)]
pub(crate) struct FrictionWatch {
    out: Vec<f64>,
    /// Per friction: the first time and power where it did positive work, and the largest
    /// power.
    pub(crate) first: Vec<Option<(f64, f64, f64)>>,
}

impl FrictionWatch {
    /// Evaluates the powers at one output point.
    pub(crate) fn check(&mut self, prep: &Prepared, input: &[f64], t: f64) {
        let Some(obs) = &prep.friction_power else {
            return;
        };
        self.out.resize(obs.len(), 0.0);
        self.first.resize(obs.len() / 2, None);
        obs.eval(input, &mut self.out);
        for (k, pair) in self.out.chunks(2).enumerate() {
            let (power, size) = (pair[0], pair[1]);
            // -cos of the angle between friction and slip: 1 when friction opposes it.
            if power > 1e-6 * size && power > 0.0 {
                match &mut self.first[k] {
                    Some(f) => f.2 = f.2.max(power),
                    slot @ None => *slot = Some((t, power, power)),
                }
            }
        }
    }

    /// One loud warning per friction that did positive work.
    pub(crate) fn warnings(&self, prep: &Prepared) -> Vec<String> {
        let Some(obs) = &prep.friction_power else {
            return Vec::new();
        };
        self.first
            .iter()
            .enumerate()
            .filter_map(|(k, f)| {
                let (t, p, max) = (*f)?;
                Some(format!(
                    "friction `{}` does positive work on the slip from t = {t:.6e} (power {p:.3e} W there, up to {max:.3e} W): it drives the motion instead of opposing it, so this result is wrong. Its `opposes` direction says which way the body slides, but it slides the other way: drop `opposes` (friction then follows the slip, and sticks and slips: mode = \"coulomb\")",
                    obs.names[2 * k]
                ))
            })
            .collect()
    }
}

/// Watches the reactions declared `one_sided` along a run: a normal force can push, never
/// pull; one that pulls means the body would leave the surface, which the model's coordinates
/// do not let it do.
#[derive(Default)]
pub(crate) struct PushWatch {
    /// Per reaction: the first `(t, value)` where it pulled, and its largest magnitude.
    pub(crate) seen: Vec<(Option<(f64, f64)>, f64)>,
}

impl PushWatch {
    /// One output point: `columns` are the output columns after `t` and the state.
    pub(crate) fn check(&mut self, prep: &Prepared, t: f64, columns: &[f64]) {
        self.seen.resize(prep.one_sided.len(), (None, 0.0));
        for ((_, j), s) in prep.one_sided.iter().zip(&mut self.seen) {
            let v = columns[*j];
            s.1 = s.1.max(v.abs());
            if v < 0.0 && s.0.is_none() {
                s.0 = Some((t, v));
            }
        }
    }

    /// A loud warning per one-sided reaction that pulled by more than round-off.
    pub(crate) fn warnings(&self, prep: &Prepared) -> Vec<String> {
        prep.one_sided
            .iter()
            .zip(&self.seen)
            .filter_map(|((name, _), (first, largest))| {
                let (t, v) = (*first)?;
                (v < -1e-9 * largest).then(|| format!(
                    "reaction `{name}` is one-sided (it can only push) but pulls from t = {t:.6e} ({name} = {v:.6e}): the body would leave the surface there, and the model's coordinates keep it on; this motion is wrong from then on. Model the contact with [[contacts]] (it opens and closes), or give the body a coordinate to leave by"
                ))
            })
            .collect()
    }
}

/// The `[sweep.measures]` over the observation inputs.
fn compile_measures(
    model: &mut Model,
    system: &CompiledModel,
) -> Result<Option<Observer>, SimError> {
    let Some(s) = &model.run.sweep else {
        return Ok(None);
    };
    let names = s.measures.iter().map(|m| m.name.clone()).collect();
    let ex: Vec<Id> = s.measures.iter().map(|m| m.of).collect();
    Observer::new(&mut model.pool, &system.observation_inputs, names, &ex)
        .map(Some)
        .map_err(|error| compile_error("sweep measure", error))
}

/// The initial state `[q(0), q'(0)]` as a function of the parameters (sweeps change them).
fn compile_initial_conditions(
    model: &mut Model,
    d: &pdyn_mech::Derivation,
) -> Result<Observer, SimError> {
    // Each member of a coordinate family its own expression (sweeps compute them all).
    model.materialize_initials();
    let param_ids: Vec<Id> = model.parameters.iter().map(|q| q.id).collect();
    let mut ic_exprs = Vec::new();
    let mut ic_rates = Vec::new();
    // By coordinate (the first entry of each), not searched per coordinate: quadratic in a
    // net's 30,000 coordinates.
    let mut initial: rustc_hash::FxHashMap<usize, (Id, Id)> = rustc_hash::FxHashMap::default();
    for &(k, e, r) in &model.initial_exprs {
        initial.entry(k).or_insert((e, r));
    }
    for i in &d.free {
        if let Some(&(e, r)) = initial.get(i) {
            ic_exprs.push(e);
            ic_rates.push(r);
        }
    }
    ic_exprs.extend(ic_rates);
    Observer::new(
        &mut model.pool,
        &param_ids,
        d.state_names.clone(),
        &ic_exprs,
    )
    .map_err(|error| compile_error("initial conditions", error))
}

fn compile_error(what: &str, error: pdyn_expr::compile::CompileError) -> SimError {
    SimError::Compile {
        what: what.to_string(),
        error,
    }
}

/// An event function `g(t, y)`.
type EventFn<'a> = dyn Fn(f64, &[f64]) -> f64 + 'a;

/// Resolves a method name (`symplectic` is Yoshida's 4th-order composition of Verlet).
pub fn method_by_name(name: &str) -> Option<Method> {
    match name {
        "symplectic" => Some(Method::Yoshida4),
        other => Method::from_name(other),
    }
}

/// The `--method help` text.
pub fn methods_help() -> String {
    let mut s =
        String::from("Integration methods (--method NAME or [simulate] method = \"NAME\"):\n\n");
    s += "  symplectic  alias of yoshida4 (fixed step, needs --dt)\n";
    for m in Method::all() {
        s += &format!(
            "  {:<11} {}\n",
            m.name(),
            m.doc().split_whitespace().collect::<Vec<_>>().join(" ")
        );
    }
    s
}

/// The accelerations and output columns that are not finite at `(t, y)`, by name.
fn non_finite_at(prep: &Prepared, sys: &CompiledModel, t: f64, y: &[f64]) -> Vec<String> {
    let n = sys.n;
    if y.len() < 2 * n || y.iter().any(|v| !v.is_finite()) {
        return Vec::new();
    }
    let mut names = Vec::new();
    let mut dydt = vec![0.0f64; 2 * n];
    pdyn_ode::OdeSystem::rhs(sys, t, y, &mut dydt);
    for (k, d) in dydt[n..].iter().enumerate() {
        if !d.is_finite() {
            names.push(format!("{}'", prep.state_names[n + k]));
        }
    }
    let mut input = Vec::new();
    sys.observation_input(t, y, &mut input);
    let mut out = vec![0.0; prep.observer.len()];
    prep.observer.eval(&input, &mut out);
    for (name, v) in prep.observer.names.iter().zip(&out) {
        if !v.is_finite() {
            names.push(name.clone());
        }
    }
    names
}

/// Integrates a prepared model.
pub fn run(prep: &Prepared, set: &RunSettings) -> Result<RunResult, SimError> {
    if let Some(h) = &prep.hybrid {
        return hybrid::run(prep, h, set);
    }
    let (sol, failure) = integrate(prep, set)?;
    Ok(tabulate_owned(prep, sol, set, failure))
}

/// The integration of [`run`], before tabulation: the solver's output points and why it
/// stopped early, if it did.
pub(crate) fn integrate(
    prep: &Prepared,
    set: &RunSettings,
) -> Result<(Solution, Option<RunFailure>), SimError> {
    integrate_observed(prep, set, None)
}

/// What [`integrate_observed`] adds to [`integrate`]: an observer of the accepted steps and a
/// saved state to start from ([`pdyn_ode::solve_observed`]; explicit adaptive pairs only).
pub(crate) type Watch<'a, 'o> = (
    &'a mut pdyn_ode::resume::Observer<'o>,
    Option<&'a pdyn_ode::ResumeState>,
);

/// [`integrate`], watched step by step when `watch` is given.
pub(crate) fn integrate_observed(
    prep: &Prepared,
    set: &RunSettings,
    watch: Option<Watch<'_, '_>>,
) -> Result<(Solution, Option<RunFailure>), SimError> {
    let method = method_by_name(&set.method).ok_or_else(|| SimError::UnknownMethod {
        name: set.method.clone(),
    })?;
    set.validate()?;
    if let Some(checks) = &prep.value_checks {
        checks
            .check(&prep.system.parameters())
            .map_err(SimError::InvalidValue)?;
    }
    let fixed = matches!(
        method.kind(),
        MethodKind::FixedStep | MethodKind::Symplectic
    );
    if fixed && set.dt.is_none() {
        return Err(SimError::NeedsStep {
            method: set.method.clone(),
        });
    }
    let mut opts = Options::default();
    if let Some(r) = set.rtol {
        opts.rtol = r.into();
    }
    if let Some(a) = set.atol {
        opts.atol = a.into();
    }
    opts.h0 = set.dt;
    opts.max_step = set.max_step;
    if let Some(m) = set.max_steps {
        opts.max_steps = m;
    } else if let (true, Some(dt)) = (fixed, set.dt) {
        // A fixed-step run takes exactly t_end/dt steps: that is what was asked for.
        opts.max_steps = opts.max_steps.max((set.t_end / dt).ceil() as usize + 10);
    }
    let t_end = set.t_end;
    opts.t_eval = set.output_times();
    opts.interrupt = set.interrupt.clone();

    let sys = &prep.system;
    let n = sys.n;
    let event_fns: Vec<Box<EventFn<'_>>> = prep
        .events
        .iter()
        .map(|ev| {
            let (obs, needs) = (&ev.function, ev.needs_unknowns);
            let f: Box<EventFn<'_>> = Box::new(move |t: f64, y: &[f64]| {
                let mut input = Vec::with_capacity(sys.observation_inputs.len());
                if needs {
                    sys.observation_input(t, y, &mut input);
                } else {
                    input.push(t);
                    input.extend_from_slice(&y[..2 * n]);
                    input.extend(sys.parameters());
                }
                let mut out = [0.0];
                obs.eval(&input, &mut out);
                out[0]
            });
            f
        })
        .collect();
    let events: Vec<Event> = prep
        .events
        .iter()
        .zip(&event_fns)
        .map(|(ev, g)| {
            let mut e = Event::new(g.as_ref()).direction(match ev.direction {
                Crossing::Rising => Direction::Rising,
                Crossing::Falling => Direction::Falling,
                Crossing::Both => Direction::Both,
            });
            if let Some(k) = ev.terminal {
                e = e.terminal(k);
            }
            e
        })
        .collect();

    let result = if let Some((observer, resume)) = watch {
        // The observer stops the run itself on an interrupt, after its last checkpoint.
        opts.interrupt = None;
        pdyn_ode::solve_observed(
            method,
            sys,
            (0.0, t_end),
            &prep.y0,
            &opts,
            &events,
            resume,
            observer,
        )
    } else if method.kind() == MethodKind::Symplectic {
        if !sys.separable && !matches!(method, Method::Gauss4 | Method::Gauss6) {
            return Err(SimError::NotSeparable {
                method: set.method.clone(),
            });
        }
        pdyn_ode::solve_second_order_with_events(
            method,
            sys,
            (0.0, t_end),
            &prep.y0[..n],
            &prep.y0[n..],
            &opts,
            &events,
        )
    } else {
        pdyn_ode::solve_with_events(method, sys, (0.0, t_end), &prep.y0, &opts, &events)
    };
    let (sol, failure) = match result {
        Ok(s) => (s, None),
        Err(mut e) => {
            let Some(fp) = e.failure_point() else {
                return Err(SimError::Integrator(e));
            };
            let (t, state, stiff_at) = (
                fp.t,
                prep.state_names
                    .iter()
                    .cloned()
                    .zip(fp.y.iter().copied())
                    .collect(),
                fp.partial.stats.stiffness_detected_at,
            );
            let non_finite = non_finite_at(prep, sys, fp.t, &fp.y);
            // The partial solution moves out of the error (a long run's outputs are not
            // copied); the failure keeps the time and state.
            let Some(partial) = e.take_partial() else {
                return Err(SimError::Integrator(e));
            };
            let failure = RunFailure {
                t,
                state,
                error: e,
                stiff_at,
                non_finite,
            };
            (partial, Some(failure))
        }
    };
    Ok((sol, failure))
}

/// The scale of each conserved quantity over a run: the larger of its value at the first
/// output and its median along the run. The median, not the maximum, so that a run that
/// goes wrong (a satellite spiralling into the planet, where the kinetic energy grows without
/// bound) cannot enlarge the yardstick its own error is measured with.
/// `observer` compiled to native code for `evaluations` when that pays
/// ([`Observer::native_for`]) and the run's equations are native too (not under `--no-jit`).
pub(crate) fn native_for(
    prep: &Prepared,
    observer: &Observer,
    evaluations: usize,
) -> Option<Observer> {
    if prep.system.is_native() {
        observer.native_for(evaluations)
    } else {
        None
    }
}

/// The larger of the first value and the median of `|Q|` along a run (not empty).
pub(crate) fn scale_of(mut v: Vec<f64>) -> f64 {
    let first = v[0];
    v.sort_by(f64::total_cmp);
    first.max(v[v.len() / 2])
}

pub(crate) fn tabulate(
    prep: &Prepared,
    sol: &Solution,
    set: &RunSettings,
    failure: Option<RunFailure>,
) -> RunResult {
    let extras = observed_columns(prep, sol);
    let scales = extras.scales;
    let rows = (0..sol.len())
        .zip(extras.outputs)
        .map(|(k, extra)| row(sol.t[k], sol.y_at(k), &extra))
        .collect();
    finish_table(
        prep,
        sol,
        set,
        failure,
        rows,
        scales,
        extras.watch,
        extras.push,
    )
}

/// [`tabulate`] of a solution no longer needed: its states are released as the rows that
/// copy them are made (last first), so that a long table of many particles is held once,
/// not twice (201 rows of a 10^4-particle net's 6·10^4 states are 97 MB). The same rows.
pub(crate) fn tabulate_owned(
    prep: &Prepared,
    mut sol: Solution,
    set: &RunSettings,
    failure: Option<RunFailure>,
) -> RunResult {
    let extras = observed_columns(prep, &sol);
    let scales = extras.scales;
    let width = sol.n;
    let mut rows = Vec::with_capacity(sol.len());
    for (k, extra) in extras.outputs.into_iter().enumerate().rev() {
        rows.push(row(sol.t[k], sol.y_at(k), &extra));
        sol.y.truncate(k * width);
        sol.y.shrink_to_fit();
    }
    rows.reverse();
    finish_table(
        prep,
        &sol,
        set,
        failure,
        rows,
        scales,
        extras.watch,
        extras.push,
    )
}

/// `[t, y..., extra...]`.
fn row(t: f64, y: &[f64], extra: &[f64]) -> Vec<f64> {
    let mut row = Vec::with_capacity(1 + y.len() + extra.len());
    row.push(t);
    row.extend_from_slice(y);
    row.extend_from_slice(extra);
    row
}

/// The observer's columns at each output point, what the friction and push watches saw
/// along them (in time order), and the scale of each conserved quantity.
struct Observed {
    outputs: Vec<Vec<f64>>,
    watch: FrictionWatch,
    push: PushWatch,
    scales: Vec<f64>,
}

/// The columns and the conservation scales come from one program, the observer's (the
/// scales are its trailing outputs: [`observations`]), evaluated once per row.
fn observed_columns(prep: &Prepared, sol: &Solution) -> Observed {
    let sys = &prep.system;
    let mut outputs = Vec::with_capacity(sol.len());
    let mut input = Vec::new();
    let columns = prep.observer.len();
    let mut extra = vec![0.0; columns + prep.observer.trailing()];
    let mut scale_series = vec![Vec::with_capacity(sol.len()); prep.observer.trailing()];
    let mut watch = FrictionWatch::default();
    let mut push = PushWatch::default();
    // Solve for the accelerations and reactions at each row only when a program evaluated
    // here reads them (as `measured`); the others give the same bits without them.
    let base = sys.inputs.len();
    let solve = std::iter::once(&prep.observer)
        .chain(prep.friction_power.as_ref())
        .any(|o| !o.reads_only_first(base));
    // A long table's columns as native code (the same bits), when interpreting them row by
    // row would cost more than compiling them once.
    let native_observer = native_for(prep, &prep.observer, sol.len());
    let observer = native_observer.as_ref().unwrap_or(&prep.observer);
    for k in 0..sol.len() {
        let t = sol.t[k];
        let y = sol.y_at(k);
        if solve {
            sys.observation_input(t, y, &mut input);
        } else {
            sys.observation_input_without_unknowns(t, y, &mut input);
        }
        observer.eval_with_trailing(&input, &mut extra);
        let (row, scales) = extra.split_at(columns);
        watch.check(prep, &input, t);
        push.check(prep, t, row);
        outputs.push(row.to_vec());
        for (series, &v) in scale_series.iter_mut().zip(scales) {
            series.push(v.abs());
        }
    }
    let scales = if sol.is_empty() {
        vec![f64::NAN; scale_series.len()]
    } else {
        scale_series.into_iter().map(scale_of).collect()
    };
    Observed {
        outputs,
        watch,
        push,
        scales,
    }
}

/// The run's result from its rows: drifts of the conserved quantities, events, monitors,
/// warnings, status.
#[allow(clippy::too_many_arguments)]
fn finish_table(
    prep: &Prepared,
    sol: &Solution,
    set: &RunSettings,
    failure: Option<RunFailure>,
    rows: Vec<Vec<f64>>,
    scales: Vec<f64>,
    watch: FrictionWatch,
    push: PushWatch,
) -> RunResult {
    let columns = prep.columns();
    let offset = 1 + prep.state_names.len();
    let drifts: Vec<(f64, f64)> = match rows.first() {
        None => Vec::new(),
        Some(first) => (0..prep.observer.len())
            .filter(|&j| prep.conserved[j])
            .map(|j| {
                let first = first[offset + j];
                // NaN propagates (f64::max would drop it and call a NaN energy conserved).
                let dev =
                    rows.iter()
                        .map(|r| (r[offset + j] - first).abs())
                        .fold(0.0, |a: f64, d| {
                            if d.is_nan() || a.is_nan() {
                                f64::NAN
                            } else {
                                a.max(d)
                            }
                        });
                (first, dev)
            })
            .collect(),
    };
    let non_finite = rows.iter().any(|r| r.iter().any(|x| !x.is_finite()));
    let t_last = rows.last().map_or(0.0, |r| r[0]);
    let (events, monitors, mut warnings, status) = report(
        prep, sol, set, &failure, &drifts, &scales, t_last, non_finite,
    );
    warnings.extend(watch.warnings(prep));
    warnings.extend(push.warnings(prep));
    RunResult {
        columns,
        outputs: rows.len(),
        rows,
        events,
        monitors,
        warnings,
        stats: sol.stats.clone(),
        method: match method_by_name(&set.method) {
            Some(m) => Solver::of(
                m,
                &set.rtol.map_or(Options::default().rtol, Into::into),
                sol,
            ),
            None => Solver::Ode(sol.method),
        },
        failure,
        status,
        hybrid: None,
    }
}
