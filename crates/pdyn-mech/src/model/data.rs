//! `[data.NAME]`: a measured time series read from a CSV or Parquet file, each of its columns a
//! function of time in the model's expressions (`NAME_COLUMN(t)`, or of any argument).
//!
//! The file is read with `pdyn_data::source` (CSV or Parquet, told by its bytes; every value a finite number, times strictly
//! increasing, problems located by file, line and column) and each column interpolated with
//! `pdyn_data::interp` (linear, natural cubic or PCHIP). The interpolants are registered in
//! the model's expression pool as tabulated functions ([`pdyn_expr::tabulated`]), so that
//! derivatives (`d/dt ground_a(t) = ground_a'(t)`), compiled programs and native code see
//! them like any other function. Outside the data's time range a column is NaN, and the
//! first argument that fell outside is kept ([`DataColumn::left_range`]) for the run to
//! report.

use super::raw::{Name, RawData, RawModel};
use super::{Loader, ModelError};
use pdyn_data::interp::{Interpolant, Kind};
use pdyn_data::source::Source;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// One column of a `[data.NAME]` table as a tabulated function.
#[derive(Debug)]
pub struct DataColumn {
    /// The function's name in expressions (`ground_a`).
    pub name: String,
    /// The data file, as the model names it (for messages).
    pub file: String,
    interpolant: Interpolant,
    /// The bits of the argument met outside the range nearest to it (`NO_EXCURSION` until
    /// then).
    excursion: AtomicU64,
}

/// No argument has left the range yet (a NaN's bits, never an argument that was compared).
const NO_EXCURSION: u64 = u64::MAX;

/// Arguments this close to an end (relative to the span) count as the end: an integrator's
/// last step may land an ulp past `t_end`.
const END_SLACK: f64 = 1e-12;

impl DataColumn {
    /// The data's first and last times.
    pub fn range(&self) -> (f64, f64) {
        self.interpolant.range()
    }

    /// The argument nearest the range at which the column was asked for outside it, if any.
    pub fn left_range(&self) -> Option<f64> {
        let bits = self.excursion.load(Ordering::Relaxed);
        (bits != NO_EXCURSION).then(|| f64::from_bits(bits))
    }

    /// Forgets a recorded excursion (before a new run).
    pub fn reset(&self) {
        self.excursion.store(NO_EXCURSION, Ordering::Relaxed);
    }
}

impl pdyn_expr::Tabulated for DataColumn {
    fn eval(&self, order: u8, x: f64) -> f64 {
        if let Some(v) = self.interpolant.derivative(order, x) {
            return v;
        }
        let (t0, t1) = self.interpolant.range();
        let slack = END_SLACK * (t1 - t0);
        if x >= t0 - slack && x < t0 {
            return self.interpolant.derivative(order, t0).unwrap_or(f64::NAN);
        }
        if x > t1 && x <= t1 + slack {
            return self.interpolant.derivative(order, t1).unwrap_or(f64::NAN);
        }
        // The excursion nearest the range is kept: where the run first needed data it
        // did not have (a step-size guess may ask much further out first). A NaN argument
        // is not one: the NaN came from elsewhere and is reported there.
        if !x.is_nan() {
            let distance = |y: f64| if y < t0 { t0 - y } else { y - t1 };
            let _ = self
                .excursion
                .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |old| {
                    (old == NO_EXCURSION || distance(x) < distance(f64::from_bits(old)))
                        .then_some(x.to_bits())
                });
        }
        f64::NAN
    }

    fn degree(&self) -> u8 {
        self.interpolant.degree()
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The data columns registered in `pool` (each `[data.NAME]` column), in file order.
pub fn columns(pool: &pdyn_expr::Pool) -> Vec<&DataColumn> {
    pool.tables()
        .iter()
        .filter_map(|t| t.function.as_any().downcast_ref::<DataColumn>())
        .collect()
}

/// A run that left a data table's time range: the column and the argument outside nearest
/// its range.
pub fn left_range(pool: &pdyn_expr::Pool) -> Option<(&DataColumn, f64)> {
    columns(pool)
        .into_iter()
        .find_map(|c| c.left_range().map(|x| (c, x)))
}

/// The message for a run that asked a data column outside its range.
pub fn left_range_message(column: &DataColumn, x: f64) -> String {
    let (t0, t1) = column.range();
    format!(
        "the run left the time range of the data: `{}` ({}) was needed at t = {x}, but the \
         data cover [{t0}, {t1}]",
        column.name, column.file
    )
}

impl Loader<'_> {
    /// `[data.NAME]` tables: each column registered in the pool as `NAME_COLUMN`.
    pub(super) fn read_data(&mut self, raw: &RawModel) -> Result<(), ModelError> {
        for (name, table) in &raw.data {
            self.read_data_table(raw, name, table)?;
        }
        Ok(())
    }

    fn read_data_table(
        &mut self,
        raw: &RawModel,
        name: &Name,
        table: &toml::Spanned<RawData>,
    ) -> Result<(), ModelError> {
        let t = table.get_ref();
        let Some(file) = &t.file else {
            return Err(self
                .err(name.span(), format!("[data.{}] needs `file`", name.get_ref()))
                .help("file = \"record.csv\": a CSV file with a header line (or a Parquet file), relative to the model file"));
        };
        let kind = match &t.interpolation {
            None => Kind::Linear,
            Some(k) => Kind::parse(k.get_ref()).ok_or_else(|| {
                self.err(
                    k.span(),
                    format!("unknown interpolation `{}`", k.get_ref()),
                )
                .help("interpolation = \"linear\" (the default), \"cubic\" (natural spline) or \"pchip\"")
            })?,
        };
        let time = t
            .time
            .as_ref()
            .map_or_else(|| "t".to_string(), |n| n.get_ref().clone());
        let path = data_path(self.origin, file.get_ref());
        let shown = path.display().to_string();
        let bytes = std::fs::read(&path).map_err(|e| {
            self.err(
                file.span(),
                format!("cannot read the data file {shown}: {e}"),
            )
            .help("the path is relative to the model file's directory")
        })?;
        let mut wanted: Vec<&str> = vec![time.as_str()];
        if let Some(cols) = &t.columns {
            wanted.extend(cols.get_ref().iter().map(|c| c.get_ref().as_str()));
        }
        let all_columns = t.columns.is_none();
        let data_error = |ld: &Loader, e: pdyn_data::DataError| {
            let err = ld.err(file.span(), located(&e));
            if e.message.starts_with("no column named") {
                err.help(
                    "name the time column with `time = \"...\"` and the columns used with \
                     `columns = [...]`",
                )
            } else {
                match e.help {
                    Some(h) => err.help(h),
                    None => err,
                }
            }
        };
        let source = Source::from_bytes(&shown, bytes).map_err(|e| data_error(self, e))?;
        let columns = if all_columns {
            let mut c = source
                .read_columns(&shown, &[])
                .map_err(|e| data_error(self, e))?;
            let Some(i) = c.names.iter().position(|n| *n == time) else {
                let e = c.at_header(pdyn_data::DataError::new(
                    &shown,
                    format!("no column named `{time}` (the time)"),
                ));
                return Err(self
                    .err(file.span(), located(&e))
                    .help("name the time column with `time = \"...\"`"));
            };
            c.move_first(i);
            c
        } else {
            source
                .read_columns(&shown, &wanted)
                .map_err(|e| data_error(self, e))?
        };
        let series = pdyn_data::csv::Series::from_columns(columns, 2, "a [data] table")
            .map_err(|e| data_error(self, e))?;
        if series.names.is_empty() {
            return Err(self
                .err(
                    file.span(),
                    format!("{shown} has no column besides the time `{time}`"),
                )
                .help("a data table needs at least one column of values"));
        }
        for (column, values) in series.names.iter().zip(&series.values) {
            let fname = format!("{}_{}", name.get_ref(), column);
            if !is_function_name(&fname) {
                return Err(self
                    .err(file.span(), format!("the column `{column}` of {shown} gives the function name `{fname}`, which is not a name"))
                    .help("column names are letters, digits and `_` (rename the column in the file's header)"));
            }
            if let Some(kind) = declared_elsewhere(raw, &fname) {
                return Err(self
                    .err(
                        name.span(),
                        format!("the data column `{fname}` has the name of a {kind}"),
                    )
                    .help("rename the data table or the other entry"));
            }
            let interpolant = Interpolant::new(kind, &series.t, values, &shown)
                .map_err(|e| data_error(self, e))?;
            let function = Arc::new(DataColumn {
                name: fname.clone(),
                file: shown.clone(),
                interpolant,
                excursion: AtomicU64::new(NO_EXCURSION),
            });
            self.pool.add_table(&fname, function).map_err(|e| {
                self.err(name.span(), e.to_string())
                    .help("data tables and their columns need names of their own")
            })?;
        }
        Ok(())
    }
}

/// A data error as one line: `file:line:column: message (column `a`, text `x`)`.
pub(super) fn located(e: &pdyn_data::DataError) -> String {
    let mut out = e.file.clone();
    if let Some(line) = e.line {
        out.push_str(&format!(":{line}"));
        if let Some(column) = e.column {
            out.push_str(&format!(":{column}"));
        }
    }
    out.push_str(&format!(": {}", e.message));
    match (&e.column_name, &e.text) {
        (Some(c), Some(t)) => out.push_str(&format!(" (column `{c}`, text `{t}`)")),
        (Some(c), None) => out.push_str(&format!(" (column `{c}`)")),
        (None, Some(t)) => out.push_str(&format!(" (text `{t}`)")),
        (None, None) => {}
    }
    out
}

/// The data file's path: relative to the model file's directory (the working directory for a
/// model given as text).
pub(super) fn data_path(origin: &str, file: &str) -> std::path::PathBuf {
    let file = std::path::Path::new(file);
    if file.is_absolute() {
        return file.to_path_buf();
    }
    match std::path::Path::new(origin).parent() {
        Some(dir) if !origin.starts_with('<') => dir.join(file),
        _ => file.to_path_buf(),
    }
}

pub(super) fn is_function_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_alphabetic() || c == '_')
        && chars.all(|c| c.is_alphanumeric() || c == '_')
}

/// The kind of entry declared under `name` elsewhere in the file, if any.
fn declared_elsewhere(raw: &RawModel, name: &str) -> Option<&'static str> {
    let has =
        |mut keys: indexmap::map::Keys<'_, Name, super::raw::Sv>| keys.any(|k| k.get_ref() == name);
    if has(raw.parameters.keys()) {
        Some("parameter")
    } else if has(raw.coordinates.keys()) {
        Some("coordinate")
    } else if has(raw.definitions.keys()) {
        Some("definition")
    } else if has(raw.points.keys()) {
        Some("point")
    } else if raw.particles.keys().any(|k| k.get_ref() == name) {
        Some("particle")
    } else {
        None
    }
}
