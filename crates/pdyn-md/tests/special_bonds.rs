//! `special_bonds lj f₁ f₂ f₃`: the pair energy and forces of bonded neighbours scaled by
//! their bond distance, checked against a direct all-pairs sum written here, whose relations
//! come from the chains' bead indices (not from pdyn-md's neighbour search).

use pdyn_md::potential::{CutoffMode, LennardJones};
use pdyn_md::thermostat::Thermostat;
use pdyn_md::*;

const CHAINS: usize = 4;
const BEADS: usize = 10;
const RC: f64 = 2.5;

/// Four zig-zag chains of ten beads (bond ≈ 0.97, 1-3 distance 1.6, 1-4 ≈ 2.46: all within
/// the cutoff), 1.2 apart, jittered.
fn chains(factors: [f64; 3], bond: BondKind) -> System {
    let mut p = Particles::with_capacity(CHAINS * BEADS, 1000).unwrap();
    let mut rng = Rng::new(7);
    for c in 0..CHAINS {
        for k in 0..BEADS {
            let mut j = || 0.05 * (2.0 * rng_uniform(&mut rng) - 1.0);
            let pos = Vec3::new(
                0.5 + 0.8 * k as f64 + j(),
                1.0 + 1.2 * c as f64 + 0.55 * (k % 2) as f64 + j(),
                2.0 + j(),
            );
            p.push(Particle {
                mass: 1.0,
                pos,
                vel: Vec3::ZERO,
            })
            .unwrap();
        }
    }
    let mut s = System::new(p, SimBox::new(12.0, 12.0, 12.0).unwrap());
    for c in 0..CHAINS {
        for k in 0..BEADS - 1 {
            let i = c * BEADS + k;
            s.add_bond(Bond {
                i,
                j: i + 1,
                kind: bond,
            })
            .unwrap();
        }
    }
    s.special_lj = factors;
    s
}

fn rng_uniform(rng: &mut Rng) -> f64 {
    // a normal deviate squashed to (0, 1) is enough for a jitter
    0.5 + 0.5 * libm::tanh(rng.normal() / 3.0)
}

/// LJ shifted to zero at `RC`, and `−du/dr / r`.
fn lj(r2: f64) -> (f64, f64) {
    let u = |r2: f64| {
        let s6 = 1.0 / (r2 * r2 * r2);
        4.0 * (s6 * s6 - s6)
    };
    let s6 = 1.0 / (r2 * r2 * r2);
    (u(r2) - u(RC * RC), 24.0 * (2.0 * s6 * s6 - s6) / r2)
}

/// Direct sum over all pairs: energy and forces, each pair scaled by its relation along the
/// chain (|i − j| = 1, 2, 3 within one chain), plus the bonds.
fn direct(s: &System, factors: [f64; 3], bond: BondKind) -> (f64, Vec<[f64; 3]>) {
    let p = &s.particles;
    let n = p.len();
    let mut u = 0.0;
    let mut f = vec![[0.0; 3]; n];
    for i in 0..n {
        for j in i + 1..n {
            let d = s.sim_box.delta(p.pos(i), p.pos(j)).0;
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let same_chain = i / BEADS == j / BEADS;
            let factor = match j - i {
                1..=3 if same_chain => factors[j - i - 1],
                _ => 1.0,
            };
            let mut e = 0.0;
            let mut fr = 0.0;
            if r2 < RC * RC {
                let (a, b) = lj(r2);
                e += factor * a;
                fr += factor * b;
            }
            if same_chain && j - i == 1 {
                let (a, b) = bond.energy_force(r2).unwrap();
                e += a;
                fr += b;
            }
            u += e;
            for k in 0..3 {
                f[i][k] += fr * d[k];
                f[j][k] -= fr * d[k];
            }
        }
    }
    (u, f)
}

#[test]
fn special_bonds_energy_and_forces_equal_a_direct_sum() {
    let fene = BondKind::FeneWca {
        k: 30.0,
        r_max: 1.5,
        epsilon: 1.0,
        sigma: 1.0,
    };
    for factors in [
        [0.0, 1.0, 1.0],
        [0.0, 0.5, 0.25],
        [1.0, 1.0, 1.0],
        [0.0, 0.0, 0.0],
    ] {
        let s = chains(factors, fene);
        let (u, f) = direct(&s, factors, fene);
        let ff = ForceField::single(
            LennardJones::new(1.0, 1.0).truncated(RC, CutoffMode::ShiftedEnergy),
        );
        let sim = Simulation::new(s, ff, Thermostat::None, SimParams::default()).unwrap();
        let n = (CHAINS * BEADS) as f64;
        let got = sim.potential_energy();
        println!(
            "special lj {factors:?}: U/N = {:.15} (direct {:.15})",
            got / n,
            u / n
        );
        assert!((got - u).abs() / n < 1e-10, "{factors:?}: {got} vs {u}");
        for (i, fi) in f.iter().enumerate() {
            let g = sim.force(i).0;
            for k in 0..3 {
                assert!(
                    (g[k] - fi[k]).abs() < 1e-9 * (1.0 + fi[k].abs()),
                    "{factors:?} atom {i}"
                );
            }
        }
    }
    // the scaling matters here: lj 0 1 1 removes the bonded pairs' LJ energy
    let (u011, _) = direct(&chains([0.0, 1.0, 1.0], fene), [0.0, 1.0, 1.0], fene);
    let (u111, _) = direct(&chains([1.0; 3], fene), [1.0; 3], fene);
    assert!((u011 - u111).abs() > 1.0);
}

#[test]
fn fire_minimisation_sees_the_scaled_pairs() {
    let fene = BondKind::FeneWca {
        k: 30.0,
        r_max: 1.5,
        epsilon: 1.0,
        sigma: 1.0,
    };
    let factors = [0.0, 1.0, 1.0];
    let mut s = chains(factors, fene);
    let ff =
        ForceField::single(LennardJones::new(1.0, 1.0).truncated(RC, CutoffMode::ShiftedEnergy));
    let rep = minimize_fire(&mut s, &ff, &FireParams::default()).unwrap();
    let (u, _) = direct(&s, factors, fene);
    assert!(
        (rep.energy - u).abs() < 1e-9 * (1.0 + u.abs()),
        "{} vs {u}",
        rep.energy
    );
}
