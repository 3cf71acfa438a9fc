//! Programs whose parameter-only work is done once per parameter change, not per evaluation.
//!
//! A right-hand side is evaluated thousands of times with the same parameters: the 100-link
//! chain's mass sums `m_k + … + m_100` (5,000 additions) and products of lengths and masses
//! `l_j*l_k*(m_k + … + m_100)` cost as much at every call as the state-dependent work they
//! multiply. [`HoistedProgram::compile`] splits the instructions of a [`Program`] into a
//! *prelude*, which reads only constants and the invariant inputs (the parameters), and the
//! *main* program, which reads the prelude's results as extra inputs. Products are lowered
//! as (variant factors) × (invariant factors), so their invariant part is one prelude value
//! (`Compiler::product_hoisting`).
//!
//! [`HoistedInputs`] runs the prelude again only when an invariant input has changed (bits
//! compared), so callers that change parameters between runs (sweeps, `--set`) need no
//! notification, and the main program is an ordinary [`Program`] for the interpreter or the
//! JIT alike.

use crate::compile::{CompileError, Compiler, Instr, Program, CONST_BASE, TEMP_BASE};
use crate::pool::{Id, Pool};

/// A program split into its parameter-only prelude and its main part; see the module
/// documentation.
#[derive(Clone, Debug)]
pub struct HoistedProgram {
    /// Inputs `inputs` (all of them; it reads only the invariant ones) → the hoisted values.
    prelude: Program,
    /// Inputs `[inputs | hoisted values]` → the outputs.
    main: Program,
    n_inputs: usize,
    first_invariant: usize,
}

impl HoistedProgram {
    /// Compiles `outputs` over `inputs`, of which `inputs[first_invariant..]` keep their
    /// values from one evaluation to the next.
    pub fn compile(
        pool: &mut Pool,
        inputs: &[Id],
        first_invariant: usize,
        outputs: &[Id],
    ) -> Result<HoistedProgram, CompileError> {
        let hoist = first_invariant < inputs.len();
        let mut c = Compiler::new(pool, inputs, first_invariant, hoist);
        let mut outs = Vec::with_capacity(outputs.len());
        for &o in outputs {
            outs.push(c.value(o)?);
        }
        let n_in = inputs.len() as u32;
        let n_consts = c.consts.len() as u32;
        let n_temps = c.instrs.len();

        // Instructions whose values no output needs are dropped: lowering a sum as
        // `C·Σ v_i` leaves its terms' products `C·v_i` unread.
        let mut live = vec![false; n_temps];
        let mark = |r: u32, live: &mut Vec<bool>| {
            if r >= TEMP_BASE {
                live[(r - TEMP_BASE) as usize] = true;
            }
        };
        for &o in &outs {
            mark(o, &mut live);
        }
        for k in (0..n_temps).rev() {
            if live[k] {
                let ins = &c.instrs[k];
                mark(ins.a(), &mut live);
                if ins.op().reads_b() {
                    mark(ins.b(), &mut live);
                }
            }
        }
        // Prelude temporaries, numbered in order; main temporaries likewise.
        let mut index = vec![0u32; n_temps];
        let (mut n_pre, mut n_main) = (0u32, 0u32);
        for (k, &inv) in c.invariant.iter().enumerate() {
            if !live[k] {
                continue;
            }
            if inv {
                index[k] = n_pre;
                n_pre += 1;
            } else {
                index[k] = n_main;
                n_main += 1;
            }
        }
        // The prelude values the main program reads (as inputs `n_in + h`), in order of
        // first use.
        let mut hoisted: Vec<u32> = Vec::new();
        let mut slot = vec![u32::MAX; n_temps];
        let mut need = |r: u32, slot: &mut Vec<u32>| {
            if r >= TEMP_BASE {
                let k = (r - TEMP_BASE) as usize;
                if c.invariant[k] && slot[k] == u32::MAX {
                    slot[k] = hoisted.len() as u32;
                    hoisted.push(r);
                }
            }
        };
        for (k, ins) in c.instrs.iter().enumerate() {
            if live[k] && !c.invariant[k] {
                need(ins.a(), &mut slot);
                if ins.op().reads_b() {
                    need(ins.b(), &mut slot);
                }
            }
        }
        for &o in &outs {
            need(o, &mut slot);
        }
        let n_hoisted = hoisted.len() as u32;

        let pre_remap = |r: u32| -> u32 {
            if r >= TEMP_BASE {
                n_in + n_consts + index[(r - TEMP_BASE) as usize]
            } else if r >= CONST_BASE {
                n_in + (r - CONST_BASE)
            } else {
                r
            }
        };
        let main_base = n_in + n_hoisted;
        let main_remap = |r: u32| -> u32 {
            if r >= TEMP_BASE {
                let k = (r - TEMP_BASE) as usize;
                if c.invariant[k] {
                    n_in + slot[k]
                } else {
                    main_base + n_consts + index[k]
                }
            } else if r >= CONST_BASE {
                main_base + (r - CONST_BASE)
            } else {
                r
            }
        };
        let remap_instr = |ins: &Instr, f: &dyn Fn(u32) -> u32| {
            let b = if ins.op().b_is_immediate() {
                ins.b()
            } else if ins.op().reads_b() {
                f(ins.b())
            } else {
                0
            };
            Instr::new(ins.op(), f(ins.a()), b)
        };
        let kept = |prelude: bool| {
            c.instrs
                .iter()
                .zip(&c.invariant)
                .zip(&live)
                .filter(move |((_, &inv), &l)| l && inv == prelude)
                .map(|((ins, _), _)| ins)
        };
        let pre_instrs = kept(true).map(|i| remap_instr(i, &pre_remap)).collect();
        let main_instrs = kept(false).map(|i| remap_instr(i, &main_remap)).collect();
        let tables: std::sync::Arc<[crate::compile::TableCall]> =
            c.table_calls.iter().map(|(_, call)| call.clone()).collect();
        let prelude = Program::from_parts(
            n_in as usize,
            c.consts.clone(),
            pre_instrs,
            hoisted.iter().map(|&r| pre_remap(r)).collect(),
            tables.clone(),
        );
        let main = Program::from_parts(
            main_base as usize,
            c.consts,
            main_instrs,
            outs.iter().map(|&r| main_remap(r)).collect(),
            tables,
        );
        Ok(HoistedProgram {
            prelude,
            main,
            n_inputs: n_in as usize,
            first_invariant: first_invariant.min(inputs.len()),
        })
    }

    /// The parameter-only part: inputs as [`HoistedProgram::n_inputs`], outputs the hoisted
    /// values.
    pub fn prelude(&self) -> &Program {
        &self.prelude
    }

    /// The per-evaluation part: inputs `[inputs | hoisted values]`.
    pub fn main(&self) -> &Program {
        &self.main
    }

    /// Number of inputs the caller provides.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.main.n_outputs()
    }

    /// Total instructions, prelude and main.
    pub fn len(&self) -> usize {
        self.prelude.len() + self.main.len()
    }

    /// True when neither part has an instruction.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The main program's input vector for one evaluator, with the hoisted values kept up to
/// date; see the module documentation. Allocation-free after construction.
#[derive(Clone, Debug)]
pub struct HoistedInputs {
    /// `[inputs | hoisted values]`.
    extended: Vec<f64>,
    prelude_ws: Vec<f64>,
    /// Whether `extended`'s hoisted values belong to its invariant inputs.
    valid: bool,
}

impl HoistedInputs {
    /// Buffers for `h`; the prelude runs at the first [`HoistedInputs::update`].
    pub fn new(h: &HoistedProgram) -> HoistedInputs {
        HoistedInputs {
            extended: vec![0.0; h.main.n_inputs()],
            prelude_ws: h.prelude.workspace(),
            valid: false,
        }
    }

    /// The main program's inputs for `inputs` (length [`HoistedProgram::n_inputs`]): copies
    /// them, and computes the hoisted values again when an invariant input differs, bit for
    /// bit, from the previous call's (NaN parameters included: their bits are compared).
    ///
    /// # Panics
    /// If `inputs` is shorter than [`HoistedProgram::n_inputs`] (a programming error, as for
    /// [`Program::eval`]; the callers build the input vector from the same leaves).
    #[inline]
    pub fn update(&mut self, h: &HoistedProgram, inputs: &[f64]) -> &[f64] {
        let (n, k) = (h.n_inputs, h.first_invariant);
        let same = self.valid
            && self.extended[k..n]
                .iter()
                .zip(&inputs[k..n])
                .all(|(a, b)| a.to_bits() == b.to_bits());
        self.extended[..n].copy_from_slice(&inputs[..n]);
        if !same {
            let (given, hoisted) = self.extended.split_at_mut(n);
            h.prelude.eval(given, &mut self.prelude_ws, hoisted);
            self.valid = true;
        }
        &self.extended
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hoisted program computes what the plain one does (products reordered, so to
    /// rounding), recomputes its hoisted values when a parameter changes and not otherwise,
    /// and moves the parameter-only work out of the main program.
    #[test]
    fn hoisted_values_follow_the_parameters() {
        let mut p = Pool::new();
        let mut inputs = vec![p.time()];
        inputs.extend(["x", "v", "m1", "m2", "l"].iter().map(|n| p.var(n)));
        let srcs = [
            "(m1 + m2)*l^2*cos(x)*v^2 + m2*l*sin(x)",
            "(m1 + m2)*l^2*sin(x) - t*m1",
            "m1*m2",
            "x",
        ];
        let outs: Vec<Id> = srcs.iter().map(|s| p.parse_scalar(s).unwrap()).collect();
        let plain = Program::compile(&mut p, &inputs, &outs).unwrap();
        let h = HoistedProgram::compile(&mut p, &inputs, 3, &outs).unwrap();
        // (m1 + m2)*l^2, m2*l and m1*m2 are hoisted: the main program has no addition of
        // masses and fewer instructions.
        assert!(h.prelude().len() >= 4, "{}", h.prelude().len());
        assert!(
            h.main().len() < plain.len(),
            "{} vs {}",
            h.main().len(),
            plain.len()
        );
        // No main instruction reads only parameters, hoisted values and constants.
        let main = h.main();
        let invariant = |r: u32| r >= 3 && (r as usize) < main.first_temporary();
        let mut temps_variant = true;
        for ins in main.instructions() {
            let b_inv = !ins.op().reads_b() || invariant(ins.b());
            temps_variant &= !(invariant(ins.a()) && b_inv);
        }
        assert!(temps_variant);
        let mut hi = HoistedInputs::new(&h);
        let mut ws = h.main().workspace();
        let mut pws = plain.workspace();
        let (mut o1, mut o2) = (vec![0.0; 4], vec![0.0; 4]);
        for (k, params) in [[1.0, 2.0, 0.5], [1.0, 2.0, 0.5], [3.0, 0.25, 2.0]]
            .iter()
            .enumerate()
        {
            for step in 0..3 {
                let s = step as f64 * 0.7 + k as f64;
                let input = [s, 0.3 * s, 1.0 - s, params[0], params[1], params[2]];
                plain.eval(&input, &mut pws, &mut o1);
                let ext = hi.update(&h, &input);
                h.main().eval(ext, &mut ws, &mut o2);
                for (a, b) in o1.iter().zip(&o2) {
                    assert!(
                        (a - b).abs() <= 1e-14 * a.abs().max(1.0),
                        "{o1:?} vs {o2:?}"
                    );
                }
            }
        }
    }
}
