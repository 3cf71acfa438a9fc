//! The one error type of the statics commands (`pdyn equilibrium`, `pdyn modes`): a model
//! that cannot be linearized, an equilibrium that cannot be found, modes that cannot be
//! computed.

use crate::derive::DeriveError;
use crate::equilibrium::EquilibriumError;
use crate::linearization::LinearizationError;
use crate::modes::ModesError;

/// Why equilibrium or modes failed.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum StaticsError {
    /// The equations could not be derived.
    Derive(DeriveError),
    /// The equations could not be linearized.
    Linearization(LinearizationError),
    /// No equilibrium was found.
    Equilibrium(EquilibriumError),
    /// The eigenproblem could not be solved.
    Modes(ModesError),
    /// The damped modes could not be computed.
    Damped(crate::damped::DampedError),
}

impl std::fmt::Display for StaticsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StaticsError::Derive(e) => write!(f, "{e}"),
            StaticsError::Linearization(e) => write!(f, "{e}"),
            StaticsError::Equilibrium(e) => write!(f, "{e}"),
            StaticsError::Modes(e) => write!(f, "{e}"),
            StaticsError::Damped(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for StaticsError {}

impl From<DeriveError> for StaticsError {
    fn from(e: DeriveError) -> Self {
        StaticsError::Derive(e)
    }
}
impl From<LinearizationError> for StaticsError {
    fn from(e: LinearizationError) -> Self {
        StaticsError::Linearization(e)
    }
}
impl From<crate::lanczos::LanczosError> for StaticsError {
    fn from(e: crate::lanczos::LanczosError) -> Self {
        StaticsError::Modes(ModesError::Sparse(e))
    }
}
impl From<EquilibriumError> for StaticsError {
    fn from(e: EquilibriumError) -> Self {
        StaticsError::Equilibrium(e)
    }
}
impl From<crate::damped::DampedError> for StaticsError {
    fn from(e: crate::damped::DampedError) -> Self {
        StaticsError::Damped(e)
    }
}
impl From<ModesError> for StaticsError {
    fn from(e: ModesError) -> Self {
        StaticsError::Modes(e)
    }
}

/// Derives `model`'s equations as a run does (nothing simplified for printing) and compiles
/// their linearization.
pub fn linearize(
    model: &mut crate::Model,
) -> Result<(crate::Derivation, crate::linearization::Linearizer), StaticsError> {
    let opts = crate::DeriveOptions {
        simplify_printed: false,
        solve_budget: crate::derive::RUN_SOLVE_BUDGET,
        ..crate::DeriveOptions::default()
    };
    let d = crate::derive(model, &opts)?;
    let lin = crate::linearization::Linearizer::new(model, &d)?;
    Ok((d, lin))
}

/// The state `pdyn modes` and Python's `Model.modes` linearize about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum About {
    /// The static equilibrium nearest the initial values.
    Equilibrium,
    /// The initial values, at rest (whatever forces are out of balance there).
    Initial,
}

impl About {
    /// How the report names it.
    pub fn describe(self) -> &'static str {
        match self {
            About::Equilibrium => "static equilibrium",
            About::Initial => "initial state (at rest)",
        }
    }
}

/// Dense (every mode) or sparse (the lowest few).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Dense below [`crate::sparse_statics::SPARSE_FROM`] coordinates, sparse from there on.
    Auto,
    /// Every mode, dense matrices (`O(n³)`).
    Dense,
    /// The lowest `count` modes (default [`crate::sparse_statics::DEFAULT_SPARSE_COUNT`]) by
    /// shift-invert Lanczos.
    Sparse,
}

/// What modes to compute, as every front end asks for them.
#[derive(Clone, Debug)]
pub struct ModesRequest {
    /// The state.
    pub about: About,
    /// The solver.
    pub solver: Solver,
    /// The lowest `count` modes (all for the dense solver by default); at least 1.
    pub count: Option<usize>,
}

/// The modes of a model, ready to print or to hand to Python.
#[derive(Clone, Debug)]
pub struct ModesReport {
    /// The free coordinates, in the order of the shapes' components.
    pub names: Vec<String>,
    /// The state linearized about.
    pub about: About,
    /// Its free coordinates.
    pub q: Vec<f64>,
    /// `|f|` there.
    pub residual: f64,
    /// True when the sparse solver was used.
    pub sparse: bool,
    /// The modes, lowest first (`count` of them when asked).
    pub modes: crate::modes::Modes,
    /// The damped modes (as many, lowest `ωₙ` first), when there is damping: from the
    /// undamped modes when it is classical, else from the dense companion form for up to
    /// [`crate::damped::DAMPED_LIMIT`] coordinates.
    pub damped: Option<Vec<crate::damped::DampedMode>>,
    /// How the damped modes were found (`None` without damping).
    pub damped_path: Option<crate::damped::DampedPath>,
    /// `‖C M⁻¹ K x − K M⁻¹ C x‖ / (‖C M⁻¹ K x‖ + ‖K M⁻¹ C x‖)` on fixed probes
    /// ([`crate::classical_damping::commutation_defect`]); NaN without damping.
    pub commutation_defect: f64,
    /// True when `C ≠ 0`.
    pub has_damping: bool,
    /// `M`, `K`, `C` at the state.
    pub matrices: crate::linearization::SparseLinearization,
}

/// The modes of `model` as `request` asks: derivation, linearization, the state (equilibrium by
/// Newton, or the initial values), then the dense or the sparse eigenproblem, and the damped
/// modes where there is damping.
pub fn modes_about(
    model: &mut crate::Model,
    request: &ModesRequest,
) -> Result<ModesReport, StaticsError> {
    let (_, lin) = linearize(model)?;
    modes_of(&lin, request)
}

/// The modes of a linearized model as `request` asks ([`modes_about`] after the
/// linearization): the state, the dense or the sparse eigenproblem, the damped modes.
pub fn modes_of<L: crate::linearization::Linearize + ?Sized>(
    lin: &L,
    request: &ModesRequest,
) -> Result<ModesReport, StaticsError> {
    use crate::equilibrium::EquilibriumOptions;
    use crate::sparse_statics::{DEFAULT_SPARSE_COUNT, SPARSE_FROM};
    let n = lin.len();
    let sparse = match request.solver {
        Solver::Auto => n >= SPARSE_FROM,
        Solver::Dense => false,
        Solver::Sparse => true,
    };
    // The modes show neutral directions as zero frequencies: no separate search for them.
    let balance = EquilibriumOptions {
        neutral: false,
        ..EquilibriumOptions::default()
    };
    // The sparse equilibrium's linearization there is the one the modes need (the same
    // numbers as `at_sparse` at its `q`): not computed again.
    let (q, residual, found) = match request.about {
        About::Equilibrium if sparse => {
            let eq = crate::sparse_statics::solve(lin, None, &balance)?;
            (eq.q, eq.residual, Some(eq.linearization))
        }
        About::Equilibrium => {
            let eq = crate::equilibrium::solve(lin, None, &balance)?;
            (eq.q, eq.residual, None)
        }
        About::Initial => (lin.initial().to_vec(), f64::NAN, None),
    };
    let matrices = found.unwrap_or_else(|| lin.at_sparse(&q));
    let residual = if residual.is_nan() {
        matrices.force.iter().map(|x| x * x).sum::<f64>().sqrt()
    } else {
        residual
    };
    let has_damping = matrices.damping.val.iter().any(|&c| c != 0.0);
    let count = request.count.map(|c| c.max(1));
    let (mut modes, dense) = if sparse {
        let count = count.unwrap_or(DEFAULT_SPARSE_COUNT).min(n);
        (crate::sparse_statics::lowest_modes(&matrices, count)?, None)
    } else {
        let dense = lin.at(&q);
        (crate::modes::modes(&dense)?, Some(dense))
    };
    let inertia = lin.inertia_at(&q);
    match &dense {
        Some(d) => {
            let chol = d.mass.clone().cholesky();
            modes.add_participation(&inertia, |b| {
                let x = chol
                    .as_ref()?
                    .solve(&nalgebra::DVector::from_column_slice(b));
                Some(x.iter().copied().collect())
            });
        }
        None => {
            let ldl = crate::modes::factor_mass(&matrices.mass).ok();
            modes.add_participation(&inertia, |b| Some(ldl.as_ref()?.solve(b)));
        }
    }
    let shown = count.unwrap_or(modes.modes.len()).min(modes.modes.len());
    let (damped, damped_path, commutation_defect) = if has_damping {
        damped_of(&matrices, &modes.modes, dense.as_ref(), shown)?
    } else {
        (None, None, f64::NAN)
    };
    modes.modes.truncate(shown);
    Ok(ModesReport {
        names: lin.names().to_vec(),
        about: request.about,
        q,
        residual,
        sparse,
        modes,
        damped,
        damped_path,
        commutation_defect,
        has_damping,
        matrices,
    })
}

/// The damped modes (the `shown` lowest by `ωₙ`), how they were found and the damping's
/// relative commutator ([`crate::classical_damping::commutation_defect`]): from the undamped
/// `modes` when the damping is classical, else by the dense companion form up to
/// [`crate::damped::DAMPED_LIMIT`] coordinates, else none.
type DampedOf = (
    Option<Vec<crate::damped::DampedMode>>,
    Option<crate::damped::DampedPath>,
    f64,
);

fn damped_of(
    matrices: &crate::linearization::SparseLinearization,
    modes: &[crate::modes::Mode],
    dense: Option<&crate::linearization::Linearization>,
    shown: usize,
) -> Result<DampedOf, StaticsError> {
    use crate::classical_damping::{commutation_defect, from_undamped, is_classical};
    use crate::damped::{damped_modes, sort, DampedPath, DAMPED_LIMIT};
    let defect = commutation_defect(matrices);
    let classical = if is_classical(defect) {
        from_undamped(matrices, modes)
    } else {
        None
    };
    let (mut all, path) = match classical {
        Some(mut all) => {
            sort(&mut all);
            (all, DampedPath::Classical)
        }
        None if matrices.mass.n <= DAMPED_LIMIT => {
            let all = match dense {
                Some(d) => damped_modes(d)?,
                None => damped_modes(&matrices.to_dense())?,
            };
            (all, DampedPath::Companion)
        }
        None => return Ok((None, Some(DampedPath::NotComputed), defect)),
    };
    all.truncate(shown);
    Ok((Some(all), Some(path), defect))
}
