//! Units and dimensions in model files: unit literals inside expressions, and a model whose
//! terms do not have the same dimension refused with both terms named.

use pdyn_mech::{derive, load, DeriveOptions};

/// A block on a spring along x, with `force` applied to it.
fn block(params: &str, force: &str) -> String {
    format!(
        r#"
name = "block"

[parameters]
{params}

[coordinates]
x = {{ initial = "0.1 m", rate = 0 }}

[particles.block]
mass = "m"
position = "[x, 0, 0]"

[[forces]]
kind = "applied"
on = "block"
force = "{force}"
"#
    )
}

fn load_err(src: &str) -> String {
    match load(src, "model.toml") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e.render(src),
    }
}

#[test]
fn a_spring_force_added_to_a_velocity_is_refused_naming_both_terms() {
    let src = block(
        "m = \"2 kg\"\nk = \"100 N/m\"\nl0 = \"5 cm\"",
        "[-k*(x - l0) + x', 0, 0]",
    );
    let e = load_err(&src);
    assert!(
        e.starts_with("model.toml:19:11: error: dimension mismatch"),
        "{e}"
    );
    assert!(
        e.contains("`-k*(x - l0)` is kg·m/s^2 (force) but `x'` is m/s (velocity)"),
        "{e}"
    );
    // The same force with a damper's term is fine, and the damping coefficient's dimension
    // is found from its use.
    let ok = block(
        "m = \"2 kg\"\nk = \"100 N/m\"\nl0 = \"5 cm\"\nc = 3",
        "[-k*(x - l0) - c*x', 0, 0]",
    );
    let mut m = load(&ok, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(&ok)));
    derive(&mut m, &DeriveOptions::default()).unwrap();
}

#[test]
fn a_name_used_with_two_dimensions_is_refused() {
    // `c` is a damping coefficient in the first term and a stiffness in the second.
    let src = block("m = \"2 kg\"\nc = 3", "[-c*x' - c*x, 0, 0]");
    let e = load_err(&src);
    assert!(e.contains("dimension mismatch"), "{e}");
    assert!(e.contains("`-c*x'` is") && e.contains("`c*x` is"), "{e}");
}

#[test]
fn fields_have_the_dimension_their_role_needs() {
    let src = block("m = \"2 m\"\nk = \"100 N/m\"", "[-k*x, 0, 0]");
    let e = load_err(&src);
    assert!(
        e.contains("the mass of `block` has the dimension m (length), but it must be kg (mass)"),
        "{e}"
    );
    let src = block("m = \"2 kg\"\nk = \"100 N/m\"", "[-k, 0, 0]");
    let e = load_err(&src);
    assert!(
        e.contains("an applied force has the dimension kg/s^2 (stiffness)"),
        "{e}"
    );
    let src = block("m = \"2 kg\"\nF0 = \"3 N\"", "[F0*sin(t), 0, 0]");
    let e = load_err(&src);
    assert!(
        e.contains("the argument of `sin` must be a pure number, but `t` is s (time)"),
        "{e}"
    );
    let src = block(
        "m = \"2 kg\"\nF0 = \"3 N\"\nomega = \"2*pi/(120 s)\"",
        "[F0*sin(omega*t), 0, 0]",
    );
    load(&src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(&src)));
}

#[test]
fn a_spring_and_its_initial_conditions_are_checked() {
    let spring = |k: &str, l0: &str, rate: &str| {
        format!(
            r#"
[parameters]
m = "2 kg"
k = "{k}"

[points]
O = "[0, 0, 0]"

[coordinates]
x = {{ initial = "0.1 m", rate = "{rate}" }}

[particles.block]
mass = "m"
position = "[x, 0, 0]"

[[forces]]
kind = "spring"
between = ["block", "O"]
k = "k"
l0 = "{l0}"
"#
        )
    };
    let ok = spring("100 N/m", "5 cm", "0.2 m/s");
    load(&ok, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(&ok)));
    let e = load_err(&spring("100 N", "5 cm", "0"));
    assert!(
        e.contains("the stiffness `k` has the dimension kg·m/s^2 (force), but it must be kg/s^2 (stiffness)"),
        "{e}"
    );
    let e = load_err(&spring("100 N/m", "5 kg", "0"));
    assert!(e.contains("the free length `l0`"), "{e}");
    let e = load_err(&spring("100 N/m", "5 cm", "2 m/s^2"));
    assert!(
        e.contains("`rate` of `x`") && e.contains("m/s (velocity)"),
        "{e}"
    );
}

#[test]
fn models_without_units_are_not_checked() {
    // `[1, yB, 0]` adds a pure number to a length: fine in a model written in plain numbers.
    let src = r#"
[parameters]
m = 2
c = 3

[coordinates]
x = { initial = 0.1, rate = 0 }

[particles.block]
mass = "m"
position = "[x + 1, 0, 0]"

[[forces]]
kind = "applied"
on = "block"
force = "[-c*x' + x, 0, 0]"
"#;
    load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)));
}

#[test]
fn every_shipped_example_with_units_passes_the_check() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut with_units = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let src = std::fs::read_to_string(&path).unwrap();
        if src.contains("[nbody]") || src.contains("[md]") {
            continue;
        }
        let has_units = src.lines().any(|l| {
            l.split_once('=').is_some_and(|(_, v)| {
                let v = v.trim().trim_matches('"');
                pdyn_mech::units::looks_like_quantity(v.split('"').next().unwrap_or(""))
            })
        });
        if let Err(e) = load(&src, &path.display().to_string()) {
            assert!(!e.message.contains("dimension"), "{}", e.render(&src));
        }
        with_units += usize::from(has_units);
    }
    assert!(with_units >= 6, "only {with_units} examples declare units");
}

#[test]
fn quantities_inside_expressions_are_exact() {
    let src = block(
        "m = \"2 kg\"\nomega = \"2*pi/(120 s)\"\nF0 = \"3 N\"",
        "[F0*cos(omega*t), 0, 0]",
    );
    let m = load(&src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(&src)));
    let omega = m.parameters.iter().find(|p| p.name == "omega").unwrap();
    assert_eq!(omega.value, std::f64::consts::PI / 60.0);
}

/// Modelica's rule (issue 34): a bare number standing as a whole term takes the dimension
/// its context needs, so engineers' SI models that mix bare numbers with units load, and an
/// angle unit alone makes nothing strict. Each model here is correct.
#[test]
fn bare_numbers_beside_units_take_their_context_dimension() {
    let with = |params: &str, coords: &str, position: &str, extra: &str| {
        format!(
            "gravity = \"[0, -9.81 m/s^2, 0]\"\n[parameters]\nm = \"2 kg\"\nk = \"100 N/m\"\n{params}\n[coordinates]\n{coords}\n[points]\nO = \"[0, 0, 0]\"\n[particles.p]\nmass = \"m\"\nposition = \"{position}\"\n[[forces]]\nkind = \"spring\"\nbetween = [\"p\", \"O\"]\nk = \"k\"\nl0 = 0.5\n{extra}"
        )
    };
    let cases = [
        // a bare component beside a coordinate
        with("", "y = { initial = 1, rate = 0 }", "[2, y, 0]", ""),
        // a bare initial value and parameter beside a stiffness in N/m
        with(
            "x0 = 0.5",
            "x = { initial = \"x0\", rate = 0 }",
            "[x, 0, 0]",
            "",
        ),
        // bare numbers in an event function and a monitor
        with(
            "",
            "y = { initial = 3, rate = 0 }",
            "[0, y, 0]",
            "[[events]]\nname = \"low\"\nwhen = \"y - 2\"\n[monitors]\nabove = \"y - 1.5\"\n",
        ),
        // an offset in a position, a bare number added to a length
        with("", "x = { initial = 1, rate = 0 }", "[x + 0.25, 0, 0]", ""),
        // a scale factor stays a pure number
        with("", "x = { initial = 1, rate = 0 }", "[2*x, 0, 0]", ""),
        // min/max with a bare number
        with(
            "",
            "x = { initial = 1, rate = 0 }",
            "[max(x, 0.1), 0, 0]",
            "",
        ),
        // a bare rate beside units
        with(
            "",
            "x = { initial = \"10 cm\", rate = 0.3 }",
            "[x, 0, 0]",
            "",
        ),
        // a bare number beside a quantity inside one expression
        with(
            "",
            "x = { initial = 1, rate = 0 }",
            "[x - 2 + 3 cm, 0, 0]",
            "",
        ),
        // an applied force with a bare constant term
        with(
            "",
            "x = { initial = 1, rate = 0 }",
            "[x, 0, 0]",
            "[[forces]]\nkind = \"applied\"\non = \"p\"\nforce = \"[-k*x + 5, 0, 0]\"\n",
        ),
        // a vector of bare numbers as a point
        with("", "x = { initial = 1, rate = 0 }", "[x, 1.5, -2]", ""),
    ];
    for src in &cases {
        load(src, "model.toml").unwrap_or_else(|e| panic!("{}\n{src}", e.render(src)));
    }
    // An angle alone does not make a plain-number model strict.
    let angle = "[parameters]\ntheta0 = \"30 deg\"\nm = 2\n[coordinates]\nx = { initial = \"theta0\", rate = 0 }\n[particles.p]\nmass = \"m\"\nposition = \"[2, x, 0]\"\n[[forces]]\nkind = \"applied\"\non = \"p\"\nforce = \"[0, -m*9.81 + x', 0]\"\n";
    load(angle, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(angle)));
    // Two quantities whose dimensions are both known still conflict.
    let e = load_err(&with(
        "",
        "x = { initial = 1, rate = 0 }",
        "[x + 2 s, 0, 0]",
        "",
    ));
    assert!(e.contains("s (time)") && e.contains("m (length)"), "{e}");
    // A scale factor does not soak up a dimension: 2*x (a length) plus x' (a velocity).
    let e = load_err(&with(
        "",
        "x = { initial = 1, rate = 0 }",
        "[x, 0, 0]",
        "[[forces]]\nkind = \"applied\"\non = \"p\"\nforce = \"[-k*x + 2*m*x', 0, 0]\"\n",
    ));
    assert!(e.contains("dimension mismatch"), "{e}");
}

/// The times of `[simulate]` are times (issue 34: `output_dt = "5 kg"` was accepted): a
/// quantity of other units is a located error naming both dimensions; bare numbers and
/// times in any unit pass.
#[test]
fn simulate_times_must_be_times() {
    for (key, value) in [
        ("output_dt", "\"5 kg\""),
        ("t_end", "\"2 m\""),
        ("max_step", "\"1 N\""),
        ("dt", "\"3 kg*m\""),
    ] {
        let src = block("k = \"100 N/m\"\nm = \"1 kg\"", "[-k*x, 0, 0]")
            + &format!("[simulate]\n{key} = {value}\n");
        let e = load_err(&src);
        assert!(
            e.contains(&format!("`{key}` has the dimension")) && e.contains("s (time)"),
            "{e}"
        );
    }
    for value in ["0.5", "\"0.5 s\"", "\"2 min\"", "\"1 ms\""] {
        let src = block("k = \"100 N/m\"\nm = \"1 kg\"", "[-k*x, 0, 0]")
            + &format!("[simulate]\nt_end = 10\noutput_dt = {value}\n");
        load(&src, "model.toml").unwrap_or_else(|e| panic!("{value}: {}", e.render(&src)));
    }
}
