//! Sensor fusion: an accelerometer (high rate, biased, noisy) with position fixes (low rate,
//! noisy), by a Kalman filter and the Rauch–Tung–Striebel smoother, each axis independently.
//!
//! **Model** (per axis). State `x = (p, v, b)`: position, velocity, accelerometer bias. The
//! accelerometer reads `a_m = a + b + w` and drives the state as a known input held over each
//! sample interval: `p' = v`, `v' = a_m − b − w`, `b' = η`, with `w` white noise of spectral
//! density `σ_a²/f_s` (σ_a the standard deviation of one sample at rate `f_s`, so that the
//! velocity error of a pure integration grows as `σ_a √(t/f_s)`, as in
//! [`crate::integrate`]) and `η` a bias random walk of density `σ_b²` (`σ_b` in
//! (m/s²)/√s; 0 is a constant bias). Over a step `Δ`: `F = [[1, Δ, −Δ²/2], [0, 1, −Δ], [0, 0, 1]]`,
//! input `(Δ²/2, Δ, 0) a_m`, and the exact discrete covariance
//! `Q = σ_a²/f_s [[Δ³/3, Δ²/2, 0], [Δ²/2, Δ, 0], [0, 0, 0]] +
//! σ_b² [[Δ⁵/20, Δ⁴/8, −Δ³/6], [Δ⁴/8, Δ³/3, −Δ²/2], [−Δ³/6, −Δ²/2, Δ]]`.
//! A fix measures `p` with noise σ_p. Fixes between accelerometer samples are processed at
//! their own times. The covariance update uses Joseph's form (stays symmetric positive).
//!
//! **Prior.** Position: the first fix's value, σ = [`Noise::p0`] (default 10⁴, effectively
//! unknown); velocity 0 with σ = [`Noise::v0`] (default 10³); bias 0 with σ =
//! [`Noise::bias0`] (default 1 m/s²).
//!
//! **Noise levels** given, or estimated: σ_a from the accelerometer record itself by second
//! differences (`Var Δ²a = 6 σ_a²` for a signal smooth at the sampling scale; Gasser, Sroka &
//! Jennen-Steinmetz 1986) — the fixes cannot tell σ_a, whose effect between two fixes is far
//! below σ_p in any useful set-up, so the likelihood is flat in it; σ_p by maximising the
//! log-likelihood of the innovations (the prediction errors at the fixes, Gaussian with
//! variance `S = HPHᵀ + σ_p²` under the model; Harvey 1989) summed over the axes: a grid of
//! ½ decade over 6 decades, then golden section on log σ_p to 0.01 decade. σ_b is never
//! estimated (give it; 0 means a constant bias, which the filter estimates).

use crate::error::DataError;

type M3 = [[f64; 3]; 3];

/// Noise levels and prior of the fusion model (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Accelerometer noise, standard deviation of one sample (m/s²); `None`: estimate.
    pub sigma_a: Option<f64>,
    /// Position-fix noise, standard deviation (m); `None`: estimate.
    pub sigma_p: Option<f64>,
    /// Bias random walk (m/s²/√s); 0 for a constant bias.
    pub sigma_b: f64,
    /// Prior standard deviation of the initial position about the first fix.
    pub p0: f64,
    /// Prior standard deviation of the initial velocity about 0.
    pub v0: f64,
    /// Prior standard deviation of the bias about 0.
    pub bias0: f64,
}

impl Default for Noise {
    fn default() -> Noise {
        Noise {
            sigma_a: None,
            sigma_p: None,
            sigma_b: 0.0,
            p0: 1e4,
            v0: 1e3,
            bias0: 1.0,
        }
    }
}

/// The smoothed estimate of one axis at the accelerometer's sample times.
#[derive(Clone, Debug, Default)]
pub struct AxisEstimate {
    /// Position.
    pub p: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
    /// Accelerometer bias.
    pub b: Vec<f64>,
    /// Standard deviations of p, v, b (from the smoothed covariance).
    pub sd: [Vec<f64>; 3],
    /// The smoothed covariance matrices (row-major 3×3), kept only when asked for.
    pub cov: Vec<[f64; 9]>,
    /// The filtered (causal, forward-only) position, for comparison.
    pub p_filtered: Vec<f64>,
}

/// The result of [`fuse`].
#[derive(Clone, Debug)]
pub struct Fused {
    /// The accelerometer's sample times.
    pub t: Vec<f64>,
    /// One estimate per axis.
    pub axes: Vec<AxisEstimate>,
    /// The accelerometer noise used.
    pub sigma_a: f64,
    /// The fix noise used.
    pub sigma_p: f64,
    /// The bias random walk used.
    pub sigma_b: f64,
    /// Whether σ_a and σ_p were estimated.
    pub estimated: [bool; 2],
    /// The log-likelihood of the innovations at the noise levels used.
    pub log_likelihood: f64,
    /// The normalised innovations' mean square (≈ 1 for a consistent model).
    pub innovation_nis: f64,
}

/// The inputs of one axis.
struct Axis<'a> {
    ta: &'a [f64],
    a: &'a [f64],
    tf: &'a [f64],
    z: &'a [f64],
}

fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

fn transpose(a: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = a[j][i];
        }
    }
    c
}

fn inverse(a: &M3) -> Option<M3> {
    let c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    let c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    let c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    let det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02;
    if !(det.abs() > 0.0) || !det.is_finite() {
        return None;
    }
    let inv = [
        [
            c00,
            a[0][2] * a[2][1] - a[0][1] * a[2][2],
            a[0][1] * a[1][2] - a[0][2] * a[1][1],
        ],
        [
            c01,
            a[0][0] * a[2][2] - a[0][2] * a[2][0],
            a[0][2] * a[1][0] - a[0][0] * a[1][2],
        ],
        [
            c02,
            a[0][1] * a[2][0] - a[0][0] * a[2][1],
            a[0][0] * a[1][1] - a[0][1] * a[1][0],
        ],
    ];
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = inv[i][j] / det;
        }
    }
    Some(out)
}

fn transition(dt: f64) -> M3 {
    [[1.0, dt, -0.5 * dt * dt], [0.0, 1.0, -dt], [0.0, 0.0, 1.0]]
}

fn process_noise(dt: f64, qa: f64, qb: f64) -> M3 {
    let (d2, d3) = (dt * dt, dt * dt * dt);
    let (d4, d5) = (d2 * d2, d2 * d3);
    [
        [
            qa * d3 / 3.0 + qb * d5 / 20.0,
            qa * d2 / 2.0 + qb * d4 / 8.0,
            -qb * d3 / 6.0,
        ],
        [
            qa * d2 / 2.0 + qb * d4 / 8.0,
            qa * dt + qb * d3 / 3.0,
            -qb * d2 / 2.0,
        ],
        [-qb * d3 / 6.0, -qb * d2 / 2.0, qb * dt],
    ]
}

/// One filter node: the state predicted to its time and the state after its fix (if any).
#[derive(Clone, Copy)]
struct Node {
    dt: f64,
    xp: [f64; 3],
    pp: M3,
    xf: [f64; 3],
    pf: M3,
    /// The accelerometer sample this node is the time of, if any.
    sample: bool,
}

/// Runs the forward filter of one axis; returns the log-likelihood, the sum of normalised
/// squared innovations and their number, and the nodes when `keep`.
fn filter(
    ax: &Axis,
    qa: f64,
    qb: f64,
    sp: f64,
    prior: &Noise,
    keep: bool,
) -> (f64, f64, usize, Vec<Node>) {
    let n = ax.ta.len();
    let r = sp * sp;
    let mut x = [ax.z.first().copied().unwrap_or(0.0), 0.0, 0.0];
    let mut p: M3 = [
        [prior.p0 * prior.p0, 0.0, 0.0],
        [0.0, prior.v0 * prior.v0, 0.0],
        [0.0, 0.0, prior.bias0 * prior.bias0],
    ];
    let mut nodes = Vec::with_capacity(if keep { n + ax.tf.len() } else { 0 });
    let (mut ll, mut nis, mut count) = (0.0, 0.0, 0usize);
    let mut jf = 0; // next fix
    let mut time = ax.ta[0];
    let mut a_held = ax.a[0];
    let step = |x: &mut [f64; 3], p: &mut M3, dt: f64, a_m: f64| {
        if dt > 0.0 {
            let f = transition(dt);
            let nx = [
                x[0] + dt * x[1] - 0.5 * dt * dt * x[2] + 0.5 * dt * dt * a_m,
                x[1] - dt * x[2] + dt * a_m,
                x[2],
            ];
            *x = nx;
            let fp = mat_mul(&f, p);
            let mut np = mat_mul(&fp, &transpose(&f));
            let q = process_noise(dt, qa, qb);
            for i in 0..3 {
                for j in 0..3 {
                    np[i][j] += q[i][j];
                }
            }
            *p = np;
        }
    };
    let update = |x: &mut [f64; 3], p: &mut M3, zv: f64| {
        let s = p[0][0] + r;
        let nu = zv - x[0];
        let k = [p[0][0] / s, p[1][0] / s, p[2][0] / s];
        for i in 0..3 {
            x[i] += k[i] * nu;
        }
        // Joseph form: (I − K H) P (I − K H)ᵀ + K r Kᵀ.
        let mut ikh = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for i in 0..3 {
            ikh[i][0] -= k[i];
        }
        let mut np = mat_mul(&mat_mul(&ikh, p), &transpose(&ikh));
        for i in 0..3 {
            for j in 0..3 {
                np[i][j] += k[i] * r * k[j];
            }
        }
        *p = np;
        (
            -0.5 * (libm::log(2.0 * std::f64::consts::PI * s) + nu * nu / s),
            nu * nu / s,
        )
    };
    for k in 0..n {
        // Fixes strictly before this sample's time, after the previous node.
        while jf < ax.tf.len() && ax.tf[jf] < ax.ta[k] {
            let dt = ax.tf[jf] - time;
            step(&mut x, &mut p, dt, a_held);
            time = ax.tf[jf];
            let (xp, pp) = (x, p);
            let (l, e) = update(&mut x, &mut p, ax.z[jf]);
            ll += l;
            nis += e;
            count += 1;
            if keep {
                nodes.push(Node {
                    dt,
                    xp,
                    pp,
                    xf: x,
                    pf: p,
                    sample: false,
                });
            }
            jf += 1;
        }
        let dt = ax.ta[k] - time;
        step(&mut x, &mut p, dt, a_held);
        time = ax.ta[k];
        a_held = ax.a[k];
        let (xp, pp) = (x, p);
        while jf < ax.tf.len() && ax.tf[jf] == ax.ta[k] {
            let (l, e) = update(&mut x, &mut p, ax.z[jf]);
            ll += l;
            nis += e;
            count += 1;
            jf += 1;
        }
        if keep {
            nodes.push(Node {
                dt,
                xp,
                pp,
                xf: x,
                pf: p,
                sample: true,
            });
        }
    }
    (ll, nis, count, nodes)
}

/// The RTS smoother over the nodes of [`filter`]; the estimates at accelerometer samples.
fn smooth(nodes: &[Node], keep_cov: bool) -> AxisEstimate {
    let m = nodes.len();
    let mut xs = vec![[0.0; 3]; m];
    let mut ps = vec![[[0.0; 3]; 3]; m];
    if m > 0 {
        xs[m - 1] = nodes[m - 1].xf;
        ps[m - 1] = nodes[m - 1].pf;
    }
    for k in (0..m.saturating_sub(1)).rev() {
        let next = &nodes[k + 1];
        let f = transition(next.dt);
        let c = match inverse(&next.pp) {
            Some(inv) => mat_mul(&mat_mul(&nodes[k].pf, &transpose(&f)), &inv),
            // A singular prediction (no uncertainty left): nothing to correct.
            None => [[0.0; 3]; 3],
        };
        let mut x = nodes[k].xf;
        for i in 0..3 {
            for j in 0..3 {
                x[i] += c[i][j] * (xs[k + 1][j] - next.xp[j]);
            }
        }
        let mut d = ps[k + 1];
        for i in 0..3 {
            for j in 0..3 {
                d[i][j] -= next.pp[i][j];
            }
        }
        let cd = mat_mul(&mat_mul(&c, &d), &transpose(&c));
        let mut p = nodes[k].pf;
        for i in 0..3 {
            for j in 0..3 {
                p[i][j] += cd[i][j];
            }
        }
        xs[k] = x;
        ps[k] = p;
    }
    let mut e = AxisEstimate::default();
    for k in 0..m {
        if !nodes[k].sample {
            continue;
        }
        e.p.push(xs[k][0]);
        e.v.push(xs[k][1]);
        e.b.push(xs[k][2]);
        for i in 0..3 {
            e.sd[i].push(ps[k][i][i].max(0.0).sqrt());
        }
        if keep_cov {
            let p = ps[k];
            e.cov.push([
                p[0][0], p[0][1], p[0][2], p[1][0], p[1][1], p[1][2], p[2][0], p[2][1], p[2][2],
            ]);
        }
        e.p_filtered.push(nodes[k].xf[0]);
    }
    e
}

/// Fuses an accelerometer record (`ta`, one column per axis in `a`) with position fixes (`tf`,
/// one column per axis in `z`, the same axes). Times strictly increasing (checked by
/// [`crate::csv::Series`]); every fix must lie within the accelerometer's time range.
/// `keep_cov`: return the smoothed covariance matrices too.
pub fn fuse(
    ta: &[f64],
    a: &[Vec<f64>],
    tf: &[f64],
    z: &[Vec<f64>],
    noise: &Noise,
    keep_cov: bool,
) -> Result<Fused, DataError> {
    if a.is_empty() || a.len() != z.len() {
        return Err(DataError::new(
            "",
            format!(
                "{} accelerometer axis(es) but {} position axis(es): they must match",
                a.len(),
                z.len()
            ),
        ));
    }
    if ta.len() < 2 || tf.is_empty() {
        return Err(DataError::new(
            "",
            "fusion needs at least 2 accelerometer samples and 1 fix",
        ));
    }
    let (t0, t1) = (ta[0], ta[ta.len() - 1]);
    if let Some(i) = tf.iter().position(|&s| s < t0 || s > t1) {
        return Err(DataError::new(
            "",
            format!(
                "fix {} at time {} is outside the accelerometer record [{t0}, {t1}]",
                i + 1,
                tf[i]
            ),
        )
        .help("keep only the fixes taken while the accelerometer was recording"));
    }
    for (what, s) in [
        ("σ_p", noise.sigma_p),
        ("σ_a", noise.sigma_a),
        ("σ_b", Some(noise.sigma_b)),
    ] {
        if let Some(s) = s {
            if !(s >= 0.0) || !s.is_finite() {
                return Err(DataError::new(
                    "",
                    format!("{what} = {s} must be ≥ 0 and finite"),
                ));
            }
        }
    }
    if noise.sigma_p == Some(0.0) {
        return Err(
            DataError::new("", "σ_p = 0 would make the fixes exact").help("give a positive σ_p")
        );
    }
    let axes: Vec<Axis> = a
        .iter()
        .zip(z)
        .map(|(a, z)| Axis { ta, a, tf, z })
        .collect();
    let fs = (ta.len() - 1) as f64 / (t1 - t0);
    let qb = noise.sigma_b * noise.sigma_b;
    let second_diff_sd = |xs: &[f64]| {
        if xs.len() < 3 {
            return 1.0;
        }
        let s: f64 = xs
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2))
            .sum();
        let v = (s / (6.0 * (xs.len() - 2) as f64)).sqrt();
        if v > 0.0 {
            v
        } else {
            1.0
        }
    };
    // σ_a: from the accelerometer itself, by second differences (Var Δ²a = 6 σ_a² for a
    // signal smooth at the sampling scale). The fixes cannot tell it: between fixes its
    // effect on the position is far below σ_p in any useful set-up, so the innovations'
    // likelihood is flat in σ_a.
    let sa = match noise.sigma_a {
        Some(s) => s,
        None => a.iter().map(|c| second_diff_sd(c)).fold(0.0, f64::max),
    };
    let qa = sa * sa / fs;
    // σ_p: maximum likelihood of the innovations, a grid of ½ decade over 6 decades around
    // the fixes' own second differences (which include the motion, hence an upper scale),
    // then golden section to 0.01 decade.
    let objective = |lp: f64| {
        let sp = libm::pow(10f64, lp);
        let l: f64 = axes
            .iter()
            .map(|ax| filter(ax, qa, qb, sp, noise, false).0)
            .sum();
        if l.is_finite() {
            -l
        } else {
            f64::INFINITY
        }
    };
    let sp = match noise.sigma_p {
        Some(s) => s,
        None => {
            let guess = libm::log10(z.iter().map(|c| second_diff_sd(c)).fold(0.0, f64::max));
            let mut best = (f64::INFINITY, guess);
            for k in 0..13 {
                let lp = guess - 5.0 + 0.5 * k as f64;
                let v = objective(lp);
                if v < best.0 {
                    best = (v, lp);
                }
            }
            if !best.0.is_finite() {
                return Err(DataError::new(
                    "",
                    "σ_p could not be estimated (no finite likelihood of the fixes)",
                )
                .help("give σ_p"));
            }
            libm::pow(10f64, golden(objective, best.1 - 0.5, best.1 + 0.5))
        }
    };
    let est = [noise.sigma_a.is_none(), noise.sigma_p.is_none()];
    let mut out_axes = Vec::with_capacity(axes.len());
    let (mut ll, mut nis, mut count) = (0.0, 0.0, 0usize);
    for ax in &axes {
        let (l, e, c, nodes) = filter(ax, qa, qb, sp, noise, true);
        ll += l;
        nis += e;
        count += c;
        out_axes.push(smooth(&nodes, keep_cov));
    }
    Ok(Fused {
        t: ta.to_vec(),
        axes: out_axes,
        sigma_a: sa,
        sigma_p: sp,
        sigma_b: noise.sigma_b,
        estimated: est,
        log_likelihood: ll,
        innovation_nis: if count > 0 {
            nis / count as f64
        } else {
            f64::NAN
        },
    })
}

/// The minimiser of `f` on `[a, b]` by golden section to 0.01.
fn golden(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let (mut f1, mut f2) = (f(x1), f(x2));
    while b - a > 0.01 {
        if f1 <= f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = f(x2);
        }
    }
    if f1 <= f2 {
        x1
    } else {
        x2
    }
}
