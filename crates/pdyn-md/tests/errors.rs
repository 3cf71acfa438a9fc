//! Bad input gives typed errors with context, never a panic or a silent result.

mod common;
use common::*;
use pdyn_md::potential::{CutoffMode, LennardJones};
use pdyn_md::thermostat::*;
use pdyn_md::*;

fn lj() -> ForceField<potential::Truncated<LennardJones>> {
    ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain))
}

#[test]
fn box_shorter_than_twice_cutoff_plus_skin_is_refused() {
    let (p, bx) = lattice(Lattice::Fcc, 0.8442, [3; 3], 1.0, 1000).unwrap(); // L = 5.04 < 5.6
    let e = Simulation::new(
        System::new(p, bx),
        lj(),
        Thermostat::None,
        SimParams::default(),
    )
    .unwrap_err();
    assert!(
        matches!(e, MdError::BoxTooSmall { axis: 0, required, .. } if (required - 5.6).abs() < 1e-12)
    );
}

#[test]
fn overlap_is_reported_with_the_pair_and_fire_resolves_it() {
    let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [4; 3], 1.0, 1000).unwrap();
    let mut r = p.pos(5);
    r.0[0] = p.x[9] + 0.3;
    r.0[1] = p.y[9];
    r.0[2] = p.z[9];
    p.set_pos(5, r);
    let mut sys = System::new(p, bx);
    let e = Simulation::new(sys.clone(), lj(), Thermostat::None, SimParams::default()).unwrap_err();
    match e {
        MdError::Overlap { i, j, distance, .. } => {
            assert_eq!((i, j), (5, 9));
            assert!((distance - 0.3).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    let rep = minimize_fire(&mut sys, &lj(), &FireParams::default()).unwrap();
    println!("{rep:?}");
    assert!(rep.converged);
    maxwell_boltzmann(&mut sys.particles, 1.0, 1.0, 1).unwrap();
    let mut sim = Simulation::new(sys, lj(), Thermostat::None, SimParams::default()).unwrap();
    sim.run(100, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
}

#[test]
fn exploding_time_step_is_detected_within_a_few_steps_and_keeps_partial_results() {
    let mut sim = lj_liquid(5, 4, 0.05);
    sim.params.thermo_every = 1;
    let f = sim
        .run(1000, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap_err();
    println!("{f}");
    match f.error {
        MdError::Unstable {
            step,
            atom,
            neighbor,
            ..
        } => {
            assert!(step <= 50, "detected only at step {step}");
            assert!(atom < 500 && neighbor.is_some());
            assert_eq!(f.partial.records.len() as u64, step); // steps 0..step-1
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn thermostat_without_temperature_is_refused() {
    assert_eq!(
        Langevin::new(LangevinParams::default()).unwrap_err(),
        MdError::MissingTemperature {
            thermostat: "langevin"
        }
    );
    assert!(matches!(
        NoseHooverChain::new(NoseHooverParams {
            temperature: Some(-1.0),
            ..Default::default()
        }),
        Err(MdError::MissingTemperature { .. })
    ));
    assert!(Berendsen::new(BerendsenParams::default()).is_err());
}

#[test]
fn bad_bonds_and_types_are_refused_and_stretched_fene_breaks() {
    let (p, bx) = lattice(Lattice::Sc, 0.5, [5; 3], 1.0, 1000).unwrap();
    let mut sys = System::new(p, bx);
    assert!(matches!(
        sys.add_bond(Bond {
            i: 0,
            j: 500,
            kind: BondKind::Harmonic { k: 1.0, r0: 1.0 }
        }),
        Err(MdError::IndexOutOfRange { index: 500, .. })
    ));
    assert!(sys.set_types(vec![0; 3]).is_err());
    let mut bad_types = sys.clone();
    bad_types.types[3] = 2;
    assert!(matches!(
        Simulation::new(bad_types, lj(), Thermostat::None, SimParams::default()),
        Err(MdError::IndexOutOfRange { what: "type", .. })
    ));
    // sc spacing 1.26 > R0 = 1.2: broken from the start
    sys.add_bond(Bond {
        i: 0,
        j: 1,
        kind: BondKind::Fene {
            k: 30.0,
            r_max: 1.2,
        },
    })
    .unwrap();
    assert!(matches!(
        Simulation::new(sys, lj(), Thermostat::None, SimParams::default()),
        Err(MdError::BondBroken { atoms: [0, 1], .. })
    ));
}

/// A Kremer–Grest bead-spring melt (FENE + WCA) runs stably under Langevin dynamics.
#[test]
fn kremer_grest_chains_run() {
    let (p, bx) = lattice(Lattice::Sc, 0.85, [8; 3], 1.0, 1000).unwrap();
    let mut sys = System::new(p, bx);
    // chains of 8 along z (sc rows are consecutive in index order: k is the fastest index)
    for c in 0..64 {
        for b in 0..7 {
            let i = c * 8 + b;
            sys.add_bond(Bond {
                i,
                j: i + 1,
                kind: BondKind::Fene {
                    k: 30.0,
                    r_max: 1.5,
                },
            })
            .unwrap();
        }
    }
    let wca = LennardJones::new(1.0, 1.0)
        .truncated(libm::pow(2f64, 1.0 / 6.0), CutoffMode::ShiftedEnergy);
    let th = Langevin::new(LangevinParams {
        temperature: Some(1.0),
        ..Default::default()
    })
    .unwrap();
    let params = SimParams {
        dt: 0.005,
        skin: 0.4,
        ..SimParams::default()
    };
    let mut sim = Simulation::new(
        sys,
        ForceField::single(wca),
        Thermostat::Langevin(th),
        params,
    )
    .unwrap();
    let rep = sim
        .run(2000, &mut |_: &ThermoRecord, _: &System| {})
        .unwrap();
    let t = rep.records.last().unwrap().temperature;
    assert!((t - 1.0).abs() < 0.15, "{t}");
}
