//! The `pdyn` binary, end to end.

use std::process::Command;

fn pdyn(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .output()
        .expect("run pdyn");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

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
