//! Sine and cosine of one argument as one operation.
//!
//! A rotation brings `sin(q)` and `cos(q)` together: every link of a pendulum chain needs both
//! of its angle at every evaluation. Computed apart, each reduces `q` modulo `π/2`
//! (`rem_pio2`) and evaluates its kernel polynomial; `libm::sincos` reduces once and
//! evaluates both kernels, with the bits of `libm::sin` and `libm::cos` (the same reduction
//! and kernels, tested in `tests::sincos_gives_the_bits_of_sin_and_cos`). Two calls cost
//! 37 ns, one `sincos` 22 ns (|x| < 12, this machine), and they were 29 % of the 100-link
//! chain's run.
//!
//! [`fuse_sin_cos`] rewrites a finished instruction list: a `Sin` and a `Cos` of the same
//! register become [`Op::SinCos`] (the sine) immediately followed by [`Op::CosOfSinCos`] (the
//! cosine), at the place of the earlier of the two. The later one only moves up: its operand
//! is the earlier one's, already computed there, so the order stays topological.

use crate::compile::{Instr, Op};
use rustc_hash::FxHashMap;

/// `instrs` with every `Sin`, `Cos` pair of one operand fused (see the module documentation),
/// and the registers of the instructions and of `outputs` renumbered to the new order.
/// Temporaries start at register `first_temp`: instruction `k` writes `first_temp + k`.
pub(crate) fn fuse_sin_cos(first_temp: u32, instrs: Vec<Instr>, outputs: &mut [u32]) -> Vec<Instr> {
    // The first sine and the first cosine of each operand (a program has one of each per
    // operand: its nodes are hash-consed).
    let mut sine: FxHashMap<u32, usize> = FxHashMap::default();
    let mut cosine: FxHashMap<u32, usize> = FxHashMap::default();
    for (k, ins) in instrs.iter().enumerate() {
        match ins.op() {
            Op::Sin => sine.entry(ins.a()).or_insert(k),
            Op::Cos => cosine.entry(ins.a()).or_insert(k),
            _ => continue,
        };
    }
    const NONE: usize = usize::MAX;
    let mut partner = vec![NONE; instrs.len()];
    let mut pairs = 0;
    for (a, &s) in &sine {
        if let Some(&c) = cosine.get(a) {
            partner[s] = c;
            partner[c] = s;
            pairs += 1;
        }
    }
    if pairs == 0 {
        return instrs;
    }
    // Old index → new index; the new list as (old index, operation).
    let mut moved = vec![0u32; instrs.len()];
    let mut order: Vec<(usize, Op)> = Vec::with_capacity(instrs.len());
    for (k, ins) in instrs.iter().enumerate() {
        let other = partner[k];
        if other == NONE {
            moved[k] = order.len() as u32;
            order.push((k, ins.op()));
        } else if other > k {
            let (s, c) = if ins.op() == Op::Sin {
                (k, other)
            } else {
                (other, k)
            };
            moved[s] = order.len() as u32;
            order.push((s, Op::SinCos));
            moved[c] = order.len() as u32;
            order.push((c, Op::CosOfSinCos));
        }
        // else: the later of a pair, placed with the earlier one.
    }
    let renumber = |r: u32| {
        if r >= first_temp {
            first_temp + moved[(r - first_temp) as usize]
        } else {
            r
        }
    };
    for o in outputs.iter_mut() {
        *o = renumber(*o);
    }
    order
        .into_iter()
        .map(|(k, op)| {
            let ins = &instrs[k];
            let b = if ins.op().reads_b() {
                renumber(ins.b())
            } else {
                ins.b()
            };
            Instr::new(op, renumber(ins.a()), b)
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::compile::{Op, Program};
    use crate::hoist::{HoistedInputs, HoistedProgram};
    use crate::{Id, Pool};

    /// xorshift64: a seeded stream of 64-bit words.
    pub(crate) fn next(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    pub(crate) fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// What makes the fusion exact: `libm::sincos` gives `libm::sin`'s and `libm::cos`'s bits,
    /// on 10^5 seeded arguments with |x| spread log-uniformly over 10^-3 … 10^6 (both signs),
    /// on random bit patterns (every binade, subnormals, NaNs) and on the special values.
    #[test]
    fn sincos_gives_the_bits_of_sin_and_cos() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut args: Vec<f64> = (0..100_000)
            .map(|_| {
                let u = (next(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
                let magnitude = libm::pow(10.0, -3.0 + 9.0 * u);
                if next(&mut state) & 1 == 0 {
                    magnitude
                } else {
                    -magnitude
                }
            })
            .collect();
        args.extend((0..20_000).map(|_| f64::from_bits(next(&mut state))));
        args.extend([
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 2.0,
            -f64::MIN_POSITIVE / 3.0,
            f64::from_bits(1),
            -f64::from_bits(1),
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            1e-8,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            1e22,
        ]);
        for x in args {
            let (s, c) = libm::sincos(x);
            assert!(
                same(s, libm::sin(x)) && same(c, libm::cos(x)),
                "x = {x:e} ({:#x}): sincos ({s:e}, {c:e}), sin {:e}, cos {:e}",
                x.to_bits(),
                libm::sin(x),
                libm::cos(x)
            );
        }
    }

    fn count(prog: &Program, op: Op) -> usize {
        prog.instructions().iter().filter(|i| i.op() == op).count()
    }

    /// A chain's positions: `l_i sin(q_i)` and `-l_i cos(q_i)`, the sines of all links first
    /// (so each cosine moves up to its sine), and a lone sine and a lone cosine that stay as
    /// they are. Values: the closed form with `libm::sin` and `libm::cos`, bit for bit.
    #[test]
    fn a_sine_and_a_cosine_of_one_argument_are_one_operation() {
        let mut p = Pool::new();
        let n = 6;
        let mut inputs: Vec<Id> = (1..=n).map(|i| p.var(&format!("q{i}"))).collect();
        inputs.extend([p.var("u"), p.var("w")]);
        let mut outs: Vec<Id> = (1..=n)
            .map(|i| p.parse_scalar(&format!("{i}*sin(q{i})")).unwrap())
            .collect();
        outs.extend((1..=n).map(|i| p.parse_scalar(&format!("-{i}*cos(q{i})")).unwrap()));
        outs.push(p.parse_scalar("sin(u) + cos(w)").unwrap());
        // The cosine's value as an output of its own, and read by a later instruction.
        outs.push(p.parse_scalar("cos(q3)").unwrap());
        outs.push(p.parse_scalar("cos(q3)*u").unwrap());
        let prog = Program::compile(&mut p, &inputs, &outs).unwrap();
        assert_eq!(count(&prog, Op::SinCos), n);
        assert_eq!(count(&prog, Op::CosOfSinCos), n);
        assert_eq!((count(&prog, Op::Sin), count(&prog, Op::Cos)), (1, 1));
        let ins = prog.instructions();
        for (k, i) in ins.iter().enumerate() {
            if i.op() == Op::SinCos {
                assert_eq!(ins[k + 1].op(), Op::CosOfSinCos);
                assert_eq!(ins[k + 1].a(), i.a());
            }
        }
        // Every operand is computed before it is read.
        let first = prog.first_temporary() as u32;
        for (k, i) in ins.iter().enumerate() {
            assert!(i.a() < first + k as u32);
            assert!(!i.op().reads_b() || i.b() < first + k as u32);
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut out = vec![0.0; outs.len()];
        let mut ws = prog.workspace();
        for _ in 0..200 {
            let x: Vec<f64> = (0..n + 2)
                .map(|_| ((next(&mut state) >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 40.0)
                .collect();
            prog.eval(&x, &mut ws, &mut out);
            for i in 0..n {
                let l = (i + 1) as f64;
                assert_eq!(out[i].to_bits(), (l * libm::sin(x[i])).to_bits());
                assert_eq!(out[n + i].to_bits(), (-l * libm::cos(x[i])).to_bits());
            }
            let lone = libm::sin(x[n]) + libm::cos(x[n + 1]);
            assert_eq!(out[2 * n].to_bits(), lone.to_bits());
            assert_eq!(out[2 * n + 1].to_bits(), libm::cos(x[2]).to_bits());
            assert_eq!(out[2 * n + 2].to_bits(), (libm::cos(x[2]) * x[n]).to_bits());
        }
    }

    /// The hoisted programs are fused too, in the prelude (a parameter's angle) and in the
    /// main part, with the plain program's bits.
    #[test]
    fn hoisted_programs_are_fused() {
        let mut p = Pool::new();
        let inputs = [p.var("q"), p.var("alpha")];
        let outs: Vec<Id> = [
            "sin(q)*cos(alpha) + cos(q)*sin(alpha)",
            "cos(q) - sin(alpha)",
        ]
        .iter()
        .map(|s| p.parse_scalar(s).unwrap())
        .collect();
        let h = HoistedProgram::compile(&mut p, &inputs, 1, &outs).unwrap();
        assert_eq!(count(h.prelude(), Op::SinCos), 1);
        assert_eq!(count(h.main(), Op::SinCos), 1);
        let plain = Program::compile(&mut p, &inputs, &outs).unwrap();
        let mut hi = HoistedInputs::new(&h);
        let (mut o1, mut o2) = ([0.0; 2], [0.0; 2]);
        for x in [[0.3, 1.2], [-7.5, 0.01], [1e5, -3.0]] {
            plain.eval(&x, &mut plain.workspace(), &mut o1);
            let ext = hi.update(&h, &x);
            h.main().eval(ext, &mut h.main().workspace(), &mut o2);
            let want0 = libm::sin(x[0]) * libm::cos(x[1]) + libm::cos(x[0]) * libm::sin(x[1]);
            assert!((o1[0] - want0).abs() <= 1e-15 * want0.abs().max(1.0));
            assert_eq!(
                o1[1].to_bits(),
                (libm::cos(x[0]) - libm::sin(x[1])).to_bits()
            );
            assert_eq!(o2[1].to_bits(), o1[1].to_bits());
        }
    }
}
