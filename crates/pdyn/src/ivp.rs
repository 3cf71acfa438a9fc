//! Right-hand sides given as expression strings (`pdyn.solve_ivp(["y1", "-y0"], ...)`):
//! expressions in `t`, `y0..y{n-1}` and named arguments, compiled to one program — native code
//! by pdyn-jit where there is a JIT — and cached, so that a loop calling `solve_ivp` with the
//! same expressions (other `args` values, other `y0`) compiles them once.

use pdyn_expr::{Pool, Program};
use std::fmt;
use std::sync::{Arc, Mutex};

/// Why expressions do not compile.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum IvpCompileError {
    /// An expression that does not parse.
    Parse {
        /// Its index in the list.
        index: usize,
        /// Its text.
        text: String,
        /// 1-based column of the problem.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// Expressions that parse but do not compile (an unknown name, a vector).
    Compile {
        /// The compiler's message.
        message: String,
        /// The state size (the names `y0..y{n-1}` are defined).
        n: usize,
    },
}

impl fmt::Display for IvpCompileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IvpCompileError::Parse {
                index,
                text,
                column,
                message,
            } => write!(
                f,
                "expression {index} (`{text}`), column {column}: {message}"
            ),
            IvpCompileError::Compile { message, n } => write!(
                f,
                "{message} (the expressions may use t, y0..y{}, and the names given in args)",
                n.saturating_sub(1)
            ),
        }
    }
}

impl std::error::Error for IvpCompileError {}

/// The cache key: expressions, state size, parameter names, JIT mode.
type CacheKey = (Vec<String>, usize, Vec<String>, bool);
/// Compiled right-hand sides. Bounded: cleared when it holds [`CACHE_SIZE`] programs.
static COMPILED: Mutex<Vec<(CacheKey, Arc<pdyn_jit::Evaluator>)>> = Mutex::new(Vec::new());
/// Most programs the cache keeps.
pub const CACHE_SIZE: usize = 64;

/// [`compile_exprs`], then native code (`jit`) with the interpreter as fallback; cached.
pub fn compile_rhs(
    exprs: &[String],
    n: usize,
    params: &[(String, f64)],
    jit: bool,
) -> Result<Arc<pdyn_jit::Evaluator>, IvpCompileError> {
    let key: CacheKey = (
        exprs.to_vec(),
        n,
        params.iter().map(|p| p.0.clone()).collect(),
        jit,
    );
    // A panic while the lock was held cannot leave the list half-written (a push or a clear):
    // the poisoned list is still a valid cache.
    let mut cache = COMPILED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, ev)) = cache.iter().find(|(k, _)| *k == key) {
        return Ok(ev.clone());
    }
    let program = compile_exprs(exprs, n, params)?;
    let mode = if jit {
        pdyn_jit::JitMode::Auto
    } else {
        pdyn_jit::JitMode::Off
    };
    let ev = Arc::new(pdyn_jit::Evaluator::new(program, mode));
    if cache.len() >= CACHE_SIZE {
        cache.clear();
    }
    cache.push((key, ev.clone()));
    Ok(ev)
}

/// Compiles expressions in `t`, `y0..y{n-1}` and the names of `params` into one program
/// over the inputs `[t, y0.., params..]`.
pub fn compile_exprs(
    exprs: &[String],
    n: usize,
    params: &[(String, f64)],
) -> Result<Program, IvpCompileError> {
    let mut pool = Pool::new();
    let mut outputs = Vec::new();
    for (i, src) in exprs.iter().enumerate() {
        let id = pool.parse_scalar(src).map_err(|e| {
            let (_, column) = pdyn_expr::error::line_col(src, e.span.start);
            IvpCompileError::Parse {
                index: i,
                text: src.clone(),
                column,
                message: e.message,
            }
        })?;
        outputs.push(id);
    }
    let mut inputs = vec![pool.var("t")];
    for k in 0..n {
        inputs.push(pool.var(&format!("y{k}")));
    }
    for (name, _) in params {
        inputs.push(pool.var(name));
    }
    Program::compile(&mut pool, &inputs, &outputs).map_err(|e| IvpCompileError::Compile {
        message: e.to_string(),
        n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_compile_once_and_errors_are_located() {
        let exprs = vec!["y1".to_string(), "-k*y0".to_string()];
        let params = [("k".to_string(), 4.0)];
        let a = compile_rhs(&exprs, 2, &params, false).unwrap();
        let b = compile_rhs(&exprs, 2, &params, false).unwrap();
        assert!(
            Arc::ptr_eq(&a, &b),
            "the second call is served by the cache"
        );
        let e = compile_exprs(&["y1 +".to_string()], 2, &[]).unwrap_err();
        assert!(matches!(e, IvpCompileError::Parse { index: 0, .. }), "{e}");
        let e = compile_exprs(&["z".to_string()], 2, &[]).unwrap_err();
        assert!(e.to_string().contains("y0..y1"), "{e}");
    }
}
