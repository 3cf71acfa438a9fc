//! Static equilibrium: the state at rest where every force balances, `f(q, 0) = 0`, found by
//! Newton's method with the exact Jacobian `-K` ([`crate::linearization`]), damped where the
//! structure is slack.
//!
//! A net released flat has no stiffness across its plane (its springs are at their natural
//! length), so the plain Newton step is undefined there. Each step solves
//! `(K + μ D) δq = f` with `D` the mass matrix's diagonal (Levenberg–Marquardt: for large `μ`
//! a short step along the forces, as damped dynamics would take; for `μ → 0` Newton's step),
//! `μ` shrinking tenfold after a step taken and growing tenfold after one refused; a step is
//! taken where it lowers `|f|` or, for conservative forces, the potential energy
//! (`damped_newton.rs`). Where `μ` must grow past any bound, no state balances the
//! forces: the stiffness is singular along the directions the forces push (a mechanism),
//! which are named.

use crate::damped_newton::TrialEnd;
use crate::linearization::{Linearization, Linearize};
use nalgebra::{DMatrix, DVector};

/// Knobs of [`solve`].
#[derive(Clone, Debug)]
pub struct EquilibriumOptions {
    /// Converged when `|f| <= tolerance * force scale` (Euclidean norm; the scale is the
    /// largest of `|f|` at the start and `max |K_ii| * max(|q0|, 1)`). Default 1e-12.
    pub tolerance: f64,
    /// Most steps. Default 200.
    pub max_steps: usize,
    /// Whether to look for the directions along which the equilibrium found is neutral
    /// ([`Equilibrium::neutral`]; an eigenproblem of its own). Default true; the modes skip it,
    /// since they show such directions as zero frequencies.
    pub neutral: bool,
}

impl Default for EquilibriumOptions {
    fn default() -> Self {
        EquilibriumOptions {
            tolerance: 1e-12,
            max_steps: 200,
            neutral: true,
        }
    }
}

/// A direction of free motion: the coordinates it moves, largest first, with their share.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeDirection {
    /// `(coordinate name, component)` of the unit vector, components below a tenth of the
    /// largest left out.
    pub components: Vec<(String, f64)>,
    /// How many coordinates the direction moves in all.
    pub moved: usize,
}

impl FreeDirection {
    /// The direction of the vector `v` over the coordinates `names`: its components of at
    /// least a tenth of the largest, largest first, signed so that the largest is positive
    /// (a stable report).
    pub fn of(v: &[f64], names: &[String]) -> FreeDirection {
        let big = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let sign = v
            .iter()
            .find(|x| x.abs() == big)
            .map_or(1.0, |x| x.signum());
        let mut components: Vec<(String, f64)> = v
            .iter()
            .zip(names)
            .filter(|(x, _)| x.abs() >= 0.1 * big)
            .map(|(&x, n)| (n.clone(), sign * x))
            .collect();
        components.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()).then(a.0.cmp(&b.0)));
        FreeDirection {
            moved: components.len(),
            components,
        }
    }
}

impl std::fmt::Display for FreeDirection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const SHOWN: usize = 6;
        let parts: Vec<String> = self
            .components
            .iter()
            .take(SHOWN)
            .map(|(n, c)| format!("{c:+.3} {n}"))
            .collect();
        write!(f, "{}", parts.join(" "))?;
        if self.moved > SHOWN {
            write!(f, " (and {} more coordinates)", self.moved - SHOWN)?;
        }
        Ok(())
    }
}

/// Why no equilibrium was found.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum EquilibriumError {
    /// The stiffness is singular along directions the forces push: no state at rest
    /// balances them (a free structure under load, a pin missing).
    Mechanism {
        /// The out-of-balance force left, `|f|`.
        residual: f64,
        /// The directions of free motion.
        directions: Vec<FreeDirection>,
    },
    /// Newton's method did not converge within the step limit.
    NotConverged {
        /// Steps taken.
        steps: usize,
        /// `|f|` at the end.
        residual: f64,
    },
}

impl std::fmt::Display for EquilibriumError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EquilibriumError::Mechanism {
                residual,
                directions,
            } => {
                write!(
                    f,
                    "no equilibrium: the structure is a mechanism (its stiffness is singular) \
                     and the forces push along its free motion (out-of-balance force {residual:.3e}); free direction"
                )?;
                if directions.len() > 1 {
                    write!(f, "s")?;
                }
                for (k, d) in directions.iter().enumerate() {
                    write!(f, "{} {d}", if k == 0 { ":" } else { ";" })?;
                }
                Ok(())
            }
            EquilibriumError::NotConverged { steps, residual } => write!(
                f,
                "Newton's method did not converge in {steps} steps (out-of-balance force \
                 {residual:.3e})"
            ),
        }
    }
}

impl std::error::Error for EquilibriumError {}

/// An equilibrium found.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    /// The free coordinates at equilibrium.
    pub q: Vec<f64>,
    /// `|f|` there (Euclidean norm of the out-of-balance generalized forces).
    pub residual: f64,
    /// The force scale the tolerance is relative to.
    pub scale: f64,
    /// Newton steps taken.
    pub steps: usize,
    /// The linearization there.
    pub linearization: Linearization,
    /// Directions along which the equilibrium is neutral (the stiffness is singular there,
    /// but no force pushes along them): the equilibrium is not unique.
    pub neutral: Vec<FreeDirection>,
}

fn max_abs(v: &DVector<f64>) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// The equilibrium nearest `start` (default: the initial values).
pub fn solve<L: Linearize + ?Sized>(
    lin: &L,
    start: Option<&[f64]>,
    opts: &EquilibriumOptions,
) -> Result<Equilibrium, EquilibriumError> {
    let n = lin.len();
    let q = DVector::from_column_slice(start.unwrap_or(lin.initial()));
    let at = lin.at(q.as_slice());
    let stiff = (0..n).fold(0.0f64, |m, i| m.max(at.stiffness[(i, i)].abs()));
    let length = max_abs(&q).max(1.0);
    let scale = at.force.norm().max(stiff * length).max(f64::MIN_POSITIVE);
    let target = opts.tolerance * scale;
    let diag: DVector<f64> = DVector::from_iterator(
        n,
        (0..n).map(|i| at.mass[(i, i)].abs().max(f64::MIN_POSITIVE)),
    );
    // μ is relative to K's scale over D's: μ = 1 makes the two comparable.
    let ratio = stiff.max(f64::MIN_POSITIVE) / diag.max();
    let dense = Dense(lin);
    let end = crate::damped_newton::solve(
        &dense,
        q.iter().copied().collect(),
        at,
        diag.as_slice(),
        ratio,
        target,
        opts,
    )?;
    let (q, at, residual, steps) = (end.q, end.at, end.residual, end.steps);
    let neutral = if opts.neutral {
        free_directions(lin.names(), &at.stiffness)
    } else {
        Vec::new()
    };
    Ok(Equilibrium {
        q,
        residual,
        scale,
        steps,
        linearization: at,
        neutral,
    })
}

/// The dense path of damped Newton: `K` as it is, solved by LU.
struct Dense<'a, L: ?Sized>(&'a L);

impl<L: Linearize + ?Sized> crate::damped_newton::NewtonSystem for Dense<'_, L> {
    type At = Linearization;
    type Trial = TrialEnd<Linearization>;

    fn trial(&self, q: &[f64]) -> Self::Trial {
        if self.0.force_alone() {
            TrialEnd::Force(self.0.force(q))
        } else {
            TrialEnd::Whole(self.0.at(q))
        }
    }

    fn trial_residual(&self, trial: &Self::Trial) -> f64 {
        match trial {
            // nalgebra's norm, as `residual` takes it of the linearization's `f`.
            TrialEnd::Force(f) => DVector::from_column_slice(f).norm(),
            TrialEnd::Whole(at) => at.force.norm(),
        }
    }

    fn taken(&self, q: &[f64], trial: Self::Trial) -> Linearization {
        match trial {
            // `f` again with the matrices (one evaluation of the loads, cheap where
            // `force_alone`; the dense path is for small systems): the same numbers.
            TrialEnd::Force(_) => self.0.at(q),
            TrialEnd::Whole(at) => at,
        }
    }

    fn residual(&self, at: &Linearization) -> f64 {
        at.force.norm()
    }

    fn step(&self, at: &Linearization, damping: &[f64]) -> Option<Vec<f64>> {
        let mut a = at.stiffness.clone();
        for (i, d) in damping.iter().enumerate() {
            a[(i, i)] += d;
        }
        a.lu()
            .solve(&at.force)
            .map(|dq| dq.iter().copied().collect())
    }

    fn free_directions(&self, at: &Linearization) -> Vec<FreeDirection> {
        free_directions(self.0.names(), &at.stiffness)
    }

    fn force(&self, q: &[f64]) -> Vec<f64> {
        self.0.force(q)
    }

    fn stiffness_mul(&self, at: &Linearization, v: &[f64]) -> Vec<f64> {
        (&at.stiffness * DVector::from_column_slice(v))
            .iter()
            .copied()
            .collect()
    }

    fn conservative(&self, at: &Linearization) -> bool {
        let k = &at.stiffness;
        let big = k.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = (0..k.nrows())
            .flat_map(|i| (0..i).map(move |j| (i, j)))
            .fold(0.0f64, |m, (i, j)| m.max((k[(i, j)] - k[(j, i)]).abs()));
        worst <= SYMMETRIC * big
    }
}

/// Asymmetry of `K` (relative to its largest entry) below which the forces are taken to derive
/// from a potential: round-off in entries computed from different expressions.
pub(crate) const SYMMETRIC: f64 = 1e-9;

/// The null space of the stiffness's symmetric part: eigenvectors whose eigenvalue is below
/// 1e-9 of the largest in magnitude.
pub fn free_directions(names: &[String], stiffness: &DMatrix<f64>) -> Vec<FreeDirection> {
    let sym = (stiffness + stiffness.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let largest = eig.eigenvalues.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut out = Vec::new();
    for (k, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda.abs() > 1e-9 * largest && largest > 0.0 {
            continue;
        }
        let v: Vec<f64> = eig.eigenvectors.column(k).iter().copied().collect();
        out.push(FreeDirection::of(&v, names));
    }
    out
}

/// The reactions of the supports holding the model's points (pins): minus the sum of the
/// forces the two-body forces put on each point, at rest at `q` (t = 0). Points no force
/// touches are left out. `state` is the state's symbols, coordinates then rates
/// ([`crate::Derivation::state`]).
pub fn support_reactions(
    model: &mut crate::Model,
    state: &[pdyn_expr::Id],
    q: &[f64],
) -> Result<Vec<(String, [f64; 3])>, crate::linearization::LinearizationError> {
    let mut names: Vec<String> = Vec::new();
    let mut sums: Vec<[pdyn_expr::Id; 3]> = Vec::new();
    for (name, _) in &model.points {
        let on: Vec<&crate::model::PointLoad> = model
            .point_loads
            .iter()
            .filter(|l| &l.point == name)
            .collect();
        if on.is_empty() {
            continue;
        }
        let mut total = [pdyn_expr::Pool::ZERO; 3];
        for l in on {
            for (c, t) in total.iter_mut().enumerate() {
                *t = model.pool.add(&[*t, l.force[c]]);
            }
        }
        names.push(name.clone());
        sums.push(total.map(|c| model.pool.neg(c)));
    }
    let outputs: Vec<pdyn_expr::Id> = sums.iter().flatten().copied().collect();
    let out = at_rest(model, state, q, &outputs)?;
    Ok(names
        .into_iter()
        .enumerate()
        .map(|(k, name)| (name, [out[3 * k], out[3 * k + 1], out[3 * k + 2]]))
        .collect())
}

/// The tension of every spring and damper ([`crate::model::AxialForce`]) at rest at `q`
/// (t = 0): a truss's bar forces, positive in tension. `state` as for [`support_reactions`].
pub fn axial_forces(
    model: &mut crate::Model,
    state: &[pdyn_expr::Id],
    q: &[f64],
) -> Result<Vec<(String, f64)>, crate::linearization::LinearizationError> {
    let outputs: Vec<pdyn_expr::Id> = model.axial.iter().map(|a| a.tension).collect();
    let out = at_rest(model, state, q, &outputs)?;
    Ok(model
        .axial
        .iter()
        .map(|a| a.label.clone())
        .zip(out)
        .collect())
}

/// `outputs` evaluated at rest at `q` (t = 0, rates zero), the parameters at their values.
fn at_rest(
    model: &mut crate::Model,
    state: &[pdyn_expr::Id],
    q: &[f64],
    outputs: &[pdyn_expr::Id],
) -> Result<Vec<f64>, crate::linearization::LinearizationError> {
    let p = &mut model.pool;
    let mut inputs = vec![p.time()];
    inputs.extend(state);
    inputs.extend(model.parameters.iter().map(|par| par.id));
    let prog = pdyn_expr::Program::compile(p, &inputs, outputs)
        .map_err(|e| crate::linearization::LinearizationError::Compile(e.to_string()))?;
    let n = state.len() / 2;
    let mut input = vec![0.0; inputs.len()];
    input[1..1 + n].copy_from_slice(q);
    for (k, par) in model.parameters.iter().enumerate() {
        input[1 + 2 * n + k] = par.value;
    }
    let mut ws = prog.workspace();
    let mut out = vec![0.0; outputs.len()];
    prog.eval(&input, &mut ws, &mut out);
    Ok(out)
}
