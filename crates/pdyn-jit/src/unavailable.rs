//! The build without a code generator (WebAssembly): [`JitProgram::compile`] says so, and
//! [`crate::Evaluator`] with `JitMode::Auto` interprets, as on any host Cranelift does not
//! support. A `JitProgram` cannot exist here, so its methods are never reached; they keep the
//! native build's signatures so that callers compile unchanged.
use crate::JitError;
use pdyn_expr::Program;

/// A program as native code: none can be made in this build (see the module documentation).
#[derive(Clone, Debug)]
pub struct JitProgram {
    never: std::convert::Infallible,
}

impl JitProgram {
    /// Always [`JitError::Unsupported`]: this build has no code generator.
    pub fn compile(_prog: &Program) -> Result<JitProgram, JitError> {
        Err(JitError::Unsupported {
            reason: "built for WebAssembly, where programs are interpreted".to_string(),
        })
    }

    /// Number of generated functions.
    pub fn chunks(&self) -> usize {
        match self.never {}
    }

    /// A spill array for [`JitProgram::eval`].
    pub fn workspace(&self) -> Vec<f64> {
        match self.never {}
    }

    /// Number of inputs read by [`JitProgram::eval`].
    pub fn n_inputs(&self) -> usize {
        match self.never {}
    }

    /// Number of outputs written by [`JitProgram::eval`].
    pub fn n_outputs(&self) -> usize {
        match self.never {}
    }

    /// Number of instructions of the source program.
    pub fn len(&self) -> usize {
        match self.never {}
    }

    /// True when the source program had no instruction.
    pub fn is_empty(&self) -> bool {
        match self.never {}
    }

    /// Evaluates every output.
    pub fn eval(&self, _inputs: &[f64], _ws: &mut [f64], _out: &mut [f64]) {
        match self.never {}
    }
}
