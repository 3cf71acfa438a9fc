//! Long mechanics runs (issue 29): the table written into `trajectory.csv` as the integration
//! goes, in bounded memory; checkpoints; the exact continuation from one.
//!
//! The integrator ([`pdyn_ode::solve_observed`]) hands over its output points after every
//! accepted step; each becomes a row of the file at once (the bytes `output::write_csv`
//! writes for the same row) and feeds running aggregates ([`Tally`]) that give the same
//! summary numbers as the whole table would: the first value and the largest deviation of
//! each conserved quantity, the friction and one-sided-reaction watches, where values stopped
//! being finite. Only the conservation scale is a median along the run, so `|Q|` of each
//! conserved quantity is kept per output row (8 bytes per quantity and row, not the rows).
//!
//! A checkpoint, after an accepted step when one is due (and on a clean stop by a signal),
//! holds the integrator's state ([`pdyn_ode::ResumeState`]), the tally, the events and
//! possible misses so far, and the length of `trajectory.csv`, every number as its bits. A
//! restart truncates the file to that length and continues bit for bit.
//!
//! Supported: smooth models integrated by an explicit adaptive pair (DOPRI5, Tsit5, RK23,
//! DOP853, Vern9) or by `auto` (the default), which runs one of them; if `auto` finds the
//! problem stiff and switches to Radau5, the rest of the run is integrated unobserved: its
//! rows are written when it ends, and the last checkpoint is the one before the switch (a
//! restart from it switches again at the same step). A hybrid model (contacts, impacts), the
//! closed form, the stiff and the fixed-step methods are written at the end as before, and
//! refuse `--restart` and `--checkpoint-every` by name.

use super::compiled::NATIVE_PAYS_FROM;
use super::measured::{report, NonFinite, NonFiniteScan};
use super::{
    integrate_observed, method_by_name, request::located, scale_of, FrictionWatch, Prepared,
    PushWatch, RunResult, RunSettings, Solver,
};
use crate::checkpoint::{bits, unbit, unbits, Checkpointer, Every, LongRun, Restart};
use crate::model_file::ModelFile;
use crate::number_rows::NumberRows;
use crate::stream::RowFile;
use crate::{Error, Request};
use pdyn_mech::Model;
use pdyn_ode::resume::RESUMABLE;
use pdyn_ode::{Accepted, Direction, EventHit, EventMemory, PossibleMiss, ResumeState, Stats};
use serde_json::{json, Value};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// The checkpoint kind of a mechanics run.
pub const KIND: &str = "mechanics";

/// Why this run cannot be streamed and checkpointed, or `None` when it can.
pub fn unsupported(prep: &Prepared, set: &RunSettings) -> Option<String> {
    let names: Vec<&str> = RESUMABLE.iter().map(|m| m.name()).collect();
    let supported = format!(
        "mechanics runs are checkpointed when the model is smooth and integrated by auto or an explicit adaptive method ({})",
        names.join(", ")
    );
    if prep.hybrid.is_some() {
        return Some(format!(
            "{supported}; this model has contacts, friction or impacts (a hybrid run), which is not checkpointed yet"
        ));
    }
    match method_by_name(&set.method) {
        Some(m) if m == pdyn_ode::Method::Auto || RESUMABLE.contains(&m) => None,
        _ => Some(format!(
            "{supported}; this run's method is `{}`, which is not",
            set.method
        )),
    }
}

/// A run streamed into its output directory, with checkpoints and a restart when asked.
pub struct Plan {
    dir: PathBuf,
    checkpoints: Option<Checkpointer>,
    restart: Option<Restart>,
}

/// Decides how the run of `prep` with `set` writes its table: `Some` when it is streamed
/// (`--out` given, rows to the files only, no plots, a supported model and method), `None`
/// when the table is kept and written at the end. `--restart` and `--checkpoint-every` are
/// refused, saying why, when the run cannot honour them.
pub fn plan(
    prep: &Prepared,
    set: &RunSettings,
    file: Option<&ModelFile>,
    req: &Request,
    long: &LongRun,
) -> Result<Option<Plan>, Error> {
    let asked = if long.restart.is_some() {
        Some("--restart")
    } else if long.checkpoint_every.is_some_and(|e| e != Every::Off) {
        Some("--checkpoint-every")
    } else {
        None
    };
    let why_not = unsupported(prep, set);
    if let (Some(option), Some(why)) = (asked, &why_not) {
        return Err(Error::argument(option, format!("{option}: {why}")));
    }
    let streamed = long.stream_only && !req.plots;
    let (Some(dir), Some(file), true, None) = (&req.out, file, streamed, why_not) else {
        if let Some(option) = asked {
            return Err(Error::argument(
                option,
                format!(
                    "{option} continues the files of --out DIR and draws no plots (--plot needs the whole history in memory)"
                ),
            ));
        }
        return Ok(None);
    };
    let restart = match &long.restart {
        Some(path) => Some(crate::checkpoint::read(path, KIND, file, req)?),
        None => None,
    };
    let every = long
        .checkpoint_every
        .unwrap_or(Every::Seconds(crate::checkpoint::DEFAULT_SECONDS));
    let checkpoints = (every != Every::Off).then(|| {
        Checkpointer::new(dir, every, KIND, file, req)
            .starting_at(restart.as_ref().map_or(0, |r| r.steps))
    });
    Ok(Some(Plan {
        dir: dir.clone(),
        checkpoints,
        restart,
    }))
}

/// A streamed run's result.
pub struct Streamed {
    /// The result: its `rows` hold only the last row; `outputs` counts them all.
    pub result: RunResult,
    /// The integration's failure, or output columns that hold NaN or infinity.
    pub failure: Option<Error>,
    /// `summary.json`'s `checkpoint` and `restarted_from` fields (null when none).
    pub checkpoint: Value,
    /// See `checkpoint`.
    pub restarted_from: Value,
}

/// Everything a checkpoint restores besides the integrator: what was found before it.
#[derive(Default)]
struct Before {
    events: Vec<EventHit>,
    misses: Vec<PossibleMiss>,
}

/// Runs `prep` as `plan` says: rows into `trajectory.csv` as they come, checkpoints when due.
pub fn execute(
    model: &mut Model,
    prep: &Prepared,
    set: &RunSettings,
    mut plan: Plan,
) -> Result<Streamed, Error> {
    crate::data::reset_data_range(model);
    set.validate().map_err(|e| located(model, "", e))?;
    let csv = plan.dir.join("trajectory.csv");
    let width = prep.columns().len();
    let (mut file, mut tally, before, resume) = match &plan.restart {
        None => {
            let header = crate::output::csv_header(&prep.columns());
            (
                NumberRows::new(RowFile::create(&csv, &header)?, width),
                Tally::new(prep),
                Before::default(),
                None,
            )
        }
        Some(r) => {
            let damaged = |what: &str| {
                Error::argument(
                    "--restart",
                    format!(
                        "cannot restart from {}: its state is damaged or from another version ({what})",
                        r.path.display()
                    ),
                )
            };
            let len = r.files.get(0).and_then(Value::as_u64);
            let len = len.ok_or_else(|| damaged("no length of trajectory.csv"))?;
            let s = &r.state;
            let resume = ode_state(&s["ode"]).ok_or_else(|| damaged("integrator"))?;
            let tally = Tally::from_json(prep, &s["tally"]).ok_or_else(|| damaged("monitors"))?;
            let before = before_from_json(s).ok_or_else(|| damaged("events"))?;
            (
                NumberRows::new(RowFile::resume(&csv, len)?, width),
                tally,
                before,
                Some(resume),
            )
        }
    };
    tally.t_end = set.t_end;
    let n = prep.system.n * 2;
    let interrupt = set.interrupt.clone();
    let mut io_error: Option<Error> = None;
    let outcome = {
        let mut observer = |step: &mut Accepted<'_>| -> ControlFlow<()> {
            if let Err(e) = take_rows(&mut file, &mut tally, prep, step.solution, n) {
                io_error = Some(e);
                return ControlFlow::Break(());
            }
            let stop = interrupt
                .as_ref()
                .is_some_and(|i| i.load(std::sync::atomic::Ordering::Relaxed));
            if let Some(cp) = plan.checkpoints.as_mut() {
                if stop || cp.due(step.solution.stats.accepted as u64) {
                    if let Err(e) = checkpoint(cp, &mut file, step, &tally, &before) {
                        io_error = Some(e);
                        return ControlFlow::Break(());
                    }
                }
            }
            if stop {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        };
        let observer: &mut pdyn_ode::resume::Observer<'_> = &mut observer;
        integrate_observed(prep, set, Some((observer, resume.as_ref())))
    };
    let checkpoint_at = plan
        .checkpoints
        .as_ref()
        .map(|cp| (cp.path().to_path_buf(), cp.last_time));
    let stopped_writing = |e: Error| Error::WriteDuringRun {
        error: Box::new(e),
        checkpoint: checkpoint_at.clone(),
    };
    if let Some(e) = io_error {
        return Err(stopped_writing(e));
    }
    let (mut sol, failure) = outcome.map_err(|e| located(model, "", e))?;
    // The last step's outputs (the solve ended there, unobserved).
    take_rows(&mut file, &mut tally, prep, &mut sol, n).map_err(stopped_writing)?;
    file.flush().map_err(stopped_writing)?;
    let Before {
        mut events,
        mut misses,
    } = before;
    events.append(&mut sol.events);
    sol.events = events;
    misses.append(&mut sol.possible_misses);
    sol.possible_misses = misses;
    let (result, non_finite) = tally.finish(prep, &sol, set, failure);
    let left_data = || crate::data::left_data_range(model);
    let failure = result
        .failure
        .clone()
        .map(|failure| {
            left_data().unwrap_or(Error::Integration {
                origin: model.origin.clone(),
                failure: Box::new(failure),
            })
        })
        .or_else(|| {
            non_finite.map(|nf| left_data().unwrap_or(nf.error(&model.origin, &result.columns)))
        });
    let checkpoint = plan
        .checkpoints
        .as_ref()
        .map_or(Value::Null, |cp| cp.summary_field());
    let restarted_from = plan
        .restart
        .as_ref()
        .map_or(Value::Null, |r| r.summary_field());
    Ok(Streamed {
        result,
        failure,
        checkpoint,
        restarted_from,
    })
}

/// Moves the solution's output points into the file as rows.
fn take_rows(
    file: &mut NumberRows,
    tally: &mut Tally,
    prep: &Prepared,
    sol: &mut pdyn_ode::Solution,
    n: usize,
) -> Result<(), Error> {
    if sol.t.is_empty() {
        return Ok(());
    }
    let (ts, ys) = (&sol.t, &sol.y);
    let mut written = Ok(());
    for (k, &t) in ts.iter().enumerate() {
        tally.point(prep, t, &ys[k * n..(k + 1) * n]);
        written = file.row(&tally.row);
        if written.is_err() {
            break;
        }
    }
    tally.consider_native(prep);
    sol.t.clear();
    sol.y.clear();
    written
}

/// Writes a checkpoint after the step `step`: the file flushed and synced first, its length
/// recorded.
fn checkpoint(
    cp: &mut Checkpointer,
    file: &mut NumberRows,
    step: &Accepted<'_>,
    tally: &Tally,
    before: &Before,
) -> Result<(), Error> {
    let len = file.sync()?;
    let state = step.state();
    let events: Vec<Value> = before
        .events
        .iter()
        .chain(&step.solution.events)
        .map(event_json)
        .collect();
    let misses: Vec<Value> = before
        .misses
        .iter()
        .chain(&step.solution.possible_misses)
        .map(|m| json!([m.index, m.t_from.to_bits(), m.t_to.to_bits()]))
        .collect();
    let body = json!({
        "ode": ode_json(&state),
        "tally": tally.to_json(),
        "events": events,
        "misses": misses,
    });
    cp.write(state.t, state.stats.accepted as u64, json!([len]), body)
}

/// The running aggregates of a table that is not kept: what `tabulate` computes from the
/// whole table, point by point, in the same order and arithmetic.
pub(crate) struct Tally {
    outputs: usize,
    last: Option<Vec<f64>>,
    /// Of each conserved output column: its first value and largest deviation from it.
    drifts: Vec<(f64, f64)>,
    /// `|Q|` of each conserved quantity's scale at every output point (for the median).
    scale_series: Vec<Vec<f64>>,
    watch: FrictionWatch,
    push: PushWatch,
    non_finite: NonFiniteScan,
    conserved: Vec<usize>,
    input: Vec<f64>,
    /// The output columns, then the conservation scales (the observer's trailing outputs).
    extra: Vec<f64>,
    row: Vec<f64>,
    /// Whether a program evaluated at each output point reads the solved unknowns
    /// (accelerations, reactions): only then is the right-hand side solved there, as
    /// `tabulate` does; the other programs give the same bits without them.
    solve: bool,
    /// The observer (with the scales) as native code (the same bits), made once the rows
    /// still to come are enough to pay for its compilation ([`Tally::consider_native`]).
    native_observer: Option<super::Observer>,
    native_decided: bool,
    /// This process's first output point: its time and the outputs before it (a restart
    /// continues a count), where the projection of the rows to come starts.
    since: Option<(f64, usize)>,
    /// The run's end time, for that projection (NaN: none is made).
    t_end: f64,
}

impl Tally {
    fn new(prep: &Prepared) -> Tally {
        // The scales follow the columns in the observer's program (`sim::observations`).
        debug_assert_eq!(prep.observer.trailing(), prep.scales.len());
        Tally {
            outputs: 0,
            last: None,
            drifts: Vec::new(),
            scale_series: vec![Vec::new(); prep.scales.len()],
            watch: FrictionWatch::default(),
            push: PushWatch::default(),
            non_finite: NonFiniteScan::default(),
            conserved: (0..prep.observer.len())
                .filter(|&j| prep.conserved[j])
                .collect(),
            input: Vec::new(),
            extra: vec![0.0; prep.observer.len() + prep.observer.trailing()],
            row: Vec::new(),
            solve: reads_unknowns(prep),
            native_observer: None,
            native_decided: false,
            since: None,
            t_end: f64::NAN,
        }
    }

    /// Compiles the observer (and the scales it carries) to native code when the run's rows still to
    /// come, projected from this process's rows so far at their rate per unit of time, reach
    /// [`NATIVE_FOR_ROWS_TO_COME`]: a streamed run does not know its number of rows in
    /// advance. The 100-link chain's 4,286 rows interpreted cost about a seventh of its run.
    /// At most once; only where the right-hand side is native too (not under `--no-jit`).
    fn consider_native(&mut self, prep: &Prepared) {
        if self.native_decided {
            return;
        }
        let (Some((t0, before)), Some(last)) = (self.since, self.last.as_ref()) else {
            return;
        };
        let rows = self.outputs - before;
        let t = last[0];
        let (done, left) = ((t - t0).abs(), (self.t_end - t).abs());
        // A few rows first: the first steps of an adaptive run are its smallest.
        if rows < PROJECT_FROM_ROWS || done <= 0.0 || !left.is_finite() {
            return;
        }
        let to_come = rows as f64 * (left / done);
        if to_come >= NATIVE_FOR_ROWS_TO_COME as f64 {
            self.native_observer = super::native_for(prep, &prep.observer, NATIVE_PAYS_FROM);
            self.native_decided = true;
        }
    }

    /// One output point: its row in `self.row` (for the table), the aggregates updated.
    fn point(&mut self, prep: &Prepared, t: f64, y: &[f64]) {
        if self.solve {
            prep.system.observation_input(t, y, &mut self.input);
        } else {
            prep.system
                .observation_input_without_unknowns(t, y, &mut self.input);
        }
        if self.since.is_none() {
            self.since = Some((t, self.outputs));
        }
        let observer = self.native_observer.as_ref().unwrap_or(&prep.observer);
        observer.eval_with_trailing(&self.input, &mut self.extra);
        let (columns, scales) = self.extra.split_at(prep.observer.len());
        self.watch.check(prep, &self.input, t);
        self.push.check(prep, t, columns);
        self.row.clear();
        self.row.push(t);
        self.row.extend_from_slice(y);
        self.row.extend_from_slice(columns);
        self.non_finite.row(t, self.row.iter().copied());
        if self.outputs == 0 {
            self.drifts = self
                .conserved
                .iter()
                .map(|&j| (self.extra[j], 0.0))
                .collect();
        }
        for (d, &j) in self.drifts.iter_mut().zip(&self.conserved) {
            // As tabulate's fold: NaN propagates.
            let dev = (self.extra[j] - d.0).abs();
            d.1 = if dev.is_nan() || d.1.is_nan() {
                f64::NAN
            } else {
                d.1.max(dev)
            };
        }
        for (s, &v) in self.scale_series.iter_mut().zip(scales) {
            s.push(v.abs());
        }
        match &mut self.last {
            Some(last) => last.clone_from(&self.row),
            None => self.last = Some(self.row.clone()),
        }
        self.outputs += 1;
    }

    /// The result `tabulate` would give for the whole table, and its non-finite columns.
    fn finish(
        self,
        prep: &Prepared,
        sol: &pdyn_ode::Solution,
        set: &RunSettings,
        failure: Option<super::RunFailure>,
    ) -> (RunResult, Option<NonFinite>) {
        let scales: Vec<f64> = if self.outputs == 0 {
            vec![f64::NAN; prep.scales.len()]
        } else {
            self.scale_series.into_iter().map(scale_of).collect()
        };
        let t_last = self.last.as_ref().map_or(0.0, |r| r[0]);
        let non_finite = self.non_finite.finish();
        let (events, monitors, mut warnings, status) = report(
            prep,
            sol,
            set,
            &failure,
            &self.drifts,
            &scales,
            t_last,
            non_finite.is_some(),
        );
        warnings.extend(self.watch.warnings(prep));
        warnings.extend(self.push.warnings(prep));
        let result = RunResult {
            columns: prep.columns(),
            outputs: self.outputs,
            rows: self.last.into_iter().collect(),
            events,
            monitors,
            warnings,
            stats: sol.stats.clone(),
            method: match method_by_name(&set.method) {
                Some(m) => Solver::of(
                    m,
                    &set.rtol
                        .map_or(pdyn_ode::Options::default().rtol, Into::into),
                    sol,
                ),
                None => Solver::Ode(sol.method),
            },
            failure,
            status,
            hybrid: None,
        };
        (result, non_finite)
    }

    fn to_json(&self) -> Value {
        let pairs = |v: &[(f64, f64)]| -> Value {
            v.iter()
                .map(|(a, b)| json!([a.to_bits(), b.to_bits()]))
                .collect()
        };
        json!({
            "outputs": self.outputs,
            "last": self.last.as_deref().map(bits),
            "drifts": pairs(&self.drifts),
            "scale_series": self.scale_series.iter().map(|s| bits(s)).collect::<Vec<_>>(),
            "friction": self.watch.first.iter().map(|f| f.map(|(a, b, c)| bits(&[a, b, c]))).collect::<Vec<_>>(),
            "one_sided": self.push.seen.iter().map(|(f, m)| json!([f.map(|(a, b)| bits(&[a, b])), m.to_bits()])).collect::<Vec<_>>(),
            "non_finite_t": self.non_finite.first_t.map(f64::to_bits),
            "non_finite_columns": self.non_finite.bad,
        })
    }

    fn from_json(prep: &Prepared, v: &Value) -> Option<Tally> {
        let mut t = Tally::new(prep);
        t.outputs = usize::try_from(v["outputs"].as_u64()?).ok()?;
        t.last = match &v["last"] {
            Value::Null => None,
            l => Some(unbits(l)?),
        };
        t.drifts = v["drifts"]
            .as_array()?
            .iter()
            .map(|p| Some((unbit(&p[0])?, unbit(&p[1])?)))
            .collect::<Option<_>>()?;
        t.scale_series = v["scale_series"]
            .as_array()?
            .iter()
            .map(unbits)
            .collect::<Option<_>>()?;
        if t.scale_series.len() != prep.scales.len()
            || (t.outputs > 0 && t.drifts.len() != t.conserved.len())
        {
            return None;
        }
        t.watch.first = v["friction"]
            .as_array()?
            .iter()
            .map(|f| match f {
                Value::Null => Some(None),
                f => {
                    let x = unbits(f)?;
                    Some(Some((*x.first()?, *x.get(1)?, *x.get(2)?)))
                }
            })
            .collect::<Option<_>>()?;
        t.push.seen = v["one_sided"]
            .as_array()?
            .iter()
            .map(|p| {
                let first = match &p[0] {
                    Value::Null => None,
                    f => {
                        let x = unbits(f)?;
                        Some((*x.first()?, *x.get(1)?))
                    }
                };
                Some((first, unbit(&p[1])?))
            })
            .collect::<Option<_>>()?;
        t.non_finite.first_t = match &v["non_finite_t"] {
            Value::Null => None,
            x => Some(unbit(x)?),
        };
        t.non_finite.bad = v["non_finite_columns"]
            .as_array()?
            .iter()
            .map(Value::as_bool)
            .collect::<Option<_>>()?;
        Some(t)
    }
}

/// Rows of this process seen before [`Tally::consider_native`] projects the rows to come.
const PROJECT_FROM_ROWS: usize = 32;

/// Rows still to come from which [`Tally::consider_native`] compiles: half of
/// [`NATIVE_PAYS_FROM`], about what the compilation costs in interpreted rows (800–1,900).
/// The projection from the rate so far underestimates a run whose steps shorten as it goes
/// (a chain released from rest: the 100-link chain's projection grows from 258 rows at 32
/// rows to 1,800 at 1,632 of its 4,286 and never reaches 2,000), and overestimates one whose
/// steps lengthen; at half, the chain compiles after 432 rows.
const NATIVE_FOR_ROWS_TO_COME: usize = NATIVE_PAYS_FROM / 2;

/// Whether the observer, the friction watch or the scales read the solved unknowns (inputs
/// past [`super::CompiledModel::inputs`]).
fn reads_unknowns(prep: &Prepared) -> bool {
    let base = prep.system.inputs.len();
    std::iter::once(&prep.observer)
        .chain(prep.friction_power.as_ref())
        .chain((!prep.scales.is_empty()).then_some(&prep.scales))
        .any(|o| !o.reads_only_first(base))
}

fn event_json(e: &EventHit) -> Value {
    json!({
        "index": e.index,
        "t": e.t.to_bits(),
        "y": bits(&e.y),
        "rising": e.direction == Direction::Rising,
    })
}

fn before_from_json(s: &Value) -> Option<Before> {
    let events = s["events"]
        .as_array()?
        .iter()
        .map(|e| {
            Some(EventHit {
                index: usize::try_from(e["index"].as_u64()?).ok()?,
                t: unbit(&e["t"])?,
                y: unbits(&e["y"])?,
                direction: if e["rising"].as_bool()? {
                    Direction::Rising
                } else {
                    Direction::Falling
                },
            })
        })
        .collect::<Option<_>>()?;
    let misses = s["misses"]
        .as_array()?
        .iter()
        .map(|m| {
            Some(PossibleMiss {
                index: usize::try_from(m[0].as_u64()?).ok()?,
                t_from: unbit(&m[1])?,
                t_to: unbit(&m[2])?,
            })
        })
        .collect::<Option<_>>()?;
    Some(Before { events, misses })
}

fn stats_json(s: &Stats) -> Value {
    json!({
        "steps": s.steps,
        "accepted": s.accepted,
        "rejected": s.rejected,
        "fevals": s.fevals,
        "jac_fevals": s.jac_fevals,
        "jacobians": s.jacobians,
        "lu_decompositions": s.lu_decompositions,
        "linear_solves": s.linear_solves,
        "stiffness_detected_at": s.stiffness_detected_at.map(f64::to_bits),
    })
}

fn stats_of(v: &Value) -> Option<Stats> {
    let n = |k: &str| v[k].as_u64().and_then(|x| usize::try_from(x).ok());
    Some(Stats {
        steps: n("steps")?,
        accepted: n("accepted")?,
        rejected: n("rejected")?,
        fevals: n("fevals")?,
        jac_fevals: n("jac_fevals")?,
        jacobians: n("jacobians")?,
        lu_decompositions: n("lu_decompositions")?,
        linear_solves: n("linear_solves")?,
        stiffness_detected_at: match &v["stiffness_detected_at"] {
            Value::Null => None,
            x => Some(unbit(x)?),
        },
        // Long runs resume explicit pairs only (see `resume.rs`): no linear systems.
        sparse_lu: false,
    })
}

fn ode_json(s: &ResumeState) -> Value {
    let counts = |v: &[usize]| -> Value { v.iter().map(|&c| json!(c)).collect() };
    json!({
        "method": s.method.name(),
        "t": s.t.to_bits(),
        "y": bits(&s.y),
        "h": s.h.to_bits(),
        "facold": s.facold.to_bits(),
        "first_stage": bits(&s.first_stage),
        "attempts": s.attempts,
        "stats": stats_json(&s.stats),
        "stiffness": counts(&s.stiffness),
        "non_finite_in_row": s.non_finite_in_row,
        "events": {
            "g_prev": bits(&s.events.g_prev),
            "g_prev2": bits(&s.events.g_prev2),
            "t_prev": s.events.t_prev.to_bits(),
            "t_prev2": s.events.t_prev2.to_bits(),
            "counts": counts(&s.events.counts),
        },
        "next_output": s.next_output,
    })
}

fn ode_state(v: &Value) -> Option<ResumeState> {
    let n = |x: &Value| x.as_u64().and_then(|x| usize::try_from(x).ok());
    let counts = |x: &Value| -> Option<Vec<usize>> { x.as_array()?.iter().map(n).collect() };
    let stiffness = counts(&v["stiffness"])?;
    let e = &v["events"];
    Some(ResumeState {
        method: pdyn_ode::Method::from_name(v["method"].as_str()?)?,
        t: unbit(&v["t"])?,
        y: unbits(&v["y"])?,
        h: unbit(&v["h"])?,
        facold: unbit(&v["facold"])?,
        first_stage: unbits(&v["first_stage"])?,
        attempts: n(&v["attempts"])?,
        stats: stats_of(&v["stats"])?,
        stiffness: [*stiffness.first()?, *stiffness.get(1)?, *stiffness.get(2)?],
        non_finite_in_row: n(&v["non_finite_in_row"])?,
        events: EventMemory {
            g_prev: unbits(&e["g_prev"])?,
            g_prev2: unbits(&e["g_prev2"])?,
            t_prev: unbit(&e["t_prev"])?,
            t_prev2: unbit(&e["t_prev2"])?,
            counts: counts(&e["counts"])?,
        },
        next_output: n(&v["next_output"])?,
    })
}

/// The directory of a streamed run.
impl Plan {
    /// Where the files go.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

#[cfg(test)]
mod tests {
    use super::{Tally, NATIVE_FOR_ROWS_TO_COME, PROJECT_FROM_ROWS};

    /// Feeds `rows` output points at times `k·dt` (states varied along) to a fresh tally of a
    /// run ending at `t_end`, as `take_rows` does (a projection after each chunk of 8); the
    /// rows' text and whether the tally went native.
    fn stream(prep: &super::Prepared, rows: usize, dt: f64, t_end: f64) -> (Vec<u8>, bool) {
        let mut tally = Tally::new(prep);
        tally.t_end = t_end;
        let mut out = Vec::new();
        for k in 0..rows {
            let t = k as f64 * dt;
            let y: Vec<f64> = (0..8)
                .map(|i| 0.3 * (i % 4) as f64 + libm::sin(t * (i + 1) as f64))
                .collect();
            tally.point(prep, t, &y);
            for &x in &tally.row {
                crate::output::append_number(&mut out, x);
                out.push(b',');
            }
            if k % 8 == 7 {
                tally.consider_native(prep);
            }
        }
        (out, tally.native_observer.is_some())
    }

    /// A streamed run compiles its output columns once the rows still to come, projected from
    /// those so far, reach [`NATIVE_FOR_ROWS_TO_COME`]; not for a short run nor before
    /// [`PROJECT_FROM_ROWS`] rows; and the native rows are the interpreter's, byte for byte.
    #[test]
    fn a_long_stream_goes_native_with_the_interpreters_bytes() {
        let mut model =
            pdyn_mech::load(&super::super::tree_tests::released_chain(4), "c.toml").unwrap();
        let prep = super::super::prepare(&mut model).unwrap();
        assert!(prep.system.is_native(), "the JIT is available in tests");
        assert!(!prep.scales.is_empty(), "the chain's energy is monitored");
        let dt = 1e-3;
        let rows = 300;
        // The projection at `m` rows (t = (m - 1) dt) is m (t_end - t) / t: about
        // (t_end - t) / dt more rows, the most at the first projection (m = 32).
        let long_end = (rows + NATIVE_FOR_ROWS_TO_COME + 20) as f64 * dt;
        let short_end = (NATIVE_FOR_ROWS_TO_COME - 100) as f64 * dt;
        let (native, went) = stream(&prep, rows, dt, long_end);
        assert!(went, "enough rows to come: compiled");
        let (interpreted, stayed) = stream(&prep, rows, dt, short_end);
        assert!(!stayed, "too few rows to come: interpreted");
        assert_eq!(
            native, interpreted,
            "the native rows are the interpreter's bytes"
        );
        // Too few rows to project from: nothing compiled however far the end.
        let (_, early) = stream(&prep, PROJECT_FROM_ROWS - 8, dt, 1e9);
        assert!(!early);
    }
}
