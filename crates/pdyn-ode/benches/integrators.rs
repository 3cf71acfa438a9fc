//! Criterion benchmarks: whole solves of Arenstorf (4 equations), Pleiades (28) and
//! Robertson (3, stiff), and a Kepler run with velocity Verlet.
//!
//! Run: `cargo bench -p pdyn-ode --bench integrators`.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pdyn_ode::{solve, solve_second_order, FnSecondOrder, FnSystem, FnSystemWithJacobian};
use pdyn_ode::{Method, Options};

use pdyn_ode::problems::{arenstorf_rhs, pleiades_rhs, AREN_T, AREN_Y0, PLEI_Y0};

fn arenstorf(_t: f64, y: &[f64], f: &mut [f64]) {
    arenstorf_rhs(y, f)
}

fn pleiades(_t: f64, s: &[f64], f: &mut [f64]) {
    pleiades_rhs(s, f)
}

fn bench(c: &mut Criterion) {
    let aren = FnSystem::new(4, arenstorf);
    let plei = FnSystem::new(28, pleiades);
    for (m, tol) in [
        (Method::Dopri5, 1e-8),
        (Method::Tsit5, 1e-8),
        (Method::Dop853, 1e-10),
    ] {
        let o = Options::with_tol(tol);
        c.bench_function(&format!("arenstorf/{m}/tol={tol:e}"), |b| {
            b.iter(|| solve(m, &aren, (0.0, AREN_T), black_box(&AREN_Y0), &o).unwrap())
        });
        c.bench_function(&format!("pleiades/{m}/tol={tol:e}"), |b| {
            b.iter(|| solve(m, &plei, (0.0, 3.0), black_box(&PLEI_Y0), &o).unwrap())
        });
    }
    let rober = FnSystemWithJacobian::new(
        3,
        |_t, y: &[f64], f: &mut [f64]| {
            f[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
            f[2] = 3e7 * y[1] * y[1];
            f[1] = -f[0] - f[2];
        },
        |_t, y: &[f64], j: &mut [f64]| {
            j.copy_from_slice(&[
                -0.04,
                1e4 * y[2],
                1e4 * y[1],
                0.04,
                -1e4 * y[2] - 6e7 * y[1],
                -1e4 * y[1],
                0.0,
                6e7 * y[1],
                0.0,
            ]);
        },
    );
    let o = Options {
        rtol: 1e-6.into(),
        atol: 1e-10.into(),
        ..Default::default()
    };
    c.bench_function("robertson/radau5/1e11", |b| {
        b.iter(|| {
            solve(
                Method::Radau5,
                &rober,
                (0.0, 1e11),
                black_box(&[1.0, 0.0, 0.0]),
                &o,
            )
            .unwrap()
        })
    });
    let kepler = FnSecondOrder::new(2, true, |_t, q: &[f64], _v: &[f64], a: &mut [f64]| {
        let r2 = q[0] * q[0] + q[1] * q[1];
        let r3 = r2 * r2.sqrt();
        a[0] = -q[0] / r3;
        a[1] = -q[1] / r3;
    });
    let e: f64 = 0.6;
    let v0 = ((1.0 + e) / (1.0 - e)).sqrt();
    let o = Options {
        h0: Some(2.0 * std::f64::consts::PI / 100.0),
        t_eval: Some(vec![200.0 * std::f64::consts::PI]),
        ..Default::default()
    };
    c.bench_function("kepler/verlet/10^4 steps", |b| {
        b.iter(|| {
            solve_second_order(
                Method::VelocityVerlet,
                &kepler,
                (0.0, 200.0 * std::f64::consts::PI),
                black_box(&[1.0 - e, 0.0]),
                &[0.0, v0],
                &o,
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
