//! The Lennard-Jones equation of state at ρ* = 0.8, T* = 2.0 against the modified
//! Benedict–Webb–Rubin fit of Johnson, Zollweg & Gubbins, Mol. Phys. 78, 591 (1993) (JZG),
//! whose 32 coefficients (their Table 10) are fitted to simulations of the full potential.
//!
//! Simulation: 864 atoms (fcc 6³), r_c = 4σ plain cutoff plus the standard tail corrections
//! (Allen & Tildesley §2.8), Langevin at T* = 2 (BAOAB, configurational error O(dt²)),
//! dt = 0.002, 2 000 steps of equilibration, 20 000 steps of production; statistical error from
//! 10 block averages. Measured (release, 2026-11-23): T* = 1.991 ± 0.008,
//! P* = 5.260 ± 0.031 against the fit's 5.312 (1.7σ), U/N = −4.756 ± 0.006 against −4.760 (0.7σ).
//! Release only:
//! `cargo test --release -p pdyn-md --test eos -- --ignored --nocapture`

use pdyn_md::potential::{CutoffMode, LennardJones};
use pdyn_md::thermostat::*;
use pdyn_md::*;

/// JZG Table 10, x₁ … x₃₂ (as published).
#[allow(clippy::excessive_precision)]
const X: [f64; 32] = [
    0.862_308_509_750_742_1,
    2.976_218_765_822_098,
    -8.402_230_115_796_038,
    0.105_413_662_920_355_5,
    -0.856_458_382_817_459_8,
    1.582_759_470_107_601,
    0.763_942_194_830_545_3,
    1.753_173_414_312_048,
    2.798_291_772_190_376e3,
    -4.839_422_026_085_765_7e-2,
    0.996_326_519_772_193_5,
    -3.698_000_291_272_493e1,
    2.084_012_299_434_647e1,
    8.305_402_124_717_285e1,
    -9.574_799_715_203_068e2,
    -1.477_746_229_234_994e2,
    6.398_607_852_471_505e1,
    1.603_993_673_294_834e1,
    6.805_916_615_864_377e1,
    -2.791_293_578_795_945e3,
    -6.245_128_304_568_454,
    -8.116_836_104_958_41e3,
    1.488_735_559_561_229e1,
    -1.059_346_754_655_084e4,
    -1.131_607_632_802_822e2,
    -8.867_771_540_418_822e3,
    -3.986_982_844_450_543e1,
    -4.689_270_299_917_261e3,
    2.593_535_277_438_717e2,
    -2.694_523_589_434_903e3,
    -7.218_487_631_550_215e2,
    1.721_802_063_863_269e2,
];

/// Residual Helmholtz energy per particle, JZG eq. (5): `A = Σ aᵢ ρⁱ/i + Σ bᵢ Gᵢ`.
fn helmholtz(rho: f64, t: f64) -> f64 {
    let x = |i: usize| X[i - 1];
    let a = [
        x(1) * t + x(2) * t.sqrt() + x(3) + x(4) / t + x(5) / (t * t),
        x(6) * t + x(7) + x(8) / t + x(9) / (t * t),
        x(10) * t + x(11) + x(12) / t,
        x(13),
        x(14) / t + x(15) / (t * t),
        x(16) / t,
        x(17) / t + x(18) / (t * t),
        x(19) / (t * t),
    ];
    let b = [
        x(20) / (t * t) + x(21) / t.powi(3),
        x(22) / (t * t) + x(23) / t.powi(4),
        x(24) / (t * t) + x(25) / t.powi(3),
        x(26) / (t * t) + x(27) / t.powi(4),
        x(28) / (t * t) + x(29) / t.powi(3),
        x(30) / (t * t) + x(31) / t.powi(3) + x(32) / t.powi(4),
    ];
    let gamma = 3.0;
    let f = libm::exp(-gamma * rho * rho);
    let mut g = [0.0; 6];
    g[0] = (1.0 - f) / (2.0 * gamma);
    for k in 1..6 {
        g[k] = -(f * rho.powi(2 * k as i32) - 2.0 * k as f64 * g[k - 1]) / (2.0 * gamma);
    }
    let s1: f64 = (0..8)
        .map(|i| a[i] * rho.powi(i as i32 + 1) / (i + 1) as f64)
        .sum();
    let s2: f64 = (0..6).map(|i| b[i] * g[i]).sum();
    s1 + s2
}

/// `(P, U/N)` from the JZG fit: `P = ρT + ρ² ∂A/∂ρ`, `U = A − T ∂A/∂T`.
fn jzg(rho: f64, t: f64) -> (f64, f64) {
    let h = 1e-5;
    let da_drho = (helmholtz(rho + h, t) - helmholtz(rho - h, t)) / (2.0 * h);
    let da_dt = (helmholtz(rho, t + h) - helmholtz(rho, t - h)) / (2.0 * h);
    (rho * t + rho * rho * da_drho, helmholtz(rho, t) - t * da_dt)
}

fn block_mean(v: &[f64], blocks: usize) -> (f64, f64) {
    let m = v.len() / blocks;
    let means: Vec<f64> = (0..blocks)
        .map(|b| v[b * m..(b + 1) * m].iter().sum::<f64>() / m as f64)
        .collect();
    let mean = means.iter().sum::<f64>() / blocks as f64;
    let var = means.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (blocks - 1) as f64;
    (mean, (var / blocks as f64).sqrt())
}

#[test]
fn jzg_fit_is_evaluated_correctly() {
    // ideal-gas limit, and the sample value α^r(T=2, ρ=0.4) = −0.335277093352 of the teqp port
    assert!((jzg(1e-7, 2.0).0 / (1e-7 * 2.0) - 1.0).abs() < 1e-5);
    assert!((helmholtz(0.4, 2.0) / 2.0 + 0.335_277_093_351_993_57).abs() < 1e-10);
}

#[test]
#[ignore]
fn lj_equation_of_state_at_rho_08_t_2() {
    let (rho, t) = (0.8, 2.0);
    let rc = 4.0;
    let (mut p, bx) = lattice(Lattice::Fcc, rho, [6; 3], 1.0, 10_000).unwrap();
    maxwell_boltzmann(&mut p, t, 1.0, 2024).unwrap();
    let lj = LennardJones::new(1.0, 1.0);
    let ff = ForceField::single(lj.truncated(rc, CutoffMode::Plain));
    let th = Langevin::new(LangevinParams {
        temperature: Some(t),
        damping: 1.0,
        seed: 5,
    })
    .unwrap();
    let params = SimParams {
        dt: 0.002,
        thermo_every: 10,
        ..SimParams::default()
    };
    let mut sim =
        Simulation::new(System::new(p, bx), ff, Thermostat::Langevin(th), params).unwrap();
    sim.run(2000, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    let n = sim.system.particles.len() as f64;
    let (mut ps, mut us, mut ts) = (vec![], vec![], vec![]);
    sim.run(20_000, &mut |r: &ThermoRecord, _: &System| {
        ps.push(r.pressure);
        us.push(r.potential / n);
        ts.push(r.temperature);
    })
    .unwrap();
    let (p_sim, p_err) = block_mean(&ps, 10);
    let (u_sim, u_err) = block_mean(&us, 10);
    let (t_sim, t_err) = block_mean(&ts, 10);
    let p_sim = p_sim + lj.pressure_tail(rho, rc);
    let u_sim = u_sim + lj.energy_tail_per_particle(rho, rc);
    let (p_ref, u_ref) = jzg(rho, t);
    println!("T = {t_sim:.4} ± {t_err:.4}");
    println!("P = {p_sim:.4} ± {p_err:.4} (JZG fit {p_ref:.4})");
    println!("U/N = {u_sim:.4} ± {u_err:.4} (JZG fit {u_ref:.4})");
    // JZG quote the fit's deviation from their simulations as a few hundredths in P and U here;
    // allow 3σ statistical plus 0.05 for the fit
    assert!((p_sim - p_ref).abs() < 3.0 * p_err + 0.05);
    assert!((u_sim - u_ref).abs() < 3.0 * u_err + 0.02);
}
