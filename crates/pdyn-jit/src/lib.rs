//! # pdyn-jit — native code for compiled right-hand sides
//!
//! [`pdyn_expr::Program`] is a flat register program run by an interpreter: each instruction
//! costs a `match` dispatch and a load/store through the register file. This crate translates
//! the same instruction list into machine code with Cranelift, so that a compiled right-hand
//! side runs near the speed of a hand-written Rust closure. `pdyn-expr` stays free of the code
//! generator: it only exposes a read-only view of a program (instructions, constants, output
//! registers), and this crate depends on it.
//!
//! ## What is emitted, and why results agree bit for bit
//! Functions `extern "C" fn(inputs: *const f64, out: *mut f64, spill: *mut f64)`, one per
//! chunk of 2,048 instructions, each a single basic block, called in order (values a later
//! chunk or a later call-free segment needs pass through the `spill` workspace, bits
//! unchanged; long live ranges make Cranelift's register allocation superlinear — see
//! `SpillPlan`): every instruction of the program becomes one
//! SSA value, in the program's order, so the
//! arithmetic is the same sequence of IEEE operations as the interpreter's (no reassociation,
//! no fused multiply-add). `+ − × ÷`, negation, `sqrt`, `abs` and `sign` are native
//! instructions (correctly rounded, like Rust's); integer powers up to 64 are multiplied out
//! in `f64::powi`'s own order. Transcendental functions (`sin`, `cos`,
//! `tan`, `asin`, `acos`, `atan`, `atan2`, `sinh`, `cosh`, `tanh`, `exp`, `ln`, `powf`,
//! larger `powi`) and `min`/`max` call `extern "C"` shims that call the same `f64` methods the
//! interpreter calls, hence the same libm: the JIT and [`Program::eval`] give identical bits
//! (NaN payloads aside). `min`/`max` go through shims because Rust's NaN-ignoring semantics and
//! its choice between `+0` and `−0` are not those of Cranelift's `fmin`/`fmax`.
//!
//! ## Choosing the engine
//! [`JitProgram::compile`] fails with [`JitError::Unsupported`] where Cranelift has no backend
//! for the host. [`Evaluator`] wraps the choice: [`JitMode::Auto`] uses native code when it can
//! and falls back to the interpreter otherwise; [`JitMode::Off`] always interprets (the CLI
//! exposes this as `--no-jit`). Both engines have the same `eval(inputs, ws, out)` contract.
//!
//! ## Threads
//! A [`JitProgram`] is `Send + Sync` and cheap to clone (the code is shared behind an `Arc`):
//! the generated function touches only its arguments and its own stack frame, so any number
//! of threads may call it at once. The code memory is freed when the last clone is dropped.
#![warn(missing_docs)]

use pdyn_expr::compile::CompiledLinearSystem;
use pdyn_expr::hoist::{HoistedInputs, HoistedProgram};
use pdyn_expr::lu::{DenseSolver, SingularMatrix};
use pdyn_expr::Program;

mod batch;
// Cranelift generates code for the host; a WebAssembly build has neither a host code generator
// nor executable memory, so there `native` is the module that says so and everything
// interprets (`JitMode::Auto` falls back, as on any platform without a backend).
#[cfg_attr(target_arch = "wasm32", path = "unavailable.rs")]
mod native;
pub use native::JitProgram;

pub use batch::BatchKernel;

/// Why a program could not be compiled to native code. The interpreter remains usable.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum JitError {
    /// Cranelift has no code generator for this host (architecture or OS).
    Unsupported {
        /// Cranelift's reason.
        reason: String,
    },
    /// The program uses an operation this crate does not translate (a newer `Op`).
    UnsupportedOp {
        /// The operation, printed.
        op: String,
    },
    /// Cranelift rejected the generated function (a bug here, reported rather than panicking).
    Codegen {
        /// Cranelift's message.
        message: String,
    },
}

impl std::fmt::Display for JitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JitError::Unsupported { reason } => {
                write!(f, "no native code generator for this platform: {reason}")
            }
            JitError::UnsupportedOp { op } => {
                write!(f, "operation {op} has no native translation")
            }
            JitError::Codegen { message } => write!(f, "native code generation failed: {message}"),
        }
    }
}

impl std::error::Error for JitError {}

/// Whether to generate native code. Default: [`JitMode::Auto`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum JitMode {
    /// Native code where the platform supports it, the interpreter otherwise.
    #[default]
    Auto,
    /// Always the interpreter (the CLI's `--no-jit`).
    Off,
}

/// A compiled program run natively or by the interpreter, behind one `eval` contract.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum Evaluator {
    /// Native code.
    Native(JitProgram),
    /// The interpreter of [`Program::eval`].
    Interpreted(Program),
}

impl Evaluator {
    /// Chooses the engine for `prog` according to `mode`; with [`JitMode::Auto`], a failure of
    /// the JIT (unsupported platform, code generation error) falls back to the interpreter.
    pub fn new(prog: Program, mode: JitMode) -> Evaluator {
        match mode {
            JitMode::Off => Evaluator::Interpreted(prog),
            JitMode::Auto => match JitProgram::compile(&prog) {
                Ok(j) => Evaluator::Native(j),
                Err(_) => Evaluator::Interpreted(prog),
            },
        }
    }

    /// True when native code runs.
    pub fn is_native(&self) -> bool {
        matches!(self, Evaluator::Native(_))
    }

    /// A workspace for [`Evaluator::eval`].
    pub fn workspace(&self) -> Vec<f64> {
        match self {
            Evaluator::Native(j) => j.workspace(),
            Evaluator::Interpreted(p) => p.workspace(),
        }
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        match self {
            Evaluator::Native(j) => j.n_outputs(),
            Evaluator::Interpreted(p) => p.n_outputs(),
        }
    }

    /// Evaluates every output, with the contract of [`Program::eval`]; `ws` must come from
    /// [`Evaluator::workspace`].
    #[inline]
    pub fn eval(&self, inputs: &[f64], ws: &mut [f64], out: &mut [f64]) {
        match self {
            Evaluator::Native(j) => j.eval(inputs, ws, out),
            Evaluator::Interpreted(p) => p.eval(inputs, ws, out),
        }
    }
}

/// A [`CompiledLinearSystem`] whose entries `A`, `b` are evaluated by an [`Evaluator`] (the
/// main part of its [`HoistedProgram`]; the parameter-only prelude is interpreted, once per
/// parameter change), then solved by the same [`DenseSolver`]. Owns its buffers; `solve`
/// allocates nothing.
#[derive(Clone, Debug)]
pub struct JitLinearSystem {
    program: HoistedProgram,
    inputs: HoistedInputs,
    eval: Evaluator,
    n: usize,
    ws: Vec<f64>,
    ab: Vec<f64>,
    solver: DenseSolver,
}

impl JitLinearSystem {
    /// Builds the evaluator of `sys`'s entries according to `mode`.
    pub fn new(sys: &CompiledLinearSystem, mode: JitMode) -> JitLinearSystem {
        let n = sys.n();
        let program = sys.program().clone();
        let eval = Evaluator::new(program.main().clone(), mode);
        JitLinearSystem {
            inputs: HoistedInputs::new(&program),
            program,
            ws: eval.workspace(),
            eval,
            n,
            ab: vec![0.0; n * n + n],
            solver: sys.solver(),
        }
    }

    /// True when the entries are evaluated by native code.
    pub fn is_native(&self) -> bool {
        self.eval.is_native()
    }

    /// Solves for the unknowns at `inputs`, writing them to `x` (as
    /// [`CompiledLinearSystem::solve`], with the same result bits).
    pub fn solve(&mut self, inputs: &[f64], x: &mut [f64]) -> Result<(), SingularMatrix> {
        let ext = self.inputs.update(&self.program, inputs);
        self.eval.eval(ext, &mut self.ws, &mut self.ab);
        debug_assert_eq!(self.ab.len(), self.n * self.n + self.n);
        self.solver.solve(&mut self.ab, x)
    }
}
