//! Compilation of expressions into a flat register program for fast `f64` evaluation.
//!
//! A [`Program`] evaluates a list of output expressions at once. Its instructions are the
//! distinct nodes of their DAG in topological order, so a subexpression shared by several
//! outputs (or by a right-hand side and its Jacobian) is computed once: common-subexpression
//! elimination comes free from hash-consing. Registers are laid out as
//! `[inputs | constants | temporaries]` in one workspace allocated by [`Program::workspace`];
//! [`Program::eval`] then allocates nothing.
//!
//! Lowering choices: subtraction instead of multiplying by −1, one division per distinct
//! negative power (`b^(-e)` is `1/b^e`, shared by every product that has the factor, which
//! then multiplies by it), `x^2 = x*x`, `x^(k/2)` through `sqrt`, a sum that is an already
//! compiled sum plus one term continues from it (partial sums of a chain's positions). With
//! invariant inputs ([`crate::hoist`]) products are lowered as variant × invariant part and
//! sums with a common invariant factor as that factor times the rest. A sine and a cosine of
//! one operand are one `sincos` ([`Op::SinCos`], `crate::sincos`).
//! Division by zero, `log` of a negative number and the like give `inf`/`NaN`, as IEEE
//! arithmetic does; they never panic.

use crate::hoist::{HoistedInputs, HoistedProgram};
use crate::lu::{DenseSolver, SingularMatrix};
use crate::number::Number;
use crate::pool::{Func, Id, Node, Pool};
use crate::tabulated::{TableFn, Tabulated};
use rustc_hash::FxHashMap;
use std::sync::Arc;

/// The operation of one [`Instr`]. Unary operations read `a` only; `Powi` reads `a` and takes
/// its integer exponent from `b` (not a register); every other binary operation reads `a`, `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
#[allow(missing_docs)] // the names are the operations
pub enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Neg,
    Powi,
    Powf,
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Ln,
    Abs,
    Sign,
    Min,
    Max,
    /// A tabulated function at `reg[a]`: `b` is the index of the call in
    /// [`Program::tables`] (not a register).
    Table,
    /// `sin(a)`, whose cosine the next instruction holds ([`Op::CosOfSinCos`], same `a`):
    /// both from one `libm::sincos`, which gives the bits of `libm::sin` and `libm::cos`
    /// ([`crate::sincos`]).
    SinCos,
    /// `cos(a)`, computed by the [`Op::SinCos`] just before it. An evaluator may also compute
    /// it alone as `libm::cos(a)`: the same bits.
    CosOfSinCos,
}

impl Op {
    /// True when the operation reads the register `b` (binary operations except `Powi`).
    pub fn reads_b(self) -> bool {
        matches!(
            self,
            Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Powf | Op::Atan2 | Op::Min | Op::Max
        )
    }

    /// True when `b` holds a number that is not a register (`Powi`'s exponent, `Table`'s
    /// call index): renumbering registers leaves it as it is.
    pub fn b_is_immediate(self) -> bool {
        matches!(self, Op::Powi | Op::Table)
    }

    /// The operation that computes this instruction's value by itself: `Sin` for
    /// [`Op::SinCos`], `Cos` for [`Op::CosOfSinCos`] (the same bits), the operation itself
    /// otherwise. For evaluators that do not fuse the pair.
    pub fn alone(self) -> Op {
        match self {
            Op::SinCos => Op::Sin,
            Op::CosOfSinCos => Op::Cos,
            op => op,
        }
    }
}

/// One instruction: `reg[dst] = op(reg[a], reg[b])`; for `Powi`, `b` holds the exponent. The
/// destination of instruction `k` is register [`Program::first_temporary`]` + k`.
#[derive(Clone, Copy, Debug)]
pub struct Instr {
    op: Op,
    a: u32,
    b: u32,
}

impl Instr {
    pub(crate) fn new(op: Op, a: u32, b: u32) -> Instr {
        Instr { op, a, b }
    }

    /// The operation.
    pub fn op(&self) -> Op {
        self.op
    }

    /// The first operand register.
    pub fn a(&self) -> u32 {
        self.a
    }

    /// The second operand register, or for [`Op::Powi`] the exponent (as `i32` bits); unused
    /// (0) for unary operations.
    pub fn b(&self) -> u32 {
        self.b
    }
}

/// Why a set of expressions could not be compiled.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum CompileError {
    /// An output depends on a symbol, coordinate or `t` that is not among the inputs.
    MissingInput {
        /// The leaf, printed.
        name: String,
    },
}

impl std::fmt::Display for CompileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CompileError::MissingInput { name } => {
                write!(
                    f,
                    "`{name}` has no value: it is not among the program inputs"
                )
            }
        }
    }
}

impl std::error::Error for CompileError {}

/// A compiled set of expressions; see the module documentation.
#[derive(Clone, Debug)]
pub struct Program {
    n_inputs: usize,
    consts: Vec<f64>,
    instrs: Vec<Instr>,
    outputs: Vec<u32>,
    tables: Arc<[TableCall]>,
}

/// One tabulated function (or derivative) a program calls ([`Op::Table`]).
#[derive(Clone, Debug)]
pub struct TableCall {
    /// The function.
    pub function: Arc<dyn Tabulated>,
    /// Which derivative (0: the value).
    pub order: u8,
}

impl TableCall {
    /// The value at `x`: what the interpreter and native code both compute.
    #[inline]
    pub fn eval(&self, x: f64) -> f64 {
        self.function.eval(self.order, x)
    }
}

pub(crate) struct Compiler<'a> {
    pool: &'a mut Pool,
    reg: FxHashMap<Id, u32>,
    const_regs: FxHashMap<u64, u32>,
    pub(crate) consts: Vec<f64>,
    /// Temporaries before renumbering: (op, a, b) with operands as provisional registers.
    pub(crate) instrs: Vec<Instr>,
    /// For each temporary: whether it depends only on constants and invariant inputs.
    pub(crate) invariant: Vec<bool>,
    pub(crate) n_inputs: u32,
    /// Inputs from this index on keep their values from one evaluation to the next (the
    /// parameters); `n_inputs` when none is known to.
    first_invariant: u32,
    /// Whether products are lowered for hoisting (see `Compiler::product_hoisting`).
    hoist: bool,
    /// The sums compiled so far (node, register), by [`term_set_hash`] of their terms.
    sums: FxHashMap<u64, Vec<(Id, u32)>>,
    /// Memo of `Compiler::split_sum`.
    split_sums: FxHashMap<Id, Option<(Id, Id)>>,
    /// The tabulated functions called, in order of first call (`Op::Table`'s `b`).
    pub(crate) table_calls: Vec<(TableFn, TableCall)>,
}

/// A hash of a set of terms that is the sum of the terms' hashes (wrapping), so that the
/// hash of the set without one term is one subtraction away.
fn term_set_hash(ts: &[Id]) -> u64 {
    ts.iter().fold(0u64, |h, &t| h.wrapping_add(term_hash(t)))
}

fn term_hash(t: Id) -> u64 {
    // SplitMix64's finaliser: distinct ids spread over all 64 bits. A linear hash (Fx's
    // multiply) would not do: the sum of the hashes would be a multiple of the sum of the
    // ids, and sets with equal id sums would collide.
    let mut z = (t.index() as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Provisional registers: inputs `0..n`, constants `CONST_BASE + k`, temporaries `TEMP_BASE + k`;
/// renumbered to the dense layout once the number of constants is known.
pub(crate) const CONST_BASE: u32 = 1 << 30;
pub(crate) const TEMP_BASE: u32 = 1 << 31;

impl<'a> Compiler<'a> {
    /// A compiler of expressions over `inputs`; inputs from `first_invariant` on are the same
    /// at every evaluation, and with `hoist` products are ordered so that their invariant
    /// part is one value (see `product_hoisting`).
    pub(crate) fn new(
        pool: &'a mut Pool,
        inputs: &[Id],
        first_invariant: usize,
        hoist: bool,
    ) -> Compiler<'a> {
        let mut c = Compiler {
            pool,
            reg: FxHashMap::default(),
            const_regs: FxHashMap::default(),
            consts: Vec::new(),
            instrs: Vec::new(),
            invariant: Vec::new(),
            n_inputs: inputs.len() as u32,
            first_invariant: first_invariant.min(inputs.len()) as u32,
            hoist,
            sums: FxHashMap::default(),
            split_sums: FxHashMap::default(),
            table_calls: Vec::new(),
        };
        for (i, &x) in inputs.iter().enumerate() {
            c.reg.insert(x, i as u32);
        }
        c
    }

    /// Whether the provisional register `r` holds a value that depends only on constants and
    /// invariant inputs.
    pub(crate) fn is_invariant(&self, r: u32) -> bool {
        if r >= TEMP_BASE {
            self.invariant[(r - TEMP_BASE) as usize]
        } else if r >= CONST_BASE {
            true
        } else {
            r >= self.first_invariant
        }
    }

    fn constant(&mut self, x: f64) -> u32 {
        if let Some(&r) = self.const_regs.get(&x.to_bits()) {
            return r;
        }
        let r = CONST_BASE + self.consts.len() as u32;
        self.consts.push(x);
        self.const_regs.insert(x.to_bits(), r);
        r
    }

    fn emit(&mut self, op: Op, a: u32, b: u32) -> u32 {
        let inv = self.is_invariant(a) && (!op.reads_b() || self.is_invariant(b));
        self.instrs.push(Instr { op, a, b });
        self.invariant.push(inv);
        TEMP_BASE + self.instrs.len() as u32 - 1
    }

    pub(crate) fn value(&mut self, id: Id) -> Result<u32, CompileError> {
        if let Some(&r) = self.reg.get(&id) {
            return Ok(r);
        }
        // Children first, iteratively, so deep expressions cannot overflow the stack.
        let reg = &self.reg;
        let order = self.pool.topo_order_pruned(&[id], |n| reg.contains_key(&n));
        for n in order {
            if !self.reg.contains_key(&n) {
                let r = self.node(n)?;
                self.reg.insert(n, r);
            }
        }
        Ok(self.reg[&id])
    }

    fn node(&mut self, id: Id) -> Result<u32, CompileError> {
        let p = &*self.pool;
        Ok(match p.node(id).clone() {
            Node::Num(n) => self.constant(n.to_f64()),
            Node::Const(c) => self.constant(c.value()),
            Node::Time | Node::Sym(_) | Node::Coord(..) => {
                return Err(CompileError::MissingInput {
                    name: p.to_text(id),
                })
            }
            Node::Add(ts) => {
                if self.hoist {
                    if let Some((variant, invariant)) = self.split_sum(id)? {
                        let v = self.value(variant)?;
                        let i = self.value(invariant)?;
                        return Ok(self.emit(Op::Mul, v, i));
                    }
                }
                // A sum that is a sum already computed plus one term continues from it: a
                // chain's particle positions and velocities are each the previous one's plus
                // a term, n additions instead of n²/2 (the 100-link chain's output columns).
                let (mut acc, rest) = match self.sum_minus_one_term(&ts) {
                    Some((r, j)) => (Some(r), std::slice::from_ref(&ts[j])),
                    None => (None, &ts[..]),
                };
                for &t in rest {
                    let (c, rest) = self.pool.split_coeff(t);
                    let (neg, term) = if c.is_negative() && rest != Pool::ONE {
                        let pos = self.pool.scale(c.neg(), rest);
                        (true, pos)
                    } else {
                        (false, t)
                    };
                    let v = self.value(term)?;
                    acc = Some(match (acc, neg) {
                        (None, false) => v,
                        (None, true) => self.emit(Op::Neg, v, 0),
                        (Some(a), false) => self.emit(Op::Add, a, v),
                        (Some(a), true) => self.emit(Op::Sub, a, v),
                    });
                }
                let r = acc.unwrap_or_else(|| self.constant(0.0));
                self.sums
                    .entry(term_set_hash(&ts))
                    .or_default()
                    .push((id, r));
                r
            }
            Node::Mul(fs) => {
                // A factor `b^(-e)` is already compiled (children first) as the reciprocal
                // `1/b^e`: one division, shared by every product that divides by it (each
                // pair's `r^-3` in an N-body right-hand side). Products multiply by it.
                // They used to divide by `b^e` again, leaving the reciprocal unused: one
                // division per product where a multiplication does (Pleiades' right-hand
                // side: 84 divisions → 21).
                let mut factors: Vec<Id> = Vec::with_capacity(fs.len());
                let mut negate = false;
                for &f in fs.iter() {
                    match self.pool.node(f) {
                        Node::Num(c) if *c == Number::MINUS_ONE => negate = true,
                        _ => factors.push(f),
                    }
                }
                let acc = if self.hoist {
                    self.product_hoisting(&factors)?
                } else {
                    self.product(&factors)?
                };
                let v = match acc {
                    Some(v) => v,
                    None => self.constant(1.0),
                };
                if negate {
                    self.emit(Op::Neg, v, 0)
                } else {
                    v
                }
            }
            Node::Pow(b, e) => self.power(b, e)?,
            Node::Call(Func::Table(t), args) => {
                let a = self.value(args[0])?;
                let k = match self.table_calls.iter().position(|(u, _)| *u == t) {
                    Some(k) => k,
                    None => {
                        let call = TableCall {
                            function: self.pool.table(t.table).function.clone(),
                            order: t.order,
                        };
                        self.table_calls.push((t, call));
                        self.table_calls.len() - 1
                    }
                };
                self.emit(Op::Table, a, k as u32)
            }
            Node::Call(f, args) => {
                let a = self.value(args[0])?;
                let b = if args.len() > 1 {
                    self.value(args[1])?
                } else {
                    0
                };
                let op = match f {
                    Func::Sin => Op::Sin,
                    Func::Cos => Op::Cos,
                    Func::Tan => Op::Tan,
                    Func::Asin => Op::Asin,
                    Func::Acos => Op::Acos,
                    Func::Atan => Op::Atan,
                    Func::Atan2 => Op::Atan2,
                    Func::Sinh => Op::Sinh,
                    Func::Cosh => Op::Cosh,
                    Func::Tanh => Op::Tanh,
                    Func::Exp => Op::Exp,
                    Func::Log => Op::Ln,
                    Func::Abs => Op::Abs,
                    Func::Sign => Op::Sign,
                    Func::Min => Op::Min,
                    Func::Max => Op::Max,
                    Func::Table(_) => unreachable!("tabulated calls are compiled above"),
                };
                self.emit(op, a, b)
            }
        })
    }

    fn product(&mut self, fs: &[Id]) -> Result<Option<u32>, CompileError> {
        let mut acc = None;
        for &f in fs {
            let v = self.value(f)?;
            acc = Some(match acc {
                None => v,
                Some(a) => self.emit(Op::Mul, a, v),
            });
        }
        Ok(acc)
    }

    /// A sum compiled earlier whose terms are `ts` but one: its register and the index of
    /// the missing term. One hash lookup per term, the match then checked term by term.
    fn sum_minus_one_term(&self, ts: &[Id]) -> Option<(u32, usize)> {
        if ts.len() < 3 || self.sums.is_empty() {
            return None;
        }
        let whole = term_set_hash(ts);
        for (j, &t) in ts.iter().enumerate() {
            let Some(found) = self.sums.get(&whole.wrapping_sub(term_hash(t))) else {
                continue;
            };
            for &(id, r) in found {
                if let Node::Add(us) = self.pool.node(id) {
                    let same = us.len() + 1 == ts.len()
                        && us
                            .iter()
                            .zip(ts.iter().enumerate().filter(|&(k, _)| k != j))
                            .all(|(u, (_, t))| u == t);
                    if same {
                        return Some((r, j));
                    }
                }
            }
        }
        None
    }

    /// A sum whose terms all have the same invariant part `C` (their parameter-only factors,
    /// coefficient included) next to a variant part: `(Σ variant parts, C)`. `Σ C·v_i` is
    /// then computed as `C·Σ v_i`, and a product with the sum as a factor folds `C` into its
    /// hoisted part: the 100-link chain's mass-matrix entries
    /// `(l_j*l_k*sin(q_j)*sin(q_k) + l_j*l_k*cos(q_j)*cos(q_k))*(m_k + … + m_n)` take four
    /// operations per evaluation instead of six. Memoised; `None` for anything else.
    fn split_sum(&mut self, id: Id) -> Result<Option<(Id, Id)>, CompileError> {
        if let Some(&s) = self.split_sums.get(&id) {
            return Ok(s);
        }
        let mut result = None;
        if let Node::Add(ts) = self.pool.node(id).clone() {
            // Each term's invariant and variant factors; the invariant lists must be equal
            // (factors are in canonical order, so equal parts have equal lists), which is
            // checked before any node is made: most sums fail at their second term.
            let mut common: Option<Vec<Id>> = None;
            let mut variants: Vec<Vec<Id>> = Vec::with_capacity(ts.len());
            for &t in ts.iter() {
                let Node::Mul(fs) = self.pool.node(t).clone() else {
                    break;
                };
                let (mut invariant, mut variant) = (Vec::new(), Vec::new());
                for &f in fs.iter() {
                    let r = self.value(f)?;
                    if self.is_invariant(r) {
                        invariant.push(f);
                    } else {
                        variant.push(f);
                    }
                }
                if invariant.is_empty() || variant.is_empty() {
                    break;
                }
                if common.as_ref().is_some_and(|c| *c != invariant) {
                    break;
                }
                common = Some(invariant);
                variants.push(variant);
            }
            if let (Some(c), true) = (common, variants.len() == ts.len()) {
                let parts: Vec<Id> = variants
                    .iter()
                    .map(|v| match v[..] {
                        [one] => one,
                        _ => self.pool.mul(v),
                    })
                    .collect();
                result = Some((self.pool.add(&parts), self.pool.mul(&c)));
            }
        }
        self.split_sums.insert(id, result);
        Ok(result)
    }

    /// A product as (its variant factors) × (its invariant factors), each part a node of its
    /// own: the invariant part is then computed once per parameter change (hoisted), and the
    /// variant part is shared by every product with the same variant factors. In the n-link
    /// chain's forcing, `l_k*S_jk*q_k'^2*cos(q_k)` for every row j becomes one shared
    /// `q_k'^2*cos(q_k)` times a hoisted `l_k*S_jk`: one multiplication per term, not three.
    fn product_hoisting(&mut self, fs: &[Id]) -> Result<Option<u32>, CompileError> {
        let mut invariant = Vec::new();
        let mut variant = Vec::new();
        let mut split = false;
        for &f in fs {
            let r = self.value(f)?;
            if self.is_invariant(r) {
                invariant.push(f);
            } else if let Some((v, i)) = self.split_sum(f)? {
                variant.push(v);
                invariant.push(i);
                split = true;
            } else {
                variant.push(f);
            }
        }
        if !split && (invariant.is_empty() || variant.is_empty()) {
            return self.product(fs);
        }
        let part = |c: &mut Compiler, ids: Vec<Id>| -> Result<u32, CompileError> {
            match ids[..] {
                [one] => c.value(one),
                _ => {
                    let node = c.pool.mul(&ids);
                    c.value(node)
                }
            }
        };
        let v = part(self, variant)?;
        let i = part(self, invariant)?;
        Ok(Some(self.emit(Op::Mul, v, i)))
    }

    fn power(&mut self, b: Id, e: Id) -> Result<u32, CompileError> {
        let bv = self.value(b)?;
        let Some(x) = self.pool.as_num(e) else {
            let ev = self.value(e)?;
            return Ok(self.emit(Op::Powf, bv, ev));
        };
        if x.is_negative() {
            let pe = self.pool.num(x.neg());
            let pos = self.pool.pow(b, pe);
            let pv = self.value(pos)?;
            let one = self.constant(1.0);
            return Ok(self.emit(Op::Div, one, pv));
        }
        if let Some(k) = x.as_integer() {
            return Ok(match k {
                2 => self.emit(Op::Mul, bv, bv),
                3 => {
                    let sq = self.emit(Op::Mul, bv, bv);
                    self.emit(Op::Mul, sq, bv)
                }
                k if k <= i32::MAX as i64 => self.emit(Op::Powi, bv, k as u32),
                _ => {
                    let c = self.constant(k as f64);
                    self.emit(Op::Powf, bv, c)
                }
            });
        }
        if let Some((n, 2)) = x.as_rational().and_then(|r| r.small()) {
            {
                // b^(k/2) = sqrt(b) * b^((k-1)/2)
                let s = self.emit(Op::Sqrt, bv, 0);
                let whole = (n - 1) / 2;
                if whole == 0 {
                    return Ok(s);
                }
                let we = self.pool.int(whole);
                let wp = self.pool.pow(b, we);
                let wv = self.value(wp)?;
                return Ok(self.emit(Op::Mul, s, wv));
            }
        }
        let c = self.constant(x.to_f64());
        Ok(self.emit(Op::Powf, bv, c))
    }
}

impl Program {
    /// Compiles `outputs` as functions of `inputs` (leaf expressions: symbols, coordinates and
    /// their rates, `t`), in the order given.
    pub fn compile(
        pool: &mut Pool,
        inputs: &[Id],
        outputs: &[Id],
    ) -> Result<Program, CompileError> {
        let mut c = Compiler::new(pool, inputs, inputs.len(), false);
        let mut outs = Vec::with_capacity(outputs.len());
        for &o in outputs {
            outs.push(c.value(o)?);
        }
        let n_consts = c.consts.len() as u32;
        let base = c.n_inputs;
        let remap = |r: u32| -> u32 {
            if r >= TEMP_BASE {
                base + n_consts + (r - TEMP_BASE)
            } else if r >= CONST_BASE {
                base + (r - CONST_BASE)
            } else {
                r
            }
        };
        let instrs = c
            .instrs
            .iter()
            .map(|i| Instr {
                op: i.op,
                a: remap(i.a),
                b: if i.op.b_is_immediate() {
                    i.b
                } else {
                    remap(i.b)
                },
            })
            .collect();
        Ok(Program::from_parts(
            inputs.len(),
            c.consts,
            instrs,
            outs.into_iter().map(remap).collect(),
            c.table_calls.into_iter().map(|(_, call)| call).collect(),
        ))
    }

    /// A program from its renumbered parts (registers `[inputs | constants | temporaries]`),
    /// each sine and cosine of one operand fused ([`crate::sincos`]).
    pub(crate) fn from_parts(
        n_inputs: usize,
        consts: Vec<f64>,
        instrs: Vec<Instr>,
        mut outputs: Vec<u32>,
        tables: Arc<[TableCall]>,
    ) -> Program {
        let first_temp = (n_inputs + consts.len()) as u32;
        let instrs = crate::sincos::fuse_sin_cos(first_temp, instrs, &mut outputs);
        Program {
            n_inputs,
            consts,
            instrs,
            outputs,
            tables,
        }
    }

    /// The tabulated functions the program calls: [`Op::Table`]'s `b` indexes them.
    pub fn tables(&self) -> &Arc<[TableCall]> {
        &self.tables
    }

    /// Number of instructions (the program's size).
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    /// True when every output is an input or a constant.
    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// Number of inputs expected by [`Program::eval`].
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    /// Number of outputs written by [`Program::eval`].
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Read-only view of the instructions, in evaluation order (for code generators such as
    /// `pdyn-jit`). Registers are laid out `[inputs | constants | temporaries]`.
    pub fn instructions(&self) -> &[Instr] {
        &self.instrs
    }

    /// The constants, held in registers `n_inputs()..n_inputs() + constants().len()`.
    pub fn constants(&self) -> &[f64] {
        &self.consts
    }

    /// The register of each output, in output order.
    pub fn output_registers(&self) -> &[u32] {
        &self.outputs
    }

    /// The register written by instruction 0 (`n_inputs() + constants().len()`).
    pub fn first_temporary(&self) -> usize {
        self.n_inputs + self.consts.len()
    }

    /// A register file for [`Program::eval`], with the constants loaded.
    pub fn workspace(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.n_inputs + self.consts.len() + self.instrs.len()];
        w[self.n_inputs..self.n_inputs + self.consts.len()].copy_from_slice(&self.consts);
        w
    }

    /// Evaluates every output. `ws` must come from [`Program::workspace`]; `inputs` and `out`
    /// must have the lengths [`Program::n_inputs`] and [`Program::n_outputs`].
    ///
    /// # Panics
    /// If a slice is shorter than required (a programming error, not a data error).
    #[inline]
    pub fn eval(&self, inputs: &[f64], ws: &mut [f64], out: &mut [f64]) {
        let n = self.n_inputs;
        let start = n + self.consts.len();
        assert!(
            inputs.len() >= n && ws.len() >= start + self.instrs.len(),
            "Program::eval: inputs or workspace too short"
        );
        ws[..n].copy_from_slice(&inputs[..n]);
        let regs = ws.as_mut_ptr();
        let len = self.instrs.len();
        for (k, ins) in self.instrs.iter().enumerate() {
            // SAFETY: `compile` only emits operands that are inputs, constants or earlier
            // temporaries, so `ins.a`, `ins.b` < `start + k` <= ws.len() (checked above), and the
            // destination `start + k` is in bounds, as is `SinCos`'s second one `start + k + 1`
            // (checked: `k + 1 < len`). `Powi` stores an exponent, not a register, in `b`, and
            // never reads it as one.
            unsafe {
                let a = *regs.add(ins.a as usize);
                let reg_b = || *regs.add(ins.b as usize);
                let v = match ins.op {
                    Op::Add => a + reg_b(),
                    Op::Sub => a - reg_b(),
                    Op::Mul => a * reg_b(),
                    Op::Div => a / reg_b(),
                    Op::Neg => -a,
                    Op::Sqrt => a.sqrt(),
                    Op::Powi => a.powi(ins.b as i32),
                    Op::Powf => libm::pow(a, reg_b()),
                    Op::Sin => libm::sin(a),
                    Op::Cos => libm::cos(a),
                    Op::Tan => libm::tan(a),
                    Op::Asin => libm::asin(a),
                    Op::Acos => libm::acos(a),
                    Op::Atan => libm::atan(a),
                    Op::Atan2 => libm::atan2(a, reg_b()),
                    Op::Sinh => libm::sinh(a),
                    Op::Cosh => libm::cosh(a),
                    Op::Tanh => libm::tanh(a),
                    Op::Exp => libm::exp(a),
                    Op::Ln => libm::log(a),
                    Op::Abs => a.abs(),
                    Op::Sign => {
                        if a > 0.0 {
                            1.0
                        } else if a < 0.0 {
                            -1.0
                        } else {
                            a * 0.0 // 0 for 0, NaN for NaN
                        }
                    }
                    Op::Min => a.min(reg_b()),
                    Op::Max => a.max(reg_b()),
                    Op::Table => self.tables[ins.b as usize].eval(a),
                    Op::SinCos => {
                        let (sin, cos) = libm::sincos(a);
                        // The next instruction is this one's `CosOfSinCos` (`fuse_sin_cos`
                        // emits them so), whose register is the next one.
                        if k + 1 < len {
                            *regs.add(start + k + 1) = cos;
                        }
                        sin
                    }
                    // Written by the `SinCos` just before.
                    Op::CosOfSinCos => *regs.add(start + k),
                };
                *regs.add(start + k) = v;
            }
        }
        for (o, &r) in out.iter_mut().zip(&self.outputs) {
            *o = ws[r as usize];
        }
    }
}

impl Pool {
    /// `∂f_i/∂v_j`, row-major (`fs.len() × vars.len()`).
    pub fn jacobian(&mut self, fs: &[Id], vars: &[Id]) -> Vec<Id> {
        let wanted: rustc_hash::FxHashSet<Id> = vars.iter().copied().collect();
        let column: rustc_hash::FxHashMap<Id, usize> =
            vars.iter().enumerate().map(|(j, &v)| (v, j)).collect();
        let mut out = vec![Pool::ZERO; fs.len() * vars.len()];
        for (i, &f) in fs.iter().enumerate() {
            // Only the variables `f` contains have a derivative other than zero (a net's
            // particle depends on its few neighbours of the N).
            for v in self.occurring(f, &wanted) {
                let j = column[&v];
                out[i * vars.len() + j] = self.diff(f, v);
            }
        }
        out
    }
}

/// A linear system `A x = b` compiled for numeric solution at evaluation time: the entries are
/// one [`HoistedProgram`], the solve a [`DenseSolver`] (Cholesky when `A` is symbolically
/// symmetric, as a mass matrix is; LU otherwise). Owns its buffers; `solve` allocates nothing.
#[derive(Clone, Debug)]
pub struct CompiledLinearSystem {
    program: HoistedProgram,
    inputs: HoistedInputs,
    n: usize,
    ws: Vec<f64>,
    ab: Vec<f64>,
    solver: DenseSolver,
}

impl CompiledLinearSystem {
    /// Compiles a square system.
    pub fn new(
        pool: &mut Pool,
        sys: &crate::linsolve::LinearSystem,
        inputs: &[Id],
    ) -> Result<CompiledLinearSystem, CompileError> {
        CompiledLinearSystem::hoisted(pool, sys, inputs, inputs.len())
    }

    /// Compiles a square system whose inputs from `first_invariant` on (the parameters) keep
    /// their values between solves: the work that depends on them only is done once per
    /// change ([`HoistedProgram`]).
    pub fn hoisted(
        pool: &mut Pool,
        sys: &crate::linsolve::LinearSystem,
        inputs: &[Id],
        first_invariant: usize,
    ) -> Result<CompiledLinearSystem, CompileError> {
        let n = sys.cols();
        debug_assert_eq!(sys.rows(), n);
        let mut outs = sys.a.clone();
        outs.extend_from_slice(&sys.b);
        // Hash-consing makes equal entries one node: symmetry is an identity test.
        let symmetric = (0..n).all(|i| (0..i).all(|j| outs[i * n + j] == outs[j * n + i]));
        let program = HoistedProgram::compile(pool, inputs, first_invariant, &outs)?;
        let ws = program.main().workspace();
        Ok(CompiledLinearSystem {
            inputs: HoistedInputs::new(&program),
            program,
            n,
            ws,
            ab: vec![0.0; n * n + n],
            solver: DenseSolver::new(n, symmetric),
        })
    }

    /// A fresh solver for this system's size and structure (for evaluators of the same
    /// entries, such as native code).
    pub fn solver(&self) -> DenseSolver {
        self.solver.clone()
    }

    /// The program computing the entries: `n²` matrix entries row-major, then the `n`
    /// right-hand sides.
    pub fn program(&self) -> &HoistedProgram {
        &self.program
    }

    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Solves for the unknowns at `inputs`, writing them to `x`.
    pub fn solve(&mut self, inputs: &[f64], x: &mut [f64]) -> Result<(), SingularMatrix> {
        let n = self.n;
        debug_assert_eq!(self.ab.len(), n * n + n);
        let ext = self.inputs.update(&self.program, inputs);
        self.program.main().eval(ext, &mut self.ws, &mut self.ab);
        self.solver.solve(&mut self.ab, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Partial sums (a chain's positions `x_i = l_1 sin q_1 + … + l_i sin q_i`) are each the
    /// previous one plus a term: n additions, not n²/2, and the bits of the plain left fold.
    #[test]
    fn partial_sums_continue_from_the_previous_one() {
        let mut p = Pool::new();
        let n = 40;
        let qs: Vec<Id> = (1..=n).map(|i| p.var(&format!("q{i}"))).collect();
        let terms: Vec<Id> = (1..=n)
            .map(|i| p.parse_scalar(&format!("{i}*sin(q{i})")).unwrap())
            .collect();
        let sums: Vec<Id> = (1..=n).map(|i| p.add(&terms[..i])).collect();
        let prog = Program::compile(&mut p, &qs, &sums).unwrap();
        let adds = prog
            .instructions()
            .iter()
            .filter(|i| i.op() == Op::Add)
            .count();
        assert_eq!(adds, n - 1);
        let x: Vec<f64> = (0..n).map(|i| 0.3 + 0.17 * i as f64).collect();
        let mut out = vec![0.0; n];
        prog.eval(&x, &mut prog.workspace(), &mut out);
        let mut acc = 0.0;
        for i in 0..n {
            let t = (i + 1) as f64 * libm::sin(x[i]);
            acc = if i == 0 { t } else { acc + t };
            assert_eq!(out[i].to_bits(), acc.to_bits(), "x_{}", i + 1);
        }
    }

    #[test]
    fn evaluates_and_shares_subexpressions() {
        let mut p = Pool::new();
        let (x, y) = (p.var("x"), p.var("y"));
        let f1 = p.parse_scalar("-GM*x/(x^2 + y^2)^(3/2)").unwrap();
        let f2 = p.parse_scalar("-GM*y/(x^2 + y^2)^(3/2)").unwrap();
        let gm = p.var("GM");
        let prog = Program::compile(&mut p, &[x, y, gm], &[f1, f2]).unwrap();
        let mut ws = prog.workspace();
        let mut out = [0.0; 2];
        prog.eval(&[0.6, 0.8, 2.0], &mut ws, &mut out);
        assert!(
            (out[0] + 1.2).abs() < 1e-15 && (out[1] + 1.6).abs() < 1e-15,
            "{out:?}"
        );
        // x^2, y^2, sum, sqrt, product, reciprocal shared: far fewer than 2× one output.
        assert!(prog.len() <= 12, "{} instructions", prog.len());
        // The denominator both outputs share is inverted once and multiplied in.
        let divisions = prog.instrs.iter().filter(|i| i.op == Op::Div).count();
        assert_eq!(divisions, 1);
    }

    #[test]
    fn a_quotient_is_one_division() {
        let mut p = Pool::new();
        let (x, y) = (p.var("x"), p.var("y"));
        let f = p.parse_scalar("x/(x^2 + y^2)").unwrap();
        let prog = Program::compile(&mut p, &[x, y], &[f]).unwrap();
        let divisions = prog.instrs.iter().filter(|i| i.op == Op::Div).count();
        assert_eq!(divisions, 1);
        let mut out = [0.0];
        prog.eval(&[3.0, 4.0], &mut prog.workspace(), &mut out);
        assert!((out[0] - 0.12).abs() < 1e-16);
    }

    #[test]
    fn bad_arithmetic_gives_nan_or_inf_not_panic() {
        let mut p = Pool::new();
        let x = p.var("x");
        let outs: Vec<Id> = ["1/x", "log(x - 1)", "sqrt(x - 1)", "x^(-3/2)", "sign(x)"]
            .iter()
            .map(|s| p.parse_scalar(s).unwrap())
            .collect();
        let prog = Program::compile(&mut p, &[x], &outs).unwrap();
        let mut ws = prog.workspace();
        let mut out = [0.0; 5];
        prog.eval(&[0.0], &mut ws, &mut out);
        assert!(out[0].is_infinite());
        assert!(out[1].is_nan());
        assert!(out[2].is_nan());
        assert!(out[3].is_infinite());
        assert_eq!(out[4], 0.0);
    }

    #[test]
    fn missing_inputs_are_named() {
        let mut p = Pool::new();
        let e = p.parse_scalar("a*b").unwrap();
        let a = p.var("a");
        let err = Program::compile(&mut p, &[a], &[e]).unwrap_err();
        assert_eq!(err, CompileError::MissingInput { name: "b".into() });
    }
}
