//! Parquet on `wasm32`: not built (the page reads no files, and the codecs include C code).
//! The functions of `parquet.rs` with a clear refusal.

use crate::csv::Columns;
use crate::error::DataError;

fn refusal(file: &str) -> DataError {
    DataError::new(
        file,
        "Parquet files cannot be read in this build (WebAssembly)",
    )
    .help("give the data as CSV, or run the model with the pdyn command or Python")
}

/// The names of the file's columns: refused.
pub fn column_names(file: &str, _bytes: &[u8]) -> Result<Vec<String>, DataError> {
    Err(refusal(file))
}

/// The file's columns: refused.
pub fn read_columns(file: &str, _bytes: &[u8], _wanted: &[&str]) -> Result<Columns, DataError> {
    Err(refusal(file))
}
