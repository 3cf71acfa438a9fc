//! A pair potential written as a formula in `r`, derived and compiled.
//!
//! The text `u(r)` is parsed by pdyn-expr with `r` a positive symbol and every `[parameters]`
//! name bound to its value; `u'(r)` is the symbolic derivative, and one program computes
//! `(u, f/r)` with `f/r = −u'(r)/r`, the pair the force loop of pdyn-md expects
//! ([`pdyn_md::potential::RawPair`]). The program runs as native code through pdyn-jit when
//! the platform has a Cranelift backend, otherwise in pdyn-expr's interpreter; both give the
//! same bits. The cutoff modes (shifted energy, shifted force) come from
//! [`pdyn_md::potential::Truncated`], as for the built-in kernels.
//!
//! The force loop does not call the program pair by pair: it hands over all of a particle's
//! neighbours at once ([`RawPair::raw_batch`]), and the program runs *column-wise* — each
//! instruction applied to up to [`LANES`] pairs in a tight loop the compiler vectorises, so
//! the dispatch of an instruction is paid once per batch instead of once per pair. Before
//! that the instruction list is rewritten once ([`Columns::new`]): instructions no output
//! needs are dropped, and divisions share reciprocals — `a / x` becomes `a · (1/x)` with one
//! `1/x` per `x`, `1/xᵏ` becomes `(1/x)ᵏ` — because a derived potential divides by many
//! powers of `r` (LJ: five divisions per pair, against one in the built-in kernel), and a
//! division costs several multiplications. The results then differ from
//! [`FormulaPair::at`] by a few units in the last place (tested to 1e-13 relative).

use pdyn_expr::compile::Op;
use pdyn_expr::syntax::Ast;
use pdyn_expr::{Binding, ExprError, Number, Pool, Program, Scope, Value};
use pdyn_jit::{Evaluator, JitMode};
use pdyn_md::potential::RawPair;
use std::cell::RefCell;
use std::ops::Range;

/// Pairs per column of the batch evaluator: enough to amortise each instruction's dispatch,
/// few enough that a program's registers (`LANES` values each) stay in the L1 cache.
pub const LANES: usize = 64;

thread_local! {
    /// Register columns of the batch evaluator, per thread (the force loop runs on rayon
    /// workers; `raw_batch(&self)` must not allocate per call), with the id of the column
    /// program whose constants they hold.
    static COLUMNS: RefCell<(u64, Vec<f64>)> = const { RefCell::new((u64::MAX, Vec::new())) };
}

/// Ids of column programs.
static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A compiled `u(r)`: input `r`, outputs `u(r)` and `−u'(r)/r`.
#[derive(Debug, Clone)]
pub struct FormulaPair {
    eval: Evaluator,
    /// The program rewritten for the column-wise batch evaluator (`None` when it has an
    /// operation the batch evaluator does not know: `raw_batch` then goes pair by pair).
    columns: Option<Columns>,
    /// The interpreter's register file with its constants in place (empty for native code):
    /// copied per call, so that `raw(&self)` can run on any number of threads at once.
    template: Vec<f64>,
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
        let rs = pool.symbol("r", true);
        let r = pool.sym(rs);
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
        let du = pool.diff(u, r);
        let minus = pool.neg(du);
        let fr = pool.div(minus, r);
        let prog = Program::compile(&mut pool, &[r], &[u, fr]).map_err(|e| FormulaError {
            span: ast.span(),
            message: format!("cannot compile the potential: {e}"),
            help: None,
        })?;
        let eval = Evaluator::new(prog.clone(), mode);
        Ok(FormulaPair {
            columns: Columns::new(&prog),
            template: eval.workspace(),
            eval,
            text: text.to_string(),
        })
    }

    /// True when the formula runs as native code.
    pub fn is_native(&self) -> bool {
        self.eval.is_native()
    }

    /// The formula as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// `(u(r), −u'(r)/r)` at distance `r`.
    pub fn at(&self, r: f64) -> (f64, f64) {
        let mut out = [0.0; 2];
        if self.template.is_empty() {
            self.eval.eval(&[r], &mut [], &mut out);
        } else if self.template.len() <= 256 {
            let mut ws = [0.0; 256];
            let ws = &mut ws[..self.template.len()];
            ws.copy_from_slice(&self.template);
            self.eval.eval(&[r], ws, &mut out);
        } else {
            let mut ws = self.template.clone();
            self.eval.eval(&[r], &mut ws, &mut out);
        }
        (out[0], out[1])
    }

    /// `(u, f/r)` at the squared distances `r2` (slices of one length), column-wise; equal to
    /// [`FormulaPair::at`]`(r2[k].sqrt())` up to the rounding of shared reciprocals. Without a
    /// column program (an operation the batch evaluator does not know), pair by pair.
    pub fn at_squared_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        let Some(cp) = &self.columns else {
            for ((&s, u), f) in r2.iter().zip(u).zip(fr) {
                (*u, *f) = self.at(s.sqrt());
            }
            return;
        };
        COLUMNS.with(|cell| {
            let mut guard = cell.borrow_mut();
            let (id, regs) = &mut *guard;
            if regs.len() < cp.rows * LANES {
                regs.resize(cp.rows * LANES, 0.0);
                *id = u64::MAX;
            }
            let regs = &mut regs[..cp.rows * LANES];
            if *id != cp.id {
                // constant rows are never written by a step: filled once per program
                for &(row, v) in &cp.consts {
                    regs[row as usize * LANES..][..LANES].fill(v);
                }
                *id = cp.id;
            }
            for ((r2c, uc), fc) in r2
                .chunks(LANES)
                .zip(u.chunks_mut(LANES))
                .zip(fr.chunks_mut(LANES))
            {
                let m = r2c.len();
                for (x, &s) in regs[..m].iter_mut().zip(r2c) {
                    *x = s.sqrt();
                }
                for st in &cp.steps {
                    // operands lie below the destination row (`Columns::new` numbers rows so)
                    let (lo, hi) = regs.split_at_mut(st.dst as usize * LANES);
                    column(st.op, st.a, st.b, lo, &mut hi[..m]);
                }
                let row = |r: u32| &regs[r as usize * LANES..][..m];
                uc.copy_from_slice(&row(cp.outs[0])[..uc.len().min(m)]);
                fc.copy_from_slice(&row(cp.outs[1])[..fc.len().min(m)]);
            }
        });
    }
}

/// One step of a column program: `row[dst] = op(row[a], row[b])` (`b` the exponent for
/// `Powi`).
#[derive(Debug, Clone, Copy)]
struct Step {
    op: Op,
    a: u32,
    b: u32,
    dst: u32,
}

/// A [`Program`] rewritten for column-wise evaluation: rows `[inputs | constants |
/// temporaries | new rows]`, the live instructions only, divisions through shared reciprocals.
#[derive(Debug, Clone)]
struct Columns {
    /// Identifies the program in a thread's [`COLUMNS`], whose constant rows are filled once.
    id: u64,
    rows: usize,
    consts: Vec<(u32, f64)>,
    steps: Vec<Step>,
    outs: [u32; 2],
}

impl Columns {
    /// The column program of `prog` (one input `r`, two outputs), or `None` when `prog` has an
    /// operation [`column`] does not evaluate or not two outputs.
    fn new(prog: &Program) -> Option<Columns> {
        let ins = prog.instructions();
        if !ins.iter().all(|i| batchable(i.op())) || prog.output_registers().len() != 2 {
            return None;
        }
        let n_in = prog.n_inputs();
        let start = prog.first_temporary();
        let consts = prog.constants();
        let const_of = |r: u32| {
            let r = r as usize;
            (r >= n_in && r < start).then(|| consts[r - n_in])
        };
        // liveness, backwards from the outputs
        let mut live = vec![false; start + ins.len()];
        for &o in prog.output_registers() {
            live[o as usize] = true;
        }
        for (k, i) in ins.iter().enumerate().rev() {
            if live[start + k] {
                live[i.a() as usize] = true;
                if i.op().reads_b() {
                    live[i.b() as usize] = true;
                }
            }
        }
        let mut c = Builder {
            rows: (start + ins.len()) as u32,
            consts: consts
                .iter()
                .enumerate()
                .map(|(k, &v)| ((n_in + k) as u32, v))
                .collect(),
            steps: vec![],
            one: None,
            recip: std::collections::HashMap::new(),
            power: std::collections::HashMap::new(),
        };
        // original register -> row holding its value (a division by the constant 1 becomes
        // the reciprocal's row)
        let mut map: Vec<u32> = (0..(start + ins.len()) as u32).collect();
        for (k, i) in ins.iter().enumerate() {
            let dst = (start + k) as u32;
            if !live[dst as usize] {
                continue;
            }
            let a = map[i.a() as usize];
            let b = if i.op().reads_b() {
                map[i.b() as usize]
            } else {
                i.b()
            };
            match i.op() {
                Op::Div => {
                    let r = c.recip_of(b);
                    if const_of(i.a()) == Some(1.0) {
                        map[dst as usize] = r;
                    } else {
                        c.push(Op::Mul, a, r, dst);
                    }
                }
                Op::Powi if (i.b() as i32) < 0 && (i.b() as i32) != i32::MIN => {
                    let r = c.recip_of(a);
                    let k = -(i.b() as i32);
                    c.push(Op::Powi, r, k as u32, dst);
                    c.power.insert(dst, (r, k));
                }
                Op::Powi => {
                    c.push(Op::Powi, a, i.b(), dst);
                    if (i.b() as i32) > 0 {
                        c.power.insert(dst, (a, i.b() as i32));
                    }
                }
                op => c.push(op, a, b, dst),
            }
        }
        let outs = prog.output_registers();
        let outs = [map[outs[0] as usize], map[outs[1] as usize]];
        // the rewrite leaves some powers unused (`xᵏ` when only `1/xᵏ` was needed): drop
        // every step no output depends on
        let mut need = vec![false; c.rows as usize];
        for o in outs {
            need[o as usize] = true;
        }
        let mut steps = Vec::with_capacity(c.steps.len());
        for st in c.steps.iter().rev() {
            if need[st.dst as usize] {
                need[st.a as usize] = true;
                if st.op.reads_b() {
                    need[st.b as usize] = true;
                }
                steps.push(*st);
            }
        }
        steps.reverse();
        // compact rows: [input | constants used | one row per step, in step order], so that
        // every step writes a row above its operands (evaluated in place, no copy)
        let mut row = vec![u32::MAX; c.rows as usize];
        for (r, x) in row.iter_mut().enumerate().take(n_in) {
            *x = r as u32;
        }
        let mut next = n_in as u32;
        let mut kept = vec![];
        for &(r, v) in &c.consts {
            if need[r as usize] {
                row[r as usize] = next;
                kept.push((next, v));
                next += 1;
            }
        }
        for st in &mut steps {
            st.a = row[st.a as usize];
            if st.op.reads_b() {
                st.b = row[st.b as usize];
            }
            row[st.dst as usize] = next;
            st.dst = next;
            next += 1;
        }
        let outs = [row[outs[0] as usize], row[outs[1] as usize]];
        if outs.contains(&u32::MAX) {
            return None; // an output that is neither input, constant nor step: not expected
        }
        Some(Columns {
            id: NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            rows: next as usize,
            consts: kept,
            steps,
            outs,
        })
    }
}

/// State of [`Columns::new`].
struct Builder {
    rows: u32,
    consts: Vec<(u32, f64)>,
    steps: Vec<Step>,
    /// Row holding the constant 1.
    one: Option<u32>,
    /// Row of `1/x` for row `x`.
    recip: std::collections::HashMap<u32, u32>,
    /// Rows known to hold `xᵏ`, `k > 0`: `(x, k)`.
    power: std::collections::HashMap<u32, (u32, i32)>,
}

impl Builder {
    fn push(&mut self, op: Op, a: u32, b: u32, dst: u32) {
        self.steps.push(Step { op, a, b, dst });
    }

    fn new_row(&mut self) -> u32 {
        self.rows += 1;
        self.rows - 1
    }

    /// The row of `1/x`, made once: `(1/y)ᵏ` when `x = yᵏ`, else one division.
    fn recip_of(&mut self, x: u32) -> u32 {
        if let Some(&r) = self.recip.get(&x) {
            return r;
        }
        let r = if let Some(&(y, k)) = self.power.get(&x) {
            let ry = self.recip_of(y);
            let r = self.new_row();
            self.push(Op::Powi, ry, k as u32, r);
            r
        } else {
            let one = match self.one {
                Some(o) => o,
                None => {
                    let o = self.new_row();
                    self.consts.push((o, 1.0));
                    self.one = Some(o);
                    o
                }
            };
            let r = self.new_row();
            self.push(Op::Div, one, x, r);
            r
        };
        self.recip.insert(x, r);
        r
    }
}

/// One instruction over a column: `out[l] = op(a[l], b[l])` for every lane, with exactly the
/// operations of `Program::eval`; `lo` holds the rows.
#[inline]
fn column(op: Op, a: u32, b: u32, lo: &[f64], out: &mut [f64]) {
    let m = out.len();
    let a = &lo[a as usize * LANES..][..m];
    let rb = || &lo[b as usize * LANES..][..m];
    let un = |out: &mut [f64], f: fn(f64) -> f64| {
        for (o, &x) in out.iter_mut().zip(a) {
            *o = f(x);
        }
    };
    let bin = |out: &mut [f64], f: fn(f64, f64) -> f64| {
        for ((o, &x), &y) in out.iter_mut().zip(a).zip(rb()) {
            *o = f(x, y);
        }
    };
    match op {
        Op::Add => bin(out, |x, y| x + y),
        Op::Sub => bin(out, |x, y| x - y),
        Op::Mul => bin(out, |x, y| x * y),
        Op::Div => bin(out, |x, y| x / y),
        Op::Neg => un(out, |x| -x),
        Op::Sqrt => un(out, f64::sqrt),
        Op::Powi => powi_column(out, a, b as i32),
        Op::Powf => bin(out, f64::powf),
        Op::Sin => un(out, f64::sin),
        Op::Cos => un(out, f64::cos),
        Op::Tan => un(out, f64::tan),
        Op::Asin => un(out, f64::asin),
        Op::Acos => un(out, f64::acos),
        Op::Atan => un(out, f64::atan),
        Op::Atan2 => bin(out, f64::atan2),
        Op::Sinh => un(out, f64::sinh),
        Op::Cosh => un(out, f64::cosh),
        Op::Tanh => un(out, f64::tanh),
        Op::Exp => un(out, f64::exp),
        Op::Ln => un(out, f64::ln),
        Op::Abs => un(out, f64::abs),
        Op::Sign => un(out, |x| {
            if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                x * 0.0 // 0 for 0, NaN for NaN
            }
        }),
        Op::Min => bin(out, f64::min),
        Op::Max => bin(out, f64::max),
        // an operation newer than this evaluator: `compile` then leaves batching off
        // (`batchable`), so this arm is not reached; NaN rather than a panic if it were
        _ => out.fill(f64::NAN),
    }
}

/// Whether [`column`] evaluates `op` (every operation `Program` had when it was written).
fn batchable(op: Op) -> bool {
    matches!(
        op,
        Op::Add
            | Op::Sub
            | Op::Mul
            | Op::Div
            | Op::Neg
            | Op::Sqrt
            | Op::Powi
            | Op::Powf
            | Op::Sin
            | Op::Cos
            | Op::Tan
            | Op::Asin
            | Op::Acos
            | Op::Atan
            | Op::Atan2
            | Op::Sinh
            | Op::Cosh
            | Op::Tanh
            | Op::Exp
            | Op::Ln
            | Op::Abs
            | Op::Sign
            | Op::Min
            | Op::Max
    )
}

/// `out[l] = a[l]^k` by the squarings and products of `f64::powi` (compiler-builtins'
/// `__powidf2`: multiply in the base for every set bit of `|k|`, square between bits,
/// reciprocal last for `k < 0`), lane by lane in packed loops.
fn powi_column(out: &mut [f64], a: &[f64], k: i32) {
    let m = out.len();
    let mut base = [0.0f64; LANES];
    let base = &mut base[..m];
    base.copy_from_slice(&a[..m]);
    out.fill(1.0);
    let mut pow = k.unsigned_abs();
    loop {
        if pow & 1 != 0 {
            for (o, &x) in out.iter_mut().zip(base.iter()) {
                *o *= x;
            }
        }
        pow >>= 1;
        if pow == 0 {
            break;
        }
        for x in base.iter_mut() {
            *x *= *x;
        }
    }
    if k < 0 {
        for o in out.iter_mut() {
            *o = 1.0 / *o;
        }
    }
}

impl RawPair for FormulaPair {
    #[inline]
    fn raw(&self, r2: f64) -> (f64, f64) {
        self.at(r2.sqrt())
    }

    fn raw_batch(&self, r2: &[f64], u: &mut [f64], fr: &mut [f64]) {
        self.at_squared_batch(r2, u, fr)
    }

    fn prefers_batch(&self) -> bool {
        self.columns.is_some()
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

    /// The column-wise batch agrees with the point evaluation (native and interpreted) to
    /// round-off (shared reciprocals), for every operation kind, batch lengths across the
    /// column size, and negative integer powers.
    #[test]
    fn batch_matches_point_evaluation() {
        for mode in [JitMode::Auto, JitMode::Off] {
            for text in [
                LJ,
                "D*((1 - exp(-a*(r - r0)))^2 - 1)",
                "eps*exp(-r/sigma)/r + r^(-7) - r^(-3)",
                "sin(r)^2 + r^3/7 + atan(r) + sqrt(r) + abs(r - 1) + log(r) + cosh(r)",
                "min(r, 1.5) + max(r^2, 2) + sign(r - 1)*tanh(r) + r^2.5",
            ] {
                let f = FormulaPair::compile(text, &params(), mode).unwrap();
                for n in [1, 3, 4, 63, 64, 65, 130] {
                    let r2: Vec<f64> = (0..n).map(|k| 0.64 + 0.051 * k as f64).collect();
                    let (mut u, mut fr) = (vec![0.0; n], vec![0.0; n]);
                    f.raw_batch(&r2, &mut u, &mut fr);
                    for k in 0..n {
                        let (a, b) = f.raw(r2[k]);
                        for (x, y) in [(a, u[k]), (b, fr[k])] {
                            assert!(
                                (x - y).abs() <= 1e-13 * x.abs().max(1e-300),
                                "{text} {mode:?} r2 = {}: point {x} vs batch {y}",
                                r2[k]
                            );
                        }
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
