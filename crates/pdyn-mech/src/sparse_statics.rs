//! Equilibrium and modes of large systems with sparse matrices: the same mathematics as
//! [`crate::equilibrium`] and [`crate::modes`], with `M`, `K`, `C` kept sparse
//! ([`crate::linearization::Linearizer::at_sparse`]) and every solve an envelope `L D Lᵀ`
//! ([`crate::sparse::EnvelopeLdlt`]): memory and work in proportion to `n b²` (`b` the
//! bandwidth after reverse Cuthill–McKee), where the dense path needs `n²` memory and `n³` work.
//!
//! - **Equilibrium**: Newton–Levenberg–Marquardt as in [`crate::equilibrium::solve`], each step
//!   `(K_s + μ D) δq = f` with `K_s = (K + Kᵀ)/2` (Newton's exact step for conservative forces,
//!   whose `K` is symmetric, taken where it lowers `|f|` or the energy; for others a
//!   quasi-Newton step, taken only where it lowers `|f|`: `damped_newton.rs`).
//! - **Modes**: the `count` lowest of `K_s φ = ω² M φ` by shift-invert Lanczos
//!   ([`crate::lanczos::nearest`], shift 0, or just below 0 when `K` is singular).
//! - **Free directions** (a mechanism, a neutral equilibrium): the eigenvectors of
//!   `K_s φ = λ D φ` with `|λ| ≤ 10⁻⁹ max_i |K_ii| / D_ii`, the lowest six looked at.

use crate::equilibrium::{EquilibriumError, EquilibriumOptions, FreeDirection};
use crate::lanczos::{nearest, LanczosError, LanczosOptions};
use crate::linearization::{Linearize, SparseLinearization};
use crate::modes::{Mode, Modes, ModesError};
use crate::sparse::{rcm, Csr, EnvelopeLdlt, SparseError};

/// Coordinates from which the front ends choose the sparse path by default: below it the
/// dense one (all modes, `O(n³)`) takes under half a second.
pub const SPARSE_FROM: usize = 300;

/// Modes the sparse path finds when no count is asked for.
pub const DEFAULT_SPARSE_COUNT: usize = 20;

/// An equilibrium found by [`solve`].
#[derive(Clone, Debug)]
pub struct SparseEquilibrium {
    /// The free coordinates at equilibrium.
    pub q: Vec<f64>,
    /// `|f|` there.
    pub residual: f64,
    /// The force scale the tolerance is relative to.
    pub scale: f64,
    /// Newton steps taken.
    pub steps: usize,
    /// The linearization there.
    pub linearization: SparseLinearization,
    /// Directions along which the equilibrium is neutral.
    pub neutral: Vec<FreeDirection>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The equilibrium nearest `start` (default: the initial values), sparse.
pub fn solve<L: Linearize + ?Sized>(
    lin: &L,
    start: Option<&[f64]>,
    opts: &EquilibriumOptions,
) -> Result<SparseEquilibrium, EquilibriumError> {
    let q: Vec<f64> = start.unwrap_or(lin.initial()).to_vec();
    let at = lin.at_sparse(&q);
    let kd = at.stiffness.diag();
    let stiff = kd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let length = q.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let scale = norm(&at.force).max(stiff * length).max(f64::MIN_POSITIVE);
    let target = opts.tolerance * scale;
    let diag: Vec<f64> = at
        .mass
        .diag()
        .iter()
        .map(|x| x.abs().max(f64::MIN_POSITIVE))
        .collect();
    let dmax = diag.iter().fold(0.0f64, |m, x| m.max(*x));
    let ratio = stiff.max(f64::MIN_POSITIVE) / dmax;
    let at = SparseAt::new(at);
    let ks = &at.ks;
    // One ordering for every step: the pattern of K + D does not change.
    let order = rcm(&ks.add(1.0, &Csr::diagonal(&diag), 1.0));
    let sparse = Sparse {
        lin,
        order,
        diag: &diag,
    };
    let end = crate::damped_newton::solve(&sparse, q, at, &diag, ratio, target, opts)?;
    let (q, SparseAt { at, ks }, residual, steps) = (end.q, end.at, end.residual, end.steps);
    let neutral = if opts.neutral {
        free_directions(lin.names(), &ks, &diag)
    } else {
        Vec::new()
    };
    Ok(SparseEquilibrium {
        q,
        residual,
        scale,
        steps,
        linearization: at,
        neutral,
    })
}

/// The sparse path of damped Newton: the symmetric part of `K`, by envelope `L D Lᵀ` in one
/// reverse Cuthill–McKee order.
struct Sparse<'a, L: ?Sized> {
    lin: &'a L,
    order: Vec<usize>,
    diag: &'a [f64],
}

/// A sparse linearization with the symmetric part of its stiffness.
struct SparseAt {
    at: SparseLinearization,
    ks: Csr,
}

impl SparseAt {
    fn new(at: SparseLinearization) -> SparseAt {
        let ks = symmetric_part(&at.stiffness);
        SparseAt { at, ks }
    }
}

impl<L: Linearize + ?Sized> crate::damped_newton::NewtonSystem for Sparse<'_, L> {
    type At = SparseAt;

    fn at(&self, q: &[f64]) -> SparseAt {
        SparseAt::new(self.lin.at_sparse(q))
    }

    fn residual(&self, at: &SparseAt) -> f64 {
        norm(&at.at.force)
    }

    fn step(&self, at: &SparseAt, damping: &[f64]) -> Option<Vec<f64>> {
        let a = at.ks.add(1.0, &Csr::diagonal(damping), 1.0);
        let f = EnvelopeLdlt::with_order(&a, self.order.clone()).ok()?;
        Some(f.solve(&at.at.force))
    }

    fn free_directions(&self, at: &SparseAt) -> Vec<FreeDirection> {
        free_directions(self.lin.names(), &at.ks, self.diag)
    }

    fn force(&self, q: &[f64]) -> Vec<f64> {
        self.lin.force(q)
    }

    fn conservative(&self, at: &SparseAt) -> bool {
        at.at.stiffness.asymmetry() <= crate::equilibrium::SYMMETRIC
    }
}

/// `(A + Aᵀ) / 2`.
pub fn symmetric_part(a: &Csr) -> Csr {
    a.add(0.5, &a.transpose(), 0.5)
}

/// The eigenvectors of `K_s φ = λ D φ` with `|λ|` at most 1e-9 of `max |K_ii| / D_ii`: among
/// the lowest six (or `n`).
pub fn free_directions(names: &[String], ks: &Csr, diag: &[f64]) -> Vec<FreeDirection> {
    let n = ks.n;
    let largest = (0..n).fold(0.0f64, |m, i| m.max((ks.get(i, i) / diag[i]).abs()));
    if largest == 0.0 {
        // No stiffness at all: every coordinate is free; name them one by one.
        return names
            .iter()
            .take(6)
            .map(|name| FreeDirection {
                components: vec![(name.clone(), 1.0)],
                moved: 1,
            })
            .collect();
    }
    let d = Csr::diagonal(diag);
    let opts = LanczosOptions {
        count: n.min(6),
        shift: -1e-7 * largest,
        ..LanczosOptions::default()
    };
    let Ok(pairs) = nearest(ks, &d, &opts) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (lambda, v) in pairs.values.iter().zip(&pairs.vectors) {
        if lambda.abs() > 1e-9 * largest {
            continue;
        }
        // Unit Euclidean length, as the dense path reports them.
        let len = norm(v);
        let v: Vec<f64> = v.iter().map(|x| x / len).collect();
        out.push(FreeDirection::of(&v, names));
    }
    out
}

/// The `count` lowest modes of `lin` by shift-invert Lanczos on the sparse `K_s`, `M`.
pub fn lowest_modes(lin: &SparseLinearization, count: usize) -> Result<Modes, ModesError> {
    let m = &lin.mass;
    let n = m.n;
    if m.asymmetry() > 1e-12 {
        return Err(ModesError::MassNotPositiveDefinite);
    }
    if m.diag().iter().any(|&d| d.is_nan() || d <= 0.0) {
        return Err(ModesError::MassNotPositiveDefinite);
    }
    let stiffness_asymmetry = lin.stiffness.asymmetry();
    let ks = symmetric_part(&lin.stiffness);
    let count = count.clamp(1, n);
    let mut opts = LanczosOptions {
        count,
        ..LanczosOptions::default()
    };
    let pairs = match nearest(&ks, m, &opts) {
        // K singular (a free body, a neutral direction): shift just below 0.
        Err(LanczosError::Factor(SparseError::SingularMatrix { .. })) => {
            let largest = (0..n).fold(0.0f64, |a, i| a.max((ks.get(i, i) / m.get(i, i)).abs()));
            opts.shift = -1e-7 * largest.max(f64::MIN_POSITIVE);
            nearest(&ks, m, &opts)
        }
        r => r,
    }
    .map_err(ModesError::Sparse)?;
    let mut modes = Vec::with_capacity(pairs.values.len());
    let mut kphi = vec![0.0; n];
    for (&w2, phi) in pairs.values.iter().zip(&pairs.vectors) {
        let big = phi
            .iter()
            .copied()
            .fold(0.0f64, |b, x| if x.abs() > b.abs() { x } else { b });
        let phi: Vec<f64> = if big != 0.0 {
            phi.iter().map(|x| x / big).collect()
        } else {
            phi.clone()
        };
        ks.mul_vec(&phi, &mut kphi);
        modes.push(Mode {
            omega_squared: w2,
            omega: if w2 >= 0.0 { w2.sqrt() } else { f64::NAN },
            modal_mass: m.form(&phi, &phi),
            modal_stiffness: phi.iter().zip(&kphi).map(|(a, b)| a * b).sum(),
            shape: phi,
            participation: [f64::NAN; 3],
            effective_mass: [f64::NAN; 3],
        });
    }
    Ok(Modes {
        modes,
        stiffness_asymmetry,
        total_mass: [f64::NAN; 3],
    })
}
