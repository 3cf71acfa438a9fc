//! A batch kernel's native loop, generated with Cranelift (see the parent module for the
//! steps it runs and why its results are the column interpreter's bits).
use super::{sign, Steps};
use crate::native::{
    binary_shim, codegen, inline_powi, new_module, shims, unary_shim, Code, RawFn,
};
use crate::JitError;
use cranelift_codegen::ir::condcodes::IntCC;
use cranelift_codegen::ir::{
    types, AbiParam, BlockArg, Function, InstBuilder, MemFlags, SigRef, Signature, Type, Value,
};
use cranelift_codegen::isa::CallConv;
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_module::{Linkage, Module};
use pdyn_expr::compile::Op;

/// The code of one kernel.
pub(super) type BatchCode = Code;

/// The generated loop: `(inputs, outputs, n)`, each of `inputs`/`outputs` an array of column
/// pointers. It lives in the crate's [`Code`] (which owns and frees the code memory), stored
/// there as a [`RawFn`] and turned back into this type to be called.
type BatchFn = unsafe extern "C" fn(*const *const f64, *const *mut f64, usize);

/// Signatures of the shims a kernel may call.
struct Shims {
    unary: SigRef,
    binary: SigRef,
    powi: SigRef,
}

/// Emits the steps once for values of type `ty` (`F64` or `F64X2`): `vals` holds the inputs
/// and constants (rows below the first step) and receives one value per step.
fn emit_steps(
    b: &mut FunctionBuilder,
    steps: &Steps,
    ty: Type,
    ptr: Type,
    sigs: &Shims,
    vals: &mut Vec<Value>,
) {
    for st in &steps.steps {
        let a = vals[st.a as usize];
        let rb = if st.op.reads_b() {
            Some(vals[st.b as usize])
        } else {
            None
        };
        let native = crate::native::native_arith(b, st.op, a, rb);
        let v = match native {
            Some(v) => v,
            None => match st.op {
                Op::Powi if st.b == 0 => {
                    let one = b.ins().f64const(1.0);
                    splat(b, ty, one)
                }
                Op::Powi if st.b as i32 > 0 && st.b as i32 <= crate::native::MAX_INLINE_POWI => {
                    inline_powi(b, a, st.b)
                }
                op => per_lane(b, ty, a, rb, |b, x, y| {
                    scalar_call(b, op, st.b, x, y, ptr, sigs)
                }),
            },
        };
        debug_assert_eq!(vals.len(), st.dst as usize);
        vals.push(v);
    }
}

fn splat(b: &mut FunctionBuilder, ty: Type, x: Value) -> Value {
    if ty == types::F64 {
        x
    } else {
        b.ins().splat(ty, x)
    }
}

/// `f` applied lane by lane (directly for scalars).
fn per_lane(
    b: &mut FunctionBuilder,
    ty: Type,
    a: Value,
    rb: Option<Value>,
    mut f: impl FnMut(&mut FunctionBuilder, Value, Option<Value>) -> Value,
) -> Value {
    if ty == types::F64 {
        return f(b, a, rb);
    }
    let mut lane_result = |b: &mut FunctionBuilder, lane: u8| {
        let x = b.ins().extractlane(a, lane);
        let y = rb.map(|y| b.ins().extractlane(y, lane));
        f(b, x, y)
    };
    let first = lane_result(b, 0);
    let mut v = b.ins().splat(ty, first);
    for lane in 1..ty.lane_count() as u8 {
        let r = lane_result(b, lane);
        v = b.ins().insertlane(v, r, lane);
    }
    v
}

/// A scalar operation without a packed form, through its shim.
fn scalar_call(
    b: &mut FunctionBuilder,
    op: Op,
    exponent: u32,
    x: Value,
    y: Option<Value>,
    ptr: Type,
    sigs: &Shims,
) -> Value {
    let call = |b: &mut FunctionBuilder, addr: usize, sig: SigRef, args: &[Value]| {
        let f = b.ins().iconst(ptr, addr as i64);
        let c = b.ins().call_indirect(sig, f, args);
        b.inst_results(c)[0]
    };
    match op {
        Op::Sign => {
            let f = sign as extern "C" fn(f64) -> f64;
            call(b, f as usize, sigs.unary, &[x])
        }
        Op::Powi => {
            let e = b.ins().iconst(types::I32, exponent as i32 as i64);
            let f = shims::powi as extern "C" fn(f64, i32) -> f64;
            call(b, f as usize, sigs.powi, &[x, e])
        }
        op => {
            if let Some(f) = unary_shim(op) {
                call(b, f as usize, sigs.unary, &[x])
            } else if let (Some(f), Some(y)) = (binary_shim(op), y) {
                call(b, f as usize, sigs.binary, &[x, y])
            } else {
                // `Steps::new` refuses operations `known` does not list: not reached
                b.ins().f64const(f64::NAN)
            }
        }
    }
}

/// Emits the kernel of `steps` into `func`:
///
/// ```text
/// entry:   load the column pointers; constants (scalar and splat)   → vhead(0)
/// vhead i: i + 2 ≤ n ? vbody(i) : shead(i)
/// vbody i: two points packed; store; → vhead(i + 2)
/// shead i: i < n ? sbody(i) : exit
/// sbody i: one point; store; → shead(i + 1)
/// ```
fn emit_kernel(
    steps: &Steps,
    ptr: Type,
    call_conv: CallConv,
    func: &mut Function,
    fctx: &mut FunctionBuilderContext,
) {
    const W: i64 = 2;
    let vty = types::F64X2;
    let mut b = FunctionBuilder::new(func, fctx);
    let entry = b.create_block();
    b.append_block_params_for_function_params(entry);
    let [vhead, vbody, shead, sbody] = [(); 4].map(|_| {
        let blk = b.create_block();
        b.append_block_param(blk, ptr);
        blk
    });
    let exit = b.create_block();

    b.switch_to_block(entry);
    let params = b.block_params(entry).to_vec();
    let (inp, outp, n) = (params[0], params[1], params[2]);
    let mut sig = |params: &[Type]| {
        let mut s = Signature::new(call_conv);
        s.params.extend(params.iter().map(|&t| AbiParam::new(t)));
        s.returns.push(AbiParam::new(types::F64));
        b.import_signature(s)
    };
    let sigs = Shims {
        unary: sig(&[types::F64]),
        binary: sig(&[types::F64, types::F64]),
        powi: sig(&[types::F64, types::I32]),
    };
    let table = MemFlags::trusted();
    // columns are `f64` slices: 8-byte aligned, not 16
    let data = MemFlags::new().with_notrap();
    let ins: Vec<Value> = (0..steps.n_inputs)
        .map(|k| b.ins().load(ptr, table, inp, 8 * k as i32))
        .collect();
    let outs: Vec<Value> = (0..steps.outs.len())
        .map(|k| b.ins().load(ptr, table, outp, 8 * k as i32))
        .collect();
    let cs: Vec<Value> = steps
        .consts
        .iter()
        .map(|&(_, v)| b.ins().f64const(v))
        .collect();
    let vcs: Vec<Value> = cs.iter().map(|&c| b.ins().splat(vty, c)).collect();
    let zero = b.ins().iconst(ptr, 0);
    b.ins().jump(vhead, &[BlockArg::Value(zero)]);

    // one iteration of `ty` at index i: load, steps, store
    let body = |b: &mut FunctionBuilder, i: Value, ty: Type, consts: &[Value]| {
        let off = b.ins().ishl_imm(i, 3);
        let mut vals: Vec<Value> = ins
            .iter()
            .map(|&p| {
                let addr = b.ins().iadd(p, off);
                b.ins().load(ty, data, addr, 0)
            })
            .collect();
        vals.extend_from_slice(consts);
        emit_steps(b, steps, ty, ptr, &sigs, &mut vals);
        for (&p, &r) in outs.iter().zip(&steps.outs) {
            let addr = b.ins().iadd(p, off);
            b.ins().store(data, vals[r as usize], addr, 0);
        }
    };

    b.switch_to_block(vhead);
    let i = b.block_params(vhead)[0];
    let end = b.ins().iadd_imm(i, W);
    let more = b.ins().icmp(IntCC::UnsignedLessThanOrEqual, end, n);
    let arg = [BlockArg::Value(i)];
    b.ins().brif(more, vbody, &arg, shead, &arg);

    b.switch_to_block(vbody);
    let i = b.block_params(vbody)[0];
    body(&mut b, i, vty, &vcs);
    let next = b.ins().iadd_imm(i, W);
    b.ins().jump(vhead, &[BlockArg::Value(next)]);

    b.switch_to_block(shead);
    let i = b.block_params(shead)[0];
    let more = b.ins().icmp(IntCC::UnsignedLessThan, i, n);
    b.ins().brif(more, sbody, &[BlockArg::Value(i)], exit, &[]);

    b.switch_to_block(sbody);
    let i = b.block_params(sbody)[0];
    body(&mut b, i, types::F64, &cs);
    let next = b.ins().iadd_imm(i, 1);
    b.ins().jump(shead, &[BlockArg::Value(next)]);

    b.switch_to_block(exit);
    b.ins().return_(&[]);
    b.seal_all_blocks();
    b.finalize();
}

/// Compiles `steps` to a native loop.
pub(super) fn compile(steps: &Steps) -> Result<Code, JitError> {
    let mut module = new_module(true)?;
    let ptr = module.target_config().pointer_type();
    let call_conv = module.isa().default_call_conv();
    let mut ctx = module.make_context();
    let mut fctx = FunctionBuilderContext::new();
    ctx.func
        .signature
        .params
        .extend([ptr, ptr, ptr].map(AbiParam::new));
    emit_kernel(steps, ptr, call_conv, &mut ctx.func, &mut fctx);
    let id = module
        .declare_function("pdyn_batch", Linkage::Local, &ctx.func.signature)
        .map_err(codegen)?;
    module.define_function(id, &mut ctx).map_err(codegen)?;
    module.finalize_definitions().map_err(codegen)?;
    let raw = module.get_finalized_function(id);
    // SAFETY: `raw` is finalized code. It is stored as a `RawFn` (a function pointer of the
    // same size) and only ever called as the `BatchFn` it is, by `call`.
    let func = unsafe { std::mem::transmute::<*const u8, RawFn>(raw) };
    Ok(Code {
        module: Some(module),
        funcs: vec![func],
    })
}

/// Calls the native loop on column pointers taken from slices of length ≥ `n`.
#[inline]
pub(super) fn call(code: &Code, ip: &[*const f64], op: &[*mut f64], n: usize) {
    // SAFETY: `compile` stored one function, generated with the signature of `BatchFn`. It
    // reads `ip[..n_inputs]` and `op[..n_outputs]` (both arrays at least that long: `run`
    // checked the column counts), then reads `n` values from each input column and writes `n`
    // values to each output column; `run` took them from slices of length `n`, the outputs
    // borrowed mutably, so the accesses are in bounds and unaliased. The code is alive while
    // `code` is.
    unsafe {
        let f = std::mem::transmute::<RawFn, BatchFn>(code.funcs[0]);
        f(ip.as_ptr(), op.as_ptr(), n)
    }
}
