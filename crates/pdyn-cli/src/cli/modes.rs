//! `pdyn modes MODEL`: natural frequencies and mode shapes of the model linearized about its
//! static equilibrium (or its initial state), `K φ = ω² M φ`: dense (every mode) for small
//! systems, the lowest few by sparse shift-invert Lanczos for large ones; with damping, the
//! damped modes of `s² M + s C + K` too (natural frequency and damping ratio): from the
//! undamped modes when the damping is classical (`C M⁻¹ K = K M⁻¹ C`), else from the dense
//! companion form (at most 1,000 coordinates); the output says which.

use super::set_parameters;
use clap::{Args, ValueEnum};
use pdyn::sim::net::statics::modes_about;
use pdyn::Error;
use pdyn_mech::damped::DampedMode;
use pdyn_mech::sparse::Csr;
use pdyn_mech::statics::{self, ModesRequest, StaticsError};
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

/// How the eigenproblem is solved.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Solver {
    /// Dense below 300 coordinates, sparse from there on.
    Auto,
    /// Every mode, with dense matrices (`O(n³)`).
    Dense,
    /// The lowest COUNT modes (default 20) by shift-invert Lanczos on sparse matrices.
    Sparse,
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
    /// Print the lowest COUNT modes only (all by default; 20 with the sparse solver, which
    /// computes only these).
    #[arg(long)]
    count: Option<usize>,
    /// Dense (every mode) or sparse (the lowest COUNT, for large systems).
    #[arg(long, value_enum, default_value_t = Solver::Auto)]
    solver: Solver,
    /// Print each mode's shape (always in --json).
    #[arg(long)]
    shapes: bool,
    /// Write the matrices solved (K.mtx, M.mtx, C.mtx: Matrix Market, as read by SciPy's
    /// `scipy.io.mmread`) into this directory.
    #[arg(long, value_name = "DIR")]
    matrices: Option<PathBuf>,
    /// Machine-readable output (frequencies and shapes).
    #[arg(long)]
    json: bool,
}

/// K.mtx, M.mtx and C.mtx in `dir`.
fn write_matrices(dir: &std::path::Path, k: &Csr, m: &Csr, c: &Csr) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create", e))?;
    for (name, a) in [("K.mtx", k), ("M.mtx", m), ("C.mtx", c)] {
        let path = dir.join(name);
        std::fs::write(&path, a.to_matrix_market()).map_err(|e| Error::io(&path, "write", e))?;
    }
    Ok(())
}

/// `pdyn modes MODEL`.
pub fn run(a: ModesArgs) -> Result<String, Error> {
    // Force families compact (one representative and index arrays): a net is linearized by
    // its kernels, any other model expanded first.
    let mut model = pdyn::model_file::ModelFile::read(&a.model)?.mechanics_deferring()?;
    set_parameters(&mut model, &a.set)?;
    let origin = model.origin.clone();
    let fail = |error: StaticsError| Error::Statics {
        origin: origin.clone(),
        error,
    };
    if a.count == Some(0) {
        return Err(Error::argument(
            "--count",
            "--count must be at least 1".to_string(),
        ));
    }
    let request = ModesRequest {
        about: match a.about {
            About::Equilibrium => statics::About::Equilibrium,
            About::Initial => statics::About::Initial,
        },
        solver: match a.solver {
            Solver::Auto => statics::Solver::Auto,
            Solver::Dense => statics::Solver::Dense,
            Solver::Sparse => statics::Solver::Sparse,
        },
        count: a.count,
    };
    let report = modes_about(&mut model, &request).map_err(fail)?;
    if let Some(dir) = &a.matrices {
        let m = &report.matrices;
        write_matrices(dir, &m.stiffness, &m.mass, &m.damping)?;
    }
    let n = report.names.len();
    let sparse = report.sparse;
    let about = report.about.describe();
    let residual = report.residual;
    let result = &report.modes;
    let lin_names = &report.names;
    let damped = &report.damped;
    let has_damping = report.has_damping;
    let shown = &result.modes[..];
    let damped_shown: &[DampedMode] = damped.as_deref().unwrap_or(&[]);
    let tau = std::f64::consts::TAU;
    // The directions a rigid translation of the particles moves some mass along.
    let biggest = result
        .total_mass
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(0.0f64, f64::max);
    let active: Vec<usize> = (0..3)
        .filter(|&d| result.total_mass[d].is_finite() && result.total_mass[d] > 1e-12 * biggest)
        .collect();
    const AXES: [&str; 3] = ["x", "y", "z"];
    if a.json {
        let header = super::modes_json::Header {
            model: &model.name,
            about,
            residual,
            names: lin_names,
            sparse,
            damped_path: report
                .damped_path
                .map(|path| (path, report.commutation_defect)),
            damped: damped.as_deref(),
        };
        return Ok(super::modes_json::modes_json(&header, result, shown.len()));
    }
    let mut s = String::new();
    if sparse {
        let _ = writeln!(
            s,
            "{}: the lowest {} of {n} modes (sparse shift-invert Lanczos) about the {about} (|f| = {residual:.3e})",
            model.name,
            result.modes.len()
        );
    } else {
        let _ = writeln!(
            s,
            "{}: {n} modes about the {about} (|f| = {residual:.3e})",
            model.name,
        );
    }
    if result.stiffness_asymmetry > 1e-9 {
        let _ = writeln!(
            s,
            "  note: the stiffness is not symmetric (relative asymmetry {:.2e}: a non-conservative force); its symmetric part is used",
            result.stiffness_asymmetry
        );
    }
    let mass_heads: String = active
        .iter()
        .map(|&d| format!("  eff. mass {} %", AXES[d]))
        .collect();
    let _ = writeln!(
        s,
        "\n  mode      omega (rad/s)       f (Hz)           period (s)       modal mass{mass_heads}   largest components"
    );
    for (k, m) in shown.iter().enumerate() {
        let mut order: Vec<usize> = (0..m.shape.len()).collect();
        order.sort_by(|&i, &j| m.shape[j].abs().total_cmp(&m.shape[i].abs()));
        let main: Vec<String> = order
            .iter()
            .take(3)
            .filter(|&&i| m.shape[i].abs() >= 0.1)
            .map(|&i| format!("{}:{:+.2}", lin_names[i], m.shape[i]))
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
        let shares: String = active
            .iter()
            .map(|&d| {
                format!(
                    "  {:>15.3}",
                    100.0 * m.effective_mass[d] / result.total_mass[d]
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "  {:>4}  {w:>18}  {f:>16}  {t:>16}  {:>12.4e}{shares}   {}",
            k + 1,
            m.modal_mass,
            main.join(" ")
        );
    }
    if !active.is_empty() {
        let captured: Vec<String> = active
            .iter()
            .map(|&d| {
                let sum: f64 = shown.iter().map(|m| m.effective_mass[d]).sum();
                format!(
                    "{} {:.3} % of {:.6e}",
                    AXES[d],
                    100.0 * sum / result.total_mass[d],
                    result.total_mass[d]
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "\n  effective mass of these modes (a ground acceleration along an axis excites each mode in this share): {}",
            captured.join(", ")
        );
    }
    let path = report.damped_path.map(|p| p.describe()).unwrap_or_default();
    if damped.is_some() {
        let _ = writeln!(
            s,
            "\n  damped modes (roots s of det(s² M + s C + K) = 0, lowest natural frequency first)\n  path: {path}\n  mode      omega_n (rad/s)     damping ratio     omega_d (rad/s)"
        );
        for (k, d) in damped_shown.iter().enumerate() {
            if d.oscillatory {
                let _ = writeln!(
                    s,
                    "  {:>4}  {:>18.10e}  {:>16.10e}  {:>18.10e}",
                    k + 1,
                    d.omega_n,
                    d.damping_ratio,
                    d.im
                );
            } else {
                let _ = writeln!(s, "  {:>4}  not oscillating: e^({:.6e} t)", k + 1, d.re);
            }
        }
    } else if has_damping {
        let _ = writeln!(s, "\n  damped modes {path}");
    }
    if a.shapes {
        for (k, m) in shown.iter().enumerate() {
            let _ = writeln!(s, "\nMode {} shape (largest component +1):", k + 1);
            for (n, x) in lin_names.iter().zip(&m.shape) {
                let _ = writeln!(s, "  {n}  {x:+.9e}");
            }
        }
    }
    Ok(s)
}
