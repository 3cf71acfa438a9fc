//! Complexity regression on deterministic counts, not on time: deriving and compiling the
//! equations `M(q) q'' = f` of an n-link planar pendulum chain is O(n²) in size (M has n²
//! entries, each O(1) after sharing; f has n entries of O(n) terms). Doubling n from 20 to 40
//! must therefore multiply the expression nodes created and the compiled instructions by
//! about 4, and at most 4.5; an O(n³) regression would give about 8.

use pdyn_expr::compile::CompiledLinearSystem;
use pdyn_expr::Id;
use pdyn_mech::derive::Form;
use pdyn_mech::{derive, load, DeriveOptions};

#[path = "common/chain.rs"]
mod chain;
use chain::chain_toml;

/// Counts for the chain of `n` links: (nodes in the pool after derivation, distinct nodes of
/// the system's DAG, compiled instructions of `[A | b]`).
fn counts(n: usize, opts: &DeriveOptions) -> (usize, usize, usize) {
    let mut m = load(&chain_toml(n), "chain.toml").unwrap();
    let d = derive(&mut m, opts).unwrap();
    let created = m.pool.len();
    let entries: Vec<Id> = d.system.a.iter().chain(&d.system.b).copied().collect();
    let dag = m.pool.dag_size(&entries);
    let mut inputs: Vec<Id> = vec![m.pool.time()];
    inputs.extend(&d.state);
    inputs.extend(m.parameters.iter().map(|p| p.id));
    let sys = CompiledLinearSystem::new(&mut m.pool, &d.system, &inputs).unwrap();
    (created, dag, sys.program().len())
}

/// The bench's options (`pdyn-mech/benches/chain.rs`): projected form, numeric solve.
#[test]
fn chain_derivation_grows_quadratically() {
    let opts = DeriveOptions {
        form: Form::Projected,
        symbolic_limit: 0,
        simplify: false,
        ..DeriveOptions::default()
    };
    check(&opts);
}

/// The user's path: `pdyn derive` / `pdyn run` defaults (automatic form, simplified printing).
#[test]
fn chain_derivation_with_default_options_grows_quadratically() {
    check(&DeriveOptions::default());
}

fn check(opts: &DeriveOptions) {
    let (c20, d20, i20) = counts(20, opts);
    let (c40, d40, i40) = counts(40, opts);
    let ratio = |a: usize, b: usize| b as f64 / a as f64;
    let (rc, rd, ri) = (ratio(c20, c40), ratio(d20, d40), ratio(i20, i40));
    eprintln!("n=20: created {c20}, dag {d20}, instructions {i20}");
    eprintln!("n=40: created {c40}, dag {d40}, instructions {i40}");
    eprintln!("ratios: created {rc:.3}, dag {rd:.3}, instructions {ri:.3}");
    assert!(
        rc <= 4.5,
        "pool nodes created grow {rc:.3}x from n=20 to 40"
    );
    assert!(rd <= 4.5, "system DAG grows {rd:.3}x from n=20 to 40");
    assert!(
        ri <= 4.5,
        "compiled instructions grow {ri:.3}x from n=20 to 40"
    );
}

/// A run evaluates `[A | b]` thousands of times with the same parameters: the parameter-only
/// work (the chain's mass sums `m_k + … + m_n`, the products `l_j*l_k*(m_k + … + m_n)`) is
/// hoisted out of the per-evaluation program ([`pdyn_expr::hoist::HoistedProgram`]), which
/// must lose a fixed share of its instructions and still grow as n².
#[test]
fn the_run_s_evaluation_leaves_the_parameter_work_to_the_prelude() {
    let opts = DeriveOptions {
        simplify_printed: false,
        solve_budget: pdyn_mech::derive::RUN_SOLVE_BUDGET,
        ..DeriveOptions::default()
    };
    let sizes = |n: usize| {
        let mut m = load(&chain_toml(n), "chain.toml").unwrap();
        let d = derive(&mut m, &opts).unwrap();
        let mut inputs: Vec<Id> = vec![m.pool.time()];
        inputs.extend(&d.state);
        inputs.extend(m.parameters.iter().map(|p| p.id));
        let plain = CompiledLinearSystem::new(&mut m.pool, &d.system, &inputs).unwrap();
        let first_parameter = 1 + d.state.len();
        let hoisted =
            CompiledLinearSystem::hoisted(&mut m.pool, &d.system, &inputs, first_parameter)
                .unwrap();
        let h = hoisted.program();
        (plain.program().len(), h.main().len(), h.prelude().len())
    };
    let (plain20, main20, pre20) = sizes(20);
    let (plain40, main40, pre40) = sizes(40);
    eprintln!("n=20: plain {plain20}, main {main20}, prelude {pre20}");
    eprintln!("n=40: plain {plain40}, main {main40}, prelude {pre40}");
    for (plain, main) in [(plain20, main20), (plain40, main40)] {
        assert!((main as f64) < 0.8 * plain as f64, "main {main} of {plain}");
    }
    assert!(main40 as f64 <= 4.5 * main20 as f64, "{main20} -> {main40}");
}

/// The hoisted system solves to the plain one's accelerations (to rounding: products and
/// sums are associated differently) at random states and parameters, including after the
/// parameters change between solves.
#[test]
fn the_hoisted_system_solves_like_the_plain_one() {
    let opts = DeriveOptions {
        simplify_printed: false,
        solve_budget: 0,
        ..DeriveOptions::default()
    };
    let n = 6;
    let mut m = load(&chain_toml(n), "chain.toml").unwrap();
    let d = derive(&mut m, &opts).unwrap();
    assert!(d.solution.is_none(), "solved numerically");
    let mut inputs: Vec<Id> = vec![m.pool.time()];
    inputs.extend(&d.state);
    inputs.extend(m.parameters.iter().map(|p| p.id));
    let mut plain = CompiledLinearSystem::new(&mut m.pool, &d.system, &inputs).unwrap();
    let mut hoisted =
        CompiledLinearSystem::hoisted(&mut m.pool, &d.system, &inputs, 1 + 2 * n).unwrap();
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut x1, mut x2) = (vec![0.0; n], vec![0.0; n]);
    let mut params: Vec<f64> = m.parameters.iter().map(|p| p.value).collect();
    for trial in 0..40 {
        if trial % 10 == 0 {
            params = params.iter().map(|_| 0.5 + rand()).collect();
        }
        let mut input = vec![rand()];
        input.extend((0..2 * n).map(|_| 4.0 * rand() - 2.0));
        input.extend(&params);
        plain.solve(&input, &mut x1).unwrap();
        hoisted.solve(&input, &mut x2).unwrap();
        let scale = x1.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for (a, b) in x1.iter().zip(&x2) {
            assert!(
                (a - b).abs() <= 1e-10 * scale,
                "trial {trial}: {x1:?} vs {x2:?}"
            );
        }
    }
}

/// `pdyn derive`'s options: the printing solve budget, which must pay for simplifying the
/// exact solution too.
fn printing_options() -> DeriveOptions {
    DeriveOptions {
        solve_budget: pdyn_mech::derive::PRINT_SOLVE_BUDGET,
        simplify_solution_within_budget: true,
        ..DeriveOptions::default()
    }
}

/// (simplification work units, pool nodes) of deriving the `n`-link chain with `opts`.
fn work(n: usize, opts: &DeriveOptions) -> (u64, usize) {
    let mut m = load(&chain_toml(n), "chain.toml").unwrap();
    derive(&mut m, opts).unwrap();
    (m.pool.simplify_work(), m.pool.len())
}

/// Monotone in n (issue 12): the 3-link chain's exact elimination fits the cheap budget, and
/// simplifying its solution (for accelerations printed by reference anyway) cost over
/// 100,000 work units, more than deriving the 4- or 8-link chain. Counted, not timed: the
/// simplification stays within the solve budget (the 3-link chain is solved numerically,
/// like the 4-link one), and the pool grows with n.
#[test]
fn derivation_for_printing_is_monotone_in_n() {
    let opts = printing_options();
    let counts: Vec<(usize, (u64, usize))> =
        [2, 3, 4, 8].iter().map(|&n| (n, work(n, &opts))).collect();
    eprintln!("(n, (simplification work, pool nodes)): {counts:?}");
    for &(n, (simplify_work, _)) in &counts {
        assert!(
            simplify_work <= opts.solve_budget,
            "n = {n}: {simplify_work} simplification work units, over the solve budget of {}",
            opts.solve_budget
        );
    }
    // Since issue 34 the printing budget (40,000) lets the double pendulum in Newton form be
    // solved by default; the 3-link chain's attempt, which gives up, then builds more nodes
    // than the 4-link chain's (842 against 511 when this was written), but stays within the
    // budget (asserted above) and under the 8-link chain's.
    let nodes = |n: usize| counts.iter().find(|c| c.0 == n).map(|c| c.1 .1).unwrap();
    assert!(
        nodes(2) <= nodes(3) && nodes(3) <= nodes(8) && nodes(4) <= nodes(8),
        "{counts:?}"
    );
    // The double pendulum's solution fits, and is simplified as before (it is printed).
    let mut m = load(&chain_toml(2), "chain.toml").unwrap();
    let d = derive(&mut m, &opts).unwrap();
    let mut r = load(&chain_toml(2), "chain.toml").unwrap();
    let e = derive(&mut r, &DeriveOptions::default()).unwrap();
    let text = |p: &pdyn_expr::Pool, s: &[Id]| s.iter().map(|&x| p.to_text(x)).collect::<Vec<_>>();
    assert_eq!(
        text(&m.pool, d.solution.as_deref().unwrap()),
        text(&r.pool, e.solution.as_deref().unwrap())
    );
    // Without the option (a run's), the 3-link solution is found and simplified whatever it
    // costs: the count this test bounds.
    let (unbounded, _) = work(3, &DeriveOptions::default());
    eprintln!("n = 3 without the option: {unbounded} work units");
    assert!(unbounded > opts.solve_budget);
}
