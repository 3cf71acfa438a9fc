//! `pdyn optimize` (issue 26, item 5): the launch angle of the longest range.
//! Truths: without drag the range v0² sin(2θ)/g is longest at θ = π/4 exactly; with drag,
//! an independent estimate from the library's runs: the range sampled at 401 angles within
//! ±1e-3 rad of the optimum, a least-squares cubic through them, and its stationary point
//! (no Brent, no slope differences). Both to 1e-8 rad.

use pdyn::optimize::{self, Goal};
use pdyn::sim::{self, RunSettings};

fn model() -> pdyn_mech::Model {
    let path = format!(
        "{}/../../examples/data/launch_angle.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let src = std::fs::read_to_string(&path).unwrap();
    pdyn_mech::load(&src, &path).unwrap_or_else(|e| panic!("{}", e.render(&src)))
}

fn prepared(
    drag: f64,
) -> (
    sim::Prepared,
    RunSettings,
    Goal,
    Vec<pdyn_mech::model::spec::Stat>,
) {
    let mut m = model();
    pdyn::params::set_parameter_values(&mut m, &[("c".to_string(), drag)], "--set").unwrap();
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let prep = sim::prepare(&mut m).unwrap();
    let over = [("theta".to_string(), 0.0, std::f64::consts::FRAC_PI_2)];
    let goal = optimize::goal_of(&m, "range", true, &over, "--maximize").unwrap();
    (prep, set, goal, optimize::stats_of(&m))
}

#[test]
fn without_drag_the_best_angle_is_a_quarter_turn() {
    let (prep, set, goal, stats) = prepared(0.0);
    let best = optimize::optimize(&prep, &set, &stats, &goal).unwrap();
    let err = (best.x[0] - std::f64::consts::FRAC_PI_4).abs();
    eprintln!(
        "theta {}, error {err:e}, {} runs",
        best.x[0], best.evaluations
    );
    assert!(err < 1e-8, "theta = {}, error {err}", best.x[0]);
    // The range there is v0²/g.
    assert!((best.value - 400.0 / 9.81).abs() < 1e-9, "{}", best.value);
    assert!(!best.at_bound);
}

#[test]
fn with_drag_the_best_angle_agrees_with_a_cubic_fit_of_sampled_ranges() {
    let (prep, set, goal, stats) = prepared(0.05);
    let best = optimize::optimize(&prep, &set, &stats, &goal).unwrap();
    let theta = best.x[0];
    // Drag lowers the best angle below 45°.
    assert!(theta < 0.7 && theta > 0.6, "{theta}");
    // The independent estimate, centred on a coarse sweep's best (not on the optimiser's).
    let k = prep
        .parameter_names
        .iter()
        .position(|n| n == "theta")
        .unwrap();
    let range = |th: f64| {
        let p = prep.with_parameters(&[(k, th)]);
        sim::measured::measure(&p, &set, &stats).unwrap().measures[0]
    };
    let coarse = (0..=1000)
        .map(|i| 0.6 + 0.1 * i as f64 / 1000.0)
        .max_by(|&a, &b| range(a).total_cmp(&range(b)))
        .unwrap();
    let w = 1e-3;
    let n = 401;
    // Least squares for r(u) = a + b u + c u² + d u³, u = (θ − coarse)/w.
    let mut ata = [[0.0f64; 4]; 4];
    let mut atb = [0.0f64; 4];
    for i in 0..n {
        let u = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
        let r = range(coarse + w * u);
        let row = [1.0, u, u * u, u * u * u];
        for p in 0..4 {
            for q in 0..4 {
                ata[p][q] += row[p] * row[q];
            }
            atb[p] += row[p] * r;
        }
    }
    let coef = solve4(ata, atb);
    // r'(u) = b + 2c u + 3d u² = 0, the root near 0.
    let (b, c, d) = (coef[1], coef[2], coef[3]);
    let disc = (c * c - 3.0 * d * b).sqrt();
    let u = if c < 0.0 {
        (-c - disc) / (3.0 * d)
    } else {
        (-c + disc) / (3.0 * d)
    };
    let u = if (3.0 * d).abs() < 1e-300 || !u.is_finite() {
        -b / (2.0 * c)
    } else {
        u
    };
    let reference = coarse + w * u;
    let err = (theta - reference).abs();
    eprintln!("optimizer {theta}, reference {reference}, difference {err:e}");
    assert!(
        err < 1e-8,
        "optimizer {theta}, reference {reference}, difference {err}"
    );
}

#[allow(clippy::needless_range_loop)] // elimination reads best with indices
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(p, c);
        b.swap(p, c);
        for i in c + 1..4 {
            let m = a[i][c] / a[c][c];
            for j in c..4 {
                a[i][j] -= m * a[c][j];
            }
            b[i] -= m * b[c];
        }
    }
    let mut x = [0.0; 4];
    for c in (0..4).rev() {
        let mut s = b[c];
        for j in c + 1..4 {
            s -= a[c][j] * x[j];
        }
        x[c] = s / a[c][c];
    }
    x
}

#[test]
fn two_parameters_by_nelder_mead_reach_the_bound_of_speed() {
    // Range grows with v0: the optimum is at v0's upper bound, theta interior.
    let mut m = model();
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let prep = sim::prepare(&mut m).unwrap();
    let over = [
        ("theta".to_string(), 0.0, std::f64::consts::FRAC_PI_2),
        ("v0".to_string(), 10.0, 20.0),
    ];
    let goal = optimize::goal_of(&m, "range", true, &over, "--maximize").unwrap();
    let best = optimize::optimize(&prep, &set, &optimize::stats_of(&m), &goal).unwrap();
    assert_eq!(best.method, "nelder-mead");
    assert!(best.at_bound);
    assert_eq!(best.x[1], 20.0);
    assert!((best.x[0] - 0.675_668).abs() < 1e-4, "{:?}", best.x);
}

#[test]
fn unknown_measures_and_parameters_are_refused() {
    let m = model();
    let over = [("theta".to_string(), 0.0, 1.0)];
    let e = optimize::goal_of(&m, "rang", true, &over, "--maximize").unwrap_err();
    assert!(e.to_string().contains("its measures: range"), "{e}");
    let bad = [("phi".to_string(), 0.0, 1.0)];
    let e = optimize::goal_of(&m, "range", true, &bad, "--maximize").unwrap_err();
    assert!(e.to_string().contains("`phi` is not a parameter"), "{e}");
}
