//! Issue 34, item 5: a name from `[unknowns]` as a coordinate's rate (a conical pendulum's ω),
//! solved by `pdyn forces` in closed form when it enters only squared, and refused with a
//! located error where a number is needed. Expected values are worked by hand in each test.

use pdyn_expr::{FreeScope, Id};
use pdyn_mech::prescribed::{solve_forces, ForcesError, ForcesOptions, ForcesResult};
use pdyn_mech::{load, Model};

fn example(name: &str) -> Model {
    let path = format!("{}/../../examples/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    load(&src, &path).unwrap_or_else(|e| panic!("{}", e.render(&src)))
}

fn model(src: &str) -> Model {
    load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

fn solve(m: &mut Model) -> ForcesResult {
    solve_forces(m, &ForcesOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn index(r: &ForcesResult, name: &str) -> usize {
    r.unknowns.iter().position(|u| u == name).unwrap()
}

fn sym(r: &ForcesResult, name: &str) -> Id {
    r.symbolic.as_ref().expect("a closed form")[index(r, name)]
}

fn param(m: &Model, name: &str) -> f64 {
    m.parameters.iter().find(|p| p.name == name).unwrap().value
}

/// `got` and `expected` agree as expressions (checked numerically at the model's parameter
/// values and at a second, unrelated set, so a form that is only right at one point fails).
fn same(m: &mut Model, got: Id, expected: &str) {
    let mut scope = FreeScope::default();
    let e = m
        .pool
        .parse_in(expected, &mut scope)
        .unwrap()
        .scalar()
        .unwrap();
    let leaves: Vec<Id> = m.parameters.iter().map(|p| p.id).collect();
    let prog = pdyn_expr::Program::compile(&mut m.pool, &leaves, &[got, e]).unwrap();
    let mut ws = prog.workspace();
    let base: Vec<f64> = m.parameters.iter().map(|p| p.value).collect();
    let other: Vec<f64> = base.iter().map(|v| v * 0.7 + 0.01).collect();
    for values in [base, other] {
        let mut out = [0.0; 2];
        prog.eval(&values, &mut ws, &mut out);
        assert!(
            (out[0] - out[1]).abs() <= 1e-12 * out[1].abs().max(1.0),
            "got {} = {}, expected {expected} = {}",
            m.pool.to_text(got),
            out[0],
            out[1]
        );
    }
}

const CONICAL: &str = r#"
gravity = "[0, 0, -g]"
[parameters]
g = 9.81
m = 0.2
L = 1.5
alpha = 0.5
[unknowns]
omega = {}
[coordinates]
phi = { initial = 0.0, rate = "omega", acceleration = 0.0 }
[definitions]
e_r = "[cos(phi), sin(phi), 0]"
k = "[0, 0, 1]"
string = "L*(sin(alpha)*e_r - cos(alpha)*k)"
[particles.bob]
mass = "m"
position = "string"
[[forces]]
kind = "reaction"
name = "T"
on = "bob"
direction = "-string/L"
"#;

/// The rate of a coordinate may be an unknown: it loads, keeps its expression, and `pdyn
/// forces` substitutes it for the rate at the instant.
#[test]
fn an_unknown_may_be_a_coordinates_rate() {
    let m = example("conical_pendulum");
    assert_eq!(m.unknown_initials.len(), 1);
    let u = &m.unknown_initials[0];
    assert_eq!(
        (u.name.as_str(), u.key, u.text.as_str()),
        ("phi", "rate", "omega")
    );
    assert_eq!(u.unknowns, ["omega"]);
    match m.coordinates[0].kind {
        pdyn_mech::model::CoordinateKind::Free { initial, rate } => {
            assert_eq!(initial, 0.0);
            assert!(rate.is_nan(), "no number before pdyn forces: {rate}");
        }
        _ => panic!("phi is free"),
    }
    // An expression of unknowns and parameters is accepted the same way (`V/R`).
    let m = model(&CONICAL.replace("rate = \"omega\"", "rate = \"2*omega/L\""));
    assert_eq!(m.unknown_initials[0].text, "2*omega/L");
}

/// Conical pendulum, by hand: vertically T cos α = m g; radially (towards the axis)
/// T sin α = m (L sin α) ω². So T = m g / cos α and ω = √(g/(L cos α)), found exactly, the
/// positive root because ω is a rate (turning the other way is the same motion).
#[test]
fn conical_pendulum_rate_and_tension_in_closed_form() {
    for mut m in [example("conical_pendulum"), model(CONICAL)] {
        let r = solve(&mut m);
        let (g, mass, l, alpha) = (
            param(&m, "g"),
            param(&m, "m"),
            param(&m, "L"),
            param(&m, "alpha"),
        );
        let omega = sym(&r, "omega");
        same(&mut m, omega, "sqrt(g/(L*cos(alpha)))");
        let t = sym(&r, "T");
        same(&mut m, t, "m*g/cos(alpha)");
        assert_eq!(r.numeric.len(), 1, "one solution: {:?}", r.numeric);
        let w = r.numeric[0][index(&r, "omega")];
        assert!(
            (w - (g / (l * libm::cos(alpha))).sqrt()).abs() < 1e-12,
            "{w}"
        );
        let tension = r.numeric[0][index(&r, "T")];
        assert!(
            (tension - mass * g / libm::cos(alpha)).abs() < 1e-12,
            "{tension}"
        );
        let notes = r.notes.join("\n");
        assert!(!notes.contains("numerically"), "{notes}");
        assert!(
            notes.contains("omega enters only as omega^2")
                || notes.contains("`omega` enters only as omega^2"),
            "{notes}"
        );
        assert!(notes.contains("taken: omega is the rate of phi"), "{notes}");
    }
}

/// The class: any unknown that enters only squared. A car on a frictionless banked curve at
/// the speed V that needs no friction (the rate of theta is V/R): N cos β = m g and
/// N sin β = m V²/R, so V = √(g R tan β) and N = m g / cos β.
#[test]
fn a_speed_that_enters_squared_is_found_exactly() {
    let src = r#"
gravity = "[0, 0, -g]"
[parameters]
g = 9.81
m = 1200
R = 50
beta = 0.5
[unknowns]
V = {}
[coordinates]
theta = { initial = 0.0, rate = "V/R", acceleration = 0.0 }
[definitions]
e_r = "[cos(theta), sin(theta), 0]"
k = "[0, 0, 1]"
[particles.car]
mass = "m"
position = "R*e_r"
[[forces]]
kind = "reaction"
name = "N"
on = "car"
direction = "cos(beta)*k - sin(beta)*e_r"
"#;
    let mut m = model(src);
    let r = solve(&mut m);
    let v = sym(&r, "V");
    same(&mut m, v, "sqrt(g*R*tan(beta))");
    let n = sym(&r, "N");
    same(&mut m, n, "m*g/cos(beta)");
    assert_eq!(r.numeric.len(), 1);
    assert!(r.numeric[0][index(&r, "V")] > 0.0);
}

/// Without a sign (ω is in a prescribed angle, not a rate, and has no range) both roots are
/// listed and the note says so; a declared range keeps one, negative included.
#[test]
fn the_sign_of_the_root_follows_what_is_declared() {
    let prescribed = CONICAL.replace(
        "phi = { initial = 0.0, rate = \"omega\", acceleration = 0.0 }",
        "phi = \"omega*t\"",
    );
    let mut m = model(&prescribed);
    let r = solve(&mut m);
    let w = (9.81f64 / (1.5 * libm::cos(0.5f64))).sqrt();
    let k = index(&r, "omega");
    let mut roots: Vec<f64> = r.numeric.iter().map(|s| s[k]).collect();
    roots.sort_by(f64::total_cmp);
    assert_eq!(roots.len(), 2, "{roots:?}");
    assert!(
        (roots[0] + w).abs() < 1e-12 && (roots[1] - w).abs() < 1e-12,
        "{roots:?}"
    );
    let notes = r.notes.join("\n");
    assert!(notes.contains("omega = ±"), "{notes}");
    assert!(notes.contains("both roots"), "{notes}");

    let positive = prescribed.replace("omega = {}", "omega = { range = [0, 100] }");
    let mut m = model(&positive);
    let r = solve(&mut m);
    assert_eq!(r.numeric.len(), 1);
    assert!((r.numeric[0][k] - w).abs() < 1e-12);
    assert!(r
        .notes
        .join("\n")
        .contains("declared range is non-negative"));

    let negative = prescribed.replace("omega = {}", "omega = { range = [-100, 0] }");
    let mut m = model(&negative);
    let r = solve(&mut m);
    assert_eq!(r.numeric.len(), 1);
    assert!((r.numeric[0][k] + w).abs() < 1e-12);
    let omega = sym(&r, "omega");
    same(&mut m, omega, "-sqrt(g/(L*cos(alpha)))");
}

/// ω² = g/(L cos α) < 0 when the string points above the pivot (α > π/2): no real rate, said
/// as such with the exact power, not a failed numeric search.
#[test]
fn a_negative_square_is_no_real_root() {
    let mut m = model(&CONICAL.replace("alpha = 0.5", "alpha = 2.0"));
    match solve_forces(&mut m, &ForcesOptions::default()) {
        Err(e @ ForcesError::NoRealRoot { .. }) => {
            let text = e.to_string();
            assert!(text.contains("omega^2 = g/(L*cos(alpha))"), "{text}");
            assert!(text.contains("no real omega"), "{text}");
        }
        other => panic!("expected NoRealRoot, got {other:?}"),
    }
}

/// A run needs numbers: the model loads, but a run's preparation gets a located error naming
/// the rate, the unknown and `pdyn forces`.
#[test]
fn a_rate_left_to_forces_is_a_located_error_for_a_run() {
    let m = model(CONICAL);
    let e = m.unknown_initial_error().expect("refused for a run");
    let text = e.render(CONICAL);
    assert!(text.starts_with("model.toml:11:"), "{text}");
    assert!(text.contains("the rate of `phi`"), "{text}");
    assert!(text.contains("rate = \"omega\""), "{text}");
    assert!(text.contains("the unknown `omega`"), "{text}");
    assert!(text.contains("pdyn forces"), "{text}");
    // A model without unknown initial conditions has nothing to refuse.
    let numbers = CONICAL
        .replace("[unknowns]\nomega = {}\n", "")
        .replace("alpha = 0.5", "alpha = 0.5\nomega = 2.7");
    assert!(model(&numbers).unknown_initial_error().is_none());
}

/// What cannot be a rate even with unknowns stays a located error: a function of time, an
/// undefined name, a vector.
#[test]
fn bad_rates_naming_unknowns_are_located_errors() {
    for (rate, says) in [
        ("omega*t", "`rate` of `phi` must be a number here"),
        ("omega + q", "undefined name `q`"),
        ("[omega, 0]", "`rate` must be a scalar"),
    ] {
        let src = CONICAL.replace("rate = \"omega\"", &format!("rate = \"{rate}\""));
        let e = load(&src, "model.toml").expect_err(rate);
        let text = e.render(&src);
        assert!(text.starts_with("model.toml:11:"), "{text}");
        assert!(text.contains(says), "{text}");
        assert!(text.contains(rate), "the offending text is shown: {text}");
    }
    let src = CONICAL.replace("rate = \"omega\"", "rate = \"omega*t\"");
    let text = load(&src, "model.toml").unwrap_err().render(&src);
    assert!(text.contains("[unknowns]"), "what would be valid: {text}");
}
