//! A pair potential written as a formula in `r`, derived and compiled.
//!
//! The text `u(r)` is parsed by pdyn-expr with every `[parameters]` name bound to its value
//! and `r` bound to `√s`, `s = r²` a positive symbol: the force loop of pdyn-md hands over
//! squared distances, and in `s` most potentials need no square root at all (Lennard-Jones:
//! `(σ/r)¹² = σ¹² s⁻⁶`). The force follows from the derivative in `s`,
//! `f/r = −u'(r)/r = −2 du/ds`, and one program computes `(u, f/r)` from `s`, the pair
//! [`pdyn_md::potential::RawPair`] expects. The cutoff modes (shifted energy, shifted force)
//! come from [`pdyn_md::potential::Truncated`], as for the built-in kernels.
//!
//! The program runs as a pdyn-jit [`BatchKernel`]: one native loop over all of a particle's
//! neighbours per call ([`RawPair::raw_batch`]), two pairs per iteration in packed registers,
//! the divisions by powers of `s` sharing one reciprocal; single points ([`FormulaPair::at`])
//! go through the same kernel. Without a JIT (`--no-jit`, or no Cranelift backend) the
//! kernel's column interpreter runs the same operations, with the same bits.

use pdyn_expr::syntax::Ast;
use pdyn_expr::{Binding, ExprError, Number, Pool, Program, Scope, Value};
use pdyn_jit::{BatchKernel, JitMode};
use pdyn_md::potential::RawPair;
use std::ops::Range;

/// A compiled `u(r)`: input `s = r²`, outputs `u(r)` and `−u'(r)/r`.
#[derive(Debug, Clone)]
pub struct FormulaPair {
    kernel: BatchKernel,
    text: String,
}

/// Why a formula cannot be a pair potential.
#[derive(Debug, Clone, PartialEq)]
pub struct FormulaError {
    /// Byte range in the formula text.
    pub span: Range<usize>,
    /// What is wrong.
    pub message: String,
    /// What would be valid.
    pub help: Option<String>,
}

impl From<ExprError> for FormulaError {
    fn from(e: ExprError) -> Self {
        FormulaError {
            span: e.span,
            message: e.message,
            help: e.help,
        }
    }
}

struct RScope<'a> {
    r: pdyn_expr::Id,
    params: &'a [(String, f64)],
}

impl Scope for RScope<'_> {
    fn resolve(&mut self, pool: &mut Pool, name: &str) -> Option<Binding> {
        if name == "r" {
            return Some(Binding::Value(Value::Scalar(self.r)));
        }
        let (_, v) = self.params.iter().rev().find(|(n, _)| n == name)?;
        // Integers stay exact so that the derivative keeps integer exponents and factors.
        let num = if v.fract() == 0.0 && v.abs() < 1e15 {
            pdyn_expr::Rational::new(*v as i128, 1).map_or(Number::Float(*v), Number::Rat)
        } else {
            Number::Float(*v)
        };
        Some(Binding::Value(Value::Scalar(pool.num(num))))
    }
    fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.params.iter().map(|(n, _)| n.clone()).collect();
        v.push("r".into());
        v
    }
}

/// Names used in `ast` that are neither `r`, a parameter, `pi` nor `e`, with their spans; and
/// whether `r` appears at all.
fn foreign_names(
    ast: &Ast,
    params: &[(String, f64)],
    out: &mut Vec<(String, Range<usize>)>,
    uses_r: &mut bool,
) {
    match ast {
        Ast::Ident { name, span } => {
            if name == "r" {
                *uses_r = true;
            } else if !params.iter().any(|(n, _)| n == name) && name != "pi" && name != "e" {
                out.push((name.clone(), span.clone()));
            }
        }
        Ast::Num { .. } | Ast::Quantity { .. } => {}
        Ast::Neg { expr, .. } | Ast::Component { expr, .. } => {
            foreign_names(expr, params, out, uses_r)
        }
        Ast::Prime { expr, span, .. } => {
            out.push(("'".into(), span.clone()));
            foreign_names(expr, params, out, uses_r)
        }
        Ast::Binary { lhs, rhs, .. } => {
            foreign_names(lhs, params, out, uses_r);
            foreign_names(rhs, params, out, uses_r);
        }
        Ast::Call { args, .. } => args
            .iter()
            .for_each(|a| foreign_names(a, params, out, uses_r)),
        Ast::Vector { items, .. } => items
            .iter()
            .for_each(|a| foreign_names(a, params, out, uses_r)),
    }
}

impl FormulaPair {
    /// Parses, differentiates and compiles `text` (a formula in `r` and `params`).
    pub fn compile(
        text: &str,
        params: &[(String, f64)],
        mode: JitMode,
    ) -> Result<FormulaPair, FormulaError> {
        let ast = pdyn_expr::syntax::parse(text)?;
        let mut foreign = vec![];
        let mut uses_r = false;
        foreign_names(&ast, params, &mut foreign, &mut uses_r);
        if let Some((_, span)) = foreign.first() {
            let mut names: Vec<String> = vec![];
            for (n, _) in &foreign {
                let n = format!("`{n}`");
                if !names.contains(&n) {
                    names.push(n);
                }
            }
            return Err(FormulaError {
                span: span.clone(),
                message: format!(
                    "a pair potential must be a function of r alone, but it also uses {}",
                    names.join(", ")
                ),
                help: Some("constants belong in [parameters]; the distance is `r`".into()),
            });
        }
        if !uses_r {
            return Err(FormulaError {
                span: ast.span(),
                message: "the potential does not depend on r (it exerts no force)".into(),
                help: Some("write u(r) in terms of the pair distance `r`".into()),
            });
        }
        let mut pool = Pool::new();
        let ss = pool.symbol("r²", true);
        let s = pool.sym(ss);
        let half = pool.num(Number::ratio(1, 2));
        let r = pool.pow(s, half);
        let mut scope = RScope { r, params };
        let u = match pdyn_expr::lower::lower(&mut pool, &ast, &mut scope)? {
            Value::Scalar(u) => u,
            Value::Vector(_) => {
                return Err(FormulaError {
                    span: ast.span(),
                    message: "a pair potential is a scalar, not a vector".into(),
                    help: None,
                })
            }
        };
        // f/r = −u'(r)/r = −2 du/ds, since du/ds = u'(r)/(2r)
        let du = pool.diff(u, s);
        let fr = pool.scale(Number::int(-2), du);
        let cannot = |e: String| FormulaError {
            span: ast.span(),
            message: format!("cannot compile the potential: {e}"),
            help: None,
        };
        let prog =
            Program::compile(&mut pool, &[s], &[u, fr]).map_err(|e| cannot(e.to_string()))?;
        let kernel = BatchKernel::new(&prog, mode)
            .ok_or_else(|| cannot("an operation without a batch kernel".into()))?;
        Ok(FormulaPair {
            kernel,
            text: text.to_string(),
        })
    }

    /// True when the formula runs as native code.
    pub fn is_native(&self) -> bool {
        self.kernel.is_native()
    }

    /// The formula as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// `(u(r), −u'(r)/r)` at distance `r`.
    pub fn at(&self, r: f64) -> (f64, f64) {
        self.at_squared(r * r)
    }

    /// `(u, f/r)` at the squared distance `r2`.
    pub fn at_squared(&self, r2: f64) -> (f64, f64) {
        let (mut u, mut fr) = ([0.0], [0.0]);
        self.kernel.run(&[&[r2]], &mut [&mut u, &mut fr]);
        (u[0], fr[0])
    }

    /// `(u, f/r)` at the squared distances `r2` (slices of one length), one call of the
    /// kernel; the same bits as [`FormulaPair::at_squared`] point by point.
    pub fn at_squared_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        self.kernel.run(&[r2], &mut [u, fr]);
    }
}

impl RawPair for FormulaPair {
    #[inline]
    fn raw(&self, r2: f64) -> (f64, f64) {
        self.at_squared(r2)
    }

    fn raw_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        self.at_squared_batch(r2, u, fr)
    }

    fn prefers_batch(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pdyn_md::potential::{CutoffMode, LennardJones, Morse, PairPotential, Truncated};

    fn params() -> Vec<(String, f64)> {
        vec![
            ("eps".into(), 1.3),
            ("sigma".into(), 0.9),
            ("D".into(), 0.8),
            ("a".into(), 1.7),
            ("r0".into(), 1.1),
        ]
    }

    const LJ: &str = "4*eps*((sigma/r)^12 - (sigma/r)^6)";

    /// The compiled force is −du/dr by central differences, for both engines and every
    /// cutoff mode.
    #[test]
    fn force_is_minus_derivative_by_finite_differences() {
        for mode in [JitMode::Auto, JitMode::Off] {
            for text in [
                LJ,
                "D*((1 - exp(-a*(r - r0)))^2 - 1)",
                "eps*exp(-r/sigma)/r",
                "sin(r)^2 + r^3/7",
            ] {
                let f = FormulaPair::compile(text, &params(), mode).unwrap();
                for cm in [
                    CutoffMode::Plain,
                    CutoffMode::ShiftedEnergy,
                    CutoffMode::ShiftedForce,
                ] {
                    let p = Truncated::new(f.clone(), 2.7, cm);
                    for r in [0.83, 0.97, 1.21, 1.77, 2.5] {
                        let h = 1e-6;
                        let du = (p.energy_force((r + h) * (r + h)).0
                            - p.energy_force((r - h) * (r - h)).0)
                            / (2.0 * h);
                        let fr = p.energy_force(r * r).1;
                        assert!(
                            (fr * r + du).abs() < 1e-6 * (1.0 + du.abs()),
                            "{text} {cm:?} r={r}: f = {}, -du/dr = {}",
                            fr * r,
                            -du
                        );
                    }
                }
            }
        }
    }

    /// The formula and the built-in kernels agree to round-off.
    #[test]
    fn formula_matches_builtin_kernels() {
        let lj = FormulaPair::compile(LJ, &params(), JitMode::Auto).unwrap();
        let mo = FormulaPair::compile("D*((1 - exp(-a*(r - r0)))^2 - 1)", &params(), JitMode::Auto)
            .unwrap();
        let klj = LennardJones::new(1.3, 0.9);
        let kmo = Morse::new(0.8, 1.7, 1.1);
        for r in [0.8, 0.9, 1.0, 1.3, 2.0, 2.4] {
            for ((u, f), (v, g)) in [
                (lj.raw(r * r), klj.raw(r * r)),
                (mo.raw(r * r), kmo.raw(r * r)),
            ] {
                assert!(
                    (u - v).abs() <= 1e-13 * (1.0 + v.abs()),
                    "u {u} vs {v} at {r}"
                );
                assert!(
                    (f - g).abs() <= 1e-13 * (1.0 + g.abs()),
                    "f/r {f} vs {g} at {r}"
                );
            }
        }
    }

    /// The batch, the point evaluation and the two engines (native code, `--no-jit`'s
    /// interpreter) give the same bits at random distances, for every operation kind and
    /// batch lengths across the kernel's packing (two pairs) and the interpreter's columns.
    #[test]
    fn batch_point_and_engines_agree_bit_for_bit() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let r2: Vec<f64> = (0..130)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                0.3 + 8.0 * ((state >> 11) as f64 / (1u64 << 53) as f64)
            })
            .collect();
        for text in [
            LJ,
            "D*((1 - exp(-a*(r - r0)))^2 - 1)",
            "eps*exp(-r/sigma)/r + r^(-7) - r^(-3)",
            "sin(r)^2 + r^3/7 + atan(r) + sqrt(r) + abs(r - 1) + log(r) + cosh(r)",
            "min(r, 1.5) + max(r^2, 2) + sign(r - 1)*tanh(r) + r^2.5",
        ] {
            let native = FormulaPair::compile(text, &params(), JitMode::Auto).unwrap();
            assert!(native.is_native(), "this test host has a Cranelift backend");
            let interp = FormulaPair::compile(text, &params(), JitMode::Off).unwrap();
            assert!(!interp.is_native());
            for n in [1, 2, 3, 4, 63, 64, 65, 130] {
                let batch = |f: &FormulaPair| {
                    let (mut u, mut fr) = (vec![0.0; n], vec![0.0; n]);
                    f.raw_batch(&r2[..n], &mut u, &mut fr);
                    (u, fr)
                };
                let (a, b) = (batch(&native), batch(&interp));
                for (k, &s) in r2[..n].iter().enumerate() {
                    let p = native.raw(s);
                    let q = interp.raw(s);
                    for (x, y) in [
                        (a.0[k], b.0[k]),
                        (a.1[k], b.1[k]),
                        (a.0[k], p.0),
                        (a.1[k], p.1),
                        (p.0, q.0),
                        (p.1, q.1),
                    ] {
                        assert_eq!(
                            x.to_bits(),
                            y.to_bits(),
                            "{text}, r2 = {s}, n = {n}: {x:e} vs {y:e}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn other_symbols_are_named_and_located() {
        let e = FormulaPair::compile("4*eps*((s/r)^12 - (s/x)^6)", &params(), JitMode::Off)
            .unwrap_err();
        assert!(
            e.message.contains("`s`") && e.message.contains("`x`"),
            "{}",
            e.message
        );
        assert_eq!(e.span, 8..9);
        assert_eq!(e.message.matches("`s`").count(), 1, "{}", e.message);
        let e = FormulaPair::compile("eps*t", &params(), JitMode::Off).unwrap_err();
        assert!(e.message.contains("`t`"), "{}", e.message);
        let e = FormulaPair::compile("eps*sigma", &params(), JitMode::Off).unwrap_err();
        assert!(e.message.contains("does not depend on r"), "{}", e.message);
    }
}
