//! Families read from node and element tables (`[tables.NAME]`, issue 33): the hanging net
//! read from CSV tables is the index-range net, member for member; keyed node ids, columns as
//! numbers and as indices; and every bad table is an error located in the model file that
//! names the table's file, line and column.

use pdyn_mech::model::{load_file, Model, Target};
use std::path::{Path, PathBuf};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

fn loaded(path: &Path) -> Model {
    load_file(path).unwrap_or_else(|e| {
        let src = std::fs::read_to_string(path).unwrap();
        panic!("{}", e.render(&src))
    })
}

/// A directory of its own for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pdyn_row_tables_{test}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The error of loading `model` with the files `files` beside it, rendered (`file:line:col:
/// error: ...`, the line, a caret, the help).
fn table_error(test: &str, model: &str, files: &[(&str, &str)]) -> String {
    let dir = scratch(test);
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("model.toml");
    std::fs::write(&path, model).unwrap();
    let out = match load_file(&path) {
        Ok(_) => panic!("expected an error for:\n{model}"),
        Err(e) => e.render(model),
    };
    let _ = std::fs::remove_dir_all(&dir);
    out
}

/// The line and column (1-based) at which `needle` starts in `text`.
fn line_col_of(text: &str, needle: &str) -> (usize, usize) {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("`{needle}` in {text}"));
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |p| p + 1) + 1;
    (line, col)
}

/// Asserts the rendered error points at `needle` in `model` (its first character).
fn assert_at(err: &str, model: &str, needle: &str) {
    let (line, col) = line_col_of(model, needle);
    assert!(
        err.contains(&format!("model.toml:{line}:{col}:")),
        "expected the error at {line}:{col} (`{needle}`):\n{err}"
    );
}

/// What a model is made of, printed, without the labels of loads and potentials (a member of
/// a family over table rows is labelled by its row, `horizontal[e=3]`, one over index ranges
/// by its indices, `horizontal[i=0, j=3]`).
fn made_of(m: &Model) -> Vec<String> {
    let p = &m.pool;
    let mut out = Vec::new();
    for par in &m.parameters {
        out.push(format!("parameter {} = {}", par.name, par.value));
    }
    for c in &m.coordinates {
        out.push(format!("coordinate {} {:?}", c.name, c.kind));
    }
    for (i, _, _) in &m.initial_exprs {
        out.push(format!("initial of {}", m.coordinates[*i].name));
    }
    for (name, r) in &m.points {
        out.push(format!("point {name} {:?}", r.map(|c| p.to_text(c))));
    }
    for q in &m.particles {
        let r = q.position.map(|c| p.to_text(c));
        out.push(format!("particle {} {} {r:?}", q.name, p.to_text(q.mass)));
    }
    for l in &m.loads {
        let target = match l.target {
            Target::Particle(i) => m.particles[i].name.clone(),
            _ => "frame".to_string(),
        };
        out.push(format!(
            "load on {target}: {:?}",
            l.force.map(|c| p.to_text(c))
        ));
    }
    for v in &m.potentials {
        out.push(format!("potential {}", p.to_text(v.energy)));
    }
    for a in &m.axial {
        let ends = a.label.split_once(" (").map_or("", |x| x.1);
        out.push(format!("axial ({ends}: {}", p.to_text(a.tension)));
    }
    out
}

#[test]
fn the_table_net_is_the_index_range_net() {
    let ranges = loaded(&examples().join("hanging_net.toml"));
    let tables = loaded(&examples().join("hanging_net_tables.toml"));
    let (a, b) = (made_of(&ranges), made_of(&tables));
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x, y);
    }
    assert_eq!(a.len(), b.len());
    // 23 particles (weight and drag on each), 72 springs: two loads each but on the two
    // pinned corners, which three springs reach each.
    assert_eq!(tables.particles.len(), 23);
    assert_eq!(tables.axial.len(), 72);
    assert_eq!(tables.loads.len(), 23 + 23 + 2 * 72 - 6);
    // The labels say which row a member is.
    assert!(
        tables.axial[0]
            .label
            .starts_with("horizontal[e=0] (P[0,0], P[1,0])"),
        "{}",
        tables.axial[0].label
    );
}

#[test]
fn node_ids_name_the_members_and_columns_are_their_numbers() {
    let m = loaded(&examples().join("truss_tables.toml"));
    let names: Vec<&str> = m.particles.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["N[20]", "N[30]", "N[50]"]);
    let points: Vec<&str> = m.points.iter().map(|p| p.0.as_str()).collect();
    assert_eq!(points, ["N[10]", "N[40]"]);
    let coords: Vec<String> = m
        .coordinates
        .iter()
        .map(|c| format!("{} {:?}", c.name, c.kind))
        .collect();
    assert_eq!(coords[0], "X[20] Free { initial: 1.0, rate: 0.0 }");
    assert_eq!(coords[4], "Y[30] Free { initial: 0.0, rate: 0.0 }");
    // Six bars between the ids of truss_bars.csv, each k = EA/L with L from the nodes' rows:
    // the diagonal 10-50 is sqrt(2) long.
    assert_eq!(m.axial.len(), 6);
    let ends: Vec<&str> = m
        .axial
        .iter()
        .map(|a| a.label.split_once(' ').unwrap().1)
        .collect();
    assert_eq!(
        ends,
        [
            "(N[10], N[20])",
            "(N[20], N[30])",
            "(N[40], N[50])",
            "(N[50], N[30])",
            "(N[10], N[50])",
            "(N[20], N[50])"
        ]
    );
    let diagonal = m.pool.to_text(m.axial[4].tension);
    assert!(diagonal.contains("sqrt(2)"), "{diagonal}");
    // The load of -1 P on node 30 only.
    let load = m
        .loads
        .iter()
        .find(|l| l.label.starts_with("load"))
        .unwrap();
    assert_eq!(load.target, Target::Particle(1));
    assert_eq!(m.pool.to_text(load.force[1]), "-P");
}

const NODES: &str = "id,x,y,fixed\n10,0,0,1\n20,1,0,0\n30,2,0,0\n";
const BARS: &str = "a,b,EA\n10,20,1e6\n20,30,1e6\n";

/// A two-bar chain along x: nodes 10 (pinned), 20, 30; `bars` as given.
fn chain(bars_field: &str) -> String {
    format!(
        r#"[tables.nodes]
file = "nodes.csv"
key = "id"
[tables.bars]
file = "bars.csv"{bars_field}
[parameters]
m = 1.0
[coordinates]
"X[r]" = {{ initial = "nodes_x", rate = 0, for = "r in nodes", where = "nodes_fixed == 0" }}
[points]
"N[r]" = {{ position = "[nodes_x, 0, 0]", for = "r in nodes", where = "nodes_fixed == 1" }}
[particles."N[r]"]
for = "r in nodes"
where = "nodes_fixed == 0"
mass = "m"
position = "[X[r], 0, 0]"
[[forces]]
kind = "spring"
name = "bar"
for = "e in bars"
between = ["N[bars_a]", "N[bars_b]"]
k = "bars_EA"
l0 = 1
"#
    )
}

#[test]
fn a_missing_table_file_is_located_at_its_name() {
    let model = chain("");
    let e = table_error("missing", &model, &[("nodes.csv", NODES)]);
    assert_at(&e, &model, "\"bars.csv\"");
    assert!(e.contains("cannot read the table file"), "{e}");
    assert!(e.contains("bars.csv"), "{e}");
}

#[test]
fn an_empty_table_and_a_table_without_its_columns_are_refused() {
    let model = chain("");
    let e = table_error(
        "empty",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", "a,b,EA\n")],
    );
    assert_at(&e, &model, "\"bars.csv\"");
    assert!(
        e.contains("table `bars`") && e.contains("no data rows"),
        "{e}"
    );
    // A column the model uses that the file lacks: named with the table's columns.
    let e = table_error(
        "no_column",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", "a,b,ea\n10,20,1\n")],
    );
    assert_at(&e, &model, "bars_EA");
    assert!(
        e.contains("table `bars`") && e.contains("has no column `EA`"),
        "{e}"
    );
    assert!(e.contains("`a`, `b`, `ea`"), "{e}");
    // One `columns` names that the file lacks.
    let model = chain("\ncolumns = [\"a\", \"b\", \"EA\"]");
    let e = table_error(
        "no_column_listed",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", "a,b,ea\n10,20,1\n")],
    );
    assert_at(&e, &model, "\"bars.csv\"");
    assert!(e.contains("no column named `EA`"), "{e}");
}

#[test]
fn a_non_finite_value_is_located_in_the_table() {
    let model = chain("");
    let e = table_error(
        "nan",
        &model,
        &[
            ("nodes.csv", NODES),
            ("bars.csv", "a,b,EA\n10,20,1e6\n20,30,NaN\n"),
        ],
    );
    assert_at(&e, &model, "\"bars.csv\"");
    assert!(e.contains("bars.csv:3:7: the value is NaN"), "{e}");
}

#[test]
fn a_non_integer_index_is_located_at_its_cell() {
    let model = chain("");
    let e = table_error(
        "fraction",
        &model,
        &[
            ("nodes.csv", NODES),
            ("bars.csv", "a,b,EA\n10,20,1e6\n20,30.5,1e6\n"),
        ],
    );
    // In the model: the end that uses it; in the table: line 3, column 4.
    assert_at(&e, &model, "bars_b");
    assert!(e.contains("bar[e=1] (table `bars`"), "{e}");
    assert!(
        e.contains("bars.csv:3:4: `bars_b` is used as an index, but 30.5 is not an integer"),
        "{e}"
    );
}

#[test]
fn an_element_naming_a_node_that_does_not_exist_is_refused() {
    let model = chain("");
    let e = table_error(
        "no_node",
        &model,
        &[
            ("nodes.csv", NODES),
            ("bars.csv", "a,b,EA\n10,20,1e6\n20,31,1e6\n"),
        ],
    );
    assert_at(&e, &model, "N[bars_b]");
    assert!(e.contains("bar[e=1] (table `bars`, "), "{e}");
    assert!(e.contains("bars.csv line 3)"), "{e}");
    assert!(e.contains("N[31] is outside N[10..30]"), "{e}");
    assert!(e.contains("(`bars_b` = 31 at "), "{e}");
    assert!(e.contains("bars.csv:3:4)"), "{e}");
    // Inside the ids' range but not one of them.
    let e = table_error(
        "no_node_inside",
        &model,
        &[
            ("nodes.csv", NODES),
            (
                "bars.csv",
                "a,b,EA
10,20,1e6
25,30,1e6
",
            ),
        ],
    );
    assert_at(&e, &model, "N[bars_a]");
    assert!(e.contains("N[25] is not declared: `N` is declared over the rows of tables, and no row names N[25] (`bars_a` = 25 at "), "{e}");
    assert!(e.contains("bars.csv:3:1)"), "{e}");
}

#[test]
fn duplicate_ids_and_a_missing_key_are_refused() {
    let model = chain("");
    let e = table_error(
        "duplicate",
        &model,
        &[
            ("nodes.csv", "id,x,y,fixed\n10,0,0,1\n20,1,0,0\n20,2,0,0\n"),
            ("bars.csv", BARS),
        ],
    );
    assert_at(&e, &model, "\"id\"");
    assert!(
        e.contains("nodes.csv:4:1: the key 20 appears twice (first at line 3)"),
        "{e}"
    );
    let e = table_error(
        "fractional_key",
        &model,
        &[
            ("nodes.csv", "id,x,y,fixed\n10,0,0,1\n20.5,1,0,0\n"),
            ("bars.csv", BARS),
        ],
    );
    assert!(
        e.contains("nodes.csv:3:1: `nodes_id` is used as an index, but 20.5 is not an integer"),
        "{e}"
    );
    let model = chain("").replace("key = \"id\"", "key = \"node\"");
    let e = table_error(
        "no_key",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", BARS)],
    );
    assert_at(&e, &model, "\"node\"");
    assert!(
        e.contains("table `nodes` has no column `node` to be its key"),
        "{e}"
    );
}

#[test]
fn an_element_joining_a_node_to_itself_names_its_row() {
    let model = chain("");
    let e = table_error(
        "self_join",
        &model,
        &[
            ("nodes.csv", NODES),
            ("bars.csv", "a,b,EA\n10,20,1e6\n\n20,20,1e6\n"),
        ],
    );
    assert!(e.contains("bar[e=1] (table `bars`, "), "{e}");
    // The blank line counts: the row is the file's line 4.
    assert!(
        e.contains("bars.csv line 4): `between` joins `N[20]` to itself"),
        "{e}"
    );
}

#[test]
fn a_family_over_an_unknown_table_or_a_column_out_of_its_rows_is_refused() {
    let model = chain("").replace("for = \"e in bars\"", "for = \"e in bar\"");
    let e = table_error(
        "unknown_table",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", BARS)],
    );
    assert_at(&e, &model, "bar\"\nbetween");
    assert!(e.contains("`bar` is not a table"), "{e}");
    assert!(e.contains("the tables are `nodes`, `bars`"), "{e}");
    // A column used where no row of its table is bound.
    let model = chain("").replace("k = \"bars_EA\"", "k = \"nodes_x\"");
    let e = table_error(
        "unbound",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", BARS)],
    );
    assert_at(&e, &model, "nodes_x\"\nl0");
    assert!(e.contains("`nodes_x` is a column of table `nodes`"), "{e}");
    // A table's column may not be redeclared.
    let model = chain("").replace("m = 1.0", "m = 1.0\nbars_EA = 2");
    let e = table_error(
        "redeclared",
        &model,
        &[("nodes.csv", NODES), ("bars.csv", BARS)],
    );
    assert!(
        e.contains("duplicate name `bars_EA`: already a table column"),
        "{e}"
    );
}

#[test]
fn a_table_size_counts_its_rows() {
    // `bars` is the number of rows: a range over it, and a number in expressions.
    let dir = scratch("size");
    std::fs::write(dir.join("nodes.csv"), NODES).unwrap();
    std::fs::write(dir.join("bars.csv"), BARS).unwrap();
    let model = chain("").replace("m = 1.0", "m = \"bars + 1\"").replace(
        "for = \"e in bars\"\nbetween = [\"N[bars_a]\", \"N[bars_b]\"]\nk = \"bars_EA\"",
        "for = \"e in 0..bars-1\"\nbetween = [\"N[10*e + 10]\", \"N[10*e + 20]\"]\nk = \"bars_EA[10*e + 10]\"",
    );
    // `bars_EA[k]` names row k of a table without a key (the rows' numbers): out of range.
    let path = dir.join("model.toml");
    std::fs::write(&path, &model).unwrap();
    let e = load_file(&path).unwrap_err().render(&model);
    assert!(
        e.contains("table `bars` has no row 10 (its rows are named by its row numbers 0..1)"),
        "{e}"
    );
    let model = model.replace("bars_EA[10*e + 10]", "bars_EA[e]");
    std::fs::write(&path, &model).unwrap();
    let m = load_file(&path).unwrap_or_else(|e| panic!("{}", e.render(&model)));
    assert_eq!(m.parameters[0].value, 3.0);
    assert_eq!(m.axial.len(), 2);
    let _ = std::fs::remove_dir_all(&dir);
}
