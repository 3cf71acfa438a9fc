//! Closed forms of linear structures with many degrees of freedom (issue 12): a 10-storey shear
//! building under base shaking and a 50-mass spring chain, each element with its own symbolic
//! mass and stiffness. Their accelerations are left to the numeric solve (too many unknowns
//! to eliminate symbolically), so `pdyn check` and `pdyn run --method exact` solve
//! `M q'' = f` at the parameters' values, by the eigen-decomposition of M and K; the result
//! must match a tight numerical integration. (The models are those of
//! bench/structure_models.py.)

use pdyn::sim::{self, RunSettings};
use pdyn_mech::Model;

/// An n-storey shear building: floor masses m_i, storey stiffnesses k_i, storey height L,
/// the ground moving as d0 sin(omega t).
fn building(n: usize) -> String {
    let mut s = format!("name = \"{n}-storey building\"\ngravity = \"[0, -g, 0]\"\n\n");
    s += "[parameters]\ng = 9.81\nL = 3.0\nd0 = 0.05\nomega = 9.0\n";
    for i in 1..=n {
        s += &format!(
            "m{i} = {}\nk{i} = {}\n",
            1.0 + 0.1 * (i % 3) as f64,
            400 + 10 * i
        );
    }
    s += "\n[coordinates]\nd = \"d0*sin(omega*t)\"\n";
    for i in 1..=n {
        s += &format!("y{i} = {{ initial = \"{i}*L\", rate = 0.0 }}\n");
    }
    s += "\n[points]\nground = \"[0, d, 0]\"\n";
    for i in 1..=n {
        s += &format!("\n[particles.floor{i}]\nmass = \"m{i}\"\nposition = \"[0, y{i}, 0]\"\n");
    }
    for i in 1..=n {
        let (below, lower) = if i == 1 {
            ("ground".to_string(), "d".to_string())
        } else {
            (format!("floor{}", i - 1), format!("y{}", i - 1))
        };
        s += &format!(
            "\n[[forces]]\nkind = \"spring\"\nbetween = [\"floor{i}\", \"{below}\"]\n\
             k = \"k{i}\"\nl0 = \"L\"\nlength = \"y{i} - {lower}\"\n"
        );
    }
    s + "\n[simulate]\nt_end = 10.0\n"
}

/// n masses m_i in a line between two walls, joined by springs k_1 ... k_(n+1) of unstretched
/// length L; the first mass starts displaced by 0.1.
fn spring_chain(n: usize) -> String {
    let mut s = format!("name = \"{n}-mass spring chain\"\n\n[parameters]\nL = 1.0\n");
    for i in 1..=n {
        s += &format!("m{i} = {}\n", 1.0 + 0.25 * (i % 4) as f64);
    }
    for i in 1..=n + 1 {
        s += &format!("k{i} = {}\n", 100 + 5 * (i % 7));
    }
    s += "\n[coordinates]\n";
    for i in 1..=n {
        let extra = if i == 1 { " + 0.1" } else { "" };
        s += &format!("x{i} = {{ initial = \"{i}*L{extra}\", rate = 0.0 }}\n");
    }
    s += &format!(
        "\n[points]\nleft_wall = \"[0, 0, 0]\"\nright_wall = \"[{}*L, 0, 0]\"\n",
        n + 1
    );
    for i in 1..=n {
        s += &format!("\n[particles.p{i}]\nmass = \"m{i}\"\nposition = \"[x{i}, 0, 0]\"\n");
    }
    for i in 1..=n + 1 {
        let (a, xa) = if i == 1 {
            ("left_wall".to_string(), "0".to_string())
        } else {
            (format!("p{}", i - 1), format!("x{}", i - 1))
        };
        let (b, xb) = if i == n + 1 {
            ("right_wall".to_string(), format!("{}*L", n + 1))
        } else {
            (format!("p{i}"), format!("x{i}"))
        };
        s += &format!(
            "\n[[forces]]\nkind = \"spring\"\nbetween = [\"{b}\", \"{a}\"]\n\
             k = \"k{i}\"\nl0 = \"L\"\nlength = \"{xb} - {xa}\"\n"
        );
    }
    s + "\n[simulate]\nt_end = 10.0\n"
}

fn load(src: &str) -> Model {
    pdyn_mech::load(src, "structure.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

/// The closed form at the parameters' values agrees with an integration at rtol = 1e-11.
fn assert_closed_form_matches_integration(mut m: Model, t_end: f64) {
    let exact = sim::exact::closed_form(&mut m).unwrap_or_else(|e| panic!("{e}"));
    let values: Vec<f64> = m.parameters.iter().map(|p| p.value).collect();
    assert_eq!(exact.fixed_parameters.as_deref(), Some(&values[..]));
    let prep = sim::prepare(&mut m).unwrap();
    let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
    set.t_end = t_end;
    set.method = "dop853".into();
    set.rtol = Some(1e-11);
    set.atol = Some(1e-11);
    let rep = sim::exact::check(&prep, &exact, &set).unwrap();
    assert!(!rep.errors.is_empty());
    // The formula (modal, from dsolve) and its stable evaluation agree.
    let gap = rep.formula_gap.expect("evaluated stably");
    assert!(gap < 1e-9, "formula vs stable evaluation: {gap:e}");
    for (name, err, size) in &rep.errors {
        assert!(
            *err < 1e-7 * size.max(1e-3),
            "{name}: error {err:e} (size {size:e})"
        );
    }
}

#[test]
fn a_ten_storey_building_has_a_closed_form_at_its_parameter_values() {
    assert_closed_form_matches_integration(load(&building(10)), 5.0);
}

#[test]
fn a_fifty_mass_spring_chain_has_a_closed_form_at_its_parameter_values() {
    assert_closed_form_matches_integration(load(&spring_chain(50)), 2.0);
}

/// Changing a parameter (as `--set` does) changes the solution: it is found again at the new
/// values, not reused, and matches the integration at those values.
#[test]
fn the_closed_form_follows_the_parameter_values() {
    let with_k1 = |k1: f64| {
        let mut m = load(&spring_chain(8));
        let p = m.parameters.iter_mut().find(|p| p.name == "k1").unwrap();
        p.value = k1;
        m
    };
    let x1_at_1 = |mut m: Model| {
        let exact = sim::exact::closed_form(&mut m).unwrap();
        let prep = sim::prepare(&mut m).unwrap();
        let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
        set.t_end = 1.0;
        set.points = Some(2);
        let ex = sim::exact::run_exact(&prep, &exact, &set).unwrap();
        ex.rows.last().unwrap()[1]
    };
    let (a, b) = (x1_at_1(with_k1(100.0)), x1_at_1(with_k1(400.0)));
    assert!((a - b).abs() > 1e-4, "x1(1) unchanged by k1: {a} vs {b}");
    assert_closed_form_matches_integration(with_k1(400.0), 2.0);
}

/// A system small enough to solve in symbols keeps its closed form in the symbols (the
/// chapter's 2-storey building, masses m and stiffnesses k: 120,000 units of the budget).
#[test]
fn small_structures_keep_symbolic_closed_forms() {
    let path = format!(
        "{}/../../examples/building.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut m = load(&std::fs::read_to_string(path).unwrap());
    let exact = sim::exact::closed_form(&mut m).unwrap();
    assert!(exact.fixed_parameters.is_none());
}

/// A 2-storey building with its own mass and stiffness symbols per storey: solving it in
/// symbols swells (1.75 million simplification units, 0.5–2 s, for a solution far too large
/// to print), so `pdyn derive` gives up within its budget and says what to do instead, and
/// `pdyn check` / `--method exact` solve it at the parameter values.
#[test]
fn a_symbolic_solution_that_swells_gives_way_to_the_parameter_values() {
    let mut m = load(&building(2));
    let e = sim::exact::symbolic_closed_form(&mut m)
        .err()
        .expect("over budget");
    assert!(matches!(e, sim::ClosedFormError::TooCostly { .. }), "{e}");
    assert!(e.to_string().contains("pdyn check"), "{e}");
    // Deterministic work, not time: derivation plus at most the budget (and its last step).
    assert!(
        m.pool.simplify_work() < 2 * sim::exact::CLOSED_FORM_WORK,
        "{}",
        m.pool.simplify_work()
    );
    assert_closed_form_matches_integration(load(&building(2)), 5.0);
}

/// A diagonal mass matrix is solved exactly whatever its size (x_i'' = f_i / m_i): `pdyn
/// derive` prints the accelerations of the 10-storey building, and `pdyn run` evaluates
/// them instead of factorising a 10×10 matrix.
#[test]
fn diagonal_mass_matrices_are_solved_whatever_their_size() {
    let mut m = load(&building(10));
    let d = pdyn_mech::derive(&mut m, &pdyn_mech::DeriveOptions::default()).unwrap();
    let acc = d.accelerations().expect("solved");
    assert_eq!(acc.len(), 10);
    let last = m.pool.to_text(acc[9]);
    assert!(last.ends_with("/m10"), "{last}");
    // A coupled (non-diagonal) system of that size is still left to the numeric solve.
    let mut chain = pdyn_mech::load(
        &std::fs::read_to_string(format!(
            "{}/../../examples/pendulum_chain_3.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
        "chain",
    )
    .unwrap();
    let opts = pdyn_mech::DeriveOptions {
        symbolic_limit: 2,
        ..pdyn_mech::DeriveOptions::default()
    };
    assert!(pdyn_mech::derive(&mut chain, &opts)
        .unwrap()
        .solution
        .is_none());
}
