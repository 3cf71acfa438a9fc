//! Langevin's opt-in LAMMPS scheme (`fix langevin` + `fix nve`): one step against the update
//! written out by hand from LAMMPS's `FixLangevin::post_force` and `FixNVE`, and the canonical
//! temperature it samples.

mod common;
use common::*;
use pdyn_md::potential::{CutoffMode, LennardJones};
use pdyn_md::thermostat::*;
use pdyn_md::*;

/// LJ force on `a` from `b` (ε = σ = 1), `24 (2 r⁻¹² − r⁻⁶)/r² · (a − b)`.
fn lj_force(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let s6 = 1.0 / (r2 * r2 * r2);
    let fr = 24.0 * (2.0 * s6 * s6 - s6) / r2;
    d.map(|x| fr * x)
}

/// Two LJ atoms of masses 1 and 2.5, T = 1.7, damp = 0.4, dt = 0.005. By hand, following
/// LAMMPS: at set-up `F₀ = F_LJ(x₀) + γ₁ v₀ + γ₂ (u − ½)` with `γ₁ = −m/damp`,
/// `γ₂ = √m √(24 k_B T/(damp dt))` and one uniform `u` per component in particle order; then
/// `v½ = v₀ + (dt/2) F₀/m`, `x₁ = x₀ + dt v½`, `F₁ = F_LJ(x₁) + γ₁ v½ + γ₂ (u − ½)` (the
/// next six uniforms), `v₁ = v½ + (dt/2) F₁/m`. A friction from the full-step velocities, a
/// Gaussian or differently scaled noise, another draw order or a missing set-up draw all
/// change the numbers by far more than the tolerance.
#[test]
fn one_step_matches_lammps_update_written_out_by_hand() {
    let (t, damp, dt, seed) = (1.7, 0.4, 0.005, 11);
    let m = [1.0, 2.5];
    let x0 = [[5.0, 5.0, 5.0], [5.9, 5.5, 5.3]];
    let v0 = [[0.3, -0.2, 0.1], [-0.1, 0.4, -0.25]];
    let mut p = Particles::new();
    for i in 0..2 {
        p.push(Particle {
            mass: m[i],
            pos: Vec3(x0[i]),
            vel: Vec3(v0[i]),
        })
        .unwrap();
    }
    let bx = SimBox::new(10.0, 10.0, 10.0).unwrap();
    let ff = ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain));
    let th = Langevin::new(LangevinParams {
        temperature: Some(t),
        damping: damp,
        seed,
    })
    .unwrap()
    .with_scheme(LangevinScheme::Lammps {
        noise: LangevinNoise::Uniform,
    });
    let params = SimParams {
        dt,
        thermo_every: 1,
        ..SimParams::default()
    };
    let mut sim =
        Simulation::new(System::new(p, bx), ff, Thermostat::Langevin(th), params).unwrap();
    sim.run(1, &mut |_: &ThermoRecord, _: &System| {}).unwrap();

    let mut rng = Rng::new(seed);
    let mut langevin = |v: [[f64; 3]; 2]| {
        let mut f = [[0.0; 3]; 2];
        for i in 0..2 {
            let gamma1 = -m[i] / damp;
            let gamma2 = m[i].sqrt() * (24.0 * t / (damp * dt)).sqrt();
            for k in 0..3 {
                f[i][k] = gamma1 * v[i][k] + gamma2 * (rng.uniform() - 0.5);
            }
        }
        f
    };
    let total = |x: [[f64; 3]; 2], extra: [[f64; 3]; 2]| {
        let f01 = lj_force(x[0], x[1]);
        let mut f = [[0.0; 3]; 2];
        for k in 0..3 {
            f[0][k] = f01[k] + extra[0][k];
            f[1][k] = -f01[k] + extra[1][k];
        }
        f
    };
    let f0 = total(x0, langevin(v0));
    let mut vh = v0;
    let mut x1 = x0;
    for i in 0..2 {
        for k in 0..3 {
            vh[i][k] += 0.5 * dt * f0[i][k] / m[i];
            x1[i][k] += dt * vh[i][k];
        }
    }
    let f1 = total(x1, langevin(vh));
    let mut v1 = vh;
    for i in 0..2 {
        for k in 0..3 {
            v1[i][k] += 0.5 * dt * f1[i][k] / m[i];
        }
    }
    let p = &sim.system.particles;
    for i in 0..2 {
        let got_x = [p.x[i], p.y[i], p.z[i]];
        let got_v = [p.vx[i], p.vy[i], p.vz[i]];
        for k in 0..3 {
            assert!(
                (got_x[k] - x1[i][k]).abs() < 1e-13,
                "x[{i}][{k}]: {} against {}",
                got_x[k],
                x1[i][k]
            );
            assert!(
                (got_v[k] - v1[i][k]).abs() < 1e-12,
                "v[{i}][{k}]: {} against {}",
                got_v[k],
                v1[i][k]
            );
        }
    }
    // the noise is not negligible at this step: without it v₁ moves by more than 1e-3
    let noise_scale = (24.0 * t / (damp * dt)).sqrt() * 0.5 * dt;
    assert!(noise_scale > 1e-2);
}

/// 256 LJ atoms (ρ = 0.8442) at T = 1 and a small step (dt = 0.002): the reported (full-step)
/// temperature averages to the target within four standard errors (ten-block errors are
/// themselves uncertain by a quarter), with either noise. The error is small enough (< 0.005)
/// that a noise variance or friction off by 5 % would fail. (For a free particle this scheme's
/// full-step variance is exactly `k_B T/m`: the half-step one is `k_B T/m · 2/(2 − γh)`.)
#[test]
fn lammps_scheme_samples_the_canonical_temperature() {
    for (noise, seed) in [(LangevinNoise::Uniform, 21), (LangevinNoise::Gaussian, 22)] {
        let th = Langevin::new(LangevinParams {
            temperature: Some(1.0),
            damping: 0.2,
            seed,
        })
        .unwrap()
        .with_scheme(LangevinScheme::Lammps { noise });
        let dt = 0.002;
        let mut sim = lj_liquid(4, seed, dt);
        sim.thermostat = Thermostat::Langevin(th);
        sim.params.thermo_every = 5;
        assert_eq!(sim.kinetic_estimator(), KineticEstimator::FullStep);
        let steps = (60.0 / dt) as u64;
        sim.run(steps / 6, &mut |_: &ThermoRecord, _: &System| {})
            .unwrap();
        let mut ts = vec![];
        sim.run(steps, &mut |r: &ThermoRecord, _: &System| {
            ts.push(r.temperature)
        })
        .unwrap();
        let (t, e) = mean_and_error(&ts);
        println!("{noise:?}: T = {t:.5} ± {e:.5}");
        assert!((t - 1.0).abs() < 4.0 * e, "{noise:?}: T = {t} ± {e}");
        assert!(e < 0.005, "{noise:?}: error {e} too large to test anything");
    }
}

fn lammps_liquid(cells: usize, seed: u64) -> Simulation<potential::Truncated<LennardJones>> {
    let th = Langevin::new(LangevinParams {
        temperature: Some(1.0),
        damping: 0.5,
        seed,
    })
    .unwrap()
    .with_scheme(LangevinScheme::Lammps {
        noise: LangevinNoise::Uniform,
    });
    let mut sim = lj_liquid(cells, seed, 0.005);
    sim.thermostat = Thermostat::Langevin(th);
    sim
}

/// 2,048 atoms (the force loop in two segments) on 1, 2 and 3 threads: the same bits.
#[test]
fn lammps_scheme_does_not_depend_on_thread_count() {
    let run = |threads: usize| {
        common::on_threads(threads, || {
            let mut sim = lammps_liquid(8, 11);
            sim.run(40, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
            (sim.system.particles.clone(), sim.thermo())
        })
    };
    let (p1, t1) = run(1);
    for threads in [2, 3] {
        let (p, t) = run(threads);
        assert_eq!(p1, p, "{threads} threads");
        assert_eq!(t1, t, "{threads} threads");
    }
}

/// A run stopped after its first step (the energy sums of that step are then made again from
/// the same positions) and continued is the same bits as one run straight through: the
/// friction and noise drawn at the step are reused, not drawn again.
#[test]
fn lammps_scheme_stopped_and_continued_gives_the_same_bits() {
    let mut straight = lammps_liquid(4, 7);
    straight
        .run(10, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    let mut stopped = lammps_liquid(4, 7);
    let stop = std::sync::atomic::AtomicBool::new(true);
    let r = stopped
        .run_interruptible(10, &mut |_: &ThermoRecord, _: &System| {}, Some(&stop))
        .unwrap();
    assert_eq!(r.steps, 1);
    stopped
        .run(9, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    assert_eq!(straight.system.particles, stopped.system.particles);
}
