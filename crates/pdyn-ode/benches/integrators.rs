//! Criterion benchmarks: whole solves of Arenstorf (4 equations), Pleiades (28) and
//! Robertson (3, stiff), and a Kepler run with velocity Verlet.
//!
//! Run: `cargo bench -p pdyn-ode --bench integrators`.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use pdyn_ode::{solve, solve_second_order, FnSecondOrder, FnSystem, FnSystemWithJacobian};
use pdyn_ode::{Method, Options};

const MU: f64 = 0.012277471;
const AREN_Y0: [f64; 4] = [0.994, 0.0, 0.0, -2.001_585_106_379_082_5];
const AREN_T: f64 = 17.065_216_560_157_963;

fn arenstorf(_t: f64, y: &[f64], f: &mut [f64]) {
    let mup = 1.0 - MU;
    let r1 = (y[0] + MU) * (y[0] + MU) + y[1] * y[1];
    let r2 = (y[0] - mup) * (y[0] - mup) + y[1] * y[1];
    let d1 = r1 * r1.sqrt();
    let d2 = r2 * r2.sqrt();
    f[0] = y[2];
    f[1] = y[3];
    f[2] = y[0] + 2.0 * y[3] - mup * (y[0] + MU) / d1 - MU * (y[0] - mup) / d2;
    f[3] = y[1] - 2.0 * y[2] - mup * y[1] / d1 - MU * y[1] / d2;
}

fn pleiades(_t: f64, s: &[f64], f: &mut [f64]) {
    let (x, rest) = s.split_at(7);
    let (y, v) = rest.split_at(7);
    f[..14].copy_from_slice(v);
    for i in 0..7 {
        let (mut ax, mut ay) = (0.0, 0.0);
        for j in 0..7 {
            if i != j {
                let dx = x[j] - x[i];
                let dy = y[j] - y[i];
                let r2 = dx * dx + dy * dy;
                let r3 = r2 * r2.sqrt();
                ax += (j + 1) as f64 * dx / r3;
                ay += (j + 1) as f64 * dy / r3;
            }
        }
        f[14 + i] = ax;
        f[21 + i] = ay;
    }
}

const PLEI_Y0: [f64; 28] = [
    3.0, 3.0, -1.0, -3.0, 2.0, -2.0, 2.0, 3.0, -3.0, 2.0, 0.0, 0.0, -4.0, 4.0, 0.0, 0.0, 0.0, 0.0,
    0.0, 1.75, -1.5, 0.0, 0.0, 0.0, -1.25, 1.0, 0.0, 0.0,
];

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
