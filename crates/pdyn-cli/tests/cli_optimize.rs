//! `pdyn optimize` end to end: the launch angle without drag is π/4 (closed form), JSON on
//! success and on failure, `--help`.

use std::process::Command;

fn pdyn(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .output()
        .expect("run pdyn");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn model() -> String {
    format!(
        "{}/../../examples/data/launch_angle.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn the_best_angle_without_drag_is_a_quarter_turn() {
    let m = model();
    let (code, stdout, stderr) = pdyn(&[
        "optimize",
        &m,
        "--maximize",
        "range",
        "--over",
        "theta=0..pi/2",
        "--set",
        "c=0",
        "--json",
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let theta = v["x"]["theta"].as_f64().unwrap();
    assert!((theta - std::f64::consts::FRAC_PI_4).abs() < 1e-8, "{v}");
    assert_eq!(v["method"], "brent");
    let (code, stdout, _) = pdyn(&[
        "optimize",
        &m,
        "--maximize",
        "range",
        "--over",
        "theta=0..pi/2",
    ]);
    assert_eq!(code, 0);
    assert!(stdout.contains("maximum of range"), "{stdout}");
}

#[test]
fn bad_requests_are_located_errors_in_json() {
    let m = model();
    for (args, option, wanted) in [
        (
            vec!["--maximize", "height", "--over", "theta=0..1"],
            "--maximize",
            "not a measure",
        ),
        (
            vec!["--maximize", "range", "--over", "phi=0..1"],
            "--over",
            "not a parameter",
        ),
        (
            vec!["--maximize", "range", "--over", "theta=1..0"],
            "--over",
            "finite interval",
        ),
        (
            vec!["--maximize", "range", "--over", "theta=0-1"],
            "--over",
            "NAME=LO..HI",
        ),
    ] {
        let mut all = vec!["optimize", m.as_str()];
        all.extend(args);
        all.push("--json");
        let (code, stdout, _) = pdyn(&all);
        assert_eq!(code, 2, "{all:?}: {stdout}");
        let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(v["error"]["location"]["file"], option, "{stdout}");
        let message = v["error"]["message"].as_str().unwrap();
        assert!(message.contains(wanted), "{message}");
    }
    let (code, stdout, _) = pdyn(&["optimize", "--help"]);
    assert_eq!(code, 0);
    assert!(
        stdout.contains("--maximize") && stdout.contains("--over"),
        "{stdout}"
    );
}
