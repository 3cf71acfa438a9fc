//! The adaptive driver shared by the explicit Runge–Kutta pairs (DOPRI5, Tsit5, DOP853).
//!
//! The loop is Hairer's (dopri5.f `DOPCOR`): before each attempt the step is clipped so that
//! the integration lands exactly on `tf` (`h = tf − t` when `t + 1.01h` would pass it); the
//! method computes its stages, the new state and the error `err`; the shared
//! [`PiState`](crate::controller) accepts or rejects and proposes the next step; after an
//! accepted step the event locator and the output at requested times use the method's dense
//! output, prepared only when needed.

use crate::controller::{initial_step, Controller, PiState};
use crate::error::{invalid, point, OdeError};
use crate::events::{check_t_eval, DenseOutput, Event, EventState, Output};
use crate::options::{Options, StiffnessAction};
use crate::problem::OdeSystem;
use crate::resume::{Accepted, Observer, ResumeState, StateView};
use crate::solution::{Solution, Stats, Status};
use crate::Method;

/// One explicit embedded Runge–Kutta pair: stages, error estimate, dense output. It owns its
/// workspace (allocated once in [`ExplicitRk::new`]).
pub(crate) trait ExplicitRk: DenseOutput {
    /// The public method tag.
    const METHOD: Method;
    /// Order of the propagated solution (used by the initial-step estimate).
    const ORDER: i32;
    /// Stiffness threshold on `h|λ|` (dopri5.f: 3.25, dop853.f: 6.1).
    const STIFF_THRESHOLD: f64;
    /// Default controller.
    fn default_controller() -> Controller;
    /// I-exponent of the controller for parameters `c`.
    fn alpha(c: &Controller) -> f64;
    /// Allocates the workspace for dimension `n`.
    fn new(n: usize) -> Self;
    /// Buffer holding `f(t, y)` at the start of the next step.
    fn f_start(&mut self) -> &mut [f64];
    /// Computes one step of size `h` from `(t, y)`, writes the new state to `y_new` and
    /// returns the scaled error norm.
    #[allow(clippy::too_many_arguments)]
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        atol: &[f64],
        rtol: &[f64],
        stats: &mut Stats,
    ) -> f64;
    /// Work to do once the step is accepted (e.g. DOP853's `f(t+h, y_new)`).
    fn on_accept<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t_new: f64,
        y_new: &[f64],
        stats: &mut Stats,
    );
    /// Hairer's stiffness indicator `h|λ|` for the accepted step.
    fn stiffness(&self, h: f64, y_new: &[f64]) -> f64;
    /// Prepares the dense output of the accepted step `[t, t + h]`.
    #[allow(clippy::too_many_arguments)]
    fn prepare_dense<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &[f64],
        stats: &mut Stats,
    );
    /// Makes the last stage the first of the next step.
    fn advance(&mut self);
}

/// Validated common inputs.
pub(crate) struct Setup {
    pub n: usize,
    pub dir: f64,
    pub atol: Vec<f64>,
    pub rtol: Vec<f64>,
    pub hmax: f64,
    /// [`Options::min_step`] (0 when unset).
    pub hmin: f64,
}

pub(crate) fn setup<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    y0: &[f64],
    opts: &Options,
) -> Result<Setup, OdeError> {
    let n = sys.dim();
    if n == 0 {
        return Err(invalid("the system has no components"));
    }
    if y0.len() != n {
        return Err(invalid(format!(
            "y0 has {} components, the system {n}",
            y0.len()
        )));
    }
    if !t0.is_finite() || !tf.is_finite() {
        return Err(invalid("t0 and tf must be finite"));
    }
    if y0.iter().any(|v| !v.is_finite()) {
        return Err(invalid("y0 must be finite"));
    }
    let atol = opts.atol.check(n, "atol")?;
    let rtol = opts.rtol.check(n, "rtol")?;
    if atol.iter().zip(&rtol).any(|(a, r)| *a == 0.0 && *r == 0.0) {
        return Err(invalid("atol and rtol cannot both be zero for a component"));
    }
    if let Some(te) = &opts.t_eval {
        check_t_eval(te, t0, tf)?;
    }
    if let Some(h) = opts.h0 {
        if !h.is_finite() || h == 0.0 {
            return Err(invalid("h0 must be finite and nonzero"));
        }
    }
    let hmax = match opts.max_step {
        Some(m) if m.is_nan() || m <= 0.0 => return Err(invalid("max_step must be positive")),
        Some(m) => m.abs(),
        None => (tf - t0).abs(),
    };
    let hmin = match opts.min_step {
        Some(m) if !(m >= 0.0 && m.is_finite()) => {
            return Err(invalid("min_step must be finite and non-negative"))
        }
        Some(m) if m > hmax => return Err(invalid("min_step exceeds max_step")),
        Some(m) => m,
        None => 0.0,
    };
    Ok(Setup {
        n,
        dir: if tf >= t0 { 1.0 } else { -1.0 },
        atol,
        rtol,
        hmax,
        hmin,
    })
}

/// Integrates with the explicit pair `M` from `t0` to `tf`.
pub(crate) fn integrate<M: ExplicitRk, S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
    stiff_action: StiffnessAction,
) -> Result<Solution, OdeError> {
    let hooks = Hooks {
        resume: None,
        observer: None,
    };
    integrate_with::<M, S>(sys, t0, tf, y0, opts, events, stiff_action, hooks)
}

/// What [`crate::resume::solve_observed`] adds to a solve: a saved state to start from, an
/// observer of the accepted steps.
pub(crate) struct Hooks<'r, 'o, 'p> {
    pub resume: Option<&'r ResumeState>,
    pub observer: Option<&'o mut Observer<'p>>,
}

/// [`integrate`] with [`Hooks`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn integrate_with<M: ExplicitRk, S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    y0: &[f64],
    opts: &Options,
    events: &[Event<'_>],
    stiff_action: StiffnessAction,
    hooks: Hooks<'_, '_, '_>,
) -> Result<Solution, OdeError> {
    let Hooks {
        resume,
        mut observer,
    } = hooks;
    let Setup {
        n,
        dir,
        atol,
        rtol,
        hmax,
        hmin,
    } = setup(sys, t0, tf, y0, opts)?;
    let mut sol = Solution::new(M::METHOD, n);
    if opts.dense_output {
        sol.dense = Some(crate::DenseSolution::new(n));
    }
    let mut y_new = vec![0.0; n];
    let mut ytmp = vec![0.0; n];
    let mut ytmp2 = vec![0.0; n];
    let mut rk = M::new(n);
    let ctrl = opts.controller.unwrap_or_else(M::default_controller);
    let mut pi = PiState::new(&ctrl, M::alpha(&ctrl));
    let nstiff = opts.stiffness_check_interval.max(1);

    let mut out = Output::new(opts, dir);
    let mut ev;
    let mut t;
    let mut y;
    let mut h;
    let mut nstep;
    let (mut iasti, mut nonsti, mut stiff_countdown);
    let mut nonfinite_in_row;
    match resume {
        None => {
            y = y0.to_vec();
            out.start(&mut sol, t0, y0);
            if t0 == tf {
                return Ok(sol);
            }
            sys.rhs(t0, &y, rk.f_start());
            sol.stats.fevals += 1;
            h = match opts.h0 {
                Some(h0) => h0.abs().min(hmax) * dir,
                None => {
                    let f0 = rk.f_start().to_vec();
                    sol.stats.fevals += 1;
                    initial_step(
                        sys,
                        t0,
                        &y,
                        &f0,
                        dir,
                        M::ORDER,
                        hmax,
                        &atol,
                        &rtol,
                        &mut ytmp,
                        &mut ytmp2,
                    )
                }
            };
            if h.abs() < hmin {
                h = hmin * dir;
            }
            ev = EventState::new(events, n, t0, y0);
            t = t0;
            nstep = 0usize;
            (iasti, nonsti, stiff_countdown) = (0usize, 0usize, nstiff);
            nonfinite_in_row = 0usize;
        }
        Some(r) => {
            // Everything the loop below reads, as it was after the saved step.
            y = r.y.clone();
            rk.f_start().copy_from_slice(&r.first_stage);
            sol.stats = r.stats.clone();
            pi.restore(r.facold);
            out.resume_at(r.next_output);
            ev = EventState::new(events, n, t0, y0);
            ev.restore(&r.events);
            t = r.t;
            h = r.h;
            nstep = r.attempts;
            [iasti, nonsti, stiff_countdown] = r.stiffness;
            nonfinite_in_row = r.non_finite_in_row;
        }
    }
    let mut reject = false;
    let mut last = false;
    loop {
        if opts.interrupted() {
            return Err(OdeError::Interrupted {
                at: point(t, &y, &mut sol),
            });
        }
        if nstep >= opts.max_steps {
            return Err(OdeError::MaxSteps {
                max_steps: opts.max_steps,
                at: point(t, &y, &mut sol),
            });
        }
        if 0.1 * h.abs() <= t.abs() * f64::EPSILON || h == 0.0 {
            return Err(OdeError::StepSizeUnderflow {
                h,
                at: point(t, &y, &mut sol),
            });
        }
        if (t + 1.01 * h - tf) * dir > 0.0 {
            h = tf - t;
            last = true;
        }
        nstep += 1;
        sol.stats.steps += 1;
        let err = rk.attempt(sys, t, &y, h, &mut y_new, &atol, &rtol, &mut sol.stats);
        if !err.is_finite() {
            nonfinite_in_row += 1;
            if nonfinite_in_row > 20 {
                return Err(OdeError::NonFinite {
                    at: point(t, &y, &mut sol),
                });
            }
        } else {
            nonfinite_in_row = 0;
        }
        let (accepted, mut hnew) = pi.propose(err, h);
        if accepted {
            sol.stats.accepted += 1;
            let t_new = if last { tf } else { t + h };
            rk.on_accept(sys, t_new, &y_new, &mut sol.stats);
            // Hairer's stiffness detection (every `nstiff` accepted steps, or while suspected).
            stiff_countdown -= 1;
            let check = stiff_countdown == 0;
            if check {
                stiff_countdown = nstiff;
            }
            if check || iasti > 0 {
                let hlamb = rk.stiffness(h, &y_new);
                if hlamb > M::STIFF_THRESHOLD {
                    nonsti = 0;
                    iasti += 1;
                    if iasti == 15 {
                        sol.stats.stiffness_detected_at.get_or_insert(t);
                        if stiff_action == StiffnessAction::Error {
                            return Err(OdeError::Stiff {
                                at: point(t, &y, &mut sol),
                            });
                        }
                    }
                } else {
                    nonsti += 1;
                    if nonsti == 6 {
                        iasti = 0;
                    }
                }
            }
            let crossed = !events.is_empty() && ev.check(t_new, &y_new);
            if crossed || out.needs_dense(t_new) || sol.dense.is_some() {
                rk.prepare_dense(sys, t, &y, h, &y_new, &mut sol.stats);
            }
            let stop = if crossed {
                ev.locate(&rk, t, t_new, &mut sol.events)
            } else {
                None
            };
            if let Some(d) = sol.dense.as_mut() {
                rk.record(t, stop.map_or(t_new, |s| s.0), d);
            }
            ev.drain_suspects(&mut sol.possible_misses);
            out.emit(&mut sol, &rk, t_new, &y_new, stop.map(|s| s.0), &mut ytmp);
            if let Some((_, idx)) = stop {
                sol.status = Status::TerminalEvent(idx);
                return Ok(sol);
            }
            std::mem::swap(&mut y, &mut y_new);
            t = t_new;
            rk.advance();
            if last {
                return Ok(sol);
            }
            if hnew.abs() > hmax {
                hnew = dir * hmax;
            }
            if reject {
                hnew = dir * hnew.abs().min(h.abs());
            }
            reject = false;
        } else {
            if hmin > 0.0 && h.abs() <= hmin {
                return Err(OdeError::MinStep {
                    min_step: hmin,
                    at: point(t, &y, &mut sol),
                });
            }
            reject = true;
            last = false;
            if sol.stats.accepted >= 1 {
                sol.stats.rejected += 1;
            }
        }
        h = if hnew.abs() < hmin { hmin * dir } else { hnew };
        if let (true, Some(watch)) = (accepted, observer.as_mut()) {
            // Between two steps: the state the loop continues from is complete here.
            let mut step = Accepted {
                t,
                view: StateView {
                    method: M::METHOD,
                    y: &y,
                    first_stage: rk.f_start(),
                    h,
                    facold: pi.memory(),
                    attempts: nstep,
                    stiffness: [iasti, nonsti, stiff_countdown],
                    non_finite_in_row: nonfinite_in_row,
                    events: &ev,
                    next_output: out.next_index(),
                },
                solution: &mut sol,
            };
            if watch(&mut step).is_break() {
                return Err(OdeError::Interrupted {
                    at: point(t, &y, &mut sol),
                });
            }
        }
    }
}

/// Hairer's stiffness estimate `ρ = |h| ‖k_s − k_{s−1}‖ / ‖y_{n+1} − y_stage‖` (dopri5.f,
/// dop853.f): the last two stages were evaluated at nearly the same point, so the quotient
/// approximates the dominant eigenvalue of the Jacobian times `h`. 0 when the states coincide.
pub(crate) fn stiffness_ratio(
    h: f64,
    k_last: &[f64],
    k_prev: &[f64],
    y_new: &[f64],
    y_stage: &[f64],
) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..y_new.len() {
        let dk = k_last[i] - k_prev[i];
        let dy = y_new[i] - y_stage[i];
        num += dk * dk;
        den += dy * dy;
    }
    if den > 0.0 {
        h.abs() * (num / den).sqrt()
    } else {
        0.0
    }
}

/// Dimensions from which a step's vector loops run as AVX code where the processor has it
/// (four lanes per instruction instead of SSE2's two, three-operand instructions without
/// SSE2's register copies): every dimension beyond the compile-time sizes of
/// [`dispatch_dim`], from a 16-link chain (the stage loops ~7 % of its run) to a net's
/// thousands of components. The same operations in the same order (no fused multiply-add,
/// sums still one component at a time), so the same bits on every processor.
#[cfg(target_arch = "x86_64")]
pub(crate) const AVX_FROM: usize = 9;

/// Calls `$self.attempt_n::<S, N>(args)` with `N` the system dimension when it is one of the
/// listed sizes (loops of compile-time length: unrolled and vectorised), `N = 0` (run-time
/// length) otherwise, compiled for AVX ([`avx_attempt`]) from [`AVX_FROM`] components where
/// the processor has it. The arithmetic is the same in every variant.
macro_rules! dispatch_dim {
    ($self:ident, $S:ty, [$($n:literal),*], $args:tt) => {{
        #[cfg(target_arch = "x86_64")]
        if $self.n >= crate::explicit::AVX_FROM && std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the processor has AVX (checked just above).
            return unsafe { $self.attempt_avx::<$S> $args };
        }
        match $self.n {
            $($n => $self.attempt_n::<$S, $n> $args,)*
            _ => $self.attempt_n::<$S, 0> $args,
        }
    }};
}
pub(crate) use dispatch_dim;

/// Defines `attempt_avx`, a method's `attempt_n::<S, 0>` compiled for AVX, for
/// [`dispatch_dim`].
macro_rules! avx_attempt {
    () => {
        /// `attempt_n` of any dimension, compiled for AVX.
        ///
        /// # Safety
        /// The processor must have AVX.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx")]
        #[allow(clippy::too_many_arguments)]
        unsafe fn attempt_avx<S: OdeSystem + ?Sized>(
            &mut self,
            sys: &S,
            t: f64,
            y: &[f64],
            h: f64,
            y_new: &mut [f64],
            atol: &[f64],
            rtol: &[f64],
            stats: &mut Stats,
        ) -> f64 {
            self.attempt_n::<S, 0>(sys, t, y, h, y_new, atol, rtol, stats)
        }
    };
}
pub(crate) use avx_attempt;

/// `out_j = y_j + h Σ_m a_m k_{m,j}` over the nonzero `a_m` (stage-major `k`).
///
/// The sum is accumulated stage by stage over whole vectors (vectorisable inner loops) but per
/// component in the same order as the Fortran codes, `((a_1 k_1 + a_2 k_2) + …)`, then
/// `y + h·sum`, so results are bit-identical to Hairer's. Always inlined: called with a
/// dimension `n` known at compile time (DOP853's dense output for small systems), its loops
/// unroll.
#[inline(always)]
pub(crate) fn stage_input(y: &[f64], k: &[f64], n: usize, a_row: &[f64], h: f64, out: &mut [f64]) {
    let out = &mut out[..n];
    let y = &y[..n];
    if a_row.len() == 1 {
        // `y + (h a21) k1`, in the order of the Fortran codes.
        let ha = h * a_row[0];
        for ((o, &yj), &kj) in out.iter_mut().zip(y).zip(&k[..n]) {
            *o = yj + ha * kj;
        }
        return;
    }
    if n < SMALL {
        // Few components: one pass per component (less loop overhead).
        for j in 0..n {
            let mut acc = 0.0;
            for (m, &a) in a_row.iter().enumerate() {
                if a != 0.0 {
                    acc += a * k[m * n + j];
                }
            }
            out[j] = y[j] + h * acc;
        }
        return;
    }
    let mut first = true;
    for (m, &a) in a_row.iter().enumerate() {
        if a == 0.0 {
            continue;
        }
        let km = &k[m * n..(m + 1) * n];
        if first {
            for (o, &kj) in out.iter_mut().zip(km) {
                *o = a * kj;
            }
            first = false;
        } else {
            for (o, &kj) in out.iter_mut().zip(km) {
                *o += a * kj;
            }
        }
    }
    if first {
        out.copy_from_slice(y);
        return;
    }
    for (o, &yj) in out.iter_mut().zip(y) {
        *o = yj + h * *o;
    }
}

/// Below this dimension the stage sums run component by component.
pub(crate) const SMALL: usize = 16;

/// `out_j = Σ_m w_m k_{m,j}` over the nonzero `w_m`, accumulated in stage order.
#[inline(always)]
pub(crate) fn combine(k: &[f64], n: usize, w: &[f64], out: &mut [f64]) {
    let out = &mut out[..n];
    let mut first = true;
    for (m, &a) in w.iter().enumerate() {
        if a == 0.0 {
            continue;
        }
        let km = &k[m * n..(m + 1) * n];
        if first {
            for (o, &kj) in out.iter_mut().zip(km) {
                *o = a * kj;
            }
            first = false;
        } else {
            for (o, &kj) in out.iter_mut().zip(km) {
                *o += a * kj;
            }
        }
    }
    if first {
        out.fill(0.0);
    }
}

/// The AVX step against the baseline build, for each method's tests.
#[cfg(test)]
pub(crate) mod avx_check {
    use super::ExplicitRk;
    use crate::problem::OdeSystem;
    use crate::Stats;

    /// 60 masses in a row between springs, a pendulum's restoring force each, forced: 120
    /// components (beyond `AVX_FROM`).
    pub(crate) struct Chain;

    impl OdeSystem for Chain {
        fn dim(&self) -> usize {
            120
        }
        fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
            let m = y.len() / 2;
            for i in 0..m {
                let left = if i > 0 { y[i - 1] } else { 0.0 };
                let right = if i + 1 < m { y[i + 1] } else { 0.0 };
                d[i] = y[m + i];
                d[m + i] = 300.0 * (left - 2.0 * y[i] + right) - libm::sin(y[i])
                    + 0.1 * libm::cos(3.0 * t);
            }
        }
    }

    /// A step's result `(error, y_new)` by `attempt` (the AVX code where the processor has it)
    /// and by `baseline` (`attempt_n::<_, 0>` compiled for the baseline processor): the same
    /// bits. Returns the first method, stepped, for further checks.
    #[allow(clippy::type_complexity)]
    pub(crate) fn same_bits<M: ExplicitRk>(
        baseline: impl Fn(&mut M, f64, &[f64], f64, &mut [f64], &[f64], &[f64], &mut Stats) -> f64,
    ) -> (M, M, Vec<f64>) {
        let n = Chain.dim();
        let y: Vec<f64> = (0..n).map(|i| libm::sin(i as f64 * 0.37) * 0.3).collect();
        let (atol, rtol) = (vec![1e-9; n], vec![1e-7; n]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        // Steps of several sizes, one backwards; the first one's methods are returned.
        let mut steps = [0.013, 1e-3, 0.37, -0.2].map(|h| {
            let (mut a, mut b) = (M::new(n), M::new(n));
            Chain.rhs(0.2, &y, a.f_start());
            Chain.rhs(0.2, &y, b.f_start());
            let (mut ya, mut yb) = (vec![0.0; n], vec![0.0; n]);
            let (mut sa, mut sb) = (Stats::default(), Stats::default());
            let ea = a.attempt(&Chain, 0.2, &y, h, &mut ya, &atol, &rtol, &mut sa);
            let eb = baseline(&mut b, 0.2, &y, h, &mut yb, &atol, &rtol, &mut sb);
            assert_eq!(
                ea.to_bits(),
                eb.to_bits(),
                "h = {h}: error {ea:e} against {eb:e}"
            );
            assert!(ea > 0.0 && ea.is_finite(), "h = {h}");
            assert_eq!(bits(&ya), bits(&yb), "h = {h}");
            assert_ne!(bits(&ya), bits(&y), "h = {h}: a step was taken");
            Some((a, b, ya))
        });
        steps[0].take().expect("four steps taken")
    }
}
