//! Native code with Cranelift: the translation of a [`Program`] to machine code, and the
//! code memory it lives in (see the crate documentation for what is emitted and why).

use cranelift_codegen::control::ControlPlane;
use cranelift_codegen::ir::condcodes::FloatCC;
use cranelift_codegen::ir::{
    types, AbiParam, InstBuilder, MemFlags, Signature, StackSlotData, StackSlotKind, Value,
};
use cranelift_codegen::isa::TargetIsa;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_codegen::Context;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{default_libcall_names, FuncId, Linkage, Module, ModuleReloc};
use pdyn_expr::compile::{Op, TableCall};
use pdyn_expr::Program;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use crate::JitError;

pub(crate) fn codegen<E: std::fmt::Display>(e: E) -> JitError {
    JitError::Codegen {
        message: e.to_string(),
    }
}

/// One chunk of a program: `(inputs, out, spill)`.
pub(crate) type RawFn = unsafe extern "C" fn(*const f64, *mut f64, *mut f64);

/// Instructions per generated function. Cranelift's register allocator slows down sharply on
/// one huge basic block (many values live across many calls), so a long program becomes a
/// sequence of functions of this size that pass the values they share through a spill array.
/// Measured on the 100-link chain's `A x = b` (user CPU of `pdyn run --t-end 0.001`): 3.5 s of
/// code generation as one function, 2.2 s as chunks of 2,048 (512 gave the same).
const CHUNK: usize = 2048;

/// Longest run of instructions whose values stay in registers (see `SpillPlan`). Measured on
/// the 100-link chain's `A x = b` (106,553 instructions, compile time of the test binary at
/// load ≈ 6): unbounded runs 1.3–4.0 s, 64 0.6–0.8 s, 16 and 32 no better; 64 also kept
/// the evaluation time (46–77 µs).
const SEGMENT: usize = 64;

/// An input is loaded again in each window of this many instructions rather than kept in a
/// register from its first use to its last: a run's hoisted programs read thousands of
/// precomputed parameter products as inputs (`pdyn_expr::hoist`), and kept live across a
/// whole chunk they made register allocation 34 % of the 16-link chain's `pdyn run`.
const INPUT_WINDOW: usize = 64;

/// Programs of this length or more are compiled without Cranelift's mid-end optimisations:
/// a `Program` is already free of common subexpressions, and on long ones the e-graph pass
/// cost more than register allocation for nothing in return (16-link chain's `M` and `f`:
/// 0.82 µs per evaluation either way, compile 20–29 ms instead of 36–56 ms under load).
/// Short programs keep them: the satellite's right-hand side ran 1.9 µs per 100 calls with,
/// 2.6 µs without.
const UNOPTIMIZED_FROM: usize = 1024;

/// Programs up to this length are not cut into segments (see `SpillPlan`). Since a run's
/// programs are hoisted (`pdyn_expr::hoist`), their shared values live long: unsegmented, the
/// 16-link chain's `M` and `f` (about 1,500 instructions) made register allocation a third of
/// its `pdyn run`; segmented they compile in 4–7 ms instead of 12–19 ms and evaluate as fast
/// (0.69–0.82 µs). Before hoisting, segments had cost that program 2.5× its evaluation time.
const SEGMENTED_FROM: usize = 1024;

/// Whether `prog` is cut into segments (see `SpillPlan`): when longer than `SEGMENTED_FROM`,
/// or when it calls functions and has at least as many outputs as instructions. Unsegmented,
/// every output is stored after the last instruction, so all of them stay live across every
/// later call (which clobbers every XMM register): the 16-link chain's link numbers (141
/// instructions, 16 `sincos` calls, 160 outputs) compiled in 1.25 ms, segmented in 1.0 ms,
/// evaluating as fast (0.17 µs).
fn is_segmented(prog: &Program) -> bool {
    prog.len() > SEGMENTED_FROM
        || (prog.n_outputs() >= prog.len() && prog.instructions().iter().any(is_call))
}

/// The JIT module owning the code memory; freed on drop.
pub(crate) struct Code {
    pub(crate) module: Option<JITModule>,
    /// The chunks, called in order.
    pub(crate) funcs: Vec<RawFn>,
}

impl Drop for Code {
    fn drop(&mut self) {
        if let Some(m) = self.module.take() {
            // SAFETY: `func` points into this module's memory and is only reachable through
            // this `Code`, which is being dropped: no call can be in flight or follow.
            unsafe { m.free_memory() };
        }
    }
}

// SAFETY: after `finalize_definitions` the module is never mutated again (only freed, in
// `Drop`, which has exclusive access). The generated function reads `inputs`, writes `out`
// and its own stack frame, and calls pure shims: concurrent calls do not interfere.
unsafe impl Send for Code {}
// SAFETY: see `Send`; `&Code` only allows calling the finished function.
unsafe impl Sync for Code {}

/// A [`Program`] translated to native code; see the crate documentation.
#[derive(Clone)]
pub struct JitProgram {
    code: Arc<Code>,
    n_inputs: usize,
    n_outputs: usize,
    len: usize,
    /// Values passed between chunks.
    n_spill: usize,
    /// The tabulated functions the code calls by address (see `shims::table`): kept alive
    /// with the code.
    _tables: Arc<[TableCall]>,
}

impl std::fmt::Debug for JitProgram {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JitProgram")
            .field("n_inputs", &self.n_inputs)
            .field("n_outputs", &self.n_outputs)
            .field("instructions", &self.len)
            .field("chunks", &self.code.funcs.len())
            .finish()
    }
}

/// Largest exponent of `x^k` multiplied out inline rather than called.
pub(crate) const MAX_INLINE_POWI: i32 = 64;

/// `x^k` for `0 ≤ k`, as the same multiplications in the same order as `f64::powi` (LLVM's
/// `__powidf2`: square-and-multiply from the lowest bit, the result starting at 1), so the
/// bits agree with the interpreter; a call per power was most of the cost of a pair
/// potential such as `(sigma/r)^12`.
pub(crate) fn inline_powi(b: &mut FunctionBuilder, x: Value, k: u32) -> Value {
    let mut base = x;
    let mut acc: Option<Value> = None;
    let mut k = k;
    loop {
        if k & 1 == 1 {
            // 1·x is x exactly, so the first factor needs no multiplication.
            acc = Some(match acc {
                None => base,
                Some(r) => b.ins().fmul(r, base),
            });
        }
        k >>= 1;
        if k == 0 {
            break;
        }
        base = b.ins().fmul(base, base);
    }
    acc.unwrap_or_else(|| b.ins().f64const(1.0))
}

/// A JIT module for the host with the settings every generated function uses (the chunks
/// and the batch kernel); `optimize` runs Cranelift's mid-end (e-graph rewrites).
pub(crate) fn new_module(optimize: bool) -> Result<JITModule, JitError> {
    let isa_builder = cranelift_native::builder().map_err(|r| JitError::Unsupported {
        reason: r.to_string(),
    })?;
    let mut flags = settings::builder();
    for (k, v) in [
        ("opt_level", if optimize { "speed" } else { "none" }),
        ("use_colocated_libcalls", "false"),
        ("is_pic", "false"),
        // The IR is generated here from a checked `Program`, and the agreement tests compare
        // every example's native code with the interpreter; Cranelift's IR verifier took
        // about 3 % of a `pdyn run` of the 4-link chain (and it is off in wasmtime too).
        ("enable_verifier", "false"),
    ] {
        flags.set(k, v).map_err(codegen)?;
    }
    let isa = isa_builder
        .finish(settings::Flags::new(flags))
        .map_err(codegen)?;
    Ok(JITModule::new(JITBuilder::with_isa(
        isa,
        default_libcall_names(),
    )))
}

/// The operations Cranelift has as instructions, correctly rounded like Rust's (`+ − × ÷`,
/// negation, `sqrt`, `abs`), on scalars or lanes alike; `None` for the others. Shared by the
/// chunks and the batch kernel.
pub(crate) fn native_arith(
    b: &mut FunctionBuilder,
    op: Op,
    a: Value,
    rb: Option<Value>,
) -> Option<Value> {
    Some(match (op, rb) {
        (Op::Add, Some(y)) => b.ins().fadd(a, y),
        (Op::Sub, Some(y)) => b.ins().fsub(a, y),
        (Op::Mul, Some(y)) => b.ins().fmul(a, y),
        (Op::Div, Some(y)) => b.ins().fdiv(a, y),
        (Op::Neg, _) => b.ins().fneg(a),
        (Op::Sqrt, _) => b.ins().sqrt(a),
        (Op::Abs, _) => b.ins().fabs(a),
        _ => return None,
    })
}

/// Whether instruction `ins` is emitted as a call (a shim): every XMM register is
/// caller-saved on the platforms we target, so a value live across a call must be spilled.
fn is_call(ins: &pdyn_expr::compile::Instr) -> bool {
    let op = ins.op();
    match op {
        Op::Powi => !(0..=MAX_INLINE_POWI).contains(&(ins.b() as i32)),
        Op::Table | Op::SinCos => true,
        // Its value comes from the `SinCos` before it.
        Op::CosOfSinCos => false,
        _ => unary_shim(op).is_some() || binary_shim(op).is_some(),
    }
}

/// Which values cross from one segment to a later one, and where they are kept meanwhile.
///
/// In programs longer than `SEGMENTED_FROM`, a *segment* is a run of at most `SEGMENT`
/// instructions with no call in it (a call ends its segment) and no chunk boundary; the
/// outputs, stored after the last instruction, form segments of `SEGMENT` stores. (Shorter
/// programs have one segment per chunk.) Every SSA value lives inside one segment: a value
/// read in a later segment is stored to the spill array right after it is computed and loaded
/// again where it is needed, and inputs and constants are reloaded per segment. Left to
/// Cranelift, long live ranges (values across `sin`/`cos` calls, which clobber every XMM
/// register; a symmetric matrix's entry kept live from its first output to its mirror
/// thousands of stores later) made its register allocator most of the compile time: 1.7 s of
/// the 100-link chain's 6.9 s `pdyn run`, and 4–6 s of the chain's JIT compilation under load,
/// now 0.6 s. In a long program the loads and stores cost little next to the arithmetic and
/// calls they sit between; in a short one they showed (see `SEGMENTED_FROM`).
struct SpillPlan {
    chunks: usize,
    /// Instruction indices in the order they are emitted (see `schedule`).
    order: Vec<u32>,
    /// Spill slot of each temporary (instruction index), `u32::MAX` when it stays in its
    /// segment.
    slot: Vec<u32>,
    /// The segment in which each instruction reads its operands.
    read_segment: Vec<u32>,
    /// The segment in which each instruction's result is available.
    def_segment: Vec<u32>,
    /// The segment of the first outputs stored after the last instruction (`stored_at_end`).
    output_segment: u32,
    /// Outputs per output segment (`SEGMENT`; unbounded for short programs).
    max_segment: usize,
    n_slots: usize,
    /// The outputs that are instruction `k`'s value and stored as soon as it is computed
    /// (segmented programs) are `defined_outputs[output_start[k]..output_start[k + 1]]`.
    output_start: Vec<u32>,
    defined_outputs: Vec<u32>,
    /// The other outputs, stored after the last instruction.
    stored_at_end: Vec<u32>,
}

/// The order in which a segmented program's instructions are emitted: depth first from its
/// outputs, each instruction right after those of its operands not emitted yet, so a value
/// is used soon after it is computed. The compiler's order computes all of a sum's terms
/// before adding them: a 100-term row of the 100-link chain's forcing kept its products
/// live across segments, and 9,960 values went through the spill array (20,000 reloads, a
/// third of the 700 KB of machine code). Each instruction computes the same operation on the
/// same operands in any order, so the values are the same to the bit. A `SinCos` and its
/// `CosOfSinCos` stay adjacent: one call computes both.
fn schedule(prog: &Program) -> Vec<u32> {
    let len = prog.len();
    let first_temp = prog.first_temporary() as u32;
    let instructions = prog.instructions();
    let mut placed = vec![false; len];
    let mut order = Vec::with_capacity(len);
    let mut stack: Vec<(u32, bool)> = Vec::new();
    let roots = prog
        .output_registers()
        .iter()
        .filter(|&&r| r >= first_temp)
        .map(|&r| r - first_temp)
        .chain(0..len as u32);
    for root in roots {
        stack.push((root, false));
        while let Some((k, operands_done)) = stack.pop() {
            if placed[k as usize] {
                continue;
            }
            let op = instructions[k as usize].op();
            if op == Op::CosOfSinCos && k > 0 {
                // Placed with its `SinCos`, which has the same operand.
                stack.push((k - 1, false));
                continue;
            }
            if operands_done {
                placed[k as usize] = true;
                order.push(k);
                if op == Op::SinCos && (k + 1) < len as u32 {
                    placed[k as usize + 1] = true;
                    order.push(k + 1);
                }
                continue;
            }
            stack.push((k, true));
            // The first operand is popped, so emitted, first: a running sum before the term
            // added to it.
            let ins = &instructions[k as usize];
            let b = ins.op().reads_b().then(|| ins.b());
            for r in b.into_iter().chain([ins.a()]) {
                if r >= first_temp && !placed[(r - first_temp) as usize] {
                    stack.push((r - first_temp, false));
                }
            }
        }
    }
    order
}

impl SpillPlan {
    fn new(prog: &Program) -> SpillPlan {
        // Short programs keep every value in registers for the whole chunk: their register
        // allocation is cheap, and spilling around calls cost the satellite 1.65× the
        // hand-written closure's time instead of 1.2× (see `SEGMENTED_FROM`).
        if is_segmented(prog) {
            SpillPlan::in_order(prog, schedule(prog))
        } else {
            SpillPlan::in_order(prog, (0..prog.len() as u32).collect())
        }
    }

    /// The plan for emitting `prog`'s instructions in `order` (a topological order).
    fn in_order(prog: &Program, order: Vec<u32>) -> SpillPlan {
        let len = prog.len();
        let chunks = len.div_ceil(CHUNK).max(1);
        let first_temp = prog.first_temporary() as u32;
        let segmented = is_segmented(prog);
        let mut read_segment = vec![0; len];
        let mut def_segment = vec![0; len];
        let mut seg = 0u32;
        let max_seg = if segmented { SEGMENT } else { usize::MAX };
        let mut seg_start = 0usize;
        for (at, &k) in order.iter().enumerate() {
            if at > 0 && (at % CHUNK == 0 || at - seg_start >= max_seg) {
                seg += 1;
                seg_start = at;
            }
            if prog.instructions()[k as usize].op() == Op::CosOfSinCos && k > 0 {
                // Defined with its `SinCos` (`schedule` keeps them adjacent), by the same
                // call, even when a chunk boundary falls between them.
                let with = def_segment[k as usize - 1];
                read_segment[k as usize] = with;
                def_segment[k as usize] = with;
                continue;
            }
            read_segment[k as usize] = seg;
            if segmented && is_call(&prog.instructions()[k as usize]) {
                seg += 1;
                seg_start = at + 1;
            }
            def_segment[k as usize] = seg;
        }
        // In a segmented program an output that is an instruction's value is stored when it
        // is computed (a symmetric matrix's two halves, both then): kept for the end, each
        // would be spilled, loaded again and stored, three memory accesses instead of one, and
        // the 100-link chain's M has 10,000 of them. Other outputs, and all of a short
        // program's, are stored after the last instruction (`SEGMENT` to a segment): stores
        // between the satellite's loads and arithmetic made it 2.68 µs per 100 calls
        // instead of 1.87.
        let at_definition = |r: u32| segmented && r >= first_temp;
        let mut output_start = vec![0u32; len + 1];
        let mut stored_at_end = Vec::new();
        for (i, &r) in prog.output_registers().iter().enumerate() {
            if at_definition(r) {
                output_start[(r - first_temp) as usize + 1] += 1;
            } else {
                stored_at_end.push(i as u32);
            }
        }
        for k in 0..len {
            output_start[k + 1] += output_start[k];
        }
        let mut defined_outputs = vec![0u32; output_start[len] as usize];
        let mut next = output_start.clone();
        for (i, &r) in prog.output_registers().iter().enumerate() {
            if at_definition(r) {
                let k = (r - first_temp) as usize;
                defined_outputs[next[k] as usize] = i as u32;
                next[k] += 1;
            }
        }
        let first_output_segment = if segmented { seg + 1 } else { seg };
        // The last segment that reads each temporary.
        let mut last_use = def_segment.clone();
        let mut read = |r: u32, s: u32| {
            if r >= first_temp {
                let k = (r - first_temp) as usize;
                last_use[k] = last_use[k].max(s);
            }
        };
        for (k, ins) in prog.instructions().iter().enumerate() {
            if ins.op() == Op::CosOfSinCos {
                continue; // emits nothing: its `SinCos` read the operand
            }
            read(ins.a(), read_segment[k]);
            if ins.op().reads_b() {
                read(ins.b(), read_segment[k]);
            }
        }
        for (j, &i) in stored_at_end.iter().enumerate() {
            let r = prog.output_registers()[i as usize];
            read(r, first_output_segment + (j / max_seg) as u32);
        }
        let mut slot = vec![u32::MAX; len];
        let mut n_slots = 0;
        for k in 0..len {
            if last_use[k] > def_segment[k] {
                slot[k] = n_slots as u32;
                n_slots += 1;
            }
        }
        SpillPlan {
            chunks,
            order,
            slot,
            read_segment,
            def_segment,
            output_segment: first_output_segment,
            max_segment: max_seg,
            n_slots,
            output_start,
            defined_outputs,
            stored_at_end,
        }
    }
}

/// Emits chunk `c` of `prog` into `func`: instructions `c*CHUNK ..`, storing the values later
/// chunks need into the spill array, and (last chunk) the outputs.
fn emit_chunk(
    prog: &Program,
    plan: &SpillPlan,
    c: usize,
    ptr: types::Type,
    call_conv: cranelift_codegen::isa::CallConv,
    func: &mut cranelift_codegen::ir::Function,
    fctx: &mut FunctionBuilderContext,
) -> Result<(), JitError> {
    let mut b = FunctionBuilder::new(func, fctx);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let params = b.block_params(block);
    let (inp, outp, spill) = (params[0], params[1], params[2]);

    let mut sig1 = Signature::new(call_conv);
    sig1.params.push(AbiParam::new(types::F64));
    sig1.returns.push(AbiParam::new(types::F64));
    let sig1 = b.import_signature(sig1);
    let mut sig2 = Signature::new(call_conv);
    sig2.params.push(AbiParam::new(types::F64));
    sig2.params.push(AbiParam::new(types::F64));
    sig2.returns.push(AbiParam::new(types::F64));
    let sig2 = b.import_signature(sig2);
    let mut sigi = Signature::new(call_conv);
    sigi.params.push(AbiParam::new(types::F64));
    sigi.params.push(AbiParam::new(types::I32));
    sigi.returns.push(AbiParam::new(types::F64));
    let sigi = b.import_signature(sigi);
    let mut sigt = Signature::new(call_conv);
    sigt.params.push(AbiParam::new(ptr));
    sigt.params.push(AbiParam::new(types::F64));
    sigt.returns.push(AbiParam::new(types::F64));
    let sigt = b.import_signature(sigt);
    let mut sigsc = Signature::new(call_conv);
    sigsc.params.push(AbiParam::new(types::F64));
    sigsc.params.push(AbiParam::new(ptr));
    sigsc.returns.push(AbiParam::new(types::F64));
    let sigsc = b.import_signature(sigsc);
    // Where `shims::sincos` writes the cosine, made on the first `SinCos`.
    let mut cosine_slot = None;

    // Registers, per segment (see `SpillPlan`): inputs loaded and constants materialised on
    // first use in the segment, temporaries of earlier segments loaded from the spill array,
    // temporaries of this segment are the SSA values of its instructions.
    let n_in = prog.n_inputs();
    let consts = prog.constants();
    let first_temp = prog.first_temporary();
    // Each register's SSA value with the segment it belongs to; an input's also with the
    // window of `INPUT_WINDOW` instructions in which it was loaded (see there).
    let mut regs: Vec<Option<(Value, u32, u32)>> = vec![None; first_temp + prog.len()];
    let flags = MemFlags::trusted();
    let get = |b: &mut FunctionBuilder,
               regs: &mut Vec<Option<(Value, u32, u32)>>,
               r: u32,
               seg: u32,
               at: usize| {
        let r = r as usize;
        let window = if r < n_in {
            (at / INPUT_WINDOW) as u32
        } else {
            0
        };
        if let Some((v, s, w)) = regs[r] {
            if s == seg && w == window {
                return v;
            }
        }
        let v = if r < n_in {
            b.ins().load(types::F64, flags, inp, (8 * r) as i32)
        } else if r < first_temp {
            b.ins().f64const(consts[r - n_in])
        } else {
            // Defined in an earlier segment, which spilled it (the plan saw this read).
            let slot = plan.slot[r - first_temp] as usize;
            b.ins().load(types::F64, flags, spill, (8 * slot) as i32)
        };
        regs[r] = Some((v, seg, window));
        v
    };
    // Instruction `k`'s value `v` defined: kept for later reads in its segment, spilled for
    // later segments, stored to the outputs that are it.
    let define =
        |b: &mut FunctionBuilder, regs: &mut Vec<Option<(Value, u32, u32)>>, k: usize, v: Value| {
            // A call's result belongs to the segment after the call (in a segmented program).
            regs[first_temp + k] = Some((v, plan.def_segment[k], 0));
            let slot = plan.slot[k];
            if slot != u32::MAX {
                b.ins().store(flags, v, spill, (8 * slot as usize) as i32);
            }
            let outputs = plan.output_start[k] as usize..plan.output_start[k + 1] as usize;
            for &i in &plan.defined_outputs[outputs] {
                b.ins().store(flags, v, outp, (8 * i as usize) as i32);
            }
        };
    let start = c * CHUNK;
    let end = (start + CHUNK).min(prog.len());
    for (at, &k) in plan.order[start..end].iter().enumerate() {
        let (at, k) = (start + at, k as usize);
        let ins = &prog.instructions()[k];
        if ins.op() == Op::CosOfSinCos {
            continue; // defined by its `SinCos`, just before
        }
        let seg = plan.read_segment[k];
        let a = get(&mut b, &mut regs, ins.a(), seg, at);
        let rb = if ins.op().reads_b() {
            Some(get(&mut b, &mut regs, ins.b(), seg, at))
        } else {
            None
        };
        let native = native_arith(&mut b, ins.op(), a, rb);
        let v = match native {
            Some(v) => v,
            None => match ins.op() {
                Op::Sign => {
                    // 1 for a > 0, −1 for a < 0, a·0 otherwise (±0, or NaN for NaN).
                    let zero = b.ins().f64const(0.0);
                    let one = b.ins().f64const(1.0);
                    let minus_one = b.ins().f64const(-1.0);
                    let gt = b.ins().fcmp(FloatCC::GreaterThan, a, zero);
                    let lt = b.ins().fcmp(FloatCC::LessThan, a, zero);
                    let az = b.ins().fmul(a, zero);
                    let r = b.ins().select(lt, minus_one, az);
                    b.ins().select(gt, one, r)
                }
                Op::Powi => {
                    let k = ins.b() as i32;
                    if (0..=MAX_INLINE_POWI).contains(&k) {
                        inline_powi(&mut b, a, k as u32)
                    } else {
                        let f = b.ins().iconst(
                            ptr,
                            shims::powi as extern "C" fn(f64, i32) -> f64 as usize as i64,
                        );
                        let e = b.ins().iconst(types::I32, k as i64);
                        let call = b.ins().call_indirect(sigi, f, &[a, e]);
                        b.inst_results(call)[0]
                    }
                }
                Op::SinCos if k + 1 < prog.len() => {
                    let slot = *cosine_slot.get_or_insert_with(|| {
                        b.create_sized_stack_slot(StackSlotData::new(
                            StackSlotKind::ExplicitSlot,
                            8,
                            3,
                        ))
                    });
                    let f = b.ins().iconst(
                        ptr,
                        shims::sincos as extern "C" fn(f64, *mut f64) -> f64 as usize as i64,
                    );
                    let at = b.ins().stack_addr(ptr, slot, 0);
                    let call = b.ins().call_indirect(sigsc, f, &[a, at]);
                    let sin = b.inst_results(call)[0];
                    let cos = b.ins().stack_load(types::F64, slot, 0);
                    define(&mut b, &mut regs, k + 1, cos);
                    sin
                }
                Op::Table => {
                    // The interpreter's own call (`TableCall::eval`) through a shim, on the
                    // `TableCall` the program holds: the same bits. `JitProgram` keeps the
                    // program's calls alive as long as the code.
                    let Some(call) = prog.tables().get(ins.b() as usize) else {
                        return Err(JitError::UnsupportedOp {
                            op: "Table without its call".to_string(),
                        });
                    };
                    let f = b.ins().iconst(
                        ptr,
                        shims::table as extern "C" fn(*const TableCall, f64) -> f64 as usize as i64,
                    );
                    let at = b
                        .ins()
                        .iconst(ptr, call as *const TableCall as usize as i64);
                    let call = b.ins().call_indirect(sigt, f, &[at, a]);
                    b.inst_results(call)[0]
                }
                op => {
                    if let Some(s) = unary_shim(op) {
                        let f = b.ins().iconst(ptr, s as usize as i64);
                        let call = b.ins().call_indirect(sig1, f, &[a]);
                        b.inst_results(call)[0]
                    } else if let (Some(s), Some(y)) = (binary_shim(op), rb) {
                        let f = b.ins().iconst(ptr, s as usize as i64);
                        let call = b.ins().call_indirect(sig2, f, &[a, y]);
                        b.inst_results(call)[0]
                    } else {
                        return Err(JitError::UnsupportedOp {
                            op: format!("{op:?}"),
                        });
                    }
                }
            },
        };
        define(&mut b, &mut regs, k, v);
    }
    if c + 1 == plan.chunks {
        for (j, &i) in plan.stored_at_end.iter().enumerate() {
            let seg = plan.output_segment + (j / plan.max_segment) as u32;
            let r = prog.output_registers()[i as usize];
            let v = get(&mut b, &mut regs, r, seg, prog.len() + j);
            b.ins().store(flags, v, outp, (8 * i as usize) as i32);
        }
    }
    b.ins().return_(&[]);
    b.finalize();
    Ok(())
}

pub(crate) mod shims {
    //! `extern "C"` wrappers of the functions the interpreter calls (`libm`'s, as everywhere
    //! in pdyn: the same bits natively and in WebAssembly).
    macro_rules! unary {
        ($($name:ident => $f:path),* $(,)?) => {
            $(pub extern "C" fn $name(x: f64) -> f64 { $f(x) })*
        };
    }
    unary!(sin => libm::sin, cos => libm::cos, tan => libm::tan, asin => libm::asin,
           acos => libm::acos, atan => libm::atan, sinh => libm::sinh, cosh => libm::cosh,
           tanh => libm::tanh, exp => libm::exp, ln => libm::log);
    pub extern "C" fn atan2(y: f64, x: f64) -> f64 {
        libm::atan2(y, x)
    }
    /// A tabulated function's value: `call` points into the `Program::tables` that the
    /// `JitProgram` holds.
    pub extern "C" fn table(call: *const pdyn_expr::compile::TableCall, x: f64) -> f64 {
        // SAFETY: generated code passes the address of an element of the tables the
        // `JitProgram` keeps alive (see `JitProgram::compile`).
        unsafe { (*call).eval(x) }
    }
    /// `sin(x)`, with `cos(x)` written to `cos` (a stack slot of the generated code).
    pub extern "C" fn sincos(x: f64, cos: *mut f64) -> f64 {
        let (s, c) = libm::sincos(x);
        // SAFETY: generated code passes the address of an 8-byte stack slot of its own frame.
        unsafe { *cos = c };
        s
    }
    pub extern "C" fn powf(x: f64, y: f64) -> f64 {
        libm::pow(x, y)
    }
    pub extern "C" fn powi(x: f64, k: i32) -> f64 {
        x.powi(k)
    }
    pub extern "C" fn min(a: f64, b: f64) -> f64 {
        a.min(b)
    }
    pub extern "C" fn max(a: f64, b: f64) -> f64 {
        a.max(b)
    }
}

pub(crate) fn unary_shim(op: Op) -> Option<extern "C" fn(f64) -> f64> {
    Some(match op {
        Op::Sin => shims::sin,
        Op::Cos => shims::cos,
        Op::Tan => shims::tan,
        Op::Asin => shims::asin,
        Op::Acos => shims::acos,
        Op::Atan => shims::atan,
        Op::Sinh => shims::sinh,
        Op::Cosh => shims::cosh,
        Op::Tanh => shims::tanh,
        Op::Exp => shims::exp,
        Op::Ln => shims::ln,
        _ => return None,
    })
}

pub(crate) fn binary_shim(op: Op) -> Option<extern "C" fn(f64, f64) -> f64> {
    Some(match op {
        Op::Atan2 => shims::atan2,
        Op::Powf => shims::powf,
        Op::Min => shims::min,
        Op::Max => shims::max,
        _ => return None,
    })
}

/// One chunk's machine code, compiled away from the module (see [`compile_chunks`]).
struct MachineCode {
    bytes: Vec<u8>,
    alignment: u64,
    relocs: Vec<ModuleReloc>,
}

/// Most threads that compile one program's chunks.
const MAX_COMPILE_THREADS: usize = 4;

/// Machine code of every chunk of `prog`, in order. Chunks are independent functions, so a
/// program of several is compiled on several threads (up to the processors available): code
/// generation was a quarter of the 100-link chain's preparation for `pdyn run`. Each chunk's
/// code is the same whichever thread compiles it.
fn compile_chunks(
    prog: &Program,
    plan: &SpillPlan,
    isa: &dyn TargetIsa,
    sig: &Signature,
    ids: &[FuncId],
) -> Result<Vec<MachineCode>, JitError> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(MAX_COMPILE_THREADS)
        .min(plan.chunks);
    let compile_from = |next: &AtomicUsize| -> Vec<(usize, Result<MachineCode, JitError>)> {
        let mut ctx = Context::new();
        let mut fctx = FunctionBuilderContext::new();
        let mut done = Vec::new();
        loop {
            let c = next.fetch_add(1, Ordering::Relaxed);
            if c >= plan.chunks {
                return done;
            }
            done.push((
                c,
                compile_chunk(prog, plan, c, isa, sig, ids[c], &mut ctx, &mut fctx),
            ));
        }
    };
    let next = AtomicUsize::new(0);
    let mut results = if threads <= 1 {
        compile_from(&next)
    } else {
        std::thread::scope(|scope| {
            let workers: Vec<_> = (1..threads)
                .map(|_| scope.spawn(|| compile_from(&next)))
                .collect();
            let mut all = compile_from(&next);
            for w in workers {
                // A worker panicking is a bug in code generation: let it propagate.
                all.extend(w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
            }
            all
        })
    };
    results.sort_unstable_by_key(|(c, _)| *c);
    results.into_iter().map(|(_, code)| code).collect()
}

/// Chunk `c` of `prog` compiled to machine code for `isa`.
#[allow(clippy::too_many_arguments)]
fn compile_chunk(
    prog: &Program,
    plan: &SpillPlan,
    c: usize,
    isa: &dyn TargetIsa,
    sig: &Signature,
    id: FuncId,
    ctx: &mut Context,
    fctx: &mut FunctionBuilderContext,
) -> Result<MachineCode, JitError> {
    ctx.clear();
    ctx.func.signature = sig.clone();
    let ptr = isa.pointer_type();
    emit_chunk(prog, plan, c, ptr, sig.call_conv, &mut ctx.func, fctx)?;
    let alignment = ctx
        .compile(isa, &mut ControlPlane::default())
        .map_err(|e| codegen(e.inner))?
        .buffer
        .alignment as u64;
    let code = ctx
        .compiled_code()
        .ok_or_else(|| codegen("no code after compilation"))?;
    let relocs = code
        .buffer
        .relocs()
        .iter()
        .map(|r| ModuleReloc::from_mach_reloc(r, &ctx.func, id))
        .collect();
    Ok(MachineCode {
        bytes: code.code_buffer().to_vec(),
        alignment,
        relocs,
    })
}

impl JitProgram {
    /// Translates `prog` to native code for the host.
    pub fn compile(prog: &Program) -> Result<JitProgram, JitError> {
        let mut module = new_module(prog.len() < UNOPTIMIZED_FROM)?;
        let ptr = module.target_config().pointer_type();
        let mut sig = Signature::new(module.isa().default_call_conv());
        for _ in 0..3 {
            sig.params.push(AbiParam::new(ptr));
        }
        let plan = SpillPlan::new(prog);
        let ids = (0..plan.chunks)
            .map(|c| {
                module
                    .declare_function(&format!("pdyn_chunk{c}"), Linkage::Local, &sig)
                    .map_err(codegen)
            })
            .collect::<Result<Vec<FuncId>, _>>()?;
        let machine = compile_chunks(prog, &plan, module.isa(), &sig, &ids)?;
        for (&id, code) in ids.iter().zip(&machine) {
            module
                .define_function_bytes(id, code.alignment, &code.bytes, &code.relocs)
                .map_err(codegen)?;
        }
        module.finalize_definitions().map_err(codegen)?;
        let funcs = ids
            .into_iter()
            .map(|id| {
                let raw = module.get_finalized_function(id);
                // SAFETY: `raw` is the finalized code of a function with exactly this
                // signature, using the platform's default (C) calling convention.
                unsafe { std::mem::transmute::<*const u8, RawFn>(raw) }
            })
            .collect();
        Ok(JitProgram {
            code: Arc::new(Code {
                module: Some(module),
                funcs,
            }),
            n_inputs: prog.n_inputs(),
            n_outputs: prog.n_outputs(),
            len: prog.len(),
            n_spill: plan.n_slots,
            _tables: prog.tables().clone(),
        })
    }

    /// Number of generated functions (programs longer than a chunk are split).
    pub fn chunks(&self) -> usize {
        self.code.funcs.len()
    }

    /// A spill array for [`JitProgram::eval`] (empty when no value crosses a call or a chunk).
    pub fn workspace(&self) -> Vec<f64> {
        vec![0.0; self.n_spill]
    }

    /// Number of inputs read by [`JitProgram::eval`].
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    /// Number of outputs written by [`JitProgram::eval`].
    pub fn n_outputs(&self) -> usize {
        self.n_outputs
    }

    /// Number of instructions of the source program.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the source program had no instruction.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Evaluates every output: the same values, bit for bit, as [`Program::eval`] on the
    /// source program. `ws` comes from [`JitProgram::workspace`]; allocates nothing.
    ///
    /// # Panics
    /// If `inputs` is shorter than [`JitProgram::n_inputs`], `out` shorter than
    /// [`JitProgram::n_outputs`] or `ws` shorter than the workspace (a programming error, not
    /// a data error).
    #[inline]
    pub fn eval(&self, inputs: &[f64], ws: &mut [f64], out: &mut [f64]) {
        assert!(
            inputs.len() >= self.n_inputs
                && out.len() >= self.n_outputs
                && ws.len() >= self.n_spill,
            "JitProgram::eval: inputs, workspace or outputs too short"
        );
        for f in &self.code.funcs {
            // SAFETY: each chunk reads `inputs[..n_inputs]`, reads and writes
            // `ws[..n_spill]` and writes `out[..n_outputs]`, all in bounds (checked above);
            // the code is alive while `self.code` is.
            unsafe { f(inputs.as_ptr(), out.as_mut_ptr(), ws.as_mut_ptr()) }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Evaluator, JitMode};
    use pdyn_expr::{Id, Pool};

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[test]
    fn integer_powers_multiplied_out_agree_with_powi_bit_for_bit() {
        // Every exponent the compiler emits as Powi (4 and up; 64 is the last inlined, 65+
        // call), at inputs spread over many binades, including overflow and underflow.
        let mut p = Pool::new();
        let x = p.var("x");
        let outs: Vec<Id> = (4..=70)
            .map(|k| p.parse_scalar(&format!("x^{k}")).unwrap())
            .collect();
        let prog = Program::compile(&mut p, &[x], &outs).unwrap();
        let jit = JitProgram::compile(&prog).unwrap();
        let mut ws = prog.workspace();
        let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![0.0; outs.len()]);
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..2000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let mantissa = (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            let exponent = ((state >> 3) % 40) as i32 - 20;
            let v = mantissa * 10f64.powi(exponent);
            prog.eval(&[v], &mut ws, &mut o1);
            jit.eval(&[v], &mut jit.workspace(), &mut o2);
            for (k, (a, b)) in o1.iter().zip(&o2).enumerate() {
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "x^{} at x = {v:e}: interpreter {a:e}, jit {b:e}",
                    k + 4
                );
            }
        }
    }

    /// A long sum is emitted term by term (each product right before it is added), not all
    /// products first: few values cross segments, and the result is the interpreter's.
    #[test]
    fn long_sums_are_emitted_term_by_term() {
        let mut p = Pool::new();
        let xs: Vec<Id> = (0..300).map(|i| p.var(&format!("x{i}"))).collect();
        let mut outs = Vec::new();
        for row in 0..4 {
            let terms: Vec<Id> = (0..300)
                .map(|j| {
                    let k = p.int(row + 2);
                    let xk = p.pow(xs[j], k);
                    p.mul(&[xk, xs[(j + 1) % 300]])
                })
                .collect();
            outs.push(p.add(&terms));
        }
        let prog = Program::compile(&mut p, &xs, &outs).unwrap();
        assert!(prog.len() > SEGMENTED_FROM, "{}", prog.len());
        let plan = SpillPlan::new(&prog);
        let in_program_order = SpillPlan::in_order(&prog, (0..prog.len() as u32).collect());
        // In the compiler's order every product comes before the additions and crosses into
        // a later segment.
        assert!(
            plan.n_slots * 5 < in_program_order.n_slots,
            "{} spilled values, {} in program order",
            plan.n_slots,
            in_program_order.n_slots
        );
        let jit = JitProgram::compile(&prog).unwrap();
        let input: Vec<f64> = (0..300).map(|i| 0.9 + 0.001 * i as f64).collect();
        let (mut o1, mut o2) = (vec![0.0; 4], vec![0.0; 4]);
        prog.eval(&input, &mut prog.workspace(), &mut o1);
        jit.eval(&input, &mut jit.workspace(), &mut o2);
        for (a, b) in o1.iter().zip(&o2) {
            assert!(same(*a, *b), "interpreter {a:e}, jit {b:e}");
        }
    }

    /// Outputs of every kind in a program of several chunks and segments: instruction values
    /// (stored when computed, some twice, like a symmetric matrix's halves, some also read
    /// by later instructions), inputs and constants (stored after the last instruction).
    #[test]
    fn outputs_of_every_kind_land_in_place_in_a_long_program() {
        let mut p = Pool::new();
        let xs: Vec<Id> = (0..40).map(|i| p.var(&format!("x{i}"))).collect();
        let mut outs = Vec::new();
        for i in 0..40 {
            for j in i..40 {
                let e = p
                    .parse_scalar(&format!("x{i}*sin(x{j}) + {}*x{j}^2", i + 1))
                    .unwrap();
                outs.push(e);
                if i != j {
                    outs.push(e);
                }
            }
        }
        let last = *outs.last().unwrap();
        let total = p.parse_scalar("x0*x39 + 3").unwrap();
        let uses_an_output = p.add(&[last, total]);
        let constant = p.parse_scalar("2.5").unwrap();
        outs.extend([xs[7], constant, uses_an_output, xs[7], last]);
        let prog = Program::compile(&mut p, &xs, &outs).unwrap();
        let jit = JitProgram::compile(&prog).unwrap();
        assert!(
            prog.len() > SEGMENTED_FROM && jit.chunks() >= 2,
            "{}",
            prog.len()
        );
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![f64::NAN; outs.len()]);
        for _ in 0..20 {
            let input: Vec<f64> = (0..40)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
                })
                .collect();
            prog.eval(&input, &mut prog.workspace(), &mut o1);
            jit.eval(&input, &mut jit.workspace(), &mut o2);
            for (k, (a, b)) in o1.iter().zip(&o2).enumerate() {
                assert!(same(*a, *b), "output {k}: interpreter {a:e}, jit {b:e}");
            }
            assert_eq!(o2[o2.len() - 5], input[7]);
            assert_eq!(o2[o2.len() - 4], 2.5);
        }
    }

    /// Fused sines and cosines (`Op::SinCos`) in programs of several chunks and segments:
    /// the cosine defined by its sine's call, spilled when read in a later segment, stored as
    /// an output, also when a chunk boundary falls between the pair. The interpreter's bits.
    #[test]
    fn fused_sines_and_cosines_agree_with_the_interpreter_across_chunks() {
        let mut straddled = 0;
        // Outputs that come first shift the pairs' places: one of these shifts puts a pair
        // across the boundary.
        for (n, shift) in (0..12).flat_map(|s| [(260, s), (281, s)]) {
            let mut p = Pool::new();
            let xs: Vec<Id> = (0..n).map(|i| p.var(&format!("x{i}"))).collect();
            let mut outs: Vec<Id> = (0..shift)
                .map(|m| p.parse_scalar(&format!("x{m}*x{}", m + 1)).unwrap())
                .collect();
            for i in 0..n {
                // A chain's link: its sine and cosine read far apart and as outputs.
                let e = p
                    .parse_scalar(&format!(
                        "x{i}^2*sin(x{i}) + x{j}*cos(x{i}) + {k}*x{i}*x{j}",
                        j = (i + 7) % n,
                        k = i + 1
                    ))
                    .unwrap();
                outs.push(e);
                if i % 5 == 0 {
                    outs.push(p.parse_scalar(&format!("cos(x{i})")).unwrap());
                }
            }
            let total = p.add(&outs);
            outs.push(total);
            let prog = Program::compile(&mut p, &xs, &outs).unwrap();
            let fused = prog
                .instructions()
                .iter()
                .filter(|i| i.op() == Op::SinCos)
                .count();
            assert_eq!(fused, n);
            let plan = SpillPlan::new(&prog);
            for (at, &k) in plan.order.iter().enumerate() {
                if prog.instructions()[k as usize].op() == Op::SinCos {
                    assert_eq!(plan.order[at + 1], k + 1, "the pair is emitted together");
                    straddled += usize::from((at + 1) % CHUNK == 0);
                }
            }
            let jit = JitProgram::compile(&prog).unwrap();
            assert!(jit.chunks() >= 2, "{}", prog.len());
            let input: Vec<f64> = (0..n).map(|i| 0.3 * i as f64 - 20.0).collect();
            let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![f64::NAN; outs.len()]);
            prog.eval(&input, &mut prog.workspace(), &mut o1);
            jit.eval(&input, &mut jit.workspace(), &mut o2);
            for (k, (a, b)) in o1.iter().zip(&o2).enumerate() {
                assert!(
                    same(*a, *b),
                    "n = {n}, output {k}: interpreter {a:e}, jit {b:e}"
                );
            }
            assert_eq!(o1[shift + 1].to_bits(), libm::cos(input[0]).to_bits());
        }
        assert!(
            straddled > 0,
            "no program had a pair across a chunk boundary"
        );
    }

    /// A short program with calls and as many outputs as instructions (a chain's link
    /// numbers) is emitted in segments, with the interpreter's bits; one with few outputs is
    /// not.
    #[test]
    fn short_programs_with_many_outputs_and_calls_are_segmented() {
        let mut p = Pool::new();
        let n = 16;
        let mut inputs: Vec<Id> = (0..n).map(|i| p.var(&format!("q{i}"))).collect();
        inputs.extend((0..n).map(|i| p.var(&format!("w{i}"))));
        let mut outs = Vec::new();
        for i in 0..n {
            let l = 1.0 + 0.1 * i as f64;
            for src in [
                "1.5".to_string(),
                format!("{l}*cos(q{i})"),
                format!("{l}*sin(q{i})"),
                "0".to_string(),
                format!("-{l}*sin(q{i})*w{i}^2"),
                format!("{l}*cos(q{i})*w{i}^2"),
                "0".to_string(),
                "0".to_string(),
                "-9.81*1.5".to_string(),
                "0".to_string(),
            ] {
                outs.push(p.parse_scalar(&src).unwrap());
            }
        }
        let prog = Program::compile(&mut p, &inputs, &outs).unwrap();
        assert!(prog.len() < SEGMENTED_FROM && is_segmented(&prog));
        let few = Program::compile(&mut p, &inputs, &outs[31..33]).unwrap();
        assert!(!is_segmented(&few));
        let jit = JitProgram::compile(&prog).unwrap();
        let x: Vec<f64> = (0..2 * n).map(|i| 0.7 * i as f64 - 9.0).collect();
        let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![f64::NAN; outs.len()]);
        prog.eval(&x, &mut prog.workspace(), &mut o1);
        jit.eval(&x, &mut jit.workspace(), &mut o2);
        for (k, (a, b)) in o1.iter().zip(&o2).enumerate() {
            assert!(same(*a, *b), "output {k}: interpreter {a:e}, jit {b:e}");
        }
    }

    /// A tabulated function for tests: `x³ - order` in [-1, 1] (any bits will do), NaN
    /// outside.
    #[derive(Debug)]
    struct Cubed;

    impl pdyn_expr::Tabulated for Cubed {
        fn eval(&self, order: u8, x: f64) -> f64 {
            if (-1.0..=1.0).contains(&x) {
                x * x * x - order as f64
            } else {
                f64::NAN
            }
        }
        fn degree(&self) -> u8 {
            3
        }
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
    }

    #[test]
    fn tabulated_calls_agree_with_the_interpreter_across_spills() {
        // The table's calls clobber registers like `sin`'s: values live across them (and
        // across chunks, in a long program) must come back the same.
        let mut p = Pool::new();
        let table = p.add_table("g", Arc::new(Cubed)).unwrap();
        let x = p.var("x");
        let mut outs = Vec::new();
        for k in 0..300 {
            let arg = p
                .parse_scalar(&format!("x*{}/301 + sin(x)/7", k + 1))
                .unwrap();
            let g = p.tabulated(table, (k % 3) as u8, arg);
            let w = p.parse_scalar(&format!("x^2 + {k}")).unwrap();
            outs.push(p.mul2(g, w));
            let dg = p.dt(g);
            outs.push(dg);
        }
        let prog = Program::compile(&mut p, &[x], &outs).unwrap();
        let jit = JitProgram::compile(&prog).unwrap();
        let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![f64::NAN; outs.len()]);
        for input in [-0.9, -0.3, 0.0, 0.41, 0.77, 2.0] {
            prog.eval(&[input], &mut prog.workspace(), &mut o1);
            jit.eval(&[input], &mut jit.workspace(), &mut o2);
            for (k, (a, b)) in o1.iter().zip(&o2).enumerate() {
                assert!(
                    same(*a, *b),
                    "output {k} at {input}: interpreter {a:e}, jit {b:e}"
                );
            }
        }
        // The value really is the table's: g(x) x^2 at x = 0.5 for k = 300 - 1 (order 2).
        prog.eval(&[0.5], &mut prog.workspace(), &mut o1);
        let arg = 0.5 * 300.0 / 301.0 + libm::sin(0.5) / 7.0;
        let want = (arg * arg * arg - 2.0) * (0.25 + 299.0);
        assert!(
            (o1[2 * 299] - want).abs() < 1e-12 * want.abs(),
            "{} vs {want}",
            o1[598]
        );
    }

    #[test]
    fn every_operation_agrees_with_the_interpreter() {
        let mut p = Pool::new();
        let (x, y) = (p.var("x"), p.var("y"));
        let srcs = [
            "x + y",
            "x - y",
            "x*y",
            "x/y",
            "-x",
            "x^2",
            "x^3",
            "x^7",
            "x^4",
            "x^6",
            "x^12",
            "x^13",
            "x^64",
            "x^65",
            "x^(-12)",
            "x^(-3)",
            "x^(3/2)",
            "x^(5/2)",
            "x^y",
            "x^0.3",
            "sqrt(x)",
            "sin(x)",
            "cos(x)",
            "tan(x)",
            "asin(x)",
            "acos(x)",
            "atan(x)",
            "atan2(x, y)",
            "sinh(x)",
            "cosh(x)",
            "tanh(x)",
            "exp(x)",
            "log(x)",
            "abs(x)",
            "sign(x)",
            "min(x, y)",
            "max(x, y)",
            "3",
            "x",
        ];
        let outs: Vec<Id> = srcs.iter().map(|s| p.parse_scalar(s).unwrap()).collect();
        let prog = Program::compile(&mut p, &[x, y], &outs).unwrap();
        let jit = JitProgram::compile(&prog).unwrap();
        let mut ws = prog.workspace();
        let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![0.0; outs.len()]);
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.7,
            2.5,
            f64::NAN,
            f64::INFINITY,
            1e300,
        ];
        for &a in &specials {
            for &b in &specials {
                prog.eval(&[a, b], &mut ws, &mut o1);
                jit.eval(&[a, b], &mut jit.workspace(), &mut o2);
                for k in 0..outs.len() {
                    assert!(
                        same(o1[k], o2[k]),
                        "{} at ({a}, {b}): {} vs {}",
                        srcs[k],
                        o1[k],
                        o2[k]
                    );
                }
            }
        }
    }

    #[test]
    fn off_mode_interprets_and_auto_is_native_here() {
        let mut p = Pool::new();
        let x = p.var("x");
        let e = p.parse_scalar("x*x + 1").unwrap();
        let prog = Program::compile(&mut p, &[x], &[e]).unwrap();
        let off = Evaluator::new(prog.clone(), JitMode::Off);
        assert!(!off.is_native());
        let auto = Evaluator::new(prog, JitMode::Auto);
        assert!(auto.is_native(), "this test host has a Cranelift backend");
        let mut out = [0.0];
        let mut ws = auto.workspace();
        auto.eval(&[3.0], &mut ws, &mut out);
        assert_eq!(out[0], 10.0);
    }

    #[test]
    fn is_send_and_sync_and_callable_from_threads() {
        fn assert_send_sync<T: Send + Sync>() {}
        assert_send_sync::<JitProgram>();
        let mut p = Pool::new();
        let x = p.var("x");
        let e = p.parse_scalar("sin(x)*x").unwrap();
        let prog = Program::compile(&mut p, &[x], &[e]).unwrap();
        let jit = JitProgram::compile(&prog).unwrap();
        std::thread::scope(|s| {
            for k in 0..4 {
                let jit = jit.clone();
                s.spawn(move || {
                    let mut out = [0.0];
                    let xk = k as f64 * 0.3;
                    jit.eval(&[xk], &mut jit.workspace(), &mut out);
                    assert_eq!(out[0].to_bits(), (libm::sin(xk) * xk).to_bits());
                });
            }
        });
    }
}
