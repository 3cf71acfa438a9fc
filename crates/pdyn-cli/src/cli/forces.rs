//! `pdyn forces MODEL`: the forces a prescribed motion requires, and design criteria (the text
//! is `pdyn::report::forces::report`'s).

use super::{load_model, numeric_pairs, set_parameters};
use clap::Args;
use pdyn::report::forces::ForcesRequest;
use pdyn::Error;
use std::path::PathBuf;

/// `pdyn forces`.
#[derive(Args, Debug)]
pub struct ForcesArgs {
    /// The model file (TOML), e.g. examples/aircraft_turn.toml.
    model: PathBuf,
    /// The instant: `t=…` and coordinate values, e.g. `--at t=0,theta=0.5`.
    #[arg(long, value_delimiter = ',')]
    at: Vec<String>,
    /// Override parameter values, e.g. `--set V=102,m=3e5`.
    #[arg(long, value_delimiter = ',')]
    set: Vec<String>,
    /// Print expressions in LaTeX.
    #[arg(long)]
    latex: bool,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

/// `pdyn forces MODEL`.
pub fn run(a: ForcesArgs) -> Result<String, Error> {
    let mut model = load_model(&a.model)?;
    set_parameters(&mut model, &a.set)?;
    let req = ForcesRequest {
        at: numeric_pairs(&a.at, "--at")?,
        latex: a.latex,
        json: a.json,
    };
    pdyn::report::forces::report(model, &req)
}
