//! The templates compiled once each and evaluated over their elements: gather the inputs of
//! every element into columns, run the kernel over the columns into one buffer of outputs, and
//! sum each acceleration from its terms there (and scatter-add the derivatives into the
//! Jacobian).
//!
//! Inputs come from the vector `[t, q, q', parameters]` that [`super::super::compiled`]
//! keeps, so that setting parameters needs nothing here: each kernel input is, element by
//! element, an index into that vector (the gather table), or one index for every element (a
//! parameter, `t`: its column is refilled only when its value changes).

use super::runs::MIN_MEAN_RUN;
use super::structure::{self, Group, Source, Structure};
use super::sums::Sums;
use pdyn_expr::compile::CompileError;
use pdyn_expr::{Id, Pool, Program};
use pdyn_jit::{BatchKernel, JitMode};
use std::cell::{Cell, OnceCell, RefCell};

/// Templates with fewer elements than this are interpreted (no machine code to generate for a
/// pinned corner's few springs); the others run as native loops.
pub const NATIVE_FROM: usize = 16;

/// Evaluations after which the small templates are compiled too: Cranelift's cost for one
/// (about 0.5–1 M instructions) is that of interpreting its few elements ~500 times, so a
/// short run never pays it and a long one (the 20 × 20 net's 8 s: 17,000 evaluations, 4 %
/// of its time in the interpreter) soon gets it back.
pub const NATIVE_AFTER: u32 = 500;

/// "No coordinate" in a scatter table: the component is constant in time.
const NONE: u32 = u32::MAX;

/// One template compiled, and where its elements read and write.
#[derive(Clone)]
struct Kernel {
    /// The accelerations an element gives (x, y, z of each particle it pushes) over its inputs.
    kernel: BatchKernel,
    /// Per input: where each element's value comes from in `[t, q, q', parameters]`.
    gather: Vec<Gather>,
    /// Per output: per element, the index of the acceleration it adds to (a free coordinate
    /// in state order), or [`NONE`].
    scatter: Vec<Vec<u32>>,
    /// Where its output columns start in [`NetKernels::outputs`] (output `o` of element `e`
    /// at `at + o * elements + e`).
    at: usize,
    /// Per output: which axis of which particle it is, by the particle of each element
    /// (`acts[o / 3][e]`, the particle pushed by the outputs `3 (o / 3) .. 3 (o / 3) + 3`).
    acts: Vec<Vec<u32>>,
    /// Which outputs are not identically zero.
    nonzero: Vec<bool>,
    /// The derivatives of the outputs by the slot inputs, not identically zero: `(output,
    /// input)` of each output of `jacobian_program`.
    jacobian_entries: Vec<(u32, u32)>,
    jacobian_program: Program,
    /// Compiled on first use: an explicit method never asks for it.
    jacobian_kernel: OnceCell<Option<BatchKernel>>,
    mode: JitMode,
    /// A template interpreted for its few elements although native code is allowed: its
    /// program and the mode, compiled after [`NATIVE_AFTER`] evaluations.
    late: Option<Late>,
    /// When they pay, the stretches of elements over which every per-element input steps by
    /// one in the state: the kernel then reads those inputs where they are, nothing gathered.
    stretches: Option<Stretches>,
    elements: usize,
    /// The gathered input columns, kept between evaluations: the columns of parameters are
    /// refilled only when a parameter's value changed.
    columns: RefCell<Columns>,
    /// One more than the largest index of `[t, q, q', parameters]` a broadcast input reads,
    /// and of `[q, q']` a per-element input reads: vectors at least this long are checked
    /// once per gather, not once per value.
    input_len: usize,
    state_len: usize,
}

/// Consecutive elements whose per-element inputs are each consecutive in the state (a family
/// declared over the same indices as the coordinates: `spring[i,j]` reads `x[i,j]` and
/// `x[i+1,j]`, which step with `j`): the kernel runs once per stretch on slices of the
/// state, where gathering would copy each input column value by value.
#[derive(Clone)]
struct Stretches {
    /// `(first element, elements)` of each stretch.
    stretches: Vec<(u32, u32)>,
    /// Per stretch, per input: where the first element's value is, in the state, or (a
    /// broadcast input) in the input's column, at the stretch's first element.
    from: Vec<u32>,
}

impl Stretches {
    /// The stretches of a kernel's `elements` reading by `gather`, when there are per-element
    /// inputs and the stretches are [`MIN_MEAN_RUN`] elements long on average.
    fn new(gather: &[Gather], elements: usize) -> Option<Stretches> {
        let each: Vec<&[u32]> = gather
            .iter()
            .filter_map(|g| match g {
                Gather::Each(from) => Some(from.as_slice()),
                Gather::Broadcast(_) => None,
            })
            .collect();
        if each.is_empty() || each.iter().any(|from| from.len() != elements) {
            return None;
        }
        let mut stretches = Vec::new();
        let mut from = Vec::new();
        let mut first = 0;
        for e in 1..=elements {
            let goes_on =
                e < elements && each.iter().all(|f| f[e - 1].checked_add(1) == Some(f[e]));
            if goes_on {
                continue;
            }
            stretches.push((first as u32, (e - first) as u32));
            from.extend(gather.iter().map(|g| match g {
                Gather::Each(f) => f[first],
                Gather::Broadcast(_) => first as u32,
            }));
            first = e;
        }
        (stretches.len() * MIN_MEAN_RUN <= elements).then_some(Stretches { stretches, from })
    }
}

/// A small template's native code, made once the run has shown itself long.
#[derive(Clone)]
struct Late {
    program: Program,
    mode: JitMode,
    native: OnceCell<Option<BatchKernel>>,
}

/// Where one kernel input comes from, element by element.
#[derive(Clone)]
enum Gather {
    /// Per element, the index of its value in the state `[q, q']` (a coordinate or a rate).
    Each(Vec<u32>),
    /// The same entry for every element (a parameter, `t`).
    Broadcast(u32),
}

impl Gather {
    /// The index in the state `[q, q']` of element `e`'s value, if it is a state's.
    fn state_index(&self, e: usize) -> Option<u32> {
        match self {
            Gather::Each(from) => Some(from[e]),
            Gather::Broadcast(_) => None,
        }
    }
}

/// Column buffers of one kernel.
#[derive(Clone, Default)]
struct Columns {
    inputs: Vec<Vec<f64>>,
    /// The value each broadcast input column holds (NaN bits: not filled yet).
    filled: Vec<u64>,
    jacobian: Vec<Vec<f64>>,
}

/// The accelerations of a model of free particles, template by template.
#[derive(Clone)]
pub struct NetKernels {
    kernels: Vec<Kernel>,
    /// Every kernel's output columns, one after the other.
    outputs: RefCell<Vec<f64>>,
    /// The sum forming each acceleration (a free coordinate in state order) from the
    /// outputs, each sum in a register instead of adding each output into its acceleration in
    /// memory; a particle's three sums together ([`Sums`]).
    sums: Sums,
    /// Free coordinates.
    n: usize,
    /// Whether every kernel that has elements runs native code.
    native: bool,
    /// Whether a kernel reads a velocity.
    reads_rates: bool,
    /// Evaluations of the accelerations so far (up to [`NATIVE_AFTER`]).
    evaluations: Cell<u32>,
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
            let outputs = g.outputs();
            let (leaves, sources) = structure::template_inputs(
                pool,
                &outputs,
                g.slots,
                &structure.slot_symbols,
                parameters,
            );
            reads_rates |= sources
                .iter()
                .any(|s| matches!(s, Source::Slot { order: 1, .. }));
            let program = Program::compile(pool, &leaves, &outputs)?;
            let elements = g.particles.len() / g.slots;
            let (mode, late) = if elements >= NATIVE_FROM || jit == JitMode::Off {
                (jit, None)
            } else {
                let late = Late {
                    program: program.clone(),
                    mode: jit,
                    native: OnceCell::new(),
                };
                (JitMode::Off, Some(late))
            };
            let Some(kernel) = BatchKernel::new(&program, mode) else {
                return Ok(None);
            };
            let Some(gather) = gather_table(g, &sources, structure, n) else {
                return Ok(None);
            };
            let acts: Vec<Vec<u32>> = g
                .acts_on
                .iter()
                .map(|&(slot, _)| {
                    (0..elements)
                        .map(|e| g.particles[e * g.slots + slot as usize])
                        .collect()
                })
                .collect();
            let scatter: Vec<Vec<u32>> = (0..outputs.len())
                .map(|o| {
                    acts[o / 3]
                        .iter()
                        .map(|&p| structure.axes[p as usize][o % 3].unwrap_or(NONE))
                        .collect()
                })
                .collect();
            // ∂(F/m)/∂(slot input), for the implicit methods.
            let mut jacobian_entries = Vec::new();
            let mut derivatives = Vec::new();
            for (o, &f) in outputs.iter().enumerate() {
                for (k, (&leaf, source)) in leaves.iter().zip(&sources).enumerate() {
                    if !matches!(source, Source::Slot { .. }) {
                        continue;
                    }
                    let d = pool.diff(f, leaf);
                    if d != Pool::ZERO {
                        jacobian_entries.push((o as u32, k as u32));
                        derivatives.push(d);
                    }
                }
            }
            let jacobian_program = Program::compile(pool, &leaves, &derivatives)?;
            let len = |each: bool| {
                gather
                    .iter()
                    .filter_map(|g| match g {
                        Gather::Each(from) if each => from.iter().max().map(|&i| i as usize + 1),
                        Gather::Broadcast(i) if !each => Some(*i as usize + 1),
                        _ => None,
                    })
                    .max()
                    .unwrap_or(0)
            };
            let (input_len, state_len) = (len(false), len(true));
            let stretches = Stretches::new(&gather, elements);
            let columns = Columns {
                inputs: vec![vec![0.0; elements]; kernel.n_inputs()],
                filled: vec![f64::NAN.to_bits(); kernel.n_inputs()],
                jacobian: Vec::new(),
            };
            kernels.push(Kernel {
                kernel,
                gather,
                scatter,
                at: 0,
                acts,
                nonzero: outputs.iter().map(|&c| c != Pool::ZERO).collect(),
                jacobian_entries,
                jacobian_program,
                jacobian_kernel: OnceCell::new(),
                mode,
                late,
                stretches,
                elements,
                columns: RefCell::new(columns),
                input_len,
                state_len,
            });
        }
        let native = kernels
            .iter()
            .all(|k| k.kernel.is_native() || k.mode == JitMode::Off);
        let mut at = 0;
        for k in &mut kernels {
            k.at = at;
            at += k.scatter.len() * k.elements;
        }
        let (term_start, terms) = sums(&kernels, n);
        // Every term is an output (the sums index the outputs they were built from): checked
        // here once (`Sums::new`), so that the sums read them unchecked.
        if term_start.len() != n + 1 {
            return Ok(None);
        }
        let Some(sums) = Sums::new(&term_start, &terms, &structure.axes, at) else {
            return Ok(None);
        };
        Ok(Some(NetKernels {
            kernels,
            outputs: RefCell::new(vec![0.0; at]),
            sums,
            n,
            native: native && jit == JitMode::Auto,
            reads_rates,
            evaluations: Cell::new(0),
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

    /// Elements evaluated per evaluation of the accelerations, every kernel's together (a
    /// spring between two particles is one element, not one per end).
    pub fn elements(&self) -> usize {
        self.kernels.iter().map(|k| k.elements).sum()
    }

    /// Values gathered per evaluation of the accelerations (the columns of parameters are
    /// filled once, not counted): a deterministic count.
    pub fn gathered(&self) -> usize {
        self.kernels
            .iter()
            .map(|k| {
                let each = k
                    .gather
                    .iter()
                    .filter(|g| matches!(g, Gather::Each(_)))
                    .count();
                each * k.elements
            })
            .sum()
    }

    /// Terms summed into the accelerations per evaluation: three at a time (a particle's x,
    /// y and z together, [`Sums`]) and in all (deterministic counts).
    pub fn terms_summed(&self) -> (usize, usize) {
        (self.sums.together(), self.sums.terms())
    }

    /// The runs the accelerations are summed by, output by output, when they pay
    /// ([`Sums`]): a deterministic count.
    pub fn summed_by_runs(&self) -> Option<usize> {
        self.sums.runs()
    }

    /// Of the kernels with per-element inputs, those that read them in place, stretch by
    /// stretch (nothing gathered), when they run native code, and their stretches; and the
    /// kernels with per-element inputs in all (deterministic counts).
    pub fn read_in_place(&self) -> (usize, usize, usize) {
        let reading = self
            .kernels
            .iter()
            .filter(|k| k.elements > 0 && k.gather.iter().any(|g| matches!(g, Gather::Each(_))));
        reading.fold((0, 0, 0), |(kernels, stretches, all), k| {
            match &k.stretches {
                Some(s) => (kernels + 1, stretches + s.stretches.len(), all + 1),
                None => (kernels, stretches, all + 1),
            }
        })
    }

    /// A copy whose kernels all gather their inputs into columns, none reading in place:
    /// the reference the stretches are checked against.
    pub fn gathering_copy(&self) -> NetKernels {
        let mut copy = self.clone();
        copy.kernels.iter_mut().for_each(|k| k.stretches = None);
        copy
    }

    /// Whether the large kernels run as native code.
    pub fn is_native(&self) -> bool {
        self.native
    }

    /// Whether an acceleration depends on a velocity.
    pub fn reads_rates(&self) -> bool {
        self.reads_rates
    }

    /// Counts one evaluation of the accelerations: true once there have been
    /// [`NATIVE_AFTER`], when the small templates run as native code too.
    fn count_evaluation(&self) -> bool {
        let done = self.evaluations.get();
        if done < NATIVE_AFTER {
            self.evaluations.set(done + 1);
        }
        done >= NATIVE_AFTER
    }

    /// Small templates compiled late, after [`NATIVE_AFTER`] evaluations, and running
    /// native code (a deterministic count).
    pub fn compiled_late(&self) -> usize {
        self.kernels
            .iter()
            .filter_map(|k| k.late.as_ref()?.native.get()?.as_ref())
            .filter(|native| native.is_native())
            .count()
    }

    /// The accelerations `q''` (free coordinates in state order) at `input = [t, q, q',
    /// parameters]`.
    pub fn accelerations(&self, input: &[f64], acc: &mut [f64]) {
        let outputs = &mut *self.outputs.borrow_mut();
        let late = self.count_evaluation();
        for k in &self.kernels {
            run_kernel(k, Values::Input(input), outputs, late);
        }
        self.sums.sum_into(outputs, &mut acc[..self.n]);
    }

    /// The same accelerations at the state `y = [q, q']`, read where it is: `input = [t, q,
    /// q', parameters]` gives `t` and the parameters only (its `q`, `q'` are not read, so the
    /// caller need not copy the state there at every evaluation).
    pub fn accelerations_of_state(&self, y: &[f64], input: &[f64], acc: &mut [f64]) {
        let outputs = &mut *self.outputs.borrow_mut();
        let late = self.count_evaluation();
        for k in &self.kernels {
            run_kernel(k, Values::State { y, input }, outputs, late);
        }
        self.sums.sum_into(outputs, &mut acc[..self.n]);
    }

    /// True when no load acts along a particle's component that is constant in time: the
    /// generic derivation then has Newton's equations (one per coordinate) and checks the
    /// momenta; otherwise it projects them, and does not.
    pub fn newton_form(&self) -> bool {
        self.kernels.iter().all(|k| {
            k.nonzero
                .iter()
                .zip(&k.scatter)
                .all(|(&nonzero, rows)| !nonzero || !rows.contains(&NONE))
        })
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
        for k in &self.kernels {
            if k.elements == 0 {
                continue;
            }
            let outputs = &mut *self.outputs.borrow_mut();
            run_kernel(k, Values::Input(input), outputs, false);
            let outs = &outputs[k.at..k.at + k.scatter.len() * k.elements];
            for (a, pushed) in k.acts.iter().enumerate() {
                for (e, &p) in pushed.iter().enumerate() {
                    let m = mass[p as usize];
                    let f = [0, 1, 2].map(|c| m * outs[(3 * a + c) * k.elements + e]);
                    let r = position[p as usize];
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
        }
        out
    }

    /// Adds `∂q''/∂w` into rows `n..2n` of the dense Jacobian `jac` (`2n × 2n`, row-major)
    /// of the first-order system, at `input = [t, q, q', parameters]`. The caller zeroes
    /// `jac` and sets the identity block.
    pub fn add_jacobian(&self, input: &[f64], jac: &mut [f64]) {
        let n = self.n;
        let m = 2 * n;
        let compiled = self.jacobian_terms(input, &mut |row, column, value| {
            jac[(n + row) * m + column] += value;
        });
        if !compiled {
            // Cannot happen: the same operations as the kernels', which compiled.
            jac.iter_mut().for_each(|x| *x = f64::NAN);
        }
    }

    /// Every term of `∂q''/∂w` (`w = [q, q']`) at `input = [t, q, q', parameters]`, element
    /// by element: `term(row, column, value)` with `row` the acceleration (a free coordinate
    /// in state order) and `column` the index in `w` (`< n`: a coordinate, `≥ n`: a rate).
    /// An entry of the Jacobian is the sum of its terms (a particle's springs each give one).
    /// False when a kernel of derivatives could not be compiled (cannot happen: the same
    /// operations as the kernels', which compiled).
    pub fn jacobian_terms(&self, input: &[f64], term: &mut dyn FnMut(usize, usize, f64)) -> bool {
        for k in &self.kernels {
            if k.elements == 0 || k.jacobian_entries.is_empty() {
                continue;
            }
            let kernel = k
                .jacobian_kernel
                .get_or_init(|| BatchKernel::new(&k.jacobian_program, k.mode));
            let Some(kernel) = kernel else {
                return false;
            };
            let cols = &mut *k.columns.borrow_mut();
            gather(k, Values::Input(input), cols);
            let outputs = k.jacobian_entries.len();
            if cols.jacobian.len() < outputs {
                cols.jacobian.resize(outputs, vec![0.0; k.elements]);
            }
            let ins: Vec<&[f64]> = cols.inputs.iter().map(|c| c.as_slice()).collect();
            let mut outs: Vec<&mut [f64]> = cols.jacobian[..outputs]
                .iter_mut()
                .map(|c| c.as_mut_slice())
                .collect();
            kernel.run(&ins, &mut outs);
            for (&(output, input_k), out) in k.jacobian_entries.iter().zip(&outs) {
                let rows = &k.scatter[output as usize];
                let from = &k.gather[input_k as usize];
                for (e, (&row, &value)) in rows.iter().zip(out.iter()).enumerate() {
                    if row == NONE {
                        continue;
                    }
                    if let Some(column) = from.state_index(e) {
                        term(row as usize, column as usize, value);
                    }
                }
            }
        }
        true
    }

    /// Free coordinates (accelerations) the kernels form.
    pub fn coordinates(&self) -> usize {
        self.n
    }
}

/// Runs `k` over its elements at `input`: its output columns, one value per element, in its
/// part of `outputs`; with `late`, a small template's native code (compiled now if it is not
/// yet: the same bits as the interpreter's).
fn run_kernel(k: &Kernel, input: Values, outputs: &mut [f64], late: bool) {
    if k.elements == 0 {
        return;
    }
    let kernel = match &k.late {
        Some(l) if late => l
            .native
            .get_or_init(|| BatchKernel::new(&l.program, l.mode))
            .as_ref()
            .unwrap_or(&k.kernel),
        _ => &k.kernel,
    };
    let cols = &mut *k.columns.borrow_mut();
    let outputs = &mut outputs[k.at..k.at + k.scatter.len() * k.elements];
    // The columns' slices on the stack for the usual few columns: two allocations per kernel
    // and evaluation were 2 % of a net's run.
    const FEW: usize = 16;
    // Stretches for native code only: the column interpreter (WebAssembly, small templates)
    // pays its dispatch per call, which a whole gathered column amortises better.
    if let (Some(stretches), true) = (
        &k.stretches,
        kernel.is_native() && k.gather.len() <= FEW && k.scatter.len() <= FEW,
    ) {
        let (state, input) = sources(k, input);
        fill_broadcast(k, input, cols);
        let mut ins: [&[f64]; FEW] = [&[]; FEW];
        for ((slot, g), col) in ins.iter_mut().zip(&k.gather).zip(&cols.inputs) {
            *slot = match g {
                Gather::Each(_) => state,
                Gather::Broadcast(_) => col,
            };
        }
        let mut outs: [&mut [f64]; FEW] = Default::default();
        for (slot, column) in outs.iter_mut().zip(outputs.chunks_mut(k.elements)) {
            *slot = column;
        }
        kernel.run_stretches(
            &ins[..k.gather.len()],
            &stretches.from,
            &mut outs[..k.scatter.len()],
            &stretches.stretches,
        );
        return;
    }
    gather(k, input, cols);
    let outputs = outputs.chunks_mut(k.elements);
    if cols.inputs.len() <= FEW && k.scatter.len() <= FEW {
        let mut ins: [&[f64]; FEW] = [&[]; FEW];
        let mut outs: [&mut [f64]; FEW] = Default::default();
        for (slot, c) in ins.iter_mut().zip(&cols.inputs) {
            *slot = c;
        }
        for (slot, c) in outs.iter_mut().zip(outputs) {
            *slot = c;
        }
        let (n_in, n_out) = (cols.inputs.len(), k.scatter.len());
        kernel.run(&ins[..n_in], &mut outs[..n_out]);
        return;
    }
    let ins: Vec<&[f64]> = cols.inputs.iter().map(|c| c.as_slice()).collect();
    let mut outs: Vec<&mut [f64]> = outputs.collect();
    kernel.run(&ins, &mut outs);
}

/// The terms of each acceleration (the rows [`Sums`] is built from): every output not identically
/// zero of every element, by the acceleration it adds to (kernel by kernel, output by output,
/// element by element within one acceleration).
fn sums(kernels: &[Kernel], n: usize) -> (Vec<u32>, Vec<u32>) {
    let mut count = vec![0u32; n + 1];
    let each = |f: &mut dyn FnMut(u32, u32)| {
        for k in kernels {
            for (o, rows) in k.scatter.iter().enumerate() {
                if !k.nonzero[o] {
                    continue;
                }
                for (e, &row) in rows.iter().enumerate() {
                    if row != NONE {
                        f(row, (k.at + o * k.elements + e) as u32);
                    }
                }
            }
        }
    };
    each(&mut |row, _| count[row as usize + 1] += 1);
    // Row `r` starts after every term of the rows before it.
    let mut total = 0;
    for c in &mut count {
        total += *c;
        *c = total;
    }
    let mut next = count.clone();
    let mut terms = vec![0u32; count[n] as usize];
    each(&mut |row, i| {
        terms[next[row as usize] as usize] = i;
        next[row as usize] += 1;
    });
    (count, terms)
}

/// Where a kernel's inputs are read.
#[derive(Clone, Copy)]
enum Values<'a> {
    /// Everything from `[t, q, q', parameters]`.
    Input(&'a [f64]),
    /// The per-element values (coordinates, rates) from the state `y = [q, q']`, `t` and the
    /// parameters from `input` (whose `q`, `q'` are not read).
    State { y: &'a [f64], input: &'a [f64] },
}

/// Fills the input columns of kernel `k` from `values`: every element's coordinates, and a
/// parameter's column only when its value changed since it was filled.
fn gather(k: &Kernel, values: Values, cols: &mut Columns) {
    let (state, input) = sources(k, values);
    fill_broadcast(k, input, cols);
    for (col, from) in cols.inputs.iter_mut().zip(&k.gather) {
        if let Gather::Each(from) = from {
            for (x, &i) in col.iter_mut().zip(from) {
                // SAFETY: `i < k.state_len <= state.len()` (asserted by `sources`).
                *x = unsafe { *state.get_unchecked(i as usize) };
            }
        }
    }
}

/// The state `[q, q']` and the input vector `[t, q, q', parameters]` kernel `k` reads,
/// checked once to be as long as its tables need.
fn sources<'a>(k: &Kernel, values: Values<'a>) -> (&'a [f64], &'a [f64]) {
    let (state, input) = match values {
        Values::Input(input) => (input.get(1..).unwrap_or_default(), input),
        Values::State { y, input } => (y, input),
    };
    assert!(
        input.len() >= k.input_len && state.len() >= k.state_len,
        "net kernel inputs: {} values, {} of state; the gather table reads {}, {}",
        input.len(),
        state.len(),
        k.input_len,
        k.state_len
    );
    (state, input)
}

/// Fills each broadcast input column of `k` (a parameter, `t`) whose value changed since.
fn fill_broadcast(k: &Kernel, input: &[f64], cols: &mut Columns) {
    for ((col, from), filled) in cols.inputs.iter_mut().zip(&k.gather).zip(&mut cols.filled) {
        if let Gather::Broadcast(i) = from {
            let v = input[*i as usize];
            if v.to_bits() != *filled {
                col.iter_mut().for_each(|x| *x = v);
                *filled = v.to_bits();
            }
        }
    }
}

/// Per input of group `g`, where each element's value is in `[t, q, q', parameters]` (`n`
/// free coordinates); `None` when an element lacks a coordinate its template reads (cannot
/// happen: equal templates read the same components).
fn gather_table(
    g: &Group,
    sources: &[Source],
    structure: &Structure,
    n: usize,
) -> Option<Vec<Gather>> {
    let elements = g.particles.len() / g.slots;
    sources
        .iter()
        .map(|s| match *s {
            Source::Slot { slot, axis, order } => (0..elements)
                .map(|e| {
                    let particle = g.particles[e * g.slots + slot as usize] as usize;
                    let q = structure.axes[particle][axis as usize]?;
                    Some(order as u32 * n as u32 + q)
                })
                .collect::<Option<Vec<u32>>>()
                .map(Gather::Each),
            Source::Parameter(k) => Some(Gather::Broadcast(1 + 2 * n as u32 + k)),
            Source::Time => Some(Gather::Broadcast(0)),
        })
        .collect()
}
