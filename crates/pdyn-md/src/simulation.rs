//! [`System`] (particles, types, box, bonds) and [`Simulation`] (system, force field,
//! neighbour list, thermostat, velocity-Verlet stepping with failure detection).
//!
//! Velocity Verlet (Swope, Andersen, Berens & Wilson, J. Chem. Phys. 76, 637 (1982)):
//! `v ← v + (h/2) a; x ← x + h v; a ← F(x)/m; v ← v + (h/2) a`. Second order, symplectic and
//! time-reversible for NVE, so the energy error stays bounded (`O(h²)` fluctuations, no drift).
//!
//! Failure detection, every step: a non-finite state, a particle that moves more than
//! `SimParams::max_displacement` in one step, or (for NVE and Nosé–Hoover, whose conserved
//! quantity is known) a change of that quantity per particle beyond
//! `SimParams::max_energy_change` stops the run with `MdError::Unstable`, the step and the
//! offending particle; the records so far are returned in `RunFailure::partial`.

use crate::bonds::Bond;
use crate::forces::ForceScratch;
use crate::potential::PairPotential;
use crate::special::SpecialPairs;
use crate::thermostat::Thermostat;
use crate::{
    ForceField, KineticEstimator, MdError, NeighborList, RunFailure, SimBox, ThermoRecord,
};
use pdyn_particles::{Particles, Vec3};
use std::sync::atomic::Ordering;

mod snapshot;
pub use snapshot::{Snapshot, ThermostatState};

/// Particles in a periodic box, with types and bonds.
#[derive(Debug, Clone)]
pub struct System {
    /// Positions (wrapped into the box at every neighbour-list build), velocities, masses.
    pub particles: Particles,
    /// Type of each particle (index into the force field's table).
    pub types: Vec<u32>,
    /// Periodic box.
    pub sim_box: SimBox,
    /// Box lengths removed by wrapping: unwrapped `r = x + image·L`.
    pub images: Vec<[i32; 3]>,
    /// Bonds.
    pub bonds: Vec<Bond>,
    /// Factors of the pair interaction between 1-2, 1-3 and 1-4 bonded neighbours (LAMMPS
    /// `special_bonds lj`; default [`crate::special::NO_SCALING`], every pair in full).
    pub special_lj: [f64; 3],
}

impl System {
    /// Particles of type 0 in `sim_box`, no bonds.
    pub fn new(particles: Particles, sim_box: SimBox) -> Self {
        let n = particles.len();
        System {
            particles,
            types: vec![0; n],
            sim_box,
            images: vec![[0; 3]; n],
            bonds: vec![],
            special_lj: crate::special::NO_SCALING,
        }
    }

    /// Sets the type of every particle (lengths must match).
    pub fn set_types(&mut self, types: Vec<u32>) -> Result<(), MdError> {
        if types.len() != self.particles.len() {
            return Err(MdError::IndexOutOfRange {
                what: "types length",
                index: types.len(),
                len: self.particles.len(),
            });
        }
        self.types = types;
        Ok(())
    }

    /// Adds a bond between existing particles `i ≠ j`.
    pub fn add_bond(&mut self, bond: Bond) -> Result<(), MdError> {
        let n = self.particles.len();
        for idx in [bond.i, bond.j] {
            if idx >= n {
                return Err(MdError::IndexOutOfRange {
                    what: "bond particle",
                    index: idx,
                    len: n,
                });
            }
        }
        if bond.i == bond.j {
            return Err(MdError::IndexOutOfRange {
                what: "bond to itself",
                index: bond.i,
                len: n,
            });
        }
        self.bonds.push(bond);
        Ok(())
    }

    /// Unwrapped position of particle `i` (continuous across boundaries).
    pub fn unwrapped(&self, i: usize) -> Vec3 {
        let l = self.sim_box.l;
        let m = self.images[i];
        let p = &self.particles;
        Vec3::new(
            p.x[i] + m[0] as f64 * l[0],
            p.y[i] + m[1] as f64 * l[1],
            p.z[i] + m[2] as f64 * l[2],
        )
    }

    /// Number density `N/V`.
    pub fn density(&self) -> f64 {
        self.particles.len() as f64 / self.sim_box.volume()
    }
}

/// Run parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimParams {
    /// Time step (default 0.005 τ, LAMMPS `bench/in.lj`).
    pub dt: f64,
    /// Neighbour-list skin δ (default 0.3 σ).
    pub skin: f64,
    /// Thermodynamic output every this many steps (default 100; 0 = only at the end).
    pub thermo_every: u64,
    /// Boltzmann constant (default 1: reduced LJ units).
    pub boltzmann: f64,
    /// Pairs closer than this at the start are refused as overlapping (default 0.7 σ, where
    /// LJ's pair energy exceeds 250 ε).
    pub overlap_distance: f64,
    /// Largest displacement of a particle in one step before the run is declared unstable
    /// (default 0.5 σ).
    pub max_displacement: f64,
    /// Largest change of the conserved quantity per particle since the start of the run
    /// (NVE, Nosé–Hoover) before the run is declared unstable (default 1.0 ε).
    pub max_energy_change: f64,
    /// The neighbour list is considered every this many steps (LAMMPS `neigh_modify every`;
    /// default 1, 0 counts as 1).
    pub neighbor_every: u64,
    /// `true` (default): at a considered step, rebuild only if the exact displacement test
    /// ([`NeighborList::needs_rebuild`]) asks for it. `false`: rebuild unconditionally at every
    /// considered step (LAMMPS `check no`, as in `bench/in.lj` with `every 20`), which skips
    /// the test but lets pairs that come within the cutoff between builds go unseen. The list
    /// is exact only with `neighbor_every = 1` and `neighbor_check = true`.
    pub neighbor_check: bool,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            dt: 0.005,
            skin: 0.3,
            thermo_every: 100,
            boltzmann: 1.0,
            overlap_distance: 0.7,
            max_displacement: 0.5,
            max_energy_change: 1.0,
            neighbor_every: 1,
            neighbor_check: true,
        }
    }
}

/// Thermodynamic records and counters of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunReport {
    /// One record every `thermo_every` steps (and at step 0 of the first run).
    pub records: Vec<ThermoRecord>,
    /// Neighbour-list builds during the run.
    pub builds: u64,
    /// Steps completed.
    pub steps: u64,
}

/// Receives thermodynamic records (and the system) during a run.
pub trait Observer {
    /// Called at every thermo output.
    fn observe(&mut self, record: &ThermoRecord, system: &System);
}

impl<F: FnMut(&ThermoRecord, &System)> Observer for F {
    fn observe(&mut self, record: &ThermoRecord, system: &System) {
        self(record, system)
    }
}

/// A molecular-dynamics run in progress.
#[derive(Debug, Clone)]
pub struct Simulation<P> {
    /// The particles, box, types and bonds.
    pub system: System,
    /// Pair potentials.
    pub force_field: ForceField<P>,
    /// Thermostat (or `Thermostat::None`).
    pub thermostat: Thermostat,
    /// Parameters.
    pub params: SimParams,
    nl: NeighborList,
    /// Pairs scaled by `system.special_lj`, from the bonds at construction.
    special: SpecialPairs,
    scratch: ForceScratch,
    /// Total force on every particle (pair + bond), particle order.
    out: Vec<[f64; 3]>,
    /// Steps taken so far.
    pub step: u64,
    potential: f64,
    virial: f64,
    e0: Option<f64>,
    /// Kinetic energy of the half-step velocities of the last step: after the first half-kick
    /// (velocity Verlet), after the O step (Langevin BAOAB, [`KineticEstimator::HalfStep`]);
    /// `None` before the first step.
    half_step_kinetic: Option<f64>,
}

/// Steps between two checks of the conserved energy (NVE, Nosé–Hoover) during a run. The
/// potential energy and the virial are summed only at these steps, at thermo steps and at the
/// last step of [`Simulation::run`] (as LAMMPS computes energies only when output needs
/// them): the sums cost about a fifth of the pair kernel, and the forces, hence the
/// trajectory, are the same bits either way. Non-finite states and jumps are still checked at
/// every step.
pub const ENERGY_CHECK_EVERY: u64 = 10;

impl<P: PairPotential> Simulation<P> {
    /// Checks the set-up (box against cutoff + skin, types, bonds, overlaps) and computes the
    /// initial forces.
    pub fn new(
        system: System,
        force_field: ForceField<P>,
        thermostat: Thermostat,
        params: SimParams,
    ) -> Result<Self, MdError> {
        for (name, v) in [
            ("dt", params.dt),
            ("boltzmann", params.boltzmann),
            ("max_displacement", params.max_displacement),
            ("max_energy_change", params.max_energy_change),
        ] {
            crate::thermostat::positive(name, v)?;
        }
        let nl = NeighborList::new(force_field.max_cutoff(), params.skin)?;
        nl.check_box(&system.sim_box)?;
        let nt = force_field.ntypes();
        if let Some((i, &t)) = system
            .types
            .iter()
            .enumerate()
            .find(|(_, &t)| t as usize >= nt)
        {
            let _ = i;
            return Err(MdError::IndexOutOfRange {
                what: "type",
                index: t as usize,
                len: nt,
            });
        }
        let n = system.particles.len();
        let special = SpecialPairs::from_bonds(n, &system.bonds, system.special_lj)?;
        let mut sim = Simulation {
            system,
            force_field,
            thermostat,
            params,
            nl,
            special,
            scratch: ForceScratch::default(),
            out: vec![[0.0; 3]; n],
            step: 0,
            potential: 0.0,
            virial: 0.0,
            e0: None,
            half_step_kinetic: None,
        };
        sim.rebuild();
        sim.check_overlap()?;
        if let Thermostat::Langevin(l) = &mut sim.thermostat {
            // LAMMPS's fix langevin adds its forces at set-up too, from v(0)
            l.draw_post_force(&sim.system.particles, params.dt, params.boltzmann);
        }
        sim.forces(true).map_err(|e| e.with_step(0))?;
        Ok(sim)
    }

    fn rebuild(&mut self) {
        let s = &mut self.system;
        self.nl.build(&mut s.particles, &mut s.images, &s.sim_box);
    }

    fn check_overlap(&self) -> Result<(), MdError> {
        let d2 = self.params.overlap_distance.powi(2);
        // of the pairs below the threshold, the first in particle order (i < j), whatever the
        // list's internal order
        let mut worst: Option<(usize, usize, f64)> = None;
        self.nl.for_each_pair(d2, |a, b, r2| {
            let pair = (a.min(b), a.max(b), r2);
            if worst.is_none_or(|w| pair < w) {
                worst = Some(pair);
            }
        });
        match worst {
            Some((i, j, r2)) => Err(MdError::Overlap {
                i,
                j,
                distance: r2.sqrt(),
                threshold: self.params.overlap_distance,
            }),
            None => Ok(()),
        }
    }

    /// Pair and bond forces into accelerations (plus the friction and noise of the last draw
    /// under Langevin's LAMMPS scheme); potential energy and virial when `energy` (else the
    /// two keep their last values, see [`ENERGY_CHECK_EVERY`]).
    fn forces(&mut self, energy: bool) -> Result<(), MdError> {
        let s = &mut self.system;
        let (u_p, w_p) =
            self.force_field
                .compute(&self.nl, &s.types, &mut self.scratch, &mut self.out, energy);
        let (u_s, w_s) = self.special.correct(s, &self.force_field, &mut self.out);
        let (u_b, w_b) = bond_forces(s, &mut self.out, energy)?;
        let p = &mut s.particles;
        let langevin = match &self.thermostat {
            Thermostat::Langevin(l) => l.post_force(),
            _ => None,
        };
        if let Some(extra) = langevin {
            // LAMMPS: f += γ₁ v + f_ran, then v += (h/2) f/m
            for (i, (f, e)) in self.out.iter().zip(extra).enumerate() {
                let inv_m = if p.m[i] > 0.0 { 1.0 / p.m[i] } else { 0.0 };
                p.ax[i] = (f[0] + e[0]) * inv_m;
                p.ay[i] = (f[1] + e[1]) * inv_m;
                p.az[i] = (f[2] + e[2]) * inv_m;
            }
        } else {
            for (i, f) in self.out.iter().enumerate() {
                let inv_m = if p.m[i] > 0.0 { 1.0 / p.m[i] } else { 0.0 };
                p.ax[i] = f[0] * inv_m;
                p.ay[i] = f[1] * inv_m;
                p.az[i] = f[2] * inv_m;
            }
        }
        if energy {
            self.potential = u_p + u_s + u_b;
            self.virial = w_p + w_s + w_b;
        }
        Ok(())
    }

    /// Degrees of freedom `N_f` of the temperature `T = 2K/(N_f k_B)`: `3N − 3` when the
    /// dynamics conserves the total momentum (NVE, Nosé–Hoover, Berendsen: LAMMPS's
    /// `compute temp`), `3N` under Langevin, whose random forces do not conserve it. There
    /// are no constraints in pdyn-md, so nothing else is subtracted.
    pub fn dof(&self) -> f64 {
        let n = self.system.particles.len();
        if self.conserves_momentum() {
            (3 * n).saturating_sub(3) as f64
        } else {
            (3 * n) as f64
        }
    }

    /// Whether the dynamics conserves the total momentum (every thermostat but Langevin).
    pub fn conserves_momentum(&self) -> bool {
        !matches!(self.thermostat, Thermostat::Langevin(_))
    }

    /// Which velocities the reported kinetic energy and temperature come from.
    /// (Langevin's LAMMPS scheme reports the full-step velocities, as LAMMPS does.)
    pub fn kinetic_estimator(&self) -> KineticEstimator {
        match &self.thermostat {
            Thermostat::Langevin(l) if l.is_baoab() => KineticEstimator::HalfStep,
            _ => KineticEstimator::FullStep,
        }
    }

    /// Potential energy at the current positions.
    pub fn potential_energy(&self) -> f64 {
        self.potential
    }

    /// The neighbour list (cluster and cluster-pair counts, builds: diagnostics).
    pub fn neighbor_list(&self) -> &NeighborList {
        &self.nl
    }

    /// Number of distinct pairs currently inside their cutoff (a diagnostic, `O(N)` work).
    pub fn pairs_within_cutoff(&self) -> usize {
        let rc2 = self.force_field.max_cutoff().powi(2);
        let mut count = 0;
        self.nl.for_each_pair(rc2, |_, _, _| count += 1);
        count
    }

    /// Forces `mᵢ aᵢ` of particle `i` at the current positions.
    pub fn force(&self, i: usize) -> Vec3 {
        Vec3(self.out[i])
    }

    /// Thermodynamic state now.
    pub fn thermo(&self) -> ThermoRecord {
        let p = &self.system.particles;
        let k_full = p.kinetic_energy();
        let k = match self.kinetic_estimator() {
            KineticEstimator::HalfStep => self.half_step_kinetic.unwrap_or(k_full),
            KineticEstimator::FullStep => k_full,
        };
        let nf = self.dof();
        let kb = self.params.boltzmann;
        let temperature = |k: f64| if nf > 0.0 { 2.0 * k / (nf * kb) } else { 0.0 };
        let total = k + self.potential;
        let extra = match &self.thermostat {
            Thermostat::NoseHooverChain(c) => c.energy(nf, kb),
            _ => 0.0,
        };
        ThermoRecord {
            step: self.step,
            time: self.step as f64 * self.params.dt,
            temperature: temperature(k),
            full_step_temperature: temperature(k_full),
            half_step_temperature: temperature(self.half_step_kinetic.unwrap_or(k_full)),
            kinetic: k,
            potential: self.potential,
            total,
            pressure: (2.0 * k + self.virial) / (3.0 * self.system.sim_box.volume()),
            conserved: total + extra,
        }
    }

    /// Runs `steps` steps, reporting to `observer` every `params.thermo_every` steps (and at
    /// the start of the first run). On failure the state is left as it was when detected.
    pub fn run(
        &mut self,
        steps: u64,
        observer: &mut dyn Observer,
    ) -> Result<RunReport, RunFailure> {
        self.run_interruptible(steps, observer, None)
    }

    /// [`Simulation::run`], stopping early once `stop` is set (checked after every step, so
    /// within one step's work of the request; the steps taken are the same bits as without
    /// it). `RunReport::steps` says how many steps were taken; the energy and virial are
    /// those of the last step taken.
    pub fn run_interruptible(
        &mut self,
        steps: u64,
        observer: &mut dyn Observer,
        stop: Option<&std::sync::atomic::AtomicBool>,
    ) -> Result<RunReport, RunFailure> {
        let mut report = RunReport::default();
        let builds0 = self.nl.builds;
        let every = self.params.thermo_every;
        if self.step == 0 {
            let r = self.thermo();
            observer.observe(&r, &self.system);
            report.records.push(r);
        }
        let checks_energy = matches!(
            self.thermostat,
            Thermostat::None | Thermostat::NoseHooverChain(_)
        );
        if self.e0.is_none() {
            self.e0 = Some(self.thermo().conserved);
        }
        let last = self.step + steps;
        for _ in 0..steps {
            let next = self.step + 1;
            let energy = next == last
                || (every > 0 && next % every == 0)
                || (checks_energy && next % ENERGY_CHECK_EVERY == 0);
            if let Err(error) = self.one_step(checks_energy && energy, energy) {
                report.builds = self.nl.builds - builds0;
                return Err(RunFailure {
                    error,
                    partial: report,
                });
            }
            report.steps += 1;
            if every > 0 && self.step % every == 0 {
                let r = self.thermo();
                observer.observe(&r, &self.system);
                report.records.push(r);
            }
            if self.step < last && stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
                if !energy {
                    // the sums of the stopping step, from the same positions and list: the
                    // forces come out the same bits
                    if let Err(error) = self.forces(true) {
                        report.builds = self.nl.builds - builds0;
                        return Err(RunFailure {
                            error: error.with_step(self.step),
                            partial: report,
                        });
                    }
                }
                break;
            }
        }
        if every == 0 {
            let r = self.thermo();
            observer.observe(&r, &self.system);
            report.records.push(r);
        }
        report.builds = self.nl.builds - builds0;
        Ok(report)
    }

    fn one_step(&mut self, checks_energy: bool, energy: bool) -> Result<(), MdError> {
        let h = self.params.dt;
        let kb = self.params.boltzmann;
        let nf = self.dof();
        self.step += 1;
        let step = self.step;
        if let Thermostat::NoseHooverChain(c) = &mut self.thermostat {
            let ke = self.system.particles.kinetic_energy();
            c.half_step(&mut self.system.particles, h, ke, nf, kb);
        }
        let p = &mut self.system.particles;
        p.kick(0.5 * h);
        // largest displacement of this step, |v| h
        // and the kinetic energy of the half-step velocities
        let (mut vmax2, mut imax, mut mv2) = (0.0, 0, 0.0);
        for i in 0..p.len() {
            let v2 = p.vx[i] * p.vx[i] + p.vy[i] * p.vy[i] + p.vz[i] * p.vz[i];
            mv2 += p.m[i] * v2;
            if v2 > vmax2 || v2.is_nan() {
                vmax2 = v2;
                imax = i;
            }
        }
        self.half_step_kinetic = Some(0.5 * mv2);
        let disp = vmax2.sqrt() * h;
        if !within(disp, self.params.max_displacement) {
            return Err(self.unstable(step, imax, disp));
        }
        if let Thermostat::Langevin(l) = &mut self.thermostat {
            if l.is_baoab() {
                p.drift(0.5 * h);
                l.ou_step(p, h, kb);
                self.half_step_kinetic = Some(p.kinetic_energy());
                p.drift(0.5 * h);
            } else {
                p.drift(h);
            }
        } else {
            p.drift(h);
        }
        let considered = step % self.params.neighbor_every.max(1) == 0;
        if considered
            && (!self.params.neighbor_check || self.nl.needs_rebuild(&self.system.particles))
        {
            self.rebuild();
        } else {
            self.nl.update_positions(&self.system.particles);
        }
        if let Thermostat::Langevin(l) = &mut self.thermostat {
            // LAMMPS post_force: from the half-step velocities
            l.draw_post_force(&self.system.particles, h, kb);
        }
        self.forces(energy).map_err(|e| e.with_step(step))?;
        let p = &mut self.system.particles;
        p.kick(0.5 * h);
        match &mut self.thermostat {
            Thermostat::NoseHooverChain(c) => {
                let ke = p.kinetic_energy();
                c.half_step(p, h, ke, nf, kb);
            }
            Thermostat::Berendsen(b) => {
                let t = 2.0 * p.kinetic_energy() / (nf * kb);
                b.rescale(p, h, t);
            }
            _ => {}
        }
        if checks_energy || (energy && !self.potential.is_finite()) {
            let e = self.thermo().conserved;
            let de = (e - self.e0.unwrap_or(e)).abs() / self.system.particles.len().max(1) as f64;
            if !within(de, self.params.max_energy_change) {
                let p = &self.system.particles;
                let atom = p.first_non_finite().unwrap_or_else(|| {
                    (0..p.len())
                        .max_by(|&a, &b| p.acc(a).norm2().total_cmp(&p.acc(b).norm2()))
                        .unwrap_or(0)
                });
                let mut err = self.unstable(step, atom, disp);
                if let MdError::Unstable {
                    energy_change_per_atom,
                    ..
                } = &mut err
                {
                    *energy_change_per_atom = de;
                }
                return Err(err);
            }
        }
        Ok(())
    }

    fn unstable(&self, step: u64, atom: usize, displacement: f64) -> MdError {
        let p = &self.system.particles;
        let bx = &self.system.sim_box;
        let neighbor = (0..p.len())
            .filter(|&j| j != atom)
            .map(|j| (j, bx.delta(p.pos(atom), p.pos(j)).norm2()))
            .filter(|(_, d)| d.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(j, _)| j);
        let e = self.thermo().conserved;
        MdError::Unstable {
            step,
            atom,
            neighbor,
            displacement,
            energy_change_per_atom: (e - self.e0.unwrap_or(e)).abs() / p.len().max(1) as f64,
        }
    }
}

impl MdError {
    fn with_step(mut self, s: u64) -> Self {
        if let MdError::BondBroken { step, .. } = &mut self {
            *step = s;
        }
        self
    }
}

/// Adds bond forces to `out` (in bond order); returns bond energy and virial when `energy`
/// (else anything: the forces are the same bits either way).
pub(crate) fn bond_forces(
    s: &System,
    out: &mut [[f64; 3]],
    energy: bool,
) -> Result<(f64, f64), MdError> {
    let (mut u, mut w) = (0.0, 0.0);
    let p = &s.particles;
    for (b, bond) in s.bonds.iter().enumerate() {
        let d = s.sim_box.delta(p.pos(bond.i), p.pos(bond.j)).0;
        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let evaluated = if energy {
            bond.kind.energy_force(r2)
        } else {
            bond.kind.force(r2).map(|fr| (0.0, fr))
        };
        let Some((e, fr)) = evaluated else {
            let max = match bond.kind {
                crate::BondKind::Fene { r_max, .. } | crate::BondKind::FeneWca { r_max, .. } => {
                    r_max
                }
                _ => f64::INFINITY,
            };
            return Err(MdError::BondBroken {
                step: 0,
                bond: b,
                atoms: [bond.i, bond.j],
                length: r2.sqrt(),
                max,
            });
        };
        for (k, dk) in d.iter().enumerate() {
            out[bond.i][k] += fr * dk;
            out[bond.j][k] -= fr * dk;
        }
        u += e;
        w += fr * r2;
    }
    Ok((u, w))
}

/// `x ≤ limit`, false for NaN.
fn within(x: f64, limit: f64) -> bool {
    x <= limit
}
