//! Natural frequencies and mode shapes: the generalized eigenproblem `K φ = ω² M φ` of the
//! equations linearized at a state at rest ([`crate::linearization`]), dense.
//!
//! `M` is symmetric positive definite; with its Cholesky factor `M = L Lᵀ` the problem is the
//! symmetric `(L⁻¹ K L⁻ᵀ) ψ = ω² ψ`, `φ = L⁻ᵀ ψ`, whose eigenvalues are real and whose modes are
//! `M`-orthogonal. `K` is symmetrized first (its asymmetry, non-zero for non-conservative
//! forces such as a follower load, is reported).

use crate::linearization::Linearization;
use nalgebra::DMatrix;

/// Why the modes cannot be computed.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ModesError {
    /// `M` is not symmetric positive definite.
    MassNotPositiveDefinite,
    /// The sparse eigensolver failed ([`crate::sparse_statics::lowest_modes`]).
    Sparse(crate::lanczos::LanczosError),
}

impl std::fmt::Display for ModesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModesError::MassNotPositiveDefinite => write!(
                f,
                "the mass matrix is not symmetric positive definite at this state"
            ),
            ModesError::Sparse(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ModesError {}

/// One mode.
#[derive(Clone, Debug)]
pub struct Mode {
    /// `ω²` (negative: the state is unstable along this mode, which grows as `e^{√-ω² t}`).
    pub omega_squared: f64,
    /// `ω` in rad/s (NaN when `ω² < 0`).
    pub omega: f64,
    /// The shape, scaled so that its largest component is +1.
    pub shape: Vec<f64>,
    /// `φᵀ M φ` with that scaling.
    pub modal_mass: f64,
    /// `φᵀ K φ` with that scaling.
    pub modal_stiffness: f64,
}

/// The modes, lowest `ω²` first.
#[derive(Clone, Debug)]
pub struct Modes {
    /// Every mode.
    pub modes: Vec<Mode>,
    /// `max |K - Kᵀ| / max |K|`: zero for conservative forces.
    pub stiffness_asymmetry: f64,
}

/// The modes of `lin`.
pub fn modes(lin: &Linearization) -> Result<Modes, ModesError> {
    let m = &lin.mass;
    let k = &lin.stiffness;
    let kmax = k.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let asym = (k - k.transpose())
        .iter()
        .fold(0.0f64, |a, x| a.max(x.abs()));
    let mmax = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let masym = (m - m.transpose())
        .iter()
        .fold(0.0f64, |a, x| a.max(x.abs()));
    if masym > 1e-12 * mmax {
        return Err(ModesError::MassNotPositiveDefinite);
    }
    let ks = (k + k.transpose()) * 0.5;
    let ms = (m + m.transpose()) * 0.5;
    let chol = ms
        .clone()
        .cholesky()
        .ok_or(ModesError::MassNotPositiveDefinite)?;
    let l = chol.l();
    let n = m.nrows();
    // L⁻¹ K L⁻ᵀ: two triangular solves.
    let linv_k = l
        .solve_lower_triangular(&ks)
        .ok_or(ModesError::MassNotPositiveDefinite)?;
    let a = l
        .solve_lower_triangular(&linv_k.transpose())
        .ok_or(ModesError::MassNotPositiveDefinite)?;
    let a = (&a + a.transpose()) * 0.5;
    let eig = a.symmetric_eigen();
    let lt = l.transpose();
    let mut out: Vec<Mode> = Vec::with_capacity(n);
    for j in 0..n {
        let psi = eig.eigenvectors.column(j).into_owned();
        let mut phi = lt
            .solve_upper_triangular(&psi)
            .ok_or(ModesError::MassNotPositiveDefinite)?;
        let big = phi
            .iter()
            .copied()
            .fold(0.0f64, |b, x| if x.abs() > b.abs() { x } else { b });
        if big != 0.0 {
            phi /= big;
        }
        let modal_mass = (phi.transpose() * &ms * &phi)[(0, 0)];
        let modal_stiffness = (phi.transpose() * &ks * &phi)[(0, 0)];
        let w2 = eig.eigenvalues[j];
        out.push(Mode {
            omega_squared: w2,
            omega: if w2 >= 0.0 { w2.sqrt() } else { f64::NAN },
            shape: phi.iter().copied().collect(),
            modal_mass,
            modal_stiffness,
        });
    }
    out.sort_by(|a, b| a.omega_squared.total_cmp(&b.omega_squared));
    Ok(Modes {
        modes: out,
        stiffness_asymmetry: if kmax > 0.0 { asym / kmax } else { 0.0 },
    })
}

/// `M` and `K` as given, for callers that assemble their own (tests, other front ends).
pub fn modes_of(mass: DMatrix<f64>, stiffness: DMatrix<f64>) -> Result<Modes, ModesError> {
    let n = mass.nrows();
    modes(&Linearization {
        mass,
        stiffness,
        damping: DMatrix::zeros(n, n),
        force: nalgebra::DVector::zeros(n),
    })
}
