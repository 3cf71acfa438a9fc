//! Hybrid runs: contacts that open and close, friction that sticks and slips, impacts, and
//! events that change the state — event-driven, exact to the integrator's tolerance at every
//! switch.
//!
//! The run is a sequence of smooth segments. In each, every contact is in one
//! [`ContactMode`] and the model of that combination ([`pdyn_mech::hybrid::mode_model`]) is
//! derived, compiled (once, then cached) and integrated with terminal events that end the
//! segment where the mode stops being valid:
//!
//! | mode | ends when | then |
//! |---|---|---|
//! | open | the gap reaches 0, falling | an impact (restitution `e`), or resting contact |
//! | touching | the normal force `N` reaches 0, falling | open |
//! | stuck | `|F| = mu_s N`, rising | sliding, in the direction the needed force cannot hold |
//! | sliding | the slip velocity reaches 0 | stuck if `|F| <= mu_s N` there, else sliding back |
//! | any | a `[[events]]` entry with `set` fires | its assignments, at once |
//!
//! An impact solves the impulse form of the same equations, `A(q) [Δq'; P] = [0; c]`, with
//! `A` the derivation's matrix in the mode where the contact touches (rows: `m Δv = P`, and
//! each constraint at velocity level): the impacting contact's gap rate becomes `-e` times its
//! value, every other closed constraint keeps its velocity at zero. Momentum of a pair is
//! conserved, and the kinetic energy lost is recorded. A ball whose bounce intervals shrink
//! geometrically (a Zeno sequence) ends in resting contact at the accumulation time
//! `t_k + Δ_k r/(1 - r)`, `r` the ratio of the last two intervals, once the remaining time is
//! below 1e-10 of the elapsed time, rather than collapsing the step size.
//!
//! The state carries two extra quantities, integrated with it: the work of the contact forces
//! on the particles and the power dissipated by friction on the slip (`-F_t · v_s`, never
//! negative). With the impacts' kinetic-energy changes they close the energy balance
//! `E(t) - W_contacts(t) - W_impacts(t) = E(0)`, checked like a conserved quantity (the First
//! Law of Scientific Computing still means something in a hybrid model).

use super::compiled::{input_leaves, CompiledModel, Observer};
use super::{
    compile_error, method_by_name, scale_of, EventFn, EventReport, MonitorReport, Prepared,
    RunFailure, RunResult, RunSettings, RunStatus, SimError, Solver,
};
use pdyn_expr::{Id, Pool};
use pdyn_jit::JitMode;
use pdyn_mech::derive::UnknownKind;
use pdyn_mech::hybrid::{closed_modes, mode_model, ContactMode, Layout};
use pdyn_mech::model::spec::{ActionTarget, Crossing};
use pdyn_mech::{derive, Model};
use pdyn_ode::{Direction, Event, MethodKind, OdeError, OdeSystem, Options, Status};
use std::cell::RefCell;

/// A switch of one contact's mode.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Switch {
    /// When.
    pub t: f64,
    /// Which contact.
    pub contact: String,
    /// Mode before (`open`, `in contact`, `stuck`, `sliding +`...).
    pub from: &'static str,
    /// Mode after.
    pub to: &'static str,
    /// Why (`slip speed reached 0; |F| = 1.2 N <= mu_s N = 2.9 N`).
    pub reason: String,
}

/// An impact.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Impact {
    /// When.
    pub t: f64,
    /// Which contact.
    pub contact: String,
    /// Closing speed along the normal before (`-dphi/dt`, positive).
    pub normal_speed_before: f64,
    /// Separating speed along the normal after (`e` times the speed before, or 0 when the
    /// contact comes to rest).
    pub normal_speed_after: f64,
    /// The normal impulse.
    pub impulse: f64,
    /// Kinetic energy lost (positive when lost).
    pub energy_lost: f64,
}

/// Bounces accumulating in finite time, ended in resting contact.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Zeno {
    /// Which contact.
    pub contact: String,
    /// The accumulation time of the bounces.
    pub t_accumulation: f64,
    /// The ratio of successive bounce intervals.
    pub ratio: f64,
    /// Bounces integrated before the accumulation was taken.
    pub bounces: usize,
}

/// One interval of constant modes.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ModeInterval {
    /// Start.
    pub t_from: f64,
    /// End.
    pub t_to: f64,
    /// Each contact's mode, by contact name.
    #[serde(serialize_with = "modes_as_map")]
    pub modes: Vec<(String, &'static str)>,
}

/// `[(contact, mode)]` as the JSON object `{contact: mode}`.
fn modes_as_map<S: serde::Serializer>(
    modes: &[(String, &'static str)],
    s: S,
) -> Result<S::Ok, S::Error> {
    s.collect_map(modes.iter().map(|(c, m)| (c, m)))
}

/// An event that changed the state or a parameter.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Action {
    /// When.
    pub t: f64,
    /// Which `[[events]]` entry.
    pub event: String,
    /// Its assignments with the values they made (`x' = -e*x' → 1.2`).
    pub set: Vec<String>,
}

/// What a hybrid run adds to a [`RunResult`] (serialized as `summary.json`'s `hybrid`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct HybridReport {
    /// Intervals of constant modes, in time order.
    pub timeline: Vec<ModeInterval>,
    /// Every switch of a contact's mode.
    pub switches: Vec<Switch>,
    /// Every impact.
    pub impacts: Vec<Impact>,
    /// Zeno accumulations.
    pub zeno: Vec<Zeno>,
    /// Work done by the contact forces on the particles over the run (negative: taken out).
    pub work_contacts: f64,
    /// Energy dissipated by friction on the slip (never negative).
    pub dissipated_friction: f64,
    /// Kinetic energy lost in impacts.
    pub dissipated_impacts: f64,
    /// Energy added by event actions (negative: taken out).
    pub energy_actions: f64,
    /// Every event that changed the state or a parameter.
    pub actions: Vec<Action>,
}

/// The parts of a hybrid model compiled once: contact probes, coefficients, kinetic energy,
/// event actions; and the cache of compiled modes.
#[derive(Clone)]
pub struct Hybrid {
    model: Model,
    layout: Layout,
    jit: JitMode,
    /// `[t, q, q', parameters]`.
    base_inputs: Vec<Id>,
    n: usize,
    /// Per contact: gap, gap rate, slip along tangents 1 and 2 (0 where there is none).
    probes: Observer,
    /// Their expressions, compiled again in each mode (whose programs go native when used
    /// long).
    probe_exprs: Vec<Id>,
    /// Per contact: e, mu_s, mu_k.
    coefficients: Observer,
    /// Kinetic energy, and the scale of the energy (`T + Σ|V|`).
    kinetic: Observer,
    /// Per model event: the values of its `set`.
    actions: Vec<Option<Observer>>,
    /// Whether an energy balance is checked (every other force has a potential, nothing
    /// depends explicitly on time).
    balance: bool,
    /// Output columns after `t` and the state.
    pub column_names: Vec<String>,
    /// `[sweep.measures]` over `[t, q, q', parameters]`.
    measures: Option<Observer>,
    cache: RefCell<Vec<CompiledMode>>,
}

#[derive(Clone)]
struct CompiledMode {
    modes: Vec<ContactMode>,
    system: CompiledModel,
    columns: Observer,
    /// Contact power, friction dissipation.
    rates: Observer,
    /// When the mode's equations are solved in closed form: `[q'', power, dissipation]` as
    /// one program of `[t, q, q', parameters]`, the whole augmented right-hand side in one
    /// evaluation.
    fused: Option<pdyn_jit::Evaluator>,
    /// Per contact: N, F_1, F_2.
    forces: Observer,
    /// The same as one program of `[t, q, q', parameters]` when the mode is solved in closed
    /// form (the event functions' contact forces without a solve).
    fused_forces: Option<pdyn_jit::Evaluator>,
    /// Per contact: gap, gap rate, slips (the hybrid's probes, compiled for this mode).
    probes: Observer,
    /// Per model event: its function in this mode.
    user_events: Vec<Observer>,
    impulse: Option<Impulse>,
    /// Right-hand side evaluations spent in this mode so far, and whether its observers run
    /// as native code yet (see [`NATIVE_AFTER`]).
    uses: std::cell::Cell<usize>,
    native: bool,
}

/// Right-hand side evaluations in a mode after which its observers (contact work rates,
/// forces, output columns, events) are compiled to native code: worth a fraction of a
/// millisecond of Cranelift per observer on a long run (1,000 stick-slip cycles), not on a
/// ball bouncing to rest.
const NATIVE_AFTER: usize = 20_000;

impl CompiledMode {
    fn make_native(&mut self) {
        self.rates.make_native();
        self.forces.make_native();
        self.columns.make_native();
        self.probes.make_native();
        for e in &mut self.user_events {
            e.make_native();
        }
        self.native = true;
    }
}

/// The impulse form of a mode's equations.
#[derive(Clone)]
struct Impulse {
    /// `A` row by row, over the base inputs.
    a: Observer,
    rows: usize,
    /// Per row: the velocity-level value of its constraint (0 for a Newton row).
    velocity: Observer,
    /// Per row: whether it is a constraint row.
    constraint_row: Vec<bool>,
    /// Per contact: its `touching` row.
    touching_row: Vec<Option<usize>>,
    /// Per free coordinate (state order): the column of its acceleration.
    accel_col: Vec<usize>,
    /// Per contact: the column of its normal force.
    normal_col: Vec<Option<usize>>,
}

impl Hybrid {
    /// Sets up the hybrid parts of `model`: the contacts' geometry, the programs every mode
    /// shares (probes, coefficients, energy, event actions, sweep measures) over the inputs
    /// `[t, q, q', parameters]`, found from the reference mode's derivation.
    pub fn new(model: &Model, jit: JitMode) -> Result<Hybrid, SimError> {
        let mut model = model.clone();
        let layout = Layout::new(&mut model);
        let reference = pdyn_mech::hybrid::reference_modes(&model, &layout);
        // The base inputs, from the reference mode's derivation (the same in every mode).
        let mm = mode_model(&model, &layout, &reference);
        let mut m2 = mm.model;
        let d = derive(&mut m2, &super::run_options()).map_err(SimError::Derive)?;
        let (base_inputs, _) = input_leaves(&mut m2, &d);
        model.pool = m2.pool;
        let n = d.free.len();
        let p = &mut model.pool;
        let mut probe_exprs = Vec::new();
        let mut probe_names = Vec::new();
        let mut coef_exprs = Vec::new();
        for (c, g) in model.contacts.iter().zip(&layout.contacts) {
            probe_exprs.push(c.gap);
            probe_exprs.push(g.gap_rate);
            for k in 0..2 {
                probe_exprs.push(g.slip.get(k).copied().unwrap_or(Pool::ZERO));
            }
            for w in ["gap", "gap_rate", "slip1", "slip2"] {
                probe_names.push(format!("{w}.{}", c.name));
            }
            let (mu_s, mu_k) = c.friction.unwrap_or((Pool::ZERO, Pool::ZERO));
            coef_exprs.extend([c.restitution, mu_s, mu_k]);
        }
        let probes = Observer::new(p, &base_inputs, probe_names, &probe_exprs.clone())
            .map_err(|e| compile_error("contact", e))?;
        let coefficients = Observer::new(
            p,
            &base_inputs,
            vec![String::new(); coef_exprs.len()],
            &coef_exprs,
        )
        .map_err(|e| compile_error("contact coefficient", e))?;
        let e = pdyn_mech::conservation::energy(p, &d.particles, &model.potentials);
        let kinetic = Observer::new(
            p,
            &base_inputs,
            vec!["T".into(), "scale".into(), "V".into()],
            &[e.kinetic, e.scale, e.potential],
        )
        .map_err(|e| compile_error("kinetic energy", e))?;
        let explicit_time = model.particles.iter().any(|pt| {
            pt.position
                .iter()
                .any(|&c| pdyn_mech::conservation::depends_on_time(p, c))
        }) || model
            .potentials
            .iter()
            .any(|v| pdyn_mech::conservation::depends_on_time(p, v.energy));
        // A Coulomb `friction` force does not clear `conservative` (the modes account for its
        // work); any other force without a potential makes the balance meaningless.
        let balance = model.conservative && !explicit_time;
        let mut actions = Vec::new();
        for ev in &model.run.events {
            if ev.actions.is_empty() {
                actions.push(None);
                continue;
            }
            let exprs: Vec<Id> = ev.actions.iter().map(|a| a.value).collect();
            let names = ev.actions.iter().map(|a| a.text.clone()).collect();
            let o = Observer::new(p, &base_inputs, names, &exprs).map_err(|e| {
                compile_error(
                    &format!(
                        "event `{}` (an action may use t, coordinates, rates and parameters)",
                        ev.name
                    ),
                    e,
                )
            })?;
            actions.push(Some(o));
        }
        let mut column_names = Vec::new();
        for part in &model.particles {
            for (axis, &c) in ["x", "y", "z"].iter().zip(&part.position) {
                if c != Pool::ZERO {
                    column_names.push(format!("{}.{axis}", part.name));
                }
            }
        }
        column_names.extend(model.reactions.iter().map(|r| r.name.clone()));
        for (c, g) in model.contacts.iter().zip(&layout.contacts) {
            if !c.normal_in_model {
                column_names.push(c.normal_force.0.clone());
            }
            for k in 0..g.tangents.len() {
                column_names.push(pdyn_mech::hybrid::friction_name(c, k));
            }
            if !c.held {
                column_names.push(format!("gap.{}", c.name));
            }
            for k in 0..g.tangents.len() {
                let suffix = if k == 0 { "" } else { "_2" };
                column_names.push(format!("slip.{}{suffix}", c.name));
            }
        }
        column_names.push("energy".into());
        column_names.extend(model.run.monitors.iter().map(|m| m.name.clone()));
        column_names.extend(
            [
                "work.contacts",
                "dissipated.friction",
                "dissipated.impacts",
                "energy_balance",
            ]
            .map(String::from),
        );
        let measures = match &model.run.sweep {
            None => None,
            Some(sw) => {
                let names = sw.measures.iter().map(|m| m.name.clone()).collect();
                let ex: Vec<Id> = sw.measures.iter().map(|m| m.of).collect();
                Some(
                    Observer::new(&mut model.pool, &base_inputs, names, &ex).map_err(|e| {
                        compile_error(
                            "sweep measure (in a model with contacts a measure may use t, coordinates, rates and parameters)",
                            e,
                        )
                    })?,
                )
            }
        };
        Ok(Hybrid {
            measures,
            probe_exprs,
            model,
            layout,
            jit,
            base_inputs,
            n,
            probes,
            coefficients,
            kinetic,
            actions,
            balance,
            column_names,
            cache: RefCell::new(Vec::new()),
        })
    }

    /// The `[sweep.measures]`, over `[t, q, q', parameters]`.
    pub fn measures(&self) -> Option<&Observer> {
        self.measures.as_ref()
    }

    /// The index of the compiled mode `modes` in the cache, compiling it if needed.
    fn mode(&self, modes: &[ContactMode]) -> Result<usize, SimError> {
        if let Some(k) = self.cache.borrow().iter().position(|m| m.modes == modes) {
            return Ok(k);
        }
        let compiled = self.compile(modes)?;
        let mut cache = self.cache.borrow_mut();
        cache.push(compiled);
        Ok(cache.len() - 1)
    }

    fn compile(&self, modes: &[ContactMode]) -> Result<CompiledMode, SimError> {
        let mm = mode_model(&self.model, &self.layout, modes);
        let mut m = mm.model;
        let d = derive(&mut m, &super::run_options()).map_err(|e| {
            let labels: Vec<String> = m
                .contacts
                .iter()
                .zip(modes)
                .map(|(c, md)| format!("{} {}", c.name, md.label()))
                .collect();
            let mut e = e;
            e.message = format!("{} (contacts: {})", e.message, labels.join(", "));
            SimError::Derive(e)
        })?;
        let system = CompiledModel::with_jit(&mut m, &d, self.jit)
            .map_err(|e| compile_error("contact mode", e))?;
        let obs = system.observation_inputs.clone();
        let p = &mut m.pool;
        let known = &mm.known;
        let mut cols = Vec::new();
        for part in &m.particles {
            for &c in &part.position {
                if c != Pool::ZERO {
                    cols.push(c);
                }
            }
        }
        let base_reactions = self.model.reactions.len();
        cols.extend(m.reactions[..base_reactions].iter().map(|r| r.id));
        for (c, g) in m.contacts.iter().zip(&self.layout.contacts) {
            if !c.normal_in_model {
                cols.push(p.subs(c.normal_force.1, known));
            }
            for k in 0..g.tangents.len() {
                cols.push(p.subs(c.friction_force.1[k], known));
            }
            if !c.held {
                cols.push(c.gap);
            }
            cols.extend(g.slip.iter().copied());
        }
        let energy = pdyn_mech::conservation::energy(p, &d.particles, &m.potentials);
        cols.push(p.add(&[energy.kinetic, energy.potential]));
        for mon in &m.run.monitors {
            cols.push(p.subs(mon.expr, known));
        }
        let mut names = self.column_names[..cols.len()].to_vec();
        // After the columns, not one of them: the energy's scale, T + Σ|V|, of each row.
        cols.push(energy.scale);
        names.push("energy scale".into());
        let columns =
            Observer::new(p, &obs, names, &cols).map_err(|e| compile_error("output column", e))?;
        let power = p.add(&mm.power);
        let diss = p.add(&mm.dissipation);
        let rates = Observer::new(p, &obs, vec!["power".into(), "diss".into()], &[power, diss])
            .map_err(|e| compile_error("contact work", e))?;
        let mut fexprs = Vec::new();
        for c in &m.contacts {
            fexprs.push(p.subs(c.normal_force.1, known));
            fexprs.push(p.subs(c.friction_force.1[0], known));
            fexprs.push(p.subs(c.friction_force.1[1], known));
        }
        let forces = Observer::new(p, &obs, vec![String::new(); fexprs.len()], &fexprs)
            .map_err(|e| compile_error("contact force", e))?;
        // When the mode is solved in closed form: each unknown (acceleration or reaction) as
        // its expression of the state, to compile what reads them over `[t, q, q', params]`.
        let solved: Option<rustc_hash::FxHashMap<Id, Id>> = d.solution.as_ref().map(|sol| {
            d.unknowns
                .iter()
                .zip(sol)
                .map(|(u, &x)| (u.id, x))
                .collect()
        });
        let fused_forces = solved.as_ref().and_then(|solved| {
            let outs: Vec<Id> = fexprs.iter().map(|&f| p.subs(f, solved)).collect();
            pdyn_expr::Program::compile(p, &self.base_inputs, &outs)
                .ok()
                .map(|prog| pdyn_jit::Evaluator::new(prog, self.jit))
        });
        let probes = Observer::new(
            p,
            &self.base_inputs,
            vec![String::new(); self.probe_exprs.len()],
            &self.probe_exprs,
        )
        .map_err(|e| compile_error("contact", e))?;
        let mut user_events = Vec::new();
        for ev in &m.run.events {
            let g = p.subs(ev.when, known);
            user_events.push(
                Observer::new(p, &obs, vec![ev.name.clone()], &[g])
                    .map_err(|e| compile_error(&format!("event `{}`", ev.name), e))?,
            );
        }
        let fused = match &solved {
            Some(solved) => {
                let p = &mut m.pool;
                let mut outs: Vec<Id> = d
                    .free
                    .iter()
                    .map(|&ci| p.coord(m.coordinates[ci].sym, 2))
                    .map(|acc| solved.get(&acc).copied().unwrap_or(Pool::ZERO))
                    .collect();
                outs.push(p.subs(power, solved));
                outs.push(p.subs(diss, solved));
                pdyn_expr::Program::compile(p, &self.base_inputs, &outs)
                    .ok()
                    .map(|prog| pdyn_jit::Evaluator::new(prog, self.jit))
            }
            None => None,
        };
        let impulse = impulse_form(&mut m, &d, &self.base_inputs)?;
        Ok(CompiledMode {
            modes: modes.to_vec(),
            system,
            columns,
            rates,
            fused,
            forces,
            fused_forces,
            probes,
            user_events,
            impulse,
            uses: std::cell::Cell::new(0),
            native: false,
        })
    }
}

/// The impulse form of a derivation: `A` and the velocity-level value of each constraint row.
fn impulse_form(
    m: &mut Model,
    d: &pdyn_mech::Derivation,
    base_inputs: &[Id],
) -> Result<Option<Impulse>, SimError> {
    let cols = d.unknowns.len();
    let rows = d.system.rows();
    if rows != cols {
        return Ok(None);
    }
    let p = &mut m.pool;
    let mut velocity = Vec::with_capacity(rows);
    let mut constraint_row = Vec::with_capacity(rows);
    let mut touching_row = vec![None; m.contacts.len()];
    for (r, eq) in d.equations.iter().enumerate() {
        let found = m.constraints.iter().find(|c| {
            let how = if c.derivatives == 1 { "once" } else { "twice" };
            eq.label == format!("constraint {} (differentiated {how})", c.label)
        });
        match found {
            Some(c) => {
                let v = if c.derivatives == 1 {
                    c.equation
                } else {
                    p.dt(c.equation)
                };
                velocity.push(v);
                constraint_row.push(true);
                for (k, ct) in m.contacts.iter().enumerate() {
                    if c.label == format!("contact {}: touching", ct.name) {
                        touching_row[k] = Some(r);
                    }
                }
            }
            None => {
                velocity.push(Pool::ZERO);
                constraint_row.push(false);
            }
        }
    }
    let accel_col: Vec<usize> = d
        .free
        .iter()
        .map(|&ci| {
            d.unknowns
                .iter()
                .position(|u| u.kind == UnknownKind::Acceleration(ci))
                .unwrap_or(0)
        })
        .collect();
    let normal_col = m
        .contacts
        .iter()
        .map(|c| d.unknowns.iter().position(|u| u.id == c.normal_force.1))
        .collect();
    let a = Observer::new(
        p,
        base_inputs,
        vec![String::new(); d.system.a.len()],
        &d.system.a,
    )
    .map_err(|e| compile_error("impulse matrix", e))?;
    let velocity = Observer::new(p, base_inputs, vec![String::new(); rows], &velocity)
        .map_err(|e| compile_error("constraint velocity", e))?;
    Ok(Some(Impulse {
        a,
        rows,
        velocity,
        constraint_row,
        touching_row,
        accel_col,
        normal_col,
    }))
}

/// The augmented state `[q, q', W_contacts, D_friction]` of one mode as an ODE.
struct Augmented<'a> {
    mode: &'a CompiledMode,
    n: usize,
    input: RefCell<Vec<f64>>,
    rates: RefCell<[f64; 2]>,
    /// `[t, q, q', parameters]`, workspace and outputs of the fused program.
    fused: RefCell<(Vec<f64>, Vec<f64>, Vec<f64>)>,
}

impl<'a> Augmented<'a> {
    fn new(mode: &'a CompiledMode, n: usize, params: &[f64]) -> Augmented<'a> {
        let mut base = vec![0.0; 1 + 2 * n];
        base.extend_from_slice(params);
        let (ws, out) = match &mode.fused {
            Some(f) => (f.workspace(), vec![0.0; f.n_outputs()]),
            None => (Vec::new(), Vec::new()),
        };
        Augmented {
            mode,
            n,
            input: RefCell::new(Vec::new()),
            rates: RefCell::new([0.0; 2]),
            fused: RefCell::new((base, ws, out)),
        }
    }
}

impl OdeSystem for Augmented<'_> {
    fn dim(&self) -> usize {
        2 * self.n + 2
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let n = self.n;
        if let Some(f) = &self.mode.fused {
            let mut b = self.fused.borrow_mut();
            let (base, ws, out) = &mut *b;
            base[0] = t;
            base[1..1 + 2 * n].copy_from_slice(&y[..2 * n]);
            f.eval(base, ws, out);
            dydt[..n].copy_from_slice(&y[n..2 * n]);
            dydt[n..2 * n + 2].copy_from_slice(&out[..n + 2]);
            return;
        }
        let mut input = self.input.borrow_mut();
        self.mode
            .system
            .observation_input(t, &y[..2 * n], &mut input);
        let base = input.len() - n - self.mode.system.n_reactions;
        dydt[..n].copy_from_slice(&y[n..2 * n]);
        dydt[n..2 * n].copy_from_slice(&input[base..base + n]);
        let mut r = self.rates.borrow_mut();
        self.mode.rates.eval(&input, &mut r[..]);
        dydt[2 * n] = r[0];
        dydt[2 * n + 1] = r[1];
    }
}

/// Buffers of a segment's event functions.
#[derive(Default)]
struct EventScratch {
    base: Vec<f64>,
    obs: Vec<f64>,
    out: Vec<f64>,
    ws: Vec<f64>,
}

/// What ends a segment.
#[derive(Clone, Copy, Debug)]
enum Trigger {
    Touch(usize),
    Release(usize),
    Tensile(usize),
    Breakaway(usize),
    SlipStops(usize),
    Rebase(usize),
    User(usize),
}

/// The mutable state of one hybrid run.
struct State<'h> {
    h: &'h Hybrid,
    params: Vec<f64>,
    /// Per contact: e, mu_s, mu_k.
    coef: Vec<[f64; 3]>,
    modes: Vec<ContactMode>,
    t: f64,
    y: Vec<f64>,
    w_impacts: f64,
    /// Energy added by event actions (a burn, a parameter of a potential changed).
    w_actions: f64,
    report: HybridReport,
    warnings: Vec<String>,
    /// Per contact: the times of its impacts in the current bounce sequence.
    bounces: Vec<Vec<f64>>,
    /// Per contact sliding in a plane: the slip direction the segment started with.
    slip_dir: Vec<[f64; 2]>,
    length_scale: f64,
    speed_scale: f64,
    tensile_warned: Vec<bool>,
}

const ZENO_REMAINING: f64 = 1e-10;

/// Integrations of one segment with shorter and shorter steps before a penetration is
/// reported instead of resolved.
const MAX_RETRIES: usize = 40;

/// Default largest step of a hybrid run, as a fraction of its span (`--max-step` overrides).
const MAX_STEP_FRACTION: f64 = 64.0;

impl State<'_> {
    fn base_input(&self, t: f64, y: &[f64]) -> Vec<f64> {
        let n = self.h.n;
        let mut v = Vec::with_capacity(1 + 2 * n + self.params.len());
        v.push(t);
        v.extend_from_slice(&y[..2 * n]);
        v.extend_from_slice(&self.params);
        v
    }

    /// Per contact: gap, gap rate, slip 1, slip 2.
    fn probe(&self, t: f64, y: &[f64]) -> Vec<[f64; 4]> {
        let input = self.base_input(t, y);
        let mut out = vec![0.0; self.h.probes.len()];
        self.h.probes.eval(&input, &mut out);
        out.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
    }

    fn x_tol(&self) -> f64 {
        1e-9 * self.length_scale.max(1e-300)
    }

    fn v_tol(&self) -> f64 {
        1e-9 * self.speed_scale.max(1e-300)
    }

    /// Per contact: N, F_1, F_2 in `modes` at (t, y).
    fn forces(&self, modes: &[ContactMode], t: f64, y: &[f64]) -> Result<Vec<[f64; 3]>, SimError> {
        let k = self.h.mode(modes)?;
        let cache = self.h.cache.borrow();
        let cm = &cache[k];
        cm.system.set_parameters(&self.params);
        let mut input = Vec::new();
        cm.system
            .observation_input(t, &y[..2 * self.h.n], &mut input);
        let mut out = vec![0.0; cm.forces.len()];
        cm.forces.eval(&input, &mut out);
        Ok(out.chunks(3).map(|c| [c[0], c[1], c[2]]).collect())
    }

    /// Kinetic energy, the energy's scale and the potential energy at (t, y).
    fn kinetic(&self, t: f64, y: &[f64]) -> [f64; 3] {
        let mut out = [0.0; 3];
        self.h.kinetic.eval(&self.base_input(t, y), &mut out);
        out
    }

    /// Makes every contact's mode consistent with the forces at (t, y): a touching contact
    /// whose normal force would pull opens, a stuck one whose friction would exceed `mu_s N`
    /// slides. (A sliding contact sticks only where its slip stops, at its event: right
    /// after a break-away its slip is zero too, and it must go on sliding.)
    fn settle(&mut self, t: f64) -> Result<(), SimError> {
        let k = self.modes.len();
        for _ in 0..4 * k + 4 {
            let forces = self.forces(&self.modes.clone(), t, &self.y)?;
            let mut changed = false;
            for (c, &[n_force, f1, f2]) in forces.iter().enumerate() {
                let contact = &self.h.model.contacts[c];
                let mode = self.modes[c];
                let [_, mu_s, _] = self.coef[c];
                let f_tol = 1e-12 * (n_force.abs() + f1.abs() + f2.abs()) + 1e-300;
                if mode.closed() && !contact.held && n_force < -f_tol {
                    self.switch(
                        c,
                        ContactMode::Open,
                        t,
                        format!("the normal force would pull (N = {n_force:.6e})"),
                    );
                    changed = true;
                    break;
                }
                if mode.closed() && contact.held && n_force < -f_tol && !self.tensile_warned[c] {
                    self.tensile_warned[c] = true;
                    self.warnings.push(format!(
                        "contact `{}` pulls on the particle (N = {n_force:.6e}) at t = {t:.9e}: a one-sided contact cannot hold it, but the model's coordinates keep it on the surface; give it a coordinate to leave by, or this motion is wrong from here on",
                        contact.name
                    ));
                }
                let tangents = self.h.layout.contacts[c].tangents.len();
                let f = libm::hypot(f1, f2);
                if mode == ContactMode::Stuck && f > mu_s * n_force.max(0.0) + f_tol {
                    let to = self.sliding_from_force(c, [f1, f2], tangents);
                    self.switch(
                        c,
                        to,
                        t,
                        format!("|F| = {f:.6e} exceeds mu_s N = {:.6e}", mu_s * n_force),
                    );
                    changed = true;
                    break;
                }
            }
            if !changed {
                return Ok(());
            }
        }
        Err(self.stuck_error(
            t,
            "the contact modes do not settle (each choice of modes contradicts its own forces)",
        ))
    }

    /// Sliding against the force that sticking would need.
    fn sliding_from_force(&mut self, c: usize, f: [f64; 2], tangents: usize) -> ContactMode {
        if tangents == 1 {
            ContactMode::Sliding(if f[0] > 0.0 { -1 } else { 1 })
        } else {
            let m = libm::hypot(f[0], f[1]).max(1e-300);
            self.slip_dir[c] = [-f[0] / m, -f[1] / m];
            ContactMode::Sliding(0)
        }
    }

    fn stuck_error(&self, t: f64, why: &str) -> SimError {
        SimError::Contact {
            message: format!("{why} at t = {t:.9e}"),
        }
    }

    fn switch(&mut self, c: usize, to: ContactMode, t: f64, reason: String) {
        let from = self.modes[c];
        if from == to {
            return;
        }
        self.modes[c] = to;
        self.report.switches.push(Switch {
            t,
            contact: self.h.model.contacts[c].name.clone(),
            from: from.label(),
            to: to.label(),
            reason,
        });
    }

    /// Velocity jump at (t, y) in `modes`: every constraint's velocity-level value becomes
    /// zero, except the bouncing contact's gap rate, which becomes `target`. Returns the
    /// bouncing contact's normal impulse.
    fn project(
        &mut self,
        modes: &[ContactMode],
        t: f64,
        bounce: Option<(usize, f64)>,
    ) -> Result<f64, SimError> {
        let k = self.h.mode(modes)?;
        let cache = self.h.cache.borrow();
        let Some(imp) = &cache[k].impulse else {
            return Err(self.stuck_error(
                t,
                "the impulse equations of this contact mode are not square",
            ));
        };
        let n = self.h.n;
        let input = self.base_input(t, &self.y);
        let m = imp.rows;
        let mut a = vec![0.0; m * m];
        imp.a.eval(&input, &mut a);
        let mut vel = vec![0.0; m];
        imp.velocity.eval(&input, &mut vel);
        let mut rhs = vec![0.0; m];
        for r in 0..m {
            if imp.constraint_row[r] {
                rhs[r] = -vel[r];
            }
        }
        if let Some((c, target)) = bounce {
            if let Some(r) = imp.touching_row[c] {
                rhs[r] = target - vel[r];
            }
        }
        let mut lu = pdyn_ode::linalg::Lu::new(m);
        // `A` is row by row; the factorisation reads columns.
        for (i, row) in a.chunks(m).enumerate() {
            for (j, &x) in row.iter().enumerate() {
                lu.matrix_mut()[j * m + i] = x;
            }
        }
        if lu.factor().is_err() {
            return Err(self.stuck_error(t, "the impulse equations are singular (a contact's normal does not move any coordinate)"));
        }
        lu.solve_in_place(&mut rhs);
        if rhs.iter().any(|x| !x.is_finite()) {
            return Err(self.stuck_error(t, "the impulse equations gave a non-finite velocity"));
        }
        for i in 0..n {
            self.y[n + i] += rhs[imp.accel_col[i]];
        }
        Ok(bounce
            .and_then(|(c, _)| imp.normal_col[c])
            .map_or(0.0, |col| rhs[col]))
    }

    /// The contact `c` has just closed at (t, y): an impact, then resting contact or a
    /// bounce.
    fn touch(&mut self, c: usize, t: f64) -> Result<(), SimError> {
        let probes = self.probe(t, &self.y);
        let rate = probes[c][1];
        let e = self.coef[c][0];
        let u = -rate;
        self.speed_scale = self.speed_scale.max(u.abs());
        let mut closed = self.modes.clone();
        closed[c] = self.initial_closed_mode(c, &probes[c]);
        if u <= self.v_tol() {
            self.switch(
                c,
                closed[c],
                t,
                format!("touches (closing speed {u:.3e}, no impact)"),
            );
            self.bounces[c].clear();
            return self.settle(t);
        }
        let seq = &mut self.bounces[c];
        seq.push(t);
        let mut zeno: Option<(f64, f64)> = None;
        if seq.len() >= 4 {
            let l = seq.len();
            let (d0, d1, d2) = (
                seq[l - 3] - seq[l - 4],
                seq[l - 2] - seq[l - 3],
                seq[l - 1] - seq[l - 2],
            );
            let (r1, r2) = (d1 / d0, d2 / d1);
            if r2 > 0.0 && r2 < 1.0 && (r2 - r1).abs() <= 1e-3 * r2 + 1e-9 {
                let remaining = d2 * r2 / (1.0 - r2);
                if remaining <= ZENO_REMAINING * (t - seq[0]).max(t) || e * u <= self.v_tol() {
                    zeno = Some((t + remaining, r2));
                }
            }
        }
        let plastic = zeno.is_some() || e * u <= self.v_tol();
        let target = if plastic { 0.0 } else { e * u };
        let t_before = self.kinetic(t, &self.y)[0];
        let y_before = self.y.clone();
        let mut impulse = self.project(&closed, t, Some((c, target)))?;
        // Friction at the impact: sliding, its impulse is mu_k times the normal one against
        // the slip; if that would reverse the slip, the contact sticks during the impact
        // instead (its tangential velocity becomes zero, within mu_s of the normal impulse).
        if let ContactMode::Sliding(_) = closed[c] {
            let before = probes[c];
            let after = self.probe(t, &self.y)[c];
            if before[2] * after[2] + before[3] * after[3] < 0.0 {
                self.y = y_before;
                closed[c] = ContactMode::Stuck;
                impulse = self.project(&closed, t, Some((c, target)))?;
            }
        }
        let t_after = self.kinetic(t, &self.y)[0];
        self.w_impacts += t_after - t_before;
        if t_after - t_before > 1e-9 * t_before.abs().max(1e-300)
            && self.h.model.contacts[c].friction.is_none()
        {
            self.warnings.push(format!(
                "impact at contact `{}` at t = {t:.9e} gained kinetic energy ({:.6e}): with e <= 1 an impact on a fixed surface cannot; check the surface's motion",
                self.h.model.contacts[c].name,
                t_after - t_before
            ));
        }
        self.report.impacts.push(Impact {
            t,
            contact: self.h.model.contacts[c].name.clone(),
            normal_speed_before: u,
            normal_speed_after: target,
            impulse,
            energy_lost: t_before - t_after,
        });
        if let Some((t_acc, ratio)) = zeno {
            self.report.zeno.push(Zeno {
                contact: self.h.model.contacts[c].name.clone(),
                t_accumulation: t_acc,
                ratio,
                bounces: self.bounces[c].len(),
            });
        }
        if plastic {
            let why = match zeno {
                Some((t_acc, r)) => {
                    format!("bounces accumulate at t = {t_acc:.9e} (ratio {r:.6}): resting contact")
                }
                None => "impact with no rebound: resting contact".to_string(),
            };
            self.switch(c, closed[c], t, why);
            self.bounces[c].clear();
            self.settle(t)
        } else {
            Ok(())
        }
    }

    /// The closed mode a contact starts in: sliding if it slips, stuck otherwise (the
    /// settling then frees it if it cannot stick).
    fn initial_closed_mode(&mut self, c: usize, probe: &[f64; 4]) -> ContactMode {
        let g = &self.h.layout.contacts[c];
        let slip = [probe[2], probe[3]];
        match g.tangents.len() {
            0 => ContactMode::Smooth,
            1 if slip[0].abs() > self.v_tol() => {
                ContactMode::Sliding(if slip[0] > 0.0 { 1 } else { -1 })
            }
            1 => ContactMode::Stuck,
            _ => {
                let s = libm::hypot(slip[0], slip[1]);
                if s > self.v_tol() {
                    self.slip_dir[c] = [slip[0] / s, slip[1] / s];
                    ContactMode::Sliding(0)
                } else {
                    ContactMode::Stuck
                }
            }
        }
    }
}

/// Runs a hybrid model.
pub fn run(prep: &Prepared, h: &Hybrid, set: &RunSettings) -> Result<RunResult, SimError> {
    let method = method_by_name(&set.method).ok_or_else(|| SimError::UnknownMethod {
        name: set.method.clone(),
    })?;
    set.validate()?;
    if matches!(
        method.kind(),
        MethodKind::Symplectic | MethodKind::FixedStep
    ) {
        return Err(SimError::Contact {
            message: format!(
                "method `{}` takes fixed steps; a model with contacts or event actions needs an adaptive method (auto, dopri5, dop853, tsit5, vern9, radau5) to locate its switches",
                set.method
            ),
        });
    }
    let params = prep.system.parameters();
    if let Some(checks) = &prep.value_checks {
        checks.check(&params).map_err(SimError::InvalidValue)?;
    }
    let n = h.n;
    let k = h.model.contacts.len();
    let mut coef_out = vec![0.0; 3 * k];
    let mut input0 = vec![0.0];
    input0.extend_from_slice(&prep.y0);
    input0.extend_from_slice(&params);
    h.coefficients.eval(&input0, &mut coef_out);
    let coef: Vec<[f64; 3]> = coef_out.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    for (c, v) in h.model.contacts.iter().zip(&coef) {
        let bad = if !(0.0..=1.0).contains(&v[0]) {
            Some(format!(
                "its coefficient of restitution e = {} is outside [0, 1]",
                v[0]
            ))
        } else if !(v[1] >= 0.0 && v[2] >= 0.0) {
            Some(format!(
                "its friction coefficients (mu_s = {}, mu_k = {}) must be >= 0",
                v[1], v[2]
            ))
        } else if v[2] > v[1] {
            Some(format!("mu_k = {} exceeds mu_s = {}", v[2], v[1]))
        } else {
            None
        };
        if let Some(why) = bad {
            return Err(SimError::Contact {
                message: format!("contact `{}`: {why}", c.name),
            });
        }
    }
    let mut y = prep.y0.clone();
    y.extend([0.0, 0.0]);
    let scale = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut st = State {
        h,
        params,
        coef,
        modes: h
            .model
            .contacts
            .iter()
            .zip(&h.layout.contacts)
            .map(|(c, g)| {
                if c.held {
                    closed_modes(g)[0]
                } else {
                    ContactMode::Open
                }
            })
            .collect(),
        t: 0.0,
        length_scale: scale(&y[..n]).max(1e-3),
        speed_scale: scale(&y[n..2 * n]).max(1e-3),
        y,
        w_impacts: 0.0,
        w_actions: 0.0,
        report: HybridReport::default(),
        warnings: Vec::new(),
        bounces: vec![Vec::new(); k],
        slip_dir: vec![[1.0, 0.0]; k],
        tensile_warned: vec![false; k],
    };
    // The initial modes: open, touching (after an impact if closing), stuck or sliding.
    let probes = st.probe(0.0, &st.y);
    for (c, p) in probes.iter().enumerate() {
        let contact = &h.model.contacts[c];
        let [gap, rate, ..] = *p;
        if contact.held {
            st.modes[c] = st.initial_closed_mode(c, p);
            continue;
        }
        if gap < -st.x_tol() {
            return Err(SimError::Contact {
                message: format!(
                    "contact `{}` starts penetrated: its gap is {gap:.6e} at t = 0 (it must be >= 0: the particle starts on the free side of the surface or on it)",
                    contact.name
                ),
            });
        }
        if gap <= st.x_tol() && rate <= st.v_tol() {
            st.touch(c, 0.0)?;
            let p = st.probe(0.0, &st.y)[c];
            if st.modes[c] == ContactMode::Open && p[1] <= st.v_tol() {
                st.modes[c] = st.initial_closed_mode(c, &p);
            }
        }
    }
    st.report.switches.clear();
    st.settle(0.0)?;

    let mut opts = Options::default();
    if let Some(r) = set.rtol {
        opts.rtol = r.into();
    }
    if let Some(a) = set.atol {
        opts.atol = a.into();
    }
    opts.h0 = set.dt;
    // A contact that closes between two steps of a motion the integrator finds easy (free
    // flight is a polynomial: one step can span the run) leaves the gap's sign unchanged at
    // both ends; steps of at most 1/64 of the run give the event locator's dip test the
    // three values it needs.
    opts.max_step = Some(set.max_step.unwrap_or(set.t_end / MAX_STEP_FRACTION));
    if let Some(m) = set.max_steps {
        opts.max_steps = m;
    }
    opts.interrupt = set.interrupt.clone();
    let t_end = set.t_end;
    let step_budget = opts.max_steps;
    let mut steps_used = 0usize;
    let output_times = set.output_times();
    let columns = {
        let mut c = vec!["t".to_string()];
        c.extend(prep.state_names.iter().cloned());
        c.extend(h.column_names.iter().cloned());
        c
    };
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut events: Vec<EventReport> = Vec::new();
    let mut stats = pdyn_ode::Stats::default();
    let mut failure = None;
    let mut status = RunStatus::Finished;
    let mut user_counts = vec![0usize; h.model.run.events.len()];
    let mut segment_start = 0.0;
    // The user event that ended the previous segment and whether it rose through zero.
    let mut last_fired: Option<(usize, bool)> = None;
    let mut same_time_switches = 0usize;
    let mut first = true;
    let mut sol_method;
    let mut scales: Vec<f64> = Vec::new();
    let mut push = super::PushWatch::default();
    let balance_index = columns.len() - 1;
    loop {
        let t0 = st.t;
        let mode_index = st.h.mode(&st.modes)?;
        let labels: Vec<(String, &'static str)> = h
            .model
            .contacts
            .iter()
            .zip(&st.modes)
            .map(|(c, m)| (c.name.clone(), m.label()))
            .collect();
        // A bounce keeps the contact open: one interval, the impacts are listed apart.
        if st
            .report
            .timeline
            .last()
            .is_none_or(|iv| iv.modes != labels)
        {
            st.report.timeline.push(ModeInterval {
                t_from: t0,
                t_to: t0,
                modes: labels,
            });
        }
        {
            let mut cache = h.cache.borrow_mut();
            let cm = &mut cache[mode_index];
            if !cm.native && cm.uses.get() >= NATIVE_AFTER && prep.system.is_native() {
                cm.make_native();
            }
        }
        let cache = h.cache.borrow();
        let cm = &cache[mode_index];
        cm.system.set_parameters(&st.params);
        let aug = Augmented::new(cm, n, &st.params);
        // Event functions of this segment.
        let mut triggers: Vec<(Trigger, Direction)> = Vec::new();
        for (c, contact) in h.model.contacts.iter().enumerate() {
            match st.modes[c] {
                ContactMode::Open => triggers.push((Trigger::Touch(c), Direction::Falling)),
                mode => {
                    let release = if contact.held {
                        Trigger::Tensile(c)
                    } else {
                        Trigger::Release(c)
                    };
                    triggers.push((release, Direction::Falling));
                    match mode {
                        ContactMode::Stuck => {
                            triggers.push((Trigger::Breakaway(c), Direction::Rising))
                        }
                        ContactMode::Sliding(1) => {
                            triggers.push((Trigger::SlipStops(c), Direction::Falling))
                        }
                        ContactMode::Sliding(-1) => {
                            triggers.push((Trigger::SlipStops(c), Direction::Rising))
                        }
                        ContactMode::Sliding(_) => {
                            triggers.push((Trigger::SlipStops(c), Direction::Falling));
                            triggers.push((Trigger::Rebase(c), Direction::Falling));
                        }
                        _ => {}
                    }
                }
            }
        }
        for (j, ev) in h.model.run.events.iter().enumerate() {
            let dir = match ev.direction {
                Crossing::Rising => Direction::Rising,
                Crossing::Falling => Direction::Falling,
                Crossing::Both => Direction::Both,
            };
            triggers.push((Trigger::User(j), dir));
        }
        let start_probes = st.probe(t0, &st.y);
        let params = st.params.clone();
        let coef = st.coef.clone();
        let slip_dir = st.slip_dir.clone();
        // One scratch for every event function of the segment: they are called after each
        // step and many times while a crossing is located, and must not allocate.
        // The event that ended the last segment restarts at its zero, on either side of it
        // by round-off: one still on the side it came from would fire again at once (and an
        // action doubling g would double it forever). Its function is shifted so that the
        // segment starts on the side it crossed to; a later crossing is then a new one.
        let rearm: Option<(usize, f64)> = last_fired.and_then(|(j, rising)| {
            let mut obs = Vec::new();
            cm.system.observation_input(t0, &st.y[..2 * n], &mut obs);
            let mut out = [0.0];
            cm.user_events[j].eval(&obs, &mut out);
            let g0 = out[0];
            let before_side = if rising { g0 < 0.0 } else { g0 > 0.0 };
            before_side.then_some((j, 2.0 * g0))
        });
        let scratch = RefCell::new(EventScratch {
            ws: cm
                .fused_forces
                .as_ref()
                .map_or_else(Vec::new, |f| f.workspace()),
            ..EventScratch::default()
        });
        let scratch = &scratch;
        let g_fns: Vec<Box<EventFn<'_>>> = triggers
            .iter()
            .map(|&(trig, _)| {
                let params = params.clone();
                let coef = coef.clone();
                let slip_dir = slip_dir.clone();
                let f: Box<EventFn<'_>> = Box::new(move |t: f64, y: &[f64]| {
                    let mut sc = scratch.borrow_mut();
                    let sc = &mut *sc;
                    let mut probe = |c: usize| {
                        sc.base.clear();
                        sc.base.push(t);
                        sc.base.extend_from_slice(&y[..2 * n]);
                        sc.base.extend_from_slice(&params);
                        sc.out.resize(cm.probes.len(), 0.0);
                        cm.probes.eval(&sc.base, &mut sc.out);
                        let o = &sc.out[4 * c..4 * c + 4];
                        [o[0], o[1], o[2], o[3]]
                    };
                    match trig {
                        Trigger::Touch(c) => probe(c)[0],
                        Trigger::SlipStops(c) => {
                            let p = probe(c);
                            if cm.modes[c] == ContactMode::Sliding(0) {
                                p[2] * slip_dir[c][0] + p[3] * slip_dir[c][1]
                            } else {
                                p[2]
                            }
                        }
                        Trigger::Rebase(c) => {
                            let p = probe(c);
                            p[2] * slip_dir[c][0] + p[3] * slip_dir[c][1]
                                - 0.5 * libm::hypot(p[2], p[3])
                        }
                        Trigger::Release(c) | Trigger::Tensile(c) | Trigger::Breakaway(c) => {
                            sc.out.resize(cm.forces.len(), 0.0);
                            match &cm.fused_forces {
                                Some(f) => {
                                    sc.base.clear();
                                    sc.base.push(t);
                                    sc.base.extend_from_slice(&y[..2 * n]);
                                    sc.base.extend_from_slice(&params);
                                    f.eval(&sc.base, &mut sc.ws, &mut sc.out);
                                }
                                None => {
                                    cm.system.observation_input(t, &y[..2 * n], &mut sc.obs);
                                    cm.forces.eval(&sc.obs, &mut sc.out);
                                }
                            }
                            let f = &sc.out[3 * c..3 * c + 3];
                            if matches!(trig, Trigger::Breakaway(_)) {
                                libm::hypot(f[1], f[2]) - coef[c][1] * f[0]
                            } else {
                                f[0]
                            }
                        }
                        Trigger::User(j) => {
                            cm.system.observation_input(t, &y[..2 * n], &mut sc.obs);
                            let mut out = [0.0];
                            cm.user_events[j].eval(&sc.obs, &mut out);
                            out[0] - rearm.filter(|r| r.0 == j).map_or(0.0, |r| r.1)
                        }
                    }
                });
                f
            })
            .collect();
        let ode_events: Vec<Event> = triggers
            .iter()
            .zip(&g_fns)
            .map(|(&(trig, dir), g)| {
                let e = Event::new(g.as_ref()).direction(dir);
                match trig {
                    Trigger::User(j) => {
                        let ev = &h.model.run.events[j];
                        if ev.actions.is_empty() && ev.terminal.is_none() {
                            e
                        } else {
                            e.terminal(1)
                        }
                    }
                    _ => e.terminal(1),
                }
            })
            .collect();
        opts.t_eval = output_times.as_ref().map(|ts| {
            ts.iter()
                .copied()
                .filter(|&x| if first { x >= t0 } else { x > t0 })
                .collect()
        });
        // `max_steps` bounds the whole run: every segment takes at least one step.
        let mut seg_opts = opts.clone();
        // A step that starts at a contact (gap 0 after a bounce) can carry the particle
        // through a whole short flight and into the surface: the gap's sign at the step's
        // start (zero) does not count as a crossing. Such a segment is integrated again with
        // shorter steps until no open contact penetrates (the crossing is then seen).
        let mut attempts = 0;
        let (sol, fail) = loop {
            seg_opts.max_steps = step_budget.saturating_sub(steps_used).max(1);
            let result = pdyn_ode::solve_with_events(
                method,
                &aug,
                (t0, t_end),
                &st.y,
                &seg_opts,
                &ode_events,
            );
            let (sol, fail) = match result {
                Ok(s) => (s, None),
                Err(mut e) => match e.take_partial() {
                    Some(partial) => (partial, Some(e)),
                    None => return Err(SimError::Integrator(e)),
                },
            };
            stats.add(&sol.stats);
            // The segment's end tells: a flight stepped over ends below the surface (a dip
            // and back within a step is the event locator's to find).
            let penetrated = sol.len().checked_sub(1).filter(|&i| {
                let p = st.probe(sol.t[i], sol.y_at(i));
                h.model.contacts.iter().enumerate().any(|(c, contact)| {
                    !contact.held && st.modes[c] == ContactMode::Open && p[c][0] < -st.x_tol()
                })
            });
            match penetrated {
                Some(i) if attempts < MAX_RETRIES && sol.t[i] > t0 => {
                    attempts += 1;
                    seg_opts.h0 = None;
                    seg_opts.max_step = Some((sol.t[i] - t0) / 8.0);
                }
                Some(i) => {
                    st.warnings.push(format!(
                        "a contact was found penetrated by {:.3e} at t = {:.9e}, and shorter steps did not find where it closed: the motion after this time is wrong; limit the step with {}",
                        -st.probe(sol.t[i], sol.y_at(i)).iter().map(|p| p[0]).fold(0.0, f64::min),
                        sol.t[i],
                        crate::options::RunOption::MaxStep
                    ));
                    break (sol, fail);
                }
                None => break (sol, fail),
            }
        };
        sol_method = sol.method;
        cm.uses.set(cm.uses.get() + sol.stats.fevals);
        // The next segment starts with the step this one was taking (the initial step
        // heuristic after a switch guesses too long about half the time).
        if set.dt.is_none()
            && output_times.is_none()
            && sol.len() >= 3
            && !matches!(sol.status, Status::TerminalEvent(i) if matches!(triggers[i].0, Trigger::Touch(_)))
        {
            let k = sol.len();
            let h_last = sol.t[k - 2] - sol.t[k - 3];
            opts.h0 = (h_last > 0.0).then_some(h_last);
        } else {
            opts.h0 = set.dt;
        }
        // Rows of this segment (a requested output time only, when there are output times:
        // the segment's last point is its switch).
        let stop_time = match sol.status {
            Status::TerminalEvent(_) => sol.t.last().copied(),
            Status::Finished => None,
        };
        let mut input = Vec::new();
        let mut out = vec![0.0; cm.columns.len()];
        for i in 0..sol.len() {
            let (t, yy) = (sol.t[i], sol.y_at(i));
            if !first && output_times.is_none() && i == 0 {
                // The segment's first point is the previous one's last (after the switch):
                // kept, so that a jump shows as two rows at one time.
            }
            if let (Some(ts), Some(tstop)) = (&output_times, stop_time) {
                if i + 1 == sol.len() && t == tstop && !ts.contains(&t) {
                    continue;
                }
            }
            cm.system.observation_input(t, &yy[..2 * n], &mut input);
            cm.columns.eval(&input, &mut out);
            let mut row = Vec::with_capacity(columns.len());
            row.push(t);
            row.extend_from_slice(&yy[..2 * n]);
            let (scale_of_row, out) = out.split_last().map_or((0.0, &out[..]), |(s, o)| (*s, o));
            row.extend_from_slice(out);
            let (w, dfr) = (yy[2 * n], yy[2 * n + 1]);
            let energy = out[out.len() - 1 - h.model.run.monitors.len()];
            row.extend([
                w,
                dfr,
                0.0 - st.w_impacts,
                energy - w - st.w_impacts - st.w_actions,
            ]);
            push.check(prep, t, &row[1 + 2 * n..]);
            scales.push(scale_of_row);
            rows.push(row);
        }
        for miss in &sol.possible_misses {
            // A contact that has just opened starts at gap 0 with the gap growing as t²: the
            // dip test's parabola through its first values sees a vertex at zero. Not a miss.
            if let Trigger::Touch(c) = triggers[miss.index].0 {
                let just_opened = start_probes[c][0].abs() <= st.x_tol();
                if just_opened && miss.t_from <= t0 + (t_end - t0) / MAX_STEP_FRACTION {
                    continue;
                }
            }
            let what = match triggers[miss.index].0 {
                Trigger::User(j) => format!("event `{}`", h.model.run.events[j].name),
                Trigger::Touch(c) => format!(
                    "contact `{}` (it may have touched)",
                    h.model.contacts[c].name
                ),
                _ => "a contact switch".to_string(),
            };
            st.warnings.push(format!(
                "{what} may have crossed zero twice unseen between t = {:.9e} and {:.9e}: limit the step with {}",
                miss.t_from, miss.t_to, crate::options::RunOption::MaxStep
            ));
        }
        for hit in &sol.events {
            if let Trigger::User(j) = triggers[hit.index].0 {
                if h.model.run.events[j].actions.is_empty()
                    && h.model.run.events[j].terminal.is_none()
                {
                    events.push(EventReport {
                        name: h.model.run.events[j].name.clone(),
                        t: hit.t,
                        state: hit.y[..2 * n].to_vec(),
                        rising: hit.direction == Direction::Rising,
                    });
                }
            }
        }
        drop(g_fns);
        drop(cache);
        if let Some(interval) = st.report.timeline.last_mut() {
            interval.t_to = sol.t.last().copied().unwrap_or(t0);
        }
        if let Some(e) = fail {
            let fp = e.failure_point();
            let (t, yv) = fp.map_or((st.t, st.y.clone()), |fp| (fp.t, fp.y.clone()));
            failure = Some(RunFailure {
                t,
                state: prep
                    .state_names
                    .iter()
                    .cloned()
                    .zip(yv.iter().copied())
                    .collect(),
                error: e,
                stiff_at: None,
                non_finite: Vec::new(),
            });
            status = RunStatus::Failed;
            break;
        }
        first = false;
        steps_used += sol.stats.steps.max(1);
        let Status::TerminalEvent(idx) = sol.status else {
            break;
        };
        if steps_used >= step_budget {
            let state = prep
                .state_names
                .iter()
                .cloned()
                .zip(st.y.iter().copied())
                .collect();
            failure = Some(RunFailure {
                t: sol.t.last().copied().unwrap_or(t0),
                state,
                error: OdeError::MaxSteps {
                    max_steps: step_budget,
                    at: pdyn_ode::FailurePoint {
                        t: sol.t.last().copied().unwrap_or(t0),
                        y: st.y[..2 * n].to_vec(),
                        partial: Box::new(sol.clone()),
                    },
                },
                stiff_at: None,
                non_finite: Vec::new(),
            });
            status = RunStatus::Failed;
            break;
        }
        let Some((te, ye)) = sol.last() else { break };
        st.t = te;
        st.y = ye.to_vec();
        if te - segment_start <= 1e-13 * te.abs().max(1.0) {
            same_time_switches += 1;
        } else {
            same_time_switches = 0;
        }
        segment_start = te;
        if same_time_switches > 100 {
            failure = Some(stopped(
                prep,
                te,
                &st.y,
                "the contact modes switch back and forth without time advancing (chattering): the model's friction or contact data contradict each other here".into(),
            ));
            status = RunStatus::Failed;
            break;
        }
        let trig = triggers[idx].0;
        last_fired = None;
        let res = match trig {
            Trigger::Touch(c) => st.touch(c, te),
            Trigger::Release(c) => {
                st.switch(
                    c,
                    ContactMode::Open,
                    te,
                    "the normal force reached 0".into(),
                );
                st.bounces[c].clear();
                st.settle(te)
            }
            Trigger::Tensile(c) => {
                if !st.tensile_warned[c] {
                    st.tensile_warned[c] = true;
                    st.warnings.push(format!(
                        "contact `{}` would have to pull (its normal force falls through 0 at t = {te:.9e}): a one-sided contact lets go here, but the model's coordinates keep the particle on the surface; give it a coordinate to leave by, or the motion after this time is wrong",
                        h.model.contacts[c].name
                    ));
                }
                Ok(())
            }
            Trigger::Breakaway(c) => {
                let f = st.forces(&st.modes.clone(), te, &st.y)?[c];
                let tangents = h.layout.contacts[c].tangents.len();
                let to = st.sliding_from_force(c, [f[1], f[2]], tangents);
                st.switch(
                    c,
                    to,
                    te,
                    format!("|F| reached mu_s N = {:.6e}", st.coef[c][1] * f[0]),
                );
                st.settle(te)
            }
            Trigger::SlipStops(c) | Trigger::Rebase(c) => {
                let p = st.probe(te, &st.y)[c];
                let speed = libm::hypot(p[2], p[3]);
                if matches!(trig, Trigger::Rebase(_)) && speed > 1e3 * st.v_tol() {
                    st.slip_dir[c] = [p[2] / speed, p[3] / speed];
                    Ok(())
                } else {
                    let mut trial = st.modes.clone();
                    trial[c] = ContactMode::Stuck;
                    st.project(&trial, te, None)?;
                    let f = st.forces(&trial, te, &st.y)?[c];
                    let ft = libm::hypot(f[1], f[2]);
                    let mu_s = st.coef[c][1];
                    if ft <= mu_s * f[0].max(0.0) + 1e-12 * (ft + f[0].abs()) {
                        st.switch(
                            c,
                            ContactMode::Stuck,
                            te,
                            format!(
                                "slip speed reached 0; |F| = {ft:.6e} <= mu_s N = {:.6e}",
                                mu_s * f[0]
                            ),
                        );
                    } else {
                        let tangents = h.layout.contacts[c].tangents.len();
                        let to = st.sliding_from_force(c, [f[1], f[2]], tangents);
                        st.switch(
                            c,
                            to,
                            te,
                            format!(
                                "slip speed reached 0; |F| = {ft:.6e} > mu_s N = {:.6e}",
                                mu_s * f[0]
                            ),
                        );
                    }
                    st.settle(te)
                }
            }
            Trigger::User(j) => {
                let ev = &h.model.run.events[j];
                user_counts[j] += 1;
                last_fired = Some((
                    j,
                    sol.events
                        .last()
                        .is_some_and(|e| e.direction == Direction::Rising),
                ));
                events.push(EventReport {
                    name: ev.name.clone(),
                    t: te,
                    state: st.y[..2 * n].to_vec(),
                    rising: sol
                        .events
                        .last()
                        .is_some_and(|e| e.direction == Direction::Rising),
                });
                if let Some(obs) = &h.actions[j] {
                    let input = st.base_input(te, &st.y);
                    let mut vals = vec![0.0; obs.len()];
                    obs.eval(&input, &mut vals);
                    let free: Vec<usize> = h
                        .model
                        .coordinates
                        .iter()
                        .enumerate()
                        .filter(|(_, c)| {
                            matches!(c.kind, pdyn_mech::model::CoordinateKind::Free { .. })
                        })
                        .map(|(i, _)| i)
                        .collect();
                    let [k0, _, v0] = st.kinetic(te, &st.y);
                    for (a, &v) in ev.actions.iter().zip(&vals) {
                        match a.target {
                            ActionTarget::Coordinate(ci) => {
                                if let Some(s) = free.iter().position(|&f| f == ci) {
                                    st.y[s] = v;
                                }
                            }
                            ActionTarget::Rate(ci) => {
                                if let Some(s) = free.iter().position(|&f| f == ci) {
                                    st.y[n + s] = v;
                                }
                            }
                            ActionTarget::Parameter(pi) => st.params[pi] = v,
                        }
                    }
                    // A state jump changes the energy: booked apart so the balance still
                    // closes (an impulsive burn adds energy on purpose).
                    // The energy after, with the new state and parameters (a parameter of
                    // a potential changes it too).
                    let [k1, _, v1] = st.kinetic(te, &st.y);
                    st.w_actions += (k1 + v1) - (k0 + v0);
                    let texts = ev
                        .actions
                        .iter()
                        .zip(&vals)
                        .map(|(a, v)| format!("{} → {v:.9e}", a.text))
                        .collect();
                    st.report.actions.push(Action {
                        t: te,
                        event: ev.name.clone(),
                        set: texts,
                    });
                }
                if ev.terminal.is_some_and(|k| user_counts[j] >= k) {
                    status = RunStatus::TerminalEvent(j);
                }
                if status == RunStatus::Finished {
                    st.settle(te)
                } else {
                    Ok(())
                }
            }
        };
        if let Err(e) = res {
            failure = Some(stopped(prep, te, &st.y, e.to_string()));
            status = RunStatus::Failed;
            break;
        }
        if status != RunStatus::Finished || te >= t_end {
            break;
        }
    }
    // Drift of the energy balance.
    let mut monitors = Vec::new();
    let mut warnings = st.warnings.clone();
    if h.balance && !rows.is_empty() {
        let first_b = rows[0][balance_index];
        let dev = rows.iter().fold(0.0f64, |a, r| {
            let d = (r[balance_index] - first_b).abs();
            if d.is_nan() || a.is_nan() {
                f64::NAN
            } else {
                a.max(d)
            }
        });
        let scale = scale_of(scales.clone());
        let relative = scale > 0.0;
        let drift = if relative { dev / scale } else { dev };
        monitors.push(MonitorReport {
            name: "energy_balance".into(),
            initial: first_b,
            drift,
            relative,
            scale,
            conserved: true,
        });
        if drift.is_nan() || drift > set.drift_tolerance {
            warnings.push(format!(
                "energy_balance should be conserved but drifted by {drift:.3e} (relative) over t = 0..{:.6e}: the energy minus the work of the contact forces and the energy changed at impacts and event actions must stay constant, so this result cannot be trusted (the First Law of Scientific Computing). Tighten the tolerance (e.g. {})",
                rows.last().map_or(0.0, |r| r[0]),
                crate::options::RunOption::Rtol.with("1e-9")
            ));
        }
    }
    if let Some(last) = rows.last() {
        let j = columns.len() - 4;
        st.report.work_contacts = last[j];
        st.report.dissipated_friction = last[j + 1];
        st.report.dissipated_impacts = 0.0 - st.w_impacts;
        st.report.energy_actions = st.w_actions;
        if last[j + 1] < -1e-9 * scales.iter().fold(0.0f64, |a, &b| a.max(b)) {
            warnings.push(format!(
                "friction did positive work on the slip ({:.6e} over the run): friction must oppose sliding, so this result is wrong",
                -last[j + 1]
            ));
        }
    }
    warnings.extend(push.warnings(prep));
    if let Some(f) = &failure {
        warnings.push(format!("{f}"));
    }
    Ok(RunResult {
        columns,
        outputs: rows.len(),
        rows,
        events,
        monitors,
        warnings,
        stats,
        method: Solver::Ode(sol_method),
        failure,
        status,
        hybrid: Some(st.report),
    })
}

/// A hybrid run stopped at `t` in state `y` for `reason` (modes that chatter, an impulse that
/// cannot be solved), as the failure the run reports with its partial result.
fn stopped(prep: &Prepared, t: f64, y: &[f64], reason: String) -> RunFailure {
    RunFailure {
        t,
        state: prep
            .state_names
            .iter()
            .cloned()
            .zip(y.iter().copied())
            .collect(),
        error: OdeError::InvalidInput { reason },
        stiff_at: None,
        non_finite: Vec::new(),
    }
}
