//! `pdyn kin`: kinematics of a particle from its position (Cartesian or polar) or its path and
//! speed: velocity, acceleration, normal–tangential and polar components, curvature, values at
//! instants and maxima over a range. Computed by [`pdyn::kin`]; printed here.
//!
//! With `--data FILE`, kinematics from measured samples instead ([`pdyn::data`]): positions
//! smoothed by a spline (λ by GCV) and differentiated, or (`--from accel`) accelerations
//! integrated to velocity and position.

use super::Format;
use clap::Args;
use pdyn::kin::{kin, value, KinInput, KinInstant, KinMax, KinResult};
use pdyn::Error;
use pdyn_expr::Pool;
use pdyn_mech::kinematics::{Maximum, Quantity};
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

fn show_q(pool: &Pool, q: Quantity, f: Format) -> String {
    f.show_value(pool, value(q))
}

fn json_q(pool: &Pool, q: Quantity) -> serde_json::Value {
    super::value_json(pool, value(q))
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
            let k =
                data::lib::kinematics::kinematics(&series, smoothing).map_err(|mut error| {
                    if error.file.is_empty() {
                        error.file = path.display().to_string();
                    }
                    data::data_error(error)
                })?;
            let table = data::kin_table(&k, &a.d.quantities)?;
            (data::kin_summary_text(&k), data::kin_summary(&k), table)
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
    Ok(if a.json {
        to_json(&r)
    } else {
        to_text(&r, a.format)
    })
}

fn to_text(r: &KinResult, format: Format) -> String {
    let pool = &r.pool;
    let mut out = String::new();
    for (name, q) in &r.quantities {
        out += &format!("{name} = {}\n", show_q(pool, *q, format));
    }
    if r.straight {
        out += "(straight-line motion: the normal is undefined, shown as 0, and R is infinite)\n";
    }
    for i in &r.instants {
        out += &format!("at {}:\n", i.resolved);
        for (n, q, nums) in &i.values {
            let num_text = match nums {
                Some(v) if v.len() == 1 => format!("  ≈ {}", v[0]),
                Some(v) => format!(
                    "  ≈ [{}]",
                    v.iter().map(f64::to_string).collect::<Vec<_>>().join(", ")
                ),
                None => String::new(),
            };
            out += &format!("  {n} = {}{num_text}\n", show_q(pool, *q, format));
        }
        out += &undefined_text(r, i, format);
    }
    if let Some(m) = &r.max {
        out += &max_text(pool, m, format);
    }
    if !r.assumed_positive.is_empty() {
        out += &format!(
            "assuming {} > 0 (use --signed NAME for a parameter that may be negative)\n",
            r.assumed_positive.join(", ")
        );
    }
    out
}

/// The quantities undefined at an instant, grouped by reason, and the limiting tangent at rest.
fn undefined_text(r: &KinResult, i: &KinInstant, format: Format) -> String {
    let pool = &r.pool;
    let mut out = String::new();
    let mut reasons: Vec<&str> = i.undefined.iter().map(|(_, why)| *why).collect();
    reasons.dedup();
    for why in reasons {
        let names: Vec<&str> = i
            .undefined
            .iter()
            .filter(|(_, w)| *w == why)
            .map(|(n, _)| *n)
            .collect();
        out += &format!("  {}: undefined — {why}\n", names.join(", "));
    }
    let Some(rest) = &i.at_rest else {
        return out;
    };
    let var = &r.variable;
    match (rest.order, &rest.tangent) {
        (Some(k), Some((dir, value))) => {
            let num = value.map_or(String::new(), |v| {
                format!("  ≈ [{}, {}, {}]", v[0], v[1], v[2])
            });
            out += &format!(
                "  limiting tangent as {var} increases to this instant: {}{num} (the direction of \
                 the derivative of r of order {k}, the first that is not zero here)\n",
                show_q(pool, Quantity::Vector(*dir), format)
            );
            out += if rest.reverses {
                "  the direction reverses through this instant (a cusp: the point stops and turns back)\n"
            } else {
                "  the direction is the same on both sides of this instant\n"
            };
            if let (Some(at), Some(an)) = (rest.a_t, rest.a_n) {
                out += &format!(
                    "  limits as {var} increases to this instant: a_t → {at}, a_n → {an}\n"
                );
            }
        }
        _ => {
            out += &format!(
                "  no limiting tangent found: the derivatives of r up to order {} are zero here\n",
                pdyn::kin::AT_REST_ORDERS
            );
        }
    }
    out
}

fn at_rest_json(r: &KinResult, i: &KinInstant) -> serde_json::Value {
    let undefined: serde_json::Map<String, serde_json::Value> = i
        .undefined
        .iter()
        .map(|(n, why)| (n.to_string(), json!(why)))
        .collect();
    let rest = i.at_rest.as_ref().map(|a| {
        json!({
            "order": a.order,
            "tangent": a.tangent.as_ref().map(|(dir, value)| json!({
                "exact": json_q(&r.pool, Quantity::Vector(*dir)),
                "value": value,
            })),
            "reverses": a.reverses,
            "a_t": a.a_t,
            "a_n": a.a_n,
        })
    });
    json!({"undefined": undefined, "at_rest": rest})
}

fn to_json(r: &KinResult) -> String {
    let pool = &r.pool;
    let mut js = serde_json::Map::new();
    let m: serde_json::Map<String, serde_json::Value> = r
        .quantities
        .iter()
        .map(|(n, q)| (n.to_string(), json_q(pool, *q)))
        .collect();
    js.insert("variable".into(), json!(r.variable));
    js.insert("straight".into(), json!(r.straight));
    js.insert("quantities".into(), serde_json::Value::Object(m));
    if !r.instants.is_empty() {
        let instants_json: Vec<serde_json::Value> = r
            .instants
            .iter()
            .map(|i| {
                let vals: serde_json::Map<String, serde_json::Value> = i
                    .values
                    .iter()
                    .map(|(n, q, nums)| {
                        (
                            n.to_string(),
                            json!({"exact": json_q(pool, *q), "value": nums}),
                        )
                    })
                    .collect();
                let mut o = json!({"at": i.spec, "resolved": i.resolved, "values": vals});
                if !i.undefined.is_empty() {
                    let extra = at_rest_json(r, i);
                    o["undefined"] = extra["undefined"].clone();
                    o["at_rest"] = extra["at_rest"].clone();
                }
                o
            })
            .collect();
        js.insert("at".into(), json!(instants_json));
    }
    if let Some(m) = &r.max {
        js.insert("max".into(), max_json(pool, m));
    }
    js.insert("assumed_positive".into(), json!(r.assumed_positive));
    format!("{}\n", serde_json::Value::Object(js))
}

fn max_text(pool: &Pool, m: &KinMax, format: Format) -> String {
    let (expr, over, var_name) = (&m.expr, &m.over, &m.variable);
    match &m.found {
        Maximum::Numeric(e) => format!(
            "max {expr} over {over}: {} at {var_name} = {}\n",
            e.value, e.at
        ),
        Maximum::Exact {
            at,
            value,
            parameters,
        } => format!(
            "max {expr} over {over}: {} at {var_name} = {}\n  (location found numerically for random values of {} and checked on a third set)\n",
            format.show(pool, *value),
            format.show(pool, *at),
            parameters.join(", ")
        ),
    }
}

fn max_json(pool: &Pool, m: &KinMax) -> serde_json::Value {
    let expr = &m.expr;
    match &m.found {
        Maximum::Numeric(e) => json!({"expr": expr, "value": e.value, "at": e.at}),
        Maximum::Exact { at, value, .. } => {
            json!({"expr": expr, "value": super::both(pool, *value), "at": super::both(pool, *at)})
        }
    }
}
