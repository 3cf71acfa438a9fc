//! **Radau5** — the 3-stage Radau IIA implicit Runge–Kutta method of order 5, with the
//! algorithm of Hairer & Wanner's RADAU5 code. Implicit, adaptive, L-stable, for stiff
//! problems and for `M y' = f(t, y)` with a constant (possibly singular: index-1 DAE) mass
//! matrix (a state-dependent, nonsingular `M(t, y)` is handled through
//! [`crate::MassInverse`]). Not symplectic.
//!
//! E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II: Stiff and
//! Differential-Algebraic Problems*, 2nd ed., Springer 1996, §IV.8 (radau5.f).
//!
//! * Collocation at `c = ((4 − √6)/10, (4 + √6)/10, 1)`; the stage increments `Z = (Z1, Z2,
//!   Z3)` solve `M Z_i = h Σ_j a_ij f(t + c_j h, y + Z_j)`.
//! * Simplified Newton: with `W = T⁻¹ Z` the iteration matrix of `A⁻¹ ⊗ M − h I ⊗ J`
//!   decouples into a real system `(γ/h · M − J)` and a complex one `((α + iβ)/h · M − J)`,
//!   factorised by LU ([`crate::linalg`]). Iterations stop when
//!   `θ/(1−θ) · ‖ΔZ‖ ≤ κ = max(10u/rtol', min(0.03, rtol'^{1/2}))` (at most 7); a slow
//!   contraction `θ` predicts failure and shrinks the step early.
//! * Jacobian reuse: after an accepted step the Jacobian is kept when `θ ≤ 0.001`, and the
//!   factorisations too when moreover `1 ≤ h_new/h ≤ 1.2` (then the step is not changed).
//!   The Jacobian is analytic when [`OdeSystem::has_jacobian`], else forward differences with
//!   increments `sqrt(u · max(1e-5, |y_j|))` ([`crate::jacobian`], columns grouped by
//!   [`Options::jac_sparsity`] when given).
//! * Error estimate `err = ‖(γ/h M − J)⁻¹ (f(y0) + M (d1 Z1 + d2 Z2 + d3 Z3)/h)‖`, refined by
//!   one more solve after a rejection or at the first step; step ratio
//!   `h_new/h = 1/clamp(err^{1/4}/fac, 1/8, 5)` with `fac = min(0.9, 0.9(1+2·7)/(newt+14))`,
//!   and Gustafsson's predictive controller.
//! * Tolerances are transformed as RADAU5 does: `rtol' = 0.1 rtol^{2/3}`,
//!   `atol' = rtol' · atol/rtol`; the unit roundoff is RADAU5's `u = 1e-16`.
//! * Dense output: the collocation polynomial through `y0 + Z_i` (order 3 uniformly).
//!
//! Statistics follow radau5.f: `rejected` does not count rejections before the first accepted
//! step; `fevals − jac_fevals` is NFCN; `linear_solves` is NSOL (one per Newton iteration,
//! real + complex system, the error-estimate solves not counted); `lu_decompositions` is NDEC
//! (one per real + complex pair).

use super::radau5_linear::Systems;
use crate::controller::Controller;
use crate::error::{invalid, point, OdeError};
use crate::events::{DenseOutput, Event, EventState, Output};
use crate::explicit::setup;
use crate::options::Options;
use crate::problem::{MassKind, OdeSystem};
use crate::solution::{Solution, Status};
use crate::tableau::Tableau;
use crate::Method;

/// One-line description for `--method help`.
pub const DOC: &str = "Radau IIA order 5, implicit adaptive (RADAU5 algorithm: simplified \
Newton, Jacobian reuse, predictive step control); L-stable, for stiff problems and constant \
mass matrices (index-1 DAEs). Hairer & Wanner 1996.";

const SQ6: f64 = 2.449489742783178098197284074705891391965947480656670128432692567; // √6

/// The Radau IIA tableau (order 5, stage order 3, stiffly accurate: `b` is the last row of
/// `a`). The solver works with its transformed form (the `T`, `T⁻¹` matrices and the
/// eigenvalues `γ`, `α ± iβ` of `A⁻¹` below); this is the reference the tests check them
/// against.
pub const TABLEAU: Tableau<3> = Tableau {
    a: [
        [
            (88.0 - 7.0 * SQ6) / 360.0,
            (296.0 - 169.0 * SQ6) / 1800.0,
            (-2.0 + 3.0 * SQ6) / 225.0,
        ],
        [
            (296.0 + 169.0 * SQ6) / 1800.0,
            (88.0 + 7.0 * SQ6) / 360.0,
            (-2.0 - 3.0 * SQ6) / 225.0,
        ],
        [(16.0 - SQ6) / 36.0, (16.0 + SQ6) / 36.0, 1.0 / 9.0],
    ],
    b: [(16.0 - SQ6) / 36.0, (16.0 + SQ6) / 36.0, 1.0 / 9.0],
    b_hat: None,
    c: [(4.0 - SQ6) / 10.0, (4.0 + SQ6) / 10.0, 1.0],
    order: 5,
    embedded_order: 0,
    fsal: false,
};

/// RADAU5's unit roundoff.
const UROUND: f64 = 1e-16;
/// Maximal number of Newton iterations (NIT).
const NIT: usize = 7;
/// Jacobian recomputation threshold on the contraction rate (THET).
const THET: f64 = 0.001;
/// Keep the step (and the LU factors) when `QUOT1 ≤ h_new/h ≤ QUOT2`.
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;

const T11: f64 = 9.1232394870892942792e-02;
const T12: f64 = -0.14125529502095420843;
const T13: f64 = -3.0029194105147424492e-02;
const T21: f64 = 0.24171793270710701896;
const T22: f64 = 0.20412935229379993199;
const T23: f64 = 0.38294211275726193779;
const T31: f64 = 0.96604818261509293619;
const TI11: f64 = 4.3255798900631553510;
const TI12: f64 = 0.33919925181580986954;
const TI13: f64 = 0.54177053993587487119;
const TI21: f64 = -4.1787185915519047273;
const TI22: f64 = -0.32768282076106238708;
const TI23: f64 = 0.47662355450055045196;
const TI31: f64 = -0.50287263494578687595;
const TI32: f64 = 2.5719269498556054292;
const TI33: f64 = -0.59603920482822492497;

/// Constants of the method, computed as radau5.f computes them.
struct Consts {
    c1: f64,
    c2: f64,
    c1m1: f64,
    c2m1: f64,
    c1mc2: f64,
    dd1: f64,
    dd2: f64,
    dd3: f64,
    u1: f64,
    alph: f64,
    beta: f64,
}

impl Consts {
    fn new() -> Self {
        let sq6 = 6f64.sqrt();
        let c1 = (4.0 - sq6) / 10.0;
        let c2 = (4.0 + sq6) / 10.0;
        let c81 = libm::pow(81f64, 1.0 / 3.0);
        let c9 = libm::pow(9f64, 1.0 / 3.0);
        let u1 = (6.0 + c81 - c9) / 30.0;
        let alph = (12.0 - c81 + c9) / 60.0;
        let beta = (c81 + c9) * 3f64.sqrt() / 60.0;
        let cno = alph * alph + beta * beta;
        Consts {
            c1,
            c2,
            c1m1: c1 - 1.0,
            c2m1: c2 - 1.0,
            c1mc2: c1 - c2,
            dd1: -(13.0 + 7.0 * sq6) / 3.0,
            dd2: (-13.0 + 7.0 * sq6) / 3.0,
            dd3: -1.0 / 3.0,
            u1: 1.0 / u1,
            alph: alph / cno,
            beta: beta / cno,
        }
    }
}

/// Dense output of the last accepted step: the collocation polynomial.
struct Radau5Dense {
    n: usize,
    cont: Vec<f64>,
    xsol: f64,
    hsol: f64,
    c1m1: f64,
    c2m1: f64,
}

impl DenseOutput for Radau5Dense {
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.xsol) / self.hsol;
        eval_cont(&self.cont, self.n, s, self.c1m1, self.c2m1, out);
    }
    fn record(&self, t_from: f64, t_to: f64, into: &mut crate::dense::DenseSolution) {
        let kind = crate::dense::Interpolant::Radau5 {
            c1m1: self.c1m1,
            c2m1: self.c2m1,
        };
        into.push(t_from, t_to, kind, self.xsol, self.hsol, &[&self.cont]);
    }
}

/// The collocation polynomial (radau5.f `CONTR5`) at `s = (t − x_end)/h` from its
/// coefficients `c` (`4n`).
#[inline]
pub(crate) fn eval_cont(c: &[f64], n: usize, s: f64, c1m1: f64, c2m1: f64, out: &mut [f64]) {
    for i in 0..n {
        out[i] = c[i] + s * (c[i + n] + (s - c2m1) * (c[i + 2 * n] + (s - c1m1) * c[i + 3 * n]));
    }
}

enum Next {
    Jacobian,
    Decompose,
    Step,
}

/// Integrates with Radau5.
pub(crate) fn integrate<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    tf: f64,
    y_init: &[f64],
    opts: &Options,
    events: &[Event<'_>],
) -> Result<Solution, OdeError> {
    let su = setup(sys, t0, tf, y_init, opts)?;
    let n = su.n;
    let mass = match sys.mass_kind() {
        MassKind::Identity => None,
        MassKind::Constant => {
            let mut m = vec![0.0; n * n];
            sys.mass_matrix(t0, y_init, &mut m);
            Some(m) // row-major
        }
        MassKind::StateDependent => return Err(invalid(
            "radau5 supports constant mass matrices; wrap state-dependent ones (see MassInverse)",
        )),
    };
    let ctrl = opts.controller.unwrap_or_else(Controller::radau5);
    let safe = ctrl.safety;
    let facl = 1.0 / ctrl.fac_min;
    let facr = 1.0 / ctrl.fac_max;
    // RADAU5's tolerance transformation.
    let mut rtol = su.rtol.clone();
    let mut atol = su.atol.clone();
    for i in 0..n {
        if atol[i] <= 0.0 || rtol[i] <= 10.0 * UROUND {
            return Err(invalid("radau5 needs atol > 0 and rtol > 1e-15"));
        }
        let quot = atol[i] / rtol[i];
        rtol[i] = 0.1 * libm::pow(rtol[i], 2.0 / 3.0);
        atol[i] = rtol[i] * quot;
    }
    let fnewt = (10.0 * UROUND / rtol[0]).max(0.03f64.min(rtol[0].sqrt()));
    let k = Consts::new();
    let posneg = su.dir;
    let hmaxn = su.hmax.min((tf - t0).abs());

    let mut sol = Solution::new(Method::Radau5, n);
    if opts.dense_output {
        sol.dense = Some(crate::DenseSolution::new(n));
    }
    let mut out = Output::new(opts, posneg);
    out.start(&mut sol, t0, y_init);
    if t0 == tf {
        return Ok(sol);
    }
    let mut ev = EventState::new(events, n, t0, y_init);

    let mut x = t0;
    let mut y = y_init.to_vec();
    let mut h = opts.h0.unwrap_or(1e-6);
    if h.abs() <= 10.0 * UROUND {
        h = 1e-6;
    }
    h = h.abs().min(hmaxn) * posneg;
    let mut hold = h;
    let mut reject = false;
    let mut first = true;
    let mut last = false;
    if (x + h * 1.0001 - tf) * posneg >= 0.0 {
        h = tf - x;
        last = true;
    }
    let mut faccon = 1.0f64;
    let cfac = safe * (1 + 2 * NIT) as f64;
    let mut nsing = 0;
    let mut scal: Vec<f64> = (0..n).map(|i| atol[i] + rtol[i] * y[i].abs()).collect();
    let mut y0f = vec![0.0; n];
    sys.rhs(x, &y, &mut y0f);
    sol.stats.fevals += 1;

    let (mut z1, mut z2, mut z3) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut f1, mut f2, mut f3) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut tmp = vec![0.0; n];
    let mut ytmp = vec![0.0; n];
    let mut fd = crate::jacobian::FdJacobian::default();
    let mut systems = Systems::new(sys, opts, n, mass)?;
    sol.stats.sparse_lu = systems.is_sparse();
    let mut dense = Radau5Dense {
        n,
        cont: vec![0.0; 4 * n],
        xsol: x,
        hsol: h,
        c1m1: k.c1m1,
        c2m1: k.c2m1,
    };
    let mut caljac = false;
    let mut nstep = 0usize;
    let mut theta: f64;
    let (mut hacc, mut erracc) = (0.0f64, 0.0f64);
    let mut thqold = 0.0f64;
    let mut fac1 = 0.0;
    let mut alphn = 0.0;
    let mut betan = 0.0;
    let mut next = Next::Jacobian;
    // A step of size min_step was tried since the last accepted step.
    let mut tried_min = false;

    'outer: loop {
        // Set by an "unexpected rejection" (radau5.f label 78): `Some(singular)`.
        let mut unexpected: Option<bool> = None;
        match next {
            Next::Jacobian => {
                sol.stats.jacobians += 1;
                systems.jacobian(sys, opts, &mut fd, x, &y, &y0f, &mut sol.stats);
                caljac = true;
                next = Next::Decompose;
                continue;
            }
            Next::Decompose => {
                if su.hmin > 0.0 && h.abs() < su.hmin && !last {
                    if tried_min {
                        return Err(OdeError::MinStep {
                            min_step: su.hmin,
                            at: point(x, &y, &mut sol),
                        });
                    }
                    h = su.hmin * posneg;
                    tried_min = true;
                }
                fac1 = k.u1 / h;
                alphn = k.alph / h;
                betan = k.beta / h;
                let ok2 = systems.decompose(fac1, alphn, betan);
                if !ok2 {
                    unexpected = Some(true);
                } else {
                    sol.stats.lu_decompositions += 1;
                    next = Next::Step;
                    continue;
                }
            }
            Next::Step => {}
        }
        if unexpected.is_none() {
            // ---- one step attempt (label 30)
            nstep += 1;
            sol.stats.steps += 1;
            if opts.interrupted() {
                return Err(OdeError::Interrupted {
                    at: point(x, &y, &mut sol),
                });
            }
            if nstep > opts.max_steps {
                return Err(OdeError::MaxSteps {
                    max_steps: opts.max_steps,
                    at: point(x, &y, &mut sol),
                });
            }
            if 0.1 * h.abs() <= x.abs() * UROUND || h == 0.0 || !h.is_finite() {
                return Err(OdeError::StepSizeUnderflow {
                    h,
                    at: point(x, &y, &mut sol),
                });
            }
            let xph = x + h;
            if first {
                for i in 0..n {
                    z1[i] = 0.0;
                    z2[i] = 0.0;
                    z3[i] = 0.0;
                    f1[i] = 0.0;
                    f2[i] = 0.0;
                    f3[i] = 0.0;
                }
            } else {
                let c3q = h / hold;
                let c1q = k.c1 * c3q;
                let c2q = k.c2 * c3q;
                let c = &dense.cont;
                for i in 0..n {
                    let (ak1, ak2, ak3) = (c[i + n], c[i + 2 * n], c[i + 3 * n]);
                    let z1i = c1q * (ak1 + (c1q - k.c2m1) * (ak2 + (c1q - k.c1m1) * ak3));
                    let z2i = c2q * (ak1 + (c2q - k.c2m1) * (ak2 + (c2q - k.c1m1) * ak3));
                    let z3i = c3q * (ak1 + (c3q - k.c2m1) * (ak2 + (c3q - k.c1m1) * ak3));
                    z1[i] = z1i;
                    z2[i] = z2i;
                    z3[i] = z3i;
                    f1[i] = TI11 * z1i + TI12 * z2i + TI13 * z3i;
                    f2[i] = TI21 * z1i + TI22 * z2i + TI23 * z3i;
                    f3[i] = TI31 * z1i + TI32 * z2i + TI33 * z3i;
                }
            }
            // ---- simplified Newton iteration (label 40)
            let mut newt = 0usize;
            faccon = libm::pow(faccon.max(UROUND), 0.8);
            theta = THET.abs();
            let mut dynold = 0.0f64;
            loop {
                if newt >= NIT {
                    unexpected = Some(false);
                    break;
                }
                for i in 0..n {
                    tmp[i] = y[i] + z1[i];
                }
                sys.rhs(x + k.c1 * h, &tmp, &mut z1);
                for i in 0..n {
                    tmp[i] = y[i] + z2[i];
                }
                sys.rhs(x + k.c2 * h, &tmp, &mut z2);
                for i in 0..n {
                    tmp[i] = y[i] + z3[i];
                }
                sys.rhs(xph, &tmp, &mut z3);
                sol.stats.fevals += 3;
                for i in 0..n {
                    let (a1, a2, a3) = (z1[i], z2[i], z3[i]);
                    z1[i] = TI11 * a1 + TI12 * a2 + TI13 * a3;
                    z2[i] = TI21 * a1 + TI22 * a2 + TI23 * a3;
                    z3[i] = TI31 * a1 + TI32 * a2 + TI33 * a3;
                }
                // SLVRAD
                match systems.mass() {
                    None => {
                        for i in 0..n {
                            let s2 = -f2[i];
                            let s3 = -f3[i];
                            z1[i] -= f1[i] * fac1;
                            z2[i] = z2[i] + s2 * alphn - s3 * betan;
                            z3[i] = z3[i] + s3 * alphn + s2 * betan;
                        }
                    }
                    Some(m) => {
                        for i in 0..n {
                            let (mut s1, mut s2, mut s3) = (0.0, 0.0, 0.0);
                            for j in 0..n {
                                let bb = m[i * n + j];
                                s1 -= bb * f1[j];
                                s2 -= bb * f2[j];
                                s3 -= bb * f3[j];
                            }
                            z1[i] += s1 * fac1;
                            z2[i] = z2[i] + s2 * alphn - s3 * betan;
                            z3[i] = z3[i] + s3 * alphn + s2 * betan;
                        }
                    }
                }
                systems.solve1(&mut z1);
                systems.solve2(&mut z2, &mut z3);
                sol.stats.linear_solves += 1;
                newt += 1;
                let mut dyno = 0.0;
                for i in 0..n {
                    let d = scal[i];
                    dyno += (z1[i] / d).powi(2) + (z2[i] / d).powi(2) + (z3[i] / d).powi(2);
                }
                dyno = (dyno / (3 * n) as f64).sqrt();
                if newt > 1 && newt < NIT {
                    let thq = dyno / dynold;
                    theta = if newt == 2 {
                        thq
                    } else {
                        (thq * thqold).sqrt()
                    };
                    thqold = thq;
                    if theta < 0.99 {
                        faccon = theta / (1.0 - theta);
                        let dyth = faccon * dyno * theta.powi((NIT - 1 - newt) as i32) / fnewt;
                        if dyth >= 1.0 {
                            let qnewt = 1e-4f64.max(20.0f64.min(dyth));
                            let hhfac =
                                0.8 * libm::pow(qnewt, -1.0 / (4.0 + (NIT - 1 - newt) as f64));
                            h *= hhfac;
                            reject = true;
                            last = false;
                            next = if caljac {
                                Next::Decompose
                            } else {
                                Next::Jacobian
                            };
                            continue 'outer;
                        }
                    } else {
                        unexpected = Some(false);
                        break;
                    }
                }
                dynold = dyno.max(UROUND);
                for i in 0..n {
                    let f1i = f1[i] + z1[i];
                    let f2i = f2[i] + z2[i];
                    let f3i = f3[i] + z3[i];
                    f1[i] = f1i;
                    f2[i] = f2i;
                    f3[i] = f3i;
                    z1[i] = T11 * f1i + T12 * f2i + T13 * f3i;
                    z2[i] = T21 * f1i + T22 * f2i + T23 * f3i;
                    z3[i] = T31 * f1i + f2i;
                }
                if faccon * dyno <= fnewt {
                    break;
                }
            }
            if unexpected.is_none() {
                // ---- error estimate (ESTRAD)
                let hee1 = k.dd1 / h;
                let hee2 = k.dd2 / h;
                let hee3 = k.dd3 / h;
                for i in 0..n {
                    f1[i] = hee1 * z1[i] + hee2 * z2[i] + hee3 * z3[i];
                }
                match systems.mass() {
                    None => f2.copy_from_slice(&f1),
                    Some(m) => {
                        for i in 0..n {
                            let mut s = 0.0;
                            for j in 0..n {
                                s += m[i * n + j] * f1[j];
                            }
                            f2[i] = s;
                        }
                    }
                }
                for i in 0..n {
                    tmp[i] = f2[i] + y0f[i];
                }
                systems.solve1(&mut tmp);
                let mut err = norm(&tmp, &scal);
                if err >= 1.0 && (first || reject) {
                    for i in 0..n {
                        tmp[i] += y[i];
                    }
                    sys.rhs(x, &tmp, &mut f1);
                    sol.stats.fevals += 1;
                    for i in 0..n {
                        tmp[i] = f1[i] + f2[i];
                    }
                    systems.solve1(&mut tmp);
                    err = norm(&tmp, &scal);
                }
                // ---- new step size
                let fac = safe.min(cfac / (newt + 2 * NIT) as f64);
                let mut quot = facr.max(facl.min(libm::pow(err, 0.25) / fac));
                let mut hnew = h / quot;
                if err < 1.0 {
                    first = false;
                    tried_min = false;
                    sol.stats.accepted += 1;
                    if sol.stats.accepted > 1 {
                        let facgus = (hacc / h) * libm::pow(err * err / erracc, 0.25) / safe;
                        let facgus = facr.max(facl.min(facgus));
                        quot = quot.max(facgus);
                        hnew = h / quot;
                    }
                    hacc = h;
                    erracc = 1e-2f64.max(err);
                    let x_old = x;
                    hold = h;
                    x = if last { tf } else { xph };
                    let c = &mut dense.cont;
                    for i in 0..n {
                        y[i] += z3[i];
                        let z2i = z2[i];
                        let z1i = z1[i];
                        c[i + n] = (z2i - z3[i]) / k.c2m1;
                        let ak = (z1i - z2i) / k.c1mc2;
                        let mut acont3 = z1i / k.c1;
                        acont3 = (ak - acont3) / k.c2;
                        c[i + 2 * n] = (ak - c[i + n]) / k.c1m1;
                        c[i + 3 * n] = c[i + 2 * n] - acont3;
                        c[i] = y[i];
                    }
                    dense.xsol = x;
                    dense.hsol = hold;
                    for i in 0..n {
                        scal[i] = atol[i] + rtol[i] * y[i].abs();
                    }
                    caljac = false;
                    if y.iter().any(|v| !v.is_finite()) {
                        return Err(OdeError::NonFinite {
                            at: point(x_old, &y, &mut sol),
                        });
                    }
                    // events and outputs
                    let crossed = !events.is_empty() && ev.check(x, &y);
                    let stop = if crossed {
                        ev.locate(&dense, x_old, x, &mut sol.events)
                    } else {
                        None
                    };
                    if let Some(d) = sol.dense.as_mut() {
                        dense.record(x_old, stop.map_or(x, |s| s.0), d);
                    }
                    ev.drain_suspects(&mut sol.possible_misses);
                    out.emit(&mut sol, &dense, x, &y, stop.map(|s| s.0), &mut ytmp);
                    if let Some((_, idx)) = stop {
                        sol.status = Status::TerminalEvent(idx);
                        return Ok(sol);
                    }
                    if last {
                        return Ok(sol);
                    }
                    sys.rhs(x, &y, &mut y0f);
                    sol.stats.fevals += 1;
                    hnew = posneg * hnew.abs().min(hmaxn);
                    if reject {
                        hnew = posneg * hnew.abs().min(h.abs());
                    }
                    reject = false;
                    if (x + hnew / QUOT1 - tf) * posneg >= 0.0 {
                        h = tf - x;
                        last = true;
                    } else {
                        let qt = hnew / h;
                        if theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                            next = Next::Step;
                            continue 'outer;
                        }
                        h = hnew;
                    }
                    next = if theta <= THET {
                        Next::Decompose
                    } else {
                        Next::Jacobian
                    };
                    continue 'outer;
                } else {
                    reject = true;
                    last = false;
                    if first {
                        h *= 0.1;
                    } else {
                        h = hnew;
                    }
                    if sol.stats.accepted >= 1 {
                        sol.stats.rejected += 1;
                    }
                    next = if caljac {
                        Next::Decompose
                    } else {
                        Next::Jacobian
                    };
                    continue 'outer;
                }
            }
        }
        // ---- unexpected step rejection (label 78)
        if let Some(singular) = unexpected {
            if singular {
                nsing += 1;
                if nsing >= 5 {
                    return Err(OdeError::SingularMatrix {
                        at: point(x, &y, &mut sol),
                    });
                }
            }
            h *= 0.5;
            reject = true;
            last = false;
            next = if caljac {
                Next::Decompose
            } else {
                Next::Jacobian
            };
        }
    }
}

fn norm(v: &[f64], scal: &[f64]) -> f64 {
    let s: f64 = v.iter().zip(scal).map(|(a, b)| (a / b) * (a / b)).sum();
    (s / v.len() as f64).sqrt().max(1e-10)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;

    fn mul3(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let mut c = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        c
    }

    fn inv3(a: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let (i1, i2) = ((j + 1) % 3, (j + 2) % 3);
                let (j1, j2) = ((i + 1) % 3, (i + 2) % 3);
                r[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det;
            }
        }
        r
    }

    #[test]
    fn radau_iia_tableau_has_order_5_and_t_inverts_ti() {
        let a = TABLEAU.a_rows();
        assert!(TABLEAU.row_sum_residual() < 1e-15);
        assert!(order_residual(&a, &TABLEAU.b, 5) < 1e-14);
        assert!(order_residual(&a, &TABLEAU.b, 6) > 1e-6);
        let k = Consts::new();
        assert!((TABLEAU.c[0] - k.c1).abs() < 1e-16 && (TABLEAU.c[1] - k.c2).abs() < 1e-16);
        // T⁻¹ A⁻¹ T = diag(γ, [[α, −β], [β, α]]) (radau5.f's transformation)
        let ainv = inv3(&TABLEAU.a);
        let t = [[T11, T12, T13], [T21, T22, T23], [T31, 1.0, 0.0]];
        let ti = [[TI11, TI12, TI13], [TI21, TI22, TI23], [TI31, TI32, TI33]];
        let m = mul3(&ti, &mul3(&ainv, &t));
        let (g, al, be) = (k.u1, k.alph, k.beta);
        let want = [[g, 0.0, 0.0], [0.0, al, -be], [0.0, be, al]];
        for i in 0..3 {
            for j in 0..3 {
                assert!((m[i][j] - want[i][j]).abs() < 1e-12, "{m:?}");
            }
        }
        let t = [[T11, T12, T13], [T21, T22, T23], [T31, 1.0, 0.0]];
        let ti = [[TI11, TI12, TI13], [TI21, TI22, TI23], [TI31, TI32, TI33]];
        for i in 0..3 {
            for j in 0..3 {
                let p: f64 = (0..3).map(|m| t[i][m] * ti[m][j]).sum();
                assert!((p - f64::from(u8::from(i == j))).abs() < 1e-15);
            }
        }
    }
}
