//! Damped modes: the quadratic eigenproblem `(s² M + s C + K) φ = 0` of the linearized
//! equations `M δq'' + C δq' + K δq = 0`, through its first-order companion form
//!
//! ```text
//! z' = A z,   z = [δq; δq'],   A = [ 0        I      ]
//!                                  [ −M⁻¹K   −M⁻¹C  ]
//! ```
//!
//! whose `2n` eigenvalues `s` are those of the pencil (dense real Schur form, `O(n³)`: for up
//! to [`DAMPED_LIMIT`] coordinates). A mode that oscillates is a conjugate pair
//! `s = −ζ ωₙ ± i ωₙ √(1 − ζ²)`: natural frequency `ωₙ = |s|`, damping ratio `ζ = −Re s / |s|`,
//! damped frequency `ω_d = Im s`; one of each pair (`Im s > 0`) is reported. A real `s` is a
//! motion that decays (or grows, `s > 0`) without oscillating: `e^{s t}`.
//!
//! When the damping is classical the companion form is not needed: the undamped modes give
//! the damped ones ([`crate::classical_damping`]); [`DampedPath`] says which way they were
//! found.

use crate::linearization::Linearization;
use nalgebra::DMatrix;

/// Most coordinates the dense companion form is built for (a `2n × 2n` matrix).
pub const DAMPED_LIMIT: usize = 1000;

/// Why damped modes could not be computed.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum DampedError {
    /// `M` is singular.
    SingularMass,
    /// More coordinates than [`DAMPED_LIMIT`].
    TooLarge {
        /// Coordinates.
        coordinates: usize,
    },
}

impl std::fmt::Display for DampedError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DampedError::SingularMass => write!(f, "the mass matrix is singular"),
            DampedError::TooLarge { coordinates } => write!(
                f,
                "damped modes are computed densely, for at most {DAMPED_LIMIT} coordinates \
                 ({coordinates} here)"
            ),
        }
    }
}

impl std::error::Error for DampedError {}

/// One root `s` of `det(s² M + s C + K) = 0` (of a conjugate pair, the one with `Im s > 0`).
#[derive(Clone, Debug, PartialEq)]
pub struct DampedMode {
    /// `Re s` (1/s): the decay rate is `−Re s`.
    pub re: f64,
    /// `Im s` = the damped frequency `ω_d` (rad/s), 0 for a motion that does not oscillate.
    pub im: f64,
    /// `ωₙ = |s|` (rad/s).
    pub omega_n: f64,
    /// `ζ = −Re s / |s|` (1 for a real negative root, NaN for `s = 0`).
    pub damping_ratio: f64,
    /// True for a conjugate pair (an oscillation).
    pub oscillatory: bool,
}

impl DampedMode {
    /// The mode of the root `s = re + i im` (`im ≥ 0`): `im` within 1e-10 of `|s|` of zero is
    /// a real root, a motion that does not oscillate.
    pub fn of_root(re: f64, im: f64) -> DampedMode {
        let omega_n = libm::hypot(re, im);
        let oscillatory = im > 1e-10 * omega_n.max(f64::MIN_POSITIVE);
        DampedMode {
            re,
            im: if oscillatory { im } else { 0.0 },
            omega_n,
            damping_ratio: if omega_n > 0.0 {
                -re / omega_n
            } else {
                f64::NAN
            },
            oscillatory,
        }
    }
}

/// How the damped modes were found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DampedPath {
    /// Classical damping (`C M⁻¹ K = K M⁻¹ C`): from the undamped modes computed, one
    /// single-degree-of-freedom oscillator each ([`crate::classical_damping`]).
    Classical,
    /// Every root of the dense `2n × 2n` companion form ([`damped_modes`]).
    Companion,
    /// Not computed: the damping is not classical and there are more than [`DAMPED_LIMIT`]
    /// coordinates.
    NotComputed,
}

impl DampedPath {
    /// The name `--json` and Python give it.
    pub fn name(self) -> &'static str {
        match self {
            DampedPath::Classical => "classical",
            DampedPath::Companion => "companion",
            DampedPath::NotComputed => "not_computed",
        }
    }

    /// One line saying how the damped modes were found.
    pub fn describe(self) -> String {
        match self {
            DampedPath::Classical => format!(
                "classical damping (C M⁻¹K = K M⁻¹C to {:.0e}): each undamped mode computed is a \
                 damped mode, s² + (φᵀCφ/φᵀMφ) s + ω² = 0",
                crate::classical_damping::COMMUTATION_TOLERANCE
            ),
            DampedPath::Companion => {
                "non-classical damping: every root of the dense 2n × 2n companion form".to_string()
            }
            DampedPath::NotComputed => format!(
                "not computed: the damping is not classical (C M⁻¹K ≠ K M⁻¹C) and the companion \
                 form is dense, for at most {DAMPED_LIMIT} coordinates"
            ),
        }
    }
}

/// The damped modes of `lin`, by increasing `ωₙ`.
pub fn damped_modes(lin: &Linearization) -> Result<Vec<DampedMode>, DampedError> {
    let n = lin.mass.nrows();
    if n > DAMPED_LIMIT {
        return Err(DampedError::TooLarge { coordinates: n });
    }
    let lu = lin.mass.clone().lu();
    let minv_k = lu.solve(&lin.stiffness).ok_or(DampedError::SingularMass)?;
    let minv_c = lu.solve(&lin.damping).ok_or(DampedError::SingularMass)?;
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -minv_k[(i, j)];
            a[(n + i, n + j)] = -minv_c[(i, j)];
        }
    }
    let mut out: Vec<DampedMode> = a
        .complex_eigenvalues()
        .iter()
        .filter(|s| s.im >= 0.0)
        .map(|s| DampedMode::of_root(s.re, s.im))
        .collect();
    sort(&mut out);
    Ok(out)
}

/// By increasing `ωₙ`, then `Re s`.
pub fn sort(modes: &mut [DampedMode]) {
    modes.sort_by(|x, y| x.omega_n.total_cmp(&y.omega_n).then(x.re.total_cmp(&y.re)));
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    #[test]
    fn one_degree_of_freedom_matches_the_textbook() {
        // m x'' + c x' + k x = 0: ωₙ = √(k/m), ζ = c / (2√(k m)).
        let (m, c, k) = (2.0, 3.0, 50.0);
        let lin = Linearization {
            mass: DMatrix::from_element(1, 1, m),
            stiffness: DMatrix::from_element(1, 1, k),
            damping: DMatrix::from_element(1, 1, c),
            force: DVector::zeros(1),
        };
        let modes = damped_modes(&lin).unwrap();
        assert_eq!(modes.len(), 1);
        let wn = (k / m).sqrt();
        let zeta = c / (2.0 * (k * m).sqrt());
        assert!((modes[0].omega_n - wn).abs() < 1e-13 * wn);
        assert!((modes[0].damping_ratio - zeta).abs() < 1e-13);
        assert!((modes[0].im - wn * (1.0 - zeta * zeta).sqrt()).abs() < 1e-13 * wn);
    }

    #[test]
    fn an_overdamped_oscillator_decays_at_two_real_rates() {
        // s = (−c ± √(c² − 4 k m)) / (2 m).
        let (m, c, k) = (1.0, 10.0, 9.0);
        let lin = Linearization {
            mass: DMatrix::from_element(1, 1, m),
            stiffness: DMatrix::from_element(1, 1, k),
            damping: DMatrix::from_element(1, 1, c),
            force: DVector::zeros(1),
        };
        let modes = damped_modes(&lin).unwrap();
        let rates: Vec<f64> = modes.iter().map(|d| d.re).collect();
        assert_eq!(modes.len(), 2);
        assert!(modes.iter().all(|d| !d.oscillatory));
        assert!(
            (rates[0] + 1.0).abs() < 1e-13 && (rates[1] + 9.0).abs() < 1e-13,
            "{rates:?}"
        );
    }
}
