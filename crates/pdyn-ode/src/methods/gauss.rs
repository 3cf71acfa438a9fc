//! **Gauss–Legendre** implicit Runge–Kutta methods with 2 and 3 stages (orders 4 and 6).
//! Implicit, fixed step, symplectic for any Hamiltonian system (also non-separable), symmetric,
//! A-stable.
//!
//! Stages `Z_i = h Σ_j a_ij f(t + c_j h, y + Z_j)` are solved by fixed-point iteration
//! (suited to non-stiff Hamiltonian problems; Hairer, Lubich & Wanner, *Geometric Numerical
//! Integration*, §VIII.6): the iteration starts from `h Σ_j a_ij F_j` with the stage
//! derivatives `F_j` of the previous step and runs until the increment is at round-off level
//! (`‖ΔZ‖ ≤ 2ε max(1, ‖y‖)`, or it stops decreasing below `1e-13 max(1, ‖y‖)`), at most
//! 100 sweeps; then `y_1 = y + h Σ_i b_i F_i`. The
//! nodes `c_i` are the zeros of the shifted Legendre polynomial of degree `s`; order `2s`.
//!
//! J. C. Butcher, *Implicit Runge–Kutta processes*, Math. Comp. 18 (1964) 50–64;
//! symplecticity: Sanz-Serna, BIT 28 (1988) 877–883.

use crate::fixed::{FixedStepper, StepFailure};
use crate::problem::OdeSystem;
use crate::solution::Stats;
use crate::tableau::Tableau;

/// One-line description of Gauss 4.
pub const DOC_GAUSS4: &str = "Gauss-Legendre 2-stage implicit RK, order 4, symplectic for any \
Hamiltonian (also non-separable), fixed step h0, fixed-point iteration. Butcher 1964.";
/// One-line description of Gauss 6.
pub const DOC_GAUSS6: &str = "Gauss-Legendre 3-stage implicit RK, order 6, symplectic for any \
Hamiltonian (also non-separable), fixed step h0, fixed-point iteration. Butcher 1964.";

const S3: f64 = 1.732050807568877293527446341505872366942805253810380628055; // √3
const S15: f64 = 3.872983346207416885179265399782399600424268; // √15

/// Gauss–Legendre, 2 stages.
pub const GAUSS4: Tableau<2> = Tableau {
    a: [[0.25, 0.25 - S3 / 6.0], [0.25 + S3 / 6.0, 0.25]],
    b: [0.5, 0.5],
    b_hat: None,
    c: [0.5 - S3 / 6.0, 0.5 + S3 / 6.0],
    order: 4,
    embedded_order: 0,
    fsal: false,
};

/// Gauss–Legendre, 3 stages.
pub const GAUSS6: Tableau<3> = Tableau {
    a: [
        [5.0 / 36.0, 2.0 / 9.0 - S15 / 15.0, 5.0 / 36.0 - S15 / 30.0],
        [5.0 / 36.0 + S15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - S15 / 24.0],
        [5.0 / 36.0 + S15 / 30.0, 2.0 / 9.0 + S15 / 15.0, 5.0 / 36.0],
    ],
    b: [5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0],
    b_hat: None,
    c: [0.5 - S15 / 10.0, 0.5, 0.5 + S15 / 10.0],
    order: 6,
    embedded_order: 0,
    fsal: false,
};

/// Workspace of an `S`-stage Gauss method.
pub(crate) struct Gauss<const S: usize> {
    tab: &'static Tableau<S>,
    z: Vec<f64>,
    f: Vec<f64>,
    ys: Vec<f64>,
    have_f: bool,
}

impl<const S: usize> Gauss<S> {
    pub(crate) fn new(tab: &'static Tableau<S>, n: usize) -> Self {
        Gauss {
            tab,
            z: vec![0.0; S * n],
            f: vec![0.0; S * n],
            ys: vec![0.0; n],
            have_f: false,
        }
    }
}

impl<P: OdeSystem + ?Sized, const S: usize> FixedStepper<P> for Gauss<S> {
    fn step(
        &mut self,
        sys: &P,
        t: f64,
        y: &[f64],
        h: f64,
        y_new: &mut [f64],
        stats: &mut Stats,
    ) -> Result<(), StepFailure> {
        let n = y.len();
        let tab = self.tab;
        if !self.have_f {
            sys.rhs(t, y, &mut self.ys);
            stats.fevals += 1;
            for j in 0..S {
                self.f[j * n..(j + 1) * n].copy_from_slice(&self.ys);
            }
            self.have_f = true;
        }
        for i in 0..S {
            for k in 0..n {
                let mut acc = 0.0;
                for j in 0..S {
                    acc += tab.a[i][j] * self.f[j * n + k];
                }
                self.z[i * n + k] = h * acc;
            }
        }
        let scale = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let mut dz_prev = f64::INFINITY;
        let mut converged = false;
        for _ in 0..100 {
            for j in 0..S {
                for k in 0..n {
                    self.ys[k] = y[k] + self.z[j * n + k];
                }
                sys.rhs(t + tab.c[j] * h, &self.ys, &mut self.f[j * n..(j + 1) * n]);
            }
            stats.fevals += S;
            let mut dz: f64 = 0.0;
            for i in 0..S {
                for k in 0..n {
                    let mut acc = 0.0;
                    for j in 0..S {
                        acc += tab.a[i][j] * self.f[j * n + k];
                    }
                    let znew = h * acc;
                    dz = dz.max((znew - self.z[i * n + k]).abs());
                    self.z[i * n + k] = znew;
                }
            }
            if !dz.is_finite() {
                break;
            }
            if dz <= 2.0 * f64::EPSILON * scale || (dz >= dz_prev && dz <= 1e-13 * scale) {
                converged = true;
                break;
            }
            dz_prev = dz;
        }
        if !converged && dz_prev > 1e-12 * scale {
            return Err(StepFailure::NoConvergence);
        }
        for k in 0..n {
            let mut acc = 0.0;
            for j in 0..S {
                acc += tab.b[j] * self.f[j * n + k];
            }
            y_new[k] = y[k] + h * acc;
        }
        // Stage derivatives of this step seed the next one.
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::order_residual;

    #[test]
    fn tableaus_row_sums_and_order_conditions() {
        assert!(GAUSS4.row_sum_residual() < 1e-15);
        assert!(GAUSS6.row_sum_residual() < 1e-15);
        assert!(order_residual(&GAUSS4.a_rows(), &GAUSS4.b, 4) < 1e-15);
        assert!(order_residual(&GAUSS4.a_rows(), &GAUSS4.b, 5) > 1e-5);
        assert!(order_residual(&GAUSS6.a_rows(), &GAUSS6.b, 6) < 1e-15);
        assert!(order_residual(&GAUSS6.a_rows(), &GAUSS6.b, 7) > 1e-7);
    }

    #[test]
    fn symplecticity_condition_holds() {
        // b_i a_ij + b_j a_ji − b_i b_j = 0 (Sanz-Serna, Lasagni, Suris).
        for i in 0..3 {
            for j in 0..3 {
                let m = GAUSS6.b[i] * GAUSS6.a[i][j] + GAUSS6.b[j] * GAUSS6.a[j][i]
                    - GAUSS6.b[i] * GAUSS6.b[j];
                assert!(m.abs() < 1e-16);
            }
        }
    }
}
