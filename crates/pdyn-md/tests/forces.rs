//! Forces are minus the gradient of the potential energy (central differences at random
//! configurations, across periodic boundaries, with bonds and two species), neighbour-list
//! forces equal all-pairs forces, and results do not depend on the thread count.

mod common;
use common::*;
use pdyn_md::potential::{CutoffMode, LennardJones, Morse, PairPotential};
use pdyn_md::thermostat::Thermostat;
use pdyn_md::*;

/// 64 particles on a jittered simple-cubic lattice in a box of edge 5, shifted so that many
/// sit near the faces (their interactions cross the boundary).
fn random_system(seed: u64) -> System {
    let mut rng = Rng::new(seed);
    let bx = SimBox::new(5.0, 5.2, 5.4).unwrap();
    let mut p = Particles::new();
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                let mut r = [i as f64 * 1.25, j as f64 * 1.3, k as f64 * 1.35];
                for c in r.iter_mut() {
                    *c += 0.4 * (rng.uniform() - 0.5) - 0.1;
                }
                p.push(Particle {
                    mass: 1.0 + rng.uniform(),
                    pos: Vec3(r),
                    vel: Vec3::ZERO,
                })
                .unwrap();
            }
        }
    }
    let mut s = System::new(p, bx);
    s.set_types((0..64).map(|i| (i % 2) as u32).collect())
        .unwrap();
    // a bond across the x boundary (particle 0 near x = 0, particle 48 near x = L)
    s.add_bond(Bond {
        i: 0,
        j: 48,
        kind: BondKind::Harmonic { k: 5.0, r0: 1.0 },
    })
    .unwrap();
    s.add_bond(Bond {
        i: 1,
        j: 2,
        kind: BondKind::Fene {
            k: 30.0,
            r_max: 1.8,
        },
    })
    .unwrap();
    s
}

fn check_gradient<P: PairPotential + Clone>(ff: ForceField<P>, seed: u64) {
    let params = SimParams {
        skin: 0.1,
        overlap_distance: 0.3,
        ..SimParams::default()
    };
    let sys = random_system(seed);
    let sim = Simulation::new(sys.clone(), ff.clone(), Thermostat::None, params).unwrap();
    let energy = |s: System| {
        Simulation::new(s, ff.clone(), Thermostat::None, params)
            .unwrap()
            .potential_energy()
    };
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for i in [0usize, 1, 2, 17, 48, 63] {
        let f = sim.force(i);
        for k in 0..3 {
            let mut plus = sys.clone();
            let mut minus = sys.clone();
            let mut r = plus.particles.pos(i);
            r.0[k] += h;
            plus.particles.set_pos(i, r);
            r.0[k] -= 2.0 * h;
            minus.particles.set_pos(i, r);
            let g = (energy(plus) - energy(minus)) / (2.0 * h);
            let err = (f.0[k] + g).abs() / (1.0 + g.abs());
            worst = worst.max(err);
        }
    }
    assert!(worst < 1e-6, "worst relative error {worst}");
}

#[test]
fn forces_are_minus_gradient_lj_two_species_with_bonds() {
    let mut ff = ForceField::uniform(
        2,
        LennardJones::new(1.0, 1.0).truncated(2.4, CutoffMode::ShiftedForce),
    )
    .unwrap();
    ff.set(
        0,
        1,
        LennardJones::new(0.7, 0.9).truncated(2.4, CutoffMode::ShiftedForce),
    )
    .unwrap();
    for seed in 1..4 {
        check_gradient(ff.clone(), seed);
    }
}

#[test]
fn forces_are_minus_gradient_morse_shifted_energy() {
    let ff = ForceField::uniform(
        2,
        Morse::new(1.0, 2.0, 1.1).truncated(2.4, CutoffMode::ShiftedEnergy),
    )
    .unwrap();
    check_gradient(ff, 9);
}

#[test]
fn neighbour_list_equals_all_pairs() {
    let mut ff = ForceField::uniform(
        2,
        LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain),
    )
    .unwrap();
    ff.set(
        1,
        1,
        LennardJones::new(0.5, 1.1).truncated(2.2, CutoffMode::Plain),
    )
    .unwrap();
    for seed in 1..4 {
        let mut s = random_system(seed);
        s.bonds.clear();
        // skin 0: the box (edge 5) is exactly twice the cutoff
        let params = SimParams {
            skin: 0.0,
            ..SimParams::default()
        };
        let sim = Simulation::new(s.clone(), ff.clone(), Thermostat::None, params).unwrap();
        let (u, w, f) = all_pairs(&sim.system, &ff);
        assert!((sim.potential_energy() - u).abs() < 1e-10 * u.abs().max(1.0));
        let t = sim.thermo();
        let w_nl = t.pressure * 3.0 * s.sim_box.volume() - 2.0 * t.kinetic;
        assert!((w_nl - w).abs() < 1e-9 * w.abs().max(1.0));
        for (i, fi) in f.iter().enumerate() {
            let d = sim.force(i) - Vec3(*fi);
            assert!(d.norm() < 1e-10 * (1.0 + Vec3(*fi).norm()), "particle {i}");
        }
    }
}

#[test]
fn neighbour_list_survives_many_rebuilds() {
    // after a run with several rebuilds the list-based forces still equal all pairs
    let mut sim = lj_liquid(4, 3, 0.005);
    let rep = sim
        .run(300, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    assert!(rep.builds >= 3, "only {} builds", rep.builds);
    let (u, _, f) = all_pairs(&sim.system, &sim.force_field);
    assert!((sim.potential_energy() - u).abs() < 1e-9 * u.abs());
    for (i, fi) in f.iter().enumerate() {
        assert!((sim.force(i) - Vec3(*fi)).norm() < 1e-9 * (1.0 + Vec3(*fi).norm()));
    }
}

#[test]
fn results_do_not_depend_on_thread_count() {
    let run = |threads: usize| {
        common::on_threads(threads, || {
            let mut sim = lj_liquid(4, 5, 0.005);
            sim.run(100, &mut |_: &ThermoRecord, _: &System| {})
                .unwrap();
            (sim.system.particles.clone(), sim.thermo())
        })
    };
    let (p1, t1) = run(1);
    let (p3, t3) = run(3);
    assert_eq!(p1, p3);
    assert_eq!(t1, t3);
}

#[test]
fn results_do_not_depend_on_thread_count_with_several_segments() {
    // 2,048 atoms: the force loop is cut into two segments, each with its own Newton buffer
    let run = |threads: usize| {
        common::on_threads(threads, || {
            let mut sim = lj_liquid(8, 11, 0.005);
            sim.run(40, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
            (sim.system.particles.clone(), sim.thermo())
        })
    };
    let (p1, t1) = run(1);
    let (p2, t2) = run(2);
    let (p3, t3) = run(3);
    assert_eq!(p1, p2);
    assert_eq!(t1, t2);
    assert_eq!(p1, p3);
    assert_eq!(t1, t3);
}

#[test]
fn neighbour_policy_every_n_steps() {
    // LAMMPS in.lj: `neigh_modify delay 0 every 20 check no` rebuilds at steps 20, 40, ...
    let mut sim = lj_liquid(4, 3, 0.005);
    sim.params.neighbor_every = 20;
    sim.params.neighbor_check = false;
    let rep = sim
        .run(100, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    assert_eq!(rep.builds, 5);
    // every 10 with the exact test: never more builds than considered steps
    let mut sim = lj_liquid(4, 3, 0.005);
    sim.params.neighbor_every = 10;
    let rep = sim
        .run(100, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    assert!(rep.builds <= 10, "{} builds", rep.builds);
}

/// A potential that asks the force loop for batches (as a compiled formula does).
#[derive(Clone)]
struct Batched<P>(P);

impl<P: PairPotential> PairPotential for Batched<P> {
    fn cutoff(&self) -> f64 {
        self.0.cutoff()
    }
    fn energy_force(&self, r2: f64) -> (f64, f64) {
        self.0.energy_force(r2)
    }
    fn prefers_batch(&self) -> bool {
        true
    }
}

#[test]
fn batched_force_loop_gives_the_same_bits() {
    for mode in [CutoffMode::Plain, CutoffMode::ShiftedForce] {
        let lj = LennardJones::new(1.0, 1.0).truncated(2.5, mode);
        let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [8; 3], 1.0, 1 << 24).unwrap();
        maxwell_boltzmann(&mut p, 1.44, 1.0, 4).unwrap();
        let s = System::new(p, bx);
        let mut a = Simulation::new(
            s.clone(),
            ForceField::single(lj),
            Thermostat::None,
            SimParams::default(),
        )
        .unwrap();
        let mut b = Simulation::new(
            s,
            ForceField::single(Batched(lj)),
            Thermostat::None,
            SimParams::default(),
        )
        .unwrap();
        a.run(30, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
        b.run(30, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
        assert_eq!(a.system.particles, b.system.particles, "{mode:?}");
        assert_eq!(a.thermo(), b.thermo(), "{mode:?}");
    }
}
