//! Bad data: every problem a located error (file, line, column, text, help).
#![allow(clippy::result_large_err)]

use pdyn_data::csv::{read_columns, Series};

fn series(text: &str, cols: &[&str]) -> Result<Series, pdyn_data::DataError> {
    Series::from_columns(read_columns("track.csv", text, cols)?, 3, "the test")
}

#[test]
fn unsorted_time_is_located() {
    let e = series("t,x,y\n0,0,0\n2,1,1\n1,2,2\n3,3,3\n", &["t", "x", "y"]).unwrap_err();
    assert_eq!((e.line, e.column), (Some(4), Some(1)));
    assert!(e.message.contains("not sorted"), "{e}");
    assert!(e.help.as_deref().unwrap_or("").contains("sort"));
    assert_eq!(e.column_name.as_deref(), Some("t"));
}

#[test]
fn duplicate_time_is_located() {
    let e = series(
        "# comment\nt,x,y\n0,0,0\n1,1,1\n1,2,2\n3,3,3\n",
        &["t", "x", "y"],
    )
    .unwrap_err();
    assert_eq!(e.line, Some(5));
    assert!(e.message.contains("duplicate time 1"), "{e}");
}

#[test]
fn nan_and_text_are_located_with_their_text() {
    let e = series("t,x,y\n0,0,0\n1,NaN,1\n", &["t", "x", "y"]).unwrap_err();
    assert_eq!((e.line, e.column), (Some(3), Some(3)));
    assert_eq!(e.text.as_deref(), Some("NaN"));
    assert_eq!(e.column_name.as_deref(), Some("x"));
    assert!(e.message.contains("NaN"));
    let e = series("t,x,y\n0,0,0\n1,abc,1\n", &["t", "x", "y"]).unwrap_err();
    assert_eq!(
        (e.line, e.column, e.text.as_deref()),
        (Some(3), Some(3), Some("abc"))
    );
    assert!(e.message.contains("not a number"));
    let e = series("t,x,y\n0,0,0\n1,,1\n", &["t", "x", "y"]).unwrap_err();
    assert!(e.message.contains("missing value"), "{e}");
}

#[test]
fn missing_column_names_the_columns_there_are() {
    let e = series("t,x,y\n0,0,0\n", &["t", "x", "z"]).unwrap_err();
    assert!(e.message.contains("no column named `z`"));
    assert!(e.help.as_deref().unwrap_or("").contains("`x`"));
    assert_eq!(e.line, Some(1));
}

#[test]
fn header_without_rows_and_too_few_rows() {
    let e = series("t,x,y\n\n", &["t", "x", "y"]).unwrap_err();
    assert!(e.message.contains("header but no data rows"), "{e}");
    let e = series("t,x,y\n0,0,0\n1,1,1\n", &["t", "x", "y"]).unwrap_err();
    assert!(e.message.contains("at least 3"), "{e}");
    let e = series("0,0,0\n1,1,1\n", &["t"]).unwrap_err();
    assert!(e.message.contains("header"), "{e}");
    let e = series("t,x,y\n0,0\n", &["t", "x", "y"]).unwrap_err();
    assert!(e.message.contains("field"), "{e}");
}

#[test]
fn extra_text_columns_and_other_delimiters_are_fine() {
    let s = series(
        "\u{feff}t;label;x;y\r\n0;a;0;0\r\n1;b;1;2\r\n2;c;4;8\r\n",
        &["t", "x", "y"],
    )
    .unwrap();
    assert_eq!(s.values[1], vec![0.0, 2.0, 8.0]);
    let e = format!(
        "{}",
        series("t,x,y\n0,0,0\n1,x1,1\n", &["t", "x", "y"]).unwrap_err()
    );
    assert!(
        e.starts_with("track.csv:3:3: error: not a number (column `x`, text `x1`)"),
        "{e}"
    );
}

/// Columns count characters, not bytes, on a line that is not ASCII.
#[test]
fn columns_count_characters() {
    let e = series("t,label,x,y\n0,é,0,0\n1,ñandú,bad,1\n", &["t", "x", "y"]).unwrap_err();
    assert_eq!((e.line, e.column), (Some(3), Some(9)), "{e}");
    let e = series("t,x,y\n0, 0,0\n1,  bad,1\n", &["t", "x", "y"]).unwrap_err();
    assert_eq!((e.line, e.column), (Some(3), Some(5)), "{e}");
}

#[test]
fn arrays_are_checked_like_files() {
    let e = Series::from_arrays(
        vec![0.0, 1.0, 1.0],
        vec!["x".into()],
        vec![vec![0.0; 3]],
        2,
        "t",
    )
    .unwrap_err();
    assert!(
        e.message.contains("index 2") && e.message.contains("duplicate"),
        "{e}"
    );
    let e = Series::from_arrays(
        vec![0.0, 1.0, 2.0],
        vec!["x".into()],
        vec![vec![0.0, f64::NAN, 1.0]],
        2,
        "t",
    )
    .unwrap_err();
    assert_eq!(e.file, "x");
    let e = Series::from_arrays(
        vec![0.0, 1.0, 2.0],
        vec!["x".into()],
        vec![vec![0.0; 2]],
        2,
        "t",
    )
    .unwrap_err();
    assert!(e.message.contains("2 values"), "{e}");
}

/// A file large enough to be parsed in parts on several threads (over 4 MB): values and line
/// numbers as one pass would give them, comments and blank lines anywhere, and the first error
/// in the file's order located at its line, whichever part it falls in.
#[test]
fn a_large_file_parsed_in_parts_keeps_its_lines() {
    let rows = 300_000;
    let mut text = String::from("# a long record\nt,x,label\n");
    let mut line_of_row = Vec::with_capacity(rows);
    let mut line = 2;
    for i in 0..rows {
        if i % 1000 == 500 {
            text.push_str("# a comment\n\n");
            line += 2;
        }
        line += 1;
        line_of_row.push(line);
        text.push_str(&format!("{},{},row{i}\n", i as f64 * 0.5, (i * i) as f64));
    }
    assert!(
        text.len() > 8 << 20,
        "{} bytes: big enough for two parts",
        text.len()
    );
    let c = read_columns("big.csv", &text, &["t", "x"]).unwrap();
    assert_eq!(c.len(), rows);
    assert_eq!(c.lines, line_of_row);
    for i in (0..rows).step_by(997) {
        assert_eq!(c.values[0][i], i as f64 * 0.5);
        assert_eq!(c.values[1][i], (i * i) as f64);
    }
    // Errors late in the file (in the last part) and early (in the first): each at its line.
    for bad_row in [rows - 3, 10, rows / 2 + 1] {
        let target = line_of_row[bad_row];
        let broken: String = text
            .split_inclusive('\n')
            .enumerate()
            .map(|(i, l)| {
                if i + 1 == target {
                    format!("{},NaN,x\n", bad_row as f64 * 0.5)
                } else {
                    l.to_string()
                }
            })
            .collect();
        let e = read_columns("big.csv", &broken, &["t", "x"]).unwrap_err();
        assert_eq!(e.line, Some(target), "{e}");
        // The field after `t,`: column len(t) + 2.
        let t_len = format!("{}", bad_row as f64 * 0.5).len();
        assert_eq!(e.column, Some(t_len + 2), "{e}");
    }
}

#[test]
fn quoted_header_names_may_hold_the_delimiter() {
    // pdyn writes a family member's column `x[0,1]` quoted; a reader must take it whole.
    let text = "t,\"x[0,1]\",\"y[0,1]\",\"say \"\"hi\"\"\"\n0,1,2,3\n1,4,5,6\n2,7,8,9\n";
    let (_, names) = pdyn_data::csv::header(text);
    assert_eq!(names, ["t", "x[0,1]", "y[0,1]", "say \"hi\""]);
    let c = read_columns("net.csv", text, &["t", "y[0,1]", "say \"hi\""]).unwrap();
    assert_eq!(
        c.values,
        vec![
            vec![0.0, 1.0, 2.0],
            vec![2.0, 5.0, 8.0],
            vec![3.0, 6.0, 9.0]
        ]
    );
    // A `;` file whose quoted names hold commas is still read as `;`-delimited.
    let c = read_columns("net.csv", "t;\"x[0,1]\"\n0;1\n1;2\n", &["x[0,1]"]).unwrap();
    assert_eq!(c.values, vec![vec![1.0, 2.0]]);
}

#[test]
fn an_unclosed_quote_in_the_header_is_located() {
    let e = read_columns("net.csv", "t,\"x[0,1],y\n0,1,2\n", &["t"]).unwrap_err();
    assert_eq!((e.line, e.column), (Some(1), Some(3)), "{e}");
    assert!(e.message.contains("not closed"), "{e}");
}
