//! Integrating a built N-body simulation to the output times, with pdyn's conservation
//! monitors and events.
//!
//! The run integrates from one output time to the next (`Simulation::integrate` lands on each
//! exactly). For the fixed-step integrators (WHFast, leapfrog) the output times are first
//! moved to the nearest multiple of `dt` ([`on_step_grid`]), so that no step but the last one
//! (landing on `t_end`) is shortened. At each output it
//! records the time, the total energy `E = T + V`, its parts, the virial ratio `2T/|V|` and
//! the angular momentum `L`; per-body states and orbital elements when trajectories are
//! written.
//!
//! Monitors (the First Law of Scientific Computing, as for mechanics runs):
//! - energy: `max |E(t) − E₀| / (T₀ + |V₀|)`, the change relative to the energy's physical
//!   scale (not to `E₀`, which may be near zero);
//! - angular momentum: `max |L(t) − L₀| / Σᵢ mᵢ |rᵢ × vᵢ|` (the figure-eight has `L = 0`).
//!
//! A drift above the tolerance (default [`crate::sim::DEFAULT_DRIFT_TOLERANCE`]) is a
//! warning. After a merger or a removal (which change `E` and `L` physically) the monitors
//! restart from the new values; the change is reported with the event. The signed relative
//! energy error at the end, `(E − E₀)/|E₀|`, is reported too (REBOUND's usual measure).

use super::build::{Built, Config};
use super::spec::{CollisionMode, EscapeMode, IntegratorKind};
use pdyn_gravity::{GravityError, Outcome, Particle, Primary, Simulation, Warning};

/// Above this many bodies, per-body trajectories and elements are not written unless the
/// model asks for them (`trajectory = true`).
pub const TRAJECTORY_LIMIT: usize = 100;

/// Most output times a run may ask for (checked before allocating).
pub const MAX_POINTS: usize = 10_000_000;

/// When to record the state.
#[derive(Debug, Clone, PartialEq)]
pub enum Sampling {
    /// This many equally spaced times from 0 to `t_end` (≥ 2).
    Points(usize),
    /// Every `dt` (and at `t_end`).
    Every(f64),
    /// At these times (increasing, within `0..=t_end`).
    Times(Vec<f64>),
}

/// How to run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// End time.
    pub t_end: f64,
    /// Output times.
    pub sampling: Sampling,
    /// Monitor drift that raises a warning.
    pub drift_tolerance: f64,
    /// Record per-body states and elements.
    pub trajectory: bool,
    /// The integrator's name (for advice in warnings).
    pub integrator: IntegratorKind,
    /// Collisions.
    pub collisions: CollisionMode,
    /// What an escape does.
    pub escape: EscapeMode,
    /// Set by another thread to stop at the next output time (Ctrl-C in Python).
    pub interrupt: Option<pdyn_ode::Interrupt>,
}

/// Why output times cannot be made (the front end names the option that gave them).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SamplingError {
    /// A number of points outside `2..=max`.
    Points {
        /// The number asked for.
        n: usize,
        /// [`MAX_POINTS`].
        max: usize,
    },
    /// An output interval that is not a positive number.
    Interval(f64),
    /// An interval that gives more than `max` outputs up to `t_end`.
    TooMany {
        /// The interval.
        dt: f64,
        /// The end time.
        t_end: f64,
        /// The outputs it would give.
        n: f64,
        /// [`MAX_POINTS`].
        max: usize,
    },
    /// An output time outside `0..=t_end`.
    Outside {
        /// The time.
        t: f64,
        /// The end time.
        t_end: f64,
    },
    /// Output times that do not increase.
    NotIncreasing {
        /// The time.
        t: f64,
        /// The time before it.
        previous: Option<f64>,
    },
}

impl std::fmt::Display for SamplingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SamplingError::Points { n, max } => {
                write!(f, "points must be between 2 and {max} (got {n})")
            }
            SamplingError::Interval(dt) => {
                write!(f, "the output interval must be > 0 (got {dt})")
            }
            SamplingError::TooMany { dt, t_end, n, max } => write!(
                f,
                "output every {dt} up to {t_end} is {n} outputs, more than {max}"
            ),
            SamplingError::Outside { t, t_end } => {
                write!(f, "output time {t} is outside 0..{t_end}")
            }
            SamplingError::NotIncreasing { t, previous } => {
                write!(f, "output times must increase ({t} after {previous:?})")
            }
        }
    }
}

impl std::error::Error for SamplingError {}

/// The output times of `options`, or what is wrong with them (the times of a [`Schedule`]
/// without a step grid, as a list).
pub fn output_times(t_end: f64, sampling: &Sampling) -> Result<Vec<f64>, SamplingError> {
    Ok(Schedule::new(t_end, sampling, None)?.collect())
}

/// Output times given one by one: within [0, t_end], increasing, with 0 first.
fn listed_times(t_end: f64, ts: &[f64]) -> Result<Vec<f64>, SamplingError> {
    let mut v = Vec::with_capacity(ts.len() + 1);
    if ts.first() != Some(&0.0) {
        v.push(0.0);
    }
    for &t in ts {
        if !(t.is_finite() && (0.0..=t_end).contains(&t)) {
            return Err(SamplingError::Outside { t, t_end });
        }
        if v.last().is_some_and(|&l| t <= l) && !(v.len() == 1 && t == 0.0) {
            return Err(SamplingError::NotIncreasing {
                t,
                previous: v.last().copied(),
            });
        }
        if t > 0.0 || v.is_empty() {
            v.push(t);
        }
    }
    Ok(v)
}

/// The output times of a run, one at a time, moved onto the step
/// grid as [`on_step_grid`] does for a fixed step, without a list of them in memory (a run of
/// 10⁷ outputs holds none; times given one by one are the list they came in).
#[derive(Debug, Clone)]
pub struct Schedule {
    raw: Raw,
    len: usize,
    k: usize,
    grid: Option<f64>,
    last: Option<f64>,
}

#[derive(Debug, Clone)]
enum Raw {
    Points { n: usize, t_end: f64 },
    Every { dt: f64, n: usize, t_end: f64 },
    List(Vec<f64>),
}

impl Schedule {
    /// The times of `sampling` up to `t_end`, on the grid of `grid` (a fixed step) if given;
    /// refused with the reason when they cannot be.
    pub fn new(
        t_end: f64,
        sampling: &Sampling,
        grid: Option<f64>,
    ) -> Result<Schedule, SamplingError> {
        let (raw, len) = match sampling {
            Sampling::Points(n) => {
                if *n < 2 || *n > MAX_POINTS {
                    return Err(SamplingError::Points {
                        n: *n,
                        max: MAX_POINTS,
                    });
                }
                (Raw::Points { n: *n, t_end }, *n)
            }
            Sampling::Every(dt) => {
                if !(dt.is_finite() && *dt > 0.0) {
                    return Err(SamplingError::Interval(*dt));
                }
                let n = (t_end / dt).floor();
                if n > MAX_POINTS as f64 {
                    return Err(SamplingError::TooMany {
                        dt: *dt,
                        t_end,
                        n,
                        max: MAX_POINTS,
                    });
                }
                let n = n as usize;
                // The last output is t_end itself (unless within round-off of the previous one).
                let extra = t_end - n as f64 * dt > 1e-9 * dt;
                (Raw::Every { dt: *dt, n, t_end }, n + 1 + usize::from(extra))
            }
            Sampling::Times(ts) => {
                let v = listed_times(t_end, ts)?;
                let len = v.len();
                (Raw::List(v), len)
            }
        };
        Ok(Schedule {
            raw,
            len,
            k: 0,
            grid,
            last: None,
        })
    }

    /// The number of times before moving them to the step grid.
    pub fn raw_len(&self) -> usize {
        self.len
    }

    fn raw_at(&self, k: usize) -> f64 {
        match &self.raw {
            Raw::Points { n, t_end } => t_end * k as f64 / (*n - 1) as f64,
            Raw::Every { dt, n, t_end } => {
                if k <= *n {
                    k as f64 * dt
                } else {
                    *t_end
                }
            }
            Raw::List(v) => v[k],
        }
    }
}

impl Iterator for Schedule {
    type Item = f64;

    fn next(&mut self) -> Option<f64> {
        while self.k < self.len {
            let t = self.raw_at(self.k);
            self.k += 1;
            let Some(dt) = self.grid else {
                self.last = Some(t);
                return Some(t);
            };
            if self.k == self.len {
                // t_end stays where it is
                if self.last.is_none_or(|l| t > l) {
                    self.last = Some(t);
                    return Some(t);
                }
                return None;
            }
            let t_end = self.raw_at(self.len - 1);
            let snapped = (t / dt).round() * dt;
            if snapped < t_end && self.last.is_none_or(|l| snapped > l) {
                self.last = Some(snapped);
                return Some(snapped);
            }
        }
        None
    }
}

/// The state of one body at an output time.
#[derive(Debug, Clone, Copy)]
pub struct BodyState {
    /// Index into [`NbodyResult::names`].
    pub body: usize,
    /// Mass.
    pub mass: f64,
    /// Position.
    pub pos: [f64; 3],
    /// Velocity.
    pub vel: [f64; 3],
}

/// Orbital elements of one body at an output time.
#[derive(Debug, Clone, Copy)]
pub struct ElementsRow {
    /// Time.
    pub t: f64,
    /// Index into [`NbodyResult::names`].
    pub body: usize,
    /// The elements (`None` when they do not exist, e.g. a primary of zero mass).
    pub orbit: Option<pdyn_gravity::Orbit>,
}

/// Invariants at an output time.
#[derive(Debug, Clone, Copy)]
pub struct ConservationRow {
    /// Time.
    pub t: f64,
    /// Number of bodies.
    pub n: usize,
    /// Total energy.
    pub energy: f64,
    /// Kinetic energy.
    pub kinetic: f64,
    /// Potential energy.
    pub potential: f64,
    /// Angular momentum about the origin.
    pub angular_momentum: [f64; 3],
}

/// Something that happened during the run.
#[derive(Debug, Clone)]
pub struct NbodyEvent {
    /// Time.
    pub t: f64,
    /// `collision`, `merger`, `escape`, `removal`, `close_encounter`.
    pub kind: &'static str,
    /// The bodies involved (names).
    pub bodies: Vec<String>,
    /// What happened, with advice.
    pub message: String,
}

/// One conservation monitor.
#[derive(Debug, Clone)]
pub struct Monitor {
    /// `energy` or `angular_momentum`.
    pub name: &'static str,
    /// Initial value (|L| for the angular momentum).
    pub initial: f64,
    /// Largest change relative to the scale.
    pub drift: f64,
    /// The scale the change is measured against.
    pub scale: f64,
    /// Whether the drift is within the tolerance.
    pub ok: bool,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct NbodyResult {
    /// Names of all bodies that existed during the run (a merged body keeps the first name).
    pub names: Vec<String>,
    /// Output times (with a streaming run that keeps no history, the last one only:
    /// [`NbodyResult::outputs`] counts them all).
    pub times: Vec<f64>,
    /// Outputs recorded.
    pub outputs: usize,
    /// Per output time, the bodies' states (empty unless trajectories are recorded).
    pub states: Vec<Vec<BodyState>>,
    /// Elements over time (empty unless trajectories are recorded).
    pub elements: Vec<ElementsRow>,
    /// Invariants at each output (with a streaming run that keeps no history, the first and
    /// the last).
    pub conservation: Vec<ConservationRow>,
    /// Events.
    pub events: Vec<NbodyEvent>,
    /// Conservation monitors.
    pub monitors: Vec<Monitor>,
    /// `(E_end − E₀)/|E₀|` over the last segment without mergers.
    pub energy_error: f64,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Steps taken (accepted steps for IAS15).
    pub steps: u64,
    /// The step at the end (IAS15's adapted step).
    pub final_dt: f64,
    /// Time reached.
    pub t_reached: f64,
    /// Positions of the bodies at the end (every body, also when trajectories are not kept).
    pub final_positions: Vec<[f64; 3]>,
    /// The numerical failure that stopped the run early, if any (output up to it is kept).
    pub failure: Option<GravityError>,
    /// Stopped early by [`RunOptions::interrupt`].
    pub interrupted: bool,
}

/// What the engine knows of the bodies, for a rebuild after an event.
fn bodies_of(sim: &Simulation) -> Vec<(Particle, f64)> {
    let p = sim.particles();
    (0..p.len()).map(|i| (p.get(i), sim.radii()[i])).collect()
}

#[derive(Clone, Copy, Debug)]
struct Segment {
    e0: f64,
    e_scale: f64,
    l0: [f64; 3],
    l_scale: f64,
    e_drift: f64,
    l_drift: f64,
}

impl Segment {
    fn start(sim: &Simulation) -> Segment {
        let p = sim.particles();
        let t = p.kinetic_energy();
        let e = sim.energy();
        let v = e - t;
        let l_scale: f64 = (0..p.len())
            .map(|i| p.m[i] * p.pos(i).cross(p.vel(i)).norm())
            .sum();
        Segment {
            e0: e,
            e_scale: t + v.abs(),
            l0: sim.angular_momentum().0,
            l_scale,
            e_drift: 0.0,
            l_drift: 0.0,
        }
    }
    fn update(&mut self, row: &ConservationRow) {
        let de = (row.energy - self.e0).abs() / self.e_scale;
        let l = row.angular_momentum;
        let dl = ((l[0] - self.l0[0]).powi(2)
            + (l[1] - self.l0[1]).powi(2)
            + (l[2] - self.l0[2]).powi(2))
        .sqrt();
        let dl = if self.l_scale > 0.0 {
            dl / self.l_scale
        } else {
            dl
        };
        // NaN compares false with max: keep it visible.
        self.e_drift = if de.is_nan() {
            f64::NAN
        } else {
            self.e_drift.max(de)
        };
        self.l_drift = if dl.is_nan() {
            f64::NAN
        } else {
            self.l_drift.max(dl)
        };
    }
}

/// Why a run could not go on: its output times, or a file it writes.
#[derive(Debug)]
pub enum RunError {
    /// The output times asked for.
    Sampling(SamplingError),
    /// Writing an output file.
    Write(crate::Error),
}

impl From<crate::Error> for RunError {
    fn from(e: crate::Error) -> Self {
        RunError::Write(e)
    }
}

/// Integrates `built` as `options` say, keeping the whole history in memory.
pub fn run(built: Built, options: &RunOptions) -> Result<NbodyResult, SamplingError> {
    run_with(built, options, None, &mut |_| {}, None, None).map_err(|e| match e {
        RunError::Sampling(s) => s,
        // nothing is written without a stream
        RunError::Write(_) => SamplingError::Interval(f64::NAN),
    })
}

/// Integrates `built` as `options` say, appending each output's rows to `stream` as it is
/// recorded (keeping only the first and last output in memory unless `stream.keep`), and
/// telling `steps` the steps taken so far at each output.
///
/// With `checkpoints`, a checkpoint is written at each output where one is due and when the
/// run is interrupted; with `resume` (a checkpoint's `state`), the run continues from there
/// (the stream's files already truncated to the checkpoint's lengths).
pub fn run_with(
    built: Built,
    options: &RunOptions,
    mut stream: Option<&mut super::output::Stream>,
    steps: &mut dyn FnMut(u64),
    mut checkpoints: Option<&mut crate::checkpoint::Checkpointer>,
    resume: Option<&serde_json::Value>,
) -> Result<NbodyResult, RunError> {
    let Built {
        mut sim,
        config,
        names,
        primaries,
    } = built;
    let grid = (options.integrator != IntegratorKind::Ias15).then_some(config.dt);
    let mut times = Schedule::new(options.t_end, &options.sampling, grid)
        .map_err(RunError::Sampling)?
        .enumerate()
        .peekable();
    // Current index → name index; primaries by name index (they survive mergers).
    let mut alive: Vec<usize> = (0..names.len()).collect();
    let primary_of: Vec<Option<usize>> = primaries;
    let mut res = NbodyResult {
        names: names.clone(),
        times: Vec::new(),
        outputs: 0,
        states: Vec::new(),
        elements: Vec::new(),
        conservation: Vec::new(),
        events: Vec::new(),
        monitors: Vec::new(),
        energy_error: 0.0,
        warnings: Vec::new(),
        steps: 0,
        final_dt: config.dt,
        t_reached: 0.0,
        final_positions: Vec::new(),
        failure: None,
        interrupted: false,
    };
    let mut seg = Segment::start(&sim);
    let mut e_worst = 0.0f64;
    let mut l_worst = 0.0f64;
    let mut t_offset = 0.0;
    let mut steps_before = 0u64;
    let mut engine_warnings: Vec<Warning> = Vec::new();
    let start = match resume {
        Some(state) => {
            let r = Resumed::read(state).ok_or_else(|| {
                RunError::Write(crate::Error::argument(
                    "--restart",
                    "the checkpoint's N-body state is incomplete or of another version",
                ))
            })?;
            sim.restore(&r.snapshot).map_err(|e| {
                RunError::Write(crate::Error::argument(
                    "--restart",
                    format!("the checkpoint does not fit this model: {e}"),
                ))
            })?;
            alive = r.alive;
            [t_offset, e_worst, l_worst] = r.scalars;
            seg = r.seg;
            steps_before = r.steps_before;
            res.outputs = r.outputs;
            res.conservation = r.conservation;
            res.times = vec![r.t_last];
            res.events = r.events;
            r.next
        }
        None => {
            record(
                &sim,
                0.0,
                &alive,
                &primary_of,
                options.trajectory,
                &mut res,
                &mut seg,
                stream.as_deref_mut(),
            )?;
            1
        }
    };
    let mut checkpoint = |force: bool,
                          next: usize,
                          sim: &Simulation,
                          alive: &[usize],
                          scalars: [f64; 3],
                          seg: &Segment,
                          steps_before: u64,
                          res: &NbodyResult,
                          stream: Option<&mut super::output::Stream>|
     -> Result<(), crate::Error> {
        let Some(cp) = checkpoints.as_deref_mut() else {
            return Ok(());
        };
        if !force && !cp.due(steps_before + sim.steps()) {
            return Ok(());
        }
        let files = match stream {
            Some(s) => {
                s.sync()?;
                serde_json::json!(s.lengths())
            }
            None => serde_json::Value::Null,
        };
        let t = res.times.last().copied().unwrap_or(0.0);
        let state = save_state(next, sim, alive, scalars, seg, steps_before, res);
        cp.write(t, steps_before + sim.steps(), files, state)
    };
    for _ in 0..start {
        times.next();
    }
    'outer: while let Some((k, tk)) = times.next() {
        if options
            .interrupt
            .as_ref()
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
        {
            res.interrupted = true;
            checkpoint(
                true,
                k,
                &sim,
                &alive,
                [t_offset, e_worst, l_worst],
                &seg,
                steps_before,
                &res,
                stream.as_deref_mut(),
            )?;
            break;
        }
        loop {
            match sim.integrate((tk - t_offset).max(sim.t())) {
                Ok(Outcome::Reached) => break,
                Ok(Outcome::Collision { t, i, j }) => {
                    let (a, b) = (names[alive[i]].clone(), names[alive[j]].clone());
                    let t = t + t_offset;
                    if options.collisions == CollisionMode::Stop {
                        res.events.push(NbodyEvent {
                            t,
                            kind: "collision",
                            bodies: vec![a.clone(), b.clone()],
                            message: format!("`{a}` and `{b}` touch; the run stops (collisions = \"merge\" would merge them)"),
                        });
                        record(
                            &sim,
                            t,
                            &alive,
                            &primary_of,
                            options.trajectory,
                            &mut res,
                            &mut seg,
                            stream.as_deref_mut(),
                        )?;
                        break 'outer;
                    }
                    let e_before = sim.energy();
                    let mut bodies = bodies_of(&sim);
                    let (pi, ri) = bodies[i];
                    let (pj, rj) = bodies[j];
                    let m = pi.mass + pj.mass;
                    let merged = Particle {
                        mass: m,
                        pos: (1.0 / m) * (pi.mass * pi.pos + pj.mass * pj.pos),
                        vel: (1.0 / m) * (pi.mass * pi.vel + pj.mass * pj.vel),
                    };
                    // Volume is conserved (REBOUND's merge keeps the density, too).
                    bodies[i] = (merged, libm::cbrt(ri.powi(3) + rj.powi(3)));
                    bodies.remove(j);
                    alive.remove(j);
                    steps_before += sim.steps();
                    engine_warnings.extend(sim.warnings().iter().cloned());
                    t_offset = t;
                    e_worst = e_worst.max(seg.e_drift);
                    l_worst = l_worst.max(seg.l_drift);
                    sim = match (Config {
                        dt: sim.dt(),
                        ..config
                    })
                    .simulation(&bodies)
                    {
                        Ok(s) => s,
                        Err(e) => {
                            res.failure = Some(e);
                            break 'outer;
                        }
                    };
                    let de = (sim.energy() - e_before) / e_before.abs();
                    res.events.push(NbodyEvent {
                        t,
                        kind: "merger",
                        bodies: vec![a.clone(), b.clone()],
                        message: format!("`{b}` merged into `{a}` (mass and momentum conserved; energy changed by {de:.3e} relative)"),
                    });
                    seg = Segment::start(&sim);
                }
                Ok(Outcome::Escape { t, index, distance }) => {
                    let a = names[alive[index]].clone();
                    let t = t + t_offset;
                    let advice = if options.integrator == IntegratorKind::WhFast {
                        " (WHFast's Jacobi splitting degrades for unbound bodies: consider IAS15)"
                    } else {
                        ""
                    };
                    if options.escape == EscapeMode::Stop {
                        res.events.push(NbodyEvent {
                            t,
                            kind: "escape",
                            bodies: vec![a.clone()],
                            message: format!("`{a}` is {distance:.6e} from the origin, beyond escape_radius; the run stops{advice}"),
                        });
                        record(
                            &sim,
                            t,
                            &alive,
                            &primary_of,
                            options.trajectory,
                            &mut res,
                            &mut seg,
                            stream.as_deref_mut(),
                        )?;
                        break 'outer;
                    }
                    let mut bodies = bodies_of(&sim);
                    bodies.remove(index);
                    alive.remove(index);
                    steps_before += sim.steps();
                    engine_warnings.extend(sim.warnings().iter().cloned());
                    t_offset = t;
                    e_worst = e_worst.max(seg.e_drift);
                    l_worst = l_worst.max(seg.l_drift);
                    res.events.push(NbodyEvent {
                        t,
                        kind: "removal",
                        bodies: vec![a.clone()],
                        message: format!("`{a}` escaped ({distance:.6e} from the origin) and was removed{advice}"),
                    });
                    if bodies.is_empty() {
                        break 'outer;
                    }
                    sim = match (Config {
                        dt: sim.dt(),
                        ..config
                    })
                    .simulation(&bodies)
                    {
                        Ok(s) => s,
                        Err(e) => {
                            res.failure = Some(e);
                            break 'outer;
                        }
                    };
                    seg = Segment::start(&sim);
                }
                Ok(_) => break,
                Err(e) => {
                    if let GravityError::CloseEncounter { t, body, ratio } = &e {
                        let who = alive
                            .get(*body)
                            .map_or(format!("Jacobi body {body}"), |&k| names[k].clone());
                        res.events.push(NbodyEvent {
                            t: t + t_offset,
                            kind: "close_encounter",
                            bodies: vec![who.clone()],
                            message: format!(
                                "close encounter of `{who}` (perturbation/Kepler acceleration = {ratio:.3}): WHFast cannot resolve it; \
                                 switch to IAS15 (integrator = \"ias15\" or {})",
                                crate::options::RunOption::Method.with("ias15")
                            ),
                        });
                    }
                    res.failure = Some(e);
                    break 'outer;
                }
            }
        }
        record(
            &sim,
            tk,
            &alive,
            &primary_of,
            options.trajectory,
            &mut res,
            &mut seg,
            stream.as_deref_mut(),
        )?;
        let done = steps_before + sim.steps();
        steps(done);
        if times.peek().is_some() {
            checkpoint(
                false,
                k + 1,
                &sim,
                &alive,
                [t_offset, e_worst, l_worst],
                &seg,
                steps_before,
                &res,
                stream.as_deref_mut(),
            )?;
        }
    }
    e_worst = max_nan(e_worst, seg.e_drift);
    l_worst = max_nan(l_worst, seg.l_drift);
    res.steps = steps_before + sim.steps();
    res.final_dt = sim.dt();
    res.t_reached = res.times.last().copied().unwrap_or(0.0);
    res.energy_error = res
        .conservation
        .last()
        .map_or(0.0, |r| (r.energy - seg.e0) / seg.e0.abs());
    engine_warnings.extend(sim.warnings().iter().cloned());
    // One line per kind of warning (IAS15 may raise the same one at thousands of steps): the
    // first occurrence, and how many there were.
    let mut kinds: Vec<(std::mem::Discriminant<Warning>, String, usize)> = Vec::new();
    for w in &engine_warnings {
        let d = std::mem::discriminant(w);
        if let Some(k) = kinds.iter_mut().find(|k| k.0 == d) {
            k.2 += 1;
            continue;
        }
        let advice = match w {
            Warning::LongWhFastStep { .. } => {
                " (accuracy degrades quickly above 1/20 of the period: reduce dt, or use IAS15)"
            }
            _ => "",
        };
        kinds.push((d, format!("{w}{advice}"), 1));
    }
    for (_, text, count) in kinds {
        res.warnings.push(if count > 1 {
            format!("{text} (and {} more times)", count - 1)
        } else {
            text
        });
    }
    let tol = options.drift_tolerance;
    let first = res.conservation.first().copied();
    for (name, drift, scale, initial) in [
        (
            "energy",
            e_worst,
            seg.e_scale,
            first.map_or(0.0, |r| r.energy),
        ),
        (
            "angular_momentum",
            l_worst,
            seg.l_scale,
            first.map_or(0.0, |r| {
                let l = r.angular_momentum;
                (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt()
            }),
        ),
    ] {
        let ok = drift <= tol;
        if !ok {
            res.warnings.push(format!(
                "{name} should be conserved but drifted by {drift:.3e} (relative to its scale {scale:.3e}) over t = 0..{}: \
                 this result cannot be trusted (the First Law of Scientific Computing). Reduce dt, use WHFast correctors, \
                 or switch to IAS15.",
                res.t_reached
            ));
        }
        res.monitors.push(Monitor {
            name,
            initial,
            drift,
            scale,
            ok,
        });
    }
    let p = sim.particles();
    res.final_positions = (0..p.len()).map(|i| p.pos(i).0).collect();
    if let Some(s) = stream {
        s.flush()?;
    }
    Ok(res)
}

/// Output times moved to the nearest multiple of the fixed step `dt` (the last stays at
/// `t_end`): a step shortened to land on an output would break the symplectic map's rhythm
/// (and WHFast's corrector) at every output. Times that fall together are kept once.
pub fn on_step_grid(times: &[f64], dt: f64) -> Vec<f64> {
    let Some((&t_end, inner)) = times.split_last() else {
        return Vec::new();
    };
    let mut out: Vec<f64> = Vec::with_capacity(times.len());
    for &t in inner {
        let snapped = (t / dt).round() * dt;
        if snapped < t_end && out.last().is_none_or(|&l| snapped > l) {
            out.push(snapped);
        }
    }
    if out.last().is_none_or(|&l| t_end > l) {
        out.push(t_end);
    }
    out
}

fn max_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

const EVENT_KINDS: [&str; 5] = [
    "collision",
    "merger",
    "escape",
    "removal",
    "close_encounter",
];

/// The loop's state at an output, for a checkpoint: every number as its bits.
fn save_state(
    next: usize,
    sim: &Simulation,
    alive: &[usize],
    scalars: [f64; 3],
    seg: &Segment,
    steps_before: u64,
    res: &NbodyResult,
) -> serde_json::Value {
    use crate::checkpoint::bits;
    let snap = sim.snapshot();
    let row = |r: &ConservationRow| {
        serde_json::json!({
            "n": r.n,
            "x": bits(&[r.t, r.energy, r.kinetic, r.potential, r.angular_momentum[0], r.angular_momentum[1], r.angular_momentum[2]]),
        })
    };
    serde_json::json!({
        "next": next,
        "alive": alive,
        "scalars": bits(&scalars),
        "segment": bits(&[seg.e0, seg.e_scale, seg.l0[0], seg.l0[1], seg.l0[2], seg.l_scale, seg.e_drift, seg.l_drift]),
        "steps_before": steps_before,
        "outputs": res.outputs,
        "t_last": res.times.last().copied().unwrap_or(0.0).to_bits(),
        "conservation": [res.conservation.first().map(row), res.conservation.last().map(row)],
        "events": res.events.iter().map(|e| serde_json::json!({
            "t": e.t.to_bits(), "kind": e.kind, "bodies": e.bodies, "message": e.message,
        })).collect::<Vec<_>>(),
        "engine": {
            "workspace": snap.workspace,
            "scalars": bits(&snap.scalars),
            "counters": snap.counters,
            "arrays": snap.arrays.iter().map(|a| bits(a)).collect::<Vec<_>>(),
        },
    })
}

/// What [`save_state`] wrote.
struct Resumed {
    next: usize,
    alive: Vec<usize>,
    scalars: [f64; 3],
    seg: Segment,
    steps_before: u64,
    outputs: usize,
    t_last: f64,
    conservation: Vec<ConservationRow>,
    events: Vec<NbodyEvent>,
    snapshot: pdyn_gravity::Snapshot,
}

impl Resumed {
    fn read(v: &serde_json::Value) -> Option<Resumed> {
        use crate::checkpoint::unbits;
        let usize_of = |v: &serde_json::Value| v.as_u64().map(|x| x as usize);
        let row = |v: &serde_json::Value| -> Option<ConservationRow> {
            let x = unbits(&v["x"])?;
            let [t, energy, kinetic, potential, lx, ly, lz] = x[..] else {
                return None;
            };
            Some(ConservationRow {
                t,
                n: usize_of(&v["n"])?,
                energy,
                kinetic,
                potential,
                angular_momentum: [lx, ly, lz],
            })
        };
        let sc = unbits(&v["scalars"])?;
        let sg = unbits(&v["segment"])?;
        let [e0, e_scale, l0x, l0y, l0z, l_scale, e_drift, l_drift] = sg[..] else {
            return None;
        };
        let mut conservation = Vec::new();
        for r in v["conservation"].as_array()? {
            if !r.is_null() {
                conservation.push(row(r)?);
            }
        }
        let mut events = Vec::new();
        for e in v["events"].as_array()? {
            let kind = e["kind"].as_str()?;
            events.push(NbodyEvent {
                t: f64::from_bits(e["t"].as_u64()?),
                kind: EVENT_KINDS.iter().find(|k| **k == kind)?,
                bodies: e["bodies"]
                    .as_array()?
                    .iter()
                    .map(|b| b.as_str().map(String::from))
                    .collect::<Option<_>>()?,
                message: e["message"].as_str()?.to_string(),
            });
        }
        let eng = &v["engine"];
        Some(Resumed {
            next: usize_of(&v["next"])?,
            alive: v["alive"]
                .as_array()?
                .iter()
                .map(usize_of)
                .collect::<Option<_>>()?,
            scalars: sc.try_into().ok()?,
            seg: Segment {
                e0,
                e_scale,
                l0: [l0x, l0y, l0z],
                l_scale,
                e_drift,
                l_drift,
            },
            steps_before: v["steps_before"].as_u64()?,
            outputs: usize_of(&v["outputs"])?,
            t_last: f64::from_bits(v["t_last"].as_u64()?),
            conservation,
            events,
            snapshot: pdyn_gravity::Snapshot {
                workspace: eng["workspace"].as_str()?.to_string(),
                scalars: unbits(&eng["scalars"])?,
                counters: eng["counters"]
                    .as_array()?
                    .iter()
                    .map(serde_json::Value::as_u64)
                    .collect::<Option<_>>()?,
                arrays: eng["arrays"]
                    .as_array()?
                    .iter()
                    .map(unbits)
                    .collect::<Option<_>>()?,
            },
        })
    }
}

#[allow(clippy::too_many_arguments)]
fn record(
    sim: &Simulation,
    t: f64,
    alive: &[usize],
    primary_of: &[Option<usize>],
    trajectory: bool,
    res: &mut NbodyResult,
    seg: &mut Segment,
    stream: Option<&mut super::output::Stream>,
) -> Result<(), crate::Error> {
    let keep = stream.as_ref().is_none_or(|s| s.keep);
    if !keep {
        // Bounded memory: the first conservation row (the monitors' reference), and the
        // output being recorded.
        res.times.clear();
        res.states.clear();
        res.elements.clear();
        res.conservation.truncate(1);
    }
    let p = sim.particles();
    let kinetic = p.kinetic_energy();
    let energy = sim.energy();
    let row = ConservationRow {
        t,
        n: p.len(),
        energy,
        kinetic,
        potential: energy - kinetic,
        angular_momentum: sim.angular_momentum().0,
    };
    seg.update(&row);
    res.conservation.push(row);
    res.times.push(t);
    res.outputs += 1;
    let elements_from = res.elements.len();
    if trajectory {
        res.states.push(
            (0..p.len())
                .map(|i| BodyState {
                    body: alive[i],
                    mass: p.m[i],
                    pos: p.pos(i).0,
                    vel: p.vel(i).0,
                })
                .collect(),
        );
        for i in 1..p.len() {
            // The declared primary if it still exists, otherwise the interior bodies (Jacobi).
            let primary = primary_of[alive[i]]
                .and_then(|k| alive.iter().position(|&a| a == k))
                .filter(|&j| j != i)
                .map_or(Primary::Interior, Primary::Body);
            res.elements.push(ElementsRow {
                t,
                body: alive[i],
                orbit: sim.orbit(i, primary).ok(),
            });
        }
    }
    let Some(stream) = stream else {
        return Ok(());
    };
    let names = &res.names;
    if let (Some(f), Some(states)) = (&mut stream.trajectory, res.states.last()) {
        f.rows(|w| super::output::trajectory_rows(w, t, states, names))?;
    }
    if let Some(f) = &mut stream.elements {
        f.rows(|w| super::output::elements_rows(w, &res.elements[elements_from..], names))?;
    }
    stream
        .conservation
        .rows(|w| super::output::conservation_row(w, &row))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_times_cover_the_span_and_refuse_bad_requests() {
        assert_eq!(
            output_times(1.0, &Sampling::Points(3)).unwrap(),
            [0.0, 0.5, 1.0]
        );
        assert_eq!(
            output_times(1.0, &Sampling::Every(0.4)).unwrap(),
            [0.0, 0.4, 0.8, 1.0]
        );
        assert_eq!(
            output_times(1.0, &Sampling::Every(0.5)).unwrap(),
            [0.0, 0.5, 1.0]
        );
        assert_eq!(
            output_times(2.0, &Sampling::Times(vec![0.5, 2.0])).unwrap(),
            [0.0, 0.5, 2.0]
        );
        assert!(output_times(1.0, &Sampling::Points(1)).is_err());
        assert!(output_times(1.0, &Sampling::Every(0.0)).is_err());
        assert!(output_times(1.0, &Sampling::Every(1e-300)).is_err());
        assert!(output_times(1.0, &Sampling::Times(vec![0.5, 0.2])).is_err());
        assert!(output_times(1.0, &Sampling::Times(vec![2.0])).is_err());
    }

    #[test]
    fn the_schedule_gives_the_times_of_the_lists_one_at_a_time() {
        for (t_end, sampling) in [
            (1.0, Sampling::Points(3)),
            (1.0, Sampling::Every(0.4)),
            (1.0, Sampling::Every(0.5)),
            (1000.0, Sampling::Every(0.3)),
            (1000.0, Sampling::Points(777)),
            (2.0, Sampling::Times(vec![0.5, 2.0])),
            (2.0, Sampling::Times(vec![0.0, 0.26, 0.5, 0.51, 2.0])),
        ] {
            let list = output_times(t_end, &sampling).unwrap();
            let lazy: Vec<f64> = Schedule::new(t_end, &sampling, None).unwrap().collect();
            assert_eq!(lazy, list, "{sampling:?}");
            for dt in [0.25, 0.3, 0.07] {
                let grid: Vec<f64> = Schedule::new(t_end, &sampling, Some(dt)).unwrap().collect();
                assert_eq!(grid, on_step_grid(&list, dt), "{sampling:?} dt = {dt}");
            }
        }
        assert!(Schedule::new(1.0, &Sampling::Every(1e-300), None).is_err());
        assert!(Schedule::new(1.0, &Sampling::Points(1), None).is_err());
    }

    #[test]
    fn fixed_step_outputs_fall_on_the_step_grid_and_end_at_t_end() {
        // dt = 0.3: 0.25 → 0.3, 0.5 → 0.6, 0.75 → 0.9 (rounding), 1.0 stays (t_end).
        let t = on_step_grid(&[0.0, 0.25, 0.5, 0.75, 1.0], 0.3);
        assert_eq!(t.len(), 5);
        assert_eq!(t[0], 0.0);
        assert!((t[1] - 0.3).abs() < 1e-15 && (t[2] - 0.6).abs() < 1e-15);
        assert!((t[3] - 0.9).abs() < 1e-15 && t[4] == 1.0);
        // Outputs closer than a step collapse onto one grid point.
        assert_eq!(on_step_grid(&[0.0, 0.01, 0.02, 1.0], 0.5), [0.0, 1.0]);
    }
}
