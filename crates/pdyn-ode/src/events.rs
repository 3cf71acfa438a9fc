//! Events `g(t, y) = 0` and the shared event locator; output at requested times.
//!
//! After every accepted step `[t_old, t_new]` each event function is evaluated at `t_new` and
//! compared with its value at `t_old`. A sign change (or `g(t_new) = 0` with `g(t_old) ≠ 0`)
//! in an allowed [`Direction`] is located by Brent's method (Brent 1973, *Algorithms for
//! minimization without derivatives*, ch. 4, the `zeroin` algorithm) applied to
//! `θ ↦ g(θ, u(θ))`, where `u` is the method's dense output, until the bracket is below
//! `2ε|t| + ε|t_new − t_old|`, i.e. to machine precision in `t`. Several zeros found in one step
//! are reported in time order; a terminal event (stop at the `n`-th zero of that function) ends
//! the integration at the zero, with the state given by the dense output there. A zero exactly
//! at the initial time (or at the previous located zero) is not reported again: a crossing
//! needs `g(t_old) ≠ 0`.
//!
//! Two zeros of the same `g` inside one step leave its sign unchanged, and MATLAB and SciPy
//! miss them. Here the last three values of each `g` are fitted by a parabola: when its vertex
//! lies in the step just taken and on the other side of zero, the step is sampled at
//! [`DIP_SAMPLES`] interior points of the dense output and every sign change found is located
//! as above. When the vertex lies in the step before (no dense output any more), or sampling
//! finds no sign change, the interval is recorded in [`EventState::suspects`] so that callers
//! can warn that a crossing may have been missed (limit `max_step` then).

use crate::error::{invalid, OdeError};
use crate::solution::{Direction, EventHit, PossibleMiss};

/// Dense output of the last accepted step: the state at any `t` in `[t_old, t_new]`.
pub trait DenseOutput {
    /// Writes the interpolated state at `t` into `out`.
    fn interpolate(&self, t: f64, out: &mut [f64]);
    /// Appends this step's interpolant, valid on `[t_from, t_to]`, to `into`.
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution);
}

/// An event function `g(t, y)`, its direction filter and whether it stops the integration.
#[derive(Clone, Copy)]
pub struct Event<'a> {
    /// The event function; its zeros are the events.
    pub g: &'a dyn Fn(f64, &[f64]) -> f64,
    /// Which crossings count. Default [`Direction::Both`].
    pub direction: Direction,
    /// `Some(n)`: stop the integration at the `n`-th zero (`Some(1)`: the first). Default `None`.
    pub terminal: Option<usize>,
}

impl<'a> Event<'a> {
    /// A non-terminal event detecting crossings in both directions.
    pub fn new(g: &'a dyn Fn(f64, &[f64]) -> f64) -> Self {
        Event {
            g,
            direction: Direction::Both,
            terminal: None,
        }
    }

    /// Sets the direction filter.
    pub fn direction(mut self, d: Direction) -> Self {
        self.direction = d;
        self
    }

    /// Makes the event terminal at its `n`-th occurrence (`n ≥ 1`).
    pub fn terminal(mut self, n: usize) -> Self {
        self.terminal = Some(n.max(1));
        self
    }
}

impl std::fmt::Debug for Event<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Event")
            .field("direction", &self.direction)
            .field("terminal", &self.terminal)
            .finish_non_exhaustive()
    }
}

/// Interior points at which a step is sampled when an event function seems to dip through
/// zero and back within it.
pub const DIP_SAMPLES: usize = 8;

/// Per-solve state of the event locator (allocated once).
pub(crate) struct EventState<'e, 'a> {
    events: &'e [Event<'a>],
    /// `g` at the start of the current step (`t_prev`) and of the one before (`t_prev2`).
    g_prev: Vec<f64>,
    g_prev2: Vec<f64>,
    t_prev: f64,
    t_prev2: f64,
    g_new: Vec<f64>,
    /// Per event, the vertex of its parabola through the last three values when it dips
    /// across zero inside this step.
    dipping: Vec<Option<f64>>,
    /// Sample times of a dipping step (scratch).
    samples: Vec<f64>,
    counts: Vec<usize>,
    ytmp: Vec<f64>,
    found: Vec<(f64, usize, Direction)>,
    /// `(event, t_from, t_to)`: intervals where a pair of crossings may have been missed.
    pub(crate) suspects: Vec<(usize, f64, f64)>,
}

impl<'e, 'a> EventState<'e, 'a> {
    pub(crate) fn new(events: &'e [Event<'a>], n: usize, t0: f64, y0: &[f64]) -> Self {
        let g_prev: Vec<f64> = events.iter().map(|e| (e.g)(t0, y0)).collect();
        EventState {
            events,
            g_new: g_prev.clone(),
            g_prev2: vec![f64::NAN; events.len()],
            g_prev,
            t_prev: t0,
            t_prev2: f64::NAN,
            dipping: vec![None; events.len()],
            samples: Vec::with_capacity(DIP_SAMPLES + 2),
            counts: vec![0; events.len()],
            ytmp: vec![0.0; n],
            found: Vec::with_capacity(events.len()),
            suspects: Vec::new(),
        }
    }

    /// The memory carried from one step to the next (for a saved state).
    pub(crate) fn memory(&self) -> crate::resume::EventMemory {
        crate::resume::EventMemory {
            g_prev: self.g_prev.clone(),
            g_prev2: self.g_prev2.clone(),
            t_prev: self.t_prev,
            t_prev2: self.t_prev2,
            counts: self.counts.clone(),
        }
    }

    /// Continues from a saved memory (its lengths checked by the caller).
    pub(crate) fn restore(&mut self, m: &crate::resume::EventMemory) {
        self.g_prev.copy_from_slice(&m.g_prev);
        self.g_prev2.copy_from_slice(&m.g_prev2);
        self.g_new.copy_from_slice(&m.g_prev);
        self.t_prev = m.t_prev;
        self.t_prev2 = m.t_prev2;
        self.counts.copy_from_slice(&m.counts);
    }

    /// The suspicious intervals recorded since the last call, as [`PossibleMiss`]es.
    pub(crate) fn drain_suspects(&mut self, into: &mut Vec<PossibleMiss>) {
        into.extend(self.suspects.drain(..).map(|(index, a, b)| PossibleMiss {
            index,
            t_from: a.min(b),
            t_to: a.max(b),
        }));
    }

    /// Moves the history one step on: the step ending at `t_new` has been dealt with.
    fn advance(&mut self, t_new: f64) {
        std::mem::swap(&mut self.g_prev2, &mut self.g_prev);
        self.g_prev.copy_from_slice(&self.g_new);
        self.t_prev2 = self.t_prev;
        self.t_prev = t_new;
        self.dipping.iter_mut().for_each(|d| *d = None);
    }

    /// Evaluates the event functions at the end of the step; `true` when some crossing must be
    /// located (the caller then prepares dense output and calls [`EventState::locate`]).
    pub(crate) fn check(&mut self, t_new: f64, y_new: &[f64]) -> bool {
        let mut any = false;
        for (i, e) in self.events.iter().enumerate() {
            let gn = (e.g)(t_new, y_new);
            self.g_new[i] = gn;
            if crossing(self.g_prev[i], gn, e.direction).is_some() {
                any = true;
                continue;
            }
            let points = [
                (self.t_prev2, self.g_prev2[i]),
                (self.t_prev, self.g_prev[i]),
                (t_new, gn),
            ];
            match dip(points) {
                Some(t) if within(t, self.t_prev, t_new) => {
                    self.dipping[i] = Some(t);
                    any = true;
                }
                Some(t) if within(t, self.t_prev2, self.t_prev) => {
                    // The step before is gone: only say so.
                    self.suspects.push((i, self.t_prev2, self.t_prev));
                }
                _ => {}
            }
        }
        if !any {
            self.advance(t_new);
        }
        any
    }

    /// Locates the crossings of the step `[t_old, t_new]`, appends them to `hits` in time order
    /// and returns `Some((t, index))` when a terminal event stops the integration at `t`.
    pub(crate) fn locate<I: DenseOutput + ?Sized>(
        &mut self,
        interp: &I,
        t_old: f64,
        t_new: f64,
        hits: &mut Vec<EventHit>,
    ) -> Option<(f64, usize)> {
        self.found.clear();
        let tol_step = f64::EPSILON * (t_new - t_old).abs();
        for (i, e) in self.events.iter().enumerate() {
            let (gp, gn) = (self.g_prev[i], self.g_new[i]);
            let ytmp = &mut self.ytmp;
            let mut g = |t: f64| {
                interp.interpolate(t, ytmp);
                (e.g)(t, ytmp)
            };
            if let Some(dir) = crossing(gp, gn, e.direction) {
                let t = brent(&mut g, t_old, t_new, gp, gn, tol_step);
                self.found.push((t, i, dir));
            } else if let Some(vertex) = self.dipping[i] {
                // Sample the step evenly and at the parabola's vertex (where the dip most
                // likely is); locate every sign change between neighbouring samples.
                let samples = &mut self.samples;
                samples.clear();
                samples.extend(
                    (1..=DIP_SAMPLES)
                        .map(|k| t_old + (t_new - t_old) * k as f64 / (DIP_SAMPLES + 1) as f64),
                );
                samples.push(vertex);
                if t_new >= t_old {
                    samples.sort_by(f64::total_cmp);
                } else {
                    samples.sort_by(|a, b| b.total_cmp(a));
                }
                samples.push(t_new);
                let mut found_any = false;
                let (mut ta, mut ga) = (t_old, gp);
                for (k, &tb) in samples.iter().enumerate() {
                    let gb = if k + 1 == samples.len() { gn } else { g(tb) };
                    if let Some(dir) = crossing(ga, gb, Direction::Both) {
                        found_any = true;
                        if crossing(ga, gb, e.direction).is_some() {
                            let t = brent(&mut g, ta, tb, ga, gb, tol_step);
                            self.found.push((t, i, dir));
                        }
                    }
                    (ta, ga) = (tb, gb);
                }
                if !found_any {
                    self.suspects.push((i, t_old, t_new));
                }
            }
        }
        let fwd = t_new >= t_old;
        self.found.sort_by(|a, b| {
            let o = a.0.total_cmp(&b.0);
            if fwd {
                o
            } else {
                o.reverse()
            }
        });
        self.advance(t_new);
        for &(t, i, dir) in &self.found {
            interp.interpolate(t, &mut self.ytmp);
            hits.push(EventHit {
                index: i,
                t,
                y: self.ytmp.clone(),
                direction: dir,
            });
            self.counts[i] += 1;
            if let Some(n) = self.events[i].terminal {
                if self.counts[i] >= n {
                    return Some((t, i));
                }
            }
        }
        None
    }
}

/// Whether `t` lies strictly inside the interval between `a` and `b` (either order).
fn within(t: f64, a: f64, b: f64) -> bool {
    (a < t && t < b) || (b < t && t < a)
}

/// The vertex `t*` of the parabola through three `(t, g)` points when the parabola crosses
/// zero there and back — its value at `t*` has the other sign than the last point's while the
/// last two points have the same sign — that is, where two zeros may hide between samples.
fn dip(p: [(f64, f64); 3]) -> Option<f64> {
    let [(t0, g0), (t1, g1), (t2, g2)] = p;
    if !(g0.is_finite() && g1.is_finite() && g2.is_finite() && t0.is_finite()) {
        return None;
    }
    if g1 == 0.0 || g2 == 0.0 || (g1 > 0.0) != (g2 > 0.0) {
        return None;
    }
    let f01 = (g1 - g0) / (t1 - t0);
    let f12 = (g2 - g1) / (t2 - t1);
    let a = (f12 - f01) / (t2 - t0);
    if !a.is_finite() || a == 0.0 {
        return None;
    }
    let tv = 0.5 * (t0 + t1) - f01 / (2.0 * a);
    let gv = g0 + f01 * (tv - t0) + a * (tv - t0) * (tv - t1);
    ((gv > 0.0) != (g2 > 0.0) && gv != 0.0).then_some(tv)
}

/// Direction of a crossing from `gp` (at the start of the step) to `gn`, if it counts.
fn crossing(gp: f64, gn: f64, want: Direction) -> Option<Direction> {
    if gp == 0.0 || gp.is_nan() || gn.is_nan() {
        return None;
    }
    let dir = if gp < 0.0 && gn >= 0.0 {
        Direction::Rising
    } else if gp > 0.0 && gn <= 0.0 {
        Direction::Falling
    } else {
        return None;
    };
    match want {
        Direction::Both => Some(dir),
        w if w == dir => Some(dir),
        _ => None,
    }
}

/// Brent's `zeroin` on the bracket `[a, b]` (`fa`, `fb` of opposite signs, or `fb = 0`).
/// Converges to `2ε|b| + tol_abs`.
pub(crate) fn brent(
    f: &mut impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fb: f64,
    tol_abs: f64,
) -> f64 {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    if fb == 0.0 {
        return b;
    }
    if fa == 0.0 {
        return a;
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * tol_abs;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return b;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
    }
    b
}

/// Output points [`Output::start`] reserves room for, at most.
const RESERVED_POINTS: usize = 1 << 16;

/// Output at requested times (`t_eval`) or after every step.
pub(crate) struct Output<'a> {
    t_eval: Option<&'a [f64]>,
    next: usize,
    dir: f64,
    /// With `t_eval`: whether a terminal event's point is output too.
    event_point: bool,
}

impl<'a> Output<'a> {
    /// Outputs at `opts.t_eval` (or after every step) in the direction `dir`.
    pub(crate) fn new(opts: &'a crate::Options, dir: f64) -> Self {
        Output {
            t_eval: opts.t_eval.as_deref(),
            next: 0,
            dir,
            event_point: opts.output_terminal_event,
        }
    }

    /// Continues a saved solve: the next output time is `t_eval[next]`.
    pub(crate) fn resume_at(&mut self, next: usize) {
        self.next = next;
    }

    /// Index into `t_eval` of the next output time.
    pub(crate) fn next_index(&self) -> usize {
        self.next
    }

    /// Records the initial point.
    pub(crate) fn start(&mut self, sol: &mut crate::Solution, t0: f64, y0: &[f64]) {
        match self.t_eval {
            None => sol.push(t0, y0),
            Some(ts) => {
                // At most one point per requested time (plus a terminal event's); reserved
                // up front, up to a bound (a run stopped early by an event or a failure
                // should not hold room for millions of points it never reached).
                let points = ts.len().min(RESERVED_POINTS) + 1;
                sol.t.reserve(points);
                sol.y.reserve(points * y0.len());
                while self.next < ts.len() && ts[self.next] == t0 {
                    sol.push(t0, y0);
                    self.next += 1;
                }
            }
        }
    }

    /// Whether an output time lies strictly inside a step ending at `t_new`.
    pub(crate) fn needs_dense(&self, t_new: f64) -> bool {
        match self.t_eval {
            None => false,
            Some(ts) => self.next < ts.len() && (ts[self.next] - t_new) * self.dir < 0.0,
        }
    }

    /// Emits the outputs of a step ending at `t_new` (or at a terminal event `stop`).
    pub(crate) fn emit<I: DenseOutput + ?Sized>(
        &mut self,
        sol: &mut crate::Solution,
        interp: &I,
        t_new: f64,
        y_new: &[f64],
        stop: Option<f64>,
        ytmp: &mut [f64],
    ) {
        let limit = stop.unwrap_or(t_new);
        if let Some(ts) = self.t_eval {
            while self.next < ts.len() && (ts[self.next] - limit) * self.dir <= 0.0 {
                let te = ts[self.next];
                if te == t_new {
                    sol.push(te, y_new);
                } else {
                    interp.interpolate(te, ytmp);
                    sol.push(te, ytmp);
                }
                self.next += 1;
            }
        }
        match stop {
            Some(ts) => {
                if (self.t_eval.is_none() || self.event_point) && sol.t.last() != Some(&ts) {
                    interp.interpolate(ts, ytmp);
                    sol.push(ts, ytmp);
                }
            }
            None => {
                if self.t_eval.is_none() {
                    sol.push(t_new, y_new);
                }
            }
        }
    }
}

/// Checks `t_eval`: inside `[t0, tf]` and monotone in the direction of integration.
pub(crate) fn check_t_eval(t_eval: &[f64], t0: f64, tf: f64) -> Result<(), OdeError> {
    let dir = if tf >= t0 { 1.0 } else { -1.0 };
    for w in t_eval.windows(2) {
        if (w[1] - w[0]) * dir < 0.0 {
            return Err(invalid(
                "t_eval must be monotone in the direction of integration",
            ));
        }
    }
    for &t in t_eval {
        if !t.is_finite() || (t - t0) * dir < 0.0 || (t - tf) * dir > 0.0 {
            return Err(invalid(format!("t_eval point {t} outside [t0, tf]")));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_cubic_root_to_machine_precision() {
        let mut f = |x: f64| x * x * x - 2.0;
        let r = brent(&mut f, 0.0, 2.0, -2.0, 6.0, 0.0);
        assert!((r - libm::cbrt(2f64)).abs() <= 4.0 * f64::EPSILON);
    }

    #[test]
    fn crossing_respects_direction_and_zero_start() {
        assert_eq!(
            crossing(-1.0, 1.0, Direction::Both),
            Some(Direction::Rising)
        );
        assert_eq!(crossing(-1.0, 1.0, Direction::Falling), None);
        assert_eq!(
            crossing(1.0, -1.0, Direction::Falling),
            Some(Direction::Falling)
        );
        assert_eq!(crossing(0.0, -1.0, Direction::Both), None);
        assert_eq!(
            crossing(1.0, 0.0, Direction::Both),
            Some(Direction::Falling)
        );
    }
}
