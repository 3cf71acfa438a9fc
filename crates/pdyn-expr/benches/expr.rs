//! Benchmarks of the expression engine (divan). Run with
//! `cargo bench -p pdyn-expr --bench expr`; results are recorded in docs/benchmarks.md.
//!
//! - `satellite_rhs/*`: one evaluation of the chapter's satellite right-hand side
//!   (3.3.3 Example 2), compiled program vs a hand-written Rust closure.
//! - `chain/*`: build the positions of an n-link planar chain, differentiate twice in time and
//!   compile the 3n acceleration components. `chain_sizes` prints the compiled program and DAG
//!   sizes so their growth with n can be checked (about n², not n³).

use divan::{black_box, Bencher};
use pdyn_expr::{Id, Pool, Program};

fn main() {
    chain_sizes();
    divan::main();
}

struct Satellite {
    prog: Program,
    ws: Vec<f64>,
}

fn satellite() -> Satellite {
    let mut p = Pool::new();
    let x = p.parse_scalar("x(t)").unwrap();
    let y = p.parse_scalar("y(t)").unwrap();
    let vx = p.dt(x);
    let vy = p.dt(y);
    let gm = p.var("GM");
    let ax = p.parse_scalar("-GM*x(t)/(x(t)^2 + y(t)^2)^(3/2)").unwrap();
    let ay = p.parse_scalar("-GM*y(t)/(x(t)^2 + y(t)^2)^(3/2)").unwrap();
    let prog = Program::compile(&mut p, &[x, y, vx, vy, gm], &[vx, vy, ax, ay]).unwrap();
    let ws = prog.workspace();
    Satellite { prog, ws }
}

/// Explicit Euler steps on the satellite: each right-hand side evaluation depends on the
/// previous one, as in an integrator, so the benchmark measures latency per call, not the
/// throughput of independent calls. 100 calls per iteration.
const CALLS: usize = 100;

#[divan::bench]
fn satellite_rhs_compiled(b: Bencher) {
    let mut s = satellite();
    let mut out = [0.0; 4];
    b.counter(divan::counter::ItemsCount::new(CALLS))
        .bench_local(|| {
            let mut w = [1.0, 0.0, 0.0, 1.0, 1.0];
            for _ in 0..CALLS {
                s.prog.eval(black_box(&w), &mut s.ws, &mut out);
                for i in 0..4 {
                    w[i] += 1e-3 * out[i];
                }
            }
            black_box(w)
        });
}

#[divan::bench]
fn satellite_rhs_handwritten(b: Bencher) {
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
    let mut out = [0.0; 4];
    b.counter(divan::counter::ItemsCount::new(CALLS))
        .bench_local(|| {
            let mut w = [1.0, 0.0, 0.0, 1.0, 1.0];
            for _ in 0..CALLS {
                f(black_box(&w), &mut out);
                for i in 0..4 {
                    w[i] += 1e-3 * out[i];
                }
            }
            black_box(w)
        });
}

/// Accelerations of an n-link planar chain: r_k = Σ_{i≤k} l_i [sin q_i, -cos q_i, 0].
fn chain(n: usize) -> (Pool, Vec<Id>, Vec<Id>) {
    let mut p = Pool::new();
    let mut inputs = Vec::new();
    let mut pos = [Pool::ZERO; 3];
    let mut acc = Vec::new();
    for i in 0..n {
        let q = p.symbol(&format!("q{i}"), false);
        let l = p.var(&format!("l{i}"));
        let qc = p.coord(q, 0);
        inputs.extend([qc, p.coord(q, 1), p.coord(q, 2), l]);
        let s = p.call(pdyn_expr::Func::Sin, &[qc]);
        let c = p.call(pdyn_expr::Func::Cos, &[qc]);
        let ls = p.mul2(l, s);
        let lc = p.mul2(l, c);
        pos[0] = p.add2(pos[0], ls);
        pos[1] = p.sub(pos[1], lc);
        for &x in &pos {
            let a = p.dt_n(x, 2);
            acc.push(a);
        }
    }
    (p, inputs, acc)
}

fn chain_sizes() {
    println!("n, dag_nodes, program_instructions, pool_nodes");
    for n in [10, 20, 50, 100] {
        let (mut p, inputs, acc) = chain(n);
        let dag = p.dag_size(&acc);
        let prog = Program::compile(&mut p, &inputs, &acc).unwrap();
        println!("{n}, {dag}, {}, {}", prog.len(), p.len());
    }
}

#[divan::bench(args = [10, 20, 50])]
fn chain_build_diff_compile(b: Bencher, n: usize) {
    b.bench(|| {
        let (mut p, inputs, acc) = chain(black_box(n));
        let prog = Program::compile(&mut p, &inputs, &acc).unwrap();
        black_box(prog.len())
    });
}

/// A symmetric positive definite `n×n` matrix and right-hand side (a diagonally dominant
/// mass-matrix stand-in).
fn spd(n: usize) -> Vec<f64> {
    let mut ab = vec![0.0; n * n + n];
    for i in 0..n {
        for j in 0..n {
            ab[i * n + j] = if i == j {
                n as f64 + 1.0
            } else {
                1.0 / (1.0 + (i as f64 - j as f64).abs())
            };
        }
        ab[n * n + i] = 1.0 + i as f64;
    }
    ab
}

/// `DenseSolver::solve` on a symmetric system (Cholesky factor and solve), as a run with
/// a numeric mass matrix does at every evaluation: library-internal.
#[divan::bench(args = [16, 50, 100])]
fn mass_matrix_solve(b: Bencher, n: usize) {
    let ab0 = spd(n);
    let mut solver = pdyn_expr::lu::DenseSolver::new(n, true);
    let mut ab = ab0.clone();
    let mut x = vec![0.0; n];
    b.bench_local(|| {
        ab.copy_from_slice(&ab0);
        solver.solve(black_box(&mut ab), &mut x).unwrap();
        black_box(x[0])
    });
}

/// The Cholesky factor alone (`cholesky_factor_in_place`, after copying the matrix back in),
/// at the sizes of `mass_matrix_solve`: library-internal.
#[divan::bench(args = [16, 50, 100])]
fn mass_matrix_factor(b: Bencher, n: usize) {
    let a0 = spd(n)[..n * n].to_vec();
    let mut a = a0.clone();
    b.bench_local(|| {
        a.copy_from_slice(&a0);
        pdyn_expr::lu::cholesky_factor_in_place(black_box(&mut a), n).unwrap();
        black_box(a[n * n - 1])
    });
}

/// The two triangular solves alone (`cholesky_solve_in_place` with a factor computed once):
/// library-internal.
#[divan::bench(args = [16, 50, 100])]
fn mass_matrix_triangular_solves(b: Bencher, n: usize) {
    let ab = spd(n);
    let mut u = ab[..n * n].to_vec();
    pdyn_expr::lu::cholesky_factor_in_place(&mut u, n).unwrap();
    let rhs0 = ab[n * n..].to_vec();
    let mut rhs = rhs0.clone();
    b.bench_local(|| {
        rhs.copy_from_slice(&rhs0);
        pdyn_expr::lu::cholesky_solve_in_place(black_box(&u), n, &mut rhs);
        black_box(rhs[0])
    });
}
