//! The build without a code generator (WebAssembly): no native loop can be compiled, so a
//! [`super::BatchKernel`] runs the column interpreter (the same bits).
use super::Steps;
use crate::JitError;

/// The code of one kernel: none exists in this build.
pub(super) enum BatchCode {}

/// Always [`JitError::Unsupported`].
pub(super) fn compile(_steps: &Steps) -> Result<BatchCode, JitError> {
    Err(JitError::Unsupported {
        reason: "built for WebAssembly, where kernels are interpreted".to_string(),
    })
}

/// Never called: no [`BatchCode`] exists.
pub(super) fn call(code: &BatchCode, _ip: &[*const f64], _op: &[*mut f64], _n: usize) {
    match *code {}
}
