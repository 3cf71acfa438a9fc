//! `pdyn equilibrium MODEL`: the state at rest where the forces balance, by Newton's method
//! with the exact Jacobian; the reactions at the points (pins); the residual; mechanisms named.

use super::set_parameters;
use clap::Args;
use pdyn::output::json_num;
use pdyn::sim::net::statics::equilibrium;
use pdyn::Error;
use pdyn_mech::equilibrium::{EquilibriumOptions, FreeDirection};
use pdyn_mech::statics::StaticsError;
use serde_json::json;
use std::fmt::Write;
use std::path::PathBuf;

/// `pdyn equilibrium`.
#[derive(Args, Debug)]
pub struct EquilibriumArgs {
    /// The model file (TOML), e.g. examples/hanging_net.toml.
    model: PathBuf,
    /// Override parameter values, e.g. `--set k=500,m=0.1`.
    #[arg(long, value_delimiter = ',')]
    set: Vec<String>,
    /// Converged when the out-of-balance force is below this fraction of the force scale.
    #[arg(long, default_value_t = 1e-12)]
    tolerance: f64,
    /// Most Newton steps.
    #[arg(long, default_value_t = 200)]
    max_steps: usize,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

fn direction_json(d: &FreeDirection) -> serde_json::Value {
    json!({
        "components": d.components.iter().map(|(n, c)| json!({"coordinate": n, "component": json_num(*c)})).collect::<Vec<_>>(),
        "coordinates_moved": d.moved,
    })
}

/// Spring and damper forces printed (a net has thousands; `--json` has them all).
const AXIAL_SHOWN: usize = 40;

/// `pdyn equilibrium MODEL`.
pub fn run(a: EquilibriumArgs) -> Result<String, Error> {
    // Force families compact (one representative and index arrays): a net is solved by its
    // kernels without expanding them, any other model is expanded first.
    let mut model = pdyn::model_file::ModelFile::read(&a.model)?.mechanics_deferring()?;
    set_parameters(&mut model, &a.set)?;
    if !(a.tolerance > 0.0 && a.tolerance.is_finite()) {
        return Err(Error::argument(
            "--tolerance",
            format!("must be positive and finite, it is {}", a.tolerance),
        ));
    }
    let origin = model.origin.clone();
    let fail = |error: StaticsError| Error::Statics {
        origin: origin.clone(),
        error,
    };
    let opts = EquilibriumOptions {
        tolerance: a.tolerance,
        max_steps: a.max_steps,
        ..EquilibriumOptions::default()
    };
    // A net by its kernels, any other model by its symbolic linearization; sparse matrices
    // from `SPARSE_FROM` coordinates on (the same Newton steps, solved by an envelope L D Lᵀ
    // instead of a dense LU).
    let eq = equilibrium(&mut model, &opts).map_err(fail)?;
    let (reactions, axial) = (&eq.reactions, &eq.axial);
    if a.json {
        let v = json!({
            "model": model.name,
            "steps": eq.steps,
            "residual": json_num(eq.residual),
            "force_scale": json_num(eq.scale),
            "coordinates": eq.names.iter().zip(&eq.q).map(|(n, q)| json!({"name": n, "value": json_num(*q)})).collect::<Vec<_>>(),
            "reactions": reactions.iter().map(|(n, r)| json!({"point": n, "force": r.iter().map(|x| json_num(*x)).collect::<Vec<_>>()})).collect::<Vec<_>>(),
            "axial_forces": axial.iter().map(|(n, t)| json!({"element": n, "tension": json_num(*t)})).collect::<Vec<_>>(),
            "neutral_directions": eq.neutral.iter().map(direction_json).collect::<Vec<_>>(),
        });
        return Ok(format!("{v:#}"));
    }
    let mut s = String::new();
    let _ = writeln!(s, "{}: static equilibrium", model.name);
    let _ = writeln!(
        s,
        "  Newton steps: {}; out-of-balance force |f| = {:.3e} (force scale {:.3e})",
        eq.steps, eq.residual, eq.scale
    );
    let width = eq.names.iter().map(|n| n.len()).max().unwrap_or(0);
    let _ = writeln!(s, "\nCoordinates:");
    for (n, q) in eq.names.iter().zip(&eq.q) {
        let _ = writeln!(s, "  {n:width$}  {q:.12e}");
    }
    if !reactions.is_empty() {
        let _ = writeln!(
            s,
            "\nReactions at the points (force of the support on the point):"
        );
        for (n, r) in reactions {
            let _ = writeln!(s, "  {n}: [{:.6e}, {:.6e}, {:.6e}]", r[0], r[1], r[2]);
        }
    }
    if !axial.is_empty() {
        let _ = writeln!(
            s,
            "\nSpring and damper forces (positive in tension, negative in compression):"
        );
        let width = axial.iter().map(|(n, _)| n.len()).max().unwrap_or(0);
        for (n, t) in axial.iter().take(AXIAL_SHOWN) {
            let _ = writeln!(s, "  {n:width$}  {t:+.6e}");
        }
        if axial.len() > AXIAL_SHOWN {
            let _ = writeln!(
                s,
                "  ... and {} more (--json lists every one)",
                axial.len() - AXIAL_SHOWN
            );
        }
    }
    if !eq.neutral.is_empty() {
        let _ = writeln!(
            s,
            "\nThe equilibrium is neutral (not unique) along {} direction(s) of zero stiffness:",
            eq.neutral.len()
        );
        for d in &eq.neutral {
            let _ = writeln!(s, "  {d}");
        }
    }
    Ok(s)
}
