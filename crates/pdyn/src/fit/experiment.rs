//! Measured runs to fit: a time column and columns named as the model's state.
//!
//! A column named as a coordinate (`x`) is a measured position, one named as a coordinate
//! followed by `'` (`x'`) a measured rate; a column `sigma_x` (`sigma_x'`) beside it gives
//! each sample's standard deviation (its weight is `1/σ`). The time column is `t`. Other
//! columns are not read. Times must increase strictly and start at or after the model's
//! initial time 0.

use crate::data::data_error;
use crate::Error;
use pdyn_data::source::Source;
use pdyn_data::DataError;
use std::path::Path;

/// One measured quantity of an experiment.
#[derive(Clone, Debug)]
pub struct Observed {
    /// The state component's name (`x`, `x'`).
    pub name: String,
    /// The measured values, one per time.
    pub values: Vec<f64>,
    /// Each value's standard deviation, when given per sample.
    pub sigma: Option<Vec<f64>>,
}

/// One experiment: the same model run once, measured at `t`.
#[derive(Clone, Debug)]
pub struct Experiment {
    /// Its name (the file's stem): free initial values are named with it when there are
    /// several experiments (`initial.x[run2]`).
    pub name: String,
    /// Where it came from (the file), for messages.
    pub origin: String,
    /// Sample times (strictly increasing, ≥ 0).
    pub t: Vec<f64>,
    /// The measured columns.
    pub observed: Vec<Observed>,
}

/// The names of a model's state, as derived: each coordinate solved for (`x`), then their
/// rates (`x'`).
pub fn state_names(model: &pdyn_mech::Model) -> Vec<String> {
    let free: Vec<&str> = model
        .coordinates
        .iter()
        .filter(|c| matches!(c.kind, pdyn_mech::model::CoordinateKind::Free { .. }))
        .map(|c| c.name.as_str())
        .collect();
    let mut names: Vec<String> = free.iter().map(|s| s.to_string()).collect();
    names.extend(free.iter().map(|s| format!("{s}'")));
    names
}

/// Reads an experiment from CSV text: `t`, then every column named as a state component
/// (`state_names`), with `sigma_NAME` columns as their standard deviations.
pub fn from_csv(file: &str, text: &str, state_names: &[String]) -> Result<Experiment, Error> {
    from_source(file, &Source::Csv(text.to_string()), state_names)
}

/// Reads an experiment from a data file's contents (CSV or Parquet), as [`from_csv`].
pub fn from_source(
    file: &str,
    source: &Source,
    state_names: &[String],
) -> Result<Experiment, Error> {
    let (header_line, names) = source.header(file).map_err(data_error)?;
    let at_header = |e: DataError| match header_line {
        Some(line) => e.at(line, None),
        None => e,
    };
    let listed = || {
        names
            .iter()
            .map(|h| format!("`{h}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !names.iter().any(|h| h == "t") {
        return Err(data_error(
            at_header(DataError::new(file, "no column named `t` (the time)"))
                .help(format!("the header has {}", listed())),
        ));
    }
    let measured: Vec<&String> = names
        .iter()
        .filter(|h| state_names.iter().any(|s| s == *h))
        .collect();
    if measured.is_empty() {
        return Err(data_error(
            at_header(DataError::new(
                file,
                format!(
                    "no column is named as a coordinate or rate of the model ({})",
                    state_names
                        .iter()
                        .map(|s| format!("`{s}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ))
            .help(format!(
                "name the measured columns as the model's coordinates (`x`) or rates (`x'`); \
                 the header has {}",
                listed()
            )),
        ));
    }
    let mut wanted: Vec<String> = vec!["t".into()];
    for m in &measured {
        wanted.push((*m).clone());
        let s = format!("sigma_{m}");
        if names.contains(&s) {
            wanted.push(s);
        }
    }
    let w: Vec<&str> = wanted.iter().map(String::as_str).collect();
    let cols = source.read_columns(file, &w).map_err(data_error)?;
    if cols.is_empty() {
        return Err(data_error(at_header(DataError::new(
            file,
            "the file has a header but no data rows",
        ))));
    }
    let t = cols.values[0].clone();
    if t[0] < 0.0 {
        return Err(data_error(cols.error_at(
            0,
            0,
            "the time is before the model's initial time 0 (the initial conditions hold at t = 0)",
        )));
    }
    for i in 1..t.len() {
        if t[i] <= t[i - 1] {
            let msg = if t[i] == t[i - 1] {
                format!(
                    "duplicate time {} (the previous row has the same time)",
                    t[i]
                )
            } else {
                format!(
                    "time {} comes after the larger time {}: the times are not sorted",
                    t[i],
                    t[i - 1]
                )
            };
            return Err(data_error(cols.error_at(i, 0, msg)));
        }
    }
    let mut observed = Vec::new();
    for (c, name) in cols.names.iter().enumerate().skip(1) {
        if let Some(of) = name.strip_prefix("sigma_") {
            if let Some(o) = observed.iter_mut().find(|o: &&mut Observed| o.name == of) {
                for (i, &s) in cols.values[c].iter().enumerate() {
                    if s <= 0.0 {
                        return Err(data_error(cols.error_at(
                            i,
                            c,
                            "a standard deviation must be positive",
                        )));
                    }
                }
                o.sigma = Some(cols.values[c].clone());
                continue;
            }
        }
        observed.push(Observed {
            name: name.clone(),
            values: cols.values[c].clone(),
            sigma: None,
        });
    }
    let name = Path::new(file)
        .file_stem()
        .map_or_else(|| file.to_string(), |s| s.to_string_lossy().into_owned());
    Ok(Experiment {
        name,
        origin: file.to_string(),
        t,
        observed,
    })
}

/// Reads an experiment from a data file (CSV or Parquet).
pub fn read(path: &Path, state_names: &[String]) -> Result<Experiment, Error> {
    let source = crate::data::read_source(path)?;
    from_source(&path.display().to_string(), &source, state_names)
}

/// An experiment from arrays (Python's): `columns` named as the state (`x`, `x'`) or as their
/// standard deviations (`sigma_x`); checked as a file is (finite values, strictly increasing
/// times from 0 on), problems located by index.
pub fn from_arrays(
    name: &str,
    t: Vec<f64>,
    columns: Vec<(String, Vec<f64>)>,
    state_names: &[String],
) -> Result<Experiment, Error> {
    let (names, values): (Vec<String>, Vec<Vec<f64>>) = columns.into_iter().unzip();
    let series =
        pdyn_data::csv::Series::from_arrays(t, names, values, 1, "a fit").map_err(data_error)?;
    if series.t[0] < 0.0 {
        return Err(data_error(DataError::new(
            name,
            format!(
                "at index 0: the time {} is before the model's initial time 0",
                series.t[0]
            ),
        )));
    }
    let mut observed: Vec<Observed> = Vec::new();
    for (n, v) in series.names.iter().zip(&series.values) {
        if state_names.contains(n) {
            observed.push(Observed {
                name: n.clone(),
                values: v.clone(),
                sigma: None,
            });
        }
    }
    for (n, v) in series.names.iter().zip(&series.values) {
        if let Some(of) = n.strip_prefix("sigma_") {
            let Some(o) = observed.iter_mut().find(|o| o.name == of) else {
                continue;
            };
            if let Some(i) = v.iter().position(|&s| s <= 0.0) {
                return Err(data_error(DataError::new(
                    name,
                    format!("`{n}` at index {i}: a standard deviation must be positive"),
                )));
            }
            o.sigma = Some(v.clone());
        } else if !state_names.contains(n) {
            return Err(data_error(DataError::new(
                name,
                format!(
                    "`{n}` is not a coordinate or rate of the model (the state is {})",
                    state_names.join(", ")
                ),
            )));
        }
    }
    if observed.is_empty() {
        return Err(data_error(DataError::new(
            name,
            format!(
                "no column is named as a coordinate or rate of the model ({})",
                state_names.join(", ")
            ),
        )));
    }
    Ok(Experiment {
        name: name.to_string(),
        origin: name.to_string(),
        t: series.t,
        observed,
    })
}
