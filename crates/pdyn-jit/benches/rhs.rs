//! Interpreter vs JIT vs hand-written Rust (divan). Run with
//! `cargo bench -p pdyn-jit --bench rhs`; results are recorded in docs/benchmarks-jit.md.
//!
//! - `satellite_*`: one evaluation of the satellite right-hand side (as in pdyn-expr's
//!   `expr` bench), chained as explicit Euler steps so each call depends on the previous one:
//!   latency per call, 100 calls per iteration.
//! - `chain16_mf_*`: the entries of `M(q) q'' = f(q, q')` of the 16-link planar pendulum chain
//!   derived by pdyn-mech (projected form, numeric path: 256 + 16 outputs), and a hand-written
//!   O(n²) closure computing the same `M` and `f`. `main` checks that the hand-written
//!   equations give the same `q''` as the derived ones before timing anything.
//! - `chain16_jit_compile`, `chain100_jit_compile`: the one-off cost of generating the native
//!   code (the 100-link chain's chunks on several threads).
//! - `chain100_mf_*`: the same for the 100-link chain (10,100 outputs), whose run evaluates
//!   them about 7,000 times.

use divan::{black_box, Bencher};
use pdyn_expr::compile::CompiledLinearSystem;
use pdyn_expr::hoist::HoistedInputs;
use pdyn_expr::lu::{lu_factor_in_place, lu_solve_in_place};
use pdyn_expr::{Id, Pool, Program};
use pdyn_jit::JitProgram;
use pdyn_mech::derive::Form;
use pdyn_mech::{derive, load, DeriveOptions};

fn main() {
    check_handwritten_chain::<16>();
    check_handwritten_chain::<100>();
    for c in [chain::<16>(), chain::<100>()] {
        println!(
            "chain: {} instructions, {} outputs",
            c.prog.len(),
            c.prog.n_outputs(),
        );
    }
    println!("satellite: {} instructions", satellite().len());
    divan::main();
}

fn satellite() -> Program {
    let mut p = Pool::new();
    let x = p.parse_scalar("x(t)").unwrap();
    let y = p.parse_scalar("y(t)").unwrap();
    let vx = p.dt(x);
    let vy = p.dt(y);
    let gm = p.var("GM");
    let ax = p.parse_scalar("-GM*x(t)/(x(t)^2 + y(t)^2)^(3/2)").unwrap();
    let ay = p.parse_scalar("-GM*y(t)/(x(t)^2 + y(t)^2)^(3/2)").unwrap();
    Program::compile(&mut p, &[x, y, vx, vy, gm], &[vx, vy, ax, ay]).unwrap()
}

const CALLS: usize = 100;

/// 100 chained Euler steps of `f` from the same start.
#[inline(always)]
fn euler(mut f: impl FnMut(&[f64; 5], &mut [f64; 4])) -> [f64; 5] {
    let mut w = [1.0, 0.0, 0.0, 1.0, 1.0];
    let mut out = [0.0; 4];
    for _ in 0..CALLS {
        f(black_box(&w), &mut out);
        for i in 0..4 {
            w[i] += 1e-3 * out[i];
        }
    }
    w
}

#[divan::bench]
fn satellite_interpreter(b: Bencher) {
    let prog = satellite();
    let mut ws = prog.workspace();
    b.counter(divan::counter::ItemsCount::new(CALLS))
        .bench_local(|| euler(|w, out| prog.eval(w, &mut ws, out)));
}

#[divan::bench]
fn satellite_jit(b: Bencher) {
    let jit = JitProgram::compile(&satellite()).unwrap();
    let mut ws = jit.workspace();
    b.counter(divan::counter::ItemsCount::new(CALLS))
        .bench_local(|| euler(|w, out| jit.eval(w, &mut ws, out)));
}

#[divan::bench]
fn satellite_handwritten(b: Bencher) {
    #[inline(never)]
    fn f(w: &[f64], out: &mut [f64]) {
        let (x, y, vx, vy, gm) = (w[0], w[1], w[2], w[3], w[4]);
        let r = (x * x + y * y).sqrt();
        let r3 = r * r * r;
        out[0] = vx;
        out[1] = vy;
        out[2] = -gm * x / r3;
        out[3] = -gm * y / r3;
    }
    b.counter(divan::counter::ItemsCount::new(CALLS))
        .bench_local(|| euler(|w, out| f(w, out)));
}

/// The model file of an n-link planar chain (as `examples/pendulum_chain_3.toml`).
// The chain generator shared with pdyn-mech's tests (unit masses and lengths).
#[path = "../../pdyn-mech/tests/common/chain.rs"]
mod chain_model;
use chain_model::chain_toml;

struct Chain {
    prog: Program,
    /// `[t, q, q', g, m1, l1, m2, l2, ...]`
    input: Vec<f64>,
    /// `input` followed by the hoisted values: the main program's inputs.
    ext: Vec<f64>,
}

/// The derived chain's `[A | b]` program, as `pdyn run` compiles it, at a fixed state.
fn chain<const N: usize>() -> Chain {
    let mut m = load(&chain_toml(N), "chain.toml").unwrap();
    let opts = DeriveOptions {
        form: Form::Projected,
        symbolic_limit: 0,
        simplify: false,
        ..DeriveOptions::default()
    };
    let d = derive(&mut m, &opts).unwrap();
    let mut inputs: Vec<Id> = vec![m.pool.time()];
    inputs.extend(&d.state);
    inputs.extend(m.parameters.iter().map(|p| p.id));
    // The parameters are invariant, as in a run: their products and sums are hoisted.
    let sys = CompiledLinearSystem::hoisted(&mut m.pool, &d.system, &inputs, 1 + 2 * N).unwrap();
    let mut input = vec![0.0];
    input.extend((0..N).map(|i| 0.1 + 0.07 * i as f64));
    input.extend((0..N).map(|i| 0.3 - 0.05 * i as f64));
    input.extend(m.parameters.iter().map(|p| p.value));
    let hoisted = sys.program().clone();
    let ext = HoistedInputs::new(&hoisted)
        .update(&hoisted, &input)
        .to_vec();
    Chain {
        prog: hoisted.main().clone(),
        input,
        ext,
    }
}

/// `M` (row-major) and `f` of the chain, by hand: with `μ_i = Σ_{k≥i} m_k`,
/// `M_ij = μ_max(i,j) l_i l_j cos(q_i − q_j)` and
/// `f_i = l_i Σ_j μ_max(i,j) l_j q_j'² sin(q_j − q_i) − g l_i μ_i sin q_i`,
/// with the cosine and sine of differences expanded so each angle needs one `sin` and `cos`.
#[inline(never)]
fn chain_handwritten<const N: usize>(input: &[f64], out: &mut [f64]) {
    let q = &input[1..1 + N];
    let v = &input[1 + N..1 + 2 * N];
    let par = &input[1 + 2 * N..];
    let g = par[0];
    let mut s = [0.0; N];
    let mut c = [0.0; N];
    let mut l = [0.0; N];
    let mut mu = [0.0; N];
    let mut lv2 = [0.0; N];
    for i in 0..N {
        s[i] = libm::sin(q[i]);
        c[i] = libm::cos(q[i]);
        l[i] = par[2 + 2 * i];
        lv2[i] = l[i] * v[i] * v[i];
    }
    let mut acc = 0.0;
    for i in (0..N).rev() {
        acc += par[1 + 2 * i];
        mu[i] = acc;
    }
    let (m, f) = out.split_at_mut(N * N);
    for i in 0..N {
        let mut fi = 0.0;
        for j in 0..N {
            let mij = mu[i.max(j)];
            m[i * N + j] = mij * l[i] * l[j] * (c[i] * c[j] + s[i] * s[j]);
            fi += mij * lv2[j] * (s[j] * c[i] - c[j] * s[i]);
        }
        f[i] = l[i] * fi - g * l[i] * mu[i] * s[i];
    }
}

/// The hand-written `M`, `f` and the derived ones give the same `q''` (so the comparison
/// is between equivalent computations).
fn check_handwritten_chain<const N: usize>() {
    let c = chain::<N>();
    let solve = |ab: &mut [f64]| {
        let (a, b) = ab.split_at_mut(N * N);
        let mut perm = vec![0; N];
        lu_factor_in_place(a, N, &mut perm).unwrap();
        lu_solve_in_place(a, N, &perm, b, &mut [0.0; N]);
        b.to_vec()
    };
    let mut derived = vec![0.0; N * N + N];
    c.prog.eval(&c.ext, &mut c.prog.workspace(), &mut derived);
    let mut hand = vec![0.0; N * N + N];
    chain_handwritten::<N>(&c.input, &mut hand);
    let (x1, x2) = (solve(&mut derived), solve(&mut hand));
    for (a, b) in x1.iter().zip(&x2) {
        assert!(
            (a - b).abs() <= 1e-9 * (1.0 + a.abs()),
            "hand-written chain disagrees: {x1:?} vs {x2:?}"
        );
    }
}

#[divan::bench]
fn chain16_mf_interpreter(b: Bencher) {
    mf_interpreter(b, chain::<16>());
}

#[divan::bench]
fn chain16_mf_jit(b: Bencher) {
    mf_jit(b, chain::<16>());
}

#[divan::bench]
fn chain16_mf_handwritten(b: Bencher) {
    mf_handwritten::<16>(b);
}

#[divan::bench]
fn chain100_mf_jit(b: Bencher) {
    mf_jit(b, chain::<100>());
}

#[divan::bench]
fn chain100_mf_handwritten(b: Bencher) {
    mf_handwritten::<100>(b);
}

fn mf_interpreter(b: Bencher, c: Chain) {
    let mut ws = c.prog.workspace();
    let mut out = vec![0.0; c.prog.n_outputs()];
    b.bench_local(|| {
        c.prog.eval(black_box(&c.ext), &mut ws, &mut out);
        black_box(out[0])
    });
}

fn mf_jit(b: Bencher, c: Chain) {
    let jit = JitProgram::compile(&c.prog).unwrap();
    let mut out = vec![0.0; c.prog.n_outputs()];
    let mut ws = jit.workspace();
    b.bench_local(|| {
        jit.eval(black_box(&c.ext), &mut ws, &mut out);
        black_box(out[0])
    });
}

fn mf_handwritten<const N: usize>(b: Bencher) {
    let c = chain::<N>();
    let mut out = vec![0.0; N * N + N];
    b.bench_local(|| {
        chain_handwritten::<N>(black_box(&c.input), &mut out);
        black_box(out[0])
    });
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn chain16_jit_compile(b: Bencher) {
    let c = chain::<16>();
    b.bench_local(|| JitProgram::compile(black_box(&c.prog)).unwrap().len());
}

#[divan::bench(sample_count = 5, sample_size = 1)]
fn chain100_jit_compile(b: Bencher) {
    let c = chain::<100>();
    b.bench_local(|| JitProgram::compile(black_box(&c.prog)).unwrap().len());
}
