//! What the commands other than `run` print, built once for every front end (the binary,
//! the browser): the derivation (`pdyn derive`), the forces of a prescribed motion
//! (`pdyn forces`), the check against a closed form (`pdyn check`) and a sweep
//! (`pdyn sweep`), each as text or JSON from a loaded model and typed options.

pub mod bounded;
pub mod check;
pub mod derive;
pub mod forces;
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
