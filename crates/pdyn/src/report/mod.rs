//! What the commands other than `run` print, built once for every front end (the binary,
//! the browser): the derivation (`pdyn derive`), the forces of a prescribed motion
//! (`pdyn forces`), the check against a closed form (`pdyn check`), a sweep (`pdyn sweep`),
//! kinematics from formulas (`pdyn kin`) and closed-form solutions (`pdyn dsolve`), each as
//! text or JSON from typed results and options; expressions in a [`notation::Notation`].

pub mod bounded;
pub mod check;
pub mod derive;
pub mod dsolve;
pub mod forces;
pub mod kin;
pub mod notation;
pub mod sweep;

use crate::Error;

/// A command's output: text (or JSON) for stdout, warnings, and a failure that came after
/// output was produced (an integration that stopped: exit code 1).
#[derive(Debug, Default)]
pub struct Report {
    /// The text or JSON.
    pub stdout: String,
    /// Warnings, one `warning: …` line each.
    pub stderr: String,
    /// A failure after output was produced.
    pub failure: Option<Error>,
}
