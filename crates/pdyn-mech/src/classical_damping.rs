//! Damped modes from the undamped ones, when the damping is classical.
//!
//! The linearized equations `M δq'' + C δq' + K δq = 0` (`M`, `K`, `C` symmetric) have the
//! undamped modes `K φ_j = ω_j² M φ_j` as their own modes exactly when `C` is diagonal in them,
//! which Caughey and O'Kelly (1965) showed is `C M⁻¹ K = K M⁻¹ C`: drag proportional to the
//! mass (`C = α M`, a net's or a chain's air drag), Rayleigh damping `C = α M + β K`, any
//! `C = M Σ a_k (M⁻¹ K)^k`. Then each mode is a single-degree-of-freedom oscillator
//! `η'' + c_j η' + ω_j² η = 0`, `c_j = φ_jᵀ C φ_j / φ_jᵀ M φ_j = 2 ζ_j ω_j`, whose roots are
//! `s = −ζ_j ω_j ± i ω_j √(1 − ζ_j²)` (two real roots when `ζ_j ≥ 1`, one of them 0 and the
//! other `−c_j` for a rigid-body mode): no `2n × 2n` companion eigenproblem at all.
//!
//! The test is numerical, with sparse products only: for two fixed probe vectors `x`,
//! `‖C M⁻¹ K x − K M⁻¹ C x‖ ≤` [`COMMUTATION_TOLERANCE`] `· (‖C M⁻¹ K x‖ + ‖K M⁻¹ C x‖)`
//! (`M⁻¹` by an envelope `L D Lᵀ`), with `K` and `C` symmetric to 1e-9. A nonzero
//! commutator is caught by a probe unless the probe lies in its null space, which fixed
//! irrational-looking probes do not for the matrices of a model.
//!
//! Each mode used is then checked on its own ([`from_undamped`]): `‖C φ − c M φ‖` small against
//! `‖|C| |φ|‖`. Where frequencies repeat (a symmetric net) any basis of the eigenspace is an
//! undamped basis, and classical damping need not be diagonal in the one the eigensolver
//! returned: such a cluster of modes is projected (`Vᵀ C V`, `Vᵀ K V` with `V` its
//! `M`-orthonormal shapes) and its small quadratic eigenproblem solved by its own companion
//! form, `2m × 2m` for `m` modes; it is exact when the cluster's span is invariant under
//! `M⁻¹ C`, which is checked the same way. A cluster cut by the number of modes computed fails
//! that check, and the caller falls back to the full companion form.

use crate::damped::DampedMode;
use crate::linearization::SparseLinearization;
use crate::modes::Mode;
use crate::sparse::Csr;
use nalgebra::DMatrix;

/// Largest relative commutator `‖C M⁻¹ K x − K M⁻¹ C x‖ / (‖C M⁻¹ K x‖ + ‖K M⁻¹ C x‖)` of
/// classical damping. Round-off leaves ~1e-15 for `C = α M + β K`; a damper on one particle
/// of a chain leaves order 1.
pub const COMMUTATION_TOLERANCE: f64 = 1e-8;

/// Largest relative residual `‖C φ − c M φ‖ / ‖|C| |φ|‖` of a mode (or of a cluster's span)
/// taken as a mode of the damped system: the undamped eigenvectors are accurate to about
/// 1e-10 relative; a mode that `C` mixes with another leaves order 1.
pub const MODE_TOLERANCE: f64 = 1e-7;

/// Modes whose `ω²` differ by at most this fraction (of the larger, or of 1e-9 of the largest
/// `|ω²|` for rigid-body modes) form one cluster.
pub const CLUSTER_GAP: f64 = 1e-6;

/// The relative commutator of `C M⁻¹` and `K M⁻¹` on two fixed probe vectors (see the module
/// documentation): infinite when `K` or `C` is not symmetric or `M` cannot be factored.
pub fn commutation_defect(lin: &SparseLinearization) -> f64 {
    let (m, k, c) = (&lin.mass, &lin.stiffness, &lin.damping);
    if k.asymmetry() > crate::equilibrium::SYMMETRIC
        || c.asymmetry() > crate::equilibrium::SYMMETRIC
    {
        return f64::INFINITY;
    }
    let Ok(mf) = crate::modes::factor_mass(m) else {
        return f64::INFINITY;
    };
    let n = m.n;
    let mut worst = 0.0f64;
    let mut t = vec![0.0; n];
    let mut a = vec![0.0; n];
    let mut b = vec![0.0; n];
    for probe in 0..2 {
        let x: Vec<f64> = (0..n)
            .map(|i| libm::sin(1.3 * i as f64 + 0.1 + 0.7 * probe as f64) + 0.25)
            .collect();
        // a = C M⁻¹ K x, b = K M⁻¹ C x.
        k.mul_vec(&x, &mut t);
        c.mul_vec(&mf.solve(&t), &mut a);
        c.mul_vec(&x, &mut t);
        k.mul_vec(&mf.solve(&t), &mut b);
        let diff = norm_diff(&a, &b);
        let size = norm(&a) + norm(&b);
        let defect = if size > 0.0 { diff / size } else { 0.0 };
        if !defect.is_finite() {
            return f64::INFINITY;
        }
        worst = worst.max(defect);
    }
    worst
}

/// Whether the damping of `lin` is classical: [`commutation_defect`] at most
/// [`COMMUTATION_TOLERANCE`].
pub fn is_classical(defect: f64) -> bool {
    defect <= COMMUTATION_TOLERANCE
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn norm_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `|A| |x|`, what the round-off of `A x` is proportional to.
fn abs_mul(a: &Csr, x: &[f64], y: &mut [f64]) {
    for (i, yi) in y.iter_mut().enumerate() {
        *yi = a.row(i).map(|(j, v)| (v * x[j]).abs()).sum();
    }
}

/// The roots of `s² + c s + w2 = 0` as damped modes: one of a complex pair, or both real
/// roots (computed without cancellation: `q = −(c + sign(c)√D)/2`, the roots `q` and
/// `w2 / q`).
fn roots(c: f64, w2: f64, out: &mut Vec<DampedMode>) {
    let d = c * c - 4.0 * w2;
    if d < 0.0 {
        out.push(DampedMode::of_root(-0.5 * c, 0.5 * (-d).sqrt()));
        return;
    }
    let q = -0.5 * (c + libm::copysign(d.sqrt(), c));
    out.push(DampedMode::of_root(q, 0.0));
    out.push(DampedMode::of_root(
        if q != 0.0 { w2 / q } else { 0.0 },
        0.0,
    ));
}

/// The damped modes of `lin` that the undamped `modes` (any scaling of their shapes, `ω²`
/// from `K φ = ω² M φ`) give when the damping is classical: per mode the roots of
/// `s² + c s + ω² = 0`, per cluster of repeated frequencies its projected quadratic
/// eigenproblem. `None` when a mode (or a cluster's span) is not a mode of the damped system
/// to [`MODE_TOLERANCE`]: the damping is not classical on these modes.
pub fn from_undamped(lin: &SparseLinearization, modes: &[Mode]) -> Option<Vec<DampedMode>> {
    let (m, c) = (&lin.mass, &lin.damping);
    let n = m.n;
    let mut mphi = vec![0.0; n];
    let mut cphi = vec![0.0; n];
    let mut scale = vec![0.0; n];
    // Per mode: c_j, and whether φ_j is a mode of the damped system on its own.
    let mut single: Vec<(f64, bool)> = Vec::with_capacity(modes.len());
    for mode in modes {
        let phi = &mode.shape;
        m.mul_vec(phi, &mut mphi);
        c.mul_vec(phi, &mut cphi);
        abs_mul(c, phi, &mut scale);
        let mu = dot(phi, &mphi);
        if mu.is_nan() || mu <= 0.0 {
            return None;
        }
        let cj = dot(phi, &cphi) / mu;
        let residual = cphi
            .iter()
            .zip(&mphi)
            .map(|(a, b)| (a - cj * b) * (a - cj * b))
            .sum::<f64>()
            .sqrt();
        single.push((cj, residual <= MODE_TOLERANCE * norm(&scale)));
    }
    let largest = modes
        .iter()
        .fold(0.0f64, |a, md| a.max(md.omega_squared.abs()));
    let floor = 1e-9 * largest;
    let mut out = Vec::with_capacity(modes.len() + 2);
    let mut start = 0;
    while start < modes.len() {
        let mut end = start + 1;
        while end < modes.len() {
            let (a, b) = (modes[end - 1].omega_squared, modes[end].omega_squared);
            if (a - b).abs() > CLUSTER_GAP * a.abs().max(b.abs()).max(floor) {
                break;
            }
            end += 1;
        }
        if single[start..end].iter().all(|s| s.1) {
            for (md, &(cj, _)) in modes[start..end].iter().zip(&single[start..end]) {
                roots(cj, md.omega_squared, &mut out);
            }
        } else {
            cluster(lin, &modes[start..end], &mut out)?;
        }
        start = end;
    }
    Some(out)
}

/// The damped modes of one cluster of undamped modes, by its projected quadratic eigenproblem
/// `(s² I + s Vᵀ C V + Vᵀ K V) y = 0`, `V` the cluster's shapes made `M`-orthonormal; `None`
/// when `C V` leaves the span of `M V`.
fn cluster(lin: &SparseLinearization, modes: &[Mode], out: &mut Vec<DampedMode>) -> Option<()> {
    let (m, k, c) = (&lin.mass, &lin.stiffness, &lin.damping);
    let n = m.n;
    let size = modes.len();
    // Gram–Schmidt in the M inner product, twice for orthogonality to round-off.
    let mut v: Vec<Vec<f64>> = Vec::with_capacity(size);
    let mut mv: Vec<Vec<f64>> = Vec::with_capacity(size);
    for mode in modes {
        let mut x = mode.shape.clone();
        let mut mx = vec![0.0; n];
        for _ in 0..2 {
            for (u, mu) in v.iter().zip(&mv) {
                let p = dot(&x, mu);
                for (xi, ui) in x.iter_mut().zip(u) {
                    *xi -= p * ui;
                }
            }
        }
        m.mul_vec(&x, &mut mx);
        let len = dot(&x, &mx).sqrt();
        if len.is_nan() || len <= 0.0 {
            return None;
        }
        x.iter_mut().for_each(|xi| *xi /= len);
        mx.iter_mut().for_each(|xi| *xi /= len);
        v.push(x);
        mv.push(mx);
    }
    let mut cv = vec![vec![0.0; n]; size];
    let mut kv = vec![vec![0.0; n]; size];
    let mut scale = vec![0.0; n];
    let mut cr = DMatrix::zeros(size, size);
    let mut kr = DMatrix::zeros(size, size);
    for j in 0..size {
        c.mul_vec(&v[j], &mut cv[j]);
        k.mul_vec(&v[j], &mut kv[j]);
    }
    for i in 0..size {
        for j in 0..size {
            cr[(i, j)] = 0.5 * (dot(&v[i], &cv[j]) + dot(&v[j], &cv[i]));
            kr[(i, j)] = 0.5 * (dot(&v[i], &kv[j]) + dot(&v[j], &kv[i]));
        }
    }
    // C V = M V C_r on the span: the residual of each column against |C| |v_j|.
    for j in 0..size {
        let mut r = cv[j].clone();
        for (i, mvi) in mv.iter().enumerate() {
            let a = cr[(i, j)];
            for (ri, x) in r.iter_mut().zip(mvi) {
                *ri -= a * x;
            }
        }
        abs_mul(c, &v[j], &mut scale);
        if norm(&r) > MODE_TOLERANCE * norm(&scale) {
            return None;
        }
    }
    let mut a = DMatrix::zeros(2 * size, 2 * size);
    for i in 0..size {
        a[(i, size + i)] = 1.0;
        for j in 0..size {
            a[(size + i, j)] = -kr[(i, j)];
            a[(size + i, size + j)] = -cr[(i, j)];
        }
    }
    out.extend(
        a.complex_eigenvalues()
            .iter()
            .filter(|s| s.im >= 0.0)
            .map(|s| DampedMode::of_root(s.re, s.im)),
    );
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_roots_of_an_overdamped_mode_are_real_and_their_product_is_omega_squared() {
        let mut out = Vec::new();
        roots(10.0, 9.0, &mut out);
        let mut r: Vec<f64> = out.iter().map(|d| d.re).collect();
        r.sort_by(f64::total_cmp);
        assert_eq!(r, vec![-9.0, -1.0]);
        // A rigid-body mode with damping: s = 0 and s = −c.
        out.clear();
        roots(2.0, 0.0, &mut out);
        let mut r: Vec<f64> = out.iter().map(|d| d.re).collect();
        r.sort_by(f64::total_cmp);
        assert_eq!(r, vec![-2.0, 0.0]);
    }
}
