//! Parquet files written by pandas + pyarrow (`tests/fixtures/make_parquet.py`), read back
//! through `Source`: every codec, several row groups, integer and float32 columns, and each
//! kind of bad data located by column and row.
#![allow(clippy::result_large_err)]

use pdyn_data::csv::Series;
use pdyn_data::source::Source;
use pdyn_data::DataError;

fn source(name: &str) -> (String, Source) {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&path).expect("fixture");
    let file = name.to_string();
    let s = Source::from_bytes(&file, bytes).expect("a Parquet or UTF-8 file");
    (file, s)
}

fn series(name: &str, cols: &[&str]) -> Result<Series, DataError> {
    let (file, s) = source(name);
    Series::from_columns(s.read_columns(&file, cols)?, 2, "the test")
}

#[test]
fn every_codec_gives_the_values_pandas_wrote() {
    for codec in ["snappy", "zstd", "gzip", "lz4", "none", "groups"] {
        let name = format!("track_{codec}.parquet");
        let (_, s) = source(&name);
        assert!(matches!(s, Source::Parquet(_)), "{name} told as Parquet");
        let got = series(&name, &["t", "x", "y", "count", "small"]).unwrap();
        assert_eq!(got.t.len(), 100, "{name}");
        assert_eq!(got.names, ["x", "y", "count", "small"]);
        for i in 0..100 {
            let f = i as f64;
            assert_eq!(got.t[i], f / 64.0, "{name} t[{i}]");
            assert_eq!(got.values[0][i], f * f / 8.0, "{name} x[{i}]");
            assert_eq!(got.values[1][i], -f / 4.0, "{name} y[{i}]");
            assert_eq!(got.values[2][i], f, "{name} count[{i}] (int64)");
            assert_eq!(got.values[3][i], f / 2.0, "{name} small[{i}] (float32)");
        }
    }
}

#[test]
fn the_header_lists_every_column_and_a_missing_one_is_named() {
    let (file, s) = source("track_snappy.parquet");
    let (line, names) = s.header(&file).unwrap();
    assert_eq!(line, None);
    assert_eq!(names, ["t", "x", "y", "count", "small", "label"]);
    let e = s.read_columns(&file, &["t", "z"]).unwrap_err();
    assert!(e.message.contains("no column named `z`"), "{e}");
    assert!(e.help.as_deref().unwrap_or("").contains("`label`"), "{e}");
}

#[test]
fn a_text_column_is_refused_only_when_used() {
    let (file, s) = source("track_snappy.parquet");
    assert!(s.read_columns(&file, &["t", "x"]).is_ok());
    let e = s.read_columns(&file, &["t", "label"]).unwrap_err();
    assert!(e.message.contains("holds text"), "{e}");
    assert_eq!(e.column_name.as_deref(), Some("label"));
}

#[test]
fn a_null_is_located_at_its_row_across_row_groups() {
    let e = series("null_row8.parquet", &["t", "x"]).unwrap_err();
    assert!(e.message.starts_with("row 8: missing value (null)"), "{e}");
    assert_eq!(e.column_name.as_deref(), Some("x"));
}

#[test]
fn a_nan_is_located_at_its_row() {
    let e = series("nan_row12.parquet", &["t", "x"]).unwrap_err();
    assert!(e.message.starts_with("row 12: the value is NaN"), "{e}");
    assert_eq!(e.column_name.as_deref(), Some("x"));
}

#[test]
fn times_going_back_are_located_at_their_row() {
    let e = series("unsorted_row51.parquet", &["t", "x"]).unwrap_err();
    assert!(e.message.starts_with("row 51: time 0.5 comes after"), "{e}");
    assert_eq!(e.line, None, "a Parquet file has no lines");
}

#[test]
fn timestamps_are_refused_with_what_to_write_instead() {
    let e = series("timestamps.parquet", &["t", "x"]).unwrap_err();
    assert!(e.message.contains("dates or times"), "{e}");
    assert!(e.help.as_deref().unwrap_or("").contains("seconds"), "{e}");
}

#[test]
fn a_file_without_rows_is_an_error() {
    let e = series("no_rows.parquet", &["t", "x"]).unwrap_err();
    assert!(e.message.contains("no rows"), "{e}");
}

#[test]
fn damaged_files_are_errors_or_values_never_a_panic() {
    let path = format!(
        "{}/tests/fixtures/track_snappy.parquet",
        env!("CARGO_MANIFEST_DIR")
    );
    let good = std::fs::read(path).unwrap();
    // Eight bytes flipped at offsets all through the file (data pages, dictionary, footer):
    // the reader returns an error or values (a flip in a column not read, or in statistics,
    // changes nothing), never panics or hangs. A flip in the footer's magic makes it text.
    let mut errors = 0;
    for cut in (4..good.len() - 12).step_by(37) {
        let mut bad = good.clone();
        for b in &mut bad[cut..cut + 8] {
            *b ^= 0x5A;
        }
        let read = Source::from_bytes("bad.parquet", bad).and_then(|s| {
            s.read_columns("bad.parquet", &["t", "x", "y", "count", "small"])
                .and_then(|c| Series::from_columns(c, 2, "the test"))
        });
        errors += usize::from(read.is_err());
    }
    assert!(errors > 0, "some damage is detected");
    // Cut short: without its footer magic it is not Parquet, and as text not UTF-8.
    let truncated = good[..good.len() - 100].to_vec();
    assert!(Source::from_bytes("cut.parquet", truncated).is_err());
}
