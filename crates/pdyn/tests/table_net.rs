//! Compact loading (`load_deferring`, issue 33) of force families read from node and element
//! tables (`[tables.NAME]`): a spring family whose fields are the same for every row is
//! deferred and runs as the expanded model does; one whose stiffness is a column (the FE case,
//! `k` per element) is built in full, never deferred, and is the same model as a full load.

use pdyn::sim::{self, NetPath};
use pdyn_jit::JitMode;
use pdyn_mech::Model;
use pdyn_ode::OdeSystem;
use std::path::{Path, PathBuf};

mod common;
use common::max_relative_difference;

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// `text` loaded as if it were the file `origin` (its tables are read beside it).
fn load(text: &str, origin: &Path, deferring: bool) -> Model {
    let origin = origin.display().to_string();
    let m = if deferring {
        pdyn_mech::model::load_deferring(text, &origin)
    } else {
        pdyn_mech::model::load(text, &origin)
    };
    m.unwrap_or_else(|e| panic!("{}", e.render(text)))
}

fn prepared(model: &mut Model, path: NetPath) -> sim::Prepared {
    sim::prepare_on(model, &sim::run_options(), JitMode::Auto, path).unwrap()
}

/// A state away from the initial one: every coordinate moved and moving.
fn perturbed(y0: &[f64]) -> Vec<f64> {
    y0.iter()
        .enumerate()
        .map(|(k, &v)| v + 0.01 * libm::sin(1.7 * k as f64 + 0.3))
        .collect()
}

fn rhs(p: &sim::Prepared, y: &[f64]) -> Vec<f64> {
    let mut f = vec![0.0; p.system.dim()];
    p.system.rhs(0.0, y, &mut f);
    f
}

#[test]
fn a_table_spring_family_of_one_stiffness_is_deferred_and_agrees_with_the_expanded_one() {
    let path = examples().join("hanging_net_tables.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut deferred = load(&text, &path, true);
    // Four spring families and the drag, each a representative and its other rows: all but
    // the springs that reach a pinned corner (2 horizontal, 2 vertical, 1 diagonal, 1
    // antidiagonal: a point is no particle), built as any force.
    assert!(deferred.has_deferred());
    let members: Vec<usize> = deferred.deferred.iter().map(|d| d.len()).collect();
    assert_eq!(members, [17, 17, 14, 14, 22]);
    let fast = prepared(&mut deferred, NetPath::Always);
    let mut full = load(&text, &path, false);
    let full_fast = prepared(&mut full, NetPath::Always);
    let mut full = load(&text, &path, false);
    let generic = prepared(&mut full, NetPath::Never);
    assert_eq!(fast.state_names, generic.state_names);
    assert_eq!(fast.y0, generic.y0);
    for y in [generic.y0.clone(), perturbed(&generic.y0)] {
        // The deferred members stand where the expanded ones do: the same bits.
        assert_eq!(rhs(&fast, &y), rhs(&full_fast, &y));
        let d = max_relative_difference(&rhs(&generic, &y), &rhs(&fast, &y));
        assert!(d < 1e-13, "the generic derivation differs by {d:e}");
    }
}

/// The net's tables with each spring's stiffness in a column `k` (400 structural, 100
/// diagonal, as the parameters `k` and `kd` are): the families are expanded, and the model is
/// the one with the stiffness parameters, to round-off.
#[test]
fn a_table_spring_family_with_a_stiffness_column_is_built_in_full() {
    let dir = std::env::temp_dir().join(format!("pdyn_table_net_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(examples().join("net_nodes.csv"), dir.join("net_nodes.csv")).unwrap();
    let springs = std::fs::read_to_string(examples().join("net_springs.csv")).unwrap();
    let mut with_k = String::new();
    for line in springs.lines() {
        if line.starts_with('#') {
            continue;
        }
        let k = match line.split(',').next().unwrap() {
            "family" => "k",
            "0" | "1" => "400",
            _ => "100",
        };
        with_k.push_str(&format!("{line},{k}\n"));
    }
    std::fs::write(dir.join("net_springs.csv"), with_k).unwrap();
    let path = dir.join("net.toml");
    let original = std::fs::read_to_string(examples().join("hanging_net_tables.toml")).unwrap();
    let text = original
        .replace("k = \"k\"\n", "k = \"springs_k\"\n")
        .replace("k = \"kd\"\n", "k = \"springs_k\"\n");
    assert_eq!(text.matches("springs_k").count(), 4);
    let mut deferred = load(&text, &path, true);
    // Only the drag (its `c` the same for every row) is deferred; every spring is built.
    assert_eq!(deferred.deferred.len(), 1);
    assert_eq!(deferred.deferred[0].family, "drag");
    assert_eq!(deferred.axial.len(), 72);
    let fast = prepared(&mut deferred, NetPath::Always);
    let mut reference = load(
        &original,
        &examples().join("hanging_net_tables.toml"),
        false,
    );
    let generic = prepared(&mut reference, NetPath::Never);
    assert_eq!(fast.state_names, generic.state_names);
    for y in [generic.y0.clone(), perturbed(&generic.y0)] {
        let d = max_relative_difference(&rhs(&generic, &y), &rhs(&fast, &y));
        assert!(d < 1e-13, "the stiffness column's model differs by {d:e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
