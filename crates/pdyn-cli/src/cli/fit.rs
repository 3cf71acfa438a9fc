//! `pdyn fit`: a model's parameters and initial values fitted to measured runs by least
//! squares, the Jacobian from the sensitivity equations. Computed by [`pdyn::fit::fit`];
//! printed here.

use clap::Args;
use pdyn::fit::{self, FitRequest};
use pdyn::Error;
use std::path::PathBuf;

/// `pdyn fit`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn fit examples/data/drop.toml --data examples/data/drop.csv --free c,initial.z --out out/fit
  pdyn fit model.toml --data run1.csv --data run2.csv --free c,k --sigma x=0.002 --json

A data file has a time column `t` and columns named as the model's coordinates (`x`, measured
positions) or rates (`x'`); a column `sigma_x` gives each sample's standard deviation. Parameters
are shared by the experiments; a free initial value (`initial.x`, `rate.x`) is fitted per
experiment. Starting values are the model's (change them with --set). See docs/fit.md.")]
pub struct FitArgs {
    /// The model file.
    model: PathBuf,
    /// A measured run (CSV); repeat for several experiments.
    #[arg(long, value_name = "FILE", required = true)]
    data: Vec<PathBuf>,
    /// The quantities to fit: parameters, `initial.x`, `rate.x` (comma-separated).
    #[arg(long, value_delimiter = ',', required = true)]
    free: Vec<String>,
    /// Bounds: `c=0..10`, `k=0..` (an empty side is unbounded), comma-separated.
    #[arg(long, value_delimiter = ',')]
    bounds: Vec<String>,
    /// The standard deviation of a column's samples: `x=0.01` (where the file has no `sigma_x`).
    #[arg(long, value_delimiter = ',')]
    sigma: Vec<String>,
    /// The σ are absolute: the covariance is (JᵀJ)⁻¹, not scaled by χ²/dof.
    #[arg(long)]
    absolute_sigma: bool,
    /// Parameter values (starting values of the free ones): `name=value`, comma-separated.
    #[arg(long, value_delimiter = ',')]
    set: Vec<String>,
    /// Relative tolerance of the integrations.
    #[arg(long, default_value_t = 1e-10)]
    rtol: f64,
    /// Absolute tolerance of the integrations.
    #[arg(long, default_value_t = 1e-12)]
    atol: f64,
    /// At most this many evaluations (each integrates every experiment once).
    #[arg(long, default_value_t = 200)]
    max_evaluations: usize,
    /// Write `fit_<run>.csv`, `summary.json` and the plots (`fit`, `residuals`) into this directory.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Interpret the equations (no native code).
    #[arg(long)]
    no_jit: bool,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

fn bounds(list: &[String]) -> Result<Vec<(String, f64, f64)>, Error> {
    list.iter()
        .map(|b| {
            let bad = || {
                Error::argument(
                    "--bounds",
                    format!("expected name=low..high (a side may be empty), got `{b}`"),
                )
            };
            let (name, range) = b.split_once('=').ok_or_else(bad)?;
            let (lo, hi) = range.split_once("..").ok_or_else(bad)?;
            let side = |s: &str, inf: f64| -> Result<f64, Error> {
                let s = s.trim();
                if s.is_empty() {
                    return Ok(inf);
                }
                s.parse::<f64>().map_err(|_| bad())
            };
            Ok((
                name.trim().to_string(),
                side(lo, f64::NEG_INFINITY)?,
                side(hi, f64::INFINITY)?,
            ))
        })
        .collect()
}

/// `pdyn fit ...`.
pub fn run(a: FitArgs) -> Result<String, Error> {
    for (flag, v) in [("--rtol", a.rtol), ("--atol", a.atol)] {
        if !(v > 0.0 && v.is_finite()) {
            return Err(Error::argument(
                flag,
                format!("{flag} must be a positive number, not {v}"),
            ));
        }
    }
    let mut model = super::load_model(&a.model)?;
    super::set_parameters(&mut model, &a.set)?;
    let state_names = fit::experiment::state_names(&model);
    let experiments = a
        .data
        .iter()
        .map(|p| fit::experiment::read(p, &state_names))
        .collect::<Result<Vec<_>, _>>()?;
    let req = FitRequest {
        free: a.free.iter().map(|s| s.trim().to_string()).collect(),
        bounds: bounds(&a.bounds)?,
        sigma: super::numeric_pairs(&a.sigma, "--sigma")?,
        absolute_sigma: a.absolute_sigma,
        rtol: a.rtol,
        atol: a.atol,
        lm: fit::lm::Settings {
            max_evaluations: a.max_evaluations,
            ..Default::default()
        },
        jit: if a.no_jit {
            pdyn::sim::JitMode::Off
        } else {
            pdyn::sim::JitMode::Auto
        },
    };
    let res = fit::fit(&mut model, &experiments, &req)?;
    if let Some(dir) = &a.out {
        fit::write_outputs(&res, dir, true)?;
    }
    Ok(if a.json {
        format!("{:#}\n", fit::summary_json(&res))
    } else {
        fit::summary_text(&res)
    })
}
