//! `pdyn::fit` against known truth: data generated from closed forms with seeded noise.

use pdyn::fit::{self, experiment, FitRequest};

/// SplitMix64 and Box–Muller: seeded normal noise without a dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.next().max(1e-300), self.next());
        (-2.0 * libm::log(u)).sqrt() * libm::cos(2.0 * std::f64::consts::PI * v)
    }
}

/// A body slowed by linear drag: m x'' = −c x', so x(t) = x0 + v0 (m/c)(1 − e^{−ct/m}).
const LINEAR_DRAG: &str = r#"
name = "linear drag"
[parameters]
c = 0.3
m = 2.0
[coordinates]
x = { initial = 0.0, rate = 5.0 }
[particles.body]
mass = "m"
position = "[x, 0, 0]"
[[forces]]
kind = "linear_drag"
on = "body"
c = "c"
"#;

fn csv(t: &[f64], cols: &[(&str, Vec<f64>)]) -> String {
    let mut s = String::from("t");
    for (n, _) in cols {
        s += &format!(",{n}");
    }
    s.push('\n');
    for (i, ti) in t.iter().enumerate() {
        s += &format!("{ti:e}");
        for (_, v) in cols {
            s += &format!(",{:e}", v[i]);
        }
        s.push('\n');
    }
    s
}

fn drag_data(seed: u64, sigma: f64, (c, m, x0, v0): (f64, f64, f64, f64)) -> String {
    let mut rng = Rng(seed);
    let t: Vec<f64> = (0..40).map(|i| 0.1 * f64::from(i)).collect();
    let x: Vec<f64> = t
        .iter()
        .map(|&t| x0 + v0 * m / c * (1.0 - libm::exp(-c * t / m)) + sigma * rng.normal())
        .collect();
    csv(&t, &[("x", x)])
}

fn fit_text(model: &str, data: &[&str], req: &FitRequest) -> Result<fit::FitResult, pdyn::Error> {
    let mut model = pdyn_mech::load(model, "model.toml").unwrap();
    let names = experiment::state_names(&model);
    let exps = data
        .iter()
        .enumerate()
        .map(|(i, d)| experiment::from_csv(&format!("run{}.csv", i + 1), d, &names))
        .collect::<Result<Vec<_>, _>>()?;
    fit::fit(&mut model, &exps, req)
}

fn free(names: &[&str]) -> FitRequest {
    FitRequest {
        free: names.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    }
}

#[test]
fn noiseless_linear_drag_is_recovered_exactly() {
    let truth = (0.45, 2.0, 0.1, 4.0);
    let data = drag_data(1, 0.0, truth);
    let res = fit_text(LINEAR_DRAG, &[&data], &free(&["c", "initial.x", "rate.x"])).unwrap();
    assert!(res.status.converged(), "{:?}", res.status);
    let x: Vec<f64> = res.estimates.iter().map(|e| e.value).collect();
    assert!((x[0] - 0.45).abs() < 1e-8, "{x:?}");
    assert!((x[1] - 0.1).abs() < 1e-8, "{x:?}");
    assert!((x[2] - 4.0).abs() < 1e-8, "{x:?}");
    assert!(res.unidentifiable.is_empty());
}

/// Over many seeds, the truth lies within two standard errors about 95 % of the time.
#[test]
fn standard_errors_cover_the_truth() {
    // The model's initial value (0) is the truth; c and the initial rate are fitted.
    let truth = (0.45, 2.0, 0.0, 4.0);
    let (mut inside_c, mut inside_v, runs) = (0, 0, 200);
    for seed in 0..runs {
        let data = drag_data(1000 + seed, 0.02, truth);
        let res = fit_text(LINEAR_DRAG, &[&data], &free(&["c", "rate.x"])).unwrap();
        let (c, v) = (&res.estimates[0], &res.estimates[1]);
        inside_c += usize::from((c.value - truth.0).abs() <= 2.0 * c.stderr);
        inside_v += usize::from((v.value - truth.3).abs() <= 2.0 * v.stderr);
    }
    eprintln!("coverage within 2 se: c {inside_c}/{runs}, rate.x {inside_v}/{runs}");
    // Binomial(200, 0.954): mean 190.9, sd 3.0; the band is ±3 sd (t-distribution with 38
    // degrees of freedom makes 2 se cover slightly less: 94.8 %).
    for (what, k) in [("c", inside_c), ("rate.x", inside_v)] {
        assert!((180..=199).contains(&k), "{what}: {k}/{runs} within 2 se");
    }
}

/// A damped oscillator x'' = −(k/m) x − (c/m) x' (underdamped) against its closed form.
#[test]
fn damped_oscillator_stiffness_damping_and_start() {
    let model = r#"
name = "oscillator"
[parameters]
k = 30.0
c = 0.5
m = 1.5
[coordinates]
x = { initial = 0.1, rate = 0.0 }
[particles.mass]
mass = "m"
position = "[x, 0, 0]"
[points]
wall = "[0, 0, 0]"
[[forces]]
kind = "spring"
between = ["mass", "wall"]
k = "k"
l0 = "0"
length = "x"
[[forces]]
kind = "damper"
between = ["mass", "wall"]
c = "c"
length = "x"
"#;
    let (k, c, m, x0) = (40.0f64, 0.8f64, 1.5f64, 0.2f64);
    let (zeta_w, wd) = (c / (2.0 * m), (k / m - (c / (2.0 * m)).powi(2)).sqrt());
    let exact = |t: f64| {
        x0 * libm::exp(-zeta_w * t) * (libm::cos(wd * t) + zeta_w / wd * libm::sin(wd * t))
    };
    let mut rng = Rng(7);
    let t: Vec<f64> = (0..150).map(|i| 0.02 * f64::from(i)).collect();
    let x: Vec<f64> = t.iter().map(|&t| exact(t) + 1e-3 * rng.normal()).collect();
    let data = csv(&t, &[("x", x)]);
    let res = fit_text(model, &[&data], &free(&["k", "c", "initial.x"])).unwrap();
    for (e, truth) in res.estimates.iter().zip([k, c, x0]) {
        assert!(
            (e.value - truth).abs() < 3.0 * e.stderr,
            "{}: {} ± {} vs {truth}",
            e.name,
            e.value,
            e.stderr
        );
        assert!(e.stderr < 0.05 * truth.abs(), "{}: {}", e.name, e.stderr);
    }
    // χ²/dof ≈ 1 for unit weights scaled by σ² = 1e-6.
    let s2 = res.chi2 / res.dof as f64;
    assert!((s2 / 1e-6 - 1.0).abs() < 0.3, "{s2}");
}

#[test]
fn two_experiments_share_parameters_and_have_their_own_starts() {
    // The initial rate is the model's (5); each run starts elsewhere.
    let a = drag_data(3, 0.0, (0.45, 2.0, 0.1, 5.0));
    let b = drag_data(4, 0.0, (0.45, 2.0, -0.3, 5.0));
    let res = fit_text(LINEAR_DRAG, &[&a, &b], &free(&["c", "initial.x"])).unwrap();
    let names: Vec<&str> = res.estimates.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["c", "initial.x[run1]", "initial.x[run2]"]);
    assert!((res.estimates[0].value - 0.45).abs() < 1e-8);
    assert!((res.estimates[1].value - 0.1).abs() < 1e-8);
    assert!((res.estimates[2].value + 0.3).abs() < 1e-8);
}

#[test]
fn c_and_m_of_linear_drag_are_not_identifiable() {
    let data = drag_data(5, 0.01, (0.45, 2.0, 0.0, 5.0));
    let res = fit_text(LINEAR_DRAG, &[&data], &free(&["c", "m"])).unwrap();
    assert_eq!(res.unidentifiable.len(), 1, "{:?}", res.unidentifiable);
    assert_eq!(res.unidentifiable[0].names, ["c", "m"]);
    assert!(fit::summary_text(&res).contains("not identifiable"));
    // Only c/m is determined.
    let ratio = res.estimates[0].value / res.estimates[1].value;
    assert!((ratio - 0.225).abs() < 0.01, "{ratio}");
}

#[test]
fn bad_requests_are_clear_errors() {
    let data = drag_data(6, 0.01, (0.45, 2.0, 0.1, 4.0));
    let model = LINEAR_DRAG.replace("[parameters]", "[parameters]\nunused = 3.0");
    let err = fit_text(&model, &[&data], &free(&["unused"])).unwrap_err();
    assert!(err.to_string().contains("does not affect"), "{err}");
    let err = fit_text(LINEAR_DRAG, &[&data], &free(&["k"])).unwrap_err();
    assert!(err.to_string().contains("not a parameter"), "{err}");
    let err = fit_text(LINEAR_DRAG, &[&data], &free(&["initial.q"])).unwrap_err();
    assert!(err.to_string().contains("not a coordinate"), "{err}");
    // A column named as nothing in the model.
    let other = data.replacen("t,x", "t,y", 1);
    let err = fit_text(LINEAR_DRAG, &[&other], &free(&["c"])).unwrap_err();
    assert!(err.to_string().contains("no column is named"), "{err}");
    assert_eq!(err.exit_code(), 2);
    // Unsorted times, a NaN: located.
    let mut lines: Vec<&str> = data.lines().collect();
    lines.swap(3, 4);
    let err = fit_text(LINEAR_DRAG, &[&lines.join("\n")], &free(&["c"])).unwrap_err();
    assert!(err.to_string().contains("not sorted"), "{err}");
    assert_eq!(err.location().unwrap().line, Some(5));
    let err = fit_text(
        LINEAR_DRAG,
        &["t,x\n0,1\n0.1,NaN\n0.2,1.2\n"],
        &free(&["c"]),
    )
    .unwrap_err();
    assert!(err.to_string().contains("NaN"), "{err}");
    assert_eq!(err.location().unwrap().line, Some(3));
    let err = fit_text(LINEAR_DRAG, &["t,x\n"], &free(&["c"])).unwrap_err();
    assert!(err.to_string().contains("no data rows"), "{err}");
    let err = fit_text(
        LINEAR_DRAG,
        &[&data],
        &FitRequest {
            bounds: vec![("m".into(), 0.0, 1.0)],
            ..free(&["c"])
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("not free"), "{err}");
}

#[test]
fn a_bound_holds_the_estimate() {
    let data = drag_data(8, 0.0, (0.45, 2.0, 0.1, 4.0));
    let res = fit_text(
        LINEAR_DRAG,
        &[&data],
        &FitRequest {
            bounds: vec![("c".into(), 0.0, 0.4)],
            ..free(&["c", "initial.x", "rate.x"])
        },
    )
    .unwrap();
    assert!(
        (res.estimates[0].value - 0.4).abs() < 1e-12,
        "{:?}",
        res.estimates[0]
    );
    assert!(fit::summary_text(&res).contains("at its bound"));
}

/// Native code and the interpreter give the same bits, so the same fit.
#[test]
fn native_and_interpreted_sensitivities_agree_bit_for_bit() {
    let data = drag_data(9, 0.02, (0.45, 2.0, 0.1, 4.0));
    let req = free(&["c", "initial.x", "rate.x"]);
    let native = fit_text(LINEAR_DRAG, &[&data], &req).unwrap();
    let interpreted = fit_text(
        LINEAR_DRAG,
        &[&data],
        &FitRequest {
            jit: pdyn::sim::JitMode::Off,
            ..req
        },
    )
    .unwrap();
    for (a, b) in native.estimates.iter().zip(&interpreted.estimates) {
        assert_eq!(a.value.to_bits(), b.value.to_bits(), "{}", a.name);
    }
}

/// `pdyn fit --data run.parquet`: an experiment read from a Parquet file written by pandas
/// (`pdyn-data/tests/fixtures`), columns named as the state; other columns are not read.
#[test]
fn an_experiment_is_read_from_parquet() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../pdyn-data/tests/fixtures/track_gzip.parquet");
    let e = experiment::read(&path, &["x".to_string(), "x'".to_string()]).unwrap();
    assert_eq!(e.name, "track_gzip");
    assert_eq!(e.observed.len(), 1);
    assert_eq!(e.observed[0].name, "x");
    for i in 0..100 {
        let f = i as f64;
        assert_eq!(e.t[i], f / 64.0);
        assert_eq!(e.observed[0].values[i], f * f / 8.0);
    }
    // No column named as the state: the error names the file's columns (no line: Parquet).
    let err = experiment::read(&path, &["q".to_string()]).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("no column is named as a coordinate"),
        "{text}"
    );
    assert!(text.contains("`label`"), "{text}");
}
