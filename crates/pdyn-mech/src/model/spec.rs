//! What `pdyn run` needs from a model file besides the mechanics: `[simulate]` settings,
//! `[[events]]`, `[monitors]` and `[sweep]`, resolved into numbers and expressions. The
//! integrator itself is chosen and driven by the `pdyn` crate; this module only reads and checks.

use super::raw::{RawModel, Sv};
use super::{Loader, ModelError};
use pdyn_expr::error::suggest;
use pdyn_expr::{Id, Value};
use std::ops::Range;

/// Most values one swept parameter may take (`steps` of `from`/`to`): the values are made
/// before the runs, so an absurd `steps` must be refused, not allocated. `pdyn` bounds a
/// whole sweep's runs (every combination) by the same number.
pub const MAX_SWEEP_VALUES: usize = 10_000_000;

/// `[simulate]`. Every field is optional; command-line options override it.
#[derive(Clone, Debug, Default)]
pub struct SimulateSpec {
    /// End time.
    pub t_end: Option<f64>,
    /// Method name as written, with its span (checked by the runner).
    pub method: Option<(String, Range<usize>)>,
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// Step of the fixed-step methods (or first step of the adaptive ones).
    pub dt: Option<f64>,
    /// Largest step.
    pub max_step: Option<f64>,
    /// Step limit.
    pub max_steps: Option<usize>,
    /// Output at this many equally spaced times (instead of every step).
    pub points: Option<usize>,
    /// Output every `output_dt` (instead of every step).
    pub output_dt: Option<f64>,
    /// Relative drift of a conserved quantity above which a run warns.
    pub drift_tolerance: Option<f64>,
}

/// Which zero crossings of an event function count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// From negative to positive.
    Rising,
    /// From positive to negative.
    Falling,
    /// Both.
    Both,
}

/// An `[[events]]` entry: `when` crosses zero.
#[derive(Clone, Debug)]
pub struct EventSpec {
    /// Name used in reports.
    pub name: String,
    /// The event function (of `t`, coordinates, rates, parameters; may use reactions).
    pub when: Id,
    /// Crossing direction.
    pub direction: Crossing,
    /// Stop at the n-th occurrence (`terminal = true` is 1).
    pub terminal: Option<usize>,
    /// Assignments made when it fires (`set = ["y' = -e*y'"]`), all right-hand sides
    /// evaluated before any is made.
    pub actions: Vec<EventAction>,
}

/// What an event action assigns to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActionTarget {
    /// The value of the free coordinate with this index in `Model::coordinates`.
    Coordinate(usize),
    /// Its rate.
    Rate(usize),
    /// The parameter with this index in `Model::parameters`.
    Parameter(usize),
}

/// One assignment `target = value` of an event's `set`.
#[derive(Clone, Debug)]
pub struct EventAction {
    /// What changes.
    pub target: ActionTarget,
    /// Its new value (an expression of the state just before the event, the parameters and
    /// `t`).
    pub value: Id,
    /// The text of the assignment, for reports.
    pub text: String,
}

/// A named expression evaluated along the trajectory.
#[derive(Clone, Debug)]
pub struct Monitor {
    /// Name (a CSV column).
    pub name: String,
    /// The expression.
    pub expr: Id,
}

/// A statistic of an expression over one run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stat {
    /// Largest value.
    Max,
    /// Smallest value.
    Min,
    /// Largest absolute value.
    MaxAbs,
    /// Largest minus smallest.
    PeakToPeak,
    /// Value at the end.
    Final,
    /// Time average (trapezoidal).
    Mean,
    /// Root mean square over time.
    Rms,
}

impl Stat {
    const NAMES: [(&'static str, Stat); 7] = [
        ("max", Stat::Max),
        ("min", Stat::Min),
        ("max_abs", Stat::MaxAbs),
        ("peak_to_peak", Stat::PeakToPeak),
        ("final", Stat::Final),
        ("mean", Stat::Mean),
        ("rms", Stat::Rms),
    ];
    /// The name used in model files.
    pub fn name(self) -> &'static str {
        Stat::NAMES
            .iter()
            .find(|(_, s)| *s == self)
            .map_or("?", |(n, _)| n)
    }
}

/// A response measure of a sweep.
#[derive(Clone, Debug)]
pub struct Measure {
    /// Name (a column of the sweep table).
    pub name: String,
    /// The expression.
    pub of: Id,
    /// The statistic.
    pub stat: Stat,
}

/// `[sweep]`: one parameter over a list of values.
#[derive(Clone, Debug)]
pub struct SweepSpec {
    /// Index of the swept parameter in [`super::Model::parameters`].
    pub parameter: usize,
    /// Its values.
    pub values: Vec<f64>,
    /// What to record from each run.
    pub measures: Vec<Measure>,
    /// Further parameters and their values (`[sweep.also]`): every combination is run with the
    /// whole range of the first parameter.
    pub others: Vec<(usize, Vec<f64>)>,
}

/// Everything `pdyn run` reads from the model file.
#[derive(Clone, Debug, Default)]
pub struct RunSpec {
    /// `[simulate]`.
    pub simulate: SimulateSpec,
    /// `[[events]]`.
    pub events: Vec<EventSpec>,
    /// `[monitors]`.
    pub monitors: Vec<Monitor>,
    /// `[sweep]`.
    pub sweep: Option<SweepSpec>,
    /// Where each key of `[simulate]` is written, by its key (`t_end`, `output_dt`, ...; `dt`
    /// for `h0` too): a value the runner refuses is shown at its key.
    pub simulate_spans: Vec<(&'static str, Range<usize>)>,
}

/// A `[[checks]]` entry: `condition` (an equation) solved for a parameter, possibly over a
/// range of a coordinate or parameter (the worst case is reported).
#[derive(Clone, Debug)]
pub struct CheckSpec {
    /// Name (`slip`, `tip`, ...).
    pub name: String,
    /// The condition as `lhs - rhs` (meaning `= 0`), as written (may contain `abs`).
    pub condition: Id,
    /// The text of the condition.
    pub text: String,
    /// Index of the parameter to solve for.
    pub solve_for: usize,
    /// Search interval for that parameter.
    pub range: Option<(f64, f64)>,
    /// A name to vary (a parameter or prescribed coordinate's parameter... any symbol) and its
    /// interval: the critical value is reported where it is smallest.
    pub over: Option<(Id, String, f64, f64)>,
}

pub(super) fn read_checks(ld: &mut Loader, raw: &RawModel) -> Result<Vec<CheckSpec>, ModelError> {
    let mut out = Vec::new();
    for sc in &raw.checks {
        let c = sc.get_ref();
        let name = c.name.as_ref().map_or_else(
            || format!("check {}", out.len() + 1),
            |n| n.get_ref().clone(),
        );
        let Some(cond) = &c.condition else {
            return Err(ld
                .err(sc.span(), format!("check `{name}` has no `condition`"))
                .help("condition = \"abs(T) = mu*N\" (slip), \"N_A = 0\" (tip), ..."));
        };
        let (text, off) = ld.expr_text(cond)?;
        let v = ld
            .pool
            .parse_equation_in(&text, &mut ld.scope)
            .map_err(|e| ld.located(e, off))?;
        let Value::Scalar(condition) = v else {
            return Err(ld.err(cond.span(), "a condition must be a scalar equation"));
        };
        let Some(sf) = &c.solve_for else {
            return Err(ld
                .err(
                    sc.span(),
                    format!("check `{name}` needs `solve_for`, the parameter to find"),
                )
                .help("e.g. solve_for = \"omega\""));
        };
        let Some(pi) = ld.params.iter().position(|p| &p.name == sf.get_ref()) else {
            let mut e = ld.err(sf.span(), format!("`{}` is not a parameter", sf.get_ref()));
            if let Some(s) = suggest(sf.get_ref(), ld.params.iter().map(|p| p.name.as_str())) {
                e = e.help(format!("did you mean `{s}`?"));
            }
            return Err(e);
        };
        let range = match &c.range {
            None => None,
            Some(r) if r.get_ref().len() == 2 => {
                let a = number(ld, &r.get_ref()[0], "a range bound")?;
                let b = number(ld, &r.get_ref()[1], "a range bound")?;
                Some((a.min(b), a.max(b)))
            }
            Some(r) => return Err(ld.err(r.span(), "`range` is [low, high]")),
        };
        let over = match &c.over {
            None => None,
            Some(o) => {
                let sym = ld.pool.find_symbol(o.get_ref());
                let Some(sym) = sym else {
                    return Err(ld.err(o.span(), format!("unknown name `{}`", o.get_ref())));
                };
                let (Some(from), Some(to)) = (&c.from, &c.to) else {
                    return Err(ld.err(o.span(), "`over` needs `from` and `to`"));
                };
                let a = number(ld, from, "`from`")?;
                let b = number(ld, to, "`to`")?;
                let id = if ld.params.iter().any(|p| &p.name == o.get_ref()) {
                    ld.pool.sym(sym)
                } else {
                    ld.pool.coord(sym, 0)
                };
                Some((id, o.get_ref().clone(), a, b))
            }
        };
        out.push(CheckSpec {
            name,
            condition,
            text,
            solve_for: pi,
            range,
            over,
        });
    }
    Ok(out)
}

fn number(ld: &mut Loader, sv: &Sv, what: &str) -> Result<f64, ModelError> {
    let id = ld.scalar(sv, what)?;
    ld.constant(id, sv.span(), what)
}

fn positive(ld: &mut Loader, sv: &Option<Sv>, what: &str) -> Result<Option<f64>, ModelError> {
    let Some(sv) = sv else { return Ok(None) };
    let x = number(ld, sv, what)?;
    if !(x > 0.0 && x.is_finite()) {
        return Err(ld.err(
            sv.span(),
            format!("{what} must be positive and finite, it is {x}"),
        ));
    }
    Ok(Some(x))
}

/// A positive time (`t_end`, `dt`, `output_dt`…): in a model that writes units, a value with
/// other units (`output_dt = "5 kg"`) is a located dimension error.
fn time(ld: &mut Loader, sv: &Option<Sv>, what: &str) -> Result<Option<f64>, ModelError> {
    let x = positive(ld, sv, what)?;
    if let Some(sv) = sv {
        ld.want(sv, pdyn_expr::Dimension::TIME, what);
    }
    Ok(x)
}

pub(super) fn read(
    ld: &mut Loader,
    raw: &RawModel,
    parameters: &[super::Parameter],
) -> Result<RunSpec, ModelError> {
    let mut spec = RunSpec::default();
    if let Some(s) = &raw.simulate {
        let r = s.get_ref();
        let sim = &mut spec.simulate;
        sim.t_end = time(ld, &r.t_end, "`t_end`")?;
        sim.method = r.method.as_ref().map(|m| (m.get_ref().clone(), m.span()));
        sim.rtol = positive(ld, &r.rtol, "`rtol`")?;
        sim.atol = positive(ld, &r.atol, "`atol`")?;
        sim.dt = time(ld, &r.dt, "`dt`")?.or(time(ld, &r.h0, "`h0`")?);
        sim.max_step = time(ld, &r.max_step, "`max_step`")?;
        sim.output_dt = time(ld, &r.output_dt, "`output_dt`")?;
        sim.drift_tolerance = positive(ld, &r.drift_tolerance, "`drift_tolerance`")?;
        for (option, sv) in [
            ("t_end", &r.t_end),
            ("rtol", &r.rtol),
            ("atol", &r.atol),
            ("dt", if r.dt.is_some() { &r.dt } else { &r.h0 }),
            ("max_step", &r.max_step),
            ("output_dt", &r.output_dt),
        ] {
            if let Some(sv) = sv {
                spec.simulate_spans.push((option, sv.span()));
            }
        }
        for (option, v) in [("points", &r.points), ("max_steps", &r.max_steps)] {
            if let Some(v) = v {
                spec.simulate_spans.push((option, v.span()));
            }
        }
        for (field, v, dst) in [
            ("max_steps", &r.max_steps, &mut sim.max_steps),
            ("points", &r.points, &mut sim.points),
        ] {
            if let Some(v) = v {
                if *v.get_ref() < 2 {
                    return Err(ld.err(v.span(), format!("`{field}` must be at least 2")));
                }
                *dst = Some(*v.get_ref() as usize);
            }
        }
    }
    for se in &raw.events {
        let e = se.get_ref();
        let name = e.name.as_ref().map_or_else(
            || format!("event {}", spec.events.len() + 1),
            |n| n.get_ref().clone(),
        );
        let Some(w) = &e.when else {
            return Err(ld
                .err(se.span(), format!("event `{name}` has no `when`"))
                .help("when = \"z\" stops or records when z crosses zero"));
        };
        let when = ld.scalar(w, "`when`")?;
        let direction = match e
            .direction
            .as_ref()
            .map(|d| (d.get_ref().as_str(), d.span()))
        {
            None | Some(("both", _)) => Crossing::Both,
            Some(("rising", _)) | Some(("up", _)) => Crossing::Rising,
            Some(("falling", _)) | Some(("down", _)) => Crossing::Falling,
            Some((other, span)) => {
                return Err(ld
                    .err(span, format!("unknown direction `{other}`"))
                    .help("direction is \"rising\", \"falling\" or \"both\""))
            }
        };
        let terminal = match &e.terminal {
            None => None,
            Some(t) => match t.get_ref() {
                toml::Value::Boolean(true) => Some(1),
                toml::Value::Boolean(false) => None,
                toml::Value::Integer(n) if *n >= 1 => Some(*n as usize),
                _ => return Err(ld.err(
                    t.span(),
                    "`terminal` is true, false, or the number of occurrences after which to stop",
                )),
            },
        };
        let actions = match &e.set {
            None => Vec::new(),
            Some(list) => event_actions(ld, list.get_ref())?,
        };
        spec.events.push(EventSpec {
            name,
            when,
            direction,
            terminal,
            actions,
        });
    }
    for (name, sv) in &raw.monitors {
        let v = ld.value(sv)?;
        match v {
            Value::Scalar(expr) => spec.monitors.push(Monitor {
                name: name.get_ref().clone(),
                expr,
            }),
            Value::Vector(c) => {
                for (axis, &expr) in ["x", "y", "z"].iter().zip(&c) {
                    spec.monitors.push(Monitor {
                        name: format!("{}.{axis}", name.get_ref()),
                        expr,
                    });
                }
            }
        }
    }
    if let Some(ss) = &raw.sweep {
        let s = ss.get_ref();
        let Some(pn) = &s.parameter else {
            return Err(ld
                .err(ss.span(), "a sweep needs `parameter`")
                .help("parameter = \"omega\""));
        };
        let Some(pi) = parameters.iter().position(|p| &p.name == pn.get_ref()) else {
            let mut e = ld.err(pn.span(), format!("`{}` is not a parameter", pn.get_ref()));
            if let Some(s) = suggest(pn.get_ref(), parameters.iter().map(|p| p.name.as_str())) {
                e = e.help(format!("did you mean `{s}`?"));
            }
            return Err(e);
        };
        let values = if let Some(vals) = &s.values {
            let mut out = Vec::new();
            for v in vals.get_ref() {
                match v {
                    toml::Value::Integer(i) => out.push(*i as f64),
                    toml::Value::Float(f) => out.push(*f),
                    _ => return Err(ld.err(vals.span(), "`values` must be a list of numbers")),
                }
            }
            out
        } else {
            let (Some(from), Some(to), Some(steps)) = (&s.from, &s.to, &s.steps) else {
                return Err(ld
                    .err(
                        ss.span(),
                        "a sweep needs `values = [...]`, or `from`, `to` and `steps`",
                    )
                    .help("e.g. from = 1, to = 30, steps = 300"));
            };
            let a = number(ld, from, "`from`")?;
            let b = number(ld, to, "`to`")?;
            let n = *steps.get_ref();
            if n < 2 {
                return Err(ld.err(steps.span(), "`steps` must be at least 2"));
            }
            if n as u64 > MAX_SWEEP_VALUES as u64 {
                return Err(ld
                    .err(
                        steps.span(),
                        format!(
                            "`steps` = {n} is more than a sweep may run ({MAX_SWEEP_VALUES} values)"
                        ),
                    )
                    .help("sweep a coarser grid, or split the range into several sweeps"));
            }
            (0..n)
                .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
                .collect()
        };
        if values.is_empty() {
            return Err(ld.err(ss.span(), "the sweep has no values"));
        }
        let mut measures = Vec::new();
        for (name, sm) in &s.measures {
            let m = sm.get_ref();
            let Some(of) = &m.of else {
                return Err(ld.err(
                    sm.span(),
                    format!("measure `{}` needs `of`", name.get_ref()),
                ));
            };
            let of_id = ld.scalar(of, "`of`")?;
            let stat = match &m.stat {
                None => Stat::MaxAbs,
                Some(st) => match Stat::NAMES.iter().find(|(n, _)| n == st.get_ref()) {
                    Some((_, s)) => *s,
                    None => {
                        let names: Vec<&str> = Stat::NAMES.iter().map(|(n, _)| *n).collect();
                        let mut e =
                            ld.err(st.span(), format!("unknown statistic `{}`", st.get_ref()));
                        e = match suggest(st.get_ref(), names.iter().copied()) {
                            Some(s) => e.help(format!("did you mean `{s}`?")),
                            None => e.help(format!("statistics: {}", names.join(", "))),
                        };
                        return Err(e);
                    }
                },
            };
            measures.push(Measure {
                name: name.get_ref().clone(),
                of: of_id,
                stat,
            });
        }
        let mut others = Vec::new();
        for (name, sv) in &s.also {
            let Some(k) = parameters.iter().position(|p| &p.name == name.get_ref()) else {
                let mut e = ld.err(
                    name.span(),
                    format!("`{}` is not a parameter", name.get_ref()),
                );
                if let Some(sg) =
                    suggest(name.get_ref(), parameters.iter().map(|p| p.name.as_str()))
                {
                    e = e.help(format!("did you mean `{sg}`?"));
                }
                return Err(e);
            };
            let vals: Vec<f64> = match sv.get_ref() {
                toml::Value::Array(a) => {
                    let mut v = Vec::new();
                    for x in a {
                        match x {
                            toml::Value::Integer(i) => v.push(*i as f64),
                            toml::Value::Float(f) => v.push(*f),
                            _ => return Err(ld.err(sv.span(), "values must be numbers")),
                        }
                    }
                    v
                }
                toml::Value::Table(t) => {
                    let num = |key: &str| -> Option<f64> {
                        match t.get(key)? {
                            toml::Value::Integer(i) => Some(*i as f64),
                            toml::Value::Float(f) => Some(*f),
                            _ => None,
                        }
                    };
                    match (num("from"), num("to"), num("steps")) {
                        (Some(_), Some(_), Some(n)) if n > MAX_SWEEP_VALUES as f64 => {
                            return Err(ld
                                .err(
                                    sv.span(),
                                    format!(
                                        "`steps` = {n} is more than a sweep may run \
                                         ({MAX_SWEEP_VALUES} values)"
                                    ),
                                )
                                .help(
                                    "sweep a coarser grid, or split the range into several sweeps",
                                ));
                        }
                        (Some(a), Some(b), Some(n)) if n >= 2.0 => {
                            let n = n as usize;
                            (0..n)
                                .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
                                .collect()
                        }
                        _ => {
                            return Err(ld.err(
                                sv.span(),
                                "a range is { from = ..., to = ..., steps = N } with N >= 2",
                            ))
                        }
                    }
                }
                _ => return Err(ld.err(sv.span(), "give a list of values or { from, to, steps }")),
            };
            if vals.is_empty() {
                return Err(ld.err(sv.span(), "no values"));
            }
            others.push((k, vals));
        }
        spec.sweep = Some(SweepSpec {
            parameter: pi,
            values,
            measures,
            others,
        });
    }
    Ok(spec)
}

/// The assignments of an event's `set`: `"x' = -e*x'"` (a free coordinate's value or rate) or
/// `"thrust = 0"` (a parameter).
fn event_actions(ld: &mut Loader, list: &[Sv]) -> Result<Vec<EventAction>, ModelError> {
    let mut out: Vec<EventAction> = Vec::new();
    for sv in list {
        let toml::Value::String(text) = sv.get_ref() else {
            return Err(ld
                .err(
                    sv.span(),
                    "an event action is a string \"target = expression\"",
                )
                .help("set = [\"y' = -e*y'\", \"thrust = 0\"]"));
        };
        let (_, off) = ld.expr_text(sv)?;
        let (lhs, rhs) = pdyn_expr::syntax::parse_equation(text).map_err(|e| ld.located(e, off))?;
        let Some(rhs) = rhs else {
            return Err(ld
                .err(sv.span(), format!("`{text}` is not an assignment"))
                .help("write target = expression, e.g. \"y' = -e*y'\""));
        };
        let (name, primes, lspan) = match &lhs {
            pdyn_expr::syntax::Ast::Ident { name, span } => (name.clone(), 0u8, span.clone()),
            pdyn_expr::syntax::Ast::Prime { expr, count, span } => match expr.as_ref() {
                pdyn_expr::syntax::Ast::Ident { name, .. } => (name.clone(), *count, span.clone()),
                _ => return Err(not_assignable(ld, sv, off, lhs.span())),
            },
            _ => return Err(not_assignable(ld, sv, off, lhs.span())),
        };
        let lspan = lspan.start + off..lspan.end + off;
        let target = if let Some(k) = ld.params.iter().position(|p| p.name == name) {
            if primes > 0 {
                return Err(ld
                    .err(
                        lspan,
                        format!("`{name}` is a parameter: it has no rate to set"),
                    )
                    .help(format!("set the parameter itself: \"{name} = ...\"")));
            }
            ActionTarget::Parameter(k)
        } else {
            match ld.coordinate_index(&name) {
                Some((k, true)) if primes == 0 => ActionTarget::Coordinate(k),
                Some((k, true)) if primes == 1 => ActionTarget::Rate(k),
                Some((_, true)) => {
                    return Err(ld
                        .err(lspan, format!("an event sets a coordinate (`{name}`) or its rate (`{name}'`), not a higher derivative"))
                        .help("accelerations follow from the forces; change a force's parameter instead"))
                }
                Some((_, false)) => {
                    return Err(ld
                        .err(lspan, format!("`{name}` is prescribed as a function of time: an event cannot change it"))
                        .help("only free coordinates, their rates and parameters can be set"))
                }
                None => {
                    let mut names: Vec<String> = ld.params.iter().map(|p| p.name.clone()).collect();
                    names.extend(ld.free_coordinate_names());
                    let e = ld.err(lspan, format!("`{name}` is not a free coordinate or a parameter: an event cannot set it"));
                    return Err(match suggest(&name, names.iter().map(|s| s.as_str())) {
                        Some(s) => e.help(format!("did you mean `{s}`?")),
                        None => e.help(format!("an event sets one of: {}", names.join(", "))),
                    });
                }
            }
        };
        if out.iter().any(|a| a.target == target) {
            return Err(ld
                .err(
                    lspan,
                    format!(
                        "`{}` is set twice by this event",
                        ld.source[sv.span()].trim_matches('"')
                    ),
                )
                .help("each target may be set once per event"));
        }
        // The assignments are evaluated at the state just before the event, where the
        // forces are not solved for: a reaction or contact force has no value there.
        let force_of = |name: &str| {
            ld.scope
                .names
                .get(name)
                .is_some_and(|(_, _, kind)| *kind == "reaction")
        };
        if rhs.any_name(&force_of) {
            let rspan = rhs.span();
            return Err(ld
                .err(rspan.start + off..rspan.end + off, "an event's assignment cannot use a reaction or contact force")
                .help("use t, coordinates, their rates and parameters (the forces are not solved for at the jump)"));
        }
        let v = pdyn_expr::lower::lower(&mut ld.pool, &rhs, &mut ld.scope)
            .map_err(|e| ld.located(e, off))?;
        let Value::Scalar(value) = v else {
            return Err(ld.err(sv.span(), format!("`{text}` assigns a vector to a scalar")));
        };
        out.push(EventAction {
            target,
            value,
            text: text.clone(),
        });
    }
    Ok(out)
}

fn not_assignable(ld: &Loader, sv: &Sv, off: usize, span: Range<usize>) -> ModelError {
    ld.err(
        span.start + off..span.end + off,
        "an event sets a free coordinate, its rate or a parameter",
    )
    .help(format!(
        "write \"x = ...\", \"x' = ...\" or \"k = ...\" (in {})",
        ld.source[sv.span()].trim()
    ))
}
