//! Batch kernels: one [`Program`] applied to whole columns of inputs, the loop inside the
//! machine code.
//!
//! [`crate::JitProgram`] evaluates a program at one point per call. A caller that evaluates
//! the same small program at many points — a pair potential at every neighbour distance —
//! then pays a call, the loads and stores of its arguments and the loss of packed arithmetic
//! per point. A [`BatchKernel`] is compiled once into a function
//! `fn(inputs: *const *const f64, outputs: *const *mut f64, n: usize)` that loops over the `n`
//! points itself, two points per iteration in packed `f64x2` registers (a scalar iteration
//! for an odd last point), every intermediate value in a register.
//!
//! ## The kernel's program
//! Before compilation the program is rewritten once into [`Steps`]:
//! - instructions no output needs are dropped;
//! - divisions share reciprocals: `a / x` becomes `a · (1/x)` with one `1/x` per `x`, and
//!   `1/xᵏ` becomes `(1/x)ᵏ` when `xᵏ` is a known power of `x` (a `powi`, or products such as
//!   `x·x`, `x·x·x`), because a derived potential divides by many powers of its variable
//!   (Lennard-Jones in `r²`: four divisions, one after the rewrite) and a division costs
//!   several multiplications.
//!
//! The results therefore differ from [`Program::eval`] by a few units in the last place. They
//! do not differ between the two engines of a kernel: native code and the column interpreter
//! used without a JIT ([`JitMode::Off`], or no Cranelift backend) run the same [`Steps`] with
//! the same IEEE operations in the same order (integer powers by `f64::powi`'s
//! square-and-multiply, transcendental functions through the same `f64` methods), so they give
//! the same bits (tested on random inputs).
use crate::JitMode;
use pdyn_expr::compile::Op;
use pdyn_expr::Program;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

// The native loop (Cranelift); a WebAssembly build has none and runs the column interpreter.
#[cfg_attr(target_arch = "wasm32", path = "batch/unavailable.rs")]
mod native;
use native::{call, compile, BatchCode};

/// Points per column of the interpreter: enough to amortise the dispatch of each step, few
/// enough that the rows (`LANES` values each) stay in the L1 cache.
const LANES: usize = 64;

/// One step: `row[dst] = op(row[a], row[b])` (`b` the exponent for `Powi`).
#[derive(Debug, Clone, Copy)]
struct Step {
    op: Op,
    a: u32,
    b: u32,
    dst: u32,
}

/// A [`Program`] rewritten for batch evaluation: rows `[inputs | constants | one row per
/// step, in step order]`, so every step writes a row above its operands.
#[derive(Debug)]
struct Steps {
    /// Identifies these steps in a thread's interpreter rows, whose constants are filled once.
    id: u64,
    n_inputs: usize,
    rows: usize,
    consts: Vec<(u32, f64)>,
    steps: Vec<Step>,
    outs: Vec<u32>,
}

/// Ids of [`Steps`].
static NEXT_ID: AtomicU64 = AtomicU64::new(0);

/// Whether the kernel evaluates `op` (every operation `Program` had when this was written).
fn known(op: Op) -> bool {
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

/// State of [`Steps::new`] while it rewrites.
struct Rewrite {
    rows: u32,
    consts: Vec<(u32, f64)>,
    steps: Vec<Step>,
    /// Row holding the constant 1.
    one: Option<u32>,
    /// Row of `1/x` for row `x`.
    recip: HashMap<u32, u32>,
    /// Rows known to hold `yᵏ`, `k > 0`: `(y, k)`.
    power: HashMap<u32, (u32, i32)>,
}

impl Rewrite {
    fn push(&mut self, op: Op, a: u32, b: u32, dst: u32) {
        self.steps.push(Step { op, a, b, dst });
    }

    fn new_row(&mut self) -> u32 {
        self.rows += 1;
        self.rows - 1
    }

    /// `(y, k)` with row `x = yᵏ` (`(x, 1)` when nothing better is known).
    fn as_power(&self, x: u32) -> (u32, i32) {
        self.power.get(&x).copied().unwrap_or((x, 1))
    }

    /// Records `dst = a·b` as a power when both are powers of one row.
    fn note_product(&mut self, a: u32, b: u32, dst: u32) {
        let ((ya, ka), (yb, kb)) = (self.as_power(a), self.as_power(b));
        if ya == yb {
            if let Some(k) = ka.checked_add(kb) {
                self.power.insert(dst, (ya, k));
            }
        }
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

impl Steps {
    /// The steps of `prog`, or `None` when it has an operation [`known`] does not list.
    fn new(prog: &Program) -> Option<Steps> {
        let ins = prog.instructions();
        if !ins.iter().all(|i| known(i.op().alone())) {
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
        let mut c = Rewrite {
            rows: (start + ins.len()) as u32,
            consts: consts
                .iter()
                .enumerate()
                .map(|(k, &v)| ((n_in + k) as u32, v))
                .collect(),
            steps: vec![],
            one: None,
            recip: HashMap::new(),
            power: HashMap::new(),
        };
        // original register -> row holding its value (`1/x` becomes the reciprocal's row)
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
            let e = i.b() as i32;
            // A fused sine and cosine are computed apart here (the same bits): liveness may
            // have dropped one of them.
            match i.op().alone() {
                Op::Div => {
                    let r = c.recip_of(b);
                    if const_of(i.a()) == Some(1.0) {
                        map[dst as usize] = r;
                    } else {
                        c.push(Op::Mul, a, r, dst);
                    }
                }
                Op::Powi if e < 0 && e != i32::MIN => {
                    let r = c.recip_of(a);
                    c.push(Op::Powi, r, e.unsigned_abs(), dst);
                    c.power.insert(dst, (r, -e));
                }
                Op::Powi => {
                    c.push(Op::Powi, a, i.b(), dst);
                    if e > 0 {
                        let (y, k) = c.as_power(a);
                        match k.checked_mul(e) {
                            Some(k) => c.power.insert(dst, (y, k)),
                            None => c.power.insert(dst, (a, e)),
                        };
                    }
                }
                Op::Mul => {
                    c.push(Op::Mul, a, b, dst);
                    c.note_product(a, b, dst);
                }
                op => c.push(op, a, b, dst),
            }
        }
        let outs: Vec<u32> = prog
            .output_registers()
            .iter()
            .map(|&o| map[o as usize])
            .collect();
        // the rewrite leaves some steps unused (`xᵏ` when only `1/xᵏ` was needed): keep only
        // the steps an output depends on
        let mut need = vec![false; c.rows as usize];
        for &o in &outs {
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
        // compact rows: [inputs | constants used | one row per step, in step order]
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
        let outs: Vec<u32> = outs.iter().map(|&o| row[o as usize]).collect();
        if outs.contains(&u32::MAX) {
            return None; // an output that is neither input, constant nor step: not expected
        }
        Some(Steps {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            n_inputs: n_in,
            rows: next as usize,
            consts: kept,
            steps,
            outs,
        })
    }
}

// ---------------------------------------------------------------------------------------
// The interpreter

thread_local! {
    /// Rows of the interpreter, per thread (kernels run on many threads at once and `run`
    /// takes `&self`), with the id of the [`Steps`] whose constants they hold.
    static ROWS: RefCell<(u64, Vec<f64>)> = const { RefCell::new((u64::MAX, Vec::new())) };
}

impl Steps {
    /// Evaluates the steps column-wise, [`LANES`] points at a time.
    fn interpret(&self, inputs: &[&[f64]], outputs: &mut [&mut [f64]], n: usize) {
        ROWS.with(|cell| {
            let mut guard = cell.borrow_mut();
            let (id, regs) = &mut *guard;
            if regs.len() < self.rows * LANES {
                regs.resize(self.rows * LANES, 0.0);
                *id = u64::MAX;
            }
            let regs = &mut regs[..self.rows * LANES];
            if *id != self.id {
                // constant rows are never written by a step: filled once per kernel
                for &(row, v) in &self.consts {
                    regs[row as usize * LANES..][..LANES].fill(v);
                }
                *id = self.id;
            }
            for lo in (0..n).step_by(LANES) {
                let m = LANES.min(n - lo);
                for (k, x) in inputs.iter().enumerate() {
                    regs[k * LANES..][..m].copy_from_slice(&x[lo..lo + m]);
                }
                for st in &self.steps {
                    // operands lie below the destination row
                    let (below, above) = regs.split_at_mut(st.dst as usize * LANES);
                    column(st.op, st.a, st.b, below, &mut above[..m]);
                }
                for (o, &r) in outputs.iter_mut().zip(&self.outs) {
                    o[lo..lo + m].copy_from_slice(&regs[r as usize * LANES..][..m]);
                }
            }
        });
    }
}

/// One step over a column: `out[l] = op(a[l], b[l])` for every lane, with the operations of
/// `Program::eval` (and of the native kernel); `rows` holds the operand rows.
#[inline]
fn column(op: Op, a: u32, b: u32, rows: &[f64], out: &mut [f64]) {
    let m = out.len();
    let a = &rows[a as usize * LANES..][..m];
    let rb = || &rows[b as usize * LANES..][..m];
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
        Op::Powf => bin(out, libm::pow),
        Op::Sin => un(out, libm::sin),
        Op::Cos => un(out, libm::cos),
        Op::Tan => un(out, libm::tan),
        Op::Asin => un(out, libm::asin),
        Op::Acos => un(out, libm::acos),
        Op::Atan => un(out, libm::atan),
        Op::Atan2 => bin(out, libm::atan2),
        Op::Sinh => un(out, libm::sinh),
        Op::Cosh => un(out, libm::cosh),
        Op::Tanh => un(out, libm::tanh),
        Op::Exp => un(out, libm::exp),
        Op::Ln => un(out, libm::log),
        Op::Abs => un(out, f64::abs),
        Op::Sign => un(out, |x| sign(x)),
        Op::Min => bin(out, f64::min),
        Op::Max => bin(out, f64::max),
        // `Steps::new` refuses operations `known` does not list: not reached
        _ => out.fill(f64::NAN),
    }
}

/// `out[l] = a[l]^k` by the squarings and products of `f64::powi` (compiler-builtins'
/// `__powidf2`: multiply in the base for every set bit of `|k|`, square between bits,
/// reciprocal last for `k < 0`), lane by lane in packed loops; the first factor is taken as
/// it is (`1·x = x` exactly), as the native kernel does.
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

/// `sign` as the interpreter computes it: 1 for x > 0, −1 for x < 0, `x·0` otherwise (±0,
/// or NaN for NaN); the native kernel calls it lane by lane.
pub(crate) extern "C" fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x * 0.0
    }
}

// ---------------------------------------------------------------------------------------
// The public face

/// A [`Program`] evaluated over columns of points; see the module documentation.
///
/// Cheap to clone (shared behind `Arc`s), `Send + Sync`: any number of threads may run it at
/// once.
#[derive(Clone)]
pub struct BatchKernel {
    steps: Arc<Steps>,
    /// Native code (`None`: the column interpreter).
    code: Option<Arc<BatchCode>>,
}

impl std::fmt::Debug for BatchKernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BatchKernel")
            .field("inputs", &self.steps.n_inputs)
            .field("outputs", &self.steps.outs.len())
            .field("steps", &self.steps.steps.len())
            .field("native", &self.code.is_some())
            .finish()
    }
}

impl BatchKernel {
    /// The kernel of `prog` according to `mode` ([`JitMode::Auto`]: native code when the
    /// platform has a Cranelift backend, the column interpreter otherwise; the results are
    /// the same bits). `None` when `prog` has an operation this module does not know (a newer
    /// `Op`).
    pub fn new(prog: &Program, mode: JitMode) -> Option<BatchKernel> {
        let steps = Steps::new(prog)?;
        let code = match mode {
            JitMode::Off => None,
            JitMode::Auto => compile(&steps).ok().map(Arc::new),
        };
        Some(BatchKernel {
            steps: Arc::new(steps),
            code,
        })
    }

    /// True when native code runs.
    pub fn is_native(&self) -> bool {
        self.code.is_some()
    }

    /// Number of input columns.
    pub fn n_inputs(&self) -> usize {
        self.steps.n_inputs
    }

    /// Number of output columns.
    pub fn n_outputs(&self) -> usize {
        self.steps.outs.len()
    }

    /// Number of operations per point after the rewrite.
    pub fn len(&self) -> usize {
        self.steps.steps.len()
    }

    /// True when every output is an input or a constant.
    pub fn is_empty(&self) -> bool {
        self.steps.steps.is_empty()
    }

    /// `outputs[o][k] = output o of the program at inputs[·][k]`, for every `k` below the
    /// common length `n` of the columns; allocates nothing (the interpreter's rows are
    /// per thread and kept).
    ///
    /// # Panics
    /// If the number of columns is not [`BatchKernel::n_inputs`] and
    /// [`BatchKernel::n_outputs`], or the columns differ in length (a programming error).
    pub fn run(&self, inputs: &[&[f64]], outputs: &mut [&mut [f64]]) {
        let s = &self.steps;
        assert!(
            inputs.len() == s.n_inputs && outputs.len() == s.outs.len(),
            "BatchKernel::run: {} input and {} output columns given, {} and {} expected",
            inputs.len(),
            outputs.len(),
            s.n_inputs,
            s.outs.len()
        );
        let n = outputs.first().map_or(0, |o| o.len());
        assert!(
            inputs.iter().all(|x| x.len() == n) && outputs.iter().all(|o| o.len() == n),
            "BatchKernel::run: columns of different lengths"
        );
        let Some(code) = &self.code else {
            return s.interpret(inputs, outputs, n);
        };
        // column pointers on the stack for the usual few columns
        const FEW: usize = 16;
        if inputs.len() <= FEW && outputs.len() <= FEW {
            let mut ip = [std::ptr::null::<f64>(); FEW];
            let mut op = [std::ptr::null_mut::<f64>(); FEW];
            ip.iter_mut().zip(inputs).for_each(|(p, x)| *p = x.as_ptr());
            op.iter_mut()
                .zip(outputs.iter_mut())
                .for_each(|(p, o)| *p = o.as_mut_ptr());
            call(code, &ip, &op, n);
        } else {
            let ip: Vec<*const f64> = inputs.iter().map(|x| x.as_ptr()).collect();
            let op: Vec<*mut f64> = outputs.iter_mut().map(|o| o.as_mut_ptr()).collect();
            call(code, &ip, &op, n);
        }
    }
}

impl BatchKernel {
    /// [`BatchKernel::run`] over stretches of the columns, read where they are: for stretch
    /// `k = (first, len)`, input `c` is `inputs[c][from[k n_in + c]..][..len]` and output `o`
    /// is written to `outputs[o][first..first + len]`. A net's family reads its coordinates
    /// in place this way, stretch by stretch, where a gather would copy each column first;
    /// the column pointers are set per stretch with no allocation and no per-column length
    /// check beyond the stretch's bounds.
    ///
    /// # Panics
    /// If the number of columns is not [`BatchKernel::n_inputs`] and
    /// [`BatchKernel::n_outputs`], `from` does not hold `n_inputs` starts per stretch, or a
    /// stretch reaches past the end of a column (a programming error).
    pub fn run_stretches(
        &self,
        inputs: &[&[f64]],
        from: &[u32],
        outputs: &mut [&mut [f64]],
        stretches: &[(u32, u32)],
    ) {
        let s = &self.steps;
        let (n_in, n_out) = (s.n_inputs, s.outs.len());
        assert!(
            inputs.len() == n_in && outputs.len() == n_out && from.len() == stretches.len() * n_in,
            "BatchKernel::run_stretches: {} input and {} output columns, {} starts for {} \
             stretches given; {n_in} and {n_out} columns expected",
            inputs.len(),
            outputs.len(),
            from.len(),
            stretches.len()
        );
        const FEW: usize = 16;
        let code = match &self.code {
            Some(code) if n_in <= FEW && n_out <= FEW => code,
            _ => {
                // The interpreter (or many columns): each stretch as a run of its own.
                for (k, &(first, len)) in stretches.iter().enumerate() {
                    let starts = &from[k * n_in..(k + 1) * n_in];
                    let (first, len) = (first as usize, len as usize);
                    let ins: Vec<&[f64]> = inputs
                        .iter()
                        .zip(starts)
                        .map(|(col, &f)| &col[f as usize..f as usize + len])
                        .collect();
                    let mut outs: Vec<&mut [f64]> = outputs
                        .iter_mut()
                        .map(|col| &mut col[first..first + len])
                        .collect();
                    self.run(&ins, &mut outs);
                }
                return;
            }
        };
        let mut ip = [std::ptr::null::<f64>(); FEW];
        let mut op = [std::ptr::null_mut::<f64>(); FEW];
        for (k, &(first, len)) in stretches.iter().enumerate() {
            let (first, len) = (first as usize, len as usize);
            for ((p, col), &f) in ip
                .iter_mut()
                .zip(inputs)
                .zip(&from[k * n_in..(k + 1) * n_in])
            {
                *p = col[f as usize..f as usize + len].as_ptr();
            }
            for (p, col) in op.iter_mut().zip(outputs.iter_mut()) {
                *p = col[first..first + len].as_mut_ptr();
            }
            // Each pointer starts a range of `len` values inside its column (the slicing
            // above checked it); the outputs are distinct mutable columns, none an input.
            call(code, &ip, &op, len);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pdyn_expr::{Id, Pool};

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// xorshift values over many binades, both signs, with special values mixed in.
    fn random_inputs(n: usize, seed: u64, positive: bool) -> Vec<f64> {
        let mut state = seed | 1;
        let specials = [0.0, -0.0, 1.0, -1.0, f64::NAN, f64::INFINITY, 1e300, 1e-300];
        (0..n)
            .map(|k| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                if k % 17 == 5 {
                    return specials[(state % specials.len() as u64) as usize];
                }
                let mantissa = (state >> 11) as f64 / (1u64 << 53) as f64;
                let exponent = ((state >> 3) % 12) as i32 - 6;
                let v = (0.05 + mantissa) * 2f64.powi(exponent);
                if positive || state & 4 == 0 {
                    v
                } else {
                    -v
                }
            })
            .collect()
    }

    fn kernels(srcs: &[&str], vars: &[&str]) -> (BatchKernel, BatchKernel, Program) {
        let mut p = Pool::new();
        let xs: Vec<Id> = vars.iter().map(|v| p.var(v)).collect();
        let outs: Vec<Id> = srcs.iter().map(|s| p.parse_scalar(s).unwrap()).collect();
        let prog = Program::compile(&mut p, &xs, &outs).unwrap();
        let native = BatchKernel::new(&prog, JitMode::Auto).unwrap();
        assert!(native.is_native(), "this test host has a Cranelift backend");
        let interp = BatchKernel::new(&prog, JitMode::Off).unwrap();
        assert!(!interp.is_native());
        (native, interp, prog)
    }

    /// Runs both engines on the same random columns and compares every output bit for bit;
    /// checks against the point interpreter to `tol` relative.
    fn agree(srcs: &[&str], vars: &[&str], positive: bool, tol: f64) {
        let (native, interp, prog) = kernels(srcs, vars);
        for n in [0, 1, 2, 3, 7, 63, 64, 65, 130, 257] {
            let cols: Vec<Vec<f64>> = (0..vars.len())
                .map(|k| random_inputs(n, 0x9E37_79B9 + 31 * k as u64 + n as u64, positive))
                .collect();
            let ins: Vec<&[f64]> = cols.iter().map(|c| &c[..]).collect();
            let mut o1 = vec![vec![0.0; n]; srcs.len()];
            let mut o2 = vec![vec![7.0; n]; srcs.len()];
            let mut s1: Vec<&mut [f64]> = o1.iter_mut().map(|c| &mut c[..]).collect();
            native.run(&ins, &mut s1);
            let mut s2: Vec<&mut [f64]> = o2.iter_mut().map(|c| &mut c[..]).collect();
            interp.run(&ins, &mut s2);
            let mut ws = prog.workspace();
            let mut point = vec![0.0; srcs.len()];
            for k in 0..n {
                let x: Vec<f64> = cols.iter().map(|c| c[k]).collect();
                prog.eval(&x, &mut ws, &mut point);
                for o in 0..srcs.len() {
                    let (a, b) = (o1[o][k], o2[o][k]);
                    assert!(
                        same(a, b),
                        "{} at {x:?} (n = {n}): native {a:e}, interpreter {b:e}",
                        srcs[o]
                    );
                    let p = point[o];
                    if p.is_finite() && p.abs() > 1e-250 && p.abs() < 1e250 {
                        assert!(
                            (a - p).abs() <= tol * p.abs(),
                            "{} at {x:?}: batch {a:e}, point {p:e}",
                            srcs[o]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn native_and_interpreter_agree_bit_for_bit_on_every_operation() {
        // every operation, integer powers inlined (≤ 64) and called, negative powers through
        // the shared reciprocal
        let ops = "x + y; x - y; x*y; x/y; -x; x^2; x^3; x^7; x^12; x^64; x^65; x^(-12); \
                   x^(-3); x^(-65); x^(3/2); x^y; x^0.3; sqrt(x); sin(x); cos(x); tan(x); \
                   asin(x); acos(x); atan(x); atan2(x, y); sinh(x); cosh(x); tanh(x); exp(x); \
                   log(x); abs(x); sign(x); min(x, y); max(x, y); 3; x";
        let srcs: Vec<&str> = ops.split("; ").collect();
        agree(&srcs, &["x", "y"], false, 1e-12);
    }

    #[test]
    fn pair_potentials_in_r_squared_agree_bit_for_bit() {
        // Lennard-Jones and its −2 du/ds in s = r², Morse in r = sqrt(s), a screened Coulomb
        agree(
            &[
                "4*(1.3*s^(-6) - 0.7*s^(-3))",
                "-2*4*(-6*1.3*s^(-7) + 3*0.7*s^(-4))",
                "0.8*((1 - exp(-1.7*(sqrt(s) - 1.1)))^2 - 1)",
                "exp(-sqrt(s)/0.9)/sqrt(s) + s^(-7/2)",
            ],
            &["s"],
            true,
            1e-13,
        );
    }

    #[test]
    fn divisions_share_one_reciprocal() {
        let (native, _, prog) = kernels(&["4*(s^(-6) - s^(-3))", "48*s^(-7) - 24*s^(-4)"], &["s"]);
        let divs = |ops: &mut dyn Iterator<Item = Op>| ops.filter(|&o| o == Op::Div).count();
        assert!(divs(&mut prog.instructions().iter().map(|i| i.op())) >= 4);
        assert_eq!(divs(&mut native.steps.steps.iter().map(|s| s.op)), 1);
    }

    #[test]
    fn runs_on_many_threads_with_the_same_bits() {
        let (native, interp, _) = kernels(&["exp(-x)*x^(-6)", "sin(x)/x"], &["x"]);
        let x = random_inputs(1000, 7, true);
        let reference = |k: &BatchKernel| {
            let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            k.run(&[&x], &mut [&mut a, &mut b]);
            (a, b)
        };
        let want = reference(&interp);
        std::thread::scope(|s| {
            for k in [&native, &interp, &native, &interp] {
                let (want, reference) = (&want, &reference);
                s.spawn(move || {
                    let got = reference(k);
                    assert!(got.0.iter().zip(&want.0).all(|(a, b)| same(*a, *b)));
                    assert!(got.1.iter().zip(&want.1).all(|(a, b)| same(*a, *b)));
                });
            }
        });
    }

    /// Stretches read in place give, element by element, the bits of the whole columns
    /// gathered first: two inputs read from one long column at their own starts, one from a
    /// column of its own; stretches of every length 0..=9 (the vector loop and its tail),
    /// outputs written only inside the stretches (the rest keeps its NaN).
    #[test]
    fn stretches_read_in_place_give_the_gathered_bits() {
        let (native, interp, _) =
            kernels(&["sqrt(x*x + y*y) - z", "x/(y + 2*z)"], &["x", "y", "z"]);
        let state = random_inputs(300, 11, true);
        let z = random_inputs(100, 12, true);
        let mut stretches = Vec::new();
        let mut from = Vec::new();
        let mut first = 0u32;
        for len in 0..=9u32 {
            stretches.push((first, len));
            // x from state[7 first + ..], y from state[150 + first + ..], z from its column.
            from.extend([7 * first % 100, 150 + first, first]);
            first += len + 1;
        }
        let elements = first as usize;
        for k in [&native, &interp] {
            let mut outs = vec![vec![f64::NAN; elements]; 2];
            let mut cols: Vec<&mut [f64]> = outs.iter_mut().map(|c| &mut c[..]).collect();
            k.run_stretches(&[&state, &state, &z], &from, &mut cols, &stretches);
            for (s, &(first, len)) in stretches.iter().enumerate() {
                let (first, len) = (first as usize, len as usize);
                let start = |c: usize| from[3 * s + c] as usize;
                let x = state[start(0)..start(0) + len].to_vec();
                let y = state[start(1)..start(1) + len].to_vec();
                let zs = z[start(2)..start(2) + len].to_vec();
                let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
                interp.run(&[&x, &y, &zs], &mut [&mut a, &mut b]);
                for e in 0..len {
                    assert!(same(outs[0][first + e], a[e]) && same(outs[1][first + e], b[e]));
                }
                if first + len < elements {
                    assert!(outs[0][first + len].is_nan(), "written past stretch {s}");
                }
            }
        }
    }
}
