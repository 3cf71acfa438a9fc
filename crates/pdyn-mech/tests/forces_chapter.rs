//! Forces for prescribed motion and design checks: the chapter's section 3.2 examples.

use pdyn_expr::{FreeScope, Id};
use pdyn_mech::prescribed::{solve_forces, ForcesOptions, ForcesResult};
use pdyn_mech::{load, Model};

fn example(name: &str) -> Model {
    let path = format!("{}/../../examples/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    load(&src, &path).unwrap_or_else(|e| panic!("{}", e.render(&src)))
}

fn solve(m: &mut Model, at: &[(&str, f64)]) -> ForcesResult {
    let opts = ForcesOptions {
        at: at.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
    };
    solve_forces(m, &opts).unwrap_or_else(|e| panic!("{e}"))
}

fn sym(r: &ForcesResult, name: &str) -> Id {
    let k = r.unknowns.iter().position(|u| u == name).unwrap();
    r.symbolic.as_ref().unwrap()[k]
}

fn val(r: &ForcesResult, name: &str) -> f64 {
    let k = r.unknowns.iter().position(|u| u == name).unwrap();
    r.numeric[0][k]
}

fn same(m: &mut Model, got: Id, expected: &str, coords: &[&str]) {
    let mut scope = FreeScope::with_coordinates(coords.iter().copied());
    let e = m
        .pool
        .parse_in(expected, &mut scope)
        .unwrap()
        .scalar()
        .unwrap();
    assert!(
        m.pool.provably_equal(got, e),
        "got {}, expected {expected}",
        m.pool.to_text(got)
    );
}

fn param(m: &Model, name: &str) -> f64 {
    m.parameters.iter().find(|p| p.name == name).unwrap().value
}

#[test]
fn takeoff_thrust_is_222_kn() {
    let mut m = example("takeoff");
    let r = solve(&mut m, &[]);
    let f = sym(&r, "F_T");
    same(&mut m, f, "m*v_t^2/(2*d)", &[]);
    let ft = val(&r, "F_T");
    assert!((ft - 15000.0 * 77.0 * 77.0 / 400.0).abs() < 1e-6, "{ft}");
    assert!((ft / 1e3 - 222.0).abs() < 0.5);
}

#[test]
fn tablecloth_slips_for_a_above_mu_g() {
    let mut m = example("tablecloth");
    let r = solve(&mut m, &[]);
    let c = &r.checks[0];
    assert_eq!(c.symbolic.len(), 1);
    let crit = c.symbolic[0];
    same(&mut m, crit, "mu*g", &[]);
    let (v, _) = c.min.unwrap();
    assert!((v - param(&m, "mu") * param(&m, "g")).abs() < 1e-9);
}

#[test]
fn bicycle_tips_for_mu_above_l_minus_d_over_h() {
    let mut m = example("bicycle");
    let r = solve(&mut m, &[]);
    let na = sym(&r, "N_A");
    same(&mut m, na, "m*g*(L - d - mu*h)/(L - mu*h)", &["x"]);
    let c = &r.checks[0];
    let crit = c.symbolic[0];
    same(&mut m, crit, "(L - d)/h", &[]);
    let expected = (param(&m, "L") - param(&m, "d")) / param(&m, "h");
    assert!((c.min.unwrap().0 - expected).abs() < 1e-9);
}

#[test]
fn pulley_tension() {
    let mut m = example("pulley");
    let r = solve(&mut m, &[]);
    let t = sym(&r, "T");
    same(&mut m, t, "2*mA*mB*g/(mA + mB)", &[]);
}

#[test]
fn block_on_rotating_bar_forces_and_slip() {
    let mut m = example("rotating_bar_block");
    // At a general angle, numerically: N = m g cos(theta), T = m g sin(theta) - m r omega^2.
    let th = 0.7;
    let r = solve(&mut m, &[("theta", th)]);
    let (g, mass, rad, w) = (
        param(&m, "g"),
        param(&m, "m"),
        param(&m, "r"),
        param(&m, "omega"),
    );
    assert!((val(&r, "N") - mass * g * libm::cos(th)).abs() < 1e-12);
    assert!((val(&r, "T") - (mass * g * libm::sin(th) - mass * rad * w * w)).abs() < 1e-12);
    // At theta = 0: critical omega = sqrt(mu g / r); T < 0 there: the block slides outwards.
    let mut m = example("rotating_bar_block");
    let r = solve(&mut m, &[]);
    let c = &r.checks[0];
    same(&mut m, c.symbolic[0], "sqrt(mu*g/r)", &[]);
    let mu = param(&m, "mu");
    assert!((c.min.unwrap().0 - (mu * g / rad).sqrt()).abs() < 1e-9);
    let t = c
        .forces_at_critical
        .iter()
        .find(|(n, _)| n == "T")
        .unwrap()
        .1;
    assert!(
        t < 0.0,
        "friction points inwards, so the block slides outwards: T = {t}"
    );
    assert!(m.friction_forces.contains(&"T".to_string()));
}

#[test]
fn window_blind_latch() {
    let mut m = example("window_blind");
    let r = solve(&mut m, &[]);
    let t = sym(&r, "T");
    same(&mut m, t, "g*m*cos(theta)/sin(phi)", &["theta"]);
    let n = sym(&r, "N");
    same(
        &mut m,
        n,
        "m*R*omega^2 - g*m*cos(theta - phi)/sin(phi)",
        &["theta"],
    );
    let c = &r.checks[0];
    let (g, rr, phi) = (param(&m, "g"), param(&m, "R"), param(&m, "phi"));
    let (wmax, at) = c.max.unwrap();
    let expected = (g / (rr * libm::sin(phi))).sqrt();
    assert!(
        (wmax - expected).abs() < 1e-3 * expected,
        "{wmax} vs {expected}"
    );
    assert!(
        (at.unwrap() - phi).abs() < 0.02,
        "worst angle theta = phi: {at:?}"
    );
}

#[test]
fn standard_rate_turn_for_three_aircraft() {
    // (V in m/s, rounded chapter values: bank angle in degrees, radius in m, load factor)
    for (v, bank, radius, load) in [
        (36.0, 11.0, 690.0, 1.02),
        (102.0, 28.0, 1950.0, 1.14),
        (154.0, 39.0, 2950.0, 1.3),
    ] {
        let mut m = example("aircraft_turn");
        m.parameters
            .iter_mut()
            .find(|p| p.name == "V")
            .unwrap()
            .value = v;
        let r = solve(&mut m, &[]);
        let (g, w, mass) = (param(&m, "g"), param(&m, "omega"), param(&m, "m"));
        assert!((w - std::f64::consts::PI / 60.0).abs() < 1e-15);
        let alpha = val(&r, "alpha");
        let fl = val(&r, "F_L");
        assert!((alpha - libm::atan(v * w / g)).abs() < 1e-12);
        let n = fl / (mass * g);
        assert!((n - (1.0 + v * v * w * w / (g * g)).sqrt()).abs() < 1e-12);
        assert!(
            (alpha.to_degrees() - bank).abs() < 0.6,
            "{v}: bank {}",
            alpha.to_degrees()
        );
        assert!(
            ((v / w) - radius).abs() / radius < 0.01,
            "{v}: radius {}",
            v / w
        );
        assert!((n - load).abs() < 0.01, "{v}: load factor {n}");
        assert!((val(&r, "F_T") - param(&m, "F_D")).abs() < 1e-9);
        // The upside-down solution (-F_L, alpha + pi) is outside the declared bank-angle
        // range (-pi/2, pi/2), so it is left out (issue 11: declared ranges are honoured)...
        assert_eq!(r.numeric.len(), 1);
        assert!(r
            .notes
            .iter()
            .any(|n| n.contains("outside the unknowns' declared ranges")));
        let sa = sym(&r, "alpha");
        same(&mut m, sa, "atan(V*omega/g)", &[]);
    }
    // ... and reported when the range admits it.
    let wide = example("aircraft_turn")
        .source
        .replace("range = [\"-pi/2\", \"pi/2\"]", "range = [\"-pi\", \"pi\"]");
    let mut m = load(&wide, "aircraft_turn.toml").unwrap();
    let r = solve_forces(&mut m, &ForcesOptions::default()).unwrap();
    assert_eq!(r.numeric.len(), 2);
}

#[test]
fn count_mismatch_names_what_is_missing() {
    let m = example("takeoff");
    let src = m.source.replace(
        "F_T = {}              # engine thrust",
        "F_T = {}\nF_X = {}",
    );
    let mut m2 = load(&src, "takeoff.toml").unwrap();
    let e = solve_forces(&mut m2, &ForcesOptions::default()).unwrap_err();
    assert!(e.to_string().contains("no equation involves F_X"), "{e}");
}

/// A check with two critical values in its range reports both, ascending (issue 11: only the
/// smallest was reported). Banked curve: V² = g R (sin β ∓ μ cos β)/(cos β ± μ sin β).
#[test]
fn banked_curve_reports_the_least_and_the_greatest_speed() {
    let mut m = example("banked_curve");
    let res = solve_forces(&mut m, &ForcesOptions::default()).unwrap();
    let c = &res.checks[0];
    let (g, r, b, mu) = (9.81f64, 50.0f64, 30f64.to_radians(), 0.2f64);
    let v_min =
        (g * r * (libm::sin(b) - mu * libm::cos(b)) / (libm::cos(b) + mu * libm::sin(b))).sqrt();
    let v_max =
        (g * r * (libm::sin(b) + mu * libm::cos(b)) / (libm::cos(b) - mu * libm::sin(b))).sqrt();
    let got: Vec<f64> = c.critical.iter().map(|k| k.value).collect();
    assert_eq!(got.len(), 2, "{got:?}");
    assert!((got[0] - v_min).abs() < 1e-9 * v_min, "{got:?} vs {v_min}");
    assert!((got[1] - v_max).abs() < 1e-9 * v_max, "{got:?} vs {v_max}");
    // Friction reverses between the two: down the bank at V_min, up at V_max.
    let t = |k: usize| c.critical[k].forces.iter().find(|f| f.0 == "T").unwrap().1;
    assert!(t(0) < 0.0 && t(1) > 0.0);
}
