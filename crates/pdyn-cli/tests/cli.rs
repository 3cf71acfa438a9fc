//! The `pdyn` binary, end to end.

mod common;
use common::pdyn;

#[test]
fn solves_the_rotating_bar_example() {
    let (ok, out, err) = pdyn(&[
        "solve",
        "--for",
        "N,T",
        "T*cos(theta) - N*sin(theta) = -m*r*omega^2*cos(theta)",
        "N*cos(theta) + T*sin(theta) - m*g = -m*r*omega^2*sin(theta)",
    ]);
    assert!(ok, "{err}");
    assert_eq!(
        out,
        "N = g*m*cos(theta)\nT = g*m*sin(theta) - m*omega^2*r\n"
    );
}

#[test]
fn json_output_is_machine_readable() {
    let (ok, out, err) = pdyn(&["diff", "x(t)^2", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("valid JSON");
    assert_eq!(v["result"]["text"], "2*x*x'");
}

#[test]
fn bad_input_is_located_and_exits_nonzero() {
    let (ok, out, err) = pdyn(&["simplify", "2*sn(x)"]);
    assert!(!ok);
    assert!(out.is_empty());
    assert!(
        err.contains("<expr>:1:3: error: unknown function `sn`"),
        "{err}"
    );
    assert!(err.contains("did you mean `sin`?"), "{err}");
    let (ok, _, err) = pdyn(&["solve", "--for", "x,y", "x + y = 1", "2*x + 2*y = 2"]);
    assert!(!ok);
    assert!(err.contains("do not determine y"), "{err}");
    let (ok, _, err) = pdyn(&["eval", "a*b", "--at", "a=2"]);
    assert!(!ok);
    assert!(err.contains("`b` has no value"), "{err}");
}

#[test]
fn derive_prints_the_chapter_equations_and_json() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    let (ok, out, err) = pdyn(&["derive", &format!("{root}pulley.toml")]);
    assert!(ok, "{err}");
    assert!(out.contains("T = 2*g*mA*mB/(mA + mB)"), "{out}");
    let (ok, out, err) = pdyn(&["derive", &format!("{root}building.toml"), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("valid JSON");
    assert_eq!(v["state"][0], "y1");
    assert_eq!(v["unknowns"][1], "y2''");
}

#[test]
fn derive_reports_located_model_errors() {
    let dir = std::env::temp_dir().join(format!("pdyn-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        "[parameters]\nm = 1\n\n[coordinates]\nx = { initial = 0, rate = 0 }\n\n[particles.a]\nmass = \"m\"\nposition = \"[x, sn(x), 0]\"\n",
    )
    .unwrap();
    let (ok, _, err) = pdyn(&["derive", path.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("bad.toml:9:17: error: unknown function `sn`"),
        "{err}"
    );
    assert!(err.contains("did you mean `sin`?"), "{err}");
    let (ok, _, err) = pdyn(&["derive", "/nonexistent/model.toml"]);
    assert!(!ok);
    assert!(err.contains("cannot read the model file"), "{err}");
}

fn tempdir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pdyn-cli-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn run_warns_loudly_and_writes_csv_and_json() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    let out = tempdir("run");
    let (ok, stdout, err) = pdyn(&[
        "run",
        &format!("{root}satellite_ode45.toml"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("warning: energy should be conserved"), "{err}");
    assert!(stdout.contains("DRIFTING"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(
        csv.starts_with("t,x,y,x',y',sat.x,sat.y,energy,angular_momentum.z\n"),
        "{}",
        &csv[..80]
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["ok"], true);
    assert!(!summary["warnings"].as_array().unwrap().is_empty());
    // The same model at rtol 1e-5: no warning.
    let (ok, _, err) = pdyn(&[
        "run",
        &format!("{root}satellite_ode45.toml"),
        "--rtol",
        "1e-5",
        "--atol",
        "1e-9",
    ]);
    assert!(ok && !err.contains("warning"), "{err}");
}

#[test]
fn run_reports_a_failed_integration_with_time_and_state_and_keeps_the_data() {
    let dir = tempdir("fail");
    let model = dir.join("radial_fall.toml");
    std::fs::write(
        &model,
        "name = \"radial fall into the attracting centre\"\n[parameters]\nGM = 1.0\n\n\
         [coordinates]\nx = { initial = 1.0, rate = 0.0 }\ny = { initial = 0.0, rate = 0.0 }\n\n\
         [particles.p]\nmass = 1\nposition = \"[x, y, 0]\"\n\n[points]\nO = \"[0, 0, 0]\"\n\n\
         [[forces]]\nkind = \"inverse_square\"\non = \"p\"\nto = \"O\"\nstrength = \"GM\"\n\n\
         [simulate]\nt_end = 10\nmethod = \"dopri5\"\n",
    )
    .unwrap();
    let out = dir.join("out");
    let (ok, _, err) = pdyn(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok, "the fall reaches r = 0");
    assert!(err.contains("integration failed at t = "), "{err}");
    assert!(err.contains("state: x = "), "{err}");
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(csv.lines().count() > 10, "partial results are kept");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["ok"], false);
}

#[test]
fn run_rejects_bad_settings_clearly() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    let (ok, _, err) = pdyn(&["run", &format!("{root}satellite.toml"), "--method", "ode99"]);
    assert!(!ok);
    assert!(err.contains("unknown method `ode99`"), "{err}");
    let (ok, _, err) = pdyn(&[
        "run",
        &format!("{root}satellite.toml"),
        "--method",
        "verlet",
    ]);
    assert!(!ok);
    assert!(err.contains("--dt"), "{err}");
    let (ok, _, err) = pdyn(&["run", &format!("{root}satellite.toml"), "--t-eval", "0,200"]);
    assert!(!ok);
    assert!(
        err.contains("t_eval must be increasing times within [0, 100]"),
        "{err}"
    );
    let (ok, out, err) = pdyn(&[
        "run",
        &format!("{root}satellite.toml"),
        "--t-eval",
        "0,0.5,1",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["outputs"], 3);
    assert_eq!(v["final"]["t"], 1.0);
    let (ok, out, _) = pdyn(&["run", &format!("{root}satellite.toml"), "--method", "help"]);
    assert!(ok);
    assert!(out.contains("dopri5") && out.contains("Dormand"), "{out}");
    let (ok, _, err) = pdyn(&[
        "run",
        &format!("{root}projectile_drag.toml"),
        "--method",
        "verlet",
        "--dt",
        "0.01",
    ]);
    assert!(!ok);
    assert!(err.contains("depend on velocities"), "{err}");
}

#[test]
fn sweep_prints_the_resonances() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    let (ok, out, err) = pdyn(&["sweep", &format!("{root}building.toml"), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let peaks = v["slices"][0]["measures"][0]["peaks"].as_array().unwrap();
    assert_eq!(peaks.len(), 2);
    assert!((peaks[0]["at"].as_f64().unwrap() - 8.74).abs() < 0.1);
    assert!((peaks[1]["at"].as_f64().unwrap() - 22.88).abs() < 0.1);
}

#[test]
fn derive_prints_closed_forms_and_check_compares() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    let (ok, out, err) = pdyn(&["derive", &format!("{root}rotating_rod_block.toml")]);
    assert!(ok, "{err}");
    assert!(out.contains("Closed-form solution"), "{out}");
    assert!(
        out.contains(
            "r(t) = V*sinh(omega*t*sqrt(1 + mu^2))*exp(-mu*omega*t)/(omega*sqrt(1 + mu^2))"
        ),
        "{out}"
    );
    let (ok, out, err) = pdyn(&["check", &format!("{root}suspension.toml"), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["max_relative_error"].as_f64().unwrap() < 1e-6, "{v}");
    let (ok, _, err) = pdyn(&["run", &format!("{root}satellite.toml"), "--method", "exact"]);
    assert!(!ok);
    assert!(err.contains("no closed form"), "{err}");
}

#[test]
fn native_code_and_the_interpreter_give_the_same_run() {
    // `pendulum_chain_3` solves A x = b numerically (JitLinearSystem), the others run one
    // exact program; the trajectory CSV of both engines must be identical to the last bit.
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    for name in ["satellite", "building", "pendulum_chain_3"] {
        let model = &format!("{root}{name}.toml");
        let (ok, native, err) = pdyn(&["run", model, "--json", "--t-end", "2"]);
        assert!(ok, "{model}: {err}");
        let (ok, interp, err) = pdyn(&["run", model, "--json", "--t-end", "2", "--no-jit"]);
        assert!(ok, "{model}: {err}");
        assert_eq!(native, interp, "{model}");
        assert!(native.contains("\"final\""), "{native}");
    }
}

#[test]
fn numbers_are_exact_past_64_bits() {
    let (ok, out, err) = pdyn(&["eval", "2^64 + 1 - 2^64"]);
    assert!(ok, "{err}");
    assert_eq!(out, "1\n");
    // An exact fraction also shows its floating-point value; JSON says which is exact.
    let (ok, out, _) = pdyn(&["eval", "1/3"]);
    assert!(ok);
    assert_eq!(out, "1/3 ≈ 0.3333333333333333\n");
    let (ok, out, _) = pdyn(&["eval", "[1/3, sqrt(2), 0]", "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["exact"], serde_json::json!(["1/3", null, "0"]));
    // 2^100000: exact (30,103 digits), not `1/0`.
    let (ok, out, err) = pdyn(&["simplify", "2^100000"]);
    assert!(ok, "{err}");
    assert_eq!(out.trim_end().len(), 30_103);
    // Over the budget: a located error with the limit, exit 2.
    let (ok, _, err) = pdyn(&["eval", "2^1000000"]);
    assert!(!ok);
    assert!(err.contains("over the limit of 100000 digits"), "{err}");
}

#[test]
fn expansion_is_complete_or_a_budget_error() {
    let (ok, out, err) = pdyn(&["simplify", "--expand", "(x+y)^25"]);
    assert!(ok, "{err}");
    assert_eq!(out.matches(" + ").count(), 25, "{out}");
    assert!(out.contains("5200300*x^12*y^13"), "{out}");
    let (ok, out, _) = pdyn(&["simplify", "--expand", "(a+b+c+d)^40", "--json"]);
    assert!(!ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["error"]["kind"], "budget");
    assert_eq!(v["error"]["exit_code"], 2);
    assert!(v["error"]["message"]
        .as_str()
        .unwrap()
        .contains("5000 terms"));
}

#[test]
fn high_order_derivatives_finish() {
    let (ok, out, err) = pdyn(&["diff", "sin(x)", "--wrt", "x", "-n", "100001"]);
    assert!(ok, "{err}");
    assert_eq!(out, "cos(x)\n");
    let (ok, _, err) = pdyn(&["diff", "exp(x^2)", "--wrt", "x", "-n", "100000"]);
    assert!(!ok);
    assert!(err.contains("diff -n 100000: error:"), "{err}");
    assert!(err.contains("expression nodes"), "{err}");
}

/// A coordinate's rate written in [unknowns] (issue 34, item 5): `pdyn forces` solves for it in
/// closed form; `run`, `check` and `derive` say where it is and what to do, with exit code 2.
#[test]
fn a_rate_in_unknowns_is_solved_by_forces_and_refused_by_run() {
    let model = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/conical_pendulum.toml"
    );
    let (ok, out, err) = pdyn(&["forces", model]);
    assert!(ok, "{err}");
    assert!(out.contains("T = g*m/cos(alpha)"), "{out}");
    assert!(out.contains("omega = sqrt("), "{out}");
    assert!(!out.contains("numerically"), "{out}");
    for command in ["run", "check"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_pdyn"))
            .args([command, model, "--t-end", "1"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{command}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("conical_pendulum.toml:17:7: error:"),
            "{command}: {err}"
        );
        assert!(err.contains("the rate of `phi`"), "{command}: {err}");
        assert!(err.contains("rate = \"omega\""), "{command}: {err}");
        assert!(err.contains("pdyn forces"), "{command}: {err}");
    }
    let (ok, out, err) = pdyn(&["derive", model]);
    assert!(ok, "{err}");
    assert!(
        out.contains("phi'(0) = omega (unknown, for pdyn forces)"),
        "{out}"
    );
    assert!(!out.contains("NaN"), "{out}");
}

/// Output times given on the command line replace the file's spacing (issue 25: the run
/// options are merged once, in `pdyn::sim::request`). The building's file says `points =
/// 2001`; `--output-dt 1` used to lose to it silently (points come first), and now gives the
/// 21 rows of t = 0, 1, …, 20, as Python's `t_eval=` always did.
#[test]
fn output_dt_on_the_command_line_replaces_the_files_points() {
    let model = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/building.toml");
    let (ok, out, err) = pdyn(&["run", model, "--output-dt", "1", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["outputs"], 21, "{out}");
}
