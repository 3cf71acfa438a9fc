//! `pdyn kin` end to end: the chapter's polar example, the curvy road, JSON and errors.

mod common;
use common::pdyn;

#[test]
fn polar_example_at_theta_pi() {
    let (ok, out, err) = pdyn(&[
        "kin",
        "--polar",
        "r = t/sqrt(pi), theta = t^2",
        "--at",
        "theta=pi",
    ]);
    assert!(ok, "{err}");
    let at = out.split("at theta = pi").nth(1).expect("instant block");
    assert!(at.starts_with(" (t = sqrt(pi)"), "{at}");
    for line in [
        "  r = [-1, 0, 0]",
        "  v = [-1/sqrt(pi), -2*sqrt(pi), 0]",
        "  a_polar = [-4*pi, 6, 0]",
        "  a_t = 8*pi/sqrt(1 + 4*pi^2)",
        "  a_n = 2*(3 + 4*pi^2)/sqrt(1 + 4*pi^2)",
        "  normal = [2*pi/sqrt(1 + 4*pi^2), -1/sqrt(1 + 4*pi^2), 0]",
    ] {
        assert!(at.contains(line), "missing `{line}` in\n{at}");
    }
}

#[test]
fn curvy_road_maximum_is_exact() {
    let (ok, out, err) = pdyn(&[
        "kin",
        "--path",
        "y = A*sin(2*pi*x/L)",
        "--speed",
        "V",
        "--max",
        "norm(a)",
        "--over",
        "x=0..L",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("max norm(a) over x=0..L: 4*pi^2*A*V^2/L^2 at x = L/4"),
        "{out}"
    );
    // With numbers: the value and the location.
    let (ok, out, err) = pdyn(&[
        "kin",
        "--path",
        "y = A*sin(2*pi*x/L)",
        "--set",
        "A=2,L=50,V=10",
        "--max",
        "norm(a)",
        "--over",
        "x=0..L",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let val = v["max"]["value"].as_f64().unwrap();
    let at = v["max"]["at"].as_f64().unwrap();
    let expect = 2.0 * (2.0 * std::f64::consts::PI * 10.0 / 50.0f64).powi(2);
    assert!((val - expect).abs() < 1e-9 * expect, "{val}");
    assert!((at - 12.5).abs() < 1e-6, "{at}");
}

#[test]
fn cartesian_circle_json() {
    let (ok, out, err) = pdyn(&["kin", "[R*cos(omega*t), R*sin(omega*t), 0]", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["quantities"]["radius"]["text"], "R");
    assert_eq!(v["quantities"]["a_n"]["text"], "R*omega^2");
    assert_eq!(v["quantities"]["speed"]["text"], "R*omega");
}

#[test]
fn parametric_path_with_varying_speed() {
    let (ok, out, err) = pdyn(&[
        "kin",
        "--path",
        "x = R*cos(s), y = R*sin(s)",
        "--param",
        "s",
        "--speed",
        "k*t",
        "--at",
        "s=pi/2, t=2",
        "--set",
        "R=3,k=1.5",
    ]);
    assert!(ok, "{err}");
    // a_t = k = 1.5, a_n = (k t)^2/R = 3.
    assert!(out.contains("  a_t = 3/2"), "{out}");
    assert!(out.contains("  a_n = 3"), "{out}");
    assert!(out.contains("  normal = [0, -1, 0]"), "{out}");
}

#[test]
fn errors_are_clear() {
    let (ok, _, err) = pdyn(&["kin", "[t, t^2"]);
    assert!(!ok);
    assert!(err.contains("<position>:1:"), "{err}");
    let (ok, _, err) = pdyn(&["kin", "t^2"]);
    assert!(!ok);
    assert!(err.contains("vector"), "{err}");
    let (ok, _, err) = pdyn(&["kin", "--polar", "r = 1"]);
    assert!(!ok);
    assert!(err.contains("theta"), "{err}");
    let (ok, _, err) = pdyn(&["kin", "--polar", "r = 1, theta = t", "--at", "phi=1"]);
    assert!(!ok);
    assert!(err.contains("`phi`"), "{err}");
    let (ok, _, err) = pdyn(&["kin", "--polar", "r = 1, theta = sin(t)", "--at", "theta=2"]);
    assert!(!ok);
    assert!(err.contains("never reaches"), "{err}");
    let (ok, _, _) = pdyn(&["kin", "--help"]);
    assert!(ok);
}

/// A negative value given with --set contradicts the positivity assumed while deriving: the
/// derivation is redone without it (issue 11: speed was printed as -6, the tangent against v).
#[test]
fn a_negative_rate_given_later_is_not_assumed_positive() {
    let (ok, out, err) = pdyn(&[
        "kin",
        "[R*cos(omega*t), R*sin(omega*t), 0]",
        "--set",
        "R=2,omega=-3",
        "--at",
        "t=0.5",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let at = &v["at"][0]["values"];
    assert_eq!(at["speed"]["value"][0].as_f64().unwrap(), 6.0);
    let vel: Vec<f64> = (0..3)
        .map(|i| at["v"]["value"][i].as_f64().unwrap())
        .collect();
    let tan: Vec<f64> = (0..3)
        .map(|i| at["tangent"]["value"][i].as_f64().unwrap())
        .collect();
    for i in 0..3 {
        assert!(
            (tan[i] - vel[i] / 6.0).abs() < 1e-12,
            "tangent {tan:?} vs v {vel:?}"
        );
    }
}
