//! The symbolic work of setting up a net of particles in Cartesian coordinates grows linearly
//! with the number of particles (issue 33, item 2): counted in expression nodes and program
//! instructions, never in time. Before, forming `A x = b` and the Jacobian differentiated
//! every equation by every unknown and state entry: quadratic in the nodes visited, and the
//! pool grew with them.

use pdyn_expr::Program;
use pdyn_mech::derive::{derive, DeriveOptions, RUN_SOLVE_BUDGET};
use pdyn_mech::load;

fn family_net(n: usize) -> String {
    let text = include_str!("../../../examples/hanging_net.toml");
    let line = text.lines().find(|l| l.starts_with("n = ")).unwrap();
    text.replacen(line, &format!("n = {n}"), 1)
}

/// `(particles, pool nodes after derivation and Jacobian, node derivatives formed,
/// instructions of the accelerations' program)` of the n x n net, set up as `pdyn run` does.
fn counts(n: usize) -> (usize, usize, usize, usize) {
    let src = family_net(n);
    let mut m = load(&src, "net.toml").unwrap();
    let opts = DeriveOptions {
        simplify_printed: false,
        solve_budget: RUN_SOLVE_BUDGET,
        ..DeriveOptions::default()
    };
    let d = derive(&mut m, &opts).unwrap();
    let sol = d
        .solution
        .clone()
        .expect("a diagonal mass matrix is solved exactly");
    let mut inputs = vec![m.pool.time()];
    inputs.extend(&d.state);
    inputs.extend(m.parameters.iter().map(|p| p.id));
    let _jacobian = m.pool.jacobian(&sol, &d.state);
    let prog = Program::compile(&mut m.pool, &inputs, &sol).unwrap();
    (
        m.particles.len(),
        m.pool.len(),
        m.pool.derivative_work(),
        prog.len(),
    )
}

#[test]
fn nodes_and_instructions_grow_linearly_with_the_particles() {
    // The cost of each particle added, from the 6 x 6 net (34 particles) to the 9 x 9 (79),
    // then to the 12 x 12 (142). Linear work adds a constant per particle (a little more
    // as interior nodes, with 8 springs each, outnumber edge nodes); quadratic work adds in
    // proportion to the size: twice as much per particle in the second step
    // ((142 + 79) / (79 + 34) = 1.96).
    let sizes = [counts(6), counts(9), counts(12)];
    assert_eq!(sizes.map(|c| c.0), [34, 79, 142]);
    let marginal = |k: usize, pick: fn(&(usize, usize, usize, usize)) -> usize| {
        let (a, b) = (&sizes[k], &sizes[k + 1]);
        (pick(b) - pick(a)) as f64 / (b.0 - a.0) as f64
    };
    for (what, pick) in [
        (
            "pool nodes",
            (|c| c.1) as fn(&(usize, usize, usize, usize)) -> usize,
        ),
        ("derivatives formed", |c| c.2),
        ("instructions", |c| c.3),
    ] {
        let (first, second) = (marginal(0, pick), marginal(1, pick));
        assert!(
            second < 1.25 * first,
            "{what} per particle added: {first:.0}, then {second:.0}"
        );
    }
}

/// The net of `n` x `n` nodes, pinned at two corners or free.
fn net(n: usize, pinned: bool) -> String {
    let src = family_net(n);
    if pinned {
        src
    } else {
        // No node is a pin: the condition of the pins holds nowhere.
        src.replace(", where = \"not (j == 0 and (i == 0 or i == n-1))\"", "")
            .replace("where = \"not (j == 0 and (i == 0 or i == n-1))\"", "")
            .replace("[points]\n\"P[i,j]\"", "[points]\n#\"P[i,j]\"")
    }
}

/// `A x = b` and the Jacobian, formed from the unknowns each equation contains, are entry for
/// entry (the same expression in the same pool) what differentiating every equation by every
/// unknown gives: nets of 4, 9 and 23 particles.
#[test]
fn sparse_assembly_is_the_dense_one_entry_for_entry() {
    for (n, pinned, particles) in [(2, false, 4), (3, false, 9), (5, true, 23)] {
        let src = net(n, pinned);
        let mut m = load(&src, "net.toml").unwrap_or_else(|e| panic!("{}", e.render(&src)));
        assert_eq!(m.particles.len(), particles);
        let opts = DeriveOptions {
            simplify_printed: false,
            solve_budget: RUN_SOLVE_BUDGET,
            ..DeriveOptions::default()
        };
        let d = derive(&mut m, &opts).unwrap();
        let p = &mut m.pool;
        let sys = &d.system;
        let cols = sys.cols();
        let mut nonzero = 0;
        for (i, eq) in d.equations.iter().enumerate() {
            let r = p.sub(eq.lhs, eq.rhs);
            for (j, &u) in sys.unknowns.iter().enumerate() {
                let dense = p.diff(r, u);
                assert_eq!(sys.a[i * cols + j], dense, "A[{i},{j}] of the {n}x{n} net");
                nonzero += usize::from(dense != pdyn_expr::Pool::ZERO);
            }
        }
        // The mass matrix of particles in Cartesian coordinates is diagonal.
        assert_eq!(nonzero, 3 * particles);
        let sol = d.solution.clone().unwrap();
        let jac = p.jacobian(&sol, &d.state);
        for (i, &f) in sol.iter().enumerate() {
            for (j, &w) in d.state.iter().enumerate() {
                assert_eq!(jac[i * d.state.len() + j], p.diff(f, w), "J[{i},{j}]");
            }
        }
    }
}
