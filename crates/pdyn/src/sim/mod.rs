//! `pdyn run`: integrate a model's equations of motion and check the result.
//!
//! [`prepare`] derives and compiles once (equations, events, output columns, conserved
//! quantities); [`run`] integrates with given settings and returns a table, the events, the
//! drift of every monitored quantity and warnings. Sweeps call [`run`] many times on clones of
//! one [`Prepared`].
//!
//! The First Law of Scientific Computing (chapter 3.3.3): a result that violates a conservation
//! law is flagged. Energy is monitored when every force derives from a potential (or is a
//! reaction) and nothing depends explicitly on time; angular momentum about the origin and
//! linear momentum components when the resultant moment or force vanishes identically.

pub mod compiled;
pub mod exact;
pub mod sweep;

use compiled::{depends_on_time, CompiledModel, Observer};
use pdyn_expr::{vector, Id, Pool};
use pdyn_mech::model::spec::Crossing;
use pdyn_mech::{derive, DeriveOptions, Model};
use pdyn_ode::{Direction, Event, Method, MethodKind, Options, Solution};

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
}

impl RunSettings {
    /// Settings from a model's `[simulate]` (method `auto` unless given); `t_end` is required.
    pub fn from_spec(s: &pdyn_mech::model::spec::SimulateSpec) -> Result<RunSettings, String> {
        Ok(RunSettings {
            method: s
                .method
                .as_ref()
                .map_or("auto".to_string(), |m| m.0.clone()),
            t_end: s
                .t_end
                .ok_or("no end time: add t_end = ... under [simulate]")?,
            rtol: s.rtol,
            atol: s.atol,
            dt: s.dt,
            max_step: s.max_step,
            max_steps: s.max_steps,
            points: s.points,
            output_dt: s.output_dt,
            t_eval: None,
            drift_tolerance: s.drift_tolerance.unwrap_or(DEFAULT_DRIFT_TOLERANCE),
        })
    }

    /// The value of column `name` in the last row of a result.
    pub fn final_value(res: &RunResult, name: &str) -> Option<f64> {
        let j = res.columns.iter().position(|c| c == name)?;
        res.rows.last().map(|r| r[j])
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
    /// Names of the state components.
    pub state_names: Vec<String>,
    /// Initial state.
    pub y0: Vec<f64>,
    /// Event functions (over the observation inputs when they need unknowns).
    pub events: Vec<(String, Observer, bool, Crossing, Option<usize>)>,
    /// Sweep measures: observer over the same inputs.
    pub measures: Option<Observer>,
    /// Notes from the derivation.
    pub notes: Vec<String>,
    /// Initial state as a function of the parameters (for sweeps).
    pub initial_conditions: Observer,
    /// Parameter names, in model order.
    pub parameter_names: Vec<String>,
}

impl Prepared {
    /// A copy with parameter `index` set to `value` (initial conditions recomputed).
    pub fn with_parameter(&self, index: usize, value: f64) -> Prepared {
        let mut p = self.clone();
        let mut params = p.system.parameters();
        if let Some(x) = params.get_mut(index) {
            *x = value;
        }
        p.system.set_parameters(&params);
        let mut y0 = vec![0.0; p.y0.len()];
        p.initial_conditions.eval(&params, &mut y0);
        p.y0 = y0;
        p
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
    /// `max |Q - Q0|`, divided by `|Q0|` when `relative`.
    pub drift: f64,
    /// Whether `drift` is relative.
    pub relative: bool,
    /// Whether the quantity should be conserved.
    pub conserved: bool,
}

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Column names: `t`, state, observer outputs.
    pub columns: Vec<String>,
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
    pub method: String,
    /// Why the integration stopped early, with time and state.
    pub failure: Option<String>,
}

/// Derives, compiles, and sets up monitors and events.
pub fn prepare(model: &mut Model) -> Result<Prepared, String> {
    prepare_with(model, &DeriveOptions::default())
}

/// [`prepare`] with explicit derivation options (e.g. `symbolic_limit = 0` to solve `A x = b`
/// numerically at every evaluation).
pub fn prepare_with(model: &mut Model, opts: &DeriveOptions) -> Result<Prepared, String> {
    let d = derive(model, opts).map_err(|e| format!("{}: error: {e}", model.origin))?;
    let system =
        CompiledModel::new(model, &d).map_err(|e| format!("{}: error: {e}", model.origin))?;
    let obs_inputs = system.observation_inputs.clone();
    let p = &mut model.pool;

    let mut names = Vec::new();
    let mut exprs = Vec::new();
    let mut conserved = Vec::new();
    for (pk, part) in d.particles.iter().zip(&model.particles) {
        for (axis, &c) in ["x", "y", "z"].iter().zip(&part.position) {
            if c != Pool::ZERO {
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
    // Conserved quantities.
    let explicit_time = model
        .particles
        .iter()
        .any(|pt| pt.position.iter().any(|&c| depends_on_time(p, c)))
        || model
            .potentials
            .iter()
            .any(|v| depends_on_time(p, v.energy));
    if model.conservative && !explicit_time && !model.potentials.is_empty() {
        let mut terms = Vec::new();
        for pk in &d.particles {
            let v2 = vector::dot(p, pk.v, pk.v);
            let half = p.num(pdyn_expr::Number::ratio(1, 2));
            terms.push(p.mul(&[half, pk.mass, v2]));
        }
        terms.extend(model.potentials.iter().map(|v| v.energy));
        names.push("energy".into());
        exprs.push(p.add(&terms));
        conserved.push(true);
    }
    let mut h = [Pool::ZERO; 3];
    let mut moment = [Pool::ZERO; 3];
    let mut momentum = [Pool::ZERO; 3];
    let mut total_force = [Pool::ZERO; 3];
    for pk in &d.particles {
        let mv = vector::scale(p, pk.mass, pk.v);
        let hr = vector::cross(p, pk.r, mv);
        h = vector::add(p, h, hr);
        let mr = vector::cross(p, pk.r, pk.force);
        moment = vector::add(p, moment, mr);
        momentum = vector::add(p, momentum, mv);
        total_force = vector::add(p, total_force, pk.force);
    }
    let small = |p: &mut Pool, e: Id| p.tree_size(e, 2001) < 2000;
    // In the projected form some reactions were never declared (a pendulum's pivot): the
    // forces we know are not all the forces, so momentum balances cannot be checked.
    let all_forces_known = d.form != pdyn_mech::derive::Form::Projected;
    for (c, axis) in ["x", "y", "z"].iter().enumerate() {
        if all_forces_known
            && h[c] != Pool::ZERO
            && small(p, moment[c])
            && p.provably_equal(moment[c], Pool::ZERO)
        {
            names.push(format!("angular_momentum.{axis}"));
            exprs.push(h[c]);
            conserved.push(true);
        }
    }
    for (c, axis) in ["x", "y", "z"].iter().enumerate() {
        if all_forces_known
            && momentum[c] != Pool::ZERO
            && small(p, total_force[c])
            && p.provably_equal(total_force[c], Pool::ZERO)
        {
            names.push(format!("momentum.{axis}"));
            exprs.push(momentum[c]);
            conserved.push(true);
        }
    }
    for m in &model.run.monitors {
        names.push(m.name.clone());
        exprs.push(m.expr);
        conserved.push(false);
    }
    let observer = Observer::new(p, &obs_inputs, names, &exprs)
        .map_err(|e| format!("{}: error: {e}", model.origin))?;

    let mut events = Vec::new();
    for ev in &model.run.events {
        // Cheap inputs when the event needs no accelerations or reactions.
        let (obs, needs_unknowns) =
            match Observer::new(p, &system.inputs, vec![ev.name.clone()], &[ev.when]) {
                Ok(o) => (o, false),
                Err(_) => (
                    Observer::new(p, &obs_inputs, vec![ev.name.clone()], &[ev.when]).map_err(
                        |e| format!("{}: error: event `{}`: {e}", model.origin, ev.name),
                    )?,
                    true,
                ),
            };
        events.push((
            ev.name.clone(),
            obs,
            needs_unknowns,
            ev.direction,
            ev.terminal,
        ));
    }
    let measures = match &model.run.sweep {
        Some(s) => {
            let names = s.measures.iter().map(|m| m.name.clone()).collect();
            let ex: Vec<Id> = s.measures.iter().map(|m| m.of).collect();
            Some(
                Observer::new(p, &obs_inputs, names, &ex)
                    .map_err(|e| format!("{}: error: sweep measure: {e}", model.origin))?,
            )
        }
        None => None,
    };

    let param_ids: Vec<Id> = model.parameters.iter().map(|q| q.id).collect();
    let mut ic_exprs = Vec::new();
    let mut ic_rates = Vec::new();
    for &i in &d.free {
        if let Some(&(_, e, r)) = model.initial_exprs.iter().find(|(k, _, _)| *k == i) {
            ic_exprs.push(e);
            ic_rates.push(r);
        }
    }
    ic_exprs.extend(ic_rates);
    let ic_names = d.state_names.clone();
    let initial_conditions = Observer::new(&mut model.pool, &param_ids, ic_names, &ic_exprs)
        .map_err(|e| format!("{}: error: initial conditions: {e}", model.origin))?;
    // Initial state from the current parameter values (they may have been overridden).
    let values: Vec<f64> = model.parameters.iter().map(|q| q.value).collect();
    let mut y0 = vec![0.0; d.state.len()];
    initial_conditions.eval(&values, &mut y0);
    Ok(Prepared {
        system,
        observer,
        conserved,
        state_names: d.state_names.clone(),
        y0,
        events,
        measures,
        notes: d.notes.clone(),
        initial_conditions,
        parameter_names: model.parameters.iter().map(|q| q.name.clone()).collect(),
    })
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

/// Integrates a prepared model.
pub fn run(prep: &Prepared, set: &RunSettings) -> Result<RunResult, String> {
    let method = method_by_name(&set.method).ok_or_else(|| {
        format!(
            "unknown method `{}`; run `pdyn run --method help` for the list",
            set.method
        )
    })?;
    let fixed = matches!(
        method.kind(),
        MethodKind::FixedStep | MethodKind::Symplectic
    );
    if fixed && set.dt.is_none() {
        return Err(format!(
            "method `{}` takes fixed steps: give the step with --dt (or dt = ... in [simulate])",
            set.method
        ));
    }
    if !(set.t_end.is_finite() && set.t_end > 0.0) {
        return Err(format!("t_end must be a positive time, got {}", set.t_end));
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
    if let Some(ts) = &set.t_eval {
        if ts.iter().any(|&x| !(0.0..=t_end).contains(&x)) || ts.windows(2).any(|w| w[1] <= w[0]) {
            return Err(format!(
                "t_eval must be increasing times within [0, {t_end}]"
            ));
        }
        opts.t_eval = Some(ts.clone());
    } else if let Some(npts) = set.points {
        opts.t_eval = Some(
            (0..npts)
                .map(|k| t_end * k as f64 / (npts - 1) as f64)
                .collect(),
        );
    } else if let Some(dt) = set.output_dt {
        let steps = (t_end / dt).floor() as usize;
        let mut ts: Vec<f64> = (0..=steps).map(|k| k as f64 * dt).collect();
        if ts.last().is_some_and(|&l| l < t_end * (1.0 - 1e-12)) {
            ts.push(t_end);
        }
        opts.t_eval = Some(ts);
    }

    let sys = &prep.system;
    let n = sys.n;
    let event_fns: Vec<Box<EventFn<'_>>> = prep
        .events
        .iter()
        .map(|(_, obs, needs_unknowns, _, _)| {
            let needs = *needs_unknowns;
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
        .map(|((_, _, _, dir, term), g)| {
            let mut e = Event::new(g.as_ref()).direction(match dir {
                Crossing::Rising => Direction::Rising,
                Crossing::Falling => Direction::Falling,
                Crossing::Both => Direction::Both,
            });
            if let Some(k) = term {
                e = e.terminal(*k);
            }
            e
        })
        .collect();

    let result = if method.kind() == MethodKind::Symplectic {
        if !sys.separable && !matches!(method, Method::Gauss4 | Method::Gauss6) {
            return Err(format!(
                "method `{}` needs accelerations that do not depend on velocities; this model's do \
                 (drag, dampers, friction...): use gauss4/gauss6 or an adaptive method",
                set.method
            ));
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
        Err(e) => match e.failure_point() {
            Some(fp) => {
                let state: Vec<String> = prep
                    .state_names
                    .iter()
                    .zip(&fp.y)
                    .map(|(nm, v)| format!("{nm} = {v:.6e}"))
                    .collect();
                let msg = format!(
                    "integration failed at t = {:.9e}: {e}\n  state: {}",
                    fp.t,
                    state.join(", ")
                );
                ((*fp.partial).clone(), Some(msg))
            }
            None => return Err(format!("cannot integrate: {e}")),
        },
    };
    Ok(tabulate(prep, &sol, set, failure))
}

pub(crate) fn tabulate(
    prep: &Prepared,
    sol: &Solution,
    set: &RunSettings,
    failure: Option<String>,
) -> RunResult {
    let sys = &prep.system;
    let mut columns = vec!["t".to_string()];
    columns.extend(prep.state_names.iter().cloned());
    columns.extend(prep.observer.names.iter().cloned());
    let mut rows = Vec::with_capacity(sol.len());
    let mut input = Vec::new();
    let mut extra = vec![0.0; prep.observer.len()];
    for k in 0..sol.len() {
        let t = sol.t[k];
        let y = sol.y_at(k);
        sys.observation_input(t, y, &mut input);
        prep.observer.eval(&input, &mut extra);
        let mut row = Vec::with_capacity(columns.len());
        row.push(t);
        row.extend_from_slice(y);
        row.extend_from_slice(&extra);
        rows.push(row);
    }
    let events = sol
        .events
        .iter()
        .map(|h| EventReport {
            name: prep
                .events
                .get(h.index)
                .map_or("event".into(), |e| e.0.clone()),
            t: h.t,
            state: h.y.clone(),
            rising: h.direction == Direction::Rising,
        })
        .collect();
    let offset = 1 + prep.state_names.len();
    let mut monitors = Vec::new();
    let mut warnings = Vec::new();
    for (j, name) in prep.observer.names.iter().enumerate() {
        let conserved = prep.conserved[j];
        if !conserved {
            continue;
        }
        let Some(first) = rows.first().map(|r| r[offset + j]) else {
            continue;
        };
        let dev = rows
            .iter()
            .map(|r| (r[offset + j] - first).abs())
            .fold(0.0, f64::max);
        let relative = first.abs() > 1e-12;
        let drift = if relative { dev / first.abs() } else { dev };
        if drift.is_nan() || drift > set.drift_tolerance {
            let t_last = rows.last().map_or(0.0, |r| r[0]);
            warnings.push(format!(
                "{name} should be conserved but drifted by {drift:.3e} ({}) over t = 0..{t_last}: \
                 this result cannot be trusted (the First Law of Scientific Computing). Tighten \
                 the tolerance (e.g. --rtol {:.0e}) or use a symplectic method (--method symplectic --dt ...).",
                if relative { "relative" } else { "absolute" },
                (set.rtol.unwrap_or(1e-6) * 1e-3).max(1e-13),
            ));
        }
        monitors.push(MonitorReport {
            name: name.clone(),
            initial: first,
            drift,
            relative,
            conserved,
        });
    }
    if rows.iter().any(|r| r.iter().any(|x| !x.is_finite())) && failure.is_none() {
        warnings.push("some output values are not finite (NaN or infinity)".into());
    }
    RunResult {
        columns,
        rows,
        events,
        monitors,
        warnings,
        stats: sol.stats.clone(),
        method: sol.method.name().to_string(),
        failure,
    }
}
