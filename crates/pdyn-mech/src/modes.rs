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
    /// The shape, scaled so that its largest component is ±1, and +1 for the first (lowest
    /// index) of the components within 1e-9 of the largest in magnitude ([`unit_largest`]).
    pub shape: Vec<f64>,
    /// `φᵀ M φ` with that scaling.
    pub modal_mass: f64,
    /// `φᵀ K φ` with that scaling.
    pub modal_stiffness: f64,
    /// Participation factor along x, y, z: `Γ_d = φᵀ M r_d / φᵀ M φ`, how much a ground
    /// acceleration along `e_d` excites this mode ([`Modes::add_participation`]; NaN until
    /// then). Its sign follows the shape's.
    pub participation: [f64; 3],
    /// Effective modal mass along x, y, z: `(φᵀ M r_d)² / φᵀ M φ`, independent of the shape's
    /// scaling; over all modes they add up to [`Modes::total_mass`].
    pub effective_mass: [f64; 3],
}

/// The modes, lowest `ω²` first.
#[derive(Clone, Debug)]
pub struct Modes {
    /// Every mode.
    pub modes: Vec<Mode>,
    /// `max |K - Kᵀ| / max |K|`: zero for conservative forces.
    pub stiffness_asymmetry: f64,
    /// The mass that moves with a rigid translation along x, y, z: `(M r_d)ᵀ M⁻¹ (M r_d)`,
    /// the sum of every mode's effective mass (NaN until [`Modes::add_participation`]).
    /// The share the modes found carry of it says whether enough were computed (the
    /// structural engineer's 90 % rule).
    pub total_mass: [f64; 3],
}

impl Modes {
    /// Fills each mode's participation factors and effective masses and the total mass
    /// along x, y, z, from `M r_d` ([`crate::linearization::Linearizer::inertia_at`]) and
    /// `solve_mass(b) = M⁻¹ b`.
    pub fn add_participation(
        &mut self,
        inertia: &[Vec<f64>; 3],
        solve_mass: impl Fn(&[f64]) -> Option<Vec<f64>>,
    ) {
        for (d, b) in inertia.iter().enumerate() {
            self.total_mass[d] = if b.iter().all(|&x| x == 0.0) {
                0.0
            } else {
                solve_mass(b).map_or(f64::NAN, |x| dot(b, &x))
            };
            for m in &mut self.modes {
                let l = dot(&m.shape, b);
                m.participation[d] = l / m.modal_mass;
                m.effective_mass[d] = l * l / m.modal_mass;
            }
        }
    }
}

/// Scales a mode shape so that its largest component in magnitude is ±1, with the sign that
/// makes the first component within 1e-9 (relative) of that magnitude +1. An eigenvector's
/// sign is arbitrary; taking the largest component's would let round-off decide it whenever
/// two components tie in magnitude, as in every antisymmetric mode of a symmetric structure
/// (the uniform chain's even modes: `φ_i = −φ_{n+1−i}`), so that the same model printed
/// opposite shapes from two builds. Ties go to the lowest index instead. A zero vector is left
/// as it is.
pub fn unit_largest(phi: &mut [f64]) {
    let big = phi.iter().fold(0.0f64, |b, x| b.max(x.abs()));
    if big == 0.0 || !big.is_finite() {
        return;
    }
    let tie = big * (1.0 - 1e-9);
    let first = phi.iter().copied().find(|x| x.abs() >= tie).unwrap_or(big);
    // Without a tie, `first` is the largest component itself and this divides by it.
    let scale = if first < 0.0 { -big } else { big };
    for x in phi.iter_mut() {
        *x /= scale;
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `M = L D Lᵀ` for the participation factors and the damping's commutator: a diagonal `M`
/// (free particles in Cartesian coordinates) in its own order, without the reverse
/// Cuthill–McKee pass (linear in `n` since issue 33's third session, but still a search per
/// one-vertex component); any order gives a diagonal matrix the same pivots, so the factor is
/// the one [`EnvelopeLdlt::new`] would make.
pub(crate) fn factor_mass(
    m: &crate::sparse::Csr,
) -> Result<crate::sparse::EnvelopeLdlt, crate::sparse::SparseError> {
    let diagonal = (0..m.n).all(|i| m.row(i).all(|(j, _)| j == i));
    if diagonal {
        crate::sparse::EnvelopeLdlt::with_order(m, (0..m.n).collect())
    } else {
        crate::sparse::EnvelopeLdlt::new(m)
    }
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
        unit_largest(phi.as_mut_slice());
        let modal_mass = (phi.transpose() * &ms * &phi)[(0, 0)];
        let modal_stiffness = (phi.transpose() * &ks * &phi)[(0, 0)];
        let w2 = eig.eigenvalues[j];
        out.push(Mode {
            omega_squared: w2,
            omega: if w2 >= 0.0 { w2.sqrt() } else { f64::NAN },
            shape: phi.iter().copied().collect(),
            modal_mass,
            modal_stiffness,
            participation: [f64::NAN; 3],
            effective_mass: [f64::NAN; 3],
        });
    }
    out.sort_by(|a, b| a.omega_squared.total_cmp(&b.omega_squared));
    Ok(Modes {
        modes: out,
        stiffness_asymmetry: if kmax > 0.0 { asym / kmax } else { 0.0 },
        total_mass: [f64::NAN; 3],
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
