//! The equations of motion `M(q) q'' = f(q, q', t)` linearized about a state at rest: the
//! numbers behind `pdyn equilibrium` and `pdyn modes`.
//!
//! At rest (`q' = 0`) and in equilibrium (`f = 0`), a small motion `q = q0 + δq` obeys
//! `M δq'' + C δq' + K δq = 0` with `M = M(q0)`, `K = -∂f/∂q`, `C = -∂f/∂q'`: the term
//! `(∂M/∂q) q''` vanishes with `q''`. The derivatives are exact (symbolic, taken only where the
//! expressions hold the variable: a net's particle depends on its neighbours), compiled once
//! into one program, and evaluated at any `q0`; the matrices are dense (`nalgebra`), which
//! suits systems of up to a few thousand coordinates.

use crate::derive::{Derivation, UnknownKind};
use crate::model::Model;
use crate::sparse::Csr;
use nalgebra::{DMatrix, DVector};
use pdyn_expr::{Id, Pool, Program};

/// Why a model cannot be linearized.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LinearizationError {
    /// The equations keep unknown reactions (constraints, massless frames, declared reaction
    /// forces): statics of such models is `pdyn forces`' business.
    Reactions(Vec<String>),
    /// No free coordinate.
    NoCoordinates,
    /// The expressions could not be compiled (a function without a numeric form).
    Compile(String),
    /// More equations than coordinates.
    NotSquare {
        /// Equations.
        equations: usize,
        /// Free coordinates.
        coordinates: usize,
    },
}

impl std::fmt::Display for LinearizationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinearizationError::Reactions(names) => write!(
                f,
                "the equations keep unknown reactions ({}): linearization needs a model whose \
                 equations hold the accelerations only (use `pdyn forces` for its statics)",
                names.join(", ")
            ),
            LinearizationError::NoCoordinates => write!(f, "the model has no free coordinate"),
            LinearizationError::Compile(e) => write!(f, "cannot compile the equations: {e}"),
            LinearizationError::NotSquare {
                equations,
                coordinates,
            } => write!(
                f,
                "{equations} equations for {coordinates} coordinates: linearization needs as \
                 many equations as coordinates"
            ),
        }
    }
}

impl std::error::Error for LinearizationError {}

/// The linearized equations at one state.
#[derive(Clone, Debug)]
pub struct Linearization {
    /// `M(q0)`.
    pub mass: DMatrix<f64>,
    /// `K = -∂f/∂q` at `(q0, 0)`.
    pub stiffness: DMatrix<f64>,
    /// `C = -∂f/∂q'` at `(q0, 0)`.
    pub damping: DMatrix<f64>,
    /// `f(q0, 0)`: zero in equilibrium (the out-of-balance force otherwise).
    pub force: DVector<f64>,
}

/// The linearized equations at one state, as sparse matrices (the same entries as
/// [`Linearization`], none of the zeros): for systems too large for dense `n × n` matrices.
#[derive(Clone, Debug)]
pub struct SparseLinearization {
    /// `M(q0)`.
    pub mass: Csr,
    /// `K = -∂f/∂q` at `(q0, 0)`.
    pub stiffness: Csr,
    /// `C = -∂f/∂q'` at `(q0, 0)`.
    pub damping: Csr,
    /// `f(q0, 0)`.
    pub force: Vec<f64>,
}

impl SparseLinearization {
    /// The same matrices, dense.
    pub fn to_dense(&self) -> Linearization {
        Linearization {
            mass: self.mass.to_dense(),
            stiffness: self.stiffness.to_dense(),
            damping: self.damping.to_dense(),
            force: DVector::from_column_slice(&self.force),
        }
    }
}

/// What the statics ([`crate::equilibrium`], [`crate::sparse_statics`],
/// [`crate::statics::modes_of`]) read of a model linearized at rest: the symbolic
/// [`Linearizer`] of any model, or a numeric one built from compiled per-element kernels
/// (`pdyn`'s path for many free particles), which never forms the equations symbolically.
pub trait Linearize {
    /// Names of the free coordinates, in state order.
    fn names(&self) -> &[String];
    /// Initial values of the free coordinates.
    fn initial(&self) -> &[f64];
    /// Number of free coordinates.
    fn len(&self) -> usize {
        self.names().len()
    }
    /// True when there is no coordinate.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// `M`, `K`, `C` and `f` at rest at `q` (t = 0), sparse.
    fn at_sparse(&self, q: &[f64]) -> SparseLinearization;
    /// `f` alone at rest at `q` (t = 0): what damped Newton's work along a step reads (a
    /// linearization that can compute it without the matrices says so), bit for bit the
    /// `force` of [`Linearize::at_sparse`] at `q`.
    fn force(&self, q: &[f64]) -> Vec<f64> {
        self.at_sparse(q).force
    }
    /// Whether [`Linearize::force`] computes `f` without the matrices (for less than
    /// [`Linearize::at_sparse`] costs): damped Newton then judges a trial step by `f` alone
    /// and computes the matrices only where it takes the step
    /// ([`Linearize::at_sparse_with`]). False by default: `force` is `at_sparse`'s.
    fn force_alone(&self) -> bool {
        false
    }
    /// [`Linearize::at_sparse`] at `q`, given `force`, [`Linearize::force`] at `q` (computed
    /// already): the same numbers, without computing `f` again where the linearization can.
    fn at_sparse_with(&self, q: &[f64], force: Vec<f64>) -> SparseLinearization {
        SparseLinearization {
            force,
            ..self.at_sparse(q)
        }
    }
    /// The same, dense (for small systems).
    fn at(&self, q: &[f64]) -> Linearization {
        self.at_sparse(q).to_dense()
    }
    /// `M r_d` at rest at `q`, for d = x, y, z ([`Linearizer::inertia_at`]).
    fn inertia_at(&self, q: &[f64]) -> [Vec<f64>; 3];
}

impl Linearize for Linearizer {
    fn names(&self) -> &[String] {
        &self.names
    }
    fn initial(&self) -> &[f64] {
        &self.initial
    }
    fn at_sparse(&self, q: &[f64]) -> SparseLinearization {
        Linearizer::at_sparse(self, q)
    }
    fn at(&self, q: &[f64]) -> Linearization {
        Linearizer::at(self, q)
    }
    fn inertia_at(&self, q: &[f64]) -> [Vec<f64>; 3] {
        Linearizer::inertia_at(self, q)
    }
}

/// Where each compiled output goes.
#[derive(Clone, Debug)]
enum Slot {
    Force(usize),
    Mass(usize, usize),
    Stiffness(usize, usize),
    Damping(usize, usize),
}

/// The model's `M`, `f`, `K`, `C` compiled once, to be evaluated at any state at rest.
#[derive(Clone, Debug)]
pub struct Linearizer {
    /// Names of the free coordinates, in state order.
    pub names: Vec<String>,
    /// Initial values of the free coordinates.
    pub initial: Vec<f64>,
    program: Program,
    slots: Vec<Slot>,
    /// `M r_d` for d = x, y, z (see [`Linearizer::inertia_at`]): a program and, for each of
    /// its outputs, the direction and the coordinate it adds to.
    inertia: Program,
    inertia_slots: Vec<(usize, usize)>,
    /// `[t, q, q', parameters]`, with the parameters' values set.
    input: Vec<f64>,
}

impl Linearizer {
    /// Compiles the linearization of `d`, derived from `model`.
    pub fn new(model: &mut Model, d: &Derivation) -> Result<Linearizer, LinearizationError> {
        let reactions: Vec<String> = d
            .unknowns
            .iter()
            .filter(|u| matches!(u.kind, UnknownKind::Reaction(_)))
            .map(|u| u.name.clone())
            .collect();
        if !reactions.is_empty() {
            return Err(LinearizationError::Reactions(reactions));
        }
        let n = d.free.len();
        if n == 0 {
            return Err(LinearizationError::NoCoordinates);
        }
        let sys = &d.system;
        if sys.rows() != n || sys.cols() != n {
            return Err(LinearizationError::NotSquare {
                equations: sys.rows(),
                coordinates: n,
            });
        }
        // Row i of A x = b may be any equation; column j is unknown j, the acceleration of
        // free coordinate `column[j]`.
        let column: Vec<usize> = d
            .unknowns
            .iter()
            .map(|u| match u.kind {
                UnknownKind::Acceleration(ci) => d.free.iter().position(|&f| f == ci).unwrap_or(0),
                UnknownKind::Reaction(_) => 0,
            })
            .collect();
        // Newton's equations come particle by particle (`m x'' = F_x` of P, then its y...),
        // not coordinate by coordinate: when each row holds one acceleration, row i is put
        // where its coordinate is, so that M and K come out symmetric (as the projected
        // form writes them) and the eigenproblem is a symmetric one.
        let mut row_to = (0..sys.rows()).collect::<Vec<usize>>();
        let single: Vec<Option<usize>> = (0..sys.rows())
            .map(|i| {
                let nz: Vec<usize> = (0..sys.cols())
                    .filter(|&j| sys.a[i * sys.cols() + j] != Pool::ZERO)
                    .collect();
                (nz.len() == 1).then(|| column[nz[0]])
            })
            .collect();
        if single.iter().all(Option::is_some) {
            let targets: Vec<usize> = single.iter().map(|t| t.unwrap_or(0)).collect();
            let mut seen = vec![false; n];
            if targets
                .iter()
                .all(|&t| !std::mem::replace(&mut seen[t], true))
            {
                row_to = targets;
            }
        }
        let p = &mut model.pool;
        let (q, qd) = d.state.split_at(n);
        let mut outputs: Vec<Id> = Vec::new();
        let mut slots = Vec::new();
        // The equations' rows are combined into M and f as written: M δq'' = f holds row by
        // row, and K, C are taken row by row too (a square system of independent rows).
        for (i, &b) in sys.b.iter().enumerate() {
            outputs.push(b);
            slots.push(Slot::Force(row_to[i]));
            for (j, &c) in column.iter().enumerate() {
                let a = sys.a[i * sys.cols() + j];
                if a != Pool::ZERO {
                    outputs.push(a);
                    slots.push(Slot::Mass(row_to[i], c));
                }
            }
        }
        // K and C row by row, each row differentiated only by the coordinates and rates it
        // holds (a net's particle depends on its few neighbours): no n × n table of zeros.
        let column_of: rustc_hash::FxHashMap<Id, usize> = q
            .iter()
            .chain(qd)
            .enumerate()
            .map(|(j, &v)| (v, j))
            .collect();
        let wanted: rustc_hash::FxHashSet<Id> = column_of.keys().copied().collect();
        for (i, &row) in row_to.iter().enumerate() {
            let mut vars = p.occurring(sys.b[i], &wanted);
            vars.sort_by_key(|v| column_of[v]);
            for v in vars {
                let j = column_of[&v];
                let dv = p.diff(sys.b[i], v);
                if dv == Pool::ZERO {
                    continue;
                }
                outputs.push(p.neg(dv));
                slots.push(if j < n {
                    Slot::Stiffness(row, j)
                } else {
                    Slot::Damping(row, j - n)
                });
            }
        }
        // M r_d: entry i is Σ_p m_p ∂(r_p · e_d)/∂q_i, the generalized momentum of every
        // particle moving at unit speed along e_d (the inertia load of a unit ground
        // acceleration along e_d). Each particle is differentiated only by the coordinates
        // its position holds.
        let coordinate_of: rustc_hash::FxHashMap<Id, usize> =
            q.iter().enumerate().map(|(j, &v)| (v, j)).collect();
        let coordinates: rustc_hash::FxHashSet<Id> = q.iter().copied().collect();
        let mut inertia_outputs: Vec<Id> = Vec::new();
        let mut inertia_slots = Vec::new();
        for particle in &model.particles {
            for (dir, &component) in particle.position.iter().enumerate() {
                let mut vars = p.occurring(component, &coordinates);
                vars.sort_by_key(|v| coordinate_of[v]);
                for v in vars {
                    let dv = p.diff(component, v);
                    if dv == Pool::ZERO {
                        continue;
                    }
                    inertia_outputs.push(p.mul(&[particle.mass, dv]));
                    inertia_slots.push((dir, coordinate_of[&v]));
                }
            }
        }
        let mut inputs = vec![p.time()];
        inputs.extend(&d.state);
        inputs.extend(model.parameters.iter().map(|par| par.id));
        let program = Program::compile(p, &inputs, &outputs)
            .map_err(|e| LinearizationError::Compile(e.to_string()))?;
        let inertia = Program::compile(p, &inputs, &inertia_outputs)
            .map_err(|e| LinearizationError::Compile(e.to_string()))?;
        let mut input = vec![0.0; inputs.len()];
        for (k, par) in model.parameters.iter().enumerate() {
            input[1 + 2 * n + k] = par.value;
        }
        let initial = d
            .free
            .iter()
            .map(|&ci| match model.coordinates[ci].kind {
                crate::model::CoordinateKind::Free { initial, .. } => initial,
                crate::model::CoordinateKind::Prescribed { .. } => 0.0,
            })
            .collect();
        Ok(Linearizer {
            names: d
                .free
                .iter()
                .map(|&ci| model.coordinates[ci].name.clone())
                .collect(),
            initial,
            program,
            slots,
            inertia,
            inertia_slots,
            input,
        })
    }

    /// `M r_d` at rest at `q`, for d = x, y, z: entry i is `Σ_p m_p ∂(r_p · e_d)/∂q_i`, the
    /// generalized inertia force when every particle accelerates at unit rate along `e_d`
    /// (a ground acceleration), whatever the coordinates. A mode's participation factor
    /// along `e_d` is `φᵀ M r_d / φᵀ M φ` ([`crate::modes::Mode::participation`]).
    pub fn inertia_at(&self, q: &[f64]) -> [Vec<f64>; 3] {
        let n = self.len();
        let out = self.eval_program(&self.inertia, q);
        let mut b = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (&(dir, i), v) in self.inertia_slots.iter().zip(out) {
            b[dir][i] += v;
        }
        b
    }

    /// Number of free coordinates.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True when there is no coordinate (never, for a built linearizer).
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The compiled outputs at rest at `q` (at t = 0), one per slot.
    fn eval(&self, q: &[f64]) -> Vec<f64> {
        self.eval_program(&self.program, q)
    }

    /// `program`'s outputs at rest at `q` (t = 0, the parameters' values).
    fn eval_program(&self, program: &Program, q: &[f64]) -> Vec<f64> {
        let n = self.len();
        let mut input = self.input.clone();
        input[1..1 + n].copy_from_slice(q);
        let mut ws = program.workspace();
        let mut out = vec![0.0; program.n_outputs()];
        program.eval(&input, &mut ws, &mut out);
        out
    }

    /// The linearization at rest at `q` (at t = 0), sparse: memory in proportion to the
    /// non-zero entries.
    pub fn at_sparse(&self, q: &[f64]) -> SparseLinearization {
        let n = self.len();
        let out = self.eval(q);
        let (mut m, mut k, mut c) = (Vec::new(), Vec::new(), Vec::new());
        let mut force = vec![0.0; n];
        for (slot, &v) in self.slots.iter().zip(&out) {
            match *slot {
                Slot::Force(i) => force[i] = v,
                Slot::Mass(i, j) => m.push((i, j, v)),
                Slot::Stiffness(i, j) => k.push((i, j, v)),
                Slot::Damping(i, j) => c.push((i, j, v)),
            }
        }
        let csr = |t: &[(usize, usize, f64)]| {
            Csr::from_triplets(n, t).expect("slots index the free coordinates")
        };
        SparseLinearization {
            mass: csr(&m),
            stiffness: csr(&k),
            damping: csr(&c),
            force,
        }
    }

    /// The linearization at rest at `q` (at t = 0).
    pub fn at(&self, q: &[f64]) -> Linearization {
        let n = self.len();
        let out = self.eval(q);
        let mut lin = Linearization {
            mass: DMatrix::zeros(n, n),
            stiffness: DMatrix::zeros(n, n),
            damping: DMatrix::zeros(n, n),
            force: DVector::zeros(n),
        };
        for (slot, &v) in self.slots.iter().zip(&out) {
            match *slot {
                Slot::Force(i) => lin.force[i] = v,
                Slot::Mass(i, j) => lin.mass[(i, j)] = v,
                Slot::Stiffness(i, j) => lin.stiffness[(i, j)] = v,
                Slot::Damping(i, j) => lin.damping[(i, j)] = v,
            }
        }
        lin
    }
}
