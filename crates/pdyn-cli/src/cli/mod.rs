//! The commands: one module each, doing parse → call the library → print. What the commands
//! share lives here: the output notation, model loading and `--set` (argument splitting is
//! [`pdyn::args`]).
//!
//! Every command returns an [`Outcome`] (what to print, and a failure that still produced
//! output) or a [`pdyn::Error`]; `main` prints and exits.

pub mod derive;
pub mod dsolve;
pub mod equilibrium;
pub mod expr;
pub mod fit;
pub mod forces;
pub mod fuse;
pub mod interrupt;
pub mod kin;
pub mod modes;
pub mod modes_json;
pub mod optimize;
pub mod roots;
pub mod run;
pub mod sweep;

use clap::ValueEnum;
use pdyn::report::notation::Notation;
use pdyn::Error;
use pdyn_expr::{Id, Pool, Value};
use std::path::Path;

/// What a command produced.
#[derive(Debug, Default)]
pub struct Outcome {
    /// Printed on stdout.
    pub stdout: String,
    /// Printed on stderr (warnings).
    pub stderr: String,
    /// A failure after output was produced (an integration that stopped): exit code 1.
    pub failure: Option<Error>,
}

impl Outcome {
    /// Just text on stdout.
    pub fn text(stdout: String) -> Outcome {
        Outcome {
            stdout,
            ..Outcome::default()
        }
    }
}

/// Output notation for expressions.
#[derive(Clone, Copy, Debug, Default, ValueEnum, PartialEq, Eq)]
pub enum Format {
    /// Plain text that pdyn parses back.
    #[default]
    Text,
    /// LaTeX (math mode).
    Latex,
    /// A Rust f64 expression.
    Rust,
}

impl From<Format> for Notation {
    fn from(f: Format) -> Notation {
        match f {
            Format::Text => Notation::Text,
            Format::Latex => Notation::Latex,
            Format::Rust => Notation::Rust,
        }
    }
}

impl Format {
    /// `id` in this notation.
    pub fn show(self, pool: &Pool, id: Id) -> String {
        Notation::from(self).show(pool, id)
    }

    /// A scalar or a vector in this notation.
    pub fn show_value(self, pool: &Pool, v: Value) -> String {
        Notation::from(self).show_value(pool, v)
    }
}

pub use pdyn::report::notation::value_json;

/// Loads a mechanics model file (read once); errors keep the file's text so that they can
/// show the offending line, and an `[nbody]` or `[md]` model says `pdyn run` runs it.
pub fn load_model(path: &Path) -> Result<pdyn_mech::Model, Error> {
    pdyn::model_file::ModelFile::read(path)?.mechanics()
}

/// `name=number` pairs of a comma-separated option such as `--at t=0,theta=0.5`.
pub fn numeric_pairs(list: &[String], flag: &str) -> Result<Vec<(String, f64)>, Error> {
    list.iter()
        .map(|kv| {
            let (k, v) = kv.split_once('=').ok_or_else(|| {
                Error::argument(flag, format!("{flag}: expected name=value, got `{kv}`"))
            })?;
            let x: f64 = match v.trim().parse() {
                Ok(x) => x,
                // A quantity with units, as in model files: `--set v_t="150 knot"`.
                Err(_) if pdyn_mech::units::looks_like_quantity(v) => {
                    pdyn_mech::units::parse_quantity(v).map_err(|e| {
                        Error::argument(
                            flag,
                            format!("{flag}: `{v}`: {} (in `{kv}`)", e.message),
                        )
                    })?
                }
                // A constant expression, units allowed: `--set omega="2*pi/(120 s)"`.
                Err(_) => {
                    let mut pool = pdyn_expr::Pool::new();
                    let value = pool
                        .parse_scalar(v)
                        .map_err(|e| e.message)
                        .and_then(|e| pool.eval_const(e).map_err(|e| e.to_string()));
                    value.map_err(|why| {
                        Error::argument(
                            flag,
                            format!("{flag}: `{v}` is not a number, a quantity such as `150 knot` or a constant expression such as `2*pi/(120 s)`: {why} (in `{kv}`)"),
                        )
                    })?
                }
            };
            if !x.is_finite() {
                return Err(Error::argument(
                    flag,
                    format!("{flag}: `{v}` is not a finite number (in `{kv}`)"),
                ));
            }
            Ok((k.trim().to_string(), x))
        })
        .collect()
}

/// Applies `--set name=value` (numbers) to a model's parameters; derived parameters and
/// initial conditions follow ([`pdyn_mech::parameters::set_values`]).
pub fn set_parameters(model: &mut pdyn_mech::Model, set: &[String]) -> Result<(), Error> {
    let values = numeric_pairs(set, "--set")?;
    pdyn::params::set_parameter_values(model, &values, "--set")
}
