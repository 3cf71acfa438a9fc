//! [`Error`]: everything that can stop a pdyn command, typed, with where it came from.
//!
//! Library functions below return their own error types (`ModelError`, `DeriveError`,
//! `SimError`, `KinError`, `DsolveError`, `ExprError`...). A command wraps them here with the
//! context it knows (which file, which argument), so that `main` can render every failure the
//! same way: a human message on stderr, a JSON object with `--json`, and an exit code:
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success |
//! | 1 | a numerical failure after partial output was written (an integration that stopped) |
//! | 2 | bad input: a file, a model, an option, an expression; nothing was computed |
//! | 3 | an internal error (a bug): please report it |

use crate::sim::{RunFailure, SimError};
use pdyn_expr::ExprError;
use pdyn_mech::dsolve::DsolveError;
use pdyn_mech::kinematics::KinError;
use pdyn_mech::prescribed::ForcesError;
use pdyn_mech::{DeriveError, ModelError};
use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

/// Where in the input a problem is: a file or a command-line argument, and a position in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The file name, or the argument (`--set`, `<expression>`).
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column (in characters), when known.
    pub column: Option<usize>,
}

/// A failure of a pdyn command.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What was being done: `read the model file`, `create`, `write`.
        action: &'static str,
        /// The operating system's reason.
        error: Arc<std::io::Error>,
    },
    /// An output file could not be written while a run was going (a full disk, a file-size
    /// limit): the run stopped there. Every file still ends with a whole row
    /// ([`crate::stream::RowFile::flush`]) and the last checkpoint, written atomically, is
    /// intact: after freeing space the run continues from it.
    WriteDuringRun {
        /// The failed write ([`Error::Io`]).
        error: Box<Error>,
        /// The checkpoint file, if the run writes one, and the time of the last one written.
        checkpoint: Option<(PathBuf, Option<f64>)>,
    },
    /// A model file that does not load; rendered with the offending line.
    Model {
        /// The located problem.
        error: ModelError,
        /// The file's text (to show the line).
        source: Arc<str>,
    },
    /// An expression given on the command line that does not parse or has the wrong shape.
    Expr {
        /// The argument it came from (`--set`, `<position>`, `--at`...).
        argument: String,
        /// The argument's text.
        text: String,
        /// The located problem.
        error: ExprError,
    },
    /// A command-line argument with an invalid value or combination.
    Argument {
        /// The argument (`--over`, `--set`...), empty when it is about several.
        argument: String,
        /// What is wrong and what would be valid.
        message: String,
    },
    /// A parameter value that breaks a physical requirement (a mass ≤ 0), given by the option.
    Value {
        /// The model file.
        origin: String,
        /// The option that gave the value (`--set`).
        option: String,
        /// What is wrong.
        error: pdyn_mech::validity::InvalidValue,
    },
    /// The equations of motion could not be derived.
    Derive {
        /// The model file.
        origin: String,
        /// Why.
        error: DeriveError,
    },
    /// The forces of a prescribed motion could not be found.
    Forces {
        /// The model file.
        origin: String,
        /// Why.
        error: ForcesError,
    },
    /// No equilibrium, or no modes, for a model (`pdyn equilibrium`, `pdyn modes`).
    Statics {
        /// The model file.
        origin: String,
        /// Why.
        error: pdyn_mech::statics::StaticsError,
    },
    /// A model could not be prepared or run.
    Sim {
        /// The model file.
        origin: String,
        /// What was being attempted (`--method exact: `), or empty.
        context: &'static str,
        /// Why.
        error: SimError,
    },
    /// Kinematics could not be derived or evaluated.
    Kin {
        /// The argument that asked for it (`--at t=1`, `--max`), or empty.
        context: String,
        /// Why.
        error: KinError,
    },
    /// No closed form, or an invalid `dsolve` input.
    Dsolve {
        /// The argument that asked for it (`--when y = 0`), or empty.
        context: String,
        /// Why.
        error: DsolveError,
    },
    /// A plot could not be drawn or written.
    Plot {
        /// The image file.
        path: PathBuf,
        /// Why.
        error: String,
    },
    /// An integration stopped before the end (exit code 1). What was computed up to there has
    /// been written.
    Integration {
        /// The model file.
        origin: String,
        /// Where and why.
        failure: Box<RunFailure>,
    },
    /// A result that is NaN or infinite (`1/0`), printed as such (exit code 1).
    NonFinite {
        /// What was evaluated.
        what: String,
        /// Which components are not finite.
        components: Vec<usize>,
    },
    /// Symbolic work that would exceed its limit (an expansion with too many terms, a
    /// derivative of too high an order): nothing was computed (exit code 2).
    Budget {
        /// What was being done (`simplify --expand`, `diff -n`).
        context: String,
        /// Which limit, and what to do instead.
        error: pdyn_expr::BudgetError,
    },
    /// A bug in pdyn.
    Internal {
        /// What went wrong.
        message: String,
    },
    /// An N-body integration stopped by the engine (a close encounter WHFast cannot resolve,
    /// IAS15's step underflow, a non-finite state): exit code 1, output up to it written.
    Gravity {
        /// The model file.
        origin: String,
        /// Why.
        error: pdyn_gravity::GravityError,
    },
    /// Measured data that cannot be used: the file, line and column, the offending text, what
    /// would be valid (exit code 2).
    Data {
        /// The located problem (boxed: it carries its whole location and help text).
        error: Box<pdyn_data::DataError>,
    },
    /// A fit that could not be computed (an integration that failed at the starting values):
    /// exit code 1.
    Fit {
        /// The model file.
        origin: String,
        /// What failed.
        message: String,
    },
    /// A molecular-dynamics run that stopped before its last step (exit code 1): unstable (the
    /// step, the offending atoms) or a bond stretched past its limit. What was computed up to
    /// there has been written.
    MdRun {
        /// The model file.
        origin: String,
        /// Where and why (carries the step and the atoms).
        error: pdyn_md::MdError,
    },
    /// A run stopped by a signal (SIGINT, SIGTERM) or a front end's interrupt after a whole
    /// step: every file written so far is whole and `summary.json` says `"interrupted"` (exit
    /// code 4).
    Interrupted {
        /// The model file.
        origin: String,
        /// The time the run reached.
        time: f64,
    },
}

impl Error {
    /// A short machine-readable name of the kind of failure (the `kind` of `--json` errors).
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Io { .. } | Error::WriteDuringRun { .. } => "io",
            Error::Model { .. } => "model",
            Error::Expr { .. } => "expression",
            Error::Argument { .. } => "argument",
            Error::Value { .. } => "value",
            Error::Derive { .. } => "derivation",
            Error::Forces { .. } => "forces",
            Error::Statics { .. } => "statics",
            Error::Sim { .. } => "simulation",
            Error::Kin { .. } => "kinematics",
            Error::Dsolve { .. } => "dsolve",
            Error::Plot { .. } => "plot",
            Error::Integration { .. } => "integration",
            Error::NonFinite { .. } => "non_finite",
            Error::Budget { .. } => "budget",
            Error::Internal { .. } => "internal",
            Error::Gravity { .. } => "gravity",
            Error::MdRun { .. } => "md_run",
            Error::Data { .. } => "data",
            Error::Fit { .. } => "fit",
            Error::Interrupted { .. } => "interrupted",
        }
    }

    /// The process exit code for this failure (see the module documentation).
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Integration { .. }
            | Error::NonFinite { .. }
            | Error::Gravity { .. }
            | Error::MdRun { .. }
            | Error::Fit { .. }
            | Error::WriteDuringRun { .. } => 1,
            Error::Internal { .. } => 3,
            Error::Interrupted { .. } => 4,
            _ => 2,
        }
    }

    /// Where the problem is, when it comes from a file or an argument.
    pub fn location(&self) -> Option<Location> {
        let at = |file: &str, source: &str, pos: usize| {
            let (line, column) = pdyn_expr::error::line_col(source, pos);
            Location {
                file: file.to_string(),
                line: Some(line),
                column: Some(column),
            }
        };
        let file = |f: &str| Location {
            file: f.to_string(),
            line: None,
            column: None,
        };
        match self {
            Error::Model { error, source } => Some(at(&error.origin, source, error.span.start)),
            Error::Expr {
                argument,
                text,
                error,
            } => Some(at(argument, text, error.span.start)),
            Error::Io { path, .. } | Error::Plot { path, .. } => {
                Some(file(&path.display().to_string()))
            }
            Error::WriteDuringRun { error, .. } => error.location(),
            Error::Argument { argument, .. } if !argument.is_empty() => Some(file(argument)),
            Error::Derive { origin, error } => Some(Location {
                file: origin.clone(),
                line: error.location.map(|l| l.0 as usize),
                column: error.location.map(|l| l.1 as usize),
            }),
            Error::Value { origin, .. }
            | Error::Forces { origin, .. }
            | Error::Statics { origin, .. }
            | Error::Sim { origin, .. }
            | Error::Integration { origin, .. }
            | Error::Gravity { origin, .. }
            | Error::MdRun { origin, .. }
            | Error::Fit { origin, .. } => Some(file(origin)),
            Error::Interrupted { origin, .. } => Some(file(origin)),
            Error::Data { error } if !error.file.is_empty() => Some(Location {
                file: error.file.clone(),
                line: error.line,
                column: error.column,
            }),
            _ => None,
        }
    }

    /// Reads a model file as text. Bytes that are not UTF-8 are a model error at the first
    /// of them (the line and column shown, the byte named), not an I/O error without a place.
    pub fn read_model_file(path: &std::path::Path) -> Result<String, Error> {
        let bytes = std::fs::read(path).map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "read the model file",
            error: Arc::new(e),
        })?;
        match String::from_utf8(bytes) {
            Ok(text) => Ok(text),
            Err(e) => {
                let at = e.utf8_error().valid_up_to();
                let byte = e.as_bytes()[at];
                // The text shown: the bytes up to the bad one are the same, so is the span.
                let source = String::from_utf8_lossy(e.as_bytes()).into_owned();
                let error = ModelError::new(
                    &path.display().to_string(),
                    at..at + char::REPLACEMENT_CHARACTER.len_utf8(),
                    format!("the byte 0x{byte:02X} is not UTF-8: a model file must be UTF-8 text"),
                )
                .help("save the file as UTF-8 (e.g. `iconv -f latin1 -t utf-8`)");
                Err(Error::Model {
                    error,
                    source: source.into(),
                })
            }
        }
    }

    /// An argument error.
    pub fn argument(argument: impl Into<String>, message: impl Into<String>) -> Error {
        Error::Argument {
            argument: argument.into(),
            message: message.into(),
        }
    }

    /// A file or directory that could not be created, written or read (`action`: "create",
    /// "write").
    pub fn io(path: &std::path::Path, action: &'static str, error: std::io::Error) -> Error {
        Error::Io {
            path: path.to_path_buf(),
            action,
            error: std::sync::Arc::new(error),
        }
    }

    /// An expression error in a command-line argument.
    pub fn expr(argument: &str, text: &str, error: ExprError) -> Error {
        Error::Expr {
            argument: argument.to_string(),
            text: text.to_string(),
            error,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io {
                path,
                action,
                error,
            } if *action == "read the model file" => {
                write!(f, "{}: error: cannot {action}: {error}", path.display())
            }
            Error::Io {
                path,
                action,
                error,
            } => write!(f, "cannot {action} {}: {error}", path.display()),
            Error::WriteDuringRun { error, checkpoint } => {
                write!(
                    f,
                    "{error}\nthe run stopped there; every output file ends with a whole row"
                )?;
                match checkpoint {
                    Some((path, Some(t))) => write!(
                        f,
                        "; the last checkpoint ({}, t = {t}) is intact: free space and continue with --restart {}",
                        path.display(),
                        path.display()
                    ),
                    Some((path, None)) => write!(
                        f,
                        "; no checkpoint was written yet ({} would have been the first)",
                        path.display()
                    ),
                    None => write!(f, "; the run writes no checkpoint"),
                }
            }
            Error::Model { error, source } => f.write_str(&error.render(source)),
            Error::Expr {
                argument,
                text,
                error,
            } => f.write_str(&error.render(text, argument)),
            Error::Argument { message, .. } => f.write_str(message),
            Error::Budget { context, error } => write!(f, "{context}: error: {error}"),
            Error::Derive { origin, error } => match error.location {
                Some((line, column)) => write!(f, "{origin}:{line}:{column}: error: {error}"),
                None => write!(f, "{origin}: error: {error}"),
            },
            Error::Value {
                origin,
                option,
                error,
            } => write!(f, "{origin}: error: {option}: {error}"),
            Error::Forces { origin, error } => write!(f, "{origin}: error: {error}"),
            Error::Statics { origin, error } => write!(f, "{origin}: error: {error}"),
            Error::Sim {
                origin,
                context,
                error,
            } => write!(f, "{origin}: error: {context}{error}"),
            Error::Kin { context, error } if context.is_empty() => write!(f, "{error}"),
            Error::Kin { context, error } => write!(f, "{context}: {error}"),
            Error::Dsolve { context, error } if context.is_empty() => write!(f, "{error}"),
            Error::Dsolve { context, error } => write!(f, "{context}: {error}"),
            Error::Plot { path, error } => write!(f, "cannot plot {}: {error}", path.display()),
            Error::Integration { origin, failure } => write!(f, "{origin}: error: {failure}"),
            Error::NonFinite { what, components } => write!(
                f,
                "error: {what} is not finite (NaN or infinite) in component(s) {components:?}: \
                 a division by zero or a function outside its domain"
            ),
            Error::Internal { message } => write!(
                f,
                "internal error — please report it with the command that caused it: {message}"
            ),
            Error::Gravity { origin, error } => write!(f, "{origin}: error: {error}"),
            Error::Data { error } => write!(f, "{error}"),
            Error::Fit { origin, message } => write!(f, "{origin}: error: fit: {message}"),
            Error::Interrupted { origin, time } => write!(
                f,
                "{origin}: interrupted at t = {time}: the output up to there is written (summary.json has status \"interrupted\")"
            ),
            Error::MdRun { origin, error } => {
                write!(
                    f,
                    "{origin}: error: the run stopped: {error} (the output up to that step is kept)"
                )
            }
        }
    }
}

impl std::error::Error for Error {}

impl Error {
    /// The `--json` form: `{"error": {"kind", "message", "location", "exit_code"}}`.
    pub fn to_json(&self) -> serde_json::Value {
        let location = self
            .location()
            .map(|l| serde_json::json!({"file": l.file, "line": l.line, "column": l.column}));
        serde_json::json!({
            "error": {
                "kind": self.kind(),
                "message": self.to_string(),
                "location": location,
                "exit_code": self.exit_code(),
            }
        })
    }
}
