//! Plots of a run (pdyn-plot): written by `pdyn run --plot`.

use pdyn::sim::{Prepared, RunResult};
use std::path::Path;

/// Writes the run's plots into `dir` (not yet available: pdyn-plot is being built).
pub fn write_run_plots(
    _model: &pdyn_mech::Model,
    _prep: &Prepared,
    _res: &RunResult,
    _dir: &Path,
) -> Result<(), String> {
    Err("plots are not available in this build yet".into())
}

/// Writes the sweep's response plot into `dir` (not yet available).
pub fn write_sweep_plot(
    _model: &pdyn_mech::Model,
    _res: &pdyn::sim::sweep::SweepResult,
    _peaks: &[(String, Vec<(f64, f64)>)],
    _dir: &Path,
) -> Result<(), String> {
    Err("plots are not available in this build yet".into())
}
