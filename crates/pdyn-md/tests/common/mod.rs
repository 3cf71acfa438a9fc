#![allow(dead_code)]
//! Shared set-ups for the integration tests.

use pdyn_md::potential::{CutoffMode, LennardJones, PairPotential, Truncated};
use pdyn_md::thermostat::Thermostat;
use pdyn_md::*;

/// LAMMPS bench/in.lj: fcc at ρ = 0.8442, T = 1.44, rc = 2.5, skin 0.3, dt 0.005.
pub fn lj_liquid(cells: usize, seed: u64, dt: f64) -> Simulation<Truncated<LennardJones>> {
    lj_liquid_mode(cells, seed, dt, CutoffMode::Plain)
}

/// [`lj_liquid`] with another cutoff mode.
pub fn lj_liquid_mode(
    cells: usize,
    seed: u64,
    dt: f64,
    mode: CutoffMode,
) -> Simulation<Truncated<LennardJones>> {
    let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [cells; 3], 1.0, 1 << 24).unwrap();
    maxwell_boltzmann(&mut p, 1.44, 1.0, seed).unwrap();
    let ff = ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, mode));
    let params = SimParams {
        dt,
        thermo_every: 10,
        ..SimParams::default()
    };
    Simulation::new(System::new(p, bx), ff, Thermostat::None, params).unwrap()
}

/// Naive reference: every pair once, minimum image; returns (U, W, forces).
pub fn all_pairs<P: PairPotential>(s: &System, ff: &ForceField<P>) -> (f64, f64, Vec<[f64; 3]>) {
    let p = &s.particles;
    let n = p.len();
    let (mut u, mut w) = (0.0, 0.0);
    let mut f = vec![[0.0; 3]; n];
    for i in 0..n {
        for j in i + 1..n {
            let pot = ff.get(s.types[i] as usize, s.types[j] as usize);
            let d = s.sim_box.delta(p.pos(i), p.pos(j)).0;
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if r2 < pot.cutoff() * pot.cutoff() {
                let (e, fr) = pot.energy_force(r2);
                u += e;
                w += fr * r2;
                for k in 0..3 {
                    f[i][k] += fr * d[k];
                    f[j][k] -= fr * d[k];
                }
            }
        }
    }
    (u, w, f)
}

/// Least-squares slope of y against x.
pub fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// Standard deviation.
pub fn std(y: &[f64]) -> f64 {
    let n = y.len() as f64;
    let m = y.iter().sum::<f64>() / n;
    (y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt()
}

/// Standard deviation of the residuals about the least-squares line (fluctuation with any
/// linear drift removed).
pub fn detrended_std(x: &[f64], y: &[f64]) -> f64 {
    let b = slope(x, y);
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let r: Vec<f64> = x
        .iter()
        .zip(y)
        .map(|(a, v)| v - (my + b * (a - mx)))
        .collect();
    std(&r)
}

/// Mean and standard error of correlated samples from 10 contiguous block means.
pub fn mean_and_error(xs: &[f64]) -> (f64, f64) {
    pdyn_md::analysis::block_means(xs, 10).expect("at least 20 samples")
}

/// `f` run on a rayon pool of `threads` threads (results must not depend on the count).
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}
