//! Time series from Parquet files (pandas' `to_parquet`, polars, Arrow, Spark...).
//!
//! Only flat columns of numbers are read: `DOUBLE`, `FLOAT`, `INT32` and `INT64` (integers up to
//! 2^53, which convert to `f64` exactly), compressed or not (Snappy, gzip, LZ4, Zstandard: the
//! codecs pandas, polars and Spark write by default). Everything else asked for is refused by
//! name with what would be valid: text, booleans, nested lists, timestamps (a time column must
//! hold seconds as numbers: pdyn does not guess an epoch). As with CSV, every value must be a
//! finite number: a null or a NaN is an error naming the column and the row (1-based, counted
//! from the first row of the file, as pandas' `df.iloc[row - 1]`).
//!
//! The result is the [`Columns`] a CSV file gives, so the checks that follow (increasing
//! times, enough rows) and their messages are the same; a location is a row, not a line.

use crate::csv::Columns;
use crate::error::DataError;
use bytes::Bytes;
use parquet::basic::{LogicalType, Type as PhysicalType};
use parquet::column::reader::ColumnReader;
use parquet::file::reader::{FileReader, SerializedFileReader};

/// The most rows read: 2^28 (2 GB of `f64` per column), checked before allocating.
const MAX_ROWS: usize = 1 << 28;

/// Records read per call: large enough to amortise the calls, small enough to stay in cache.
const BATCH: usize = 8192;

/// The file's footer and schema, or a located error.
fn open(file: &str, bytes: Bytes) -> Result<SerializedFileReader<Bytes>, DataError> {
    SerializedFileReader::new(bytes).map_err(|e| {
        DataError::new(file, format!("not a readable Parquet file: {e}"))
            .help("write it with pandas' DataFrame.to_parquet, polars' write_parquet or Arrow; or give a CSV file")
    })
}

/// The names of the file's (leaf) columns, in schema order.
pub fn column_names(file: &str, bytes: &[u8]) -> Result<Vec<String>, DataError> {
    let reader = open(file, Bytes::copy_from_slice(bytes))?;
    let schema = reader.metadata().file_metadata().schema_descr();
    Ok(schema.columns().iter().map(|c| c.path().string()).collect())
}

/// Reads the columns `wanted` (all of them when empty) of the Parquet file `bytes`, named
/// `file` in messages.
pub fn read_columns(file: &str, bytes: &[u8], wanted: &[&str]) -> Result<Columns, DataError> {
    let reader = open(file, Bytes::copy_from_slice(bytes))?;
    let meta = reader.metadata();
    let schema = meta.file_metadata().schema_descr();
    let names: Vec<String> = schema.columns().iter().map(|c| c.path().string()).collect();
    let wanted: Vec<String> = if wanted.is_empty() {
        names.clone()
    } else {
        wanted.iter().map(|s| s.to_string()).collect()
    };
    let index = crate::csv::column_indices(file, &names, &wanted, None)?;
    for (k, &i) in index.iter().enumerate() {
        check_numeric(file, &wanted[k], schema.column(i).as_ref())?;
    }
    let rows = usize::try_from(meta.file_metadata().num_rows()).unwrap_or(0);
    if rows > MAX_ROWS {
        return Err(DataError::new(
            file,
            format!("the file has {rows} rows; pdyn reads at most {MAX_ROWS} (2 GB per column)"),
        )
        .help("read a part of the record (filter the rows first), or decimate it"));
    }
    if rows == 0 {
        return Err(DataError::new(file, "the file has columns but no rows")
            .help("write one row per sample"));
    }
    // The footer's count is checked against the values read, so it only sizes the start.
    let mut values: Vec<Vec<f64>> = (0..wanted.len())
        .map(|_| Vec::with_capacity(rows.min(1 << 20)))
        .collect();
    for g in 0..meta.num_row_groups() {
        let group = reader
            .get_row_group(g)
            .map_err(|e| DataError::new(file, format!("row group {g}: {e}")))?;
        for (k, &i) in index.iter().enumerate() {
            let column = group
                .get_column_reader(i)
                .map_err(|e| DataError::new(file, format!("column `{}`: {e}", wanted[k])))?;
            let max_def = schema.column(i).max_def_level();
            let first_row = values[k].len();
            read_column(column, max_def, &mut values[k]).map_err(|failure| {
                let row = first_row + failure.index + 1;
                let e = DataError::new(file, format!("row {row}: {}", failure.message))
                    .column_name(&wanted[k]);
                match failure.value {
                    Some(v) => e.text(&v.to_string()),
                    None => e,
                }
                .help(
                    "every row needs a finite number in every column used; a measurement that \
                     is missing must be removed, not written as null or NaN (pdyn does not guess \
                     values)",
                )
            })?;
        }
    }
    if values.iter().any(|v| v.len() != rows) {
        return Err(DataError::new(
            file,
            format!(
                "the footer says {rows} rows, but the columns hold {}",
                values
                    .iter()
                    .map(|v| v.len().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
        .help("the file is damaged or was cut short: write it again"));
    }
    Ok(Columns::of_records(file, wanted, values))
}

/// Refuses a column that does not hold plain numbers, saying what would be valid.
fn check_numeric(
    file: &str,
    name: &str,
    column: &parquet::schema::types::ColumnDescriptor,
) -> Result<(), DataError> {
    let refuse = |what: &str, help: &str| {
        Err(
            DataError::new(file, format!("the column holds {what}, not numbers"))
                .column_name(name)
                .help(help.to_string()),
        )
    };
    if column.max_rep_level() > 0 {
        return refuse(
            "lists (a repeated field)",
            "store one number per row and column (a flat table)",
        );
    }
    match column.logical_type_ref() {
        Some(LogicalType::Timestamp(_) | LogicalType::Date | LogicalType::Time(_)) => {
            return refuse(
                "dates or times of day",
                "store the time as seconds (a number) from the start of the record, e.g. \
                 (df.time - df.time[0]).dt.total_seconds() in pandas",
            )
        }
        Some(LogicalType::Decimal(_)) => {
            return refuse(
                "decimals",
                "store the values as floating-point numbers (float64)",
            )
        }
        Some(LogicalType::Integer(int)) if !int.is_signed && int.bit_width == 64 => {
            return refuse(
                "unsigned 64-bit integers",
                "store the values as float64 or int64",
            )
        }
        _ => {}
    }
    match column.physical_type() {
        PhysicalType::DOUBLE | PhysicalType::FLOAT | PhysicalType::INT32 | PhysicalType::INT64 => {
            Ok(())
        }
        PhysicalType::BOOLEAN => refuse("booleans", "store the values as numbers"),
        PhysicalType::BYTE_ARRAY => refuse(
            "text",
            "store the values as numbers (e.g. pd.to_numeric in pandas); text columns the model \
             does not use may stay",
        ),
        other => refuse(
            &format!("values of Parquet type {other}"),
            "store the values as float64 (or int32/int64)",
        ),
    }
}

/// A value that is not a finite number: its index in the column chunk, what is wrong, and the
/// value when there is one.
struct Bad {
    index: usize,
    message: String,
    value: Option<f64>,
}

/// Appends the values of one column chunk to `out`, checking each.
fn read_column(column: ColumnReader, max_def: i16, out: &mut Vec<f64>) -> Result<(), Bad> {
    let start = out.len();
    let mut defs: Vec<i16> = Vec::new();
    match column {
        ColumnReader::DoubleColumnReader(mut r) => {
            read_typed(&mut r, &mut defs, max_def, out, start, |v: f64| Ok(v))
        }
        ColumnReader::FloatColumnReader(mut r) => {
            read_typed(&mut r, &mut defs, max_def, out, start, |v: f32| {
                Ok(f64::from(v))
            })
        }
        ColumnReader::Int32ColumnReader(mut r) => {
            read_typed(&mut r, &mut defs, max_def, out, start, |v: i32| {
                Ok(f64::from(v))
            })
        }
        ColumnReader::Int64ColumnReader(mut r) => {
            read_typed(&mut r, &mut defs, max_def, out, start, |v: i64| {
                // 2^53: beyond it not every integer has an f64.
                if v.unsigned_abs() <= 1 << 53 {
                    Ok(v as f64)
                } else {
                    Err(format!(
                        "the integer {v} is too large to be a floating-point number exactly"
                    ))
                }
            })
        }
        // Refused before reading by `check_numeric`.
        _ => Err(Bad {
            index: 0,
            message: "the column does not hold numbers".into(),
            value: None,
        }),
    }
}

/// Reads a typed column chunk in batches: nulls (a definition level below `max_def`) and
/// values that are not finite are errors at their index.
fn read_typed<T: parquet::data_type::DataType>(
    reader: &mut parquet::column::reader::ColumnReaderImpl<T>,
    defs: &mut Vec<i16>,
    max_def: i16,
    out: &mut Vec<f64>,
    start: usize,
    convert: impl Fn(T::T) -> Result<f64, String>,
) -> Result<(), Bad>
where
    T::T: Clone,
{
    let mut buffer: Vec<T::T> = Vec::with_capacity(BATCH);
    loop {
        buffer.clear();
        defs.clear();
        let levels = if max_def > 0 { Some(&mut *defs) } else { None };
        let (records, _, _) = reader
            .read_records(BATCH, levels, None, &mut buffer)
            .map_err(|e| Bad {
                index: out.len() - start,
                message: format!("cannot be decoded: {e}"),
                value: None,
            })?;
        if records == 0 {
            return Ok(());
        }
        if max_def > 0 {
            if let Some(k) = defs.iter().position(|&d| d < max_def) {
                return Err(Bad {
                    index: out.len() - start + k,
                    message: "missing value (null)".into(),
                    value: None,
                });
            }
        }
        for v in buffer.drain(..) {
            let index = out.len() - start;
            let x = convert(v).map_err(|message| Bad {
                index,
                message,
                value: None,
            })?;
            if !x.is_finite() {
                return Err(Bad {
                    index,
                    message: if x.is_nan() {
                        "the value is NaN (not a number)".into()
                    } else {
                        "the value is infinite".into()
                    },
                    value: Some(x),
                });
            }
            out.push(x);
        }
    }
}
