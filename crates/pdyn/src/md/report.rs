//! What a molecular-dynamics run prints: the lines before it starts (the system, the
//! minimisation, the thermo table's header), one line per thermo record while it runs, and the
//! report at the end. The front ends print them (the command line live on stderr).

use super::{MdResult, Prepared};
use pdyn_md::ThermoRecord;
use std::path::Path;

/// The lines printed before the run: what is simulated, the minimisation's result, and the
/// header of the live thermo table.
pub fn start_lines(prep: &Prepared) -> Vec<String> {
    let spec = &prep.spec;
    let n = super::build::atoms(prep);
    let mut lines = vec![format!(
        "{}: {n} atoms, {} steps of dt = {}, {}",
        spec.name,
        spec.steps,
        spec.dt.value,
        super::output::ensemble_name(&spec.thermostat.ensemble)
    )];
    if let Some(m) = &prep.minimized {
        lines.push(format!(
            "minimised (FIRE): {} iterations, U = {:.6}, max |F| = {:.3e}{}",
            m.iterations,
            m.energy,
            m.max_force,
            if m.converged { "" } else { " (not converged)" }
        ));
    }
    lines.push(format!(
        "{:>10} {:>12} {:>14} {:>14} {:>14} {:>12}",
        "step", "T", "KE", "PE", "E", "P"
    ));
    lines
}

/// One line of the live thermo table.
pub fn thermo_line(r: &ThermoRecord) -> String {
    format!(
        "{:>10} {:>12.6} {:>14.6} {:>14.6} {:>14.6} {:>12.6}",
        r.step, r.temperature, r.kinetic, r.potential, r.total, r.pressure
    )
}

/// The report at the end of a run (`out`: where the files were written).
pub fn text_report(prep: &Prepared, res: &MdResult, out: Option<&Path>) -> String {
    let n = res.atoms.max(1) as f64;
    let mut s = format!("{}\n", prep.spec.name);
    s += &format!(
        "{} atoms, {} steps ({} neighbour-list builds) in {:.3} s, {:.3e} atom-steps/s\n",
        res.atoms,
        res.steps,
        res.builds,
        res.seconds,
        if res.seconds > 0.0 {
            n * res.steps as f64 / res.seconds
        } else {
            0.0
        }
    );
    if let Some(r) = res.records.last() {
        s += &format!(
            "final: step {}  T = {:.6}  E/N = {:.8}  PE/N = {:.8}  P = {:.6}\n",
            r.step,
            r.temperature,
            r.total / n,
            r.potential / n,
            r.pressure
        );
    }
    let fmt = |name: &str, a: Option<super::run::Average>| match a {
        Some(super::run::Average {
            mean,
            error: Some(e),
            ..
        }) => format!("  {name:<12} {mean:.6} ± {e:.2e}\n"),
        Some(a) => format!("  {name:<12} {:.6}\n", a.mean),
        None => String::new(),
    };
    let avg = fmt("T", res.average(|r| r.temperature))
        + &fmt("P", res.average(|r| r.pressure))
        + &fmt("E/N", res.average(|r| r.total / n));
    if !avg.is_empty() {
        s += "averages (block error bars):\n";
        s += &avg;
    }
    if let Some(d) = &res.drift {
        s += &format!(
            "energy drift: {:.3e} of the mean kinetic energy, slope {:.3e} per atom per time unit\n",
            d.relative, d.slope_per_atom
        );
    }
    if let Some(dir) = out {
        s += &format!("wrote {}/thermo.csv and summary.json", dir.display());
        if res.frames > 0 {
            s += &format!(", traj.xyz ({} frames)", res.frames);
        }
        if res.rdf.is_some() {
            s += ", rdf.csv";
        }
        if !res.msd.is_empty() {
            s += ", msd.csv";
        }
        s += "\n";
    }
    s
}
