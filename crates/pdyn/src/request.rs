//! The options of one run, for every model kind, as a front end gives them: `pdyn run`'s flags
//! or `Model.run`'s keywords. Each kind resolves them against its own file table once, in the
//! library ([`crate::sim::request`], [`crate::nbody::request`], [`crate::md::request`]), and
//! refuses by name ([`crate::options::RunOption`]) what has no meaning for it.

use crate::sim::JitMode;
use std::path::PathBuf;

/// The options of one run, each `None` (or empty) when not given: the model file applies.
#[derive(Clone, Debug, Default)]
pub struct Request {
    /// Method name (`auto`, `dop853`, `radau5`, … or `exact`; `whfast`, `ias15`, `leapfrog`).
    pub method: Option<String>,
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// End time.
    pub t_end: Option<f64>,
    /// Fixed step, or first step.
    pub dt: Option<f64>,
    /// Largest step.
    pub max_step: Option<f64>,
    /// Step limit.
    pub max_steps: Option<usize>,
    /// Equally spaced output times.
    pub points: Option<usize>,
    /// Output interval.
    pub output_dt: Option<f64>,
    /// Output times (SciPy's `t_eval`).
    pub t_eval: Option<Vec<f64>>,
    /// Relative drift of a conserved quantity that is reported.
    pub drift_tolerance: Option<f64>,
    /// Parameter values (`--set`, `params=`), checked against the model's parameters.
    pub params: Vec<(String, f64)>,
    /// Native code for compiled expressions, or the interpreter.
    pub jit: JitMode,
    /// Directory the run's files are written into (MD streams its frames there as it runs).
    pub out: Option<PathBuf>,
    /// Also draw the run's plots into `out`.
    pub plots: bool,
    /// Set by another thread to stop the run early, keeping what was computed (Ctrl-C in
    /// Python; the front end knows it set it).
    pub interrupt: Option<pdyn_ode::Interrupt>,
    /// An MD run's frames for a front end that animates them (`Progress::Frame`), one every
    /// this many steps (default: the model's `dump_every`); no file is written for them.
    pub frame_every: Option<u64>,
}
