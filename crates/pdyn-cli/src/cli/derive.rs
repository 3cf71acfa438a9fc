//! `pdyn derive MODEL`: the equations of motion of a model file, as the chapter writes them
//! (the text is `pdyn::report::derive::report`'s).

use clap::{Args, ValueEnum};
use pdyn::report::derive::DeriveRequest;
use pdyn::Error;
use pdyn_mech::derive::Form;
use std::path::PathBuf;

/// Which equations to derive.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormArg {
    /// Newton's equations, or the projected form when undeclared reactions make them outnumber the unknowns.
    Auto,
    /// F = ma per particle with reactions as unknowns.
    Newton,
    /// M(q) q'' = f (Kane): workless reactions eliminated.
    Projected,
}

/// `pdyn derive`.
#[derive(Args, Debug)]
pub struct DeriveArgs {
    /// The model file (TOML), e.g. examples/satellite.toml.
    model: PathBuf,
    /// Print expressions in LaTeX.
    #[arg(long)]
    latex: bool,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
    /// Which equations to build.
    #[arg(long, value_enum, default_value_t = FormArg::Auto)]
    form: FormArg,
    /// Largest system eliminated symbolically (larger ones are solved numerically when run).
    #[arg(long, default_value_t = pdyn::report::derive::SYMBOLIC_LIMIT)]
    symbolic_limit: usize,
    /// Eliminate exactly even when it is expensive (the 3-link chain), and print
    /// explicit accelerations up to 2,000 characters (without it: elimination and
    /// simplification within a small work budget, explicit forms up to 600 characters, larger
    /// ones written by reference, (M⁻¹ f)_1).
    #[arg(long)]
    solve: bool,
}

/// `pdyn derive MODEL`.
pub fn run(a: DeriveArgs) -> Result<String, Error> {
    // Loaded compact: a model too large to print is refused before its families are expanded.
    let model = pdyn::model_file::ModelFile::read(&a.model)?.mechanics_deferring()?;
    let req = DeriveRequest {
        latex: a.latex,
        json: a.json,
        form: match a.form {
            FormArg::Auto => Form::Auto,
            FormArg::Newton => Form::Newton,
            FormArg::Projected => Form::Projected,
        },
        symbolic_limit: a.symbolic_limit,
        solve: a.solve,
    };
    pdyn::report::derive::report(model, &req)
}
