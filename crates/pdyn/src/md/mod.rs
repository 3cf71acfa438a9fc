//! Molecular dynamics from a model file: the `[md]` table.
//!
//! The pipeline mirrors `sim` for the mechanics models: [`spec::parse`] reads the table with
//! spans (numbers may be expressions of `[parameters]`, after `--set`; [`load`] adds the check
//! of the `--set` names, [`request::plan`] a front end's options), [`build::build`]
//! compiles the pair potentials (built-in kernels, or a formula in `r` differentiated and
//! compiled by pdyn-expr and pdyn-jit, [`formula`]) and sets up a `pdyn_md::Simulation`
//! (lattice or file, bonds, Maxwell–Boltzmann velocities, minimisation, thermostat),
//! [`run::run`] steps it and gathers thermodynamics, trajectory frames, RDF and MSD, and
//! [`output`] writes the files and the summary. pdyn-md knows nothing of files or symbols:
//! everything about the model file lives here. See `docs/md.md` for the format.

pub mod build;
pub mod data_file;
pub mod formula;
pub mod memory;
pub mod output;
pub mod pair;
pub mod rdf_blocks;
pub mod request;
pub mod run;
pub mod spec;

pub use build::{build, Prepared};
pub use run::{run, MdResult, Progress, RunOptions};
pub use spec::{parse, MdSpec};

use crate::Error;

/// Reads a molecular-dynamics model as [`crate::nbody::load`] reads an N-body one: `source` is
/// the text of the file `origin`, `set` overrides parameters; a problem in the file is a
/// located [`Error::Model`], a `set` name that is not a parameter an [`Error::Argument`].
pub fn load(source: &str, origin: &str, set: &[(String, f64)]) -> Result<MdSpec, Error> {
    let spec = parse(source, origin, set).map_err(|error| Error::Model {
        error,
        source: source.into(),
    })?;
    if let Some((k, _)) = set
        .iter()
        .find(|(k, _)| !spec.parameters.iter().any(|(n, _)| n == k))
    {
        let names: Vec<&str> = spec.parameters.iter().map(|(n, _)| n.as_str()).collect();
        return Err(Error::argument(
            "--set",
            format!(
                "--set: `{k}` is not a parameter (parameters: {})",
                names.join(", ")
            ),
        ));
    }
    Ok(spec)
}
