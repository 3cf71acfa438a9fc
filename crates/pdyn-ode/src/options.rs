//! Solver options (`rtol`, `atol`, `h0`, `max_step`, `max_steps`, `t_eval`, …) and the
//! parameters of the shared step-size controller.
//!
//! Names follow SciPy's `solve_ivp` and MATLAB's `odeset`. Every default is documented on its
//! field and set in the single `impl Default for Options`.

use crate::controller::Controller;
use crate::error::{invalid, OdeError};

/// Absolute or relative tolerance: one value for all components or one per component.
#[derive(Debug, Clone, PartialEq)]
pub enum Tolerance {
    /// The same tolerance for every component.
    Scalar(f64),
    /// One tolerance per component (length must equal the system dimension).
    PerComponent(Vec<f64>),
}

impl Tolerance {
    /// Tolerance of component `i`.
    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        match self {
            Tolerance::Scalar(v) => *v,
            Tolerance::PerComponent(v) => v[i],
        }
    }

    /// The smallest component (the value itself when scalar; infinity when empty).
    pub fn tightest(&self) -> f64 {
        match self {
            Tolerance::Scalar(v) => *v,
            Tolerance::PerComponent(v) => v.iter().copied().fold(f64::INFINITY, f64::min),
        }
    }

    pub(crate) fn check(&self, n: usize, name: &str) -> Result<Vec<f64>, OdeError> {
        let v: Vec<f64> = match self {
            Tolerance::Scalar(v) => vec![*v; n],
            Tolerance::PerComponent(v) => {
                if v.len() != n {
                    return Err(invalid(format!(
                        "{name} has {} components, the system {n}",
                        v.len()
                    )));
                }
                v.clone()
            }
        };
        if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(invalid(format!("{name} must be finite and non-negative")));
        }
        Ok(v)
    }
}

impl From<f64> for Tolerance {
    fn from(v: f64) -> Self {
        Tolerance::Scalar(v)
    }
}

impl From<Vec<f64>> for Tolerance {
    fn from(v: Vec<f64>) -> Self {
        Tolerance::PerComponent(v)
    }
}

/// What an explicit method does when its stiffness detector fires (Hairer's test
/// `h·|λ| > 3.25` for DOPRI5, `> 6.1` for DOP853, 15 times in a row, checked every
/// [`Options::stiffness_check_interval`] accepted steps).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StiffnessAction {
    /// Keep integrating (the count is still reported in [`crate::Stats::stiffness_detected_at`]).
    Ignore,
    /// Stop with [`crate::OdeError::Stiff`].
    Error,
}

/// Options shared by every method. Start from `Options::default()` and override fields.
///
/// ```
/// let opts = pdyn_ode::Options { rtol: 1e-8.into(), atol: 1e-10.into(), ..Default::default() };
/// assert_eq!(opts.max_steps, 1_000_000);
/// ```
#[derive(Debug, Clone)]
pub struct Options {
    /// Relative tolerance. Default `1e-6` (MATLAB's default is `1e-3`, which is often
    /// silently inaccurate).
    pub rtol: Tolerance,
    /// Absolute tolerance. Default `1e-9` (MATLAB: `1e-6`).
    pub atol: Tolerance,
    /// First step size (magnitude; the sign follows the integration direction). For adaptive
    /// methods `None` means Hairer's initial-step estimate; fixed-step methods require it and
    /// use `n = ceil(|tf − t0| / h0)` equal steps. Default `None`.
    pub h0: Option<f64>,
    /// Largest step size allowed (magnitude). Default `None` = `|tf − t0|`.
    pub max_step: Option<f64>,
    /// Maximum number of step attempts (accepted + rejected). Default `1_000_000`.
    pub max_steps: usize,
    /// Output times. `None` (default): output after every accepted step (and at `t0`).
    /// `Some(ts)`: output exactly at these times (monotone in the integration direction, within
    /// `[t0, tf]`), computed by each method's dense output.
    pub t_eval: Option<Vec<f64>>,
    /// Step-size controller parameters. `None` (default): the method's published defaults
    /// ([`Controller::dopri5`], [`Controller::dop853`], [`Controller::radau5`]).
    pub controller: Option<Controller>,
    /// Stiffness detection in the explicit methods: accepted steps between two checks
    /// (Hairer's `NSTIFF`). Default `1000`. Once a check fires the test runs at every step
    /// until it has failed 6 times in a row.
    pub stiffness_check_interval: usize,
    /// What to do when stiffness is detected. Default [`StiffnessAction::Ignore`]
    /// (`Method::Auto` switches to Radau5 regardless).
    pub on_stiffness: StiffnessAction,
    /// Record every accepted step's interpolant in [`crate::Solution::dense`] (the method's
    /// own continuous extension; DOP853 then spends its three extra stages on every step).
    /// Default `false`.
    pub dense_output: bool,
    /// Smallest step size allowed (magnitude) for the adaptive methods: steps are not made
    /// smaller (except the last one, which lands on `tf`), and a step of this size that fails
    /// its error test ends the solve with [`crate::OdeError::MinStep`]. Default `None`.
    pub min_step: Option<f64>,
    /// With `t_eval`, whether a terminal event's time and state are also output (after the
    /// requested times before it). Default `true`; SciPy's `solve_ivp` outputs exactly
    /// `t_eval` (`false`), the event being in [`crate::Solution::events`] either way.
    pub output_terminal_event: bool,
    /// A flag another thread may set to stop the integration (Ctrl-C in Python): checked
    /// before every step attempt; the solve then ends with [`OdeError::Interrupted`] and the
    /// partial solution. Default `None`.
    pub interrupt: Option<Interrupt>,
    /// Which entries of `∂f/∂y` may be nonzero (SciPy's `jac_sparsity`): the implicit
    /// methods' finite-difference Jacobians then perturb columns that share no row together,
    /// one evaluation of `f` per group of columns ([`crate::jacobian`]). Unused when the system
    /// has an analytic Jacobian. Default `None` (dense).
    pub jac_sparsity: Option<std::sync::Arc<crate::jacobian::Sparsity>>,
    /// How Radau5 and BDF solve their linear systems: dense LU, or sparse LU when the
    /// Jacobian's pattern is known ([`Options::jac_sparsity`] or
    /// [`crate::OdeSystem::jacobian_sparsity`]).
    /// Default [`LinearSolver::Auto`].
    pub linear_solver: LinearSolver,
}

/// How the implicit methods factor their iteration matrices (Radau5's `c·M − J`, BDF's
/// `I − c·J`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Sparse when the Jacobian's pattern is known, the mass matrix is the identity, the
    /// system has at least 200 components and no analytic Jacobian given only dense; dense
    /// otherwise.
    #[default]
    Auto,
    /// Dense LU with partial pivoting (radau5.f's DECSOL): `n²` memory, `n³/3` operations.
    Dense,
    /// Sparse LU on the pattern ([`crate::sparse_lu`]): nested-dissection order, no
    /// pivoting. Needs the pattern and the identity mass matrix.
    Sparse,
}

/// A stop request shared with the thread that may set it.
pub type Interrupt = std::sync::Arc<std::sync::atomic::AtomicBool>;

impl Options {
    /// Whether [`Options::interrupt`] has been set.
    pub(crate) fn interrupted(&self) -> bool {
        self.interrupt
            .as_ref()
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: Tolerance::Scalar(1e-6),
            atol: Tolerance::Scalar(1e-9),
            h0: None,
            max_step: None,
            max_steps: 1_000_000,
            t_eval: None,
            controller: None,
            stiffness_check_interval: 1000,
            on_stiffness: StiffnessAction::Ignore,
            dense_output: false,
            min_step: None,
            output_terminal_event: true,
            interrupt: None,
            jac_sparsity: None,
            linear_solver: LinearSolver::Auto,
        }
    }
}

impl Options {
    /// Options with `rtol = atol = tol`.
    pub fn with_tol(tol: f64) -> Self {
        Options {
            rtol: tol.into(),
            atol: tol.into(),
            ..Default::default()
        }
    }
}
