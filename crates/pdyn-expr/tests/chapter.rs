//! The chapter's symbolic steps (Bower, *Dynamics*, ch. 3), done by the engine.

use pdyn_expr::{FreeScope, Pool, Value};

fn vector(p: &mut Pool, src: &str) -> [pdyn_expr::Id; 3] {
    p.parse_value(src).unwrap().vector().unwrap()
}

#[test]
fn general_circular_motion_acceleration() {
    let mut p = Pool::new();
    let r = vector(&mut p, "[R*cos(th(t)), R*sin(th(t)), 0]");
    let v = r.map(|c| p.dt(c));
    let a = v.map(|c| p.dt(c));
    // a = R*alpha*(-sin, cos) - R*omega^2*(cos, sin)
    let expected = vector(
        &mut p,
        "R*th''*[-sin(th), cos(th), 0] - R*th'^2*[cos(th), sin(th), 0]",
    );
    assert_eq!(a, expected);
    let a2 = pdyn_expr::vector::dot(&mut p, a, a);
    let s = p.simplify(a2);
    assert_eq!(p.to_text(s), "R^2*th'^4 + R^2*th''^2");
    let no_trig = p.parse_scalar("R^2*th''^2 + R^2*th'^4").unwrap();
    assert_eq!(s, no_trig);
}

fn solve(p: &mut Pool, eqs: &[&str], unknowns: &[&str]) -> Vec<pdyn_expr::Id> {
    let mut scope = FreeScope::default();
    let eqs: Vec<_> = eqs
        .iter()
        .map(|e| match p.parse_equation_in(e, &mut scope).unwrap() {
            Value::Scalar(s) => s,
            Value::Vector(_) => panic!("vector equation"),
        })
        .collect();
    let us: Vec<_> = unknowns.iter().map(|u| p.var(u)).collect();
    let sys = p.linear_system(&eqs, &us).unwrap();
    p.solve_linear(&sys).unwrap()
}

#[test]
fn block_on_rotating_bar_example_5() {
    let mut p = Pool::new();
    let sol = solve(
        &mut p,
        &[
            "T*cos(theta) - N*sin(theta) = -m*r*omega^2*cos(theta)",
            "N*cos(theta) + T*sin(theta) - m*g = -m*r*omega^2*sin(theta)",
        ],
        &["N", "T"],
    );
    let n = p.parse_scalar("g*m*cos(theta)").unwrap();
    let t = p.parse_scalar("g*m*sin(theta) - m*r*omega^2").unwrap();
    assert_eq!(p.to_text(sol[0]), "g*m*cos(theta)");
    assert_eq!(sol[0], n);
    assert_eq!(sol[1], t, "T = {}", p.to_text(sol[1]));
}

#[test]
fn window_blind_latch_example_6() {
    let mut p = Pool::new();
    let sol = solve(
        &mut p,
        &[
            "-T*cos(phi - theta) - N*cos(theta) = -m*R*omega^2*cos(theta)",
            "-N*sin(theta) + T*sin(phi - theta) - m*g = -m*R*omega^2*sin(theta)",
        ],
        &["T", "N"],
    );
    let t = p.parse_scalar("g*m*cos(theta)/sin(phi)").unwrap();
    assert_eq!(sol[0], t, "T = {}", p.to_text(sol[0]));
    // N = m R omega^2 - g m cos(theta - phi)/sin(phi), with cos(theta - phi) possibly expanded.
    let n_ref = p
        .parse_scalar("m*R*omega^2 - g*m*cos(theta - phi)/sin(phi)")
        .unwrap();
    assert!(p.provably_equal(sol[1], n_ref), "N = {}", p.to_text(sol[1]));
    let text = p.to_text(sol[1]);
    assert!(
        !text.contains("^2*sin(theta)^2"),
        "unsimplified identity left: {text}"
    );
    // The determinant simplified: the only denominator is sin(phi).
    assert!(text.matches('/').count() <= 1, "{text}");
    assert!(text.contains("/sin(phi)"), "{text}");
}
