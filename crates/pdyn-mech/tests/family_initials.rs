//! A coordinate family's initial values and rates read as numbers over its members
//! (`model/family_initials.rs`, issue 33): the same values as the family written out member
//! by member (each read the symbolic way) and as their closed forms computed here, the same
//! expressions for sweeps and `--set`, and the same errors at the same places.

use pdyn_expr::{Id, Program};
use pdyn_mech::model::{load_deferring, CoordinateKind, Model};
use pdyn_mech::{load, parameters};

const N: i64 = 9;

/// A family with index arithmetic, functions of the index and a condition leaving members
/// out (`i = 4`, the ends), over the parameters `L`, `w` and the size `n`.
fn family_model(initial: &str, rate: &str) -> String {
    format!(
        r#"
[indices]
n = {N}
i = "0..n+1"

[parameters]
m = 1.0
k = 50.0
L = 0.3
w = 2.5

[coordinates]
"x[i]" = {{ initial = "{initial}", rate = "{rate}", where = "i >= 1 and i <= n and i != 4" }}

[points]
"P[i]" = {{ position = "[i*L, 0, 0]", where = "i == 0 or i == n+1 or i == 4" }}

[particles."P[i]"]
where = "i >= 1 and i <= n and i != 4"
mass = "m"
position = "[x[i], 0, 0]"

[[forces]]
kind = "spring"
for = "i in 0..n"
between = ["P[i+1]", "P[i]"]
k = "k"
l0 = "L"
"#
    )
}

const INITIAL: &str = "i*L + 0.01*L*sin(pi*i/(n + 1)) + (i - 3)^2/7 - exp(-i/w)";
const RATE: &str = "w*cos(i*L) - i/3 + sqrt(i)";

/// The members, as written above.
fn members() -> Vec<i64> {
    (1..=N).filter(|&i| i != 4).collect()
}

/// The closed forms of [`INITIAL`] and [`RATE`] at member `i`.
fn closed_form(i: i64, l: f64, w: f64) -> (f64, f64) {
    let x = i as f64;
    let n = N as f64;
    let initial = x * l
        + 0.01 * l * libm::sin(std::f64::consts::PI * x / (n + 1.0))
        + (x - 3.0) * (x - 3.0) / 7.0
        - libm::exp(-x / w);
    let rate = w * libm::cos(x * l) - x / 3.0 + libm::sqrt(x);
    (initial, rate)
}

/// `text` with the index `i` (the whole name, not the `i` of `sin` or `pi`) replaced by
/// `(value)`.
fn put_index(text: &str, value: i64) -> String {
    let mut out = String::new();
    let mut name = String::new();
    for c in text.chars().chain(std::iter::once(' ')) {
        if c.is_alphanumeric() || c == '_' {
            name.push(c);
            continue;
        }
        if name == "i" {
            out.push_str(&format!("({value})"));
        } else {
            out.push_str(&name);
        }
        name.clear();
        out.push(c);
    }
    out.pop();
    out
}

/// The same model with each member's coordinate written out on its own, its index put in
/// as a number: every one read the symbolic way (no family).
fn written_out(initial: &str, rate: &str) -> String {
    let family = family_model(initial, rate);
    let line = family
        .lines()
        .find(|l| l.starts_with("\"x[i]\""))
        .unwrap()
        .to_string();
    let mut rows = String::new();
    for i in members() {
        rows.push_str(&format!(
            "\"x[{i}]\" = {{ initial = \"{}\", rate = \"{}\" }}\n",
            put_index(initial, i),
            put_index(rate, i)
        ));
    }
    family.replace(&line, rows.trim_end())
}

fn loaded(src: &str) -> Model {
    load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

fn deferring(src: &str) -> Model {
    load_deferring(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

/// `(name, initial, rate)` of every free coordinate.
fn initials(m: &Model) -> Vec<(String, f64, f64)> {
    m.coordinates
        .iter()
        .filter_map(|c| match c.kind {
            CoordinateKind::Free { initial, rate } => Some((c.name.clone(), initial, rate)),
            _ => None,
        })
        .collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn a_familys_initial_values_are_the_closed_forms_and_the_members_written_out() {
    let src = family_model(INITIAL, RATE);
    let explicit = written_out(INITIAL, RATE);
    assert!(
        explicit.contains("\"x[5]\" = { initial = \"(5)*L"),
        "{explicit}"
    );
    let by_member = initials(&loaded(&explicit));
    for m in [loaded(&src), deferring(&src)] {
        let got = initials(&m);
        assert_eq!(got.len(), members().len());
        for ((name, x0, v0), i) in got.iter().zip(members()) {
            assert_eq!(name, &format!("x[{i}]"));
            let (x, v) = closed_form(i, 0.3, 2.5);
            assert!(close(*x0, x, 1e-15), "{name}: {x0} against {x}");
            assert!(close(*v0, v, 1e-15), "{name}: rate {v0} against {v}");
        }
        for (a, b) in got.iter().zip(&by_member) {
            assert_eq!(a.0, b.0);
            assert!(close(a.1, b.1, 2e-15), "{}: {} against {}", a.0, a.1, b.1);
            assert!(close(a.2, b.2, 2e-15), "{}: {} against {}", a.0, a.2, b.2);
        }
    }
}

/// Each `initial_exprs` entry evaluated at the parameters' values.
fn evaluated(m: &mut Model) -> Vec<(usize, f64, f64)> {
    let params: Vec<Id> = m.parameters.iter().map(|p| p.id).collect();
    let values: Vec<f64> = m.parameters.iter().map(|p| p.value).collect();
    let entries = m.initial_exprs.clone();
    entries
        .iter()
        .map(|&(c, e, r)| {
            let prog = Program::compile(&mut m.pool, &params, &[e, r])
                .unwrap_or_else(|e| panic!("coordinate {c}: {e}"));
            let mut out = [0.0; 2];
            prog.eval(&values, &mut prog.workspace(), &mut out);
            (c, out[0], out[1])
        })
        .collect()
}

#[test]
fn the_members_expressions_follow_the_parameters() {
    let src = family_model(INITIAL, RATE);
    let mut from_load = loaded(&src);
    assert!(from_load.initial_families.is_empty());
    let mut lazy = deferring(&src);
    assert!(lazy.initial_exprs.is_empty());
    assert_eq!(lazy.initial_families.len(), 1);
    // Set first (the family's numbers refreshed from its one expression), written out after;
    // and written out first, then set (each member's own expression refreshed).
    let set = [("L".to_string(), 0.41), ("w".to_string(), 1.7)];
    parameters::set_values(&mut lazy, &set).unwrap();
    parameters::set_values(&mut from_load, &set).unwrap();
    lazy.materialize_initials();
    assert!(lazy.initial_families.is_empty());
    for m in [&mut from_load, &mut lazy] {
        let free: Vec<usize> = (0..m.coordinates.len()).collect();
        let exprs = evaluated(m);
        assert_eq!(exprs.iter().map(|e| e.0).collect::<Vec<_>>(), free);
        let numbers = initials(m);
        for (((c, x, v), i), (name, x0, v0)) in exprs.iter().zip(members()).zip(numbers) {
            let (cx, cv) = closed_form(i, 0.41, 1.7);
            assert!(
                close(*x, cx, 1e-15),
                "x[{i}] (coordinate {c}): {x} against {cx}"
            );
            assert!(close(*v, cv, 1e-15), "x[{i}]: rate {v} against {cv}");
            assert!(close(x0, cx, 1e-15), "{name}: {x0} against {cx}");
            assert!(close(v0, cv, 1e-15), "{name}: rate {v0} against {cv}");
        }
    }
}

/// The error of loading `src`, rendered.
fn error_of(src: &str, lazy: bool) -> String {
    let r = if lazy {
        load_deferring(src, "model.toml")
    } else {
        load(src, "model.toml")
    };
    match r {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e.render(src),
    }
}

#[test]
fn a_member_whose_value_is_not_finite_is_the_error_it_was() {
    // Division by zero at i = 3 only; a square root of a negative number from i = 3 on;
    // a singularity the family's expression simplifies away ((i-3)/(i-3) is 1 for a symbol
    // i) but the member i = 3 has.
    let line = |text: &str| format!("model.toml:13:10: error: x[i=3]: {text}");
    for (initial, want) in [
        (
            "i*L + 1/(i - 3)",
            line("in `initial` of `x[3]`: division by zero: the divisor is zero"),
        ),
        (
            "i*L + sqrt(2 - i)",
            line("`initial` of `x[3]` evaluates to NaN"),
        ),
        (
            "(i - 3)/(i - 3)",
            line("in `initial` of `x[3]`: division by zero: the divisor is zero"),
        ),
    ] {
        let src = family_model(initial, "0");
        for lazy in [false, true] {
            let err = error_of(&src, lazy);
            assert!(err.starts_with(&want), "{initial}: {err}");
        }
    }
    // In the rate, the same.
    let src = family_model("i*L", "w/(i - 5)");
    let err = error_of(&src, true);
    assert!(
        err.starts_with("model.toml:13:10: error: x[i=5]: in `rate` of `x[5]`: division by zero"),
        "{err}"
    );
}
