//! Indexed families in model files (issue 33): a family expands to exactly the model written
//! out entry by entry, and bad families are located errors naming the member that failed.

use pdyn_mech::model::{Model, Target};
use pdyn_mech::{derive, load, DeriveOptions};

/// `examples/hanging_net.toml` with its size set to `n`.
fn family_net(n: usize) -> String {
    let text = include_str!("../../../examples/hanging_net.toml");
    let line = text.lines().find(|l| l.starts_with("n = ")).unwrap();
    text.replacen(line, &format!("n = {n}"), 1)
}

fn loaded(src: &str) -> Model {
    load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

fn load_err(src: &str) -> String {
    match load(src, "model.toml") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => e.render(src),
    }
}

/// Everything a model is made of, printed: names, initial values, masses, positions, points,
/// loads with their labels and targets, potentials.
fn summary(m: &Model) -> Vec<String> {
    let p = &m.pool;
    let mut out = Vec::new();
    for par in &m.parameters {
        out.push(format!("parameter {} = {}", par.name, par.value));
    }
    for c in &m.coordinates {
        out.push(format!("coordinate {} {:?}", c.name, c.kind));
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
        let f = l.force.map(|c| p.to_text(c));
        out.push(format!("load {} on {target}: {f:?}", l.label));
    }
    for v in &m.potentials {
        out.push(format!("potential {}: {}", v.label, p.to_text(v.energy)));
    }
    out
}

#[test]
fn the_family_net_is_the_net_written_out() {
    let explicit = include_str!("data/net3_explicit.toml");
    let a = loaded(&family_net(3));
    let b = loaded(explicit);
    // 3 x 3 nodes, two pinned: 7 particles, 21 coordinates, 2 points.
    assert_eq!(a.particles.len(), 7);
    assert_eq!(a.coordinates.len(), 21);
    assert_eq!(a.points.len(), 2);
    // Springs: 2*3 horizontal + 3*2 vertical + 4 diagonal + 4 antidiagonal, two loads each
    // except the ones fixed at a pin; drag and gravity on each particle.
    let (sa, sb) = (summary(&a), summary(&b));
    assert_eq!(sa.len(), sb.len());
    for (x, y) in sa.iter().zip(&sb) {
        assert_eq!(x, y);
    }
    // And the derived equations of motion are the same text.
    let opts = DeriveOptions::default();
    let (mut a, mut b) = (a, b);
    let da = derive(&mut a, &opts).unwrap();
    let db = derive(&mut b, &opts).unwrap();
    assert_eq!(da.equations.len(), 21);
    assert_eq!(da.state_names, db.state_names);
    for (x, y) in da.equations.iter().zip(&db.equations) {
        assert_eq!(a.pool.to_text(x.lhs), b.pool.to_text(y.lhs));
        assert_eq!(a.pool.to_text(x.rhs), b.pool.to_text(y.rhs));
    }
}

#[test]
fn member_counts_follow_the_ranges_and_conditions() {
    // Counted by hand for n = 6: 34 free nodes; springs 5*6 + 6*5 + 25 + 25 = 110, of which
    // the ones touching a pin put one load instead of two: P[0,0] has 3 springs (right, up,
    // diagonal), P[5,0] has 3 (left, up, antidiagonal): 6 single loads.
    let m = loaded(&family_net(6));
    assert_eq!(m.particles.len(), 34);
    let springs = m
        .loads
        .iter()
        .filter(|l| {
            l.label.starts_with("horizontal")
                || l.label.starts_with("vertical")
                || l.label.contains("diagonal")
        })
        .count();
    assert_eq!(springs, 2 * 110 - 6);
    let drag = m
        .loads
        .iter()
        .filter(|l| l.label.starts_with("drag"))
        .count();
    assert_eq!(drag, 34);
    assert_eq!(m.particles[0].name, "P[0,1]");
    let last = m.particles.iter().position(|p| p.name == "P[4,5]").unwrap();
    assert!(
        m.loads
            .iter()
            .any(|l| l.label.starts_with("horizontal[i=3, j=5]")
                && l.target == Target::Particle(last))
    );
}

const NET: &str = r#"
[indices]
n = 4
i = "0..n-1"
j = "0..n-1"

[parameters]
m = 1.0
k = 10.0

[coordinates]
"x[i,j]" = { initial = "i", rate = 0 }

[particles."P[i,j]"]
mass = "m"
position = "[x[i,j], j, 0]"
"#;

#[test]
fn a_neighbour_outside_the_family_is_located_and_names_the_member() {
    let src = format!(
        "{NET}\n[[forces]]\nkind = \"spring\"\nname = \"spring\"\nfor = \"i, j\"\nbetween = [\"P[i,j]\", \"P[i+1,j]\"]\nk = \"k\"\nl0 = 1\n"
    );
    let e = load_err(&src);
    assert!(
        e.contains("error: spring[i=3, j=0]: P[4,0] is outside P[0..3, 0..3]"),
        "{e}"
    );
    // Located at the name, line and column.
    let line = src.lines().position(|l| l.starts_with("between")).unwrap() + 1;
    // The second name of `between = ["P[i,j]", "P[i+1,j]"]`, after its quote.
    assert!(e.contains(&format!("model.toml:{line}:23:")), "{e}");
}

#[test]
fn a_member_outside_its_family_in_an_expression_is_located() {
    let src = NET.replace(
        "position = \"[x[i,j], j, 0]\"",
        "position = \"[x[i,j+1], j, 0]\"",
    );
    let e = load_err(&src);
    assert!(
        e.contains("P[i=0, j=3]: x[0,4] is outside x[0..3, 0..3]"),
        "{e}"
    );
    assert!(e.contains("x[i,j+1]") && e.contains("^^^^^^^^"), "{e}");
}

#[test]
fn bad_families_are_clear_errors() {
    let cases: [(&str, &str, &str); 10] = [
        // The widest range there is: refused, not overflowed.
        (
            "i = \"0..n-1\"",
            "i = \"-9223372036854775807-1..9223372036854775807\"",
            "which would make the model's families more than",
        ),
        // An empty range.
        (
            "i = \"0..n-1\"",
            "i = \"3..1\"",
            "index `i` has an empty range 3..1",
        ),
        // A range using a name that is not a size.
        (
            "i = \"0..n-1\"",
            "i = \"0..m-1\"",
            "`m` is not an index here, nor a size",
        ),
        // A family of 10^12 members is refused before anything is made.
        (
            "n = 4",
            "n = 1000000",
            "which would make the model's families more than",
        ),
        // A condition leaving nothing.
        (
            "mass = \"m\"",
            "where = \"i > n\"\nmass = \"m\"",
            "the family `P` has no members",
        ),
        // A condition that is a number.
        (
            "mass = \"m\"",
            "where = \"i + 1\"\nmass = \"m\"",
            "P[i=0, j=0]: expected a condition",
        ),
        // Index arithmetic in a declaration.
        (
            "[particles.\"P[i,j]\"]",
            "[particles.\"P[i+1,j]\"]",
            "a family is declared over index names",
        ),
        // An index with no range.
        ("\"x[i,j]\" = {", "\"x[i,k]\" = {", "index `k` has no range"),
        // An index name taken by a parameter.
        ("m = 1.0", "m = 1.0\ni = 2.0", "`i` is an index"),
        // A size of the wrong type.
        ("n = 4", "n = 4.5", "a size (an integer) or a range"),
    ];
    for (from, to, want) in cases {
        let src = NET.replacen(from, to, 1);
        assert_ne!(src, NET, "{from}");
        let e = load_err(&src);
        assert!(e.contains(want), "{to}: {e}");
    }
}

#[test]
fn a_force_family_joining_a_particle_to_itself_is_refused() {
    let src = format!(
        "{NET}\n[[forces]]\nkind = \"spring\"\nfor = \"i in 0..2, j\"\nbetween = [\"P[i,j]\", \"P[2*i - i, j]\"]\nk = \"k\"\nl0 = 1\n"
    );
    let e = load_err(&src);
    assert!(
        e.contains("spring[i=0, j=0]: `between` joins `P[0,0]` to itself"),
        "{e}"
    );
}

#[test]
fn a_force_on_a_member_that_does_not_exist_is_refused() {
    // A pin (point) on a node the family does not have.
    let src = format!(
        "{NET}\n[points]\n\"P[i,j]\" = {{ position = \"[0, 0, 0]\", where = \"i == 7\" }}\n"
    );
    let e = load_err(&src);
    assert!(e.contains("the family `P` has no members"), "{e}");
    let src = format!("{NET}\n[[forces]]\nkind = \"linear_drag\"\non = \"P[0,9]\"\nc = 1\n");
    let e = load_err(&src);
    assert!(e.contains("P[0,9] is outside P[0..3, 0..3]"), "{e}");
    let src = NET.replace("mass = \"m\"", "mass = \"m\"\nwhere = \"i > 0\"")
        + "\n[[forces]]\nkind = \"linear_drag\"\non = \"P[0,1]\"\nc = 1\n";
    let e = load_err(&src);
    assert!(e.contains("unknown particle `P[0,1]`"), "{e}");
}

#[test]
fn for_and_where_belong_to_families() {
    let src = format!(
        "{NET}\n[[forces]]\nkind = \"linear_drag\"\non = \"P[0,1]\"\nc = 1\nwhere = \"i > 0\"\n"
    );
    assert!(load_err(&src).contains("`where` needs `for`"));
    let src = NET.replace("[particles.\"P[i,j]\"]", "[particles.Q]\nmass = 1\nposition = \"[0,0,0]\"\nwhere = \"i > 0\"\n\n[particles.\"P[i,j]\"]");
    assert!(load_err(&src).contains("`for` and `where` belong to families"));
}

#[test]
fn members_are_named_like_the_chapter_and_usable_everywhere() {
    let src = format!("{NET}\n[monitors]\ncorner = \"x[n-1, n-1] + r_P[0,0].y\"\n");
    let m = loaded(&src);
    assert_eq!(m.run.monitors[0].name, "corner");
    assert_eq!(m.pool.to_text(m.run.monitors[0].expr), "x[3,3]");
    // Written with spaces or without, a member is the same name.
    let m = loaded(&NET.replace("[x[i,j], j, 0]", "[x[ i , j ], j, 0]"));
    assert_eq!(m.particles.len(), 16);
}

/// A member's field that names nothing of its own is lowered once for the family
/// (`mass = "m"`); one that names an index, a subscripted member or a table column is lowered
/// for each member: each particle's mass and position must be its own.
#[test]
fn index_free_fields_are_shared_and_indexed_ones_are_each_members() {
    let src = r#"
[indices]
n = 4
i = "1..n"

[parameters]
m = 2.0
L = 0.5

[coordinates]
"x[i]" = { initial = "i*L", rate = 0 }

[particles."P[i]"]
mass = "m"
position = "[x[i], 0, 0]"

[particles."Q[i]"]
mass = "m*i"
position = "[x[i], L*i, 0]"

[particles."R[i]"]
mass = "m + n"
position = "r_P[i] + [0, 0, 1]"
"#;
    let model = loaded(src);
    let p = &model.pool;
    let text = |name: &str| {
        let q = model.particles.iter().find(|q| q.name == name).unwrap();
        (p.to_text(q.mass), q.position.map(|c| p.to_text(c)))
    };
    for i in 1..=4 {
        let x = format!("x[{i}]");
        let (mass, position) = text(&format!("P[{i}]"));
        assert_eq!(mass, "m");
        assert_eq!(position, [x.clone(), "0".into(), "0".into()]);
        let (mass, position) = text(&format!("Q[{i}]"));
        let m_i = if i == 1 {
            "m".to_string()
        } else {
            format!("{i}*m")
        };
        assert_eq!(mass, m_i, "Q[{i}]");
        let y = if i == 1 {
            "L".to_string()
        } else {
            format!("{i}*L")
        };
        assert_eq!(position, [x.clone(), y, "0".into()], "Q[{i}]");
        let (mass, position) = text(&format!("R[{i}]"));
        assert_eq!(mass, "4 + m");
        assert_eq!(position, [x, "0".into(), "1".into()], "R[{i}]");
    }
}

/// `examples/chain_modes.toml` with `n` masses.
fn chain(n: usize) -> String {
    include_str!("../../../examples/chain_modes.toml").replacen(
        "n = 30\n",
        &format!("n = {n}\n"),
        1,
    )
}

/// The names of members a load makes, on this thread.
fn names_made_loading(src: &str) -> u64 {
    let before = pdyn_mech::model::families::names_made();
    pdyn_mech::model::load_deferring(src, "chain.toml")
        .unwrap_or_else(|e| panic!("{}", e.render(src)));
    pdyn_mech::model::families::names_made() - before
}

/// The springs of a chain find their ends `P[i+1]`, `P[i]` by index: loading `n` more masses
/// makes exactly `3 n` more names, the keys of `n` coordinates `x[i]` and `n` particles `P[i]`
/// and the `n` references `x[i]` of the particles' positions, and none for the `n` springs'
/// `2 n` ends (by name they were `5 n`).
#[test]
fn a_chain_s_springs_find_their_ends_without_names() {
    let (a, b) = (
        names_made_loading(&chain(100)),
        names_made_loading(&chain(300)),
    );
    assert_eq!(b - a, 3 * 200, "{a} names for 100 masses, {b} for 300");
}

/// The same ends found by index or by name: a chain loaded with deferral has one spring family
/// whose members join `P[i+1]` to `P[i]` (the walls' springs, to points, are built), and
/// loaded in full the springs pull on the particles the names give.
#[test]
fn springs_found_by_index_join_the_neighbours() {
    let n = 7;
    let m = pdyn_mech::model::load_deferring(&chain(n), "chain.toml").unwrap();
    let names: Vec<&str> = m.particles.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["P[1]", "P[2]", "P[3]", "P[4]", "P[5]", "P[6]", "P[7]"]
    );
    assert_eq!(m.deferred.len(), 1);
    let d = &m.deferred[0];
    // The representative joins P[2] (particle 1) to P[1] (particle 0): spring i = 1.
    assert_eq!(d.ends, [1, 0]);
    // Springs i = 2..6 join P[i+1] (particle i) to P[i] (particle i - 1).
    let members: Vec<Vec<u32>> = d.each().map(|e| e.to_vec()).collect();
    let expected: Vec<Vec<u32>> = (2..n as u32).map(|i| vec![i, i - 1]).collect();
    assert_eq!(members, expected);
}

/// A reference outside its family by index arithmetic is the same located error as before.
#[test]
fn a_spring_beyond_the_chain_names_its_member_and_the_family() {
    let src = chain(30).replace("for = \"i in 0..n\"", "for = \"i in 0..n+1\"");
    let e = match pdyn_mech::model::load_deferring(&src, "chain.toml") {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.render(&src),
    };
    assert!(e.contains("spring[i=31]: P[32] is outside P[0..31]"), "{e}");
}
