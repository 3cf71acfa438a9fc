//! The JIT and the interpreter give identical bits on the programs pdyn actually compiles:
//! every example model's right-hand side (exact solution and its Jacobian, or the linear
//! system `A x = b`), the satellite, and n-link pendulum chains. Inputs are seeded
//! pseudo-random; NaN compares equal to NaN (payloads may differ).

use pdyn_expr::compile::CompiledLinearSystem;
use pdyn_expr::{Id, Node, Program};
use pdyn_jit::{JitLinearSystem, JitMode, JitProgram};
use pdyn_mech::derive::Form;
use pdyn_mech::{derive, load, DeriveOptions, Model};

/// xorshift64*: a tiny seeded generator, uniform in [-2, 2).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        (u as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    }
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Evaluates `prog` both ways on `trials` random inputs; returns the number of outputs checked.
fn check(name: &str, prog: &Program, trials: usize) -> usize {
    let jit = JitProgram::compile(prog).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut ws = prog.workspace();
    let mut jws = jit.workspace();
    let (mut o1, mut o2) = (vec![0.0; prog.n_outputs()], vec![1.0; prog.n_outputs()]);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ prog.len() as u64);
    for _ in 0..trials {
        let input: Vec<f64> = (0..prog.n_inputs()).map(|_| rng.next()).collect();
        prog.eval(&input, &mut ws, &mut o1);
        jit.eval(&input, &mut jws, &mut o2);
        for k in 0..o1.len() {
            assert!(
                same(o1[k], o2[k]),
                "{name}: output {k} at {input:?}: interpreter {} vs JIT {}",
                o1[k],
                o2[k]
            );
        }
    }
    o1.len() * trials
}

/// The input leaves `[t, q, q', parameters]` of `pdyn run`'s compiled model, then any other
/// leaf of `exprs` (e.g. a force given as a function of time that `pdyn run` substitutes).
fn inputs(model: &mut Model, state: &[Id], exprs: &[Id]) -> Vec<Id> {
    let mut v = vec![model.pool.time()];
    v.extend(state);
    v.extend(model.parameters.iter().map(|p| p.id));
    for n in model.pool.topo_order(exprs) {
        let leaf = matches!(
            model.pool.node(n),
            Node::Time | Node::Sym(_) | Node::Coord(..)
        );
        if leaf && !v.contains(&n) {
            v.push(n);
        }
    }
    v
}

/// Every program `pdyn run` builds for `src` under `opts`; returns the outputs checked, or
/// `None` when the model does not derive under `opts` (an example meant to show an error).
fn check_model(name: &str, src: &str, opts: &DeriveOptions) -> Option<usize> {
    let mut m = load(src, name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let d = match derive(&mut m, opts) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("{name}: not derived ({e})");
            return None;
        }
    };
    let mut all: Vec<Id> = d.system.a.iter().chain(&d.system.b).copied().collect();
    all.extend(d.solution.iter().flatten());
    let inp = inputs(&mut m, &d.state, &all);
    let mut checked = 0;
    if let Some(sol) = &d.solution {
        let prog = Program::compile(&mut m.pool, &inp, sol).unwrap();
        checked += check(&format!("{name} solution"), &prog, 200);
        if let Some(acc) = d.accelerations() {
            let jac = m.pool.jacobian(&acc, &d.state);
            let jprog = Program::compile(&mut m.pool, &inp, &jac).unwrap();
            checked += check(&format!("{name} jacobian"), &jprog, 50);
        }
    }
    let sys = CompiledLinearSystem::new(&mut m.pool, &d.system, &inp).unwrap();
    checked += check(&format!("{name} system"), sys.program().main(), 200);
    // The solved system too: the JIT's A, b go through the same LU.
    let mut interp = sys.clone();
    let mut native = JitLinearSystem::new(&sys, JitMode::Auto);
    assert!(native.is_native());
    let mut rng = Rng(7);
    let n = sys.n();
    let (mut x1, mut x2) = (vec![0.0; n], vec![0.0; n]);
    for _ in 0..20 {
        let input: Vec<f64> = (0..inp.len()).map(|_| rng.next()).collect();
        let r1 = interp.solve(&input, &mut x1);
        let r2 = native.solve(&input, &mut x2);
        assert_eq!(r1, r2, "{name}");
        if r1.is_ok() {
            assert!(x1.iter().zip(&x2).all(|(a, b)| same(*a, *b)), "{name}");
        }
    }
    Some(checked)
}

#[path = "../../pdyn-mech/tests/common/chain.rs"]
mod chain;
use chain::chain_toml;

#[test]
fn every_example_model_agrees_bit_for_bit() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut models = 0;
    for path in &paths {
        let src = std::fs::read_to_string(path).unwrap();
        // The whole path as the model's name: a model's data and table files are read
        // relative to its directory.
        let name = path.to_string_lossy().to_string();
        let exact = check_model(&name, &src, &DeriveOptions::default());
        // The numeric path (no symbolic elimination) compiles different programs.
        let numeric = DeriveOptions {
            symbolic_limit: 0,
            ..DeriveOptions::default()
        };
        let numeric = check_model(&name, &src, &numeric);
        if exact.is_some() && numeric.is_some() {
            models += 1;
        }
    }
    assert!(
        models >= 12,
        "only {models} example models derived, in {dir}"
    );
}

#[test]
fn satellite_agrees_bit_for_bit() {
    let mut p = pdyn_expr::Pool::new();
    let x = p.parse_scalar("x(t)").unwrap();
    let y = p.parse_scalar("y(t)").unwrap();
    let (vx, vy) = (p.dt(x), p.dt(y));
    let gm = p.var("GM");
    let ax = p.parse_scalar("-GM*x(t)/(x(t)^2 + y(t)^2)^(3/2)").unwrap();
    let ay = p.parse_scalar("-GM*y(t)/(x(t)^2 + y(t)^2)^(3/2)").unwrap();
    let prog = Program::compile(&mut p, &[x, y, vx, vy, gm], &[vx, vy, ax, ay]).unwrap();
    assert_eq!(check("satellite", &prog, 10_000), 40_000);
}

#[test]
fn pendulum_chains_agree_bit_for_bit() {
    for n in [2, 5, 16] {
        let projected = DeriveOptions {
            form: Form::Projected,
            symbolic_limit: 0,
            simplify: false,
            ..DeriveOptions::default()
        };
        assert!(check_model(&format!("chain {n}"), &chain_toml(n), &projected).is_some());
    }
    assert!(check_model("chain 4 exact", &chain_toml(4), &DeriveOptions::default()).is_some());
}

#[test]
fn programs_longer_than_one_chunk_are_split_and_still_agree() {
    let mut m = load(&chain_toml(16), "chain 16").unwrap();
    let projected = DeriveOptions {
        form: Form::Projected,
        symbolic_limit: 0,
        simplify: false,
        ..DeriveOptions::default()
    };
    let d = derive(&mut m, &projected).unwrap();
    let all: Vec<Id> = d.system.a.iter().chain(&d.system.b).copied().collect();
    let inp = inputs(&mut m, &d.state, &all);
    let sys = CompiledLinearSystem::new(&mut m.pool, &d.system, &inp).unwrap();
    let jit = JitProgram::compile(sys.program().main()).unwrap();
    // The 16-link chain's A and b take several thousand instructions: several chunks, with
    // values crossing between them through the spill array.
    assert!(jit.chunks() >= 2, "{jit:?}");
    assert!(!jit.workspace().is_empty());
    assert_eq!(
        check("chain 16 system", sys.program().main(), 50),
        50 * (16 * 16 + 16)
    );
}
