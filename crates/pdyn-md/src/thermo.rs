//! Thermodynamic output: `T = 2K/(N_f k_B)`, kinetic `K`, potential `U`, total `K + U`,
//! pressure from the virial `P = (2K + W)/(3V)` with `W = Σ_{pairs, bonds} r·F` (Allen &
//! Tildesley §2.4), and the conserved quantity of the integrator (total energy plus
//! thermostat energy for Nosé–Hoover chains).

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
    /// Instantaneous temperature.
    pub temperature: f64,
    /// Kinetic energy.
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
