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
    assert_at_rest_where_a_damped_run_ends(&net, &eq, 69);
}

/// The sparse path (issue 33): the lowest 10 of a 1,000-mass chain, the model the example with
/// its family's size changed, against ω_j = 2 sqrt(k/m) sin(jπ/(2(n+1))).
#[test]
fn the_lowest_modes_of_a_thousand_mass_chain_by_the_sparse_solver() {
    let dir = std::env::temp_dir().join(format!("pdyn-sparse-modes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("chain1000.toml");
    let text = std::fs::read_to_string(example("chain_modes.toml")).unwrap();
    std::fs::write(&model, text.replacen("n = 30", "n = 1000", 1)).unwrap();
    let (ok, out, err) = pdyn(&["modes", model.to_str().unwrap(), "--count", "10", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["solver"], "sparse");
    assert_eq!(v["coordinate_count"], 1000);
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 10);
    for (j, m) in modes.iter().enumerate() {
        let exact = 20.0 * libm::sin((j + 1) as f64 * std::f64::consts::PI / 2002.0);
        let w = m["omega"].as_f64().unwrap();
        assert!(
            (w - exact).abs() < 1e-12 * exact,
            "mode {}: {w} vs {exact}",
            j + 1
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The net's drag is c on each particle of mass m: C = (c/m) M, so every mode is damped with
/// ζ ω = c / (2 m) = 0.2 1/s, and ω_n is the undamped ω.
#[test]
fn the_damped_modes_of_the_net_follow_from_mass_proportional_drag() {
    let (ok, out, err) = pdyn(&[
        "modes",
        &example("hanging_net.toml"),
        "--count",
        "8",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let undamped = v["modes"].as_array().unwrap();
    let damped = v["damped_modes"].as_array().unwrap();
    assert_eq!(damped.len(), 8);
    // Classical damping: from the undamped modes, no companion form (issue 33).
    assert_eq!(v["damped_path"], "classical");
    assert!(v["damping_commutation_defect"].as_f64().unwrap() < 1e-12);
    for (d, u) in damped.iter().zip(undamped) {
        let wn = d["natural_frequency"].as_f64().unwrap();
        let zeta = d["damping_ratio"].as_f64().unwrap();
        let w = u["omega"].as_f64().unwrap();
        assert!((wn - w).abs() < 1e-9 * w, "{wn} vs {w}");
        assert!((zeta * wn - 0.2).abs() < 1e-9, "{zeta} {wn}");
        let wd = d["damped_frequency"].as_f64().unwrap();
        assert!((wd - wn * (1.0 - zeta * zeta).sqrt()).abs() < 1e-9 * wn);
    }
}

#[test]
fn a_count_of_zero_is_refused() {
    let (ok, _, err) = pdyn(&["modes", &example("chain_modes.toml"), "--count", "0"]);
    assert!(!ok && err.contains("--count"), "{err}");
}

/// The Warren truss of `examples/truss.toml` against the method of joints (θ = 60°, load P
/// at the lower chord's middle, pin A, roller B): AD = EB = −P/(2 sin θ), AC = CB =
/// P/(2 tan θ), DC = EC = P/(2 sin θ), DE = −P/tan θ, the pin's reaction [0, P/2]. The bars
/// are springs of stiffness EA/a, so the equilibrium differs from the rigid-bar statics by
/// the change of geometry, of order P/EA: about 3e-5 at steel's EA, 100 times less at 100
/// times the stiffness, and the forces tend to the method of joints'.
#[test]
fn the_trusss_bar_forces_tend_to_the_method_of_joints() {
    let p = 1.0e4;
    let (s, t) = (
        libm::sin(std::f64::consts::PI / 3.0),
        libm::tan(std::f64::consts::PI / 3.0),
    );
    let joints = [
        ("AC", p / (2.0 * t)),
        ("CB", p / (2.0 * t)),
        ("AD", -p / (2.0 * s)),
        ("DC", p / (2.0 * s)),
        ("DE", -p / t),
        ("EC", p / (2.0 * s)),
        ("EB", -p / (2.0 * s)),
    ];
    let worst = |ea: &str| -> f64 {
        let (ok, out, err) = pdyn(&[
            "equilibrium",
            &example("truss.toml"),
            "--set",
            &format!("EA={ea}"),
            "--json",
        ]);
        assert!(ok, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let bars = v["axial_forces"].as_array().unwrap();
        assert_eq!(bars.len(), 7);
        let mut worst: f64 = 0.0;
        for (name, exact) in joints {
            let bar = bars
                .iter()
                .find(|b| {
                    b["element"]
                        .as_str()
                        .unwrap()
                        .starts_with(&format!("{name} ("))
                })
                .unwrap_or_else(|| panic!("bar {name} in {bars:?}"));
            let got = bar["tension"].as_f64().unwrap();
            assert_eq!(got.signum(), exact.signum(), "{name}: {got} vs {exact}");
            worst = worst.max((got - exact).abs() / p);
        }
        let r = &v["reactions"][0]["force"];
        worst = worst
            .max(r[0].as_f64().unwrap().abs() / p)
            .max((r[1].as_f64().unwrap() - p / 2.0).abs() / p);
        worst
    };
    let steel = worst("2e8");
    let stiff = worst("2e10");
    assert!(steel < 1e-4, "steel: {steel:e}");
    assert!(stiff < 1e-6, "100x stiffer: {stiff:e}");
    // The difference is the geometry's change, of order P/EA: it falls with the stiffness.
    assert!(stiff < steel / 30.0, "{steel:e} then {stiff:e}");
}

/// The sparse path's equilibrium (issue 33: 357 coordinates, the envelope `L D Lᵀ`, steps that
/// lower the energy) is where damped motion comes to rest too: an 11 × 11 hanging net with
/// heavier drag run for 60 s ends within 1e-9 m of it, coordinate by coordinate; and Newton
/// gets there from the flat start in few steps (85 when each step had to lower `|f|`).
#[test]
fn the_sparse_equilibrium_of_a_larger_net_is_where_a_damped_run_ends() {
    let dir = std::env::temp_dir().join(format!("pdyn-net11-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = std::fs::read_to_string(example("hanging_net.toml")).unwrap();
    assert!(src.contains("\nn = 5 "));
    let net = dir.join("net11.toml");
    std::fs::write(&net, src.replace("\nn = 5 ", "\nn = 11 ")).unwrap();
    let net = net.to_str().unwrap();
    let (ok, out, err) = pdyn(&["equilibrium", net, "--set", "c=0.5", "--json"]);
    assert!(ok, "{err}");
    let eq: serde_json::Value = serde_json::from_str(&out).unwrap();
    let steps = eq["steps"].as_u64().unwrap();
    assert!(steps <= 25, "{steps} Newton steps");
    assert_at_rest_where_a_damped_run_ends(net, &eq, 357);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every coordinate of `pdyn equilibrium`'s JSON `eq` (there are `count`) within 1e-9 of where
/// a 60 s run of `net` with drag c = 0.5 (tight tolerances) ends.
fn assert_at_rest_where_a_damped_run_ends(net: &str, eq: &serde_json::Value, count: usize) {
    let (ok, out, err) = pdyn(&[
        "run", net, "--set", "c=0.5", "--t-end", "60", "--rtol", "1e-12", "--atol", "1e-14",
        "--json",
    ]);
    assert!(ok, "{err}");
    let run: serde_json::Value = serde_json::from_str(&out).unwrap();
    let coordinates = eq["coordinates"].as_array().unwrap();
    assert_eq!(coordinates.len(), count);
    for c in coordinates {
        let name = c["name"].as_str().unwrap();
        let at_rest = run["final"][name].as_f64().unwrap();
        let q = c["value"].as_f64().unwrap();
        assert!((at_rest - q).abs() < 1e-9, "{name}: {at_rest} vs {q}");
    }
}

/// `pdyn modes --json` is written token by token (`cli/modes_json.rs`), not through a
/// `serde_json::Value`: its text must be exactly what serde_json's pretty printer gives for
/// the same document (keys sorted, numbers, NaN as null, escapes), with and without damped
/// modes and on both solvers.
#[test]
fn modes_json_is_serde_jsons_pretty_text() {
    let net = example("hanging_net.toml");
    let chain = example("chain_modes.toml");
    for args in [
        vec!["modes", chain.as_str(), "--json"],
        vec![
            "modes",
            chain.as_str(),
            "--json",
            "--solver",
            "sparse",
            "--count",
            "4",
        ],
        vec!["modes", net.as_str(), "--json"],
        vec![
            "modes",
            net.as_str(),
            "--json",
            "--solver",
            "sparse",
            "--count",
            "6",
        ],
    ] {
        let (ok, out, err) = pdyn(&args);
        assert!(ok, "{args:?}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let again = serde_json::to_string_pretty(&v).unwrap();
        assert_eq!(out.trim_end(), again, "{args:?}");
    }
}
