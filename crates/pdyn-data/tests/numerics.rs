//! Known truth for the numerics: interpolation orders, the smoothing spline against a dense
//! solve of its defining equations, the equivalent-kernel standard errors against Monte Carlo,
//! kinematics of a noisy circle within the stated band at the stated rate, and integration of
//! a clean accelerometer at the quadrature's order.

#![allow(clippy::needless_range_loop)]
mod common;
use common::Rng;
use pdyn_data::csv::Series;
use pdyn_data::integrate::{cumulative, integrate, AccelOptions, Bias, Rule};
use pdyn_data::interp::{Interpolant, Kind};
use pdyn_data::kinematics::kinematics;
use pdyn_data::spline::{fit, Smoothing};

fn max_err(kind: Kind, n: usize) -> f64 {
    let t: Vec<f64> = (0..n).map(|i| 3.0 * i as f64 / (n - 1) as f64).collect();
    let y: Vec<f64> = t.iter().map(|x| libm::sin(*x)).collect();
    let f = Interpolant::new(kind, &t, &y, "y").unwrap();
    // Interior points only: the natural end condition is first order wrong at the ends.
    (0..400)
        .map(|k| 1.0 + 1.0 * k as f64 / 399.0)
        .map(|x| (f.eval(x).unwrap() - libm::sin(x)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn interpolation_orders_and_range() {
    // sin on [0, 3] has its maximum inside the tested range, where PCHIP sets the slope to
    // zero (monotonicity) and drops to second order; third order away from extrema.
    for (kind, order, tol) in [
        (Kind::Linear, 2.0, 0.2),
        (Kind::Cubic, 4.0, 0.4),
        (Kind::Pchip, 2.0, 0.4),
    ] {
        let (e1, e2) = (max_err(kind, 41), max_err(kind, 81));
        let p = libm::log2(e1 / e2);
        assert!((p - order).abs() < tol, "{kind:?}: order {p} ({e1}, {e2})");
    }
    let f = Interpolant::new(
        Kind::Pchip,
        &[0.0, 1.0, 2.0, 3.0],
        &[0.0, 0.0, 1.0, 1.0],
        "y",
    )
    .unwrap();
    // Monotone data: no overshoot.
    for k in 0..=300 {
        let v = f.eval(3.0 * k as f64 / 300.0).unwrap();
        assert!((0.0..=1.0).contains(&v), "{v}");
    }
    let e = f.eval(3.5).unwrap_err();
    assert!(
        e.message.contains("outside the data's time range [0, 3]"),
        "{e}"
    );
}

/// The smoothing spline's fitted values solve `(I + λ Q R⁻¹ Qᵀ) f = y` (Green & Silverman's
/// penalty matrix K = Q R⁻¹ Qᵀ), and tr A = tr (I + λK)⁻¹: both checked by dense Gauss–Jordan
/// elimination on an uneven grid.
#[test]
fn smoothing_spline_matches_a_dense_solve() {
    let n = 12;
    let mut rng = Rng::new(3);
    let mut t = vec![0.0];
    for _ in 1..n {
        t.push(t[t.len() - 1] + 0.5 + rng.uniform());
    }
    let y: Vec<f64> = t
        .iter()
        .map(|x| libm::sin(0.7 * x) + 0.1 * rng.normal())
        .collect();
    let lam = 0.37;
    let s = fit(&t, &y, Smoothing::Lambda(lam), "y").unwrap();
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let m = n - 2;
    let mut q = vec![vec![0.0; m]; n];
    let mut r = vec![vec![0.0; m]; m];
    for j in 0..m {
        q[j][j] = 1.0 / h[j];
        q[j + 1][j] = -1.0 / h[j] - 1.0 / h[j + 1];
        q[j + 2][j] = 1.0 / h[j + 1];
        r[j][j] = (h[j] + h[j + 1]) / 3.0;
        if j + 1 < m {
            r[j][j + 1] = h[j + 1] / 6.0;
            r[j + 1][j] = h[j + 1] / 6.0;
        }
    }
    let rinv = inverse(&r);
    // K = Q R⁻¹ Qᵀ; B = I + λK.
    let mut b = vec![vec![0.0; n]; n];
    for i in 0..n {
        for k in 0..n {
            let mut v = 0.0;
            for a in 0..m {
                for c in 0..m {
                    v += q[i][a] * rinv[a][c] * q[k][c];
                }
            }
            b[i][k] = lam * v + if i == k { 1.0 } else { 0.0 };
        }
    }
    let a = inverse(&b);
    for i in 0..n {
        let f: f64 = (0..n).map(|k| a[i][k] * y[k]).sum();
        assert!((f - s.value[i]).abs() < 1e-10, "{i}: {f} vs {}", s.value[i]);
    }
    let tr: f64 = (0..n).map(|i| a[i][i]).sum();
    assert!((tr - s.edf).abs() < 1e-10, "{tr} vs {}", s.edf);
}

fn inverse(a: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = a.len();
    let mut g: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let mut r = a[i].clone();
            r.extend((0..n).map(|k| if k == i { 1.0 } else { 0.0 }));
            r
        })
        .collect();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| g[x][c].abs().total_cmp(&g[y][c].abs()))
            .unwrap();
        g.swap(c, p);
        let d = g[c][c];
        for v in g[c].iter_mut() {
            *v /= d;
        }
        for r in 0..n {
            if r != c {
                let f = g[r][c];
                let row = g[c].clone();
                for (v, w) in g[r].iter_mut().zip(row) {
                    *v -= f * w;
                }
            }
        }
    }
    g.into_iter().map(|r| r[n..].to_vec()).collect()
}

/// The equivalent-kernel standard errors against the spread of 300 fits of pure noise.
#[test]
fn standard_errors_match_monte_carlo() {
    let n = 801;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
    let lam = 1e-5;
    let mut rng = Rng::new(11);
    let runs = 300;
    let mut sums = [0.0; 3];
    let mut se = [0.0; 3];
    for _ in 0..runs {
        let y: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let s = fit(&t, &y, Smoothing::Lambda(lam), "y").unwrap();
        let mid = n / 2;
        sums[0] += s.value[mid].powi(2);
        sums[1] += s.d1[mid].powi(2);
        sums[2] += s.d2[mid].powi(2);
        // The formula with the true σ = 1.
        se = pdyn_data::spline::standard_errors(1.0, lam, 0.01);
    }
    for k in 0..3 {
        let mc = (sums[k] / runs as f64).sqrt();
        // 300 runs: the sample standard deviation is within ±10 % with ~99 % probability.
        assert!(
            (mc / se[k] - 1.0).abs() < 0.1,
            "k = {k}: Monte Carlo {mc}, formula {}",
            se[k]
        );
    }
}

struct Circle {
    t: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
}

const R: f64 = 5.0;
const W: f64 = 0.8;

/// A circle of radius R at angular speed W, sampled at 20 Hz for 20 s, with noise σ.
fn circle(sigma: f64, seed: u64) -> Circle {
    let mut rng = Rng::new(seed);
    let t: Vec<f64> = (0..=400).map(|i| i as f64 * 0.05).collect();
    let x = t
        .iter()
        .map(|s| R * libm::cos(W * s) + sigma * rng.normal())
        .collect();
    let y = t
        .iter()
        .map(|s| R * libm::sin(W * s) + sigma * rng.normal())
        .collect();
    Circle { t, x, y }
}

fn kin_of(c: Circle) -> pdyn_data::kinematics::KinData {
    let s = Series::from_arrays(
        c.t,
        vec!["x".into(), "y".into()],
        vec![c.x, c.y],
        5,
        "kinematics",
    )
    .unwrap();
    kinematics(&s, Smoothing::Gcv).unwrap()
}

/// Speed R W and a_n = R W² recovered within the stated 2-standard-error band at ≥ 90 % of the
/// interior samples, over several seeds; the noise estimate matches σ.
#[test]
fn noisy_circle_within_the_stated_band() {
    let sigma = 0.02;
    for seed in 1..=5 {
        let k = kin_of(circle(sigma, seed));
        let interior: Vec<usize> = (0..k.t.len())
            .filter(|&i| k.t[i] > k.boundary && k.t[i] < k.t[k.t.len() - 1] - k.boundary)
            .collect();
        assert!(
            interior.len() > 200,
            "boundary {} leaves too few samples",
            k.boundary
        );
        let within = |est: &[f64], se: &[f64], truth: f64| {
            interior
                .iter()
                .filter(|&&i| (est[i] - truth).abs() <= 2.0 * se[i])
                .count() as f64
                / interior.len() as f64
        };
        let speed_cov = within(&k.speed, &k.se_speed, R * W);
        let an_cov = within(&k.a_n, &k.se_a_n, R * W * W);
        assert!(
            speed_cov >= 0.9,
            "seed {seed}: speed within 2 se at {speed_cov}"
        );
        assert!(an_cov >= 0.9, "seed {seed}: a_n within 2 se at {an_cov}");
        for f in &k.fits {
            assert!(
                (f.sigma / sigma - 1.0).abs() < 0.15,
                "noise estimate {} vs {sigma}",
                f.sigma
            );
            assert!(f.from_gcv);
        }
        // The curvature is 1/R and the polar components of uniform circular motion.
        let i = interior[interior.len() / 2];
        assert!((k.curvature[i] - 1.0 / R).abs() < 3.0 * k.se_curvature[i] + 1e-9);
        let se_v = k.fits.iter().map(|f| f.se[1]).fold(0.0, f64::max);
        let se_a = k.fits.iter().map(|f| f.se[2]).fold(0.0, f64::max);
        assert!((k.v_theta[i] - R * W).abs() < 4.0 * se_v && k.v_r[i].abs() < 4.0 * se_v);
        assert!(
            (k.a_r[i] + R * W * W).abs() < 4.0 * se_a && k.a_theta[i].abs() < 4.0 * se_a,
            "a_r {}",
            k.a_r[i]
        );
    }
}

/// The band is the error: over 8 seeds, the RMS error of each velocity and acceleration
/// component in the interior is its stated standard error within 25 %. And the stated rate:
/// with λ from GCV the velocity error scales as σ^(2/3) and the acceleration error as
/// σ^(4/9) (GCV balances the squared bias ∝ ω_c⁻⁸ of the fit against its variance
/// ∝ σ² ω_c; the derivatives' variances ∝ σ² ω_c³, σ² ω_c⁵ then dominate): ten times less
/// noise gives 4.6 times smaller velocity errors and 2.8 times smaller acceleration errors,
/// within 20 %. The path `x = V t + (A/2) sin(ωt), y = A sin(ωt)`, ω = 4π/T, has zero acceleration at both
/// ends, where the natural spline's end condition would otherwise bias GCV's choice.
#[test]
fn errors_match_the_band_and_shrink_at_the_stated_rate() {
    let (v, amp) = (1.5, 2.0);
    let w = 4.0 * std::f64::consts::PI / 20.0;
    let rms = |sigma: f64| {
        let (mut ev, mut ea, mut sv, mut sa, mut count) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for seed in 20..28 {
            let mut rng = Rng::new(seed);
            let t: Vec<f64> = (0..=400).map(|i| i as f64 * 0.05).collect();
            let x = t
                .iter()
                .map(|s| v * s + 0.5 * amp * libm::sin(w * s) + sigma * rng.normal())
                .collect();
            let y = t
                .iter()
                .map(|s| amp * libm::sin(w * s) + sigma * rng.normal())
                .collect();
            let s =
                Series::from_arrays(t, vec!["x".into(), "y".into()], vec![x, y], 5, "k").unwrap();
            let k = kinematics(&s, Smoothing::Gcv).unwrap();
            for i in 0..k.t.len() {
                if k.t[i] > k.boundary && k.t[i] < k.t[k.t.len() - 1] - k.boundary {
                    let s = k.t[i];
                    ev += (k.velocity[1][i] - amp * w * libm::cos(w * s)).powi(2);
                    ea += (k.acceleration[1][i] + amp * w * w * libm::sin(w * s)).powi(2);
                    sv += k.fits[1].se[1].powi(2);
                    sa += k.fits[1].se[2].powi(2);
                    count += 1.0;
                }
            }
        }
        let r = |x: f64| (x / count).sqrt();
        (r(ev), r(ea), r(sv), r(sa))
    };
    let (v1, a1, sv1, sa1) = rms(0.005);
    let (v2, a2, sv2, sa2) = rms(0.0005);
    for (e, s) in [(v1, sv1), (a1, sa1), (v2, sv2), (a2, sa2)] {
        assert!((e / s - 1.0).abs() < 0.25, "RMS error {e}, stated {s}");
    }
    let (rv, ra) = (v1 / v2, a1 / a2);
    let (ev, ea) = (libm::pow(10f64, 2.0 / 3.0), libm::pow(10f64, 4.0 / 9.0));
    assert!(
        (rv / ev - 1.0).abs() < 0.2,
        "velocity error ratio {rv}, expected {ev}"
    );
    assert!(
        (ra / ea - 1.0).abs() < 0.2,
        "acceleration error ratio {ra}, expected {ea}"
    );
}

/// A clean accelerometer record a = −ω² A cos ωt (x = A cos ωt) integrated from the true v0 and
/// x0: the largest error of v and x over the record shrinks by 2^p when the step halves, p = 2 (trapezoid) and 4
/// (simpson), on uneven samples too.
#[test]
fn clean_integration_converges_at_the_rule_order() {
    let (amp, w, tend) = (2.0, 1.3, 6.0);
    let err = |n: usize, rule: Rule, uneven: bool| {
        let t: Vec<f64> = (0..=n)
            .map(|i| {
                let u = i as f64 / n as f64;
                tend * if uneven {
                    u + 0.03 * libm::sin(std::f64::consts::TAU * u)
                } else {
                    u
                }
            })
            .collect();
        let a: Vec<f64> = t.iter().map(|s| -w * w * amp * libm::cos(w * s)).collect();
        let r = integrate(
            &t,
            &a,
            &AccelOptions {
                v0: 0.0,
                x0: amp,
                rule,
                bias: Bias::None,
                sigma_a: Some(0.0),
            },
            "a",
        )
        .unwrap();
        // The largest error over the record (the error at one instant may pass through 0).
        (0..=n)
            .map(|i| {
                let ex = (r.x[i] - amp * libm::cos(w * t[i])).abs();
                let ev = (r.v[i] + amp * w * libm::sin(w * t[i])).abs();
                ex.max(ev)
            })
            .fold(0.0, f64::max)
    };
    for (rule, order) in [(Rule::Trapezoid, 2.0), (Rule::Simpson, 4.0)] {
        for uneven in [false, true] {
            let (e1, e2) = (err(200, rule, uneven), err(400, rule, uneven));
            let p = libm::log2(e1 / e2);
            assert!(
                (p - order).abs() < 0.2,
                "{rule:?} uneven={uneven}: order {p} ({e1} → {e2})"
            );
        }
    }
    // Uniform weights (−1, 13, 13, −1)/24 in the interior.
    let t: Vec<f64> = (0..6).map(|i| i as f64).collect();
    let y = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let c = cumulative(&t, &y, 0.0, Rule::Simpson);
    assert!((c[2] - c[1] - 13.0 / 24.0).abs() < 1e-14 && (c[4] - c[3] + 1.0 / 24.0).abs() < 1e-14);
}

/// Bias removal and the stated growth of the position error: over many seeded records of a
/// sensor at rest with noise σ_a and a constant bias, the spread of the final position and
/// velocity matches the stated σ_x, σ_v within 10 % (400 runs: ±7 % at 2 standard errors).
#[test]
fn error_growth_matches_the_statement() {
    let (fs, tend, sa, bias) = (100.0, 20.0, 0.05, 0.03);
    let n = (fs * tend) as usize;
    let t: Vec<f64> = (0..=n).map(|i| i as f64 / fs).collect();
    let mut rng = Rng::new(5);
    let runs = 400;
    for bias_rule in [Bias::Quiet(0.0, 2.0), Bias::Mean] {
        let (mut sq, mut sqv, mut stated, mut stated_v) = (0.0, 0.0, 0.0, 0.0);
        let mid = n / 2;
        for _ in 0..runs {
            let a: Vec<f64> = (0..=n).map(|_| bias + sa * rng.normal()).collect();
            let r = integrate(
                &t,
                &a,
                &AccelOptions {
                    v0: 0.0,
                    x0: 0.0,
                    rule: Rule::Trapezoid,
                    bias: bias_rule,
                    sigma_a: Some(sa),
                },
                "a",
            )
            .unwrap();
            sq += r.x[n] * r.x[n];
            sqv += r.v[mid] * r.v[mid];
            stated = r.sigma_x[n];
            stated_v = r.sigma_v[mid];
            assert!((r.bias - bias).abs() < 5.0 * r.bias_se);
        }
        let spread = (sq / runs as f64).sqrt();
        let spread_v = (sqv / runs as f64).sqrt();
        assert!(
            (spread / stated - 1.0).abs() < 0.1,
            "{bias_rule:?}: spread {spread}, stated {stated}"
        );
        assert!(
            (spread_v / stated_v - 1.0).abs() < 0.1,
            "{bias_rule:?}: v spread {spread_v}, stated {stated_v}"
        );
    }
    // σ_a from the quiet interval.
    let a: Vec<f64> = (0..=n).map(|_| bias + sa * rng.normal()).collect();
    let quiet = AccelOptions {
        rule: Rule::Trapezoid,
        bias: Bias::Quiet(0.0, 2.0),
        ..AccelOptions::default()
    };
    let r = integrate(&t, &a, &quiet, "a").unwrap();
    assert_eq!(r.sigma_a_source, "quiet interval");
    assert!((r.sigma_a / sa - 1.0).abs() < 0.15);
    let r = integrate(
        &t,
        &a,
        &AccelOptions {
            v0: 0.0,
            x0: 0.0,
            rule: Rule::Trapezoid,
            bias: Bias::None,
            sigma_a: None,
        },
        "a",
    )
    .unwrap();
    assert_eq!(r.sigma_a_source, "second differences");
    assert!((r.sigma_a / sa - 1.0).abs() < 0.1);
}

/// Three coordinates: the helix x = R cos ωt, y = R sin ωt, z = c t has speed √(R²ω² + c²),
/// a_n = R ω², curvature R ω²/(R²ω² + c²), a_t = 0, and its normal points to the axis.
#[test]
fn helix_in_three_dimensions() {
    let (r, w, c, sigma) = (3.0, 0.9, 0.5, 0.005);
    let mut rng = Rng::new(77);
    let t: Vec<f64> = (0..=600).map(|i| i as f64 * 0.05).collect();
    let x = t
        .iter()
        .map(|s| r * libm::cos(w * s) + sigma * rng.normal())
        .collect();
    let y = t
        .iter()
        .map(|s| r * libm::sin(w * s) + sigma * rng.normal())
        .collect();
    let z = t.iter().map(|s| c * s + sigma * rng.normal()).collect();
    let names = vec!["x".into(), "y".into(), "z".into()];
    let s = Series::from_arrays(t, names, vec![x, y, z], 5, "k").unwrap();
    let k = kinematics(&s, Smoothing::Gcv).unwrap();
    let speed = (r * r * w * w + c * c).sqrt();
    let kappa = r * w * w / (speed * speed);
    // z is a straight line: GCV smooths it as one (λ huge, boundary over the whole record);
    // the interior is that of the curved coordinates.
    assert!(k.fits[2].boundary > 30.0, "{}", k.fits[2].boundary);
    let b = k.fits[0].boundary.max(k.fits[1].boundary);
    let interior: Vec<usize> = (0..k.t.len())
        .filter(|&i| k.t[i] > b && k.t[i] < k.t[k.t.len() - 1] - b)
        .collect();
    assert!(interior.len() > 300);
    let cover = |est: &[f64], se: &[f64], truth: f64| {
        interior
            .iter()
            .filter(|&&i| (est[i] - truth).abs() <= 2.0 * se[i])
            .count() as f64
            / interior.len() as f64
    };
    assert!(cover(&k.speed, &k.se_speed, speed) >= 0.9);
    assert!(cover(&k.a_n, &k.se_a_n, r * w * w) >= 0.9);
    assert!(cover(&k.a_t, &k.se_a_t, 0.0) >= 0.9);
    assert!(cover(&k.curvature, &k.se_curvature, kappa) >= 0.9);
    let i = interior[interior.len() / 2];
    let toward_axis = [-libm::cos(w * k.t[i]), -libm::sin(w * k.t[i]), 0.0];
    let dot: f64 = (0..3).map(|c| k.normal[c][i] * toward_axis[c]).sum();
    assert!(dot > 0.99, "normal · (toward the axis) = {dot}");
}
