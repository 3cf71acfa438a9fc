//! `pdyn fuse`: an accelerometer record fused with position fixes by a Kalman filter and the
//! Rauch–Tung–Striebel smoother (position, velocity and accelerometer bias per axis). Computed
//! by [`pdyn::data::fuse_files`]; printed here.

use clap::Args;
use pdyn::data;
use pdyn::Error;
use std::path::PathBuf;

/// `pdyn fuse`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn fuse --accel examples/data/imu.csv --fixes examples/data/gps.csv -o fused.csv
  pdyn fuse --accel acc.csv --fixes gps.csv --sigma-a 0.05 --sigma-p 3 --json

The accelerometer file has t,ax[,ay[,az]] (high rate), the fixes file t,x[,y[,z]] (low rate, within
the accelerometer's time range). Noise levels not given are estimated: σ_a from the accelerometer's
second differences, σ_p by maximum likelihood of the innovations. See docs/data.md.")]
pub struct FuseArgs {
    /// The accelerometer record (CSV: time, then one acceleration column per axis).
    #[arg(long, value_name = "FILE")]
    accel: PathBuf,
    /// The position fixes (CSV: time, then one position column per axis).
    #[arg(long, value_name = "FILE")]
    fixes: PathBuf,
    /// The accelerometer's columns, time first (default `t,ax[,ay[,az]]`).
    #[arg(long, value_delimiter = ',')]
    accel_columns: Vec<String>,
    /// The fixes' columns, time first (default `t,x[,y[,z]]`, as many axes as the accelerometer).
    #[arg(long, value_delimiter = ',')]
    fix_columns: Vec<String>,
    /// Accelerometer noise: one sample's standard deviation (default: estimated).
    #[arg(long)]
    sigma_a: Option<f64>,
    /// Position-fix noise: standard deviation (default: estimated).
    #[arg(long)]
    sigma_p: Option<f64>,
    /// Bias random walk, (acceleration)/√time; 0: a constant bias (estimated by the filter).
    #[arg(long, default_value_t = 0.0)]
    sigma_b: f64,
    /// Prior standard deviation of the bias about 0.
    #[arg(long, default_value_t = 1.0)]
    bias0: f64,
    /// Prior standard deviation of the initial velocity about 0.
    #[arg(long, default_value_t = 1e3)]
    v0_sd: f64,
    /// Write the table (CSV) to this file; stdout gets the summary.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

/// `pdyn fuse ...`.
pub fn run(a: FuseArgs) -> Result<String, Error> {
    let noise = data::lib::fusion::Noise {
        sigma_a: a.sigma_a,
        sigma_p: a.sigma_p,
        sigma_b: a.sigma_b,
        bias0: a.bias0,
        v0: a.v0_sd,
        ..Default::default()
    };
    for (flag, v) in [("--bias0", a.bias0), ("--v0-sd", a.v0_sd)] {
        if !(v > 0.0 && v.is_finite()) {
            return Err(Error::argument(
                flag,
                format!("{flag} must be a positive number, not {v}"),
            ));
        }
    }
    let (fused, names) =
        data::fuse_files(&a.accel, &a.fixes, &a.accel_columns, &a.fix_columns, &noise)?;
    let table = data::fuse_table(&fused, &names);
    super::kin::finish(
        data::fuse_summary_text(&fused, &names),
        data::fuse_summary(&fused, &names),
        &table,
        a.output.as_deref(),
        a.json,
    )
}
