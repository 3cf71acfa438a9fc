//! Thermodynamic output: `T = 2K/(N_f k_B)`, kinetic `K`, potential `U`, total `K + U`,
//! pressure from the virial `P = (2K + W)/(3V)` with `W = Σ_{pairs, bonds} r·F` (Allen &
//! Tildesley §2.4), and the conserved quantity of the integrator (total energy plus
//! thermostat energy for Nosé–Hoover chains).
//!
//! `N_f` is `3N − 3` when the dynamics conserves the total momentum (LAMMPS's `compute temp`
//! convention), `3N` under Langevin ([`crate::Simulation::dof`]).
//!
//! Under Langevin (BAOAB) `K` is measured from the half-step velocities, after the O step
//! ([`KineticEstimator::HalfStep`]): the full-step velocities of BAOAB carry an `O(h²)`
//! bias. For a harmonic mode of frequency `ω` the stationary full-step variance is
//! `⟨v²⟩ = (k_B T/m)(1 − h²ω²/4)` while the half-step one is exact for every stable `h`
//! (Leimkuhler & Matthews, Appl. Math. Res. Express 2013, 34, §4; *Molecular Dynamics*,
//! Springer 2015, §7.4.2); the reason is that the O step draws velocities from the exact
//! Maxwell distribution of the half-step state, and the B half-kick that follows it correlates
//! `v` with the force, which lowers `⟨v²⟩` at the full step. In a Lennard-Jones liquid at
//! `h = 0.02 τ` the full-step temperature is 1–2 % low, the half-step one within its
//! statistical error (tested in `tests/nvt.rs`).

use std::fmt;

/// Header line of [`ThermoRecord`]'s CSV rows.
pub const THERMO_CSV_HEADER: &str =
    "step,time,temperature,kinetic,potential,total,pressure,conserved";

/// One line of thermodynamic output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermoRecord {
    /// Step number.
    pub step: u64,
    /// Time (`step · dt`).
    pub time: f64,
    /// Instantaneous temperature `2K/(N_f k_B)` from [`ThermoRecord::kinetic`].
    pub temperature: f64,
    /// The temperature of the full-step velocities (`temperature` except under Langevin; not
    /// in the CSV).
    pub full_step_temperature: f64,
    /// The temperature of the half-step velocities of the last step (after the first
    /// half-kick; under Langevin after the O step, and then equal to `temperature`). Its
    /// difference from `full_step_temperature` is an `O(h²)` measure of the time step's bias
    /// of the thermodynamics; equal to it at step 0. Not in the CSV.
    pub half_step_temperature: f64,
    /// Kinetic energy (of the half-step velocities under Langevin, [`KineticEstimator`]).
    pub kinetic: f64,
    /// Potential energy (pairs and bonds).
    pub potential: f64,
    /// `kinetic + potential`.
    pub total: f64,
    /// Virial pressure.
    pub pressure: f64,
    /// Quantity conserved by the integrator (`total` plus thermostat energy, when defined).
    pub conserved: f64,
}

impl fmt::Display for ThermoRecord {
    /// One CSV row matching [`THERMO_CSV_HEADER`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{},{},{},{},{},{},{},{}",
            self.step,
            self.time,
            self.temperature,
            self.kinetic,
            self.potential,
            self.total,
            self.pressure,
            self.conserved
        )
    }
}

/// Which velocities the kinetic energy and temperature of a [`ThermoRecord`] are measured from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KineticEstimator {
    /// The velocities at the step (velocity Verlet: NVE, Nosé–Hoover, Berendsen).
    FullStep,
    /// BAOAB's velocities halfway through the step, just after the Ornstein–Uhlenbeck (O)
    /// step: free of the `O(h²)` bias of the full-step ones (module docs). At step 0, before
    /// any step, the full-step velocities.
    HalfStep,
}

impl KineticEstimator {
    /// A name for summaries: `full-step` or `half-step`.
    pub fn name(self) -> &'static str {
        match self {
            KineticEstimator::FullStep => "full-step",
            KineticEstimator::HalfStep => "half-step",
        }
    }
}
