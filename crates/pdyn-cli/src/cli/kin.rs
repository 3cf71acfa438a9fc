//! `pdyn kin`: kinematics of a particle from its position (Cartesian or polar) or its path and
//! speed: velocity, acceleration, normal–tangential and polar components, curvature, values at
//! instants and maxima over a range. Computed by [`pdyn::kin`], printed by [`pdyn::report::kin`].
//!
//! With `--data FILE`, kinematics from measured samples instead ([`pdyn::data`]): positions
//! smoothed by a spline (λ by GCV) and differentiated, or (`--from accel`) accelerations
//! integrated to velocity and position.

use super::Format;
use clap::Args;
use pdyn::kin::{kin, KinInput};
use pdyn::Error;
use serde_json::json;

/// `pdyn kin`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn kin \"[R*cos(omega*t), R*sin(omega*t), 0]\"
  pdyn kin --polar \"r = t/sqrt(pi), theta = t^2\" --at theta=pi
  pdyn kin --path \"y = A*sin(2*pi*x/L)\" --speed V --max \"norm(a)\" --over x=0..L
  pdyn kin --path \"x = R*cos(s), y = R*sin(s)\" --param s --speed \"k*t\" --at \"s=pi, t=2\"

Measured data (a CSV file with a header line; see docs/data.md):
  pdyn kin --data track.csv                      positions t,x,y[,z] → v, a, a_t, a_n, polar... (λ by GCV)
  pdyn kin --data track.csv --columns time,east,north --smooth 1e-3 -o kin.csv
  pdyn kin --data acc.csv --from accel --v0 0,0 --bias 0..2 -o path.csv
                                                 accelerations t,ax[,ay[,az]] → velocity and position")]
pub struct KinArgs {
    /// Cartesian position `[x, y, z]` as functions of `t` (or of coordinates written `x(t)`).
    #[arg(allow_hyphen_values = true, conflicts_with = "data")]
    position: Option<String>,
    /// Measured samples: a CSV file (header line, then one row per sample). Positions by
    /// default; accelerations with `--from accel`.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["polar", "path", "at", "max", "over", "set"])]
    data: Option<std::path::PathBuf>,
    /// The options of --data (boxed: they would double the size of every command's
    /// arguments).
    #[command(flatten)]
    d: Box<DataArgs>,
    /// Cylindrical-polar position: `r = ..., theta = ..., z = ...` (z optional).
    #[arg(long, allow_hyphen_values = true)]
    polar: Option<String>,
    /// A planar path: `y = f(x)`, or `x = ..., y = ...` in the parameter given by --param.
    #[arg(long, allow_hyphen_values = true)]
    path: Option<String>,
    /// The parameter of a parametric path.
    #[arg(long, default_value = "s")]
    param: String,
    /// Speed along the path (a constant or a function of t).
    #[arg(long, default_value = "V", allow_hyphen_values = true)]
    speed: String,
    /// Evaluate at an instant: `t=2`, `theta=pi` (solves for t), `x=L/4` (path position),
    /// several assignments separated by commas. Repeat for several instants.
    #[arg(long, allow_hyphen_values = true)]
    at: Vec<String>,
    /// Parameter values, e.g. `--set A=2,L=50`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    set: Vec<String>,
    /// A scalar to maximise over --over, in the names printed (`norm(a)`, `a_n`, `speed`...).
    #[arg(long, allow_hyphen_values = true)]
    max: Option<String>,
    /// The range for --max: `x=0..L` or `t=0..10`.
    #[arg(long, allow_hyphen_values = true)]
    over: Option<String>,
    /// Parameters that may be negative; every other parameter is assumed positive.
    #[arg(long, value_delimiter = ',')]
    signed: Vec<String>,
    /// Output notation.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

/// The options of `pdyn kin --data`.
#[derive(Args, Debug)]
pub struct DataArgs {
    /// With --data: what the columns hold: `position` (t,x,y[,z]: smoothed and differentiated)
    /// or `accel` (t,ax[,ay[,az]]: integrated to velocity and position). [default: position]
    #[arg(long, value_name = "position|accel", requires = "data")]
    from: Option<String>,
    /// With --data: the columns to read, time first (default `t,x,y[,z]`, or `t,ax[,ay[,az]]`
    /// with --from accel).
    #[arg(long, value_delimiter = ',', requires = "data")]
    columns: Vec<String>,
    /// With --data (positions): the smoothing: `gcv` (generalized cross-validation) or a
    /// smoothing parameter λ ≥ 0 (value² · time³; 0 interpolates). [default: gcv]
    #[arg(long, requires = "data")]
    smooth: Option<String>,
    /// With --data (positions): the quantities to write, comma-separated, from: position,
    /// velocity, acceleration, speed, tangent, normal, curvature, a_t, a_n, polar, se
    /// (default all).
    #[arg(long, value_delimiter = ',', requires = "data")]
    quantities: Vec<String>,
    /// With --from accel: the quadrature: `simpson` (4th order) or `trapezoid` (2nd order).
    /// [default: simpson]
    #[arg(long, requires = "data")]
    rule: Option<String>,
    /// With --from accel: the accelerometer bias to remove: `none`, `mean` (the record starts
    /// and ends at the same velocity), `T0..T1` (the mean over an interval at rest) or a value.
    /// [default: none]
    #[arg(long, allow_hyphen_values = true, requires = "data")]
    bias: Option<String>,
    /// With --from accel: initial velocity per axis, e.g. `--v0 0,1.5`.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "data"
    )]
    v0: Vec<f64>,
    /// With --from accel: initial position per axis.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "data"
    )]
    x0: Vec<f64>,
    /// With --from accel: the accelerometer noise (one sample's standard deviation) for the
    /// error estimate; default: from the quiet interval, or from second differences.
    #[arg(long, requires = "data")]
    sigma_a: Option<f64>,
    /// With --data: write the table (CSV) to this file; stdout gets the summary.
    #[arg(short = 'o', long = "output", value_name = "FILE", requires = "data")]
    output: Option<std::path::PathBuf>,
}

/// Tables up to this many rows are printed after the summary when there is no `-o`.
const PRINT_ROWS: usize = 1000;

/// `pdyn kin --data ...`.
fn run_data(a: KinArgs, path: &std::path::Path) -> Result<String, Error> {
    use pdyn::data::{self, DataKind};
    let d = &a.d;
    let from = d.from.as_deref().unwrap_or("position");
    // An option of the other mode is an error, not silently ignored.
    let accel_only = [
        ("--rule", d.rule.is_some()),
        ("--bias", d.bias.is_some()),
        ("--v0", !d.v0.is_empty()),
        ("--x0", !d.x0.is_empty()),
        ("--sigma-a", d.sigma_a.is_some()),
    ];
    let position_only = [
        ("--smooth", d.smooth.is_some()),
        ("--quantities", !d.quantities.is_empty()),
    ];
    let (wrong, mode) = if from == "accel" {
        (
            position_only.iter().find(|o| o.1),
            "positions (the default --from position)",
        )
    } else {
        (
            accel_only.iter().find(|o| o.1),
            "accelerations (--from accel)",
        )
    };
    if let Some((flag, _)) = wrong {
        return Err(Error::argument(
            *flag,
            format!("{flag} applies only to {mode}"),
        ));
    }
    let (summary_text, summary_json, table) = match from {
        "position" => {
            let smoothing = data::parse_smoothing(d.smooth.as_deref().unwrap_or("gcv"))?;
            let series = data::read_series(
                path,
                &a.d.columns,
                DataKind::Position,
                5,
                "kinematics from samples",
            )?;
            let k = data::lib::kinematics::kinematics_with(
                &series,
                smoothing,
                data::kin_wanted(&a.d.quantities),
            )
            .map_err(|mut error| {
                if error.file.is_empty() {
                    error.file = path.display().to_string();
                }
                data::data_error(error)
            })?;
            // The summaries first: the table takes the columns (10⁶ samples: no copies).
            let (text, summary) = (data::kin_summary_text(&k), data::kin_summary(&k));
            (text, summary, data::kin_table(k, &a.d.quantities)?)
        }
        "accel" => {
            let rule_text = d.rule.as_deref().unwrap_or("simpson");
            let rule = data::lib::integrate::Rule::parse(rule_text).ok_or_else(|| {
                Error::argument(
                    "--rule",
                    format!("`{rule_text}` is not `simpson` or `trapezoid`"),
                )
            })?;
            let options = data::lib::integrate::AccelOptions {
                rule,
                bias: data::parse_bias(d.bias.as_deref().unwrap_or("none"))?,
                sigma_a: a.d.sigma_a,
                ..Default::default()
            };
            let series =
                data::read_series(path, &a.d.columns, DataKind::Acceleration, 2, "integration")?;
            let r = data::integrate_accel(&series, &options, &a.d.v0, &a.d.x0)?;
            (
                data::accel_summary_text(&r, &options),
                data::accel_summary(&r, &options),
                data::accel_table(&r),
            )
        }
        other => {
            return Err(Error::argument(
                "--from",
                format!("`{other}` is not `position` or `accel`"),
            ))
        }
    };
    finish(
        summary_text,
        summary_json,
        &table,
        a.d.output.as_deref(),
        a.json,
    )
}

/// Writes the table (to `-o`, or after the summary when short) and renders the summary.
pub(crate) fn finish(
    summary_text: String,
    mut summary_json: serde_json::Value,
    table: &pdyn::data::Table,
    output: Option<&std::path::Path>,
    json: bool,
) -> Result<String, Error> {
    if let Some(out) = output {
        table.write(out)?;
    }
    if json {
        summary_json["columns"] = json!(table.names);
        match output {
            Some(out) => summary_json["output"] = json!(out.display().to_string()),
            None => summary_json["table"] = table.to_json(),
        }
        return Ok(format!(
            "{summary_json}
"
        ));
    }
    let mut text = summary_text;
    match output {
        Some(out) => {
            text += &format!(
                "{} rows written to {}
",
                table.rows(),
                out.display()
            )
        }
        None if table.rows() <= PRINT_ROWS => {
            text.push('\n');
            text += &table.to_csv();
        }
        None => {
            text += &format!(
                "{} rows, columns {}: write them with -o FILE (or use --json)\n",
                table.rows(),
                table.names.join(",")
            )
        }
    }
    Ok(text)
}

/// `pdyn kin ...`.
pub fn run(a: KinArgs) -> Result<String, Error> {
    if let Some(path) = a.data.clone() {
        return run_data(a, &path);
    }
    // The options of --data mean nothing without it: refuse them rather than ignore them.
    let d = &a.d;
    let given = [
        ("--from", d.from.is_some()),
        ("--columns", !d.columns.is_empty()),
        ("--smooth", d.smooth.is_some()),
        ("--quantities", !d.quantities.is_empty()),
        ("--rule", d.rule.is_some()),
        ("--bias", d.bias.is_some()),
        ("--v0", !d.v0.is_empty()),
        ("--x0", !d.x0.is_empty()),
        ("--sigma-a", d.sigma_a.is_some()),
        ("--output", d.output.is_some()),
    ];
    if let Some((flag, _)) = given.iter().find(|g| g.1) {
        return Err(Error::argument(
            *flag,
            format!("{flag} applies to measured data: give the file with --data FILE"),
        ));
    }
    let input = KinInput {
        position: a.position,
        polar: a.polar,
        path: a.path,
        param: a.param,
        speed: a.speed,
        at: a.at,
        set: a.set,
        max: a.max,
        over: a.over,
        signed: a.signed,
    };
    let r = kin(&input)?;
    Ok(pdyn::report::kin::report(&r, a.format.into(), a.json))
}
