//! Bad model files give located, helpful errors — never a panic.

use pdyn_mech::{derive, load, DeriveOptions};

const GOOD: &str = r#"
name = "ok"
gravity = "[0, -g, 0]"

[parameters]
g = 9.81
m = 2.0

[coordinates]
y = { initial = 1.0, rate = 0.0 }

[particles.ball]
mass = "m"
position = "[0, y, 0]"
"#;

/// Renders the load error of `src`.
fn load_err(src: &str) -> String {
    match load(src, "model.toml") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e.render(src),
    }
}

fn derive_err(src: &str) -> String {
    derive_err_with(src, &DeriveOptions::default())
}

fn derive_err_with(src: &str, opts: &DeriveOptions) -> String {
    let mut m = load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)));
    match derive(&mut m, opts) {
        Ok(_) => panic!("expected a derivation error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_good_model_loads_and_derives() {
    let mut m = load(GOOD, "model.toml").unwrap();
    let d = derive(&mut m, &DeriveOptions::default()).unwrap();
    assert_eq!(m.pool.to_text(d.solution.unwrap()[0]), "-g");
}

#[test]
fn unknown_particle_in_a_force() {
    let src =
        format!("{GOOD}\n[[forces]]\nkind = \"applied\"\non = \"bal\"\nforce = \"[1, 0, 0]\"\n");
    let r = load_err(&src);
    assert!(
        r.starts_with("model.toml:18:6: error: unknown particle `bal`"),
        "{r}"
    );
    assert!(r.contains("did you mean `ball`?"), "{r}");
}

#[test]
fn undefined_symbol_with_suggestion() {
    let src = GOOD.replace("mass = \"m\"", "mass = \"mm\"");
    let r = load_err(&src);
    assert!(
        r.starts_with("model.toml:13:9: error: undefined name `mm`"),
        "{r}"
    );
    assert!(r.contains("did you mean `m`?"), "{r}");
    assert!(r.contains("13 | mass = \"mm\""), "{r}");
}

#[test]
fn vector_scalar_mismatch() {
    let src = GOOD.replace("position = \"[0, y, 0]\"", "position = \"y\"");
    let r = load_err(&src);
    assert!(
        r.contains("model.toml:14:12: error: the position of `ball` must be a vector"),
        "{r}"
    );
    let src = GOOD.replace("position = \"[0, y, 0]\"", "position = \"[0, y, 0] + m\"");
    let r = load_err(&src);
    assert!(r.contains("cannot add a vector and a scalar"), "{r}");
    assert!(r.contains("model.toml:14:13"), "{r}");
}

#[test]
fn duplicate_names() {
    let src = GOOD.replace(
        "[particles.ball]",
        "[definitions]\nm = \"2*g\"\n\n[particles.ball]",
    );
    let r = load_err(&src);
    assert!(
        r.contains("duplicate name `m`: already a parameter (line 7)"),
        "{r}"
    );
    let src = GOOD.replace("m = 2.0", "m = 2.0\nm = 3.0");
    let r = load_err(&src);
    assert!(r.contains("model.toml:8:1"), "{r}");
}

#[test]
fn non_positive_mass() {
    let src = GOOD.replace("m = 2.0", "m = -2.0");
    let r = load_err(&src);
    assert!(
        r.contains("the mass of `ball` must be positive, it is -2"),
        "{r}"
    );
    assert!(r.contains("model.toml:13:8"), "{r}");
}

#[test]
fn missing_initial_condition() {
    let src = GOOD.replace("y = { initial = 1.0, rate = 0.0 }", "y = { initial = 1.0 }");
    let r = load_err(&src);
    assert!(r.contains("coordinate `y` has no `rate`"), "{r}");
    assert!(r.contains("model.toml:10:5"), "{r}");
}

#[test]
fn unknown_keys_and_kinds() {
    let src = GOOD.replace("mass = \"m\"", "mas = \"m\"");
    let r = load_err(&src);
    assert!(r.contains("unknown field `mas`"), "{r}");
    let src = format!("{GOOD}\n[[forces]]\nkind = \"sprung\"\nbetween = [\"ball\", \"O\"]\n");
    let r = load_err(&src);
    assert!(r.contains("unknown force kind `sprung`"), "{r}");
    assert!(r.contains("did you mean `spring`?"), "{r}");
    let src = GOOD.replace("g = 9.81", "g = \"9.81 m/s^3x\"");
    let r = load_err(&src);
    assert!(r.contains("unknown unit `x`"), "{r}");
}

#[test]
fn underdetermined_and_overdetermined_systems() {
    // A reaction with no equation of its own: two unknown reactions along the same line.
    let src = format!(
        "{GOOD}\n[[forces]]\nkind = \"reaction\"\nname = \"N1\"\non = \"ball\"\ndirection = \"[1, 0, 0]\"\n\
         \n[[forces]]\nkind = \"reaction\"\nname = \"N2\"\non = \"ball\"\ndirection = \"[1, 0, 0]\"\n"
    );
    let e = derive_err(&src);
    assert!(
        e.contains("2 equations for 3 unknowns (y'', N1, N2)"),
        "{e}"
    );
    assert!(e.contains("look for constraints"), "{e}");
    // Square but singular: redundant coordinates.
    let src = GOOD
        .replace(
            "y = { initial = 1.0, rate = 0.0 }",
            "x = { initial = 0.0, rate = 0.0 }\ny = { initial = 1.0, rate = 0.0 }",
        )
        .replace(
            "position = \"[0, y, 0]\"",
            "position = \"[x + y, x + y, 0]\"",
        );
    let e = derive_err(&src);
    assert!(e.contains("do not determine y''"), "{e}");
    // A coordinate that moves nothing.
    let src = GOOD.replace(
        "y = { initial = 1.0, rate = 0.0 }",
        "y = { initial = 1.0, rate = 0.0 }\nz = { initial = 0.0, rate = 0.0 }",
    );
    let e = derive_err(&src);
    assert!(e.contains("no equation involves `z''`"), "{e}");
    // A force with no reaction to carry it: gravity along x on a particle that cannot move in x.
    // Newton's form reports the missing reaction; the automatic form projects it away instead.
    let src = GOOD.replace("gravity = \"[0, -g, 0]\"", "gravity = \"[-g, -g, 0]\"");
    let newton = DeriveOptions {
        form: pdyn_mech::derive::Form::Newton,
        ..DeriveOptions::default()
    };
    let e = derive_err_with(&src, &newton);
    assert!(e.contains("involves no unknown and does not hold"), "{e}");
    assert!(e.contains("declare the reaction"), "{e}");
    let mut m = load(&src, "model.toml").unwrap();
    let d = derive(&mut m, &DeriveOptions::default()).unwrap();
    assert_eq!(d.form, pdyn_mech::derive::Form::Projected);
    assert!(d.notes[0].contains("workless"));
}

#[test]
fn garbage_never_panics() {
    for src in [
        "",
        "[[forces]]\nkind = 3",
        "[particles.a]\nmass = true",
        "[coordinates]\nx = [1, 2]",
        "[particles.a]\nmass = 1\nposition = \"[x\"",
        "gravity = \"[0, 0, -g\"",
        "[parameters]\ng = \"1/0\"",
        "[coordinates]\nx = { initial = \"t\", rate = 0 }",
    ] {
        let _ = load(src, "x.toml").map_err(|e| e.render(src));
    }
}

const RAILS: &str = r#"
name = "a ball on two rails"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
[coordinates]
x = { initial = 0, rate = 0 }
y = { initial = 0, rate = 0 }
[particles.a]
mass = 1
position = "[x, y, 0]"
[[constraints]]
name = "rail 1"
equation = "x + y = 0"
[[constraints]]
name = "rail 2"
equation = "SECOND"
"#;

#[test]
fn contradictory_constraints_are_named_with_their_lines() {
    let e = derive_err(&RAILS.replace("SECOND", "x + y = 1"));
    assert!(
        e.contains("constraint `rail 2` (line 17) contradicts `rail 1` (line 14)"),
        "{e}"
    );
}

#[test]
fn a_redundant_constraint_is_named_as_such() {
    let e = derive_err(&RAILS.replace("SECOND", "2*x + 2*y = 0"));
    assert!(
        e.contains("constraint `rail 2` (line 17) repeats `rail 1` (line 14)"),
        "{e}"
    );
    // Independent rails are neither (this model lacks the rails' reactions, a different error).
    let e = derive_err(&RAILS.replace("SECOND", "x - y = 0"));
    assert!(
        !e.contains("repeats") && !e.contains("contradicts `rail"),
        "{e}"
    );
}

/// A sweep's `steps` is checked before its values are made: the fuzzer's
/// `steps = 810000002071` asked for 6.5 TB (a crash under the sanitizer, an abort without).
#[test]
fn absurd_sweep_steps_are_refused_before_allocating() {
    let main =
        format!("{GOOD}\n[sweep]\nparameter = \"m\"\nfrom = 1\nto = 2\nsteps = 810000002071\n");
    let e = load_err(&main);
    assert!(
        e.contains("`steps` = 810000002071 is more than a sweep may run"),
        "{e}"
    );
    assert!(e.contains("model.toml:"), "{e}");
    let also = format!(
        "{GOOD}\n[sweep]\nparameter = \"m\"\nvalues = [1, 2]\n\n[sweep.also]\ng = {{ from = 1, to = 2, steps = 1e30 }}\n"
    );
    let e = load_err(&also);
    assert!(e.contains("is more than a sweep may run"), "{e}");
    // Within the limit it loads.
    let fine = format!("{GOOD}\n[sweep]\nparameter = \"m\"\nfrom = 1\nto = 2\nsteps = 1000\n");
    assert!(load(&fine, "model.toml").is_ok());
}

/// A `[definitions]` name may give an initial value or rate (issue 34): definitions are
/// read after the coordinates, so these initial conditions are read once they are declared,
/// and recomputed when a parameter they use changes. A definition of the coordinates is not
/// a number at t = 0: a located error.
#[test]
fn definitions_give_initial_values() {
    let src = r#"
[parameters]
L = 2.0
w = 3.0
[definitions]
x0 = "L/2"
v0 = "w*x0"
[coordinates]
x = { initial = "x0", rate = "v0 + 1" }
[particles.p]
mass = 1
position = "[x, 0, 0]"
"#;
    let mut m = load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)));
    let free = |m: &pdyn_mech::Model| match m.coordinates[0].kind {
        pdyn_mech::model::CoordinateKind::Free { initial, rate } => (initial, rate),
        _ => panic!("free"),
    };
    assert_eq!(free(&m), (1.0, 4.0));
    pdyn_mech::parameters::set_values(&mut m, &[("L".to_string(), 4.0)]).unwrap();
    assert_eq!(free(&m), (2.0, 7.0));
    let bad = src
        .replace("x0 = \"L/2\"", "x0 = \"L/2\"\ny0 = \"2*x\"")
        .replace("\"x0\"", "\"y0\"");
    let e = load_err(&bad);
    assert!(e.contains("model.toml:10:"), "{e}");
    assert!(e.contains("`initial` of `x`"), "{e}");
}
