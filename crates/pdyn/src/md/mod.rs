//! Molecular dynamics from a model file: the `[md]` table.
//!
//! The pipeline mirrors `sim` for the mechanics models: [`spec::parse`] reads the table with
//! spans (numbers may be expressions of `[parameters]`, after `--set`; [`load`] adds the check
//! of the `--set` names, [`request::plan`] a front end's options), [`build::build`]
//! compiles the pair potentials (built-in kernels, or a formula in `r` differentiated and
//! compiled by pdyn-expr and pdyn-jit, [`formula`]) and sets up a `pdyn_md::Simulation`
//! (lattice or file, bonds, Maxwell–Boltzmann velocities, minimisation, thermostat),
//! [`run::run`] steps it and gathers thermodynamics, trajectory frames, RDF and MSD, and
//! [`output`] writes the files and the summary, [`report`] the lines printed. pdyn-md knows nothing of files or symbols:
//! everything about the model file lives here. See `docs/md.md` for the format.

pub mod build;
pub mod checkpoint;
pub mod data_file;
pub mod formula;
pub mod memory;
pub mod output;
pub mod pair;
pub mod rdf_blocks;
pub mod report;
pub mod request;
pub mod run;
pub mod spec;

pub use build::{build, Prepared};
pub use run::{run, run_with, MdResult, Progress, RunOptions};
pub use spec::{parse, MdSpec};

use crate::options::RunOption;
use crate::Error;

/// What `method` means for an `[md]` model (`pdyn run --method help`): nothing to choose.
pub const METHODS_HELP: &str =
    "Molecular-dynamics models ([md]) step with velocity Verlet at the fixed step dt
(with the thermostat's splitting: BAOAB for Langevin, Trotter for Nose-Hoover chains); there is
no method to choose. Give dt and the run length (steps, or t_end), thermo_every and dump_every
in [md] (docs/md.md).
";

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
            RunOption::Set.name(),
            format!(
                "{}: `{k}` is not a parameter (parameters: {})",
                RunOption::Set,
                names.join(", ")
            ),
        ));
    }
    Ok(spec)
}
