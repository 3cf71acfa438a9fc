//! The state of a [`Simulation`] that decides how it continues ([`Snapshot`]), for a
//! checkpoint: restored into a simulation built again from the same model, the next steps are
//! bit for bit those the saved one would have taken.
//!
//! What is saved and why: the particles (positions, velocities, accelerations as the
//! integrator keeps them, image counters), the forces, the step, the last potential energy
//! and virial (a thermo record between energy sums reports them), the reference of the
//! conserved-energy check, the half-step kinetic energy, the thermostat's state (Langevin's
//! noise generator, the Nosé–Hoover chain, every target temperature, which a ramp changes),
//! and the neighbour list as the positions of its last build and its build count: the force
//! sums run in the cluster order of the last build, so the list is made again from those
//! positions ([`NeighborList::restore`]) rather than from the current ones. The box, types,
//! masses, bonds and their special pairs do not change during a run: they come from the
//! model.

use super::Simulation;
use crate::potential::PairPotential;
use crate::thermostat::Thermostat;
use crate::MdError;

/// A thermostat's state (its kind and what changes during a run).
#[derive(Debug, Clone, PartialEq)]
pub enum ThermostatState {
    /// NVE.
    None,
    /// Langevin: the target and the noise generator (xoshiro256** words and the normal
    /// deviate held back by the polar method).
    Langevin {
        /// Target temperature.
        temperature: f64,
        /// The generator's four words.
        rng: [u64; 4],
        /// The deviate held back, if any.
        spare: Option<f64>,
    },
    /// Nosé–Hoover chain: the target, positions `ξₖ` and velocities `vₖ`.
    NoseHooverChain {
        /// Target temperature.
        temperature: f64,
        /// Positions.
        xi: Vec<f64>,
        /// Velocities.
        v: Vec<f64>,
    },
    /// Berendsen: the target.
    Berendsen {
        /// Target temperature.
        temperature: f64,
    },
}

impl ThermostatState {
    /// `none`, `langevin`, `nose-hoover`, `berendsen`.
    pub fn name(&self) -> &'static str {
        match self {
            ThermostatState::None => "none",
            ThermostatState::Langevin { .. } => "langevin",
            ThermostatState::NoseHooverChain { .. } => "nose-hoover",
            ThermostatState::Berendsen { .. } => "berendsen",
        }
    }
}

/// Everything that decides how a [`Simulation`] continues (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Steps taken.
    pub step: u64,
    /// `x`, `y`, `z` of every particle.
    pub positions: [Vec<f64>; 3],
    /// `vx`, `vy`, `vz`.
    pub velocities: [Vec<f64>; 3],
    /// `ax`, `ay`, `az`.
    pub accelerations: [Vec<f64>; 3],
    /// Box lengths removed by wrapping.
    pub images: Vec<[i32; 3]>,
    /// Total force on every particle.
    pub forces: Vec<[f64; 3]>,
    /// The last potential energy summed.
    pub potential: f64,
    /// The last virial summed.
    pub virial: f64,
    /// The conserved quantity at the start of the first run (the energy check's reference).
    pub e0: Option<f64>,
    /// Kinetic energy of the last step's half-step velocities.
    pub half_step_kinetic: Option<f64>,
    /// Positions of the neighbour list's last build.
    pub neighbor_reference: Vec<[f64; 3]>,
    /// Its builds so far.
    pub neighbor_builds: u64,
    /// The thermostat's state.
    pub thermostat: ThermostatState,
}

fn same_len(what: &'static str, expected: usize, found: usize) -> Result<(), MdError> {
    if expected == found {
        Ok(())
    } else {
        Err(MdError::SnapshotMismatch {
            what,
            expected,
            found,
        })
    }
}

impl<P: PairPotential> Simulation<P> {
    /// The state that decides how the run continues ([`Simulation::restore`]).
    pub fn snapshot(&self) -> Snapshot {
        let p = &self.system.particles;
        let thermostat = match &self.thermostat {
            Thermostat::Langevin(l) => {
                let (rng, spare) = l.rng_state();
                ThermostatState::Langevin {
                    temperature: l.temperature,
                    rng,
                    spare,
                }
            }
            Thermostat::NoseHooverChain(c) => {
                let (xi, v) = c.chain();
                ThermostatState::NoseHooverChain {
                    temperature: c.temperature,
                    xi: xi.to_vec(),
                    v: v.to_vec(),
                }
            }
            Thermostat::Berendsen(b) => ThermostatState::Berendsen {
                temperature: b.temperature,
            },
            Thermostat::None => ThermostatState::None,
        };
        Snapshot {
            step: self.step,
            positions: [p.x.clone(), p.y.clone(), p.z.clone()],
            velocities: [p.vx.clone(), p.vy.clone(), p.vz.clone()],
            accelerations: [p.ax.clone(), p.ay.clone(), p.az.clone()],
            images: self.system.images.clone(),
            forces: self.out.clone(),
            potential: self.potential,
            virial: self.virial,
            e0: self.e0,
            half_step_kinetic: self.half_step_kinetic,
            neighbor_reference: self.nl.reference().to_vec(),
            neighbor_builds: self.nl.builds,
            thermostat,
        }
    }

    /// Continues from `snap`, taken of a simulation built from the same model (same
    /// particles, box, force field, thermostat kind and parameters): the next steps are bit
    /// for bit those the saved simulation would have taken. A snapshot of another number of
    /// particles, another thermostat or chain length is refused and leaves `self` unchanged.
    pub fn restore(&mut self, snap: &Snapshot) -> Result<(), MdError> {
        let n = self.system.particles.len();
        for arr in snap
            .positions
            .iter()
            .chain(&snap.velocities)
            .chain(&snap.accelerations)
        {
            same_len("particles", n, arr.len())?;
        }
        same_len("image counters", n, snap.images.len())?;
        same_len("forces", n, snap.forces.len())?;
        same_len("neighbour-list positions", n, snap.neighbor_reference.len())?;
        let kind = |t: &Thermostat| match t {
            Thermostat::Langevin(_) => 1,
            Thermostat::NoseHooverChain(_) => 2,
            Thermostat::Berendsen(_) => 3,
            _ => 0,
        };
        let saved = match &snap.thermostat {
            ThermostatState::None => 0,
            ThermostatState::Langevin { .. } => 1,
            ThermostatState::NoseHooverChain { .. } => 2,
            ThermostatState::Berendsen { .. } => 3,
        };
        same_len(
            "thermostat (0 none, 1 Langevin, 2 Nosé–Hoover, 3 Berendsen)",
            kind(&self.thermostat),
            saved,
        )?;
        if let (Thermostat::NoseHooverChain(c), ThermostatState::NoseHooverChain { xi, v, .. }) =
            (&self.thermostat, &snap.thermostat)
        {
            same_len("Nosé–Hoover chain length", c.chain().0.len(), xi.len())?;
            same_len("Nosé–Hoover chain length", c.chain().1.len(), v.len())?;
        }
        // checked: nothing below fails
        match (&mut self.thermostat, &snap.thermostat) {
            (
                Thermostat::Langevin(l),
                ThermostatState::Langevin {
                    temperature,
                    rng,
                    spare,
                },
            ) => {
                l.temperature = *temperature;
                l.set_rng_state(*rng, *spare);
            }
            (
                Thermostat::NoseHooverChain(c),
                ThermostatState::NoseHooverChain { temperature, xi, v },
            ) => {
                c.temperature = *temperature;
                c.set_chain(xi, v)?;
            }
            (Thermostat::Berendsen(b), ThermostatState::Berendsen { temperature }) => {
                b.temperature = *temperature;
            }
            _ => {}
        }
        let p = &mut self.system.particles;
        let [x, y, z] = &snap.positions;
        p.x.copy_from_slice(x);
        p.y.copy_from_slice(y);
        p.z.copy_from_slice(z);
        let [vx, vy, vz] = &snap.velocities;
        p.vx.copy_from_slice(vx);
        p.vy.copy_from_slice(vy);
        p.vz.copy_from_slice(vz);
        let [ax, ay, az] = &snap.accelerations;
        p.ax.copy_from_slice(ax);
        p.ay.copy_from_slice(ay);
        p.az.copy_from_slice(az);
        self.system.images.copy_from_slice(&snap.images);
        self.out.copy_from_slice(&snap.forces);
        self.step = snap.step;
        self.potential = snap.potential;
        self.virial = snap.virial;
        self.e0 = snap.e0;
        self.half_step_kinetic = snap.half_step_kinetic;
        self.nl.restore(
            &snap.neighbor_reference,
            snap.neighbor_builds,
            &self.system.particles,
            &self.system.sim_box,
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::potential::{CutoffMode, LennardJones};
    use crate::thermostat::{
        Berendsen, BerendsenParams, Langevin, LangevinNoise, LangevinParams, LangevinScheme,
        NoseHooverChain, NoseHooverParams, Thermostat,
    };
    use crate::{
        lattice, maxwell_boltzmann, ForceField, Lattice, SimParams, Simulation, System,
        ThermoRecord,
    };

    type Lj = crate::potential::Truncated<LennardJones>;

    /// 256 LJ atoms (fcc, ρ = 0.8442, T = 1.44: the liquid of LAMMPS's `bench/in.lj`) with
    /// `thermostat`, neighbour list checked every step (rebuilds at irregular steps).
    fn liquid(thermostat: Thermostat) -> Simulation<Lj> {
        let (mut p, bx) = lattice(Lattice::Fcc, 0.8442, [4; 3], 1.0, 1000).unwrap();
        maxwell_boltzmann(&mut p, 1.44, 1.0, 87287).unwrap();
        let ff = ForceField::single(LennardJones::new(1.0, 1.0).truncated(2.5, CutoffMode::Plain));
        let params = SimParams {
            thermo_every: 7,
            ..SimParams::default()
        };
        Simulation::new(System::new(p, bx), ff, thermostat, params).unwrap()
    }

    fn thermostats() -> Vec<(&'static str, Thermostat)> {
        vec![
            ("nve", Thermostat::None),
            (
                "langevin",
                Thermostat::Langevin(
                    Langevin::new(LangevinParams {
                        temperature: Some(1.2),
                        damping: 0.5,
                        seed: 11,
                    })
                    .unwrap(),
                ),
            ),
            (
                "nose-hoover",
                Thermostat::NoseHooverChain(
                    NoseHooverChain::new(NoseHooverParams {
                        temperature: Some(1.2),
                        tau: 0.2,
                        chain: 3,
                    })
                    .unwrap(),
                ),
            ),
            (
                "berendsen",
                Thermostat::Berendsen(
                    Berendsen::new(BerendsenParams {
                        temperature: Some(1.2),
                        tau: 0.1,
                    })
                    .unwrap(),
                ),
            ),
            (
                "langevin, LAMMPS scheme",
                Thermostat::Langevin(
                    Langevin::new(LangevinParams {
                        temperature: Some(1.2),
                        damping: 0.5,
                        seed: 11,
                    })
                    .unwrap()
                    .with_scheme(LangevinScheme::Lammps {
                        noise: LangevinNoise::Uniform,
                    }),
                ),
            ),
        ]
    }

    /// Every record's numbers as bits, and the final positions and velocities.
    fn trace(sim: &mut Simulation<Lj>, steps: u64) -> (Vec<Vec<u64>>, Vec<u64>) {
        let mut recs: Vec<ThermoRecord> = vec![];
        sim.run(steps, &mut |r: &ThermoRecord, _: &System| recs.push(*r))
            .unwrap();
        let rows = recs
            .iter()
            .map(|r| {
                [
                    r.step as f64,
                    r.temperature,
                    r.kinetic,
                    r.potential,
                    r.pressure,
                    r.conserved,
                ]
                .map(f64::to_bits)
                .to_vec()
            })
            .collect();
        let p = &sim.system.particles;
        let state = [&p.x, &p.y, &p.z, &p.vx, &p.vy, &p.vz]
            .iter()
            .flat_map(|a| a.iter().map(|v| v.to_bits()))
            .collect();
        (rows, state)
    }

    /// For each thermostat: run 93 steps, snapshot, and continue 150 steps two ways: the same
    /// simulation on, and a simulation built afresh from the model (its noise generator, chain
    /// and neighbour list at their start) restored from the snapshot. The records and final
    /// states agree bit for bit; and without the restore they do not (the check can fail).
    #[test]
    fn snapshot_then_restore_continues_bit_for_bit_for_every_thermostat() {
        for ((name, t), (_, t_fresh)) in thermostats().into_iter().zip(thermostats()) {
            let mut a = liquid(t);
            a.run(93, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
            let snap = a.snapshot();
            let mut b = liquid(t_fresh.clone());
            b.restore(&snap).unwrap();
            assert_eq!(b.snapshot(), snap, "{name}: restore then snapshot");
            let mut unrestored = liquid(t_fresh);
            let ta = trace(&mut a, 150);
            let tb = trace(&mut b, 150);
            assert!(
                ta == tb,
                "{name}: the restored run differs from the uninterrupted one"
            );
            assert!(
                trace(&mut unrestored, 150) != ta,
                "{name}: the check cannot tell"
            );
        }
    }

    /// Each part of the state matters: restoring all of it but the noise generator (Langevin),
    /// the chain (Nosé–Hoover) or the neighbour list's reference (NVE) changes the bits.
    #[test]
    fn each_part_of_the_snapshot_is_needed() {
        let mut cases = thermostats();
        cases.truncate(3);
        for (name, t) in cases {
            let mut a = liquid(t.clone());
            a.run(93, &mut |_: &ThermoRecord, _: &System| {}).unwrap();
            let snap = a.snapshot();
            let mut partial = snap.clone();
            match &mut partial.thermostat {
                super::ThermostatState::Langevin { rng, spare, .. } => {
                    *rng = crate::Rng::new(11).state().0;
                    *spare = None;
                }
                super::ThermostatState::NoseHooverChain { xi, v, .. } => {
                    xi.iter_mut().for_each(|x| *x = 0.0);
                    v.iter_mut().for_each(|x| *x = 0.0);
                }
                _ => {
                    // the list of the initial lattice: same particles, other cluster order
                    partial.neighbor_reference =
                        liquid(Thermostat::None).snapshot().neighbor_reference;
                }
            }
            let mut b = liquid(t);
            b.restore(&partial).unwrap();
            let ta = trace(&mut a, 150);
            assert!(
                trace(&mut b, 150) != ta,
                "{name}: a partial restore went unnoticed"
            );
        }
    }

    #[test]
    fn a_snapshot_of_another_system_is_refused() {
        let a = liquid(Thermostat::None);
        let mut snap = a.snapshot();
        snap.positions[0].pop();
        let mut b = liquid(Thermostat::None);
        assert!(matches!(
            b.restore(&snap),
            Err(crate::MdError::SnapshotMismatch { .. })
        ));
        let lv = liquid(thermostats().remove(1).1).snapshot();
        assert!(b.restore(&lv).is_err());
    }
}
