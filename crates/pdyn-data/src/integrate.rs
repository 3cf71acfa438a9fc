//! Sampled acceleration integrated to velocity and position:
//! `v(t) = v₀ + ∫ (a − b) dt`, `x(t) = x₀ + ∫ v dt`, with the same rule for both integrals.
//!
//! **Rules.** `trapezoid`: second order. `simpson`: over each interval the cubic through the
//! four nearest samples (the quadratic through three at the two end intervals, Simpson's
//! parabola), integrated exactly by two-point Gauss–Legendre; fourth order (on uniform samples
//! the interior weights are `(−1, 13, 13, −1)/24`), and defined at every sample, not only at
//! every other one.
//!
//! **Bias.** An accelerometer reads `a + b + noise`; an uncorrected bias `b` grows into a
//! position error `½ b t²`. Options: `none`; `mean` (subtract the record's mean — right when
//! the record starts and ends at the same velocity, e.g. at rest, since then `∫ a dt = 0`);
//! `quiet t0..t1` (subtract the mean over an interval where the sensor was at rest); or a
//! given value.
//!
//! **Error growth.** White noise of standard deviation `σ_a` per sample at sampling rate
//! `f_s` integrates to a random walk in velocity, `σ_v(t) = σ_a √(t/f_s)`, and in position
//! `σ_x(t) = σ_a t^{3/2} / √(3 f_s)`; a remaining bias error `δb` (the standard error of the
//! estimated bias, `σ_a/√N` from N samples) adds `½ δb t²`. Reported, with `t` from the start
//! and `h = 1/f_s`: `σ_x(t)² = σ_a² h t³/3 + (½ δb t²)² − t² C(t)`, where
//! `C(t) = σ_a² h Σ_{i∈B, t_i<t} (t − t_i) / N` is the covariance of the integrated noise with
//! the bias estimated from the same N samples `B` (removing the mean of a record that starts
//! and ends at rest also removes part of its own noise); likewise
//! `σ_v(t)² = σ_a² h t + (δb t)² − 2 t σ_a² h #{i∈B, t_i<t}/N`. `σ_a` is given, or the
//! standard deviation over the quiet interval, or estimated from second differences
//! (`Var(Δ²a) = 6 σ_a²` for a signal smooth at the sampling scale; Gasser et al. 1986).

use crate::error::DataError;

/// The quadrature rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Trapezoid (second order).
    Trapezoid,
    /// Local cubic through four samples (fourth order).
    Simpson,
}

impl Rule {
    /// `trapezoid` or `simpson`.
    pub fn parse(s: &str) -> Option<Rule> {
        match s {
            "trapezoid" | "trap" => Some(Rule::Trapezoid),
            "simpson" => Some(Rule::Simpson),
            _ => None,
        }
    }
}

/// How the accelerometer bias is removed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bias {
    /// Not removed.
    None,
    /// The record's mean is removed.
    Mean,
    /// The mean over `[t0, t1]`, where the sensor was at rest, is removed.
    Quiet(f64, f64),
    /// A given bias is removed.
    Value(f64),
}

/// One axis integrated.
#[derive(Clone, Debug)]
pub struct Integrated {
    /// Velocity at the sample times.
    pub v: Vec<f64>,
    /// Position at the sample times.
    pub x: Vec<f64>,
    /// The bias removed.
    pub bias: f64,
    /// The standard error of that bias (0 when given or not removed).
    pub bias_se: f64,
    /// The accelerometer noise σ_a used for the error estimate.
    pub sigma_a: f64,
    /// Where σ_a came from: `given`, `quiet interval`, `second differences`.
    pub sigma_a_source: &'static str,
    /// Estimated standard deviation of the velocity error.
    pub sigma_v: Vec<f64>,
    /// Estimated standard deviation of the position error.
    pub sigma_x: Vec<f64>,
}

/// The cumulative integral of `y` over `t` (starting at `y0`) by `rule`.
pub fn cumulative(t: &[f64], y: &[f64], y0: f64, rule: Rule) -> Vec<f64> {
    let n = t.len();
    let mut out = Vec::with_capacity(n);
    out.push(y0);
    let mut acc = y0;
    for i in 0..n.saturating_sub(1) {
        let h = t[i + 1] - t[i];
        let piece = match rule {
            Rule::Trapezoid => 0.5 * h * (y[i] + y[i + 1]),
            Rule::Simpson if n < 3 => 0.5 * h * (y[i] + y[i + 1]),
            Rule::Simpson => {
                let lo = if i == 0 {
                    0
                } else if i + 2 >= n {
                    n - 3
                } else {
                    i - 1
                };
                let hi = if i == 0 {
                    2
                } else if i + 2 >= n {
                    n - 1
                } else {
                    i + 2
                };
                let mid = 0.5 * (t[i] + t[i + 1]);
                let off = 0.5 * h / 3f64.sqrt();
                let p = |x: f64| lagrange(&t[lo..=hi], &y[lo..=hi], x);
                0.5 * h * (p(mid - off) + p(mid + off))
            }
        };
        acc += piece;
        out.push(acc);
    }
    out
}

/// The interpolating polynomial through `(ts, ys)` at `x` (Lagrange form; 3 or 4 points).
fn lagrange(ts: &[f64], ys: &[f64], x: f64) -> f64 {
    let mut sum = 0.0;
    for j in 0..ts.len() {
        let mut l = 1.0;
        for m in 0..ts.len() {
            if m != j {
                l *= (x - ts[m]) / (ts[j] - ts[m]);
            }
        }
        sum += l * ys[j];
    }
    sum
}

/// How to integrate one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelOptions {
    /// Initial velocity.
    pub v0: f64,
    /// Initial position.
    pub x0: f64,
    /// The quadrature rule.
    pub rule: Rule,
    /// The bias removal.
    pub bias: Bias,
    /// The accelerometer's noise (one sample's standard deviation), when known.
    pub sigma_a: Option<f64>,
}

impl Default for AccelOptions {
    fn default() -> AccelOptions {
        AccelOptions {
            v0: 0.0,
            x0: 0.0,
            rule: Rule::Simpson,
            bias: Bias::None,
            sigma_a: None,
        }
    }
}

/// Integrates one axis of acceleration `a` sampled at `t` (strictly increasing, ≥ 2 samples).
/// `name` is used in messages.
pub fn integrate(
    t: &[f64],
    a: &[f64],
    o: &AccelOptions,
    name: &str,
) -> Result<Integrated, DataError> {
    let AccelOptions {
        v0,
        x0,
        rule,
        bias,
        sigma_a,
    } = *o;
    let n = t.len();
    if n < 2 || a.len() != n {
        return Err(DataError::new(
            name,
            "integration needs at least two samples",
        ));
    }
    let mean = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len() as f64;
    let sd = |xs: &[f64]| {
        let m = mean(xs);
        (xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (xs.len() as f64 - 1.0).max(1.0))
            .sqrt()
    };
    let diff_sigma = || {
        if n < 3 {
            return 0.0;
        }
        let s: f64 = (1..n - 1)
            .map(|i| (a[i + 1] - 2.0 * a[i] + a[i - 1]).powi(2))
            .sum();
        (s / (6.0 * (n - 2) as f64)).sqrt()
    };
    let (mut sigma, mut source) = match sigma_a {
        Some(s) if s >= 0.0 && s.is_finite() => (s, "given"),
        Some(s) => {
            return Err(DataError::new(
                name,
                format!("σ_a = {s} must be ≥ 0 and finite"),
            ))
        }
        None => (diff_sigma(), "second differences"),
    };
    // The samples the bias was estimated from (indices i0..i1), if it was.
    let (b, b_se, quiet) = match bias {
        Bias::None => (0.0, 0.0, None),
        Bias::Value(b) => (b, 0.0, None),
        Bias::Mean => (mean(a), sigma / (n as f64).sqrt(), Some((0, n))),
        Bias::Quiet(t0, t1) => {
            let i0 = t.partition_point(|&s| s < t0);
            let i1 = t.partition_point(|&s| s <= t1);
            if i1 < i0 + 2 {
                return Err(DataError::new(
                    name,
                    format!(
                        "the quiet interval {t0}..{t1} holds {} sample(s); at least 2 are needed",
                        i1.saturating_sub(i0)
                    ),
                )
                .help(format!(
                    "choose an interval within the record [{}, {}] where the sensor was at rest",
                    t[0],
                    t[n - 1]
                )));
            }
            let quiet = &a[i0..i1];
            if sigma_a.is_none() {
                sigma = sd(quiet);
                source = "quiet interval";
            }
            (
                mean(quiet),
                sigma / ((i1 - i0) as f64).sqrt(),
                Some((i0, i1)),
            )
        }
    };
    let corrected: Vec<f64> = a.iter().map(|x| x - b).collect();
    let v = cumulative(t, &corrected, v0, rule);
    let x = cumulative(t, &v, x0, rule);
    let h = (t[n - 1] - t[0]) / (n - 1) as f64;
    let s2 = sigma * sigma;
    let mut sigma_v = Vec::with_capacity(n);
    let mut sigma_x = Vec::with_capacity(n);
    // Running count and sum of the bias samples before the current time (for the covariance of
    // the integrated noise with the bias estimated from the same noise).
    let (mut cnt, mut sum_t) = (0.0, 0.0);
    let nq = quiet.map_or(1.0, |(i0, i1)| (i1 - i0) as f64);
    for (i, &s) in t.iter().enumerate() {
        let e = s - t[0];
        let (cv, cx) = (s2 * h * cnt / nq, s2 * h * (cnt * e - sum_t) / nq);
        let var_v = s2 * h * e + (b_se * e).powi(2) - 2.0 * e * cv;
        let var_x = s2 * h * e.powi(3) / 3.0 + (0.5 * b_se * e * e).powi(2) - e * e * cx;
        sigma_v.push(var_v.max(0.0).sqrt());
        sigma_x.push(var_x.max(0.0).sqrt());
        if let Some((i0, i1)) = quiet {
            if (i0..i1).contains(&i) {
                cnt += 1.0;
                sum_t += e;
            }
        }
    }
    Ok(Integrated {
        v,
        x,
        bias: b,
        bias_se: b_se,
        sigma_a: sigma,
        sigma_a_source: source,
        sigma_v,
        sigma_x,
    })
}
