//! N-body models: the `[nbody]` table of a model file run on `pdyn-gravity` (see
//! `docs/nbody.md`). `pdyn run FILE` comes here when the file has a top-level `[nbody]` table.
//!
//! One concept per file, in pipeline order:
//! - [`spec`]: the TOML table (and [`csv`], bodies from a CSV file) → [`spec::NbodySpec`],
//!   values evaluated with `pdyn_mech::model::constants` (parameters, expressions, unit
//!   literals), every problem a located `ModelError`;
//! - [`build`]: the spec → a `pdyn_gravity::Simulation` (elements about their primary, the
//!   Plummer sphere, centre-of-mass frame, integrator, forces, events);
//! - [`request`]: a front end's options resolved against the table, with the limits, then
//!   built ([`request::plan`]) and run ([`request::Planned::execute`]);
//! - [`run`]: integration to the output times, conservation monitors (energy and angular
//!   momentum drift against the existing tolerance), collisions, escapes, close encounters;
//! - [`output`]: CSV files, `summary.json`, the text report; [`plots`]: the figures.

pub mod build;
pub mod csv;
pub mod output;
#[cfg(feature = "plots")]
pub mod plots;
pub mod request;
pub mod run;
pub mod spec;

use crate::options::RunOption;
use crate::Error;

/// The integrators `method` takes, with their papers (`pdyn run --method help`).
pub const METHODS_HELP: &str = "N-body integrators (integrator = \"...\" in [nbody], or --method):
  whfast    Wisdom-Holman map in Jacobi coordinates with symplectic correctors (Rein & Tamayo
            2015, MNRAS 452, 376); fixed step dt, corrector = 0, 3, 5, 7, 11 or 17. Planetary
            systems dominated by one mass; stops at close encounters (use ias15).
  ias15     Adaptive 15th-order Gauss-Radau (Rein & Spiegel 2015, MNRAS 446, 1424); dt is the
            first trial step, epsilon the accuracy (default 1e-9). Close encounters, high
            eccentricities, machine-precision energy.
  leapfrog  Drift-kick-drift, second order, symplectic, fixed step dt; with gravity = \"tree\"
            (Barnes-Hut, theta) for large N.
";

/// Reads an N-body model: `source` is the text of the file `origin`; `set` overrides
/// parameters (`--set`). Problems are located [`Error::Model`]s (in the model file, or in
/// the bodies CSV file with its text), or an [`Error::Argument`] for `--set`.
pub fn load(source: &str, origin: &str, set: &[(String, f64)]) -> Result<spec::NbodySpec, Error> {
    spec::parse(source, origin, set).map_err(|e| match *e {
        spec::SetOrSpecError::Spec(s) => Error::Model {
            error: s.error,
            source: s.source.into(),
        },
        spec::SetOrSpecError::UnknownParameter { name, parameters } => Error::argument(
            RunOption::Set.name(),
            format!(
                "{}: `{name}` is not a parameter (parameters: {parameters})",
                RunOption::Set
            ),
        ),
    })
}

/// Builds the simulation of `spec`; a problem is located in the model file (whose text is
/// `source`) or in the bodies file.
pub fn build(spec: &spec::NbodySpec, source: &str) -> Result<build::Built, Error> {
    build::build(spec).map_err(|e| {
        let text: std::sync::Arc<str> = if e.origin.file == spec.origin {
            source.into()
        } else {
            // The bodies file was read moments ago by `load`; reading it again for the message
            // is simpler than carrying its text through the spec.
            std::fs::read_to_string(&e.origin.file)
                .unwrap_or_default()
                .into()
        };
        Error::Model {
            error: e.model_error(),
            source: text,
        }
    })
}
