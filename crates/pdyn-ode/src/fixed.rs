//! The driver shared by the fixed-step methods (RK4, the symplectic compositions, Gauss–Legendre).
//!
//! The interval `[t0, tf]` is divided into `N = ⌈|tf − t0| / h0⌉` equal steps, so that the last
//! step lands exactly on `tf` without a shortened step (which would break the symmetry of the
//! geometric methods). Output at requested times and event location use cubic Hermite
//! interpolation between the step ends, `u(t0 + θh) = h00(θ) y0 + h h10(θ) f0 + h01(θ) y1 +
//! h h11(θ) f1`, which costs two evaluations of `f` on the steps where it is needed.

use crate::error::{invalid, point, OdeError};
use crate::events::{DenseOutput, Event, EventState, Output};
use crate::explicit::setup;
use crate::options::Options;
use crate::problem::OdeSystem;
use crate::solution::{Solution, Stats, Status};
use crate::Method;

/// Why a fixed step failed.
pub(crate) enum StepFailure {
    /// The nonlinear iteration of an implicit method did not converge.
    NoConvergence,
}

/// One fixed-step one-step method acting on a problem of type `P`.
pub(crate) trait FixedStepper<P: ?Sized> {
    /// Advances `(t, y)` by `h` into `y_new`.
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        sys: &P,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure>;
}

/// Cubic Hermite interpolant of one step.
pub(crate) struct Hermite {
    n: usize,
    t0: f64,
    h: f64,
    buf: Vec<f64>, // y0, f0, y1, f1
}

impl Hermite {
    pub(crate) fn new(n: usize) -> Self {
        Hermite {
            n,
            t0: 0.0,
            h: 1.0,
            buf: vec![0.0; 4 * n],
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(crate) fn prepare<F: OdeSystem + ?Sized>(
        &mut self,
        deriv: &F,
        t0: f64,
        y0: &[f64],
        t1: f64,
        y1: &[f64],
        stats: &mut Stats,
    ) {
        let n = self.n;
        self.t0 = t0;
        self.h = t1 - t0;
        let (a, b) = self.buf.split_at_mut(2 * n);
        a[..n].copy_from_slice(y0);
        deriv.rhs(t0, y0, &mut a[n..]);
        b[..n].copy_from_slice(y1);
        deriv.rhs(t1, y1, &mut b[n..]);
        stats.fevals += 2;
    }
}

impl DenseOutput for Hermite {
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t0) / self.h;
        crate::dense::hermite(&self.buf, self.n, s, self.h, out);
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution) {
        use crate::dense::Interpolant;
        into.push(
            t_from,
            t_to,
            Interpolant::Hermite,
            self.t0,
            self.h,
            &[&self.buf[..4 * self.n]],
        );
    }
}

/// Integrates with a fixed-step method. `deriv` is the first-order form (for interpolation and
/// validation), `problem` what the stepper needs.
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate_fixed<P: ?Sized, F: OdeSystem + ?Sized, M: FixedStepper<P>>(
    method: Method,
    problem: &P,
    deriv: &F,
    mut stepper: M,
    t0: f64,
    tf: f64,
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let su = setup(deriv, t0, tf, y0, opts)?;
    let n = su.n;
    let mut sol = Solution::new(method, n);
    if opts.dense_output {
        sol.dense = Some(crate::DenseSolution::new(n));
    }
    let Some(h0) = opts.h0 else {
        return Err(invalid(format!(
            "{method} is a fixed-step method: set h0 (the step size)"
        )));
    };
    let span = tf - t0;
    let nsteps = if span == 0.0 {
        0
    } else {
        ((span.abs() / h0.abs()) * (1.0 - 4.0 * f64::EPSILON))
            .ceil()
            .max(1.0) as usize
    };
    let mut out = Output::new(opts, su.dir);
    out.start(&mut sol, t0, y0);
    if nsteps > opts.max_steps {
        return Err(OdeError::MaxSteps {
            max_steps: opts.max_steps,
            at: point(t0, y0, &mut sol),
        });
    }
    let h = if nsteps > 0 {
        span / nsteps as f64
    } else {
        0.0
    };
    let mut y = y0.to_vec();
    let mut y_new = vec![0.0; n];
    let mut ytmp = vec![0.0; n];
    let mut herm = Hermite::new(n);
    let mut ev = EventState::new(events, n, t0, y0);
    let mut t = t0;
    for k in 1..=nsteps {
        if opts.interrupted() {
            return Err(OdeError::Interrupted {
                at: point(t, &y, &mut sol),
            });
        }
        let t_new = if k == nsteps { tf } else { t0 + k as f64 * h };
        if stepper
            .step(problem, t, &y, t_new - t, &mut y_new, &mut sol.stats)
            .is_err()
        {
            return Err(OdeError::NoConvergence {
                at: point(t, &y, &mut sol),
            });
        }
        if y_new.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite {
                at: point(t, &y, &mut sol),
            });
        }
        sol.stats.accepted += 1;
        let crossed = !events.is_empty() && ev.check(t_new, &y_new);
        if crossed || out.needs_dense(t_new) || sol.dense.is_some() {
            herm.prepare(deriv, t, &y, t_new, &y_new, &mut sol.stats);
        }
        let stop = if crossed {
            ev.locate(&herm, t, t_new, &mut sol.events)
        } else {
            None
        };
        if let Some(d) = sol.dense.as_mut() {
            herm.record(t, stop.map_or(t_new, |s| s.0), d);
        }
        ev.drain_suspects(&mut sol.possible_misses);
        out.emit(&mut sol, &herm, t_new, &y_new, stop.map(|s| s.0), &mut ytmp);
        if let Some((_, idx)) = stop {
            sol.status = Status::TerminalEvent(idx);
            return Ok(sol);
        }
        std::mem::swap(&mut y, &mut y_new);
        t = t_new;
    }
    Ok(sol)
}
