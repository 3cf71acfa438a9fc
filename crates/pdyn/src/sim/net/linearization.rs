//! A net linearized at rest without the symbolic derivation: `M`, `K = −∂F/∂q`,
//! `C = −∂F/∂q'` and `F` from the compiled per-template kernels ([`super::kernels`]), for
//! `pdyn modes` and `pdyn equilibrium` of many free particles (issue 33).
//!
//! The symbolic [`pdyn_mech::linearization::Linearizer`] derives `m a = F` for the whole
//! model, and differentiates each row's sum of loads by every coordinate it holds: for a
//! 10^4-mass chain, seconds of simplifying and differentiating expressions that differ only
//! in which particles they name. Here the kernels give each element's `F / m` and its
//! derivatives by the element's own coordinates and rates (the slot inputs), numbers
//! computed over index arrays; the row of particle `p`'s coordinate is `m_p` times the sum of
//! its terms, and the element's derivatives land in the columns of its particles (the
//! sparsity pattern the elements' connectivity gives). The mass matrix is diagonal (one
//! particle's mass per coordinate), and `M r_d` for the participation factors is that mass
//! where the coordinate is component `d` of its particle.
//!
//! The numbers are the symbolic path's to round-off (each load divided by its particle's mass
//! and multiplied back, the terms summed in another order): `tests/particle_net.rs`.

use super::kernels::NetKernels;
use super::structure;
use pdyn_expr::{Id, Program};
use pdyn_jit::JitMode;
use pdyn_mech::linearization::{Linearize, SparseLinearization};
use pdyn_mech::model::CoordinateKind;
use pdyn_mech::sparse::{Assembly, Csr, SparseError};
use pdyn_mech::Model;
use std::cell::RefCell;

/// The linearization of a model of free particles in Cartesian coordinates, numeric.
pub struct NetLinearization {
    names: Vec<String>,
    initial: Vec<f64>,
    /// Each free coordinate's particle's mass: `M`'s diagonal.
    mass: Vec<f64>,
    /// `M r_d` (d = x, y, z): the mass where the coordinate is component `d`, else 0.
    inertia: [Vec<f64>; 3],
    kernels: NetKernels,
    /// `[t, q, q', parameters]` at rest at t = 0, the parameters' values set.
    input: Vec<f64>,
    /// How the terms of `K` and of `C` land in their matrices: the elements' pattern, found at
    /// the first linearization and refilled at the next (damped Newton's steps).
    assembly: RefCell<[Option<Assembly>; 2]>,
}

impl NetLinearization {
    /// The model's linearization by its kernels, or `None` when it is not one of at least
    /// `from` free particles in Cartesian coordinates with a free coordinate (the symbolic
    /// path then linearizes it: nothing here is an error), or when a template or a mass
    /// cannot be compiled (the symbolic path then reports why).
    pub fn new(model: &mut Model, jit: JitMode, from: usize) -> Option<NetLinearization> {
        if model.particles.len() < from || model.coordinates.is_empty() {
            return None;
        }
        let structure = structure::recognise(model)?;
        let n = model.coordinates.len();
        let parameters: Vec<Id> = model.parameters.iter().map(|q| q.id).collect();
        let values: Vec<f64> = model.parameters.iter().map(|q| q.value).collect();
        let kernels =
            NetKernels::compile(&mut model.pool, &structure, n, &parameters, jit).ok()??;
        // The masses, numbers (the recogniser checked they are constant in time).
        let masses: Vec<Id> = model.particles.iter().map(|p| p.mass).collect();
        let program = Program::compile(&mut model.pool, &parameters, &masses).ok()?;
        let mut particle_mass = vec![0.0; masses.len()];
        program.eval(&values, &mut program.workspace(), &mut particle_mass);
        let mut mass = vec![f64::NAN; n];
        let mut inertia = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (axes, &m) in structure.axes.iter().zip(&particle_mass) {
            for (axis, q) in axes.iter().enumerate() {
                if let Some(q) = *q {
                    mass[q as usize] = m;
                    inertia[axis][q as usize] = m;
                }
            }
        }
        let mut input = vec![0.0; 1 + 2 * n + values.len()];
        input[1 + 2 * n..].copy_from_slice(&values);
        let initial = model
            .coordinates
            .iter()
            .map(|c| match c.kind {
                CoordinateKind::Free { initial, .. } => initial,
                CoordinateKind::Prescribed { .. } => f64::NAN,
            })
            .collect();
        Some(NetLinearization {
            names: model.coordinates.iter().map(|c| c.name.clone()).collect(),
            initial,
            mass,
            inertia,
            kernels,
            input,
            assembly: RefCell::new([None, None]),
        })
    }

    /// `[t, q, q', parameters]` at rest at `q`.
    fn input_at(&self, q: &[f64]) -> Vec<f64> {
        let mut input = self.input.clone();
        input[1..1 + q.len()].copy_from_slice(q);
        input
    }

    /// The loads at `input`: each acceleration times its particle's mass.
    fn force_with(&self, input: &[f64]) -> Vec<f64> {
        let mut force = vec![0.0; self.names.len()];
        self.kernels.accelerations(input, &mut force);
        for (f, m) in force.iter_mut().zip(&self.mass) {
            *f *= m;
        }
        force
    }

    /// The matrix of the terms `t` (`which`: 0 for `K`, 1 for `C`), through the assembly kept
    /// from the last call when the terms are the same `(row, column)` sequence (always, for
    /// one net), else a new one.
    fn assemble(&self, t: &[(usize, usize, f64)], which: usize) -> Result<Csr, SparseError> {
        let mut kept = self.assembly.borrow_mut();
        if let Some(a) = kept[which].as_ref().and_then(|a| a.fill(t)) {
            return Ok(a);
        }
        let (assembly, a) = Assembly::new(self.names.len(), t)?;
        kept[which] = Some(assembly);
        Ok(a)
    }

    /// `M`, `K`, `C` at `input` (at rest), with `force` the loads there.
    fn matrices(&self, input: &[f64], force: Vec<f64>) -> SparseLinearization {
        // The elements' terms straight into the matrices through the assemblies kept (after
        // the first linearization: the same numbers as collecting them, without the triplets).
        if let [Some(k_assembly), Some(c_assembly)] = &*self.assembly.borrow() {
            let n = self.names.len();
            let (mut k, mut c) = (k_assembly.filler(), c_assembly.filler());
            let compiled = self
                .kernels
                .jacobian_terms(input, &mut |row, column, value| {
                    let entry = -self.mass[row] * value;
                    if column < n {
                        k.add(row, column, entry);
                    } else {
                        c.add(row, column - n, entry);
                    }
                });
            if let (true, Some(stiffness), Some(damping)) = (compiled, k.finish(), c.finish()) {
                return SparseLinearization {
                    mass: Csr::diagonal(&self.mass),
                    stiffness,
                    damping,
                    force,
                };
            }
        }
        self.matrices_by_triplets(input, force)
    }

    /// [`NetLinearization::matrices`] through triplets, whose assemblies are kept: the first
    /// time (or should the terms' sequence change).
    fn matrices_by_triplets(&self, input: &[f64], force: Vec<f64>) -> SparseLinearization {
        let n = self.names.len();
        let (mut k, mut c) = (Vec::new(), Vec::new());
        let compiled = self
            .kernels
            .jacobian_terms(input, &mut |row, column, value| {
                let entry = -self.mass[row] * value;
                if column < n {
                    k.push((row, column, entry));
                } else {
                    c.push((row, column - n, entry));
                }
            });
        // Rows and columns are free coordinates of this model, hence in bounds; a kernel of
        // derivatives that would not compile (it cannot: the same operations as the loads')
        // gives NaN matrices, which the solvers refuse.
        let csr = |t: &[(usize, usize, f64)], which: usize| match self.assemble(t, which) {
            Ok(a) if compiled => a,
            _ => Csr::diagonal(&vec![f64::NAN; n]),
        };
        SparseLinearization {
            mass: Csr::diagonal(&self.mass),
            stiffness: csr(&k, 0),
            damping: csr(&c, 1),
            force,
        }
    }

    /// Operations per evaluation of the loads (every kernel over its elements): a
    /// deterministic count, linear in the elements.
    pub fn operations(&self) -> usize {
        self.kernels.operations()
    }
}

impl Linearize for NetLinearization {
    fn names(&self) -> &[String] {
        &self.names
    }

    fn initial(&self) -> &[f64] {
        &self.initial
    }

    fn force(&self, q: &[f64]) -> Vec<f64> {
        self.force_with(&self.input_at(q))
    }

    fn force_alone(&self) -> bool {
        // The loads' kernels alone: about a twentieth of the linearization on the 20 × 20
        // hanging net (the derivatives' kernels and the matrices' assembly are the rest).
        true
    }

    fn at_sparse(&self, q: &[f64]) -> SparseLinearization {
        let input = self.input_at(q);
        let force = self.force_with(&input);
        self.matrices(&input, force)
    }

    fn at_sparse_with(&self, q: &[f64], force: Vec<f64>) -> SparseLinearization {
        // `force` is `force(q)`, `force_with` of this same input: the numbers of `at_sparse`.
        self.matrices(&self.input_at(q), force)
    }

    fn inertia_at(&self, _q: &[f64]) -> [Vec<f64>; 3] {
        self.inertia.clone()
    }
}
