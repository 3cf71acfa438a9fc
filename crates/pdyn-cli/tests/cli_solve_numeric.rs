//! `pdyn solve --in` / `--start`: numeric roots of equations without a closed form (issue 26,
//! item 5). Truths: Kepler's equation checked against pdyn-gravity's own Kepler solver and
//! by recomputing M; the roots of sin x = x/10 counted from the graph (0, and three on each
//! side); tan x = x's first positive root 4.493409457909064 (a classical value); bad
//! intervals answered with located errors, in JSON too.

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

fn json(args: &[&str]) -> serde_json::Value {
    let mut all = args.to_vec();
    all.push("--json");
    let (code, stdout, stderr) = pdyn(&all);
    assert_eq!(code, 0, "{stdout}{stderr}");
    serde_json::from_str(&stdout).unwrap()
}

#[test]
fn kepler_agrees_with_the_gravity_crates_solver() {
    for (ecc, m) in [(0.3, 1.0), (0.9, 0.2), (0.05, 5.5)] {
        let at = format!("ecc={ecc},M={m}");
        let v = json(&[
            "solve",
            "E - ecc*sin(E) = M",
            "--for",
            "E",
            "--in",
            "E=0..2*pi",
            "--at",
            &at,
        ]);
        let roots = v["roots"].as_array().unwrap();
        assert_eq!(roots.len(), 1, "{v}");
        let e = roots[0]["E"].as_f64().unwrap();
        let reference = pdyn_gravity::orbit::eccentric_anomaly(m, ecc);
        assert!((e - reference).abs() < 1e-14, "{e} vs {reference}");
        assert!((e - ecc * libm::sin(e) - m).abs() < 1e-15 * 8.0);
        let kind = roots[0]["certificate"]["kind"].as_str().unwrap();
        assert!(kind == "sign change" || kind == "exact zero", "{kind}");
    }
}

#[test]
fn every_root_in_the_interval_each_certified() {
    let v = json(&["solve", "sin(x) = x/10", "--for", "x", "--in", "x=-10..10"]);
    let roots = v["roots"].as_array().unwrap();
    assert_eq!(roots.len(), 7, "{v}");
    let v = json(&["solve", "tan(x) = x", "--for", "x", "--in", "x=0.1..7"]);
    let roots = v["roots"].as_array().unwrap();
    assert_eq!(roots.len(), 1, "{v}");
    assert!((roots[0]["x"].as_f64().unwrap() - 4.493_409_457_909_064).abs() < 1e-13);
    // The poles at π/2 and 3π/2 change the sign but are not roots.
    assert_eq!(v["discontinuities"].as_array().unwrap().len(), 2, "{v}");
    let v = json(&[
        "solve",
        "x^3 - 3*x + 2 = 0",
        "--for",
        "x",
        "--in",
        "x=-3..3.1",
    ]);
    let roots = v["roots"].as_array().unwrap();
    assert_eq!(roots.len(), 2, "{v}");
    assert_eq!(
        roots[1]["certificate"]["kind"], "double root (residual bound)",
        "{v}"
    );
}

#[test]
fn newton_on_a_system_from_starts() {
    let v = json(&[
        "solve",
        "x^2 + y^2 = 4",
        "y = x",
        "--for",
        "x,y",
        "--start",
        "x=1,y=2",
        "--start",
        "x=-3,y=1",
    ]);
    let sols = v["solutions"].as_array().unwrap();
    assert_eq!(sols.len(), 2, "{v}");
    let s2 = std::f64::consts::SQRT_2;
    assert!((sols[0]["x"].as_f64().unwrap() - s2).abs() < 1e-15);
    assert!((sols[1]["y"].as_f64().unwrap() + s2).abs() < 1e-15);
}

#[test]
fn bad_intervals_are_located_errors() {
    for (args, wanted) in [
        (
            vec!["--in", "x=3..1"],
            "lower end 3 is not below its upper end 1",
        ),
        (vec!["--in", "x=0..inf"], "--in"),
        (vec!["--in", "x=0,10"], "expected NAME=LO..HI"),
        (vec!["--in", "y=0..1"], "not the unknown"),
        (vec!["--in", "x=0..1", "--samples", "1"], "between 2 and"),
    ] {
        let mut all = vec!["solve", "sin(x) = a*x", "--for", "x", "--at", "a=0.5"];
        all.extend(args);
        all.push("--json");
        let (code, stdout, _) = pdyn(&all);
        assert_eq!(code, 2, "{all:?}: {stdout}");
        let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let message = v["error"]["message"].as_str().unwrap();
        assert!(message.contains(wanted), "{all:?}: {message}");
        assert_eq!(v["error"]["location"]["file"], "--in", "{all:?}: {stdout}");
    }
    let (code, _, stderr) = pdyn(&["solve", "sin(x) = x/2", "--for", "x"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("--in x=0..10"), "{stderr}");
}

/// `sqrt(x - 20) = 1` is defined only from x = 20: on [0, 10] there is no root because f has
/// no value there, which is said, not left as a bare "0 roots"; on [0, 30] the root 21 is
/// found and the undefined part counted (x < 20: 1,334 of the 2,001 samples, the step 0.015).
#[test]
fn samples_outside_the_functions_domain_are_counted_and_reported() {
    let v = json(&["solve", "--for", "x", "--in", "x=0..10", "sqrt(x-20)=1"]);
    assert_eq!(v["roots"].as_array().unwrap().len(), 0);
    assert_eq!(v["undefined_samples"], 2001);
    let (code, out, _) = pdyn(&["solve", "--for", "x", "--in", "x=0..10", "sqrt(x-20)=1"]);
    assert_eq!(code, 0);
    assert!(
        out.contains("not a number at 2001 of the 2001 sample points"),
        "{out}"
    );
    let v = json(&["solve", "--for", "x", "--in", "x=0..30", "sqrt(x-20)=1"]);
    let roots = v["roots"].as_array().unwrap();
    assert_eq!(roots.len(), 1);
    assert!((roots[0]["x"].as_f64().unwrap() - 21.0).abs() < 1e-12);
    assert_eq!(v["undefined_samples"], 1334);
}
