//! Long-time energy behaviour on Kepler's problem, e = 0.6, over 10^5 periods (Hairer, Lubich
//! & Wanner, *Geometric Numerical Integration*, §I.2): symplectic methods keep the energy
//! error bounded (no secular growth), DOPRI5 at comparable cost drifts linearly.
//!
//! The integration runs in chunks of 100 periods, each chunk returning only its final state
//! (`t_eval = [chunk end]`, which is a step end, so no interpolation is involved). Restarting a
//! fixed-step method is exactly the same map as not restarting it. Energy is sampled at every
//! step during the first and the last 100 periods (the band of the energy error), and the
//! bands are compared.
use pdyn_ode::{solve_second_order, FnSecondOrder, Method, Options};
use std::f64::consts::PI;

const E: f64 = 0.6;
const PERIODS: usize = 100_000;
const CHUNK: usize = 100;

fn kepler() -> impl pdyn_ode::SecondOrderSystem {
    FnSecondOrder::new(2, true, |_t, q: &[f64], _v: &[f64], a: &mut [f64]| {
        let r2 = q[0] * q[0] + q[1] * q[1];
        let r3 = r2 * r2.sqrt();
        a[0] = -q[0] / r3;
        a[1] = -q[1] / r3;
    })
}

fn energy(y: &[f64]) -> f64 {
    0.5 * (y[2] * y[2] + y[3] * y[3]) - 1.0 / (y[0] * y[0] + y[1] * y[1]).sqrt()
}

/// Energy error band (max over every step end) during the first and the last CHUNK periods,
/// and the total f-evaluations.
fn run(
    method: Method,
    steps_per_period: usize,
    opts: Options,
    periods: usize,
) -> (f64, f64, usize) {
    let sys = kepler();
    let mut q = [1.0 - E, 0.0];
    let mut v = [0.0, ((1.0 + E) / (1.0 - E)).sqrt()];
    let h = 2.0 * PI / steps_per_period as f64;
    let (mut first, mut last) = (0.0, 0.0);
    let mut fevals = 0;
    let chunks = periods / CHUNK;
    for c in 0..chunks {
        let t0 = (c * CHUNK) as f64 * 2.0 * PI;
        let t1 = ((c + 1) * CHUNK) as f64 * 2.0 * PI;
        let every_step = c == 0 || c == chunks - 1;
        let o = Options {
            h0: if method.order() == 5 { None } else { Some(h) },
            t_eval: if every_step { None } else { Some(vec![t1]) },
            ..opts.clone()
        };
        let sol = solve_second_order(method, &sys, (t0, t1), &q, &v, &o).unwrap();
        fevals += sol.stats.fevals;
        let (_, y) = sol.last().unwrap();
        q.copy_from_slice(&y[..2]);
        v.copy_from_slice(&y[2..]);
        if every_step {
            let band = (0..sol.len())
                .map(|k| (energy(sol.y_at(k)) + 0.5).abs())
                .fold(0.0, f64::max);
            if c == 0 {
                first = band;
            } else {
                last = band;
            }
        }
    }
    (first, last, fevals)
}

/// Bounded: the energy-error band over the last CHUNK periods is not wider (beyond `margin`)
/// than over the first CHUNK periods.
fn assert_bounded(method: Method, steps: usize, margin: f64, periods: usize) -> (f64, usize) {
    let (first, last, fevals) = run(method, steps, Options::default(), periods);
    eprintln!("{method}: first {first:e} last {last:e} fevals {fevals}");
    assert!(
        last <= margin * first,
        "{method}: energy error grew from {first:e} to {last:e}"
    );
    (first.max(last), fevals)
}

#[test]
fn symplectic_explicit_methods_keep_energy_bounded_and_dopri5_drifts() {
    let (e_verlet, _) = assert_bounded(Method::VelocityVerlet, 100, 1.1, PERIODS);
    let (e_y4, _) = assert_bounded(Method::Yoshida4, 50, 1.1, PERIODS);
    let (e_kl6, f_kl6) = assert_bounded(Method::KahanLi6, 30, 1.1, PERIODS);
    let (e_kl8, f_kl8) = assert_bounded(Method::KahanLi8, 20, 1.1, PERIODS);
    assert!(e_verlet < 0.02 && e_y4 < 0.01 && e_kl6 < 0.003 && e_kl8 < 0.005);

    // DOPRI5 at rtol = atol = 1e-7 costs about as much as Kahan-Li 6/8 here (≈3.7e7
    // evaluations of f); its energy error grows linearly, ending far above theirs.
    let opts = Options {
        max_steps: usize::MAX,
        ..Options::with_tol(1e-7)
    };
    let (first, last, f_dopri) = run(Method::Dopri5, 1, opts, PERIODS);
    eprintln!("dopri5: first {first:e} last {last:e} fevals {f_dopri}");
    assert!(f_dopri < 2 * f_kl8.max(f_kl6), "comparable cost");
    assert!(
        last > 5.0 * first,
        "DOPRI5 should drift: {first:e} -> {last:e}"
    );
    assert!(last > 10.0 * e_kl6.max(e_kl8), "DOPRI5 ends far worse");
}

#[test]
fn gauss_legendre_keeps_energy_bounded() {
    // Fixed-point iteration needs h·|∂a/∂q| small at perihelion (|∂a/∂q| ≈ 2/r³ ≈ 31):
    // 100 and 60 steps per period; 10^4 periods keep the test within seconds.
    let (e4, _) = assert_bounded(Method::Gauss4, 100, 1.1, PERIODS / 10);
    let (e6, _) = assert_bounded(Method::Gauss6, 60, 1.1, PERIODS / 10);
    assert!(e4 < 1e-3 && e6 < 1e-4);
}
