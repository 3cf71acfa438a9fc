//! A family's field read from one template (issue 33): a position such as `[x[i,j], y[i,j],
//! 0]` is analysed once and each member only resolves its own names. The model must be the
//! one read member by member (the same expressions, the same pool ids), and an error met by
//! one member must be the one it was, naming the member.

use pdyn_mech::load;
use pdyn_mech::model::Model;

fn loaded(src: &str) -> Model {
    load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

fn load_err(src: &str) -> String {
    match load(src, "model.toml") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e.render(src),
    }
}

/// A 3 x 3 net of particles over two indices, with a scalar family (`mm[i]`, a definition per
/// member) for the masses and a planar chain `Q[i]` with two-component positions. `POSITION`,
/// `QPOS` and `MASS` are replaced by each test.
const NET: &str = r#"
gravity = "[0, 0, -g]"

[indices]
n = 3
i = "0..n-1"
j = "0..n-1"

[parameters]
m = 0.5
k = 40.0
a = 0.1
g = 9.81

[coordinates]
"x[i,j]" = { initial = "i*a", rate = 0 }
"y[i,j]" = { initial = "j*a", rate = 0 }
"z[i,j]" = { initial = 0, rate = 0 }
"u[i]" = { initial = "i*a", rate = 0 }

[definitions]
"mm[i]" = "m*(1 + i)"

[particles."P[i,j]"]
mass = MASS
position = POSITION

[particles."Q[i]"]
mass = "m"
position = QPOS

[[forces]]
kind = "spring"
name = "h"
for = "i in 0..n-2, j"
between = ["P[i,j]", "P[i+1,j]"]
k = "k"
l0 = "a"

[[forces]]
kind = "spring"
name = "q"
for = "i in 0..n-2"
between = ["Q[i]", "Q[i+1]"]
k = "k"
l0 = "a"
"#;

fn net(mass: &str, position: &str, qpos: &str) -> String {
    NET.replace("MASS", &format!("{mass:?}"))
        .replace("QPOS", &format!("{qpos:?}"))
        .replace("POSITION", &format!("{position:?}"))
}

/// Every particle's mass, position and velocity, and every load, as text and in order.
fn summary(m: &Model) -> Vec<String> {
    let mut pool = m.pool.clone();
    let mut out = Vec::new();
    for q in &m.particles {
        let velocity = q.position.map(|c| pool.dt(c));
        out.push(format!(
            "{} {} {:?} {:?}",
            q.name,
            pool.to_text(q.mass),
            q.position.map(|c| pool.to_text(c)),
            velocity.map(|c| pool.to_text(c)),
        ));
    }
    for l in &m.loads {
        out.push(format!(
            "{} {:?}",
            l.label,
            l.force.map(|c| pool.to_text(c))
        ));
    }
    out
}

#[test]
fn a_template_gives_the_model_read_member_by_member() {
    // `0*i` names an index: the component varies, so the text has no template and each member
    // is lowered in full. The same expressions must come out.
    let templated = loaded(&net("mm[i]", "[x[i,j], y[i,j], z[i,j]]", "[u[i], a]"));
    let in_full = loaded(&net(
        "mm[i] + 0*i",
        "[x[i,j] + 0*i, y[i,j], z[i,j]]",
        "[u[i] + 0*i, a]",
    ));
    assert_eq!(summary(&templated), summary(&in_full));
    // And they are the members' own: each component the coordinate it names (the same pool
    // id), the velocity its rate, the masses m (1 + i).
    let pool = &templated.pool;
    for (k, q) in templated.particles.iter().enumerate().take(9) {
        let (i, j) = (k / 3, k % 3);
        assert_eq!(q.name, format!("P[{i},{j}]"));
        for (axis, base) in ["x", "y", "z"].iter().enumerate() {
            let sym = templated
                .coordinates
                .iter()
                .find(|c| c.name == format!("{base}[{i},{j}]"))
                .unwrap()
                .sym;
            assert_eq!(
                pool.node(q.position[axis]),
                &pdyn_expr::Node::Coord(sym, 0),
                "{} {axis}",
                q.name
            );
        }
        let mass = templated.pool.to_text(q.mass);
        let want = match i {
            0 => "m".to_string(),
            _ => format!("{}*m", i + 1),
        };
        assert_eq!(mass, want, "{}", q.name);
    }
    for (i, q) in templated.particles.iter().skip(9).enumerate() {
        assert_eq!(q.name, format!("Q[{i}]"));
        assert_eq!(pool.to_text(q.position[0]), format!("u[{i}]"));
        assert_eq!(pool.to_text(q.position[1]), "a");
        assert_eq!(q.position[2], pdyn_expr::Pool::ZERO);
    }
}

#[test]
fn an_error_met_through_a_template_names_the_member() {
    // The last column's neighbour does not exist: the template's member cannot resolve
    // `x[i,j+1]`, and the member is read in full, with the error it always had.
    let e = load_err(&net("m", "[x[i,j+1], y[i,j], 0]", "[u[i], 0]"));
    assert!(
        e.contains("P[i=0, j=2]: x[0,3] is outside x[0..2, 0..2]"),
        "{e}"
    );
    assert!(e.contains("x[i,j+1]") && e.contains("^^^^^^^^"), "{e}");
    // A scalar family where a vector's component belongs: the member's error.
    let e = load_err(&net("m", "[x[i,j], y[i,j], z[i,j]]", "[r_P[i,0], 0]"));
    assert!(e.contains("Q[i=0]: "), "{e}");
    assert!(e.contains("must be a scalar"), "{e}");
    // A scalar field naming a vector member.
    let e = load_err(&net("r_Q[i]", "[x[i,j], y[i,j], z[i,j]]", "[u[i], 0]"));
    assert!(e.contains("P[i=0, j=0]: "), "{e}");
}
