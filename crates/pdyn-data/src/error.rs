//! [`DataError`]: a problem with measured data, located in its file.

use std::fmt;

/// A problem with data: where it is (file, line, column), the offending text, what is wrong and
/// what would be valid.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct DataError {
    /// The file (or the name given to in-memory data, such as `t` or `x` for arrays).
    pub file: String,
    /// 1-based line in the file, when the problem is in one.
    pub line: Option<usize>,
    /// 1-based column (in characters) of the offending field, when known.
    pub column: Option<usize>,
    /// The name of the data column involved, when there is one.
    pub column_name: Option<String>,
    /// The offending text (a field as written), when there is one.
    pub text: Option<String>,
    /// What is wrong.
    pub message: String,
    /// What would be valid, or how to fix it.
    pub help: Option<String>,
}

impl DataError {
    /// A problem with `file` as a whole.
    pub fn new(file: &str, message: impl Into<String>) -> DataError {
        DataError {
            file: file.to_string(),
            line: None,
            column: None,
            column_name: None,
            text: None,
            message: message.into(),
            help: None,
        }
    }

    /// At a line and column.
    pub fn at(mut self, line: usize, column: Option<usize>) -> DataError {
        self.line = Some(line);
        self.column = column;
        self
    }

    /// About a named data column.
    pub fn column_name(mut self, name: &str) -> DataError {
        self.column_name = Some(name.to_string());
        self
    }

    /// The offending text.
    pub fn text(mut self, text: &str) -> DataError {
        self.text = Some(text.to_string());
        self
    }

    /// What would be valid.
    pub fn help(mut self, help: impl Into<String>) -> DataError {
        self.help = Some(help.into());
        self
    }
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if !self.file.is_empty() {
            write!(f, "{}", self.file)?;
            if let Some(line) = self.line {
                write!(f, ":{line}")?;
                if let Some(column) = self.column {
                    write!(f, ":{column}")?;
                }
            }
            write!(f, ": ")?;
        }
        write!(f, "error: {}", self.message)?;
        match (&self.column_name, &self.text) {
            (Some(c), Some(t)) => write!(f, " (column `{c}`, text `{t}`)")?,
            (Some(c), None) => write!(f, " (column `{c}`)")?,
            (None, Some(t)) => write!(f, " (text `{t}`)")?,
            (None, None) => {}
        }
        if let Some(help) = &self.help {
            write!(f, "\n  help: {help}")?;
        }
        Ok(())
    }
}

impl std::error::Error for DataError {}
