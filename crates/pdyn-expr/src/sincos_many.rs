//! Sines and cosines of many arguments at once, with `libm::sincos`'s bits.
//!
//! A pendulum chain needs `sin q_k` and `cos q_k` of every link at every evaluation: at 100
//! links, one `libm::sincos` per link was a fifth of the run, each call a chain of dependent
//! operations (reduction modulo `π/2`, then two polynomials) that a core runs one after the
//! other. [`sincos_many`] runs four arguments through the same operations side by side in
//! the lanes of an AVX register.
//!
//! The bits are `libm::sincos`'s on every argument, because the lanes run the operations of
//! libm 0.2.16's `rem_pio2`, `k_sin` and `k_cos` (FreeBSD's `__rem_pio2`, `__kernel_sin`,
//! `__kernel_cos`) in the same order, each a correctly rounded IEEE operation (no fused
//! multiply-add); libm's branches become selections between lanes computed both ways:
//! - `|x| ≤ π/4` (high word `≤ 0x3fe921fb`) is not reduced (`k_sin(x, 0, 0)`, `k_cos(x, 0)`);
//! - up to `9π/4` a multiple `k = 1…4` of `π/2` chosen by the high word is subtracted once
//!   (`x − k·pio2_1 − k·pio2_1t`), which is the first round of the general reduction with
//!   `f_n = ±k`;
//! - above, and at the four high words where that would cancel (`π/2`, `π`, `3π/2`, `2π`),
//!   `f_n = rint(x · 2/π)` and a second and third round follow when the first lost more
//!   than 16 (then 49) bits: the lane's exponent test `e_x − e_y > 16` is `|y_0| < 2^(e_x −
//!   16)`, a comparison with a power of two.
//!
//! A group of four holding a tiny (`|x| < 2^-27 √2`), huge (`|x| ≥ 2^20 π/2`, libm's
//! Payne–Hanek reduction) or non-finite argument goes through `libm::sincos` itself, as does
//! the remainder of the slice and every processor without AVX (and WebAssembly).

use crate::compile::{Instr, Op, Program};
use std::sync::Arc;

/// `sin[k], cos[k] = libm::sincos(x[k])` for every `k` (the slices have one length).
pub fn sincos_many(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    assert!(
        sin.len() == x.len() && cos.len() == x.len(),
        "sincos_many: {} arguments, {} sines, {} cosines",
        x.len(),
        sin.len(),
        cos.len()
    );
    #[cfg(target_arch = "x86_64")]
    if x.len() >= 4 && std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor has AVX (checked just above) and the slices have one length
        // (asserted).
        unsafe { avx::sincos_many(x, sin, cos) };
        return;
    }
    scalar(x, sin, cos);
}

/// `program` with each fused sine and cosine of an input register taken out of its
/// instructions: they become inputs of their own, appended after the old ones (the sines of
/// the returned registers in order, then their cosines), for a caller that computes them all
/// at once with [`sincos_many`]. Every other instruction is kept in its order with its
/// operands renumbered, so the program computes the bits it did when it is given
/// `libm::sincos`'s values there.
pub fn hoist_input_sincos(program: Program) -> (Program, Vec<u32>) {
    let n_inputs = program.n_inputs() as u32;
    let n_consts = program.constants().len() as u32;
    let first_temp = n_inputs + n_consts;
    let instrs = program.instructions();
    let mut angles: Vec<u32> = Vec::new();
    // Old temporary index → new register (hoisted: an input; kept: a later temporary).
    let mut new_reg: Vec<u32> = Vec::with_capacity(instrs.len());
    let mut kept: Vec<(Op, u32, u32)> = Vec::with_capacity(instrs.len());
    let mut k = 0;
    while k < instrs.len() {
        let ins = &instrs[k];
        let fused = ins.op() == Op::SinCos
            && ins.a() < n_inputs
            && instrs.get(k + 1).is_some_and(|c| c.op() == Op::CosOfSinCos);
        if fused {
            angles.push(ins.a());
            // Placeholders: the registers are known once the count of angles is.
            new_reg.push(u32::MAX - 2 * (angles.len() as u32 - 1));
            new_reg.push(u32::MAX - 2 * (angles.len() as u32 - 1) - 1);
            k += 2;
        } else {
            new_reg.push(kept.len() as u32);
            kept.push((ins.op(), ins.a(), ins.b()));
            k += 1;
        }
    }
    if angles.is_empty() {
        return (program, angles);
    }
    let m = angles.len() as u32;
    let shift = 2 * m;
    let renumber = |r: u32| -> u32 {
        if r < n_inputs {
            r
        } else if r < first_temp {
            r + shift
        } else {
            let t = new_reg[(r - first_temp) as usize];
            if t >= u32::MAX - 2 * m {
                // Hoisted pair j: its sine is input n_inputs + j, its cosine n_inputs + m + j.
                let d = u32::MAX - t;
                let (j, is_cos) = (d / 2, d % 2 == 1);
                n_inputs + j + if is_cos { m } else { 0 }
            } else {
                first_temp + shift + t
            }
        }
    };
    let instrs: Vec<Instr> = kept
        .iter()
        .map(|&(op, a, b)| {
            let b = if op.reads_b() { renumber(b) } else { b };
            Instr::new(op, renumber(a), b)
        })
        .collect();
    let outputs = program
        .output_registers()
        .iter()
        .map(|&r| renumber(r))
        .collect();
    let hoisted = Program::from_parts(
        (n_inputs + shift) as usize,
        program.constants().to_vec(),
        instrs,
        outputs,
        Arc::clone(program.tables()),
    );
    (hoisted, angles)
}

fn scalar(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    for ((&a, s), c) in x.iter().zip(sin.iter_mut()).zip(cos.iter_mut()) {
        (*s, *c) = libm::sincos(a);
    }
}

#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;

    // libm 0.2.16's constants (FreeBSD msun, k_sin.c, k_cos.c, e_rem_pio2.c), by their bits.
    const S1: f64 = f64::from_bits(0xbfc55555_55555549);
    const S2: f64 = f64::from_bits(0x3f811111_1110f8a6);
    const S3: f64 = f64::from_bits(0xbf2a01a0_19c161d5);
    const S4: f64 = f64::from_bits(0x3ec71de3_57b1fe7d);
    const S5: f64 = f64::from_bits(0xbe5ae5e6_8a2b9ceb);
    const S6: f64 = f64::from_bits(0x3de5d93a_5acfd57c);
    const C1: f64 = f64::from_bits(0x3fa55555_5555554c);
    const C2: f64 = f64::from_bits(0xbf56c16c_16c15177);
    const C3: f64 = f64::from_bits(0x3efa01a0_19cb1590);
    const C4: f64 = f64::from_bits(0xbe927e4f_809c52ad);
    const C5: f64 = f64::from_bits(0x3e21ee9e_bdb4b1c4);
    const C6: f64 = f64::from_bits(0xbda8fae9_be8838d4);
    const INV_PIO2: f64 = f64::from_bits(0x3fe45f30_6dc9c883);
    const TO_INT: f64 = 1.5 / f64::EPSILON;
    const PIO2_1: f64 = f64::from_bits(0x3ff921fb_54400000);
    const PIO2_1T: f64 = f64::from_bits(0x3dd0b461_1a626331);
    const PIO2_2: f64 = f64::from_bits(0x3dd0b461_1a600000);
    const PIO2_2T: f64 = f64::from_bits(0x3ba3198a_2e037073);
    const PIO2_3: f64 = f64::from_bits(0x3ba3198a_2e000000);
    const PIO2_3T: f64 = f64::from_bits(0x397b839a_252049c1);

    /// The smallest double whose high word is `high`: `|x| < below(h + 1)` is "the high word
    /// of `|x|` is at most `h`", libm's tests.
    fn below(high: u64) -> f64 {
        f64::from_bits(high << 32)
    }

    /// # Safety
    /// The processor must have AVX; the three slices have one length.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn sincos_many(x: &[f64], sin: &mut [f64], cos: &mut [f64]) {
        let n = x.len();
        let mut k = 0;
        while k + 4 <= n {
            // SAFETY: AVX is present and `k + 4 <= n` elements are in each slice.
            unsafe {
                let xv = _mm256_loadu_pd(x.as_ptr().add(k));
                if !four(xv, sin.as_mut_ptr().add(k), cos.as_mut_ptr().add(k)) {
                    super::scalar(&x[k..k + 4], &mut sin[k..k + 4], &mut cos[k..k + 4]);
                }
            }
            k += 4;
        }
        super::scalar(&x[k..], &mut sin[k..], &mut cos[k..]);
    }

    /// Four lanes at once; `false` (nothing written) when a lane needs libm's own code.
    ///
    /// # Safety
    /// AVX; `s` and `c` point at four writable elements.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn four(x: __m256d, s: *mut f64, c: *mut f64) -> bool {
        let v = _mm256_set1_pd;
        let abs_mask = _mm256_castsi256_pd(_mm256_set1_epi64x(i64::MAX));
        let ax = _mm256_and_pd(x, abs_mask);
        // Ordered comparisons: a NaN lane fails both.
        let in_range = _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_GE_OQ>(ax, v(below(0x3e46a09e))),
            _mm256_cmp_pd::<_CMP_LT_OQ>(ax, v(below(0x413921fb))),
        );
        if _mm256_movemask_pd(in_range) != 0b1111 {
            return false;
        }
        let lt = |bound: u64| _mm256_cmp_pd::<_CMP_LT_OQ>(ax, v(below(bound)));
        let high_word_is = |h: u64| _mm256_andnot_pd(lt(h), lt(h + 1));
        let small = lt(0x3fe921fc);
        // The multiple of π/2 libm subtracts up to 9π/4, by the high word (1 where `small`,
        // which takes neither reduction).
        let k = _mm256_blendv_pd(
            _mm256_blendv_pd(v(4.0), v(3.0), lt(0x4015fdbd)),
            _mm256_blendv_pd(v(2.0), v(1.0), lt(0x4002d97d)),
            lt(0x400f6a7b),
        );
        let cancelling = _mm256_or_pd(
            _mm256_or_pd(high_word_is(0x3ff921fb), high_word_is(0x400921fb)),
            _mm256_or_pd(high_word_is(0x4012d97c), high_word_is(0x401921fb)),
        );
        let all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
        let medium = _mm256_or_pd(_mm256_andnot_pd(lt(0x401c463c), all), cancelling);
        // ±k with x's sign; rint(x · 2/π) on the medium lanes.
        let sign = _mm256_and_pd(x, v(-0.0));
        let k_signed = _mm256_or_pd(k, sign);
        let rounded = _mm256_sub_pd(
            _mm256_add_pd(_mm256_mul_pd(x, v(INV_PIO2)), v(TO_INT)),
            v(TO_INT),
        );
        let f_n = _mm256_blendv_pd(k_signed, rounded, medium);
        // First round.
        let mut r = _mm256_sub_pd(x, _mm256_mul_pd(f_n, v(PIO2_1)));
        let mut w = _mm256_mul_pd(f_n, v(PIO2_1T));
        let mut y0 = _mm256_sub_pd(r, w);
        // 2^e_x: |x| with its mantissa cleared.
        let exp_x = _mm256_and_pd(ax, _mm256_castsi256_pd(_mm256_set1_epi64x(0x7ff0 << 48)));
        let lost = |y: __m256d, bits: f64| {
            _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_and_pd(y, abs_mask), _mm256_mul_pd(exp_x, v(bits)))
        };
        // Second round where the first lost more than 16 bits (medium lanes only).
        let second = _mm256_and_pd(medium, lost(y0, 1.0 / 65536.0));
        if _mm256_movemask_pd(second) != 0 {
            let t = r;
            let w2 = _mm256_mul_pd(f_n, v(PIO2_2));
            let r2 = _mm256_sub_pd(t, w2);
            let w2 = _mm256_sub_pd(
                _mm256_mul_pd(f_n, v(PIO2_2T)),
                _mm256_sub_pd(_mm256_sub_pd(t, r2), w2),
            );
            let y02 = _mm256_sub_pd(r2, w2);
            // Third round where the second still left more than 49 bits lost.
            let third = _mm256_and_pd(second, lost(y02, 1.0 / 562_949_953_421_312.0));
            let (mut r3, mut w3, mut y03) = (r2, w2, y02);
            if _mm256_movemask_pd(third) != 0 {
                let t = r2;
                let w = _mm256_mul_pd(f_n, v(PIO2_3));
                r3 = _mm256_sub_pd(t, w);
                w3 = _mm256_sub_pd(
                    _mm256_mul_pd(f_n, v(PIO2_3T)),
                    _mm256_sub_pd(_mm256_sub_pd(t, r3), w),
                );
                y03 = _mm256_sub_pd(r3, w3);
                r3 = _mm256_blendv_pd(r2, r3, third);
                w3 = _mm256_blendv_pd(w2, w3, third);
                y03 = _mm256_blendv_pd(y02, y03, third);
            }
            r = _mm256_blendv_pd(r, r3, second);
            w = _mm256_blendv_pd(w, w3, second);
            y0 = _mm256_blendv_pd(y0, y03, second);
        }
        let y1 = _mm256_sub_pd(_mm256_sub_pd(r, y0), w);
        // Unreduced lanes: y0 = x, y1 = 0, quadrant 0.
        let y0 = _mm256_blendv_pd(y0, x, small);
        let y1 = _mm256_blendv_pd(y1, _mm256_setzero_pd(), small);
        let f_n = _mm256_blendv_pd(f_n, _mm256_setzero_pd(), small);

        // k_sin(y0, y1, iy): iy = 0 on the unreduced lanes.
        let z = _mm256_mul_pd(y0, y0);
        let zw = _mm256_mul_pd(z, z);
        let rs = _mm256_add_pd(
            _mm256_add_pd(
                v(S2),
                _mm256_mul_pd(z, _mm256_add_pd(v(S3), _mm256_mul_pd(z, v(S4)))),
            ),
            _mm256_mul_pd(
                _mm256_mul_pd(z, zw),
                _mm256_add_pd(v(S5), _mm256_mul_pd(z, v(S6))),
            ),
        );
        let vz = _mm256_mul_pd(z, y0);
        let sin_unreduced = _mm256_add_pd(
            y0,
            _mm256_mul_pd(vz, _mm256_add_pd(v(S1), _mm256_mul_pd(z, rs))),
        );
        let sin_reduced = _mm256_sub_pd(
            y0,
            _mm256_sub_pd(
                _mm256_sub_pd(
                    _mm256_mul_pd(
                        z,
                        _mm256_sub_pd(_mm256_mul_pd(v(0.5), y1), _mm256_mul_pd(vz, rs)),
                    ),
                    y1,
                ),
                _mm256_mul_pd(vz, v(S1)),
            ),
        );
        let sn = _mm256_blendv_pd(sin_reduced, sin_unreduced, small);
        // k_cos(y0, y1).
        let rc = _mm256_add_pd(
            _mm256_mul_pd(
                z,
                _mm256_add_pd(
                    v(C1),
                    _mm256_mul_pd(z, _mm256_add_pd(v(C2), _mm256_mul_pd(z, v(C3)))),
                ),
            ),
            _mm256_mul_pd(
                _mm256_mul_pd(zw, zw),
                _mm256_add_pd(
                    v(C4),
                    _mm256_mul_pd(z, _mm256_add_pd(v(C5), _mm256_mul_pd(z, v(C6)))),
                ),
            ),
        );
        let hz = _mm256_mul_pd(v(0.5), z);
        let wc = _mm256_sub_pd(v(1.0), hz);
        let cs = _mm256_add_pd(
            wc,
            _mm256_add_pd(
                _mm256_sub_pd(_mm256_sub_pd(v(1.0), wc), hz),
                _mm256_sub_pd(_mm256_mul_pd(z, rc), _mm256_mul_pd(y0, y1)),
            ),
        );
        let mut sv = [0.0; 4];
        let mut cv = [0.0; 4];
        let mut nv = [0.0; 4];
        // SAFETY: the arrays hold four elements each.
        unsafe {
            _mm256_storeu_pd(sv.as_mut_ptr(), sn);
            _mm256_storeu_pd(cv.as_mut_ptr(), cs);
            _mm256_storeu_pd(nv.as_mut_ptr(), f_n);
        }
        for lane in 0..4 {
            // f_n is an integer below 2^20 in magnitude: `as i32` is exact, as in libm.
            let (sl, cl) = (sv[lane], cv[lane]);
            let (a, b) = match (nv[lane] as i32) & 3 {
                0 => (sl, cl),
                1 => (cl, -sl),
                2 => (-sl, -cl),
                _ => (-cl, sl),
            };
            // SAFETY: `s` and `c` point at four writable elements (this function's contract).
            unsafe {
                *s.add(lane) = a;
                *c.add(lane) = b;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::sincos_many;

    use crate::sincos::tests::{next, same};

    fn check(args: &[f64]) {
        let mut s = vec![0.0; args.len()];
        let mut c = vec![0.0; args.len()];
        sincos_many(args, &mut s, &mut c);
        for (k, &x) in args.iter().enumerate() {
            let (ws, wc) = libm::sincos(x);
            assert!(
                same(s[k], ws) && same(c[k], wc),
                "x = {x:e} ({:#018x}): got ({:e}, {:e}), libm ({ws:e}, {wc:e})",
                x.to_bits(),
                s[k],
                c[k]
            );
        }
    }

    /// Every branch of libm's reduction, lane by lane: arguments spread log-uniformly over
    /// 10^-9 … 10^7 (both signs), uniformly over ±40 (a spinning chain's angles), within a few
    /// ulps of every high-word threshold libm tests and of the multiples k·π/2 up to 2^20
    /// (where the first round cancels and the second and third run), random bit patterns and
    /// the special values, shuffled into groups of four so that lanes of one group take
    /// different branches.
    #[test]
    fn many_sines_and_cosines_have_libms_bits() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let unit = |st: &mut u64| (next(st) >> 11) as f64 / (1u64 << 53) as f64;
        let mut args: Vec<f64> = Vec::new();
        for _ in 0..200_000 {
            let m = libm::pow(10.0, -9.0 + 16.0 * unit(&mut state));
            args.push(if next(&mut state) & 1 == 0 { m } else { -m });
        }
        for _ in 0..200_000 {
            args.push((unit(&mut state) - 0.5) * 80.0);
        }
        let thresholds: [u64; 14] = [
            0x3e46a09e, 0x3fe921fb, 0x3ff921fb, 0x4002d97c, 0x400921fb, 0x400f6a7a, 0x4012d97c,
            0x4015fdbc, 0x401921fb, 0x401c463b, 0x413921fb, 0x00100000, 0x7fefffff, 0x7ff00000,
        ];
        for &h in &thresholds {
            for edge in [h << 32, (h + 1) << 32] {
                for d in -40i64..40 {
                    let b = (edge as i64 + d) as u64;
                    args.push(f64::from_bits(b));
                    args.push(-f64::from_bits(b));
                }
            }
        }
        // Near multiples of π/2: where y0 is small and the later rounds run.
        for j in 1..2000i64 {
            let k = if j < 1000 { j } else { (j - 999) * 1049 };
            let m = k as f64 * std::f64::consts::FRAC_PI_2;
            for d in -6i64..=6 {
                let x = f64::from_bits((m.to_bits() as i64 + d) as u64);
                args.extend([x, -x]);
            }
        }
        // The doubles nearest to k·π/2 closest to it relative to their size (k < 2^20, found
        // with 110 digits of π): within 2^-72, the reduction's second round is not enough.
        for bits in [
            0x41139c6fd67805a7u64,
            0x41239c6fd67805a7,
            0x41339c6fd67805a7,
            0x412a9adcc7f96cf0,
            0x41193c05c9ed3cbc,
            0x41293c05c9ed3cbc,
            0x4132ed045771ed8d,
            0x41344bdb557e1dc1,
            0x411edb9bbd6273d1,
            0x412edb9bbd6273d1,
            0x41388c9a4ae724a2,
            0x41223d98d86bd573,
        ] {
            for d in -2i64..=2 {
                let x = f64::from_bits((bits as i64 + d) as u64);
                args.extend([x, -x]);
            }
        }
        args.extend((0..50_000).map(|_| f64::from_bits(next(&mut state))));
        args.extend([
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            f64::from_bits(1),
            f64::MAX,
            f64::MIN,
            1e22,
            std::f64::consts::FRAC_PI_4,
            6381956970095103.0 * 2f64.powi(797), // libm's hardest case for the reduction
        ]);
        // Shuffle (Fisher–Yates) so that each group of four mixes branches.
        for i in (1..args.len()).rev() {
            let j = (next(&mut state) % (i as u64 + 1)) as usize;
            args.swap(i, j);
        }
        check(&args);
        // Slices of every length up to 9 (the remainder after the groups of four), at
        // several offsets.
        for len in 0..10 {
            for start in 0..5 {
                check(&args[start..start + len]);
            }
        }
    }

    /// A program with its input sines and cosines hoisted, given `sincos_many`'s values,
    /// computes the original program's bits: a chain's link numbers (sines and cosines of
    /// inputs, read by several instructions and as outputs themselves), a sine of a computed
    /// value (not hoisted), a lone cosine of an input (not fused, not hoisted) and a constant.
    #[test]
    fn a_program_with_hoisted_sines_and_cosines_keeps_its_bits() {
        use crate::{Id, Pool, Program};
        let mut p = Pool::new();
        let n = 7;
        let mut inputs: Vec<Id> = (1..=n).map(|i| p.var(&format!("q{i}"))).collect();
        inputs.extend([p.var("u"), p.var("w")]);
        let mut outs: Vec<Id> = Vec::new();
        for i in 1..=n {
            let e = format!("{i}.5*sin(q{i})*u - cos(q{i})*w + sin(q{i})*cos(q{i})");
            outs.push(p.parse_scalar(&e).unwrap());
            outs.push(p.parse_scalar(&format!("cos(q{i})")).unwrap());
        }
        outs.push(p.parse_scalar("sin(u*w) + cos(w) + 2.25").unwrap());
        let plain = Program::compile(&mut p, &inputs, &outs).unwrap();
        let (hoisted, angles) = super::hoist_input_sincos(plain.clone());
        assert_eq!(angles, (0..n as u32).collect::<Vec<_>>());
        assert_eq!(hoisted.n_inputs(), inputs.len() + 2 * n);
        assert_eq!(hoisted.len(), plain.len() - 2 * n);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let (mut o1, mut o2) = (vec![0.0; outs.len()], vec![0.0; outs.len()]);
        for _ in 0..500 {
            let x: Vec<f64> = (0..n + 2)
                .map(|_| ((next(&mut state) >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 60.0)
                .collect();
            plain.eval(&x, &mut plain.workspace(), &mut o1);
            let mut ext = x.clone();
            ext.resize(x.len() + 2 * n, 0.0);
            let a: Vec<f64> = angles.iter().map(|&r| x[r as usize]).collect();
            let (head, tail) = ext.split_at_mut(x.len());
            let _ = head;
            let (sn, cs) = tail.split_at_mut(n);
            super::sincos_many(&a, sn, cs);
            hoisted.eval(&ext, &mut hoisted.workspace(), &mut o2);
            for (a, b) in o1.iter().zip(&o2) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
        }
    }

    /// The groups of four that run in the vector lanes (no lane outside the range it
    /// handles) are most of a chain's: the fast path is taken, not only the fallback.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn a_chains_angles_take_the_vector_lanes() {
        if !std::arch::is_x86_feature_detected!("avx") {
            return;
        }
        let x: Vec<f64> = (1..=100).map(|i| 0.3 * i as f64 - 12.0).collect();
        let (mut s, mut c) = (vec![0.0; 4], vec![0.0; 4]);
        for g in x.chunks_exact(4) {
            // SAFETY: AVX is present (checked), four elements each.
            let vector = unsafe {
                use std::arch::x86_64::_mm256_loadu_pd;
                avx_four_for_tests(_mm256_loadu_pd(g.as_ptr()), &mut s, &mut c)
            };
            let has_zero = g.iter().any(|&a| a.abs() < 1e-8);
            assert_eq!(vector, !has_zero, "{g:?}");
        }
        check(&x);
    }

    /// The vector kernel on four lanes, for the test that it is the path taken.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn avx_four_for_tests(
        x: std::arch::x86_64::__m256d,
        s: &mut [f64],
        c: &mut [f64],
    ) -> bool {
        // SAFETY: the caller checked AVX; `s` and `c` hold four elements (asserted).
        assert!(s.len() >= 4 && c.len() >= 4);
        unsafe { super::avx::four(x, s.as_mut_ptr(), c.as_mut_ptr()) }
    }
}
