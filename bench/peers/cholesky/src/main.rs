//! pdyn-expr's dense Cholesky (`cholesky_factor_in_place` + `cholesky_solve_in_place`, as
//! `DenseSolver` runs it on a numeric mass matrix) against faer's LLT (in place, sequential,
//! scratch allocated once) and nalgebra's `Cholesky` (its storage reused), on the mass matrix
//! of an n-link planar pendulum chain at n = 16, 50, 100.
//!
//! Each library factorises and solves the same matrix and right-hand side; the solutions are
//! compared. Time per call: the minimum over many calls, the libraries interleaved in rounds
//! (the machine is shared and noisy; the minimum is the least disturbed run). The copy of the
//! matrix into the library's buffer is outside the timed region.
//! Output: CSV `n,impl,what,min_ns` then the ratios.
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::{Mat, Par};
use nalgebra::{Cholesky, DMatrix, DVector};
use std::hint::black_box;
use std::time::Instant;

/// `M_ij = l_i l_j S_max(i,j) cos(q_i − q_j)`, `S_k = Σ_{m≥k} m_m`: the mass matrix of a
/// planar chain of point masses `m_k` on links of length `l_k` at angles `q_k` (row-major).
fn chain_mass_matrix(n: usize) -> Vec<f64> {
    let l: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
    let m: Vec<f64> = (0..n).map(|i| 1.0 + 0.05 * (i % 7) as f64).collect();
    let q: Vec<f64> = (0..n).map(|i| 0.3 * (1.7 * i as f64).sin()).collect();
    let mut s = vec![0.0; n + 1];
    for k in (0..n).rev() {
        s[k] = s[k + 1] + m[k];
    }
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            a[i * n + j] = l[i] * l[j] * s[i.max(j)] * (q[i] - q[j]).cos();
        }
    }
    a
}

/// The three libraries' buffers for one size.
struct Case {
    n: usize,
    a0: Vec<f64>,
    b0: Vec<f64>,
    ours_a: Vec<f64>,
    ours_b: Vec<f64>,
    faer_a: Mat<f64>,
    faer_b: Mat<f64>,
    faer_mem: MemBuffer,
    na_a: Option<DMatrix<f64>>,
    na_b: DVector<f64>,
}

impl Case {
    fn new(n: usize) -> Case {
        let a0 = chain_mass_matrix(n);
        let b0: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).cos()).collect();
        let scratch = llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default())
            .or(llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq));
        Case {
            n,
            ours_a: a0.clone(),
            ours_b: b0.clone(),
            faer_a: Mat::from_fn(n, n, |i, j| a0[i * n + j]),
            faer_b: Mat::from_fn(n, 1, |i, _| b0[i]),
            faer_mem: MemBuffer::new(scratch),
            na_a: Some(DMatrix::from_row_slice(n, n, &a0)),
            na_b: DVector::from_column_slice(&b0),
            a0,
            b0,
        }
    }

    fn reset_ours(&mut self) {
        self.ours_a.copy_from_slice(&self.a0);
        self.ours_b.copy_from_slice(&self.b0);
    }

    fn ours(&mut self, solve: bool) {
        let n = self.n;
        pdyn_expr::lu::cholesky_factor_in_place(black_box(&mut self.ours_a), n)
            .expect("the chain's mass matrix is positive definite");
        if solve {
            pdyn_expr::lu::cholesky_solve_in_place(&self.ours_a, n, &mut self.ours_b);
        }
        black_box(&self.ours_b);
    }

    fn reset_faer(&mut self) {
        let n = self.n;
        // Symmetric: row-major and column-major are the same numbers.
        for j in 0..n {
            self.faer_a
                .col_mut(j)
                .try_as_col_major_mut()
                .expect("a Mat's columns are contiguous")
                .as_slice_mut()
                .copy_from_slice(&self.a0[j * n..(j + 1) * n]);
        }
        for i in 0..n {
            self.faer_b[(i, 0)] = self.b0[i];
        }
    }

    fn faer(&mut self, solve: bool) {
        let stack = MemStack::new(&mut self.faer_mem);
        llt::factor::cholesky_in_place(
            black_box(self.faer_a.as_mut()),
            Default::default(),
            Par::Seq,
            stack,
            Default::default(),
        )
        .expect("the chain's mass matrix is positive definite");
        if solve {
            let stack = MemStack::new(&mut self.faer_mem);
            llt::solve::solve_in_place(self.faer_a.as_ref(), self.faer_b.as_mut(), Par::Seq, stack);
        }
        black_box(&self.faer_b);
    }

    fn reset_nalgebra(&mut self) {
        if let Some(a) = &mut self.na_a {
            a.copy_from_slice(&self.a0);
        }
        self.na_b.copy_from_slice(&self.b0);
    }

    fn nalgebra(&mut self, solve: bool) {
        let a = self.na_a.take().expect("the matrix is put back after each call");
        let c = Cholesky::new(black_box(a)).expect("the chain's mass matrix is positive definite");
        if solve {
            c.solve_mut(&mut self.na_b);
        }
        black_box(&self.na_b);
        self.na_a = Some(c.unpack_dirty());
    }
}

fn main() {
    println!("n,impl,what,min_ns");
    let mut ratios = Vec::new();
    for n in [16usize, 50, 100] {
        let mut case = Case::new(n);
        // The same solution from all three, to well within the matrix's conditioning.
        case.reset_ours();
        case.ours(true);
        case.reset_faer();
        case.faer(true);
        case.reset_nalgebra();
        case.nalgebra(true);
        let scale = case.ours_b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            let (x, f, a) = (case.ours_b[i], case.faer_b[(i, 0)], case.na_b[i]);
            assert!(
                (x - f).abs() <= 1e-9 * scale && (x - a).abs() <= 1e-9 * scale,
                "n={n} x[{i}]: ours {x}, faer {f}, nalgebra {a}"
            );
        }
        let reps = 2_000_000 / (n * n / 16 + 10);
        for (what, solve) in [("factor", false), ("factor+solve", true)] {
            let mut best = [f64::INFINITY; 3];
            for _round in 0..20 {
                best[0] = best[0].min(min_ns_case(&mut case, reps / 20, 0, solve));
                best[1] = best[1].min(min_ns_case(&mut case, reps / 20, 1, solve));
                best[2] = best[2].min(min_ns_case(&mut case, reps / 20, 2, solve));
            }
            for (name, t) in ["pdyn-expr", "faer", "nalgebra"].iter().zip(best) {
                println!("{n},{name},{what},{t:.0}");
            }
            ratios.push((n, what, best[0] / best[1], best[0] / best[2]));
        }
    }
    println!();
    for (n, what, f, a) in ratios {
        println!("n={n} {what}: pdyn-expr time / faer {f:.2}, / nalgebra {a:.2}");
    }
}

/// The minimum time of one call, in ns, over `reps` calls of library `which` (0 pdyn-expr,
/// 1 faer, 2 nalgebra), each on a fresh copy of the matrix.
fn min_ns_case(case: &mut Case, reps: usize, which: usize, solve: bool) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        match which {
            0 => case.reset_ours(),
            1 => case.reset_faer(),
            _ => case.reset_nalgebra(),
        }
        let t = Instant::now();
        match which {
            0 => case.ours(solve),
            1 => case.faer(solve),
            _ => case.nalgebra(solve),
        }
        best = best.min(t.elapsed().as_nanos() as f64);
    }
    best
}
