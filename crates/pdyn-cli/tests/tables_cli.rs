//! Families read from node and element tables (`[tables.NAME]`, issue 33), end to end: the
//! truss of `examples/truss_tables.toml` against the method of joints, and the hanging net
//! read from tables against the index-range net, bit for bit.

mod common;
use common::pdyn;

fn example(name: &str) -> String {
    format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// The cantilever of `examples/truss_tables.toml` (nodes 10 (0,0) and 40 (0,1) pinned, 20
/// (1,0), 30 (2,0), 50 (1,1) free; P down at 30), by the method of joints. Joint 30: the bar
/// 50-30 along (-1,1)/√2 carries the load, T/√2 = P, so T = √2 P, and 20-30 balances its x
/// pull: -P. Joint 20: 10-20 = 20-30 = -P, and the vertical 20-50 carries nothing. Joint 50:
/// y: -(√2 P)/√2 - T(10-50)/√2 = 0, so 10-50 = -√2 P; x: -T(40-50) + P + P = 0, so 40-50 = 2P.
fn method_of_joints(p: f64) -> [(&'static str, f64); 6] {
    let r2 = std::f64::consts::SQRT_2;
    [
        ("(N[10], N[20])", -p),
        ("(N[20], N[30])", -p),
        ("(N[40], N[50])", 2.0 * p),
        ("(N[50], N[30])", r2 * p),
        ("(N[10], N[50])", -r2 * p),
        ("(N[20], N[50])", 0.0),
    ]
}

/// The largest difference between `pdyn equilibrium`'s bar forces and the method of joints',
/// relative to the load, with the tip load `p`; and the reactions' sum against the load.
fn worst_bar_error(p: f64) -> f64 {
    let (ok, out, err) = pdyn(&[
        "equilibrium",
        &example("truss_tables.toml"),
        "--set",
        &format!("P={p}"),
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let bars = v["axial_forces"].as_array().unwrap();
    assert_eq!(bars.len(), 6);
    let mut worst: f64 = 0.0;
    for (ends, exact) in method_of_joints(p) {
        let bar = bars
            .iter()
            .find(|b| b["element"].as_str().unwrap().ends_with(ends))
            .unwrap_or_else(|| panic!("bar {ends} in {bars:?}"));
        let got = bar["tension"].as_f64().unwrap();
        if exact != 0.0 {
            assert_eq!(got.signum(), exact.signum(), "{ends}: {got} vs {exact}");
        }
        worst = worst.max((got - exact).abs() / p);
    }
    // The two pins hold the load: their reactions sum to [0, P, 0].
    let reactions = v["reactions"].as_array().unwrap();
    assert_eq!(reactions.len(), 2);
    let (mut rx, mut ry) = (0.0, 0.0);
    for r in reactions {
        rx += r["force"][0].as_f64().unwrap();
        ry += r["force"][1].as_f64().unwrap();
    }
    worst.max(rx.abs() / p).max((ry - p).abs() / p)
}

#[test]
fn the_table_truss_has_the_bar_forces_of_the_method_of_joints() {
    // EA = 2e8 N: the strain P/EA is 5e-5 and the bar forces differ from the linear,
    // undeformed-geometry answer by about that; a 100 times smaller load, 100 times less.
    let steel = worst_bar_error(1.0e4);
    let light = worst_bar_error(1.0e2);
    assert!(steel < 1e-3, "P = 1e4: {steel:e}");
    assert!(light < 1e-5, "P = 1e2: {light:e}");
    assert!(light < steel / 30.0, "{steel:e} then {light:e}");
}

/// `pdyn run` of the net read from tables writes the index-range net's trajectory, byte for
/// byte (the same coordinates, in the same order, from the same expressions).
#[test]
fn the_table_net_runs_as_the_index_range_net_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("pdyn_tables_cli_{}", std::process::id()));
    let run = |model: &str, out: &str| -> String {
        let out = dir.join(out);
        let (ok, _, err) = pdyn(&["run", &example(model), "--out", out.to_str().unwrap()]);
        assert!(ok, "{err}");
        std::fs::read_to_string(out.join("trajectory.csv")).unwrap()
    };
    let ranges = run("hanging_net.toml", "ranges");
    let tables = run("hanging_net_tables.toml", "tables");
    assert!(ranges.lines().count() > 200);
    assert!(ranges == tables, "the trajectories differ");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The fields of one CSV line as RFC 4180 reads them: a quoted field may hold commas, `""` is
/// a quote. Written here from the RFC, not taken from pdyn's reader.
fn rfc4180_fields(line: &str) -> Vec<String> {
    let (mut out, mut field, mut quoted, mut chars) =
        (Vec::new(), String::new(), false, line.chars().peekable());
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    out.push(field);
    out
}

/// A family's members are named `x[1,2]`: the trajectory's header must quote them, or every
/// CSV reader splits one name into two columns and shifts every column after it.
#[test]
fn family_columns_are_one_csv_field_each() {
    let dir = std::env::temp_dir().join(format!("pdyn-family-csv-{}", std::process::id()));
    let (ok, _, err) = pdyn(&[
        "run",
        &example("hanging_net.toml"),
        "--t-end",
        "0.01",
        "--points",
        "3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let mut lines = text.lines();
    let names = rfc4180_fields(lines.next().unwrap());
    let row = rfc4180_fields(lines.next().unwrap());
    assert_eq!(names.len(), row.len(), "header {names:?}");
    // 23 free particles, 3 coordinates and 3 rates each, after `t`.
    assert_eq!(names[0], "t");
    assert!(names.iter().any(|n| n == "x[1,2]"), "{names:?}");
    assert!(names.iter().any(|n| n == "z[4,4]'"), "{names:?}");
    assert_eq!(names.iter().filter(|n| n.starts_with("x[")).count(), 2 * 23);
}
