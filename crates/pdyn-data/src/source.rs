//! A data file as it arrives: CSV text or a Parquet file, told apart by its bytes (Parquet's
//! `PAR1` at both ends), not by its name. Everything that reads measured data (`[data.NAME]`
//! tables, `pdyn kin --data`, `pdyn fuse`, `pdyn fit --data`) goes through [`Source`], so each
//! takes both formats with the same checks and messages.

use crate::csv::{self, Columns};
use crate::error::DataError;

/// The contents of a data file.
#[derive(Clone, Debug)]
pub enum Source {
    /// CSV text (UTF-8).
    Csv(String),
    /// A Parquet file's bytes.
    Parquet(Vec<u8>),
}

impl Source {
    /// The file's bytes as CSV text or Parquet. Text that is not UTF-8 is an error at the line
    /// and column of the first bad byte.
    pub fn from_bytes(file: &str, bytes: Vec<u8>) -> Result<Source, DataError> {
        if is_parquet(&bytes) {
            return Ok(Source::Parquet(bytes));
        }
        String::from_utf8(bytes).map(Source::Csv).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let before = &e.as_bytes()[..at];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let line_start = before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1);
            let column = String::from_utf8_lossy(&before[line_start..])
                .chars()
                .count()
                + 1;
            DataError::new(
                file,
                format!("the byte 0x{:02X} is not UTF-8", e.as_bytes()[at]),
            )
            .at(line, Some(column))
            .help("save the file as UTF-8 (or ASCII) text, or as Parquet")
        })
    }

    /// The names of the file's columns, and the line of a CSV file's header (`None` for
    /// Parquet, whose columns are named in its footer).
    pub fn header(&self, file: &str) -> Result<(Option<usize>, Vec<String>), DataError> {
        match self {
            Source::Csv(text) => {
                let (line, names) = csv::header(text);
                Ok((Some(line), names))
            }
            Source::Parquet(bytes) => Ok((None, crate::parquet::column_names(file, bytes)?)),
        }
    }

    /// The columns `wanted` (every column when empty), each value a finite number.
    pub fn read_columns(&self, file: &str, wanted: &[&str]) -> Result<Columns, DataError> {
        match self {
            Source::Csv(text) => csv::read_columns(file, text, wanted),
            Source::Parquet(bytes) => crate::parquet::read_columns(file, bytes, wanted),
        }
    }
}

/// The first and last four bytes of every Parquet file.
const PARQUET_MAGIC: &[u8; 4] = b"PAR1";

/// Whether `bytes` look like a Parquet file (the magic at both ends).
pub fn is_parquet(bytes: &[u8]) -> bool {
    bytes.len() >= 12 && bytes.starts_with(PARQUET_MAGIC) && bytes.ends_with(PARQUET_MAGIC)
}
