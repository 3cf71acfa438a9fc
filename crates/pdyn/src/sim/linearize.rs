//! The equations of motion linearized about an operating point: `δy' = A δy` with
//! `A = ∂f/∂y` at `(t, y₀)` (PyDy's `linearize` without inputs), from the compiled analytic
//! Jacobian when the model has one, else by central differences; and, for the state
//! `y = (q, q')`, the second-order form `δq'' + C δq' + K δq = 0` with `K = −∂q''/∂q` and
//! `C = −∂q''/∂q'` (the acceleration form: the mass matrix divided out).

use super::Prepared;
use pdyn_ode::OdeSystem;

/// A model linearized about one point.
#[derive(Clone, Debug)]
pub struct Linearization {
    /// State dimension `2n`.
    pub dim: usize,
    /// `A`, row-major `dim × dim`.
    pub a: Vec<f64>,
    /// `f(t, y₀)`: zero at an equilibrium (otherwise the linearization is about a point of a
    /// moving trajectory).
    pub f0: Vec<f64>,
    /// Whether `A` came from the analytic Jacobian (else central differences).
    pub analytic: bool,
}

impl Linearization {
    /// `K = −∂q''/∂q` and `C = −∂q''/∂q'`, each row-major `n × n`.
    pub fn stiffness_and_damping(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.dim / 2;
        let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
        for i in 0..n {
            for j in 0..n {
                k[i * n + j] = -self.a[(n + i) * self.dim + j];
                c[i * n + j] = -self.a[(n + i) * self.dim + n + j];
            }
        }
        (k, c)
    }
}

/// Linearizes `prep`'s equations about `(t, y0)`.
pub fn linearize(prep: &Prepared, t: f64, y0: &[f64]) -> Linearization {
    let sys = &prep.system;
    let dim = sys.dim();
    let mut f0 = vec![0.0; dim];
    sys.rhs(t, y0, &mut f0);
    let mut a = vec![0.0; dim * dim];
    let analytic = sys.has_jacobian();
    if analytic {
        sys.jacobian(t, y0, &mut a);
    } else {
        // Central differences with a step scaled to each component: error O(h²) ≈ 1e-10
        // relative for smooth right-hand sides.
        let (mut yp, mut ym) = (y0.to_vec(), y0.to_vec());
        let (mut fp, mut fm) = (vec![0.0; dim], vec![0.0; dim]);
        for j in 0..dim {
            let h = libm::cbrt(f64::EPSILON) * y0[j].abs().max(1.0);
            yp[j] = y0[j] + h;
            ym[j] = y0[j] - h;
            sys.rhs(t, &yp, &mut fp);
            sys.rhs(t, &ym, &mut fm);
            for i in 0..dim {
                a[i * dim + j] = (fp[i] - fm[i]) / (2.0 * h);
            }
            yp[j] = y0[j];
            ym[j] = y0[j];
        }
    }
    Linearization {
        dim,
        a,
        f0,
        analytic,
    }
}
