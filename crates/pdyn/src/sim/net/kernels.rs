//! The templates compiled once each and evaluated over their elements: gather the inputs of
//! every element into columns, run the kernel over the columns, scatter-add its outputs into
//! the accelerations (and its derivatives into the Jacobian).
//!
//! Inputs come from the vector `[t, q, q', parameters]` that [`super::super::compiled`]
//! keeps, so that setting parameters needs nothing here: each kernel input is, element by
//! element, an index into that vector (the gather table).

use super::structure::{self, Group, Source, Structure};
use pdyn_expr::compile::CompileError;
use pdyn_expr::{Id, Pool, Program};
use pdyn_jit::{BatchKernel, JitMode};
use std::cell::{OnceCell, RefCell};

/// Templates with fewer elements than this are interpreted (no machine code to generate for a
/// pinned corner's few springs); the others run as native loops.
pub const NATIVE_FROM: usize = 16;

/// "No coordinate" in a scatter table: the component is constant in time.
const NONE: u32 = u32::MAX;

/// One template compiled, and where its elements read and write.
#[derive(Clone)]
struct Kernel {
    /// `F/m` (x, y, z) of an element over its inputs.
    kernel: BatchKernel,
    /// Per input: per element, the index of its value in `[t, q, q', parameters]`.
    gather: Vec<Vec<u32>>,
    /// Per axis: per element, the index of the acceleration it adds to (a free coordinate
    /// in state order), or [`NONE`].
    scatter: [Vec<u32>; 3],
    /// Per element, its own particle (the one the load acts on).
    own: Vec<u32>,
    /// Which components of the template are not identically zero.
    nonzero: [bool; 3],
    /// The derivatives of the outputs by the slot inputs, not identically zero: `(axis,
    /// input)` of each output of `jacobian_program`.
    jacobian_entries: Vec<(u8, u32)>,
    jacobian_program: Program,
    /// Compiled on first use: an explicit method never asks for it.
    jacobian_kernel: OnceCell<Option<BatchKernel>>,
    mode: JitMode,
    elements: usize,
}

/// Column buffers of one evaluation (per kernel the largest needed).
#[derive(Clone, Default)]
struct Columns {
    inputs: Vec<Vec<f64>>,
    outputs: Vec<Vec<f64>>,
}

/// The accelerations of a model of free particles, template by template.
#[derive(Clone)]
pub struct NetKernels {
    kernels: Vec<Kernel>,
    /// Free coordinates.
    n: usize,
    columns: RefCell<Columns>,
    /// Whether every kernel that has elements runs native code.
    native: bool,
    /// Whether a kernel reads a velocity.
    reads_rates: bool,
}

impl NetKernels {
    /// Compiles each group of `structure` (over the inputs `[t, q, q', parameters]` of a model
    /// with `n` free coordinates and these parameter leaves).
    pub fn compile(
        pool: &mut Pool,
        structure: &Structure,
        n: usize,
        parameters: &[Id],
        jit: JitMode,
    ) -> Result<Option<NetKernels>, CompileError> {
        let mut kernels = Vec::with_capacity(structure.groups.len());
        let mut reads_rates = false;
        for g in &structure.groups {
            let (leaves, sources) = structure::template_inputs(
                pool,
                &g.template,
                g.slots,
                &structure.slot_symbols,
                parameters,
            );
            reads_rates |= sources
                .iter()
                .any(|s| matches!(s, Source::Slot { order: 1, .. }));
            let program = Program::compile(pool, &leaves, &g.template)?;
            let elements = g.particles.len() / g.slots;
            let mode = if elements >= NATIVE_FROM {
                jit
            } else {
                JitMode::Off
            };
            let Some(kernel) = BatchKernel::new(&program, mode) else {
                return Ok(None);
            };
            let Some(gather) = gather_table(g, &sources, structure, n) else {
                return Ok(None);
            };
            let scatter = [0, 1, 2].map(|axis| {
                (0..elements)
                    .map(|e| {
                        let own = g.particles[e * g.slots] as usize;
                        structure.axes[own][axis].unwrap_or(NONE)
                    })
                    .collect()
            });
            // ∂(F/m)/∂(slot input), for the implicit methods.
            let mut jacobian_entries = Vec::new();
            let mut derivatives = Vec::new();
            for (axis, &f) in g.template.iter().enumerate() {
                for (k, (&leaf, source)) in leaves.iter().zip(&sources).enumerate() {
                    if !matches!(source, Source::Slot { .. }) {
                        continue;
                    }
                    let d = pool.diff(f, leaf);
                    if d != Pool::ZERO {
                        jacobian_entries.push((axis as u8, k as u32));
                        derivatives.push(d);
                    }
                }
            }
            let jacobian_program = Program::compile(pool, &leaves, &derivatives)?;
            kernels.push(Kernel {
                kernel,
                gather,
                scatter,
                own: (0..elements).map(|e| g.particles[e * g.slots]).collect(),
                nonzero: g.template.map(|c| c != Pool::ZERO),
                jacobian_entries,
                jacobian_program,
                jacobian_kernel: OnceCell::new(),
                mode,
                elements,
            });
        }
        let native = kernels
            .iter()
            .all(|k| k.kernel.is_native() || k.mode == JitMode::Off);
        Ok(Some(NetKernels {
            kernels,
            n,
            columns: RefCell::new(Columns::default()),
            native: native && jit == JitMode::Auto,
            reads_rates,
        }))
    }

    /// Number of compiled templates.
    pub fn len(&self) -> usize {
        self.kernels.len()
    }

    /// True when there are no loads.
    pub fn is_empty(&self) -> bool {
        self.kernels.is_empty()
    }

    /// Operations per evaluation of every kernel over its elements (after each kernel's
    /// rewrite), a deterministic count.
    pub fn operations(&self) -> usize {
        self.kernels
            .iter()
            .map(|k| k.kernel.len() * k.elements)
            .sum()
    }

    /// Whether the large kernels run as native code.
    pub fn is_native(&self) -> bool {
        self.native
    }

    /// Whether an acceleration depends on a velocity.
    pub fn reads_rates(&self) -> bool {
        self.reads_rates
    }

    /// The accelerations `q''` (free coordinates in state order) at `input = [t, q, q',
    /// parameters]`.
    pub fn accelerations(&self, input: &[f64], acc: &mut [f64]) {
        acc[..self.n].iter_mut().for_each(|a| *a = 0.0);
        let cols = &mut *self.columns.borrow_mut();
        for k in &self.kernels {
            if k.elements == 0 {
                continue;
            }
            let outs = run_kernel(k, input, cols);
            for (axis, out) in outs.iter().enumerate() {
                for (&to, &v) in k.scatter[axis].iter().zip(out.iter()) {
                    if to != NONE {
                        acc[to as usize] += v;
                    }
                }
            }
        }
    }

    /// True when no load acts along a particle's component that is constant in time: the
    /// generic derivation then has Newton's equations (one per coordinate) and checks the
    /// momenta; otherwise it projects them, and does not.
    pub fn newton_form(&self) -> bool {
        self.kernels
            .iter()
            .all(|k| (0..3).all(|axis| !k.nonzero[axis] || !k.scatter[axis].contains(&NONE)))
    }

    /// The resultant force `Σ F` and moment about the origin `Σ r × F` of every load at
    /// `input = [t, q, q', parameters]`, each component with the sum of its terms' sizes:
    /// `[(F_x, Σ|F_x|), (F_y, ...), (F_z, ...), (M_x, Σ|y F_z| + |z F_y|), ...]`. `mass` and
    /// `position` are each particle's, numbers.
    pub fn resultants(
        &self,
        input: &[f64],
        mass: &[f64],
        position: &[[f64; 3]],
    ) -> [(f64, f64); 6] {
        let mut out = [(0.0, 0.0); 6];
        let cols = &mut *self.columns.borrow_mut();
        for k in &self.kernels {
            if k.elements == 0 {
                continue;
            }
            let outs = run_kernel(k, input, cols);
            for (e, &own) in k.own.iter().enumerate() {
                let m = mass[own as usize];
                let f = [0, 1, 2].map(|c| m * outs[c][e]);
                let r = position[own as usize];
                let terms = [
                    (r[1] * f[2], r[2] * f[1]),
                    (r[2] * f[0], r[0] * f[2]),
                    (r[0] * f[1], r[1] * f[0]),
                ];
                for (c, (&fc, (a, b))) in f.iter().zip(terms).enumerate() {
                    out[c].0 += fc;
                    out[c].1 += fc.abs();
                    out[3 + c].0 += a - b;
                    out[3 + c].1 += a.abs() + b.abs();
                }
            }
        }
        out
    }

    /// Adds `∂q''/∂w` into rows `n..2n` of the dense Jacobian `jac` (`2n × 2n`, row-major)
    /// of the first-order system, at `input = [t, q, q', parameters]`. The caller zeroes
    /// `jac` and sets the identity block.
    pub fn add_jacobian(&self, input: &[f64], jac: &mut [f64]) {
        let n = self.n;
        let m = 2 * n;
        let cols = &mut *self.columns.borrow_mut();
        for k in &self.kernels {
            if k.elements == 0 || k.jacobian_entries.is_empty() {
                continue;
            }
            let kernel = k
                .jacobian_kernel
                .get_or_init(|| BatchKernel::new(&k.jacobian_program, k.mode));
            let Some(kernel) = kernel else {
                // Cannot happen: the same operations as the kernel's, which compiled.
                jac.iter_mut().for_each(|x| *x = f64::NAN);
                return;
            };
            let outputs = k.jacobian_entries.len();
            gather(k, input, cols, kernel.n_inputs(), outputs);
            let ins: Vec<&[f64]> = cols.inputs[..kernel.n_inputs()]
                .iter()
                .map(|c| &c[..k.elements])
                .collect();
            let mut outs: Vec<&mut [f64]> = cols.outputs[..outputs]
                .iter_mut()
                .map(|c| &mut c[..k.elements])
                .collect();
            kernel.run(&ins, &mut outs);
            for (&(axis, input_k), out) in k.jacobian_entries.iter().zip(&outs) {
                let rows = &k.scatter[axis as usize];
                let from = &k.gather[input_k as usize];
                for ((&row, &at), &value) in rows.iter().zip(from).zip(out.iter()) {
                    if row == NONE {
                        continue;
                    }
                    // The gathered index is 1 + the state index of the input.
                    jac[(n + row as usize) * m + at as usize - 1] += value;
                }
            }
        }
    }
}

/// Fills the first `inputs` input columns of kernel `k` from `input`, and makes room for
/// `outputs` output columns.
/// Runs `k` over its elements at `input`: its three acceleration columns, one value per
/// element.
fn run_kernel<'c>(k: &Kernel, input: &[f64], cols: &'c mut Columns) -> Vec<&'c mut [f64]> {
    gather(k, input, cols, k.kernel.n_inputs(), 3);
    let ins: Vec<&[f64]> = cols.inputs[..k.kernel.n_inputs()]
        .iter()
        .map(|c| &c[..k.elements])
        .collect();
    let mut outs: Vec<&mut [f64]> = cols.outputs[..3]
        .iter_mut()
        .map(|c| &mut c[..k.elements])
        .collect();
    k.kernel.run(&ins, &mut outs);
    outs
}

fn gather(k: &Kernel, input: &[f64], cols: &mut Columns, inputs: usize, outputs: usize) {
    let len = k.elements;
    if cols.inputs.len() < inputs {
        cols.inputs.resize(inputs, Vec::new());
    }
    if cols.outputs.len() < outputs {
        cols.outputs.resize(outputs, Vec::new());
    }
    for c in cols.inputs[..inputs]
        .iter_mut()
        .chain(&mut cols.outputs[..outputs])
    {
        if c.len() < len {
            c.resize(len, 0.0);
        }
    }
    for (col, from) in cols.inputs.iter_mut().zip(&k.gather[..inputs]) {
        for (x, &i) in col.iter_mut().zip(from) {
            *x = input[i as usize];
        }
    }
}

/// Per input of group `g`, per element, the index of its value in `[t, q, q', parameters]`
/// (`n` free coordinates); `None` when an element lacks a coordinate its template reads
/// (cannot happen: equal templates read the same components).
fn gather_table(
    g: &Group,
    sources: &[Source],
    structure: &Structure,
    n: usize,
) -> Option<Vec<Vec<u32>>> {
    let elements = g.particles.len() / g.slots;
    sources
        .iter()
        .map(|s| {
            (0..elements)
                .map(|e| match *s {
                    Source::Slot { slot, axis, order } => {
                        let particle = g.particles[e * g.slots + slot as usize] as usize;
                        let q = structure.axes[particle][axis as usize]?;
                        Some(1 + order as u32 * n as u32 + q)
                    }
                    Source::Parameter(k) => Some(1 + 2 * n as u32 + k),
                    Source::Time => Some(0),
                })
                .collect()
        })
        .collect()
}
