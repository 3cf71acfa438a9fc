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

type Curve = fn(f64) -> [f64; 3];

/// Where the speed is zero the tangent (and the normal, curvature, a_t, a_n) is undefined:
/// it was printed as `[0, 0, 0]` or NaN. `kin` now says so and gives the limit of the tangent
/// as t increases to the instant, which here is checked against the direction of the velocity
/// just after it, `v(t0 + h)/|v(t0 + h)|` from the velocity written by hand; "reverses" is
/// checked against the direction just before; the limits of a_t and a_n against `a·T` and
/// `|a − (a·T)T|` at t0 + h.
#[test]
fn at_zero_speed_the_tangent_is_undefined_and_its_limit_is_given() {
    let cases: Vec<(&str, &str, f64, Curve, Curve)> = vec![
        (
            "[t^2, t^3, 0]",
            "t=0",
            0.0,
            |t| [2.0 * t, 3.0 * t * t, 0.0],
            |t| [2.0, 6.0 * t, 0.0],
        ),
        (
            "[t^3, 2*t^3, 0]",
            "t=0",
            0.0,
            |t| [3.0 * t * t, 6.0 * t * t, 0.0],
            |t| [6.0 * t, 12.0 * t, 0.0],
        ),
        (
            "[t - sin(t), 1 - cos(t), 0]",
            "t=2*pi",
            2.0 * std::f64::consts::PI,
            |t| [1.0 - libm::cos(t), libm::sin(t), 0.0],
            |t| [libm::sin(t), libm::cos(t), 0.0],
        ),
        (
            "[(t-1)^2, 3*(t-1)^2, (t-1)^3]",
            "t=1",
            1.0,
            |t| [2.0 * (t - 1.0), 6.0 * (t - 1.0), 3.0 * (t - 1.0).powi(2)],
            |t| [2.0, 6.0, 6.0 * (t - 1.0)],
        ),
        (
            "[2 + (t-1)^5, -(t-1)^5, 3]",
            "t=1",
            1.0,
            |t| [5.0 * (t - 1.0).powi(4), -5.0 * (t - 1.0).powi(4), 0.0],
            |t| [20.0 * (t - 1.0).powi(3), -20.0 * (t - 1.0).powi(3), 0.0],
        ),
    ];
    let unit = |v: [f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / n)
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for (r, at, t0, v, a) in cases {
        let (ok, out, err) = pdyn(&["kin", r, "--at", at, "--json"]);
        assert!(ok, "{r}: {err}");
        let j: serde_json::Value = serde_json::from_str(&out).unwrap();
        let i = &j["at"][0];
        for name in ["tangent", "normal", "curvature", "radius", "a_t", "a_n"] {
            assert!(
                i["undefined"][name].is_string(),
                "{r}: {name} not undefined: {i}"
            );
            assert!(
                i["values"][name].is_null(),
                "{r}: {name} still has a value: {i}"
            );
        }
        let h = 1e-4;
        let after = unit(v(t0 + h));
        let before = unit(v(t0 - h));
        let limit: Vec<f64> = i["at_rest"]["tangent"]["value"]
            .as_array()
            .unwrap_or_else(|| panic!("{r}: no limiting tangent: {i}"))
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let limit = [limit[0], limit[1], limit[2]];
        assert!(
            dot(limit, after) > 1.0 - 1e-6,
            "{r}: {limit:?} vs {after:?}"
        );
        assert_eq!(
            i["at_rest"]["reverses"].as_bool().unwrap(),
            dot(before, after) < 0.0,
            "{r}: {i}"
        );
        let (aa, tt) = (a(t0 + 1e-7), unit(v(t0 + 1e-7)));
        let at_ = dot(aa, tt);
        let an = (0..3)
            .map(|k| (aa[k] - at_ * tt[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let got_at = i["at_rest"]["a_t"].as_f64().unwrap();
        let got_an = i["at_rest"]["a_n"].as_f64().unwrap();
        assert!(
            (got_at - at_).abs() < 1e-3 * (1.0 + at_.abs()),
            "{r}: a_t {got_at} vs {at_}"
        );
        assert!(
            (got_an - an).abs() < 1e-3 * (1.0 + an.abs()),
            "{r}: a_n {got_an} vs {an}"
        );
        // The text says it too.
        let (_, text, _) = pdyn(&["kin", r, "--at", at]);
        assert!(text.contains("undefined — the point is at rest"), "{text}");
        assert!(text.contains("limiting tangent as t increases"), "{text}");
        assert!(!text.contains("NaN"), "{text}");
    }
    // Every derivative tried is zero: said so.
    let (ok, text, err) = pdyn(&["kin", "[(t-1)^9, 0, 0]", "--at", "t=1"]);
    assert!(ok, "{err}");
    assert!(text.contains("no limiting tangent found"), "{text}");
    // Moving: nothing undefined. Through the origin: only the polar components are.
    let (_, out, _) = pdyn(&["kin", "[cos(t), sin(t), 0]", "--at", "t=1", "--json"]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(j["at"][0]["undefined"].is_null(), "{out}");
    assert!(j["at"][0]["values"]["tangent"].is_object(), "{out}");
    let (_, out, _) = pdyn(&["kin", "[1 + cos(t), sin(t), 0]", "--at", "t=pi", "--json"]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let i = &j["at"][0];
    assert!(
        i["values"]["tangent"].is_object() && i["values"]["a_n"].is_object(),
        "{i}"
    );
    assert!(i["undefined"]["e_r"].is_string(), "{i}");
    assert!(i["at_rest"].is_null(), "{i}");
}
