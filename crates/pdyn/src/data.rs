//! Measured motion (`pdyn kin --data`, `pdyn fuse`, Python's `pdyn.kin_data`,
//! `pdyn.integrate_accel`, `pdyn.fuse`): files read into [`pdyn_data`]'s time series, its
//! computations run, results turned into [`Table`]s (CSV) and JSON summaries. The numerics
//! are the `pdyn-data` crate's (re-exported as [`lib`]); this module adds files, defaults,
//! names and the typed [`Error::Data`].

use crate::error::Error;
pub use pdyn_data as lib;
use pdyn_data::csv::Series;
use pdyn_data::fusion::{Fused, Noise};
use pdyn_data::integrate::{AccelOptions, Integrated};
use pdyn_data::kinematics::KinData;
use pdyn_data::source::Source;
use pdyn_data::spline::Smoothing;
use pdyn_data::DataError;
use serde_json::json;
use std::path::Path;

/// Rows formatted per block when a table is written.
const ROWS_PER_BLOCK: usize = 16_384;

/// Columns of numbers with their names: what is written as CSV (and given to Python).
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// Column names (the CSV header).
    pub names: Vec<String>,
    /// The columns, all of the same length.
    pub columns: Vec<Vec<f64>>,
}

impl Table {
    fn push(&mut self, name: impl Into<String>, column: Vec<f64>) {
        self.names.push(name.into());
        self.columns.push(column);
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// Writes the table as CSV (shortest round-trip numbers; `inf` where a quantity is
    /// undefined, such as the curvature at rest). Rows are formatted in blocks on rayon's
    /// threads while a writer thread writes the blocks before them in order: a few blocks in
    /// memory at a time, and the write calls (a tenth of a second for 10⁶ rows) overlap the
    /// formatting instead of leaving the other cores idle.
    pub fn write_csv<W: std::io::Write + Send>(&self, out: &mut W) -> std::io::Result<()> {
        use rayon::prelude::*;
        out.write_all(crate::output::csv_header(&self.names).as_bytes())?;
        let rows = self.rows();
        let blocks: Vec<(usize, usize)> = (0..rows)
            .step_by(ROWS_PER_BLOCK)
            .map(|a| (a, (a + ROWS_PER_BLOCK).min(rows)))
            .collect();
        // Two blocks per thread in a group: with one group written while the next is
        // formatted, twice the memory of one group is in flight.
        let at_once = 2 * rayon::current_num_threads().max(1);
        std::thread::scope(|s| {
            // A rendezvous channel: one group written while the next is formatted.
            let (send, receive) = std::sync::mpsc::sync_channel::<Vec<Vec<u8>>>(0);
            let writer = s.spawn(move || -> std::io::Result<()> {
                for texts in receive {
                    for t in texts {
                        out.write_all(&t)?;
                    }
                }
                Ok(())
            });
            for group in blocks.chunks(at_once) {
                let texts: Vec<Vec<u8>> = group
                    .par_iter()
                    .map(|&(a, b)| self.format_rows(a, b))
                    .collect();
                if send.send(texts).is_err() {
                    // The writer stopped on an error, which its join returns.
                    break;
                }
            }
            drop(send);
            writer
                .join()
                .unwrap_or_else(|_| Err(std::io::Error::other("the CSV writer thread panicked")))
        })
    }

    /// Rows `a..b` as CSV lines.
    fn format_rows(&self, a: usize, b: usize) -> Vec<u8> {
        let mut text = Vec::with_capacity((b - a) * self.names.len() * 20);
        for i in a..b {
            for (k, c) in self.columns.iter().enumerate() {
                if k > 0 {
                    text.push(b',');
                }
                crate::output::append_number(&mut text, c[i]);
            }
            text.push(b'\n');
        }
        text
    }

    /// The table as CSV text.
    pub fn to_csv(&self) -> String {
        let mut out = Vec::with_capacity(self.rows() * self.names.len() * 20 + 64);
        // Writing into a Vec cannot fail.
        let _ = self.write_csv(&mut out);
        String::from_utf8_lossy(&out).into_owned()
    }

    /// Writes the CSV to `path` (streamed: a table of 10⁶ rows is not built as one string).
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        let file = std::fs::File::create(path).map_err(|e| Error::io(path, "create", e))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
        self.write_csv(&mut w)
            .and_then(|()| std::io::Write::flush(&mut w))
            .map_err(|e| Error::io(path, "write", e))
    }

    /// The columns as a JSON object `{name: [values]}`.
    pub fn to_json(&self) -> serde_json::Value {
        let map: serde_json::Map<String, serde_json::Value> = self
            .names
            .iter()
            .zip(&self.columns)
            .map(|(n, c)| {
                let values: Vec<serde_json::Value> =
                    c.iter().map(|&x| crate::output::json_num(x)).collect();
                (n.clone(), serde_json::Value::Array(values))
            })
            .collect();
        serde_json::Value::Object(map)
    }
}

/// A data problem as a command's error.
pub fn data_error(error: DataError) -> Error {
    Error::Data {
        error: Box::new(error),
    }
}

/// Reads a data file: CSV text (not UTF-8: a located data error at the first bad byte) or
/// Parquet, told apart by its bytes.
pub fn read_source(path: &Path) -> Result<Source, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "read the data file",
        error: std::sync::Arc::new(e),
    })?;
    Source::from_bytes(&path.display().to_string(), bytes).map_err(data_error)
}

/// What the columns of a file hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataKind {
    /// Positions `t, x, y[, z]`.
    Position,
    /// Accelerations `t, ax[, ay[, az]]`.
    Acceleration,
}

/// The columns to read: those given, or the defaults `t,x,y[,z]` (positions, `z` when the
/// header has it) or `t` and every column whose name starts with `a` (accelerations: `ax`,
/// `ay`, `a_z`...).
fn choose_columns(
    file: &str,
    source: &Source,
    given: &[String],
    kind: DataKind,
) -> Result<Vec<String>, Error> {
    if !given.is_empty() {
        return Ok(given.to_vec());
    }
    let (header_line, header) = source.header(file).map_err(data_error)?;
    let has = |n: &str| header.iter().any(|h| h == n);
    let listed = || {
        header
            .iter()
            .map(|h| format!("`{h}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let missing = |what: &str, defaults: &str| {
        let e = DataError::new(
            file,
            format!("no {what} (the default columns are {defaults})"),
        );
        let e = match header_line {
            Some(line) => e.at(line, None),
            None => e,
        };
        data_error(
            e.help(format!(
                    "name the columns to use with --columns (Python: columns=), the time first; the header has {}",
                    listed()
                )),
        )
    };
    if !has("t") {
        return Err(missing("column named `t`", "the time `t`, then the data"));
    }
    let cols: Vec<String> = match kind {
        DataKind::Position => {
            if !has("x") || !has("y") {
                return Err(missing("columns named `x` and `y`", "t,x,y[,z]"));
            }
            let mut c: Vec<String> = ["t", "x", "y"].iter().map(|s| s.to_string()).collect();
            if has("z") {
                c.push("z".into());
            }
            c
        }
        DataKind::Acceleration => {
            // Every column named like an acceleration: `ax`, `a_y`, `az`...
            let acc: Vec<String> = header
                .iter()
                .filter(|h| h.starts_with('a') && h.len() > 1)
                .cloned()
                .collect();
            if acc.is_empty() {
                return Err(missing(
                    "acceleration column (a name starting with `a`, such as `ax`)",
                    "t, then every column whose name starts with `a`",
                ));
            }
            std::iter::once("t".to_string()).chain(acc).collect()
        }
    };
    Ok(cols)
}

/// Reads the series of `columns` (time first) from the data file `path` (CSV or Parquet), at
/// least `min_len` rows.
pub fn read_series(
    path: &Path,
    columns: &[String],
    kind: DataKind,
    min_len: usize,
    what: &str,
) -> Result<Series, Error> {
    let file = path.display().to_string();
    let source = read_source(path)?;
    let cols = choose_columns(&file, &source, columns, kind)?;
    let wanted: Vec<&str> = cols.iter().map(String::as_str).collect();
    let table = source.read_columns(&file, &wanted).map_err(data_error)?;
    Series::from_columns(table, min_len, what).map_err(data_error)
}

/// `--smooth`: `gcv` or a value of λ ≥ 0.
pub fn parse_smoothing(text: &str) -> Result<Smoothing, Error> {
    let t = text.trim();
    if t.eq_ignore_ascii_case("gcv") {
        return Ok(Smoothing::Gcv);
    }
    match t.parse::<f64>() {
        Ok(l) if l >= 0.0 && l.is_finite() => Ok(Smoothing::Lambda(l)),
        _ => Err(Error::argument(
            "--smooth",
            format!("`{t}` is not `gcv` or a smoothing parameter λ ≥ 0 (e.g. 1e-3)"),
        )),
    }
}

/// The quantity groups of a kinematics table, in order.
pub const KIN_GROUPS: [&str; 11] = [
    "position",
    "velocity",
    "acceleration",
    "speed",
    "tangent",
    "normal",
    "curvature",
    "a_t",
    "a_n",
    "polar",
    "se",
];

/// The derived columns a kinematics table of `groups` (all when empty) shows: what
/// [`pdyn_data::kinematics::kinematics_with`] needs to compute for [`kin_table`].
pub fn kin_wanted(groups: &[String]) -> pdyn_data::kinematics::Wanted {
    let want = |g: &str| groups.is_empty() || groups.iter().any(|x| x == g);
    pdyn_data::kinematics::Wanted {
        frame: want("tangent") || want("normal"),
        curvature: want("curvature"),
        se: want("se"),
        polar: want("polar"),
    }
}

/// The kinematics table: `t`, then the groups asked for (all when `groups` is empty), each
/// column named after the data's: `x`, `v_x`, `a_x`, `T_x`, `N_x`, `speed`, `curvature`,
/// `a_t`, `a_n`, `r`, `theta`, `v_r`, `v_theta`, `a_r`, `a_theta`, `se_speed`, `se_a_t`,
/// `se_a_n`, `se_curvature`. The columns are moved out of `k`, not copied (take its summaries
/// first).
pub fn kin_table(mut k: KinData, groups: &[String]) -> Result<Table, Error> {
    for g in groups {
        if !KIN_GROUPS.contains(&g.as_str()) {
            return Err(Error::argument(
                "--quantities",
                format!(
                    "unknown quantity `{g}`; choose from {}",
                    KIN_GROUPS.join(", ")
                ),
            ));
        }
    }
    let want = |g: &str| groups.is_empty() || groups.iter().any(|x| x == g);
    let names: Vec<String> = k.fits.iter().map(|f| f.name.clone()).collect();
    let mut t = Table::default();
    t.push("t", std::mem::take(&mut k.t));
    let vectors: [(&str, &str, Vec<Vec<f64>>); 5] = [
        ("position", "", std::mem::take(&mut k.position)),
        ("velocity", "v_", std::mem::take(&mut k.velocity)),
        ("acceleration", "a_", std::mem::take(&mut k.acceleration)),
        ("tangent", "T_", std::mem::take(&mut k.tangent)),
        ("normal", "N_", std::mem::take(&mut k.normal)),
    ];
    for (group, prefix, cols) in vectors {
        if want(group) {
            for (n, c) in names.iter().zip(cols) {
                t.push(format!("{prefix}{n}"), c);
            }
        }
        if group == "acceleration" && want("speed") {
            t.push("speed", std::mem::take(&mut k.speed));
        }
    }
    for (group, name, col) in [
        ("curvature", "curvature", std::mem::take(&mut k.curvature)),
        ("a_t", "a_t", std::mem::take(&mut k.a_t)),
        ("a_n", "a_n", std::mem::take(&mut k.a_n)),
    ] {
        if want(group) {
            t.push(name, col);
        }
    }
    if want("polar") {
        for (name, col) in [
            ("r", std::mem::take(&mut k.r)),
            ("theta", std::mem::take(&mut k.theta)),
            ("v_r", std::mem::take(&mut k.v_r)),
            ("v_theta", std::mem::take(&mut k.v_theta)),
            ("a_r", std::mem::take(&mut k.a_r)),
            ("a_theta", std::mem::take(&mut k.a_theta)),
        ] {
            t.push(name, col);
        }
    }
    if want("se") {
        for (name, col) in [
            ("se_speed", std::mem::take(&mut k.se_speed)),
            ("se_a_t", std::mem::take(&mut k.se_a_t)),
            ("se_a_n", std::mem::take(&mut k.se_a_n)),
            ("se_curvature", std::mem::take(&mut k.se_curvature)),
        ] {
            t.push(name, col);
        }
    }
    Ok(t)
}

/// The JSON summary of kinematics from samples: per coordinate λ, its source, σ, edf and the
/// standard errors; the boundary width; the band's meaning.
pub fn kin_summary(k: &KinData) -> serde_json::Value {
    let fits: Vec<serde_json::Value> = k
        .fits
        .iter()
        .map(|f| {
            json!({
                "column": f.name,
                "lambda": f.lambda,
                "lambda_from": if f.from_gcv { "gcv" } else { "given" },
                "sigma": f.sigma,
                "edf": f.edf,
                "se_position": f.se[0],
                "se_velocity": f.se[1],
                "se_acceleration": f.se[2],
                "boundary": f.boundary,
            })
        })
        .collect();
    let span = k.t.last().copied().unwrap_or(0.0) - k.t.first().copied().unwrap_or(0.0);
    json!({
        "samples": k.t.len(),
        "smoothing": fits,
        "boundary": k.boundary,
        "band_valid": 2.0 * k.boundary < span,
        "band": "standard errors from the residual noise (interior, bias excluded); ±2 se is a 95 % band",
    })
}

/// The text summary of kinematics from samples.
pub fn kin_summary_text(k: &KinData) -> String {
    let mut out = format!(
        "{} samples, t = {} .. {}\n",
        k.t.len(),
        k.t[0],
        k.t[k.t.len() - 1]
    );
    out += "smoothing spline per coordinate (standard errors in the interior):\n";
    for f in &k.fits {
        out += &format!(
            "  {}: λ = {:.4e} ({}), noise σ = {:.4e}, edf = {:.1}, se(position) = {:.3e}, se(velocity) = {:.3e}, se(acceleration) = {:.3e}, boundary {:.4}\n",
            f.name,
            f.lambda,
            if f.from_gcv { "GCV" } else { "given" },
            f.sigma,
            f.edf,
            f.se[0],
            f.se[1],
            f.se[2],
            f.boundary
        );
    }
    let span = k.t[k.t.len() - 1] - k.t[0];
    out += &format!(
        "the standard errors (columns se_*) hold farther than {:.4} from either end; ±2 se is a 95 % band for the noise (smoothing bias excluded)\n",
        k.boundary
    );
    if 2.0 * k.boundary >= span {
        out += "warning: a coordinate's smoothing spans the whole record (a straight line, too few samples, or λ too large): its standard errors are those of the interior formula, not of a line fit; the others hold beyond their own boundary\n";
    }
    out
}

/// Integration of sampled acceleration: one result per axis.
#[derive(Clone, Debug)]
pub struct AccelResult {
    /// Sample times.
    pub t: Vec<f64>,
    /// Axis names (from the acceleration columns: `ax` → `x`).
    pub axes: Vec<String>,
    /// One result per axis.
    pub integrated: Vec<Integrated>,
}

/// The axis named by an acceleration column: `ax` → `x`, `a_y` → `y`, otherwise the name.
pub fn axis_name(column: &str) -> String {
    let s = column
        .strip_prefix("a_")
        .or_else(|| column.strip_prefix('a'))
        .filter(|s| !s.is_empty())
        .unwrap_or(column);
    s.to_string()
}

/// Integrates every acceleration column of `series` with `options` (one `v0`/`x0` per axis;
/// an empty list means zeros).
pub fn integrate_accel(
    series: &Series,
    base: &AccelOptions,
    v0: &[f64],
    x0: &[f64],
) -> Result<AccelResult, Error> {
    let n_axes = series.values.len();
    for (flag, vals) in [("--v0", v0), ("--x0", x0)] {
        if !vals.is_empty() && vals.len() != n_axes {
            return Err(Error::argument(
                flag,
                format!(
                    "{} value(s) for {n_axes} axis(es) ({})",
                    vals.len(),
                    series.names.join(", ")
                ),
            ));
        }
    }
    let mut out = AccelResult {
        t: series.t.clone(),
        axes: Vec::new(),
        integrated: Vec::new(),
    };
    for (k, (name, a)) in series.names.iter().zip(&series.values).enumerate() {
        let o = AccelOptions {
            v0: v0.get(k).copied().unwrap_or(0.0),
            x0: x0.get(k).copied().unwrap_or(0.0),
            ..*base
        };
        out.axes.push(axis_name(name));
        out.integrated
            .push(pdyn_data::integrate::integrate(&series.t, a, &o, name).map_err(data_error)?);
    }
    Ok(out)
}

/// The table of an integration: `t`, then per axis `x`, `v_x`, `sigma_x`, `sigma_v_x`.
pub fn accel_table(r: &AccelResult) -> Table {
    let mut t = Table::default();
    t.push("t", r.t.clone());
    for (name, i) in r.axes.iter().zip(&r.integrated) {
        t.push(name.clone(), i.x.clone());
        t.push(format!("v_{name}"), i.v.clone());
        t.push(format!("sigma_{name}"), i.sigma_x.clone());
        t.push(format!("sigma_v_{name}"), i.sigma_v.clone());
    }
    t
}

/// The JSON summary of an integration.
pub fn accel_summary(r: &AccelResult, o: &AccelOptions) -> serde_json::Value {
    let axes: Vec<serde_json::Value> = r
        .axes
        .iter()
        .zip(&r.integrated)
        .map(|(name, i)| {
            json!({
                "axis": name,
                "bias_removed": i.bias,
                "bias_se": i.bias_se,
                "sigma_a": i.sigma_a,
                "sigma_a_from": i.sigma_a_source,
                "final_position": i.x.last(),
                "final_velocity": i.v.last(),
                "sigma_position_final": i.sigma_x.last(),
                "sigma_velocity_final": i.sigma_v.last(),
            })
        })
        .collect();
    json!({
        "samples": r.t.len(),
        "rule": match o.rule { pdyn_data::integrate::Rule::Trapezoid => "trapezoid", pdyn_data::integrate::Rule::Simpson => "simpson" },
        "bias": bias_text(o.bias),
        "axes": axes,
        "error_growth": "sigma_x(t) = sqrt(sigma_a^2 t^3/(3 f_s) + (b_se t^2/2)^2 - correlation with the bias estimate); a bias error b grows as b t^2/2",
    })
}

fn bias_text(b: pdyn_data::integrate::Bias) -> String {
    use pdyn_data::integrate::Bias;
    match b {
        Bias::None => "none".into(),
        Bias::Mean => "mean".into(),
        Bias::Quiet(a, b) => format!("quiet {a}..{b}"),
        Bias::Value(v) => format!("{v}"),
    }
}

/// The text summary of an integration.
pub fn accel_summary_text(r: &AccelResult, o: &AccelOptions) -> String {
    let n = r.t.len();
    let mut out = format!(
        "{n} samples, t = {} .. {}; rule {}; bias removal: {}\n",
        r.t[0],
        r.t[n - 1],
        match o.rule {
            pdyn_data::integrate::Rule::Trapezoid => "trapezoid (2nd order)",
            pdyn_data::integrate::Rule::Simpson => "simpson (4th order)",
        },
        bias_text(o.bias)
    );
    for (name, i) in r.axes.iter().zip(&r.integrated) {
        out += &format!(
            "  {name}: bias removed {:.6e} (se {:.2e}); σ_a = {:.4e} ({}); at the end {name} = {} ± {:.3e}, v_{name} = {} ± {:.3e}\n",
            i.bias,
            i.bias_se,
            i.sigma_a,
            i.sigma_a_source,
            i.x[n - 1],
            i.sigma_x[n - 1],
            i.v[n - 1],
            i.sigma_v[n - 1]
        );
    }
    out += "error growth: noise σ_a integrates to σ_x(t) = σ_a t^(3/2)/√(3 f_s); a bias error b adds b t²/2 (columns sigma_*)\n";
    out
}

/// `--bias`: `none`, `mean`, `T0..T1` (a quiet interval) or a value.
pub fn parse_bias(text: &str) -> Result<pdyn_data::integrate::Bias, Error> {
    use pdyn_data::integrate::Bias;
    let t = text.trim();
    let bad = || {
        Error::argument(
            "--bias",
            format!("`{t}` is not `none`, `mean`, a quiet interval `T0..T1` or a bias value"),
        )
    };
    match t {
        "none" => Ok(Bias::None),
        "mean" => Ok(Bias::Mean),
        _ => {
            if let Some((a, b)) = t.split_once("..") {
                let (a, b) = (a.trim().parse::<f64>(), b.trim().parse::<f64>());
                match (a, b) {
                    (Ok(a), Ok(b)) if a.is_finite() && b.is_finite() && a < b => {
                        Ok(Bias::Quiet(a, b))
                    }
                    _ => Err(bad()),
                }
            } else {
                match t.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(Bias::Value(v)),
                    _ => Err(bad()),
                }
            }
        }
    }
}

/// Fuses the accelerometer file with the fixes file.
pub fn fuse_files(
    accel: &Path,
    fixes: &Path,
    accel_columns: &[String],
    fix_columns: &[String],
    noise: &Noise,
) -> Result<(Fused, Vec<String>), Error> {
    let a = read_series(accel, accel_columns, DataKind::Acceleration, 2, "fusion")?;
    let f = read_series(fixes, fix_columns, DataKind::Position, 1, "fusion")?;
    // Position defaults are t,x,y[,z]: match the accelerometer's number of axes.
    let f = if fix_columns.is_empty() && f.values.len() > a.values.len() {
        Series {
            t: f.t,
            names: f.names[..a.values.len()].to_vec(),
            values: f.values[..a.values.len()].to_vec(),
        }
    } else {
        f
    };
    let result = pdyn_data::fusion::fuse(&a.t, &a.values, &f.t, &f.values, noise, false).map_err(
        |mut e| {
            // The library does not know the files: name the fixes' (its time range is the
            // usual problem) or the pair.
            if e.file.is_empty() {
                e.file = format!("{} + {}", accel.display(), fixes.display());
            }
            data_error(e)
        },
    )?;
    Ok((result, f.names))
}

/// The table of a fusion: `t`, then per axis `x`, `v_x`, `bias_x`, `sd_x`, `sd_v_x`,
/// `sd_bias_x`, `x_filtered`.
pub fn fuse_table(f: &Fused, names: &[String]) -> Table {
    let mut t = Table::default();
    t.push("t", f.t.clone());
    for (n, a) in names.iter().zip(&f.axes) {
        t.push(n.clone(), a.p.clone());
        t.push(format!("v_{n}"), a.v.clone());
        t.push(format!("bias_{n}"), a.b.clone());
        t.push(format!("sd_{n}"), a.sd[0].clone());
        t.push(format!("sd_v_{n}"), a.sd[1].clone());
        t.push(format!("sd_bias_{n}"), a.sd[2].clone());
        t.push(format!("{n}_filtered"), a.p_filtered.clone());
    }
    t
}

/// The JSON summary of a fusion.
pub fn fuse_summary(f: &Fused, names: &[String]) -> serde_json::Value {
    let mid = f.t.len() / 2;
    let axes: Vec<serde_json::Value> = names
        .iter()
        .zip(&f.axes)
        .map(|(n, a)| {
            json!({
                "axis": n,
                "bias_mid": a.b.get(mid),
                "sd_bias_mid": a.sd[2].get(mid),
                "sd_position_mid": a.sd[0].get(mid),
            })
        })
        .collect();
    json!({
        "samples": f.t.len(),
        "sigma_a": f.sigma_a,
        "sigma_a_from": if f.estimated[0] { "second differences of the accelerometer" } else { "given" },
        "sigma_p": f.sigma_p,
        "sigma_p_from": if f.estimated[1] { "maximum likelihood of the innovations" } else { "given" },
        "sigma_b": f.sigma_b,
        "log_likelihood": f.log_likelihood,
        "normalized_innovations": f.innovation_nis,
        "axes": axes,
    })
}

/// The text summary of a fusion.
pub fn fuse_summary_text(f: &Fused, names: &[String]) -> String {
    let n = f.t.len();
    let mut out = format!(
        "Kalman filter + RTS smoother, {n} accelerometer samples, t = {} .. {}\n",
        f.t[0],
        f.t[n - 1]
    );
    out += &format!(
        "  σ_a = {:.4e} ({}), σ_p = {:.4e} ({}), σ_b = {:.3e}\n",
        f.sigma_a,
        if f.estimated[0] {
            "second differences"
        } else {
            "given"
        },
        f.sigma_p,
        if f.estimated[1] {
            "maximum likelihood"
        } else {
            "given"
        },
        f.sigma_b
    );
    out += &format!(
        "  innovations: log-likelihood {:.4}, mean normalized square {:.3} (≈ 1 when the noise levels fit)\n",
        f.log_likelihood, f.innovation_nis
    );
    let mid = n / 2;
    for (name, a) in names.iter().zip(&f.axes) {
        out += &format!(
            "  {name}: bias ≈ {:.4e} ± {:.2e}; position sd at mid-record {:.3e}\n",
            a.b[mid], a.sd[2][mid], a.sd[0][mid]
        );
    }
    out
}

/// Forgets which data columns a previous run asked for outside their range (before a run).
pub fn reset_data_range(model: &pdyn_mech::Model) {
    for column in pdyn_mech::model::data::columns(&model.pool) {
        column.reset();
    }
}

/// A failed run that asked a `[data.NAME]` column outside its time range, as the error to
/// report instead of the integrator's (which only saw NaN): the column, its file, the time
/// and the data's range.
pub fn left_data_range(model: &pdyn_mech::Model) -> Option<Error> {
    let (column, t) = pdyn_mech::model::data::left_range(&model.pool)?;
    let message = pdyn_mech::model::data::left_range_message(column, t);
    Some(Error::Data {
        error: Box::new(DataError::new(&column.file, message).help(
            "end the run within the data (--t-end, [simulate] t_end) or extend the record: \
             data say nothing outside their samples",
        )),
    })
}

#[cfg(test)]
mod table_tests {
    use super::Table;

    /// Written in blocks on several threads, the CSV is the rows in order, each number in
    /// shortest round-trip form, `inf`/`NaN` as such: the same text row by row.
    #[test]
    fn a_table_over_several_blocks_is_written_in_order() {
        let n = 3 * super::ROWS_PER_BLOCK + 17;
        let mut t = Table::default();
        t.push("i", (0..n).map(|i| i as f64).collect());
        t.push(
            "v",
            (0..n)
                .map(|i| match i % 1000 {
                    7 => f64::INFINITY,
                    8 => f64::NAN,
                    _ => 1.0 / (i as f64 + 0.5),
                })
                .collect(),
        );
        let text = t.to_csv();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("i,v"));
        let mut count = 0;
        for (i, line) in lines.enumerate() {
            let (a, b) = line.split_once(',').unwrap();
            assert_eq!(a.parse::<f64>().unwrap(), i as f64, "row {i}");
            match i % 1000 {
                7 => assert_eq!(b, "inf"),
                8 => assert_eq!(b, "NaN"),
                _ => assert_eq!(b.parse::<f64>().unwrap(), 1.0 / (i as f64 + 0.5), "row {i}"),
            }
            count += 1;
        }
        assert_eq!(count, n);
    }
}
