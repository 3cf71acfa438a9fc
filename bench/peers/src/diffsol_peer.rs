//! `diffsol` (0.18) on the same problems: its explicit Tsitouras 5(4) (`tsit45`) on Arenstorf
//! and Pleiades, and its BDF on Robertson. Right-hand-side evaluations are counted by the
//! closures themselves.

use crate::{arenstorf, max_err, pleiades, time, AREN_T, AREN_Y0, PLEI_Y0, PLEI_Y3};
use diffsol::matrix::MatrixCommon;
use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod};
use std::cell::Cell;

type M = NalgebraMat<f64>;

/// Final state and f-evaluations of an explicit `tsit45` run.
fn tsit45(f: fn(&[f64], &mut [f64]), y0: &[f64], t1: f64, tol: f64) -> (Vec<f64>, usize) {
    let count = Cell::new(0usize);
    let n = y0.len();
    let y0v = y0.to_vec();
    let problem = OdeBuilder::<M>::new()
        .rtol(tol)
        .atol([tol])
        .rhs(|x, _p, _t, y| {
            count.set(count.get() + 1);
            f(x, y);
        })
        .init(move |_p, _t, y| y.copy_from_slice(&y0v), n)
        .build()
        .expect("diffsol problem");
    let mut solver = problem.tsit45().expect("diffsol tsit45");
    let (ys, _ts, _) = solver.solve(t1).expect("diffsol solve");
    let m = ys.inner();
    let last = m.ncols() - 1;
    let y: Vec<f64> = (0..n).map(|i| m[(i, last)]).collect();
    (y, count.get())
}

/// Prints CSV lines for every tolerance.
pub fn run(tols: &[f64]) {
    for &tol in tols {
        let (s, (y, nf)) = time(|| tsit45(arenstorf, &AREN_Y0, AREN_T, tol));
        println!(
            "arenstorf,diffsol,tsit45,{tol:e},{:e},{nf},{s:e}",
            max_err(&y, &AREN_Y0)
        );
        let (s, (y, nf)) = time(|| tsit45(pleiades, &PLEI_Y0, 3.0, tol));
        println!(
            "pleiades,diffsol,tsit45,{tol:e},{:e},{nf},{s:e}",
            max_err(&y, &PLEI_Y3)
        );
    }
    let rref = [
        0.2083340149701255e-7,
        0.8333360770334713e-13,
        0.9999999791665050,
    ];
    for &tol in &[1e-4, 1e-6, 1e-8, 1e-10] {
        let (s, (y, nf)) = time(|| {
            let count = Cell::new(0usize);
            let problem = OdeBuilder::<M>::new()
                .rtol(tol)
                .atol([tol * 1e-6])
                .rhs_implicit(
                    |x, _p, _t, f| {
                        count.set(count.get() + 1);
                        f[0] = -0.04 * x[0] + 1e4 * x[1] * x[2];
                        f[2] = 3e7 * x[1] * x[1];
                        f[1] = -f[0] - f[2];
                    },
                    |x, _p, _t, v, jv| {
                        jv[0] = -0.04 * v[0] + 1e4 * x[2] * v[1] + 1e4 * x[1] * v[2];
                        jv[2] = 6e7 * x[1] * v[1];
                        jv[1] = -jv[0] - jv[2];
                    },
                )
                .init(|_p, _t, y| y.copy_from_slice(&[1.0, 0.0, 0.0]), 3)
                .build()
                .expect("diffsol problem");
            let mut solver = problem.bdf::<NalgebraLU<f64>>().expect("diffsol bdf");
            let (ys, _ts, _) = solver.solve(1e11).expect("diffsol solve");
            let m = ys.inner();
            let last = m.ncols() - 1;
            let y: Vec<f64> = (0..3).map(|i| m[(i, last)]).collect();
            (y, count.get())
        });
        let e = (0..3)
            .map(|i| ((y[i] - rref[i]) / rref[i]).abs())
            .fold(0.0, f64::max);
        println!("robertson,diffsol,bdf,{tol:e},{e:e},{nf},{s:e}");
    }
}
