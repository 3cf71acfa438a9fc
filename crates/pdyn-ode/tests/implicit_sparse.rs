//! Radau5 and BDF with sparse iteration matrices (`LinearSolver::Sparse`,
//! `pdyn_ode::sparse_lu`): against closed forms of stiff linear systems, and against the dense
//! LU on a stiff nonlinear lattice of springs.

use pdyn_ode::{solve, LinearSolver, Method, OdeSystem, Options, Sparsity};
use std::sync::Arc;

/// The 2-D heat equation `u_t = D Δu` on the unit square, `m × m` interior points, zero on
/// the boundary, by the 5-point Laplacian: a stiff linear system (`λ_max ≈ 8D/h²`).
struct Heat2d {
    m: usize,
    d_over_h2: f64,
    sparsity: Arc<Sparsity>,
    analytic: bool,
}

impl Heat2d {
    fn new(m: usize, d: f64, analytic: bool) -> Heat2d {
        let h = 1.0 / (m + 1) as f64;
        let n = m * m;
        let rows: Vec<Vec<usize>> = (0..n).map(|j| Heat2d::neighbours(m, j)).collect();
        Heat2d {
            m,
            d_over_h2: d / (h * h),
            sparsity: Arc::new(Sparsity::from_columns(n, rows).unwrap()),
            analytic,
        }
    }
    /// The point itself and its neighbours inside the square, ascending.
    fn neighbours(m: usize, k: usize) -> Vec<usize> {
        let (i, j) = (k / m, k % m);
        let mut v = vec![k];
        if i > 0 {
            v.push(k - m);
        }
        if j > 0 {
            v.push(k - 1);
        }
        if j + 1 < m {
            v.push(k + 1);
        }
        if i + 1 < m {
            v.push(k + m);
        }
        v.sort_unstable();
        v
    }
}

impl OdeSystem for Heat2d {
    fn dim(&self) -> usize {
        self.m * self.m
    }
    fn rhs(&self, _t: f64, u: &[f64], du: &mut [f64]) {
        let m = self.m;
        for k in 0..m * m {
            let mut s = -4.0 * u[k];
            for nb in Heat2d::neighbours(m, k) {
                if nb != k {
                    s += u[nb];
                }
            }
            du[k] = self.d_over_h2 * s;
        }
    }
    fn jacobian_sparsity(&self) -> Option<Arc<Sparsity>> {
        Some(self.sparsity.clone())
    }
    fn has_sparse_jacobian(&self) -> bool {
        self.analytic
    }
    fn sparse_jacobian(&self, _t: f64, _u: &[f64], values: &mut [f64]) {
        let mut p = 0;
        for j in 0..self.m * self.m {
            for &i in self.sparsity.column(j) {
                values[p] = if i == j { -4.0 } else { 1.0 } * self.d_over_h2;
                p += 1;
            }
        }
    }
}

/// `sin(π x_i) sin(π y_j)` on the grid is an eigenvector of the discrete Laplacian, with
/// eigenvalue `−2 · 4/h² · sin²(πh/2)`: the semi-discrete system's exact solution from it is
/// that vector times `exp(−D · 8/h² · sin²(πh/2) · t)`.
fn heat_mode(m: usize) -> (Vec<f64>, f64) {
    let h = 1.0 / (m + 1) as f64;
    let pi = std::f64::consts::PI;
    let u0 = (0..m * m)
        .map(|k| {
            let (i, j) = (k / m, k % m);
            libm::sin(pi * (i + 1) as f64 * h) * libm::sin(pi * (j + 1) as f64 * h)
        })
        .collect();
    let rate = 8.0 / (h * h) * libm::sin(pi * h / 2.0).powi(2);
    (u0, rate)
}

#[test]
fn the_2d_heat_equation_decays_as_its_closed_form_with_the_sparse_lu() {
    let (m, d) = (40, 1.0); // 1,600 unknowns; the stiffest mode decays at ~8·41² ≈ 13,000
    for analytic in [true, false] {
        let sys = Heat2d::new(m, d, analytic);
        let (u0, rate) = heat_mode(m);
        let opts = Options {
            rtol: 1e-10.into(),
            atol: 1e-12.into(),
            ..Default::default()
        };
        let t_end = 0.05;
        let sol = solve(Method::Radau5, &sys, (0.0, t_end), &u0, &opts).unwrap();
        assert!(sol.stats.sparse_lu, "n = {} should factor sparsely", m * m);
        // A linear problem whose iteration matrices are factored exactly: Newton converges
        // in its first iteration (θ ≈ 0), so the Jacobian is never evaluated again and a
        // step takes at most two solves. An inexact factorization shows here first (the
        // solution itself stays right: simplified Newton converges to it anyway).
        assert_eq!(sol.stats.jacobians, 1, "{:?}", sol.stats);
        assert!(
            sol.stats.linear_solves <= 2 * sol.stats.steps,
            "{:?}",
            sol.stats
        );
        let (_, u) = sol.last().unwrap();
        let decay = libm::exp(-d * rate * t_end);
        let err = u
            .iter()
            .zip(&u0)
            .map(|(a, b)| (a - b * decay).abs())
            .fold(0.0, f64::max);
        assert!(
            err < 1e-9 * decay,
            "analytic = {analytic}: max error {err:e}"
        );
        if !analytic {
            // Finite differences grouped by the pattern: 5 colours of the 5-point stencil
            // would do; the greedy grouping needs a few more, never n.
            assert!(sol.stats.jac_fevals <= 8 * sol.stats.jacobians);
        }
    }
}

/// A 2-D lattice of unit masses joined to their 4 neighbours by stiff, slightly nonlinear
/// springs (`F = k δ + k₃ δ³`) and dampers, the border fixed: `y = (x, v)`, 2 unknowns per
/// free node. The finite-difference Jacobian is grouped by its pattern.
struct Lattice {
    m: usize,
    k: f64,
    k3: f64,
    c: f64,
    sparsity: Arc<Sparsity>,
}

impl Lattice {
    fn new(m: usize, k: f64, k3: f64, c: f64) -> Lattice {
        let nodes = m * m;
        let n = 4 * nodes; // x, y positions then x, y velocities
        let mut rows: Vec<Vec<usize>> = vec![Vec::new(); n];
        for node in 0..nodes {
            let mut around = Heat2d::neighbours(m, node);
            around.retain(|&a| a != node);
            around.push(node);
            for a in 0..2 {
                // position column: the velocity's derivative (acceleration) of the node and
                // its neighbours, both axes
                let col = 2 * node + a;
                for &nb in &around {
                    rows[col].push(2 * nodes + 2 * nb);
                    rows[col].push(2 * nodes + 2 * nb + 1);
                }
                // velocity column: the position's derivative and the node's own damping
                let col = 2 * nodes + 2 * node + a;
                rows[col].push(2 * node + a);
                for &nb in &around {
                    rows[col].push(2 * nodes + 2 * nb + a);
                }
            }
        }
        Lattice {
            m,
            k,
            k3,
            c,
            sparsity: Arc::new(Sparsity::from_columns(n, rows).unwrap()),
        }
    }
}

impl OdeSystem for Lattice {
    fn dim(&self) -> usize {
        4 * self.m * self.m
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let m = self.m;
        let nodes = m * m;
        let (x, v) = y.split_at(2 * nodes);
        let (dx, dv) = dy.split_at_mut(2 * nodes);
        dx.copy_from_slice(v);
        // Rest positions on a unit grid; fixed nodes around the border at rest.
        let pos = |i: isize, j: isize, a: usize| -> f64 {
            let rest = if a == 0 { j as f64 } else { i as f64 };
            if i < 0 || j < 0 || i >= m as isize || j >= m as isize {
                rest
            } else {
                x[2 * (i as usize * m + j as usize) + a]
            }
        };
        let vel = |i: isize, j: isize, a: usize| -> f64 {
            if i < 0 || j < 0 || i >= m as isize || j >= m as isize {
                0.0
            } else {
                v[2 * (i as usize * m + j as usize) + a]
            }
        };
        for node in 0..nodes {
            let (i, j) = ((node / m) as isize, (node % m) as isize);
            for a in 0..2 {
                let mut f = 0.0;
                for (di, dj) in [(-1, 0), (1, 0), (0, -1), (0, 1)] {
                    let delta = pos(i + di, j + dj, a)
                        - pos(i, j, a)
                        - if a == 0 { dj as f64 } else { di as f64 };
                    f += self.k * delta + self.k3 * delta.powi(3);
                    f += self.c * (vel(i + di, j + dj, a) - vel(i, j, a));
                }
                dv[2 * node + a] = f;
            }
        }
    }
    fn jacobian_sparsity(&self) -> Option<Arc<Sparsity>> {
        Some(self.sparsity.clone())
    }
}

/// The lattice at rest positions displaced by a few per cent, at rest.
fn lattice_start(m: usize) -> Vec<f64> {
    let nodes = m * m;
    let mut y0 = vec![0.0; 4 * nodes];
    for node in 0..nodes {
        let (i, j) = (node / m, node % m);
        y0[2 * node] = j as f64 + 0.05 * ((i * 7 + j * 3) % 5) as f64 / 5.0;
        y0[2 * node + 1] = i as f64 - 0.03 * ((i * 2 + j * 5) % 7) as f64 / 7.0;
    }
    y0
}

#[test]
fn a_stiff_lattice_gives_the_dense_lu_s_steps_and_solution() {
    let m = 8; // 256 unknowns
    let sys = Lattice::new(m, 1e4, 1e5, 2.0);
    let y0 = lattice_start(m);
    let run = |solver: LinearSolver| {
        let opts = Options {
            rtol: 1e-8.into(),
            atol: 1e-10.into(),
            linear_solver: solver,
            ..Default::default()
        };
        solve(Method::Radau5, &sys, (0.0, 0.1), &y0, &opts).unwrap()
    };
    let (dense, sparse) = (run(LinearSolver::Dense), run(LinearSolver::Sparse));
    assert!(!dense.stats.sparse_lu && sparse.stats.sparse_lu);
    // Only the linear solves' round-off differs (another order of elimination, no
    // pivoting): the step sequences may part in a step or two, no more.
    let (na, nb) = (dense.stats.accepted, sparse.stats.accepted);
    assert!(
        na.abs_diff(nb) * 100 <= na,
        "accepted steps: dense {na}, sparse {nb}"
    );
    assert!(na > 20, "{na} steps: not exercised");
    let (_, a) = dense.last().unwrap();
    let (_, b) = sparse.last().unwrap();
    let err = a
        .iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-9, "dense and sparse differ by {err:e}");
}

#[test]
fn the_sparse_solver_refuses_what_it_cannot_do() {
    // No pattern.
    let decay = pdyn_ode::FnSystem::new(300, |_t, y: &[f64], f: &mut [f64]| {
        for (fi, yi) in f.iter_mut().zip(y) {
            *fi = -yi;
        }
    });
    let opts = Options {
        linear_solver: LinearSolver::Sparse,
        ..Default::default()
    };
    let e = solve(Method::Radau5, &decay, (0.0, 1.0), &[1.0; 300], &opts).unwrap_err();
    assert!(e.to_string().contains("jac_sparsity"), "{e}");
    // A pattern of the wrong size.
    let opts = Options {
        jac_sparsity: Some(Arc::new(Sparsity::banded(10, 1, 1))),
        ..Default::default()
    };
    let e = solve(Method::Radau5, &decay, (0.0, 1.0), &[1.0; 300], &opts).unwrap_err();
    assert!(e.to_string().contains("300 components"), "{e}");
    // Rows out of range.
    assert!(Sparsity::from_columns(2, vec![vec![0, 2], vec![1]]).is_err());
    assert!(Sparsity::from_columns(3, vec![vec![0]]).is_err());
}

#[test]
fn columns_are_grouped_as_the_quadratic_constructor_groups_them() {
    let sys = Heat2d::new(9, 1.0, false);
    let n = 81;
    let dense = Sparsity::new(n, |i, j| Heat2d::neighbours(9, j).contains(&i));
    assert_eq!(*sys.sparsity, dense);
}

#[test]
fn bdf_decays_the_2d_heat_equation_as_its_closed_form_with_the_sparse_lu() {
    let (m, d) = (40, 1.0); // 1,600 unknowns, as above
    for analytic in [true, false] {
        let sys = Heat2d::new(m, d, analytic);
        let (u0, rate) = heat_mode(m);
        let (rtol, atol) = (1e-8, 1e-12);
        let opts = Options {
            rtol: rtol.into(),
            atol: atol.into(),
            ..Default::default()
        };
        let t_end = 0.05;
        let sol = solve(Method::Bdf, &sys, (0.0, t_end), &u0, &opts).unwrap();
        // `LinearSolver::Auto` with a known pattern and n ≥ 200.
        assert!(sol.stats.sparse_lu, "n = {} should factor sparsely", m * m);
        // Linear, factored exactly: Newton converges with the first Jacobian, which is
        // therefore never evaluated again (an inexact factorization would fail Newton's
        // contraction test and fetch a fresh one).
        assert_eq!(sol.stats.jacobians, 1, "{:?}", sol.stats);
        assert!(sol.stats.accepted > 20, "{:?}", sol.stats);
        let (_, u) = sol.last().unwrap();
        let decay = libm::exp(-d * rate * t_end);
        let err = u
            .iter()
            .zip(&u0)
            .map(|(a, b)| (a - b * decay).abs())
            .fold(0.0, f64::max);
        // The global error of a variable-order BDF at rtol 1e-8 over ~1.3 decay times.
        assert!(
            err < 1e-7 * decay,
            "analytic = {analytic}: max error {err:e} against {decay:e}"
        );
    }
}

#[test]
fn bdf_on_a_stiff_lattice_gives_the_dense_lu_s_steps_and_solution() {
    let m = 8; // 256 unknowns
    let sys = Lattice::new(m, 1e4, 1e5, 2.0);
    let y0 = lattice_start(m);
    let run = |solver: LinearSolver| {
        let opts = Options {
            rtol: 1e-8.into(),
            atol: 1e-10.into(),
            linear_solver: solver,
            ..Default::default()
        };
        solve(Method::Bdf, &sys, (0.0, 0.1), &y0, &opts).unwrap()
    };
    let (dense, sparse) = (run(LinearSolver::Dense), run(LinearSolver::Sparse));
    assert!(!dense.stats.sparse_lu && sparse.stats.sparse_lu);
    // The linear solves differ in round-off, BDF's Newton stops at a tolerance on the
    // correction (not at round-off) and its order choice turns such differences into a few
    // steps more or less: the sequences part by a few percent at most.
    let (na, nb) = (dense.stats.accepted, sparse.stats.accepted);
    assert!(
        na.abs_diff(nb) * 30 <= na,
        "accepted steps: dense {na}, sparse {nb}"
    );
    assert!(na > 20, "{na} steps: not exercised");
    assert!(dense.stats.lu_decompositions > 5, "{:?}", dense.stats);
    let (_, a) = dense.last().unwrap();
    let (_, b) = sparse.last().unwrap();
    let err = a
        .iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    // BDF's Newton stops at a tolerance on the correction (a fraction of rtol), not at
    // round-off, so the two differ by what that stop leaves: within rtol of the largest
    // component (8 here), far below the global error.
    let size = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(
        err < 1e-8 * size,
        "dense and sparse differ by {err:e} (largest component {size})"
    );
}

#[test]
fn bdf_s_sparse_solver_refuses_what_it_cannot_do() {
    let decay = pdyn_ode::FnSystem::new(300, |_t, y: &[f64], f: &mut [f64]| {
        for (fi, yi) in f.iter_mut().zip(y) {
            *fi = -yi;
        }
    });
    let opts = Options {
        linear_solver: LinearSolver::Sparse,
        ..Default::default()
    };
    let e = solve(Method::Bdf, &decay, (0.0, 1.0), &[1.0; 300], &opts).unwrap_err();
    assert!(e.to_string().contains("jac_sparsity"), "{e}");
    let opts = Options {
        jac_sparsity: Some(Arc::new(Sparsity::banded(10, 1, 1))),
        ..Default::default()
    };
    let e = solve(Method::Bdf, &decay, (0.0, 1.0), &[1.0; 300], &opts).unwrap_err();
    assert!(e.to_string().contains("300 components"), "{e}");
    // Below 200 components `Auto` stays dense, pattern or not.
    let opts = Options {
        jac_sparsity: Some(Arc::new(Sparsity::banded(100, 0, 0))),
        ..Default::default()
    };
    let small = pdyn_ode::FnSystem::new(100, |_t, y: &[f64], f: &mut [f64]| {
        for (fi, yi) in f.iter_mut().zip(y) {
            *fi = -yi;
        }
    });
    let sol = solve(Method::Bdf, &small, (0.0, 1.0), &[1.0; 100], &opts).unwrap();
    assert!(!sol.stats.sparse_lu);
}
