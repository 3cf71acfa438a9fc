//! Problem traits: what an integrator needs to know about the equations.
//!
//! * [`OdeSystem`]: the first-order system `M(t, y) y' = f(t, y)`, evaluated in place
//!   (`rhs(t, y, dydt)` writes into a caller-owned buffer; no allocation per call), with an
//!   optional analytic Jacobian `J = ∂f/∂y` and an optional mass matrix `M` (identity by default).
//! * [`SecondOrderSystem`]: `q'' = a(t, q, q')`, with a flag telling whether the acceleration is
//!   independent of `q'` (*separable* Hamiltonian `H = T(p) + V(q)`), which the explicit
//!   symplectic methods require.
//! * [`FnSystem`] and [`FnSecondOrder`] wrap plain closures.
//! * [`FirstOrderForm`] views a second-order system as a first-order one with state `y = (q, v)`.

/// What kind of mass matrix a system has in `M(t, y) y' = f(t, y)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum MassKind {
    /// `M = I` (the ordinary explicit form `y' = f`).
    Identity,
    /// `M` is constant (it may be singular: a differential-algebraic system of index 1, which
    /// only the implicit method Radau5 can integrate).
    Constant,
    /// `M(t, y)` depends on time and state; it must be nonsingular.
    StateDependent,
}

/// A first-order system `M(t, y) y' = f(t, y)` of dimension [`dim`](OdeSystem::dim).
///
/// Only [`dim`](OdeSystem::dim) and [`rhs`](OdeSystem::rhs) are required. Matrices passed to the
/// optional methods are dense, row-major, `n × n`: `jac[i * n + j] = ∂f_i/∂y_j`.
pub trait OdeSystem {
    /// Number of components `n` of the state.
    fn dim(&self) -> usize;

    /// Writes `f(t, y)` into `dydt` (both slices have length `n`). Must not allocate if speed
    /// matters: integrators call it once per stage.
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]);

    /// Writes `f(t, y)` for several states at once: `ys` holds `k` states one after the other
    /// (`k · n` values), `out` receives the `k` derivatives likewise. The finite-difference
    /// Jacobians call it with the `n` perturbed states. The default calls
    /// [`rhs`](OdeSystem::rhs) once per state; a system that evaluates many states in one call
    /// (SciPy's `vectorized=True`) overrides it.
    fn rhs_batch(&self, t: f64, ys: &[f64], out: &mut [f64]) {
        let n = self.dim();
        for (y, o) in ys.chunks_exact(n).zip(out.chunks_exact_mut(n)) {
            self.rhs(t, y, o);
        }
    }

    /// Whether [`jacobian`](OdeSystem::jacobian) is implemented. When `false` the implicit
    /// methods approximate the Jacobian by forward finite differences.
    fn has_jacobian(&self) -> bool {
        false
    }

    /// Writes the Jacobian `∂f/∂y` at `(t, y)` into `jac` (row-major, `n × n`). Called only when
    /// [`has_jacobian`](OdeSystem::has_jacobian) returns `true`.
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        let _ = (t, y, jac);
    }

    /// The pattern of `∂f/∂y` when the system knows it (a many-particle model knows which
    /// particles each force joins). Radau5 then factors its iteration matrices as sparse
    /// matrices ([`crate::LinearSolver`]) and, without [`sparse_jacobian`]
    /// (OdeSystem::sparse_jacobian), groups the columns of its finite differences. Default
    /// `None`; [`crate::Options::jac_sparsity`] takes precedence.
    fn jacobian_sparsity(&self) -> Option<std::sync::Arc<crate::Sparsity>> {
        None
    }

    /// Whether [`sparse_jacobian`](OdeSystem::sparse_jacobian) is implemented.
    fn has_sparse_jacobian(&self) -> bool {
        false
    }

    /// Writes the entries of `∂f/∂y` at `(t, y)` that
    /// [`jacobian_sparsity`](OdeSystem::jacobian_sparsity) names, column after column, each
    /// column's rows ascending ([`crate::Sparsity::column`]). Called only when
    /// [`has_sparse_jacobian`](OdeSystem::has_sparse_jacobian) returns `true`.
    fn sparse_jacobian(&self, t: f64, y: &[f64], values: &mut [f64]) {
        let _ = (t, y, values);
    }

    /// Kind of mass matrix (default: identity).
    fn mass_kind(&self) -> MassKind {
        MassKind::Identity
    }

    /// Writes `M(t, y)` into `m` (row-major, `n × n`). Called only when
    /// [`mass_kind`](OdeSystem::mass_kind) is not [`MassKind::Identity`].
    fn mass_matrix(&self, t: f64, y: &[f64], m: &mut [f64]) {
        let _ = (t, y, m);
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for &S {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        (**self).rhs(t, y, dydt)
    }
    fn rhs_batch(&self, t: f64, ys: &[f64], out: &mut [f64]) {
        (**self).rhs_batch(t, ys, out)
    }
    fn has_jacobian(&self) -> bool {
        (**self).has_jacobian()
    }
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        (**self).jacobian(t, y, jac)
    }
    fn jacobian_sparsity(&self) -> Option<std::sync::Arc<crate::Sparsity>> {
        (**self).jacobian_sparsity()
    }
    fn has_sparse_jacobian(&self) -> bool {
        (**self).has_sparse_jacobian()
    }
    fn sparse_jacobian(&self, t: f64, y: &[f64], values: &mut [f64]) {
        (**self).sparse_jacobian(t, y, values)
    }
    fn mass_kind(&self) -> MassKind {
        (**self).mass_kind()
    }
    fn mass_matrix(&self, t: f64, y: &[f64], m: &mut [f64]) {
        (**self).mass_matrix(t, y, m)
    }
}

/// A first-order system defined by a closure `f(t, y, dydt)`.
///
/// ```
/// use pdyn_ode::{FnSystem, OdeSystem};
/// let decay = FnSystem::new(1, |_t, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
/// let mut d = [0.0];
/// decay.rhs(0.0, &[2.0], &mut d);
/// assert_eq!(d[0], -2.0);
/// ```
pub struct FnSystem<F> {
    n: usize,
    f: F,
}

impl<F: Fn(f64, &[f64], &mut [f64])> FnSystem<F> {
    /// Wraps `f` as a system of dimension `n`.
    pub fn new(n: usize, f: F) -> Self {
        Self { n, f }
    }
}

impl<F: Fn(f64, &[f64], &mut [f64])> OdeSystem for FnSystem<F> {
    fn dim(&self) -> usize {
        self.n
    }
    #[inline]
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        (self.f)(t, y, dydt)
    }
}

/// A first-order system given by closures for `f` and its Jacobian `∂f/∂y` (row-major).
pub struct FnSystemWithJacobian<F, J> {
    n: usize,
    f: F,
    jac: J,
}

impl<F, J> FnSystemWithJacobian<F, J>
where
    F: Fn(f64, &[f64], &mut [f64]),
    J: Fn(f64, &[f64], &mut [f64]),
{
    /// Wraps `f` and its Jacobian `jac` as a system of dimension `n`.
    pub fn new(n: usize, f: F, jac: J) -> Self {
        Self { n, f, jac }
    }
}

impl<F, J> OdeSystem for FnSystemWithJacobian<F, J>
where
    F: Fn(f64, &[f64], &mut [f64]),
    J: Fn(f64, &[f64], &mut [f64]),
{
    fn dim(&self) -> usize {
        self.n
    }
    #[inline]
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        (self.f)(t, y, dydt)
    }
    fn has_jacobian(&self) -> bool {
        true
    }
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut [f64]) {
        (self.jac)(t, y, jac)
    }
}

/// A second-order system `q'' = a(t, q, v)` with `v = q'`, `q` of dimension
/// [`dim`](SecondOrderSystem::dim).
pub trait SecondOrderSystem {
    /// Number of coordinates `q` (the first-order form has `2 · dim` components).
    fn dim(&self) -> usize;

    /// Writes the acceleration `a(t, q, v)` into `acc`.
    fn accel(&self, t: f64, q: &[f64], v: &[f64], acc: &mut [f64]);

    /// `true` when `a` does not depend on `v` (a separable Hamiltonian, e.g. `T(p) + V(q)` with
    /// `T = |p|²/2`). The explicit symplectic methods (Verlet and its compositions) require it;
    /// the implicit Gauss–Legendre methods do not.
    fn separable(&self) -> bool;
}

/// A second-order system defined by a closure `a(t, q, v, acc)`.
pub struct FnSecondOrder<A> {
    n: usize,
    separable: bool,
    a: A,
}

impl<A: Fn(f64, &[f64], &[f64], &mut [f64])> FnSecondOrder<A> {
    /// Wraps `a` as a second-order system with `n` coordinates; `separable` as in
    /// [`SecondOrderSystem::separable`].
    pub fn new(n: usize, separable: bool, a: A) -> Self {
        Self { n, separable, a }
    }
}

impl<A: Fn(f64, &[f64], &[f64], &mut [f64])> SecondOrderSystem for FnSecondOrder<A> {
    fn dim(&self) -> usize {
        self.n
    }
    #[inline]
    fn accel(&self, t: f64, q: &[f64], v: &[f64], acc: &mut [f64]) {
        (self.a)(t, q, v, acc)
    }
    fn separable(&self) -> bool {
        self.separable
    }
}

/// The first-order form `y = (q, v)`, `y' = (v, a(t, q, v))` of a second-order system.
pub struct FirstOrderForm<'a, S: ?Sized>(pub &'a S);

impl<S: SecondOrderSystem + ?Sized> OdeSystem for FirstOrderForm<'_, S> {
    fn dim(&self) -> usize {
        2 * self.0.dim()
    }
    #[inline]
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let n = self.0.dim();
        let (q, v) = y.split_at(n);
        let (dq, dv) = dydt.split_at_mut(n);
        dq.copy_from_slice(v);
        self.0.accel(t, q, v, dv);
    }
}

/// The explicit form `y' = M(t, y)⁻¹ f(t, y)` of a system with a nonsingular mass matrix.
///
/// Each evaluation factorises `M(t, y)` (dense LU, workspace allocated once) and solves for
/// `y'`. The solvers apply it automatically to methods that need `M = I` and to Radau5 when
/// `M` depends on the state; a singular `M` yields NaN derivatives, which the solvers report
/// as [`crate::OdeError::NonFinite`] (use Radau5 with a constant `M` for DAEs).
pub struct MassInverse<'a, S: ?Sized> {
    sys: &'a S,
    work: std::cell::RefCell<(crate::linalg::Lu, Vec<f64>)>,
}

impl<'a, S: OdeSystem + ?Sized> MassInverse<'a, S> {
    /// Wraps `sys`.
    pub fn new(sys: &'a S) -> Self {
        let n = sys.dim();
        MassInverse {
            sys,
            work: std::cell::RefCell::new((crate::linalg::Lu::new(n), vec![0.0; n * n])),
        }
    }
}

impl<S: OdeSystem + ?Sized> OdeSystem for MassInverse<'_, S> {
    fn dim(&self) -> usize {
        self.sys.dim()
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let n = self.sys.dim();
        self.sys.rhs(t, y, dydt);
        let mut guard = self.work.borrow_mut();
        let (lu, m) = &mut *guard;
        self.sys.mass_matrix(t, y, m);
        let a = lu.matrix_mut();
        for i in 0..n {
            for j in 0..n {
                a[i + j * n] = m[i * n + j];
            }
        }
        if lu.factor().is_err() {
            dydt.fill(f64::NAN);
            return;
        }
        lu.solve_in_place(dydt);
    }
}
