//! `pdyn modes MODEL`: natural frequencies and mode shapes of the model linearized about its
//! static equilibrium (or its initial state), `K φ = ω² M φ`, dense.

use super::{load_model, set_parameters};
use clap::{Args, ValueEnum};
use pdyn::output::json_num;
use pdyn::Error;
use pdyn_mech::equilibrium::{solve, EquilibriumOptions};
use pdyn_mech::modes::modes;
use pdyn_mech::statics::{linearize, StaticsError};
use serde_json::json;
use std::fmt::Write;
use std::path::PathBuf;

/// The state to linearize about.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum About {
    /// The static equilibrium nearest the initial values (`pdyn equilibrium`).
    Equilibrium,
    /// The initial values, at rest (whatever forces are out of balance there).
    Initial,
}

/// `pdyn modes`.
#[derive(Args, Debug)]
pub struct ModesArgs {
    /// The model file (TOML), e.g. examples/chain_modes.toml.
    model: PathBuf,
    /// Override parameter values, e.g. `--set k=500,m=0.1`.
    #[arg(long, value_delimiter = ',')]
    set: Vec<String>,
    /// The state to linearize about.
    #[arg(long, value_enum, default_value_t = About::Equilibrium)]
    about: About,
    /// Print the lowest COUNT modes only (all by default).
    #[arg(long)]
    count: Option<usize>,
    /// Print each mode's shape (always in --json).
    #[arg(long)]
    shapes: bool,
    /// Machine-readable output (frequencies and shapes).
    #[arg(long)]
    json: bool,
}

/// `pdyn modes MODEL`.
pub fn run(a: ModesArgs) -> Result<String, Error> {
    let mut model = load_model(&a.model)?;
    set_parameters(&mut model, &a.set)?;
    let origin = model.origin.clone();
    let fail = |error: StaticsError| Error::Statics {
        origin: origin.clone(),
        error,
    };
    let (_, lin) = linearize(&mut model).map_err(fail)?;
    let (state, about, residual) = match a.about {
        About::Equilibrium => {
            let eq =
                solve(&lin, None, &EquilibriumOptions::default()).map_err(|e| fail(e.into()))?;
            (eq.linearization, "static equilibrium", eq.residual)
        }
        About::Initial => {
            let at = lin.at(&lin.initial);
            let r = at.force.norm();
            (at, "initial state (at rest)", r)
        }
    };
    let result = modes(&state).map_err(|e| fail(e.into()))?;
    let count = a
        .count
        .unwrap_or(result.modes.len())
        .min(result.modes.len());
    let shown = &result.modes[..count];
    let tau = std::f64::consts::TAU;
    if a.json {
        let v = json!({
            "model": model.name,
            "about": about,
            "out_of_balance_force": json_num(residual),
            "stiffness_asymmetry": json_num(result.stiffness_asymmetry),
            "coordinates": lin.names,
            "modes": shown.iter().enumerate().map(|(k, m)| json!({
                "mode": k + 1,
                "omega_squared": json_num(m.omega_squared),
                "omega": json_num(m.omega),
                "frequency_hz": json_num(m.omega / tau),
                "period": json_num(tau / m.omega),
                "modal_mass": json_num(m.modal_mass),
                "modal_stiffness": json_num(m.modal_stiffness),
                "shape": m.shape.iter().map(|x| json_num(*x)).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        });
        return Ok(format!("{v:#}"));
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: {} modes about the {about} (|f| = {residual:.3e})",
        model.name,
        result.modes.len()
    );
    if result.stiffness_asymmetry > 1e-9 {
        let _ = writeln!(
            s,
            "  note: the stiffness is not symmetric (relative asymmetry {:.2e}: a non-conservative force); its symmetric part is used",
            result.stiffness_asymmetry
        );
    }
    let _ = writeln!(
        s,
        "\n  mode      omega (rad/s)       f (Hz)           period (s)       modal mass   largest components"
    );
    for (k, m) in shown.iter().enumerate() {
        let mut order: Vec<usize> = (0..m.shape.len()).collect();
        order.sort_by(|&i, &j| m.shape[j].abs().total_cmp(&m.shape[i].abs()));
        let main: Vec<String> = order
            .iter()
            .take(3)
            .filter(|&&i| m.shape[i].abs() >= 0.1)
            .map(|&i| format!("{}:{:+.2}", lin.names[i], m.shape[i]))
            .collect();
        let (w, f, t) = if m.omega_squared >= 0.0 {
            (
                format!("{:.10e}", m.omega),
                format!("{:.10e}", m.omega / tau),
                format!("{:.10e}", tau / m.omega),
            )
        } else {
            let g = (-m.omega_squared).sqrt();
            (
                format!("unstable: grows as e^({g:.4e} t)"),
                String::new(),
                String::new(),
            )
        };
        let _ = writeln!(
            s,
            "  {:>4}  {w:>18}  {f:>16}  {t:>16}  {:>12.4e}   {}",
            k + 1,
            m.modal_mass,
            main.join(" ")
        );
    }
    if a.shapes {
        for (k, m) in shown.iter().enumerate() {
            let _ = writeln!(s, "\nMode {} shape (largest component +1):", k + 1);
            for (n, x) in lin.names.iter().zip(&m.shape) {
                let _ = writeln!(s, "  {n}  {x:+.9e}");
            }
        }
    }
    Ok(s)
}
