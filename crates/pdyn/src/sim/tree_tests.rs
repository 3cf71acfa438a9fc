//! The recursive (tree) path against the dense projected path it replaces, and the growth of
//! its work: same accelerations to round-off, operations linear in the links.

use super::compiled::CompiledModel;
use super::run_options;
use pdyn_jit::JitMode;
use pdyn_mech::DeriveOptions;
use pdyn_ode::OdeSystem;

/// An n-link chain with unequal masses and lengths, released from `0.3·i` with rates, a
/// drag force on the first particle and a spring from the last one to a fixed point (so
/// that forces depend on velocities and positions, not only gravity).
fn chain(n: usize) -> String {
    let mut s = String::from(
        "name = \"chain\"\ngravity = \"[0, -g, 0]\"\n\n[parameters]\ng = 9.81\nk = 3.0\nc = 0.2\n",
    );
    for i in 1..=n {
        s += &format!(
            "m{i} = {}\nl{i} = {}\n",
            1.0 + 0.1 * i as f64,
            1.0 + 0.05 * i as f64
        );
    }
    s += "\n[coordinates]\n";
    for i in 1..=n {
        let rate = if i % 2 == 0 { 0.1 } else { -0.2 } * i as f64;
        s += &format!("q{i} = {{ initial = {}, rate = {rate} }}\n", 0.3 * i as f64);
    }
    s += "\n[points]\nanchor = \"[2, 0, 0]\"\n";
    for i in 1..=n {
        let pos: Vec<String> = (1..=i)
            .map(|j| format!("l{j}*[sin(q{j}), -cos(q{j}), 0]"))
            .collect();
        s += &format!(
            "\n[particles.p{i}]\nmass = \"m{i}\"\nposition = \"{}\"\n",
            pos.join(" + ")
        );
    }
    s += &format!(
        "\n[[forces]]\nkind = \"drag\"\non = \"p1\"\ncoefficient = \"c\"\n\n[[forces]]\nkind = \"spring\"\nname = \"tether\"\nbetween = [\"p{n}\", \"anchor\"]\nk = \"k\"\nl0 = \"1\"\n"
    );
    s
}

/// A branching, spatial tree: a root pendulum swinging in the x-y plane, two pendulums
/// hanging from it (one in the x-y plane, one in the y-z plane), a third from the second.
const MOBILE: &str = r#"
name = "mobile"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
[coordinates]
a = { initial = 0.4, rate = 0.3 }
b = { initial = -0.7, rate = 1.1 }
c = { initial = 1.2, rate = -0.5 }
d = { initial = 0.2, rate = 0.9 }
[particles.root]
mass = "2"
position = "[sin(a), -cos(a), 0]"
[particles.left]
mass = "1"
position = "[sin(a), -cos(a), 0] + 0.7*[sin(b), -cos(b), 0]"
[particles.right]
mass = "1.5"
position = "[sin(a), -cos(a), 0] + 0.9*[0, -cos(c), sin(c)]"
[particles.tip]
mass = "0.5"
position = "[sin(a), -cos(a), 0] + 0.9*[0, -cos(c), sin(c)] + 0.4*[sin(d), -cos(d), 0]"
"#;

fn compiled(source: &str, tree: bool) -> (CompiledModel, Vec<f64>) {
    let mut model = pdyn_mech::load(source, "test.toml").unwrap();
    let opts = DeriveOptions {
        tree_from: tree.then_some(1),
        ..run_options()
    };
    let d = pdyn_mech::derive(&mut model, &opts).unwrap();
    assert_eq!(d.tree.is_some(), tree);
    let sys = CompiledModel::with_jit(&mut model, &d, JitMode::Off).unwrap();
    let mut y0 = Vec::new();
    for c in &model.coordinates {
        if let pdyn_mech::model::CoordinateKind::Free { initial, .. } = c.kind {
            y0.push(initial);
        }
    }
    for c in &model.coordinates {
        if let pdyn_mech::model::CoordinateKind::Free { rate, .. } = c.kind {
            y0.push(rate);
        }
    }
    (sys, y0)
}

/// The largest difference between the two paths' accelerations, relative to the largest
/// acceleration, at the initial state and at two others.
fn disagreement(source: &str) -> f64 {
    let (tree, y0) = compiled(source, true);
    let (dense, _) = compiled(source, false);
    assert!(tree.is_tree() && !dense.is_tree());
    let n = y0.len();
    let mut worst: f64 = 0.0;
    for (t, shift) in [(0.0, 0.0), (1.3, 0.7), (2.0, -2.1)] {
        let y: Vec<f64> = y0
            .iter()
            .enumerate()
            .map(|(i, &v)| v + shift * libm::sin((i as f64) * 0.37))
            .collect();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        tree.rhs(t, &y, &mut a);
        dense.rhs(t, &y, &mut b);
        let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (x, z) in a.iter().zip(&b) {
            assert!(x.is_finite() && z.is_finite());
            worst = worst.max((x - z).abs() / scale);
        }
    }
    worst
}

#[test]
fn tree_path_gives_the_dense_paths_accelerations_on_chains_2_to_100() {
    for n in [2, 3, 4, 5, 6, 7, 8, 10, 13, 16, 24, 32, 48, 64, 100] {
        let e = disagreement(&chain(n));
        // Cholesky on M loses digits as the chain's M grows ill-conditioned; the bound is
        // round-off times a modest condition number, far below any tolerance a run uses.
        eprintln!("n = {n}: relative disagreement {e:e}");
        assert!(e < 1e-11, "n = {n}: relative disagreement {e:e}");
    }
}

/// The chains above run the recursion in the plane, the mobile below in space: the
/// dense-path comparisons cover both.
#[test]
fn chains_in_the_plane_are_planar_trees_and_the_mobile_is_not() {
    let planar = |source: &str| {
        let mut model = pdyn_mech::load(source, "t.toml").unwrap();
        let opts = DeriveOptions {
            tree_from: Some(1),
            ..run_options()
        };
        let d = pdyn_mech::derive(&mut model, &opts).unwrap();
        d.tree.map(|t| t.is_planar())
    };
    assert_eq!(planar(&chain(5)), Some(true));
    assert_eq!(planar(MOBILE), Some(false));
}

#[test]
fn tree_path_gives_the_dense_paths_accelerations_on_a_branching_spatial_tree() {
    let e = disagreement(MOBILE);
    assert!(e < 1e-13, "relative disagreement {e:e}");
}

#[test]
fn tree_is_used_by_runs_from_four_links_and_not_for_other_models() {
    for (n, tree) in [(3, false), (4, true), (16, true)] {
        let mut model = pdyn_mech::load(&chain(n), "c.toml").unwrap();
        let prep = super::prepare(&mut model).unwrap();
        assert_eq!(prep.system.is_tree(), tree, "n = {n}");
    }
    // A particle in Cartesian coordinates is no link; nor are constrained models.
    let cartesian = "name = \"b\"\ngravity = \"[0, -g, 0]\"\n[parameters]\ng = 9.81\n\
        [coordinates]\nx = { initial = 0, rate = 1 }\ny = { initial = 0, rate = 1 }\n\
        [particles.p]\nmass = \"1\"\nposition = \"[x, y, 0]\"\n";
    let mut model = pdyn_mech::load(cartesian, "b.toml").unwrap();
    let d = pdyn_mech::derive(
        &mut model,
        &DeriveOptions {
            tree_from: Some(1),
            ..run_options()
        },
    )
    .unwrap();
    assert!(d.tree.is_none());
}

#[test]
fn tree_evaluation_ops_grow_linearly_in_the_links() {
    let ops = |n: usize| {
        let (sys, y0) = compiled(&chain(n), true);
        sys.tree_evaluation_ops(0.0, &y0).unwrap()
    };
    let (o10, o20, o40, o80) = (ops(10), ops(20), ops(40), ops(80));
    eprintln!("operations per evaluation: n = 10: {o10}, 20: {o20}, 40: {o40}, 80: {o80}");
    // Equal increments for equal steps in n: a + b n, no n² term (the dense path's M alone
    // has n² entries, its Cholesky n³/6 multiply-adds).
    let (d1, d2, d3) = (o20 - o10, (o40 - o20) / 2, (o80 - o40) / 4);
    assert!(
        d1 > 0 && d1.abs_diff(d2) * 50 <= d1 && d2.abs_diff(d3) * 50 <= d2,
        "{o10} {o20} {o40} {o80}"
    );
    assert!(o80 < 80 * 200, "{o80} operations at n = 80");
}

/// An n-link chain under gravity alone, with unequal masses and lengths, released from rest
/// at `0.3·i`: its energy is monitored (output columns and scales).
pub(super) fn released_chain(n: usize) -> String {
    let mut src = String::from("name = \"c\"\ngravity = \"[0, -g, 0]\"\n[parameters]\ng = 9.81\n");
    src += "[coordinates]\n";
    for i in 1..=n {
        src += &format!("q{i} = {{ initial = {}, rate = 0.0 }}\n", 0.3 * i as f64);
    }
    for i in 1..=n {
        let pos: Vec<String> = (1..=i)
            .map(|j| format!("{}*[sin(q{j}), -cos(q{j}), 0]", 1.0 + 0.1 * j as f64))
            .collect();
        src += &format!(
            "[particles.p{i}]\nmass = \"{}\"\nposition = \"{}\"\n",
            1.0 + 0.2 * i as f64,
            pos.join(" + ")
        );
    }
    src
}

/// A long run's table, whose output columns and conservation scales run as native code
/// (from [`super::compiled::NATIVE_PAYS_FROM`] rows) on inputs without the solved unknowns
/// (they read none), holds the bits the interpreter gives on the solved observation inputs,
/// row by row, and the same energy scale.
#[test]
fn long_tables_give_the_interpreters_bits_without_the_unknowns() {
    let n = 5;
    let src = released_chain(n);
    let mut model = pdyn_mech::load(&src, "c.toml").unwrap();
    let prep = super::prepare(&mut model).unwrap();
    assert!(prep.system.is_tree());
    let base = prep.system.inputs.len();
    assert!(prep.observer.reads_only_first(base) && prep.scales.reads_only_first(base));
    assert!(!prep.scales.is_empty(), "the chain's energy is conserved");
    let rows = super::compiled::NATIVE_PAYS_FROM + 1;
    // The switch the table relies on, on either side of the threshold.
    assert!(prep.observer.native_for(rows - 2).is_none());
    assert!(prep.observer.native_for(rows).is_some());
    let set = super::RunSettings {
        method: "dop853".into(),
        t_end: 3.0,
        rtol: Some(1e-9),
        atol: Some(1e-12),
        dt: None,
        max_step: None,
        max_steps: None,
        points: Some(rows),
        output_dt: None,
        t_eval: None,
        drift_tolerance: super::DEFAULT_DRIFT_TOLERANCE,
        interrupt: None,
    };
    let res = super::run(&prep, &set).unwrap();
    assert_eq!(res.rows.len(), rows);
    let (mut input, mut extra) = (Vec::new(), vec![0.0; prep.observer.len()]);
    let mut scale_series = vec![Vec::new(); prep.scales.len()];
    let mut scale_out = vec![0.0; prep.scales.len()];
    for row in &res.rows {
        let (t, y) = (row[0], &row[1..1 + 2 * n]);
        prep.system.observation_input(t, y, &mut input);
        assert!(
            input[base..].iter().all(|x| x.is_finite()),
            "solved unknowns"
        );
        prep.observer.eval(&input, &mut extra);
        for (a, b) in row[1 + 2 * n..].iter().zip(&extra) {
            assert_eq!(a.to_bits(), b.to_bits(), "t = {t}: {a} vs {b}");
        }
        prep.scales.eval(&input, &mut scale_out);
        for (s, v) in scale_series.iter_mut().zip(&scale_out) {
            s.push(v.abs());
        }
    }
    let expected: Vec<f64> = scale_series.into_iter().map(super::scale_of).collect();
    let got: Vec<f64> = res.monitors.iter().map(|m| m.scale).collect();
    assert_eq!(got, expected);
}
