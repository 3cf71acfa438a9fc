//! `pdyn equilibrium` and `pdyn modes`, end to end: JSON, help, errors.

mod common;
use common::pdyn;

fn example(name: &str) -> String {
    format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn modes_of_the_chain_in_json_match_the_closed_form() {
    let (ok, out, err) = pdyn(&[
        "modes",
        &example("chain_modes.toml"),
        "--json",
        "--count",
        "3",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 3);
    for (j, m) in modes.iter().enumerate() {
        let j = (j + 1) as f64;
        let exact = 20.0 * libm::sin(j * std::f64::consts::PI / 62.0);
        let w = m["omega"].as_f64().unwrap();
        assert!((w - exact).abs() < 1e-12 * exact, "{w} vs {exact}");
        let f = m["frequency_hz"].as_f64().unwrap();
        assert!((f - w / std::f64::consts::TAU).abs() < 1e-15 * w);
        assert_eq!(m["shape"].as_array().unwrap().len(), 30);
    }
}

#[test]
fn the_net_hangs_with_its_weight_on_the_two_pins() {
    let (ok, out, err) = pdyn(&["equilibrium", &example("hanging_net.toml"), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let reactions = v["reactions"].as_array().unwrap();
    assert_eq!(reactions.len(), 2);
    // The pins carry the weight of the 23 free nodes, half each by the mirror symmetry
    // x -> (n-1) a - x; their horizontal pulls cancel.
    let weight = 23.0 * 0.05 * 9.81;
    let rz: Vec<f64> = reactions
        .iter()
        .map(|r| r["force"][2].as_f64().unwrap())
        .collect();
    assert!((rz[0] + rz[1] - weight).abs() < 1e-9 * weight, "{rz:?}");
    assert!((rz[0] - rz[1]).abs() < 1e-9 * weight, "{rz:?}");
    let rx: Vec<f64> = reactions
        .iter()
        .map(|r| r["force"][0].as_f64().unwrap())
        .collect();
    assert!((rx[0] + rx[1]).abs() < 1e-9 * weight, "{rx:?}");
    assert!(v["residual"].as_f64().unwrap() < 1e-9);
}

#[test]
fn a_mechanism_is_a_clear_error_with_its_free_directions() {
    let dir = std::env::temp_dir().join(format!("pdyn-statics-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // One mass on a spring along x, under gravity along y: nothing holds it vertically.
    let model = dir.join("mechanism.toml");
    std::fs::write(
        &model,
        r#"gravity = "[0, -g, 0]"
[parameters]
g = 9.81
[coordinates]
x = { initial = 1.0, rate = 0 }
y = { initial = 0.0, rate = 0 }
[points]
O = "[0, 0, 0]"
[particles.p]
mass = 1
position = "[x, y, 0]"
[[forces]]
kind = "spring"
between = ["p", "O"]
k = 10
l0 = 1
length = "x"
direction = "[1, 0, 0]"
"#,
    )
    .unwrap();
    let (ok, out, err) = pdyn(&["equilibrium", model.to_str().unwrap(), "--json"]);
    assert!(!ok);
    assert!(
        err.contains("no equilibrium") && err.contains("+1.000 y"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["error"]["kind"], "statics");
    assert_eq!(v["error"]["exit_code"], 2);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn both_commands_have_help() {
    for cmd in ["equilibrium", "modes"] {
        let (ok, out, _) = pdyn(&[cmd, "--help"]);
        assert!(
            ok && out.contains("--json") && out.contains("--set"),
            "{out}"
        );
    }
}

/// The equilibrium is where damped motion comes to rest: the net with heavier drag run for
/// 60 s ends within 1e-9 m of it, coordinate by coordinate.
#[test]
fn the_equilibrium_is_where_a_long_damped_run_ends() {
    let net = example("hanging_net.toml");
    let (ok, out, err) = pdyn(&["equilibrium", &net, "--set", "c=0.5", "--json"]);
    assert!(ok, "{err}");
    let eq: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (ok, out, err) = pdyn(&[
        "run", &net, "--set", "c=0.5", "--t-end", "60", "--rtol", "1e-12", "--atol", "1e-14",
        "--json",
    ]);
    assert!(ok, "{err}");
    let run: serde_json::Value = serde_json::from_str(&out).unwrap();
    let coordinates = eq["coordinates"].as_array().unwrap();
    assert_eq!(coordinates.len(), 69);
    for c in coordinates {
        let name = c["name"].as_str().unwrap();
        let at_rest = run["final"][name].as_f64().unwrap();
        let q = c["value"].as_f64().unwrap();
        assert!((at_rest - q).abs() < 1e-9, "{name}: {at_rest} vs {q}");
    }
}
