//! `[data.NAME]` tables in models (issue 26, item 1): a column sampled from a closed form
//! drives a run that must agree with the closed-form solution to the interpolation's order;
//! the run that leaves the data's range and each kind of bad data are located errors.

use pdyn::sim::{self, RunSettings};
use std::path::{Path, PathBuf};

/// A scratch directory of this test (removed first).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pdyn-data-tables-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The forcing F(t) = sin(3t) sampled at `n` + 1 points on [0, π] (F'' = 0 at both ends, as
/// the natural cubic spline assumes, so the ends do not lower its order).
fn write_forcing(dir: &Path, n: usize) {
    let mut s = String::from("time,F\n");
    for i in 0..=n {
        let t = std::f64::consts::PI * i as f64 / n as f64;
        s.push_str(&format!("{t:e},{:e}\n", libm::sin(3.0 * t)));
    }
    std::fs::write(dir.join("forcing.csv"), s).unwrap();
}

/// x'' + x = F(t), x(0) = x'(0) = 0, F from the data table with `interpolation`.
fn model_text(interpolation: &str, t_end: f64) -> String {
    format!(
        r#"
[data.drive]
file = "forcing.csv"
time = "time"
interpolation = "{interpolation}"

[parameters]
m = 1.0
k = 1.0

[coordinates]
x = {{ initial = 0.0, rate = 0.0 }}

[particles.p]
mass = "m"
position = "[x, 0, 0]"

[[forces]]
kind = "applied"
on = "p"
force = "[-k*x + drive_F(t), 0, 0]"

[simulate]
t_end = {t_end}
method = "dop853"
rtol = 1e-13
atol = 1e-13
points = 101
"#
    )
}

fn load(dir: &Path, text: &str) -> Result<pdyn_mech::Model, String> {
    let path = dir.join("model.toml");
    std::fs::write(&path, text).unwrap();
    let origin = path.display().to_string();
    pdyn_mech::load(text, &origin).map_err(|e| e.render(text))
}

/// The largest difference from the closed form x = (3 sin t − sin 3t)/8 over the outputs.
fn error_of_run(interpolation: &str, n: usize) -> f64 {
    let dir = scratch(&format!("{interpolation}-{n}"));
    write_forcing(&dir, n);
    let mut model = load(&dir, &model_text(interpolation, std::f64::consts::PI)).unwrap();
    let set = RunSettings::from_spec(&model.run.simulate).unwrap();
    let prep = sim::prepare(&mut model).unwrap();
    let res = sim::run(&prep, &set).unwrap();
    assert!(res.failure.is_none(), "{:?}", res.failure);
    let (ti, xi) = (
        res.columns.iter().position(|c| c == "t").unwrap(),
        res.columns.iter().position(|c| c == "x").unwrap(),
    );
    let _ = std::fs::remove_dir_all(&dir);
    res.rows
        .iter()
        .map(|r| {
            let t = r[ti];
            let exact = (3.0 * libm::sin(t) - libm::sin(3.0 * t)) / 8.0;
            (r[xi] - exact).abs()
        })
        .fold(0.0, f64::max)
}

/// The observed order of convergence from halving the sample spacing twice.
fn observed_orders(interpolation: &str, n: usize) -> (f64, f64, f64) {
    let (e1, e2, e3) = (
        error_of_run(interpolation, n),
        error_of_run(interpolation, 2 * n),
        error_of_run(interpolation, 4 * n),
    );
    let orders = (libm::log2(e1 / e2), libm::log2(e2 / e3), e3);
    eprintln!("{interpolation}: errors {e1:.3e} {e2:.3e} {e3:.3e}, orders {orders:?}");
    orders
}

#[test]
fn linear_interpolation_converges_at_second_order() {
    let (p1, p2, e) = observed_orders("linear", 40);
    assert!(
        (1.9..2.1).contains(&p1) && (1.9..2.1).contains(&p2),
        "orders {p1}, {p2}"
    );
    assert!(e < 1e-3, "error {e}");
}

#[test]
fn cubic_interpolation_converges_at_fourth_order() {
    let (p1, p2, e) = observed_orders("cubic", 20);
    assert!(
        (3.8..4.3).contains(&p1) && (3.8..4.3).contains(&p2),
        "orders {p1}, {p2}"
    );
    assert!(e < 1e-6, "error {e}");
}

#[test]
fn pchip_interpolation_converges_at_third_order_or_better() {
    // PCHIP's slopes (the harmonic mean of the neighbouring secants) are first-order
    // accurate, so the interpolant is third order; the solution, an integral of the forcing,
    // shows 3.9 here (its errors of alternating sign partly cancel).
    let (p1, p2, e) = observed_orders("pchip", 40);
    assert!(p1 > 2.8 && p2 > 2.8, "orders {p1}, {p2}");
    assert!(e < 1e-3, "error {e}");
}

#[test]
fn native_code_and_the_interpreter_give_the_same_bits() {
    let dir = scratch("jit");
    write_forcing(&dir, 37);
    for interpolation in ["linear", "cubic", "pchip"] {
        let text = model_text(interpolation, 3.0);
        let mut runs = Vec::new();
        for jit in [true, false] {
            let mut model = load(&dir, &text).unwrap();
            let set = RunSettings::from_spec(&model.run.simulate).unwrap();
            let mode = if jit {
                pdyn_jit::JitMode::Auto
            } else {
                pdyn_jit::JitMode::Off
            };
            let prep = sim::prepare_with_jit(&mut model, &sim::run_options(), mode).unwrap();
            runs.push(sim::run(&prep, &set).unwrap().rows);
        }
        let bits = |rows: &Vec<Vec<f64>>| -> Vec<u64> {
            rows.iter().flatten().map(|v| v.to_bits()).collect()
        };
        assert_eq!(bits(&runs[0]), bits(&runs[1]), "{interpolation}");
    }
}

#[test]
fn a_run_past_the_data_is_an_error_naming_the_time_and_the_range() {
    let dir = scratch("range");
    write_forcing(&dir, 50);
    let mut model = load(&dir, &model_text("linear", 4.0)).unwrap();
    let set = RunSettings::from_spec(&model.run.simulate).unwrap();
    let prep = sim::prepare(&mut model).unwrap();
    let (_, failure) = sim::request::execute(&mut model, &prep, &set).unwrap();
    let message = failure.expect("the run must fail").to_string();
    assert!(
        message.contains("left the time range of the data")
            && message.contains("drive_F")
            && message.contains("t = 3.14159")
            && message.contains("[0, 3.14159"),
        "{message}"
    );
}

#[test]
fn bad_data_are_located_errors() {
    let dir = scratch("bad");
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "t,a\n0,1\n1,2\n1,3\n",
            "",
            &["forcing.csv:4:1", "duplicate time"],
        ),
        (
            "t,a\n0,1\n1,2\n0.5,3\n",
            "",
            &["forcing.csv:4:1", "not sorted"],
        ),
        (
            "t,a\n0,1\n1,NaN\n2,3\n",
            "",
            &["forcing.csv:3:3", "NaN", "column `a`"],
        ),
        (
            "t,a\n0,1\n1,\n2,3\n",
            "",
            &["forcing.csv:3", "missing value"],
        ),
        ("t,a\n", "", &["forcing.csv:1", "no data rows"]),
        (
            "t,a\n0,1\n1,2\n",
            "columns = [\"b\"]\n",
            &["no column named `b`", "columns = [...]"],
        ),
    ];
    for (csv, extra, wanted) in cases {
        std::fs::write(dir.join("forcing.csv"), csv).unwrap();
        let text = format!(
            "[data.g]\nfile = \"forcing.csv\"\n{extra}\n[coordinates]\nx = {{ initial = 0, rate = 0 }}\n\
             [particles.p]\nmass = 1\nposition = \"[x, 0, 0]\"\n"
        );
        let err = load(&dir, &text).expect_err(csv);
        for w in wanted {
            assert!(err.contains(w), "{csv:?}: `{w}` not in\n{err}");
        }
        assert!(
            err.contains("model.toml:2:"),
            "located at `file = ...`: {err}"
        );
    }
    let text = "[data.g]\nfile = \"forcing.csv\"\ninterpolation = \"spline\"\n";
    std::fs::write(dir.join("forcing.csv"), "t,a\n0,1\n1,2\n").unwrap();
    let err = load(&dir, text).unwrap_err();
    assert!(err.contains("unknown interpolation `spline`"), "{err}");
    let text = "[data.g]\nfile = \"missing.csv\"\n";
    let err = load(&dir, text).unwrap_err();
    assert!(err.contains("cannot read the data file"), "{err}");
    let text = "[data.g]\nfile = \"forcing.csv\"\n[parameters]\ng_a = 1.0\n";
    let err = load(&dir, text).unwrap_err();
    assert!(err.contains("has the name of a parameter"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_column_is_differentiated_as_its_interpolant() {
    // d/dt of a column is its interpolant's derivative: for the cubic spline of sin(3t) the
    // second derivative approaches -9 sin(3t) (at second order in the spacing).
    let dir = scratch("diff");
    write_forcing(&dir, 400);
    let mut model = load(&dir, &model_text("cubic", 1.0)).unwrap();
    let pool = &mut model.pool;
    let table = pool.table_named("drive_F").unwrap();
    let t = pool.time();
    let f = pool.tabulated(table, 0, t);
    let acc = pool.dt_n(f, 2);
    assert_eq!(pool.to_text(acc), "drive_F''(t)");
    // The chain rule through another argument: d/dt F(2t) = 2 F'(2t).
    let two_t = pool.parse_scalar("2*t").unwrap();
    let g = pool.tabulated(table, 0, two_t);
    let dg = pool.dt(g);
    assert_eq!(pool.to_text(dg), "2*drive_F'(2*t)");
    let prog = pdyn_expr::Program::compile(pool, &[t], &[f, acc]).unwrap();
    let mut ws = prog.workspace();
    let mut out = [0.0; 2];
    for k in 1..20 {
        let x = 0.15 * k as f64;
        prog.eval(&[x], &mut ws, &mut out);
        assert!(
            (out[0] - libm::sin(3.0 * x)).abs() < 1e-8,
            "F({x}) = {}",
            out[0]
        );
        assert!(
            (out[1] + 9.0 * libm::sin(3.0 * x)).abs() < 2e-3,
            "F''({x}) = {}",
            out[1]
        );
    }
    // Linear interpolation: the slope is the secant of the interval, the second derivative 0.
    let mut model = load(&dir, &model_text("linear", 1.0)).unwrap();
    let pool = &mut model.pool;
    let table = pool.table_named("drive_F").unwrap();
    let t = pool.time();
    let f = pool.tabulated(table, 0, t);
    let v = pool.dt(f);
    assert_eq!(pool.dt(v), pdyn_expr::Pool::ZERO);
    let prog = pdyn_expr::Program::compile(pool, &[t], &[v]).unwrap();
    let mut ws = prog.workspace();
    let mut out = [0.0];
    let h = std::f64::consts::PI / 400.0;
    let x = 10.5 * h;
    prog.eval(&[x], &mut ws, &mut out);
    let secant = (libm::sin(3.0 * 11.0 * h) - libm::sin(3.0 * 10.0 * h)) / h;
    assert!((out[0] - secant).abs() < 1e-9, "{} vs {secant}", out[0]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A Parquet fixture written by pandas (`pdyn-data/tests/fixtures/make_parquet.py`).
fn parquet_fixture(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../pdyn-data/tests/fixtures")
        .join(name);
    std::fs::read(path).unwrap()
}

/// x'' = drive_x(t) from `file` (t = i/64, x = i²/8 for i < 100).
fn parquet_model(file: &str) -> String {
    format!(
        r#"
[data.drive]
file = "{file}"
columns = ["x"]
interpolation = "cubic"

[coordinates]
q = {{ initial = 0.0, rate = 0.0 }}

[particles.p]
mass = 1
position = "[q, 0, 0]"

[[forces]]
kind = "applied"
on = "p"
force = "[drive_x(t), 0, 0]"

[simulate]
t_end = 1.5
points = 31
"#
    )
}

#[test]
fn a_parquet_table_drives_the_run_as_its_csv_twin_does_bit_for_bit() {
    let dir = scratch("parquet");
    std::fs::write(
        dir.join("track.parquet"),
        parquet_fixture("track_zstd.parquet"),
    )
    .unwrap();
    // The same numbers as CSV, each written exactly (`{:e}` round-trips).
    let mut csv = String::from("t,x\n");
    for i in 0..100 {
        let f = i as f64;
        csv.push_str(&format!("{:e},{:e}\n", f / 64.0, f * f / 8.0));
    }
    std::fs::write(dir.join("track.csv"), csv).unwrap();
    let run = |file: &str| {
        let mut model = load(&dir, &parquet_model(file)).unwrap();
        let set = RunSettings::from_spec(&model.run.simulate).unwrap();
        let prep = sim::prepare(&mut model).unwrap();
        let res = sim::run(&prep, &set).unwrap();
        assert!(res.failure.is_none(), "{:?}", res.failure);
        assert_eq!(res.rows.len(), 31);
        res.rows
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<u64>>()
    };
    let from_parquet = run("track.parquet");
    assert_eq!(from_parquet, run("track.csv"));
    // And q'' = x = 512 t² (i = 64 t) integrates to q = 128 t⁴/3, up to the spline's error.
    let mut model = load(&dir, &parquet_model("track.parquet")).unwrap();
    let set = RunSettings::from_spec(&model.run.simulate).unwrap();
    let prep = sim::prepare(&mut model).unwrap();
    let res = sim::run(&prep, &set).unwrap();
    let last = res.rows.last().unwrap();
    let exact = 128.0 * libm::pow(1.5, 4.0) / 3.0;
    assert!(
        (last[1] - exact).abs() < 1e-5 * exact,
        "{} vs {exact}",
        last[1]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_parquet_data_are_located_by_row_and_column() {
    let dir = scratch("parquet-bad");
    for (fixture, expected) in [
        ("nan_row12.parquet", "row 12: the value is NaN"),
        ("null_row8.parquet", "row 8: missing value (null)"),
        ("unsorted_row51.parquet", "row 51: time 0.5 comes after"),
        ("timestamps.parquet", "holds dates or times"),
    ] {
        std::fs::write(dir.join(fixture), parquet_fixture(fixture)).unwrap();
        let e = load(&dir, &parquet_model(fixture)).unwrap_err();
        assert!(e.contains(expected), "{fixture}: {e}");
        assert!(e.contains(fixture), "{fixture}: the file is named: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
