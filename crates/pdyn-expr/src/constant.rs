//! [`Pool::eval_const`]: the numeric value of an expression that has no free leaves.

use crate::compile::{CompileError, Program};
use crate::pool::{Id, Pool};

impl Pool {
    /// The value of `e` in `f64` arithmetic, when `e` contains no symbol, coordinate or `t`
    /// (otherwise the [`CompileError`] names the leaf without a value). The value may be NaN or
    /// infinite (`1/0`): callers decide what a non-finite constant means.
    pub fn eval_const(&mut self, e: Id) -> Result<f64, CompileError> {
        let prog = Program::compile(self, &[], &[e])?;
        let mut ws = prog.workspace();
        let mut out = [0.0];
        prog.eval(&[], &mut ws, &mut out);
        Ok(out[0])
    }
}

#[cfg(test)]
mod tests {
    use crate::Pool;

    #[test]
    fn constants_evaluate_and_free_symbols_are_refused() {
        let mut p = Pool::new();
        let e = p.parse_scalar("sqrt(3^2 + 4^2) + sin(pi/2)").unwrap();
        assert_eq!(p.eval_const(e).unwrap(), 6.0);
        let x = p.parse_scalar("x + 1").unwrap();
        assert!(p.eval_const(x).is_err());
    }
}
