//! Time series from CSV text.
//!
//! The format: an optional UTF-8 byte-order mark; lines that are blank or start with `#` are
//! skipped anywhere; the first other line is a header naming the columns; then one row per
//! sample. The delimiter is the header's: `,` (default), `;` or a tab. Fields may be quoted
//! with `"`; a quoted header name may hold the delimiter (`"x[0,1]"`, as pdyn writes it) and
//! `""` for a quote. Data fields are split at every delimiter: a text column of the rows may
//! be quoted but must not hold the delimiter.
//!
//! Only the columns asked for are parsed, so a file may carry text columns (labels, flags)
//! beside its numbers. Every value must be a finite number: an empty field, `NaN`, `inf` or
//! any other text is an error naming the file, line, column and text. A [`Series`] then
//! requires strictly increasing times and a minimum number of samples.

use crate::error::DataError;
use std::borrow::Cow;

/// Columns of numbers read from a CSV file, with where each value came from.
#[derive(Clone, Debug)]
pub struct Columns {
    /// The file name (used in messages).
    pub file: String,
    /// The names of the columns read, in the order asked for.
    pub names: Vec<String>,
    /// The values, one vector per column in `names`.
    pub values: Vec<Vec<f64>>,
    /// The 1-based line of each row.
    pub lines: Vec<usize>,
    /// For each column, the 1-based character column where its field starts, per row.
    starts: Vec<Vec<u32>>,
    /// The 1-based line of the header (0 for a file without lines: Parquet).
    pub header_line: usize,
    /// The rows are records of a binary file (Parquet): problems are located by row, and
    /// `lines` holds the 1-based row numbers.
    records: bool,
}

impl Columns {
    /// The number of rows.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Moves column `i` to the front (the time column of a file read whole).
    pub fn move_first(&mut self, i: usize) {
        if i < self.names.len() {
            let n = self.names.remove(i);
            self.names.insert(0, n);
            let v = self.values.remove(i);
            self.values.insert(0, v);
            let s = self.starts.remove(i);
            self.starts.insert(0, s);
        }
    }

    /// Columns of records (a Parquet file's rows): located by row number, not by line.
    pub fn of_records(file: &str, names: Vec<String>, values: Vec<Vec<f64>>) -> Columns {
        let rows = values.first().map_or(0, Vec::len);
        Columns {
            file: file.to_string(),
            names,
            values,
            lines: (1..=rows).collect(),
            starts: Vec::new(),
            header_line: 0,
            records: true,
        }
    }

    /// `e` located at the header line (nothing for records, which have no lines).
    pub fn at_header(&self, e: DataError) -> DataError {
        if self.records {
            e
        } else {
            e.at(self.header_line, None)
        }
    }

    /// An error located at row `row` (0-based) of column `col` (index into `names`).
    pub fn error_at(&self, row: usize, col: usize, message: impl Into<String>) -> DataError {
        if self.records {
            let mut e = DataError::new(&self.file, format!("row {}: {}", row + 1, message.into()));
            if let Some(name) = self.names.get(col) {
                e = e.column_name(name);
            }
            if let Some(v) = self.values.get(col).and_then(|v| v.get(row)) {
                e = e.text(&v.to_string());
            }
            return e;
        }
        let line = self.lines.get(row).copied().unwrap_or(self.header_line);
        let column = self
            .starts
            .get(col)
            .and_then(|s| s.get(row))
            .map(|&c| c as usize);
        let mut e = DataError::new(&self.file, message).at(line, column);
        if let Some(name) = self.names.get(col) {
            e = e.column_name(name);
        }
        if let Some(v) = self.values.get(col).and_then(|v| v.get(row)) {
            e = e.text(&v.to_string());
        }
        e
    }
}

/// The delimiter of a header line: the first of `,`, `;`, tab outside quotes.
fn delimiter(header: &str) -> char {
    let mut quoted = false;
    let mut seen = [false; 3];
    for c in header.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => seen[0] = true,
            ';' if !quoted => seen[1] = true,
            '\t' if !quoted => seen[2] = true,
            _ => {}
        }
    }
    [',', ';', '\t']
        .into_iter()
        .zip(seen)
        .find_map(|(d, s)| s.then_some(d))
        .unwrap_or(',')
}

/// The 1-based character column of a quote that opens a name and is never closed.
fn unclosed_quote(line: &str) -> Option<usize> {
    let mut open = None;
    for (col, c) in line.chars().enumerate() {
        if c == '"' {
            open = if open.is_some() { None } else { Some(col + 1) };
        }
    }
    open
}

/// The fields of a line with their 1-based character columns, quotes removed, spaces trimmed.
/// A quoted field (RFC 4180) may hold the delimiter, and `""` stands for one quote inside it:
/// pdyn writes a column named `x[0,1]` as `"x[0,1]"`.
fn fields(line: &str, delim: char) -> Vec<(usize, Cow<'_, str>)> {
    let mut out = Vec::new();
    let mut start_byte = 0;
    let mut start_char = 1;
    let mut quoted = false;
    for (chars, (i, c)) in line.char_indices().enumerate() {
        if c == '"' {
            quoted = !quoted;
        } else if c == delim && !quoted {
            out.push((start_char, &line[start_byte..i]));
            start_byte = i + c.len_utf8();
            start_char = chars + 2;
        }
    }
    out.push((start_char, &line[start_byte..]));
    out.into_iter()
        .map(|(col, f)| {
            // The column reported is that of the first non-blank character of the field.
            let lead = f.chars().take_while(|c| c.is_whitespace()).count();
            let t = f.trim();
            let t = match t.strip_prefix('"').and_then(|s| s.strip_suffix('"')) {
                Some(inner) if inner.contains("\"\"") => Cow::Owned(inner.replace("\"\"", "\"")),
                Some(inner) => Cow::Borrowed(inner),
                None => Cow::Borrowed(t),
            };
            (col + lead, t)
        })
        .collect()
}

/// Parses one field as a finite number, or says why not and what would be valid.
fn number(text: &str) -> Result<f64, (String, String)> {
    if text.is_empty() {
        return Err((
            "missing value (empty field)".into(),
            "every row needs a number in every column used; remove the row or fill the value"
                .into(),
        ));
    }
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) if v.is_nan() => Err((
            "the value is NaN (not a number)".into(),
            "a measurement that is missing must be removed, not written as NaN (pdyn does not \
             guess values)"
                .into(),
        )),
        Ok(_) => Err((
            "the value is infinite".into(),
            "values must be finite numbers".into(),
        )),
        Err(_) => Err((
            "not a number".into(),
            "write a decimal number such as 1.5, -2e-3 or 42 (a decimal point, not a comma)".into(),
        )),
    }
}

/// The header's line (1-based) and names: the first line that is not blank or a comment. A
/// text with no such line gives line 1 and no names.
pub fn header(text: &str) -> (usize, Vec<String>) {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (i, line) in text.split('\n').enumerate() {
        let l = line.strip_suffix('\r').unwrap_or(line).trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let names = fields(l, delimiter(l))
            .into_iter()
            .map(|(_, n)| n.into_owned())
            .collect();
        return (i + 1, names);
    }
    (1, Vec::new())
}

/// Reads the columns `wanted` (by header name) from CSV `text` of the file named `file`. When
/// `wanted` is empty, every column is read.
pub fn read_columns(file: &str, text: &str, wanted: &[&str]) -> Result<Columns, DataError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // The header: the first line that is not blank or a comment; `rest` is what follows it.
    let mut found = None;
    let mut offset = 0;
    for (i, raw) in text.split_inclusive('\n').enumerate() {
        offset += raw.len();
        let l = raw.strip_suffix('\n').unwrap_or(raw);
        let l = l.strip_suffix('\r').unwrap_or(l);
        if !is_skipped(l) {
            found = Some((i + 1, l));
            break;
        }
    }
    let rest = &text[offset..];
    let Some((header_line, header)) = found else {
        return Err(
            DataError::new(file, "the file has no header line and no data").help(
                "the first line names the columns (e.g. `t,x,y`); one row per sample follows",
            ),
        );
    };
    if let Some(col) = unclosed_quote(header) {
        return Err(
            DataError::new(file, "a quoted name of the header is not closed")
                .at(header_line, Some(col))
                .text(header)
                .help("close the name with `\"` (a quote inside a name is written `\"\"`)"),
        );
    }
    let delim = delimiter(header);
    let head = fields(header, delim);
    let names: Vec<String> = head.iter().map(|(_, n)| n.to_string()).collect();
    if let Some((col, n)) = head.iter().find(|(_, n)| n.parse::<f64>().is_ok()) {
        return Err(
            DataError::new(file, "the first line must be a header naming the columns")
                .at(header_line, Some(*col))
                .text(n.as_ref())
                .help(format!(
                    "add a line such as `{}` before the data",
                    default_names(head.len()).join(&delim.to_string())
                )),
        );
    }
    for (i, (col, n)) in head.iter().enumerate() {
        if n.is_empty() {
            return Err(DataError::new(file, "a column of the header has no name")
                .at(header_line, Some(*col))
                .help("name every column in the header line"));
        }
        if names[..i].iter().any(|m| m == n) {
            return Err(DataError::new(file, "two columns have the same name")
                .at(header_line, Some(*col))
                .text(n)
                .help("give every column a different name"));
        }
    }
    let wanted: Vec<String> = if wanted.is_empty() {
        names.clone()
    } else {
        wanted.iter().map(|s| s.to_string()).collect()
    };
    let index = column_indices(file, &names, &wanted, Some(header_line))?;
    let needed = index.iter().copied().max().map_or(0, |m| m + 1);
    let rows = Rows {
        file,
        delim,
        names: &names,
        wanted: &wanted,
        index: &index,
        needed,
    };
    // Large files are parsed in parts on several threads (each part starts at a line), the
    // parts' rows then joined in order; the first error in the file's order is reported.
    let parts = split_at_lines(rest, parse_threads(rest.len()));
    let parsed = crate::parallel::map(&parts, "CSV parsing", |part| rows.parse(part));
    let mut values: Vec<Vec<f64>> = vec![Vec::new(); wanted.len()];
    let mut starts: Vec<Vec<u32>> = vec![Vec::new(); wanted.len()];
    let mut row_lines = Vec::new();
    // Line numbers: a part's are counted from 0; the first line after the header is
    // `header_line + 1`.
    let mut base = header_line + 1;
    for part in parsed {
        let mut part = part.map_err(|mut e| {
            e.line = e.line.map(|l| l + base);
            e
        })?;
        if values[0].is_empty() {
            values = std::mem::take(&mut part.values);
            starts = std::mem::take(&mut part.starts);
        } else {
            for (v, pv) in values.iter_mut().zip(&part.values) {
                v.extend_from_slice(pv);
            }
            for (s, ps) in starts.iter_mut().zip(&part.starts) {
                s.extend_from_slice(ps);
            }
        }
        row_lines.extend(part.lines.iter().map(|l| l + base));
        base += part.newlines;
    }
    if row_lines.is_empty() {
        return Err(
            DataError::new(file, "the file has a header but no data rows")
                .at(header_line, None)
                .help("add one row per sample below the header"),
        );
    }
    Ok(Columns {
        file: file.to_string(),
        names: wanted,
        values,
        lines: row_lines,
        starts,
        header_line,
        records: false,
    })
}

/// The position of each of the `wanted` columns among `names`, or an error naming the first
/// one missing and listing the file's columns (at the header's line when there is one).
pub(crate) fn column_indices(
    file: &str,
    names: &[String],
    wanted: &[String],
    header_line: Option<usize>,
) -> Result<Vec<usize>, DataError> {
    wanted
        .iter()
        .map(|w| {
            names.iter().position(|n| n == w).ok_or_else(|| {
                let e = DataError::new(file, format!("no column named `{w}`"));
                let e = match header_line {
                    Some(line) => e.at(line, None),
                    None => e,
                };
                e.help(format!(
                    "the file's columns are {}; choose the columns with --columns (Python: columns=)",
                    names
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
        })
        .collect()
}

/// A blank line or a comment: not a header, not a row.
fn is_skipped(line: &str) -> bool {
    let t = line.trim();
    t.is_empty() || t.starts_with('#')
}

/// Below this many bytes a file is parsed on one thread (a thread costs more than it saves).
const PARALLEL_FROM_BYTES: usize = 4 << 20;

/// The threads to parse `len` bytes with: one per 4 MB, at most the machine's cores and 8.
fn parse_threads(len: usize) -> usize {
    if len < PARALLEL_FROM_BYTES {
        return 1;
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    cores.min(8).min(len / PARALLEL_FROM_BYTES).max(1)
}

/// `text` cut into at most `parts` pieces of about equal length, each ending after a `\n`
/// (the last one at the end of the text).
fn split_at_lines(text: &str, parts: usize) -> Vec<&str> {
    let mut out = Vec::with_capacity(parts);
    let mut rest = text;
    for k in (1..parts).rev() {
        let target = rest.len() / (k + 1);
        match rest.as_bytes()[target..].iter().position(|&b| b == b'\n') {
            Some(p) => {
                let (a, b) = rest.split_at(target + p + 1);
                out.push(a);
                rest = b;
            }
            None => break,
        }
    }
    out.push(rest);
    out
}

/// What parsing the rows needs to know of the header and the columns asked for.
struct Rows<'a> {
    file: &'a str,
    delim: char,
    names: &'a [String],
    wanted: &'a [String],
    /// For each wanted column, its field in the header.
    index: &'a [usize],
    /// The fields a row must have (the last wanted one's position + 1).
    needed: usize,
}

/// The rows of one part of a file: line numbers counted from 0 at the part's start.
struct Part {
    values: Vec<Vec<f64>>,
    starts: Vec<Vec<u32>>,
    lines: Vec<usize>,
    /// The line ends in the part (to number the next part's lines).
    newlines: usize,
}

impl Rows<'_> {
    /// Parses the rows of `part` (whole lines). Errors carry lines counted from 0 at the
    /// part's start.
    fn parse(&self, part: &str) -> Result<Part, DataError> {
        let (file, delim, needed) = (self.file, self.delim, self.needed);
        let mut values: Vec<Vec<f64>> = vec![Vec::new(); self.wanted.len()];
        let mut starts: Vec<Vec<u32>> = vec![Vec::new(); self.wanted.len()];
        let mut row_lines = Vec::new();
        let mut newlines = 0;
        // The hot loop: fields split without allocating; only the wanted ones are parsed. The
        // column (in characters) of a field is counted only for a line that is not ASCII.
        let mut fs: Vec<(usize, &str)> = Vec::with_capacity(self.names.len());
        for (line_no, raw) in part.split('\n').enumerate() {
            newlines = line_no;
            let line = raw.strip_suffix('\r').unwrap_or(raw);
            if is_skipped(line) {
                continue;
            }
            fs.clear();
            let ascii = line.is_ascii();
            let mut start = 0;
            for (k, f) in line.split(delim).enumerate() {
                if k >= needed {
                    break;
                }
                let lead = f.len() - f.trim_start().len();
                let col = if ascii {
                    start + lead + 1
                } else {
                    line[..start + lead].chars().count() + 1
                };
                let t = f.trim();
                let t = t
                    .strip_prefix('"')
                    .and_then(|x| x.strip_suffix('"'))
                    .unwrap_or(t);
                fs.push((col, t));
                start += f.len() + delim.len_utf8();
            }
            if fs.len() < needed {
                return Err(DataError::new(
                    file,
                    format!(
                        "the row has {} field(s) but column `{}` is field {} of the header",
                        fields(line, delim).len(),
                        self.names[needed - 1],
                        needed
                    ),
                )
                .at(line_no, None)
                .text(line)
                .help(format!(
                    "every row needs a value for each of the {} header columns, separated by `{}`",
                    self.names.len(),
                    if delim == '\t' {
                        "\\t".to_string()
                    } else {
                        delim.to_string()
                    }
                )));
            }
            for (k, &i) in self.index.iter().enumerate() {
                let (col, f) = fs[i];
                match number(f) {
                    Ok(v) => {
                        values[k].push(v);
                        starts[k].push(u32::try_from(col).unwrap_or(u32::MAX));
                    }
                    Err((message, help)) => {
                        return Err(DataError::new(file, message)
                            .at(line_no, Some(col))
                            .column_name(&self.wanted[k])
                            .text(f)
                            .help(help))
                    }
                }
            }
            row_lines.push(line_no);
        }
        Ok(Part {
            values,
            starts,
            lines: row_lines,
            newlines,
        })
    }
}

fn default_names(n: usize) -> Vec<String> {
    ["t", "x", "y", "z"]
        .iter()
        .map(|s| s.to_string())
        .chain((4..).map(|i| format!("c{i}")))
        .take(n.max(1))
        .collect()
}

/// A time series: strictly increasing times and one or more columns of values.
#[derive(Clone, Debug)]
pub struct Series {
    /// The times.
    pub t: Vec<f64>,
    /// The names of the value columns.
    pub names: Vec<String>,
    /// The value columns, each as long as `t`.
    pub values: Vec<Vec<f64>>,
}

impl Series {
    /// The series of a CSV file's columns: the first of `columns.names` is the time. At least
    /// `min_len` rows are required (`what` names the use, for the message).
    pub fn from_columns(columns: Columns, min_len: usize, what: &str) -> Result<Series, DataError> {
        if columns.values.is_empty() {
            return Err(DataError::new(&columns.file, "no time column"));
        }
        check_times(&columns.values[0], |row, msg| columns.error_at(row, 0, msg))?;
        if columns.len() < min_len {
            return Err(columns.at_header(DataError::new(
                &columns.file,
                format!(
                    "{} data row(s), but {what} needs at least {min_len}",
                    columns.len()
                ),
            )));
        }
        let mut values = columns.values;
        let t = values.remove(0);
        let mut names = columns.names;
        names.remove(0);
        Ok(Series { t, names, values })
    }

    /// A series from arrays (Python's), checked as a file is: equal lengths, finite values,
    /// strictly increasing times, at least `min_len` samples. Problems are located by index.
    pub fn from_arrays(
        t: Vec<f64>,
        names: Vec<String>,
        values: Vec<Vec<f64>>,
        min_len: usize,
        what: &str,
    ) -> Result<Series, DataError> {
        let at_index = |name: &str, i: usize, v: f64, msg: String| {
            DataError::new(name, format!("at index {i}: {msg}")).text(&v.to_string())
        };
        for (name, col) in
            std::iter::once(("t", &t)).chain(names.iter().map(|n| n.as_str()).zip(&values))
        {
            if col.len() != t.len() {
                return Err(DataError::new(
                    name,
                    format!("{} values, but t has {}", col.len(), t.len()),
                )
                .help("every array must have one value per time"));
            }
            if let Some(i) = col.iter().position(|v| !v.is_finite()) {
                return Err(at_index(name, i, col[i], "the value is not finite".into())
                    .help("remove missing samples instead of writing NaN (pdyn does not guess values)"));
            }
        }
        check_times(&t, |i, msg| at_index("t", i, t[i], msg))?;
        if t.len() < min_len {
            return Err(DataError::new(
                "t",
                format!("{} sample(s), but {what} needs at least {min_len}", t.len()),
            ));
        }
        Ok(Series { t, names, values })
    }
}

/// Strictly increasing times, or the first place where they are not.
fn check_times(t: &[f64], error_at: impl Fn(usize, String) -> DataError) -> Result<(), DataError> {
    for i in 1..t.len() {
        if t[i] > t[i - 1] {
            continue;
        }
        let (msg, help) =
            if t[i] == t[i - 1] {
                (
                format!("duplicate time {} (the previous row has the same time)", t[i]),
                "remove the duplicate sample (or average the two): times must increase strictly",
            )
            } else {
                (
                    format!(
                        "time {} comes after the larger time {}: the times are not sorted",
                        t[i],
                        t[i - 1]
                    ),
                    "sort the rows by time (e.g. `sort -t, -g -k1`): times must increase strictly",
                )
            };
        return Err(error_at(i, msg).help(help));
    }
    Ok(())
}
