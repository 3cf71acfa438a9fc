//! Sensor fusion with known truth: a body moving as `p = A sin ωt + V t` on two axes, an
//! accelerometer at 100 Hz (noise σ_a, a constant bias drawn from the prior), position fixes
//! at 1 Hz (noise σ_p). The smoother must beat both sensors alone, its covariance must be
//! consistent (NEES in the chi-square band over many seeded runs), and the noise levels must
//! be recoverable from the data.
#![allow(clippy::needless_range_loop)]

mod common;
use common::{chi2_quantile, Rng};
use pdyn_data::fusion::{fuse, Fused, Noise};
use pdyn_data::integrate::{integrate, AccelOptions, Bias, Rule};

const SA: f64 = 0.05;
const SP: f64 = 1.0;
const B0: f64 = 0.1;
const TEND: f64 = 60.0;

struct Run {
    ta: Vec<f64>,
    a: Vec<Vec<f64>>,
    tf: Vec<f64>,
    z: Vec<Vec<f64>>,
    /// Truth at the accelerometer times: per axis (p, v), and the bias.
    p: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
    b: Vec<f64>,
}

fn truth(axis: usize, t: f64) -> (f64, f64, f64) {
    let (amp, w, vel) = if axis == 0 {
        (3.0, 0.4, 1.0)
    } else {
        (2.0, 0.7, -0.5)
    };
    (
        amp * libm::sin(w * t) + vel * t,
        amp * w * libm::cos(w * t) + vel,
        -amp * w * w * libm::sin(w * t),
    )
}

fn simulate(seed: u64) -> Run {
    let mut rng = Rng::new(seed);
    let ta: Vec<f64> = (0..=(TEND * 100.0) as usize)
        .map(|i| i as f64 * 0.01)
        .collect();
    // Fixes at 1 Hz, offset from the accelerometer's clock by 3 ms (they fall between samples).
    let tf: Vec<f64> = (0..TEND as usize).map(|i| i as f64 + 0.003).collect();
    let b: Vec<f64> = (0..2).map(|_| B0 * rng.normal()).collect();
    let mut run = Run {
        ta: ta.clone(),
        a: vec![],
        tf: tf.clone(),
        z: vec![],
        p: vec![],
        v: vec![],
        b: b.clone(),
    };
    for axis in 0..2 {
        run.a.push(
            ta.iter()
                .map(|&t| truth(axis, t).2 + b[axis] + SA * rng.normal())
                .collect(),
        );
        run.z.push(
            tf.iter()
                .map(|&t| truth(axis, t).0 + SP * rng.normal())
                .collect(),
        );
        run.p.push(ta.iter().map(|&t| truth(axis, t).0).collect());
        run.v.push(ta.iter().map(|&t| truth(axis, t).1).collect());
    }
    run
}

fn given() -> Noise {
    Noise {
        sigma_a: Some(SA),
        sigma_p: Some(SP),
        bias0: B0,
        ..Noise::default()
    }
}

fn run_fusion(r: &Run, noise: &Noise) -> Fused {
    fuse(&r.ta, &r.a, &r.tf, &r.z, noise, true).unwrap()
}

fn rms(xs: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0.0);
    for x in xs {
        s += x * x;
        n += 1.0;
    }
    (s / n).sqrt()
}

/// RMS position error vs truth: the smoother, the fixes alone (linear interpolation between
/// them, at the accelerometer times inside the fixes' range), the accelerometer alone
/// (integrated from the true initial position and velocity, its mean removed).
#[test]
fn smoother_beats_both_sensors_alone() {
    let r = simulate(1);
    let f = run_fusion(&r, &given());
    for axis in 0..2 {
        let smoothed = rms((0..r.ta.len()).map(|k| f.axes[axis].p[k] - r.p[axis][k]));
        let inside: Vec<usize> = (0..r.ta.len())
            .filter(|&k| r.ta[k] >= r.tf[0] && r.ta[k] <= r.tf[r.tf.len() - 1])
            .collect();
        let fixes_only = rms(inside.iter().map(|&k| {
            let t = r.ta[k];
            let j = r.tf.partition_point(|&s| s <= t).clamp(1, r.tf.len() - 1) - 1;
            let u = (t - r.tf[j]) / (r.tf[j + 1] - r.tf[j]);
            r.z[axis][j] * (1.0 - u) + r.z[axis][j + 1] * u - r.p[axis][k]
        }));
        let o = AccelOptions {
            v0: r.v[axis][0],
            x0: r.p[axis][0],
            rule: Rule::Trapezoid,
            bias: Bias::Mean,
            sigma_a: Some(SA),
        };
        let acc = integrate(&r.ta, &r.a[axis], &o, "a").unwrap();
        let accel_only = rms((0..r.ta.len()).map(|k| acc.x[k] - r.p[axis][k]));
        let filtered = rms((0..r.ta.len()).map(|k| f.axes[axis].p_filtered[k] - r.p[axis][k]));
        println!("axis {axis}: smoothed {smoothed}, filtered {filtered}, fixes {fixes_only}, accelerometer {accel_only}");
        assert!(
            smoothed < 0.5 * fixes_only,
            "smoothed {smoothed} vs fixes {fixes_only}"
        );
        assert!(
            smoothed < 0.5 * accel_only,
            "smoothed {smoothed} vs accelerometer {accel_only}"
        );
        assert!(
            smoothed < filtered,
            "the smoother ({smoothed}) must beat the filter ({filtered})"
        );
        // The bias is found.
        let b = f.axes[axis].b[r.ta.len() / 2];
        assert!(
            (b - r.b[axis]).abs() < 4.0 * f.axes[axis].sd[2][r.ta.len() / 2],
            "bias {b} vs {}",
            r.b[axis]
        );
    }
}

/// NEES (e P⁻¹ e over the 3 states) averaged over 100 seeded runs at 12 instants: M times the
/// average is χ²(3M) for a consistent estimator, so each average lies in the two-sided 95 %
/// band with probability 0.95; at least 10 of the 12 instants must, and the average over all
/// instants must lie within the band too. The same for the scalar NEES of position alone.
#[test]
fn smoother_covariance_is_consistent() {
    let runs = 100;
    let checks: Vec<usize> = (0..12).map(|i| 250 + 500 * i).collect();
    let mut nees = vec![0.0; checks.len()];
    let mut nees_p = vec![0.0; checks.len()];
    for seed in 0..runs {
        let r = simulate(1000 + seed);
        let f = run_fusion(&r, &given());
        let axis = (seed % 2) as usize;
        let e = &f.axes[axis];
        for (c, &k) in checks.iter().enumerate() {
            let err = [
                e.p[k] - r.p[axis][k],
                e.v[k] - r.v[axis][k],
                e.b[k] - r.b[axis],
            ];
            let p = e.cov[k];
            let m = [[p[0], p[1], p[2]], [p[3], p[4], p[5]], [p[6], p[7], p[8]]];
            nees[c] += quad_inv(&m, &err);
            nees_p[c] += err[0] * err[0] / p[0];
        }
    }
    let m = runs as f64;
    let band = |dof: f64| {
        (
            chi2_quantile(dof * m, -1.959964) / m,
            chi2_quantile(dof * m, 1.959964) / m,
        )
    };
    for (values, dof) in [(&nees, 3.0), (&nees_p, 1.0)] {
        let (lo, hi) = band(dof);
        let avgs: Vec<f64> = values.iter().map(|s| s / m).collect();
        let inside = avgs.iter().filter(|&&x| x >= lo && x <= hi).count();
        println!("dof {dof}: band [{lo:.3}, {hi:.3}], averages {avgs:.3?}");
        assert!(
            inside >= 10,
            "{inside} of 12 averages in [{lo}, {hi}]: {avgs:?}"
        );
        let all = avgs.iter().sum::<f64>() / avgs.len() as f64;
        assert!(
            all >= lo && all <= hi,
            "overall NEES {all} outside [{lo}, {hi}]"
        );
    }
}

/// xᵀ M⁻¹ x by solving with Cholesky.
fn quad_inv(m: &[[f64; 3]; 3], x: &[f64; 3]) -> f64 {
    let mut l = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            if i == j {
                l[i][i] = (m[i][i] - s).sqrt();
            } else {
                l[i][j] = (m[i][j] - s) / l[j][j];
            }
        }
    }
    let mut y = [0.0; 3];
    for i in 0..3 {
        let s: f64 = (0..i).map(|k| l[i][k] * y[k]).sum();
        y[i] = (x[i] - s) / l[i][i];
    }
    y.iter().map(|v| v * v).sum()
}

/// σ_a and σ_p estimated by maximum likelihood of the innovations are within 25 % of the
/// truth, and the smoother with them is as good as with the true values (within 20 %).
#[test]
fn noise_levels_are_estimated() {
    let r = simulate(7);
    let f = run_fusion(
        &r,
        &Noise {
            bias0: B0,
            ..Noise::default()
        },
    );
    assert_eq!(f.estimated, [true, true]);
    println!("estimated σ_a = {}, σ_p = {}", f.sigma_a, f.sigma_p);
    assert!((f.sigma_a / SA - 1.0).abs() < 0.25, "σ_a {}", f.sigma_a);
    assert!((f.sigma_p / SP - 1.0).abs() < 0.25, "σ_p {}", f.sigma_p);
    let g = run_fusion(&r, &given());
    for axis in 0..2 {
        let e1 = rms((0..r.ta.len()).map(|k| f.axes[axis].p[k] - r.p[axis][k]));
        let e2 = rms((0..r.ta.len()).map(|k| g.axes[axis].p[k] - r.p[axis][k]));
        assert!(e1 < 1.2 * e2, "estimated noise: {e1}, given: {e2}");
    }
    // A given level is held.
    let h = run_fusion(
        &r,
        &Noise {
            sigma_p: Some(2.0),
            bias0: B0,
            ..Noise::default()
        },
    );
    assert_eq!((h.sigma_p, h.estimated), (2.0, [true, false]));
}

#[test]
fn bad_inputs_are_errors() {
    let r = simulate(3);
    let mut tf = r.tf.clone();
    tf[5] = 100.0;
    let e = fuse(&r.ta, &r.a, &tf, &r.z, &given(), false).unwrap_err();
    assert!(e.message.contains("fix 6 at time 100 is outside"), "{e}");
    let e = fuse(&r.ta, &r.a, &r.tf, &r.z[..1], &given(), false).unwrap_err();
    assert!(e.message.contains("must match"), "{e}");
    let e = fuse(
        &r.ta,
        &r.a,
        &r.tf,
        &r.z,
        &Noise {
            sigma_p: Some(0.0),
            ..given()
        },
        false,
    )
    .unwrap_err();
    assert!(e.message.contains("σ_p = 0"), "{e}");
}
