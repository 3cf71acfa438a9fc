//! Derivation of the equations of motion (chapter 3.3.1, steps 2–7).
//!
//! For every particle: `r` (from the model), `v = dr/dt`, `a = dv/dt` by the chain rule; the
//! resultant force `F` of every load on it (and on the massless frame carrying it). Then
//! - **Newton form**: `m a − F = 0`, three components per particle (identically zero ones
//!   dropped); `ΣM = 0` about the particle for each massless frame; `d²f/dt² = 0` for each
//!   constraint `f(q, t) = 0`. Unknowns: the free coordinates' second derivatives and every
//!   reaction. The equations are linear in them: `A x = b`, solved exactly when small
//!   (so `q'' = …` and the reactions print as formulas), numerically at evaluation time
//!   otherwise.
//! - **Projected (Kane) form**: `Σ_p (m_p a_p − F_p)·∂r_p/∂q_j = 0` for each free coordinate
//!   `q_j`, i.e. `M(q) q'' = f(q, q', t)` with `M_jk = Σ_p m_p ∂r_p/∂q_j·∂r_p/∂q_k`. Workless
//!   reactions (rod tensions, normal forces of fixed smooth guides) drop out, so they need not be
//!   declared; it is the form used when the Newton equations outnumber their unknowns.

use crate::model::{CoordinateKind, Model, Target};
use pdyn_expr::linsolve::{LinearError, LinearSystem};
use pdyn_expr::{vector, Id, Pool};
use rustc_hash::FxHashMap;

/// Which set of equations to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Form {
    /// Newton's equations when they are square, the projected form when they outnumber the
    /// unknowns (undeclared workless reactions).
    #[default]
    Auto,
    /// F = m a per particle, reactions as unknowns.
    Newton,
    /// `M(q) q'' = f`, reactions eliminated by projection.
    Projected,
}

/// Knobs of [`derive`].
#[derive(Clone, Debug)]
pub struct DeriveOptions {
    /// Which equations to build. Default: [`Form::Auto`].
    pub form: Form,
    /// Largest number of unknowns eliminated symbolically; larger systems are solved
    /// numerically when evaluated. Default: 6.
    pub symbolic_limit: usize,
    /// Simplify printed expressions (velocities, forces, solutions). Default: true.
    pub simplify: bool,
    /// Simplify what only printing reads: the equations of motion ([`Derivation::equations`];
    /// the linear system and its solution are formed before) and the particles'
    /// accelerations. A run turns this off: on a 16-link chain it was 95 % of `pdyn run`'s
    /// time. Default: true.
    pub simplify_printed: bool,
    /// Work budget of exact elimination (polynomial term operations): past it `A x = b` is
    /// solved numerically at each evaluation and printed by reference. Default
    /// [`CHEAP_SOLVE_BUDGET`]; `pdyn derive --solve` uses [`FULL_SOLVE_BUDGET`].
    pub solve_budget: u64,
    /// Count the simplification of the exact solution against
    /// [`DeriveOptions::solve_budget`] too: past it, no exact solution (`A x = b` is solved
    /// numerically), as when the elimination alone is over it. For a caller that prints the
    /// solution, like `pdyn derive`, whose cost then grows with the system. Default false:
    /// the solution found within the budget is simplified whatever that costs (a run
    /// evaluates it).
    pub simplify_solution_within_budget: bool,
    /// From how many free coordinates a model whose particles form a tree of links
    /// ([`crate::tree`]) is derived in the recursive form ([`Derivation::tree`]: `O(n)` per
    /// evaluation, no `M` assembled) instead of the projected `M q'' = f`. `None` (the
    /// default): never here, as `pdyn derive` prints `M`; `pdyn::sim::prepare` reads `None`
    /// as [`TREE_FROM`] for models without contacts (`Some(usize::MAX)` keeps the dense `M`).
    pub tree_from: Option<usize>,
}

/// The number of free coordinates from which a run solves a tree of links recursively.
/// Measured per evaluation on the n-link chain (release, `pdyn run` at the example's
/// settings): the dense path assembles `n²` entries and factors `M` (Cholesky, `n³/6`), the
/// recursion costs ~110 operations per link plus the link's own expressions; below 4 links
/// the dense form is as cheap and the 2- and 3-link examples keep their exact numbers.
pub const TREE_FROM: usize = 4;

impl Default for DeriveOptions {
    fn default() -> Self {
        DeriveOptions {
            form: Form::Auto,
            symbolic_limit: 6,
            simplify: true,
            simplify_printed: true,
            solve_budget: CHEAP_SOLVE_BUDGET,
            simplify_solution_within_budget: false,
            tree_from: None,
        }
    }
}

/// A model whose equations cannot be formed or solved.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct DeriveError {
    /// What is wrong, naming the coordinates, reactions or equations involved.
    pub message: String,
    /// What to do about it.
    pub help: Option<String>,
    /// Line and column (1-based) in the model file of the declaration at fault (a
    /// constraint), when there is one.
    pub location: Option<(u32, u32)>,
}

impl std::fmt::Display for DeriveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.message)?;
        if let Some(h) = &self.help {
            write!(f, "\n  = help: {h}")?;
        }
        Ok(())
    }
}

impl std::error::Error for DeriveError {}

impl DeriveError {
    /// An error about the model as a whole (no declaration at fault), with what to do.
    pub fn new(message: impl Into<String>, help: impl Into<String>) -> DeriveError {
        DeriveError {
            message: message.into(),
            help: Some(help.into()),
            location: None,
        }
    }
}

fn derr(message: impl Into<String>, help: impl Into<String>) -> DeriveError {
    DeriveError {
        message: message.into(),
        help: Some(help.into()),
        location: None,
    }
}

/// Position, velocity, acceleration and resultant force of one particle.
#[derive(Clone, Debug)]
pub struct ParticleKinematics {
    /// Name.
    pub name: String,
    /// Mass.
    pub mass: Id,
    /// Position.
    pub r: [Id; 3],
    /// Velocity.
    pub v: [Id; 3],
    /// Acceleration.
    pub a: [Id; 3],
    /// Resultant force (including loads on its massless frame).
    pub force: [Id; 3],
}

/// One scalar equation `lhs = rhs`.
#[derive(Clone, Debug)]
pub struct Equation {
    /// Where it comes from: `sat: F = ma, x`, `bike: ΣM = 0, z`, `constraint yA + yB = c`.
    pub label: String,
    /// Left side (e.g. `m*x''`).
    pub lhs: Id,
    /// Right side (e.g. the force component).
    pub rhs: Id,
}

/// What an unknown is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnknownKind {
    /// Second derivative of the free coordinate with this index in [`Model::coordinates`].
    Acceleration(usize),
    /// The reaction with this index in [`Model::reactions`].
    Reaction(usize),
}

/// An unknown of the linear system.
#[derive(Clone, Debug)]
pub struct Unknown {
    /// Printed name (`x''`, `N`).
    pub name: String,
    /// The leaf expression.
    pub id: Id,
    /// Acceleration or reaction.
    pub kind: UnknownKind,
}

/// The equations of motion of a model, ready to print or compile.
#[derive(Clone, Debug)]
pub struct Derivation {
    /// The form actually used.
    pub form: Form,
    /// Per particle kinematics and forces.
    pub particles: Vec<ParticleKinematics>,
    /// The equations (Newton or projected), `lhs = rhs`.
    pub equations: Vec<Equation>,
    /// Unknowns, in column order of `system`.
    pub unknowns: Vec<Unknown>,
    /// `A x = b` in the unknowns, entries functions of state and time.
    pub system: LinearSystem,
    /// Exact solution, one simplified expression per unknown, when the system was small.
    pub solution: Option<Vec<Id>>,
    /// Indices (into [`Model::coordinates`]) of the free coordinates, in state order.
    pub free: Vec<usize>,
    /// State leaves `w = [q_1..q_n, q_1'..q_n']`.
    pub state: Vec<Id>,
    /// Printable names of the state entries.
    pub state_names: Vec<String>,
    /// Notes for the user (form chosen and why).
    pub notes: Vec<String>,
    /// Declared reactions that the projected form eliminated, recovered from F = m a with the
    /// accelerations substituted: `(name, expression of the state)`.
    pub recovered: Vec<(String, Id)>,
    /// Whether `system` was assembled collected and contracted term by term (the projected
    /// form, derived for reading): its entries need only to be collected to print.
    pub assembled_collected: bool,
    /// Whether a given `acceleration` entered as an equation `q'' = a` (a prescribed motion):
    /// then what drives it does work, and no quantity is known to be conserved.
    pub prescribed_acceleration: bool,
    /// The recursive form of a tree of links ([`DeriveOptions::tree_from`]): when set,
    /// `equations` and `system` are empty and the accelerations are
    /// [`crate::tree::TreeForm::solve`]'s.
    pub tree: Option<crate::tree::TreeForm>,
}

impl Derivation {
    /// `q''` of each free coordinate, when solved exactly.
    pub fn accelerations(&self) -> Option<Vec<Id>> {
        let sol = self.solution.as_ref()?;
        Some(
            self.unknowns
                .iter()
                .zip(sol)
                .filter(|(u, _)| matches!(u.kind, UnknownKind::Acceleration(_)))
                .map(|(_, &s)| s)
                .collect(),
        )
    }

    /// `(name, expression)` of each reaction, when solved exactly.
    pub fn reactions(&self) -> Option<Vec<(String, Id)>> {
        let sol = self.solution.as_ref()?;
        Some(
            self.unknowns
                .iter()
                .zip(sol)
                .filter(|(u, _)| matches!(u.kind, UnknownKind::Reaction(_)))
                .map(|(u, &s)| (u.name.clone(), s))
                .collect(),
        )
    }
}

/// Work budget (polynomial term operations) of exact elimination on request (`pdyn derive
/// --solve`): the linear solver's own default.
pub const FULL_SOLVE_BUDGET: u64 = 4_000_000;
/// Default work budget of exact elimination: enough for every shipped example (the 2- and
/// 3-link chains included, whose mass matrices are contracted for reading), not for longer
/// chains, whose elimination took most of `pdyn derive` (0.05 s of it at n = 4, when n = 8
/// took 0.01 s) and gave explicit forms printed by reference anyway. It was 200,000; no
/// example needed more than 20,000.
pub const CHEAP_SOLVE_BUDGET: u64 = 20_000;
/// Work budget of exact elimination and of simplifying its result together
/// ([`DeriveOptions::simplify_solution_within_budget`]) for `pdyn derive` without `--solve`.
/// The budget is work actually done (polynomial term operations, about 0.25 µs each), not a
/// predicted size: small classic systems are solved by default. Measured minimum budgets:
/// the double pendulum in Newton form (4 unknowns: two angles, two rod tensions) 26,383
/// units, the 2-link chain in projected form 8,810. The 3-link chain needs 129,873: it
/// gives up here after 40,000 units and is printed by reference (`--solve` solves it); that
/// attempt took its `pdyn derive` from 15.8 to 55.8 million instructions (callgrind). It was 10,000, under which the double pendulum in
/// Newton form printed `(A⁻¹ b)_1` (issue 34).
pub const PRINT_SOLVE_BUDGET: u64 = 40_000;
/// Work budget of exact elimination for a run, which only evaluates the result: a closed
/// form pays off when it is found quickly (one or two unknowns, Newton's equations with a
/// few reactions); past this, `A x = b` solved numerically at each evaluation is cheaper
/// than eliminating, then compiling the large result and its Jacobian. The 3- to 6-link
/// chains spent 30–60 ms of a 40–60 ms `pdyn run` eliminating; numerically they take
/// 10 ms or less, so the run's time now grows with `n`.
pub const RUN_SOLVE_BUDGET: u64 = 20_000;

fn simp(p: &mut Pool, e: Id, on: bool) -> Id {
    if on && p.tree_size(e, 4001) <= 4000 {
        p.simplify(e)
    } else {
        e
    }
}

/// Every particle's kinematics and resultant force, Newton's equations `m a = F` (components
/// that are identically `0 = 0` dropped) with the frames' `ΣM = 0`, and the constraints
/// differentiated twice. Shared by [`derive`] and `pdyn forces`.
pub fn newton_equations(
    model: &mut Model,
) -> (Vec<ParticleKinematics>, Vec<Equation>, Vec<Equation>) {
    let p = &mut model.pool;
    // Kinematics and resultant forces.
    let mut parts = Vec::with_capacity(model.particles.len());
    for (i, pt) in model.particles.iter().enumerate() {
        let r = pt.position;
        let v = r.map(|c| p.dt(c));
        let a = v.map(|c| p.dt(c));
        let mut f = [Pool::ZERO; 3];
        for load in &model.loads {
            let on_it = match &load.target {
                Target::Particle(j) => *j == i,
                Target::Frame { frame, .. } => model.frames[*frame].particle == i,
            };
            if on_it {
                f = vector::add(p, f, load.force);
            }
        }
        parts.push(ParticleKinematics {
            name: pt.name.clone(),
            mass: pt.mass,
            r,
            v,
            a,
            force: f,
        });
    }

    // Newton's equations, frame moments, constraints.
    let axes = ["x", "y", "z"];
    let mut newton: Vec<Equation> = Vec::new();
    for pk in &parts {
        for (c, axis) in axes.iter().enumerate() {
            let lhs = p.mul2(pk.mass, pk.a[c]);
            if lhs == Pool::ZERO && pk.force[c] == Pool::ZERO {
                continue;
            }
            newton.push(Equation {
                label: format!("{}: F = ma, {axis}", pk.name),
                lhs,
                rhs: pk.force[c],
            });
        }
    }
    for (j, fr) in model.frames.iter().enumerate() {
        let rp = parts[fr.particle].r;
        let mut m = [Pool::ZERO; 3];
        for load in &model.loads {
            if let Target::Frame { frame, at } = &load.target {
                if *frame == j {
                    let arm = vector::sub(p, *at, rp);
                    let mo = vector::cross(p, arm, load.force);
                    m = vector::add(p, m, mo);
                }
            }
        }
        for (c, &mc) in m.iter().enumerate() {
            if mc != Pool::ZERO {
                newton.push(Equation {
                    label: format!(
                        "{}: ΣM = 0 about {}, {}",
                        fr.name, model.particles[fr.particle].name, axes[c]
                    ),
                    lhs: Pool::ZERO,
                    rhs: mc,
                });
            }
        }
    }
    let mut constraint_eqs = Vec::new();
    for c in &model.constraints {
        let acc = p.dt_n(c.equation, c.derivatives);
        let how = if c.derivatives == 1 { "once" } else { "twice" };
        constraint_eqs.push(Equation {
            label: format!("constraint {} (differentiated {how})", c.label),
            lhs: acc,
            rhs: Pool::ZERO,
        });
    }

    (parts, newton, constraint_eqs)
}

/// Derives the equations of motion of `model` (its pool grows with the new expressions).
pub fn derive(model: &mut Model, opts: &DeriveOptions) -> Result<Derivation, DeriveError> {
    let free: Vec<usize> = model
        .coordinates
        .iter()
        .enumerate()
        .filter(|(_, c)| matches!(c.kind, CoordinateKind::Free { .. }))
        .map(|(i, _)| i)
        .collect();
    let p = &mut model.pool;
    let q: Vec<Id> = free
        .iter()
        .map(|&i| p.coord(model.coordinates[i].sym, 0))
        .collect();
    let qd: Vec<Id> = free
        .iter()
        .map(|&i| p.coord(model.coordinates[i].sym, 1))
        .collect();
    let qdd: Vec<Id> = free
        .iter()
        .map(|&i| p.coord(model.coordinates[i].sym, 2))
        .collect();
    let mut state = q.clone();
    state.extend(&qd);
    let mut state_names: Vec<String> = free
        .iter()
        .map(|&i| model.coordinates[i].name.clone())
        .collect();
    state_names.extend(
        free.iter()
            .map(|&i| format!("{}'", model.coordinates[i].name)),
    );

    let (mut parts, newton, mut constraint_eqs) = newton_equations(model);
    // A tree of links (a chain, a mobile) in a run: the accelerations are found link by link
    // in O(n) per evaluation, so the projected M (n² entries, factored at every evaluation)
    // is not assembled at all. Newton's equations outnumber the unknowns there (no reactions
    // declared), so `Form::Auto` would have chosen the projected form.
    // One unknown per free coordinate's acceleration, whichever form is built.
    let acc_unknowns: Vec<Unknown> = free
        .iter()
        .zip(&qdd)
        .map(|(&i, &id)| Unknown {
            name: format!("{}''", model.coordinates[i].name),
            id,
            kind: UnknownKind::Acceleration(i),
        })
        .collect();
    if let Some(from) = opts.tree_from {
        if free.len() >= from
            && matches!(opts.form, Form::Auto | Form::Projected)
            && newton.len() > free.len()
        {
            if let Some(tree) = crate::tree::detect(model, &parts, &free, &qd) {
                let p = &mut model.pool;
                for pk in parts.iter_mut() {
                    pk.v = pk.v.map(|c| simp(p, c, opts.simplify));
                    pk.force = pk.force.map(|c| simp(p, c, opts.simplify));
                }
                return Ok(Derivation {
                    form: Form::Projected,
                    particles: parts,
                    equations: Vec::new(),
                    unknowns: acc_unknowns,
                    system: LinearSystem {
                        unknowns: qdd,
                        a: Vec::new(),
                        b: Vec::new(),
                    },
                    solution: None,
                    free,
                    state,
                    state_names,
                    notes: vec![format!(
                        "the particles form a tree of {} links: the accelerations are solved link \
                         by link (articulated-body recursion), without assembling M",
                        tree.len()
                    )],
                    recovered: Vec::new(),
                    assembled_collected: false,
                    prescribed_acceleration: false,
                    tree: Some(tree),
                });
            }
        }
    }
    let newton_all = newton.clone();
    let p = &mut model.pool;
    let mut notes = Vec::new();
    // A free coordinate given an `acceleration` (a motion prescribed at an instant, as `pdyn
    // forces` reads it: a bar turning at constant rate, a tablecloth pulled at `a`) whose
    // Newton equations are too few for the reactions: the given acceleration is one more
    // equation, `q'' = a`, so the reactions are solved as functions of the state. (When the
    // equations are enough, they determine `q''` themselves, as on the banked curve.)
    let n_before = newton.len() + constraint_eqs.len();
    let n_unknowns_before = qdd.len() + model.reactions.len();
    let mut given_equations = false;
    if n_before < n_unknowns_before && !model.known_accelerations.is_empty() {
        let mut given = Vec::new();
        for &(ci, acc) in &model.known_accelerations {
            let Some(k) = free.iter().position(|&f| f == ci) else {
                continue;
            };
            let name = &model.coordinates[ci].name;
            constraint_eqs.push(Equation {
                label: format!("{name}'' given (the model's `acceleration`)"),
                lhs: qdd[k],
                rhs: acc,
            });
            given.push(format!("{name}''"));
        }
        if !given.is_empty() {
            given_equations = true;
            notes.push(format!(
                "the motion is prescribed: {} given by the model (`acceleration = ...`) is an equation, \
                 not a result; the reactions follow from it (`pdyn forces` evaluates them at the instant, with the model's checks)",
                given.join(", ")
            ));
        }
    }

    let reaction_unknowns: Vec<Unknown> = model
        .reactions
        .iter()
        .enumerate()
        .map(|(k, r)| Unknown {
            name: r.name.clone(),
            id: r.id,
            kind: UnknownKind::Reaction(k),
        })
        .collect();

    let n_newton = newton.len() + constraint_eqs.len();
    let n_unknowns = acc_unknowns.len() + reaction_unknowns.len();
    let form = match opts.form {
        Form::Auto
            if n_newton > n_unknowns
                && model.constraints.is_empty()
                && model.frames.is_empty()
                && !given_equations =>
        {
            notes.push(format!(
                "Newton's equations ({n_newton}) outnumber their unknowns ({n_unknowns}): the undeclared \
                 reactions are taken as workless and eliminated by projection (Kane's method)"
            ));
            Form::Projected
        }
        Form::Auto => Form::Newton,
        other => other,
    };

    // In the projected form without working reactions, `M` and `f` are built directly,
    // collected (and, for reading, contracted) as they are assembled.
    let contract = opts.simplify && opts.simplify_printed;
    let mut direct: Option<LinearSystem> = None;
    let (equations, unknowns) = match form {
        Form::Projected => {
            if !model.constraints.is_empty() || !model.frames.is_empty() {
                return Err(derr(
                    "the projected form needs independent coordinates: this model has constraints or massless frames",
                    "use the Newton form (--form newton)",
                ));
            }
            let crate::projection::Projected {
                equations: eqs,
                mass,
                forcing,
            } = crate::projection::projected(
                p,
                &parts,
                &qd,
                &qdd,
                &free,
                &model.coordinates,
                &model.reactions,
                contract,
            );
            // Reactions that survive projection do work: they stay unknown and need equations.
            let mut unk: Vec<Unknown> = acc_unknowns;
            for ru in reaction_unknowns {
                if eqs.iter().any(|e| p.contains(e.rhs, ru.id)) {
                    unk.push(ru);
                }
            }
            if unk.len() == qdd.len() {
                direct = Some(LinearSystem {
                    unknowns: qdd.clone(),
                    a: mass,
                    b: forcing,
                });
            }
            (eqs, unk)
        }
        _ => {
            let mut eqs = newton;
            eqs.extend(constraint_eqs);
            let mut unk = acc_unknowns;
            unk.extend(reaction_unknowns);
            (eqs, unk)
        }
    };

    let assembled = direct.is_some();
    let (equations, system) = match direct {
        Some(sys) => (equations, sys),
        None => linear_form(p, equations, &unknowns)?,
    };
    let residual_count = system.rows();
    // A diagonal A (each equation has one unknown: a building's floors, a chain of masses on
    // springs) is solved exactly whatever its size: x_i = b_i / a_ii, as short as b. (Small
    // systems go through the general elimination, as before, for the same printed forms.)
    // So is a diagonal A whose rows come in another order than the unknowns (particles in
    // Cartesian coordinates declared coordinate family by family, `x[i,j]` then `y[i,j]`:
    // row `P[0,1]: x` holds `x[0,1]''` alone, row `P[0,1]: y` holds `y[0,1]''`): equation i
    // gives unknown `column[i]`. Solving that A by LU at every step made a 400-particle net's
    // set-up compile a dense 1,200 x 1,200 matrix.
    let m = unknowns.len();
    let diagonal_columns = if m > opts.symbolic_limit && residual_count == m {
        permuted_diagonal(&system.a, m)
    } else {
        None
    };
    let diagonal = diagonal_columns.is_some();

    let solution = if let Some(column) = &diagonal_columns {
        // Not simplified: a rational normal form would put an N-body force sum over one
        // common denominator, whose powers of masses and distances overflow in SI units.
        let mut x = vec![Pool::ZERO; m];
        for (i, &j) in column.iter().enumerate() {
            x[j] = p.div(system.b[i], system.a[i * m + j]);
        }
        Some(x)
    } else if m <= opts.symbolic_limit || residual_count > m {
        // Exact elimination only when it is cheap (a few reactions, a double pendulum):
        // otherwise A x = b is solved numerically at each evaluation. On the 4-link chain the
        // exact solution took 3 s of a 3.1 s `pdyn run` (elimination, then compiling its large
        // expressions and their Jacobian) and printed unreadable 37 KB lines.
        let solved = if opts.simplify_solution_within_budget {
            p.solve_linear_within(&system, true, opts.solve_budget)
        } else {
            p.solve_linear_budgeted(&system, true, opts.solve_budget)
        };
        match solved {
            Ok(sol) => Some(sol.into_iter().map(|s| simp(p, s, opts.simplify)).collect()),
            Err(LinearError::Underdetermined { free }) => {
                let names: Vec<String> = free.iter().map(|&f| p.to_text(f)).collect();
                if let Some(e) = crate::constraint_rank::dependent_constraint(model) {
                    return Err(e);
                }
                return Err(derr(
                    format!("the equations do not determine {}", names.join(", ")),
                    "the system is singular: look for a missing constraint or a reaction with no independent equation",
                ));
            }
            Err(LinearError::Inconsistent { equation }) => {
                if let Some(e) = crate::constraint_rank::dependent_constraint(model) {
                    return Err(e);
                }
                return Err(derr(
                    format!(
                        "equation `{}` contradicts the others",
                        equations[equation].label
                    ),
                    "more equations than unknowns: a reaction may be missing",
                ));
            }
            Err(_) => None,
        }
    } else {
        None
    };

    // For reading: an exact solution in two or more angles, written in their differences
    // when that is shorter (the double pendulum's denominator `L1*(m1 + m2*sin(th1 - th2)^2)`
    // rather than five expanded products). A run does not print it and skips this.
    // Then what all terms of a numerator or denominator share is taken out, as a textbook
    // writes it (one pass over the terms, no expansion).
    let solution = match solution {
        Some(sol) if opts.simplify && opts.simplify_printed && !diagonal => {
            let mut left = DIFFERENCE_BUDGET;
            Some(
                sol.into_iter()
                    .map(|s| {
                        let s = if q.len() >= 2 {
                            in_differences(p, s, &q, &mut left)
                        } else {
                            s
                        };
                        factor_quotient(p, s)
                    })
                    .collect(),
            )
        }
        other => other,
    };

    for pk in parts.iter_mut() {
        pk.v = pk.v.map(|c| simp(p, c, opts.simplify));
        pk.a =
            pk.a.map(|c| simp(p, c, opts.simplify && opts.simplify_printed));
        pk.force = pk.force.map(|c| simp(p, c, opts.simplify));
    }
    // Assembled projected equations are already collected and contracted: simplifying
    // them again (a rational normal form of every entry) was 80 % of `pdyn derive` on a
    // 16-link chain and changed nothing a reader sees.
    let simplify_equations = opts.simplify && opts.simplify_printed && !assembled;
    let equations = equations
        .into_iter()
        .map(|e| Equation {
            lhs: simp(p, e.lhs, simplify_equations),
            rhs: simp(p, e.rhs, simplify_equations),
            label: e.label,
        })
        .collect();

    // Reactions the projected form dropped, recovered from Newton's equations.
    let mut recovered = Vec::new();
    if form == Form::Projected {
        let dropped: Vec<(String, Id)> = model
            .reactions
            .iter()
            .filter(|r| !unknowns.iter().any(|u| u.id == r.id))
            .map(|r| (r.name.clone(), r.id))
            .collect();
        if let (false, Some(sol)) = (dropped.is_empty(), &solution) {
            let acc: FxHashMap<Id, Id> = unknowns
                .iter()
                .zip(sol)
                .filter(|(u, _)| matches!(u.kind, UnknownKind::Acceleration(_)))
                .map(|(u, &s)| (u.id, s))
                .collect();
            let ids: Vec<Id> = dropped.iter().map(|d| d.1).collect();
            let mut residuals: Vec<Id> = Vec::new();
            for e in &newton_all {
                let r = p.sub(e.lhs, e.rhs);
                let r = p.subs(r, &acc);
                if ids.iter().any(|&u| p.contains(r, u)) {
                    residuals.push(r);
                }
            }
            if residuals.len() >= ids.len() {
                if let Ok(sys) = p.linear_system(&residuals, &ids) {
                    match p.solve_linear_with(&sys, false) {
                        Ok(vals) => {
                            for ((name, _), v) in dropped.iter().zip(vals) {
                                recovered.push((name.clone(), simp(p, v, opts.simplify)));
                            }
                        }
                        Err(_) => notes.push(
                            "the declared reactions could not be recovered from F = ma".into(),
                        ),
                    }
                }
            }
        }
    }

    Ok(Derivation {
        form,
        particles: parts,
        equations,
        unknowns,
        system,
        solution,
        free,
        state,
        state_names,
        notes,
        recovered,
        assembled_collected: assembled && contract,
        prescribed_acceleration: given_equations,
        tree: None,
    })
}

/// Work budget (simplification work units, [`Pool::simplify_work`]) of rewriting one
/// derivation's exact solution in differences of its coordinates ([`in_differences`]), all
/// pairs and all unknowns together (the double pendulum in Newton form, four unknowns and
/// both directions of its one pair, fits it).
pub const DIFFERENCE_BUDGET: u64 = 20_000;

/// `e` written in the difference `q_a - q_b` of two coordinates when that is shorter: `q_a`
/// is replaced by `q_b + δ`, the result simplified (sines and cosines of `q_b + δ` expanded,
/// so that `cos(q_a)^2 + cos(q_b)^2 - 2 cos(q_a)^2 cos(q_b)^2 - 2 sin(q_a) sin(q_b) cos(q_a)
/// cos(q_b)` becomes `sin(δ)^2`), and `δ` replaced by `q_a - q_b` again. Each pair's
/// simplification is paid from `budget`; when it runs out, `e` is kept (equal, longer).
fn in_differences(p: &mut Pool, e: Id, q: &[Id], budget: &mut u64) -> Id {
    let present: Vec<Id> = q.iter().copied().filter(|&c| p.contains(e, c)).collect();
    if present.len() < 2 {
        return e;
    }
    let delta = p.var("δ〈difference〉");
    let mut best = e;
    let mut best_size = p.tree_size(e, usize::MAX);
    // Both directions: `q_a -> q_b + δ` keeps `q_b`'s sines and cosines whole, the other
    // `q_a`'s; which is shorter depends on the expression (the double pendulum's `th1''` reads
    // best with one, `th2''` with the other).
    for &a in &present {
        for &b in &present {
            if a == b || *budget == 0 {
                continue;
            }
            let shifted = p.add2(b, delta);
            let there: FxHashMap<Id, Id> = [(a, shifted)].into_iter().collect();
            let x = p.subs(e, &there);
            let Some(x) = p.simplify_within(x, budget) else {
                continue;
            };
            let diff = p.sub(a, b);
            let back: FxHashMap<Id, Id> = [(delta, diff)].into_iter().collect();
            let y = p.subs(x, &back);
            // What the expansion left in `q_b` and `q_a - q_b` contracts back:
            // `cos(q_b)*cos(q_a - q_b) - sin(q_b)*sin(q_a - q_b)` is `cos(q_a)`.
            let y = p.contract_trig(y);
            if p.contains(y, delta) {
                continue;
            }
            let size = p.tree_size(y, best_size + 1);
            if size < best_size {
                best = y;
                best_size = size;
            }
        }
    }
    best
}

/// `e` with what all terms of its numerator share taken out, and of its denominator too
/// ([`Pool::factor_terms`] leaves a sum under a negative power as it is): `(L1*m1 +
/// L1*m2*sin(d)^2)^-1` becomes `(L1*(m1 + m2*sin(d)^2))^-1`. Equal to `e`.
fn factor_quotient(p: &mut Pool, e: Id) -> Id {
    use pdyn_expr::Node;
    // Only quotients by a sum: a polynomial such as `omega^2*r - 2*mu*omega*r'` reads
    // better expanded than as `-omega*(2*mu*r' - omega*r)`.
    let over_a_sum = |p: &Pool, f: Id| match p.node(f) {
        Node::Pow(b, x) => {
            matches!(p.node(*b), Node::Add(_)) && p.as_num(*x).is_some_and(|n| n.is_negative())
        }
        _ => false,
    };
    let quotient = match p.node(e) {
        Node::Mul(fs) => fs.iter().any(|&f| over_a_sum(p, f)),
        _ => over_a_sum(p, e),
    };
    if !quotient {
        return e;
    }
    let e = p.factor_terms(e);
    let factor_power = |p: &mut Pool, f: Id| -> Id {
        match p.node(f).clone() {
            Node::Pow(b, x) if matches!(p.node(b), Node::Add(_)) => {
                let fb = p.factor_terms(b);
                if fb == b {
                    f
                } else {
                    p.pow(fb, x)
                }
            }
            _ => f,
        }
    };
    match p.node(e).clone() {
        Node::Mul(fs) => {
            let fs: Vec<Id> = fs.iter().map(|&f| factor_power(p, f)).collect();
            p.mul(&fs)
        }
        Node::Pow(..) => factor_power(p, e),
        _ => e,
    }
}

/// Checks the equations (each involves an unknown, or holds identically; every unknown
/// appears; enough equations) and writes them as `A x = b`.
/// For a square `a` (row-major, `m` x `m`) with exactly one entry other than zero in each row
/// and each column, the column of each row's entry; `None` otherwise.
fn permuted_diagonal(a: &[Id], m: usize) -> Option<Vec<usize>> {
    let mut column = Vec::with_capacity(m);
    let mut taken = vec![false; m];
    for row in a.chunks(m) {
        let mut nonzero = row.iter().enumerate().filter(|(_, &e)| e != Pool::ZERO);
        let (j, _) = nonzero.next()?;
        if nonzero.next().is_some() || std::mem::replace(&mut taken[j], true) {
            return None;
        }
        column.push(j);
    }
    Some(column)
}

fn linear_form(
    p: &mut Pool,
    equations: Vec<Equation>,
    unknowns: &[Unknown],
) -> Result<(Vec<Equation>, LinearSystem), DeriveError> {
    let unknown_ids: Vec<Id> = unknowns.iter().map(|u| u.id).collect();
    let wanted: rustc_hash::FxHashSet<Id> = unknown_ids.iter().copied().collect();
    // Which unknowns some equation holds, found in one traversal per equation (asking each
    // equation about each unknown was quadratic in a net of many particles).
    let mut involved = rustc_hash::FxHashSet::default();
    let mut kept = Vec::new();
    let mut residuals = Vec::new();
    for e in equations {
        let r = p.sub(e.lhs, e.rhs);
        let present = p.occurring(r, &wanted);
        if !present.is_empty() {
            involved.extend(present);
            residuals.push(r);
            kept.push(e);
        } else if !p.provably_equal(r, Pool::ZERO) {
            // The message quotes the two sides within the printing budget, else their sizes.
            let side = |id: Id, which: &str| {
                let limit = pdyn_expr::budget::PRINT_CHARS / 2 - 100;
                p.to_text_within(id, false, limit)
                    .unwrap_or_else(|size| format!("⟨{which} side: {size}⟩"))
            };
            return Err(derr(
                format!(
                    "equation `{}` involves no unknown and does not hold: {} = {}",
                    e.label,
                    side(e.lhs, "left"),
                    side(e.rhs, "right")
                ),
                "a force is missing from the free body diagram: declare the reaction that balances it ([[forces]] kind = \"reaction\")",
            ));
        }
    }
    let equations = kept;
    for u in unknowns {
        if !involved.contains(&u.id) {
            return Err(derr(
                format!("no equation involves `{}`", u.name),
                match u.kind {
                    UnknownKind::Acceleration(_) => "the coordinate does not move any particle: use it in a position, or remove it",
                    UnknownKind::Reaction(_) => "the reaction acts on nothing that moves: check its `on` and `direction`",
                },
            ));
        }
    }
    if residuals.len() < unknowns.len() {
        let names: Vec<&str> = unknowns.iter().map(|u| u.name.as_str()).collect();
        return Err(derr(
            format!(
                "{} equations for {} unknowns ({})",
                residuals.len(),
                unknowns.len(),
                names.join(", ")
            ),
            "look for constraints that relate the coordinates ([[constraints]]), or fewer unknown reactions (chapter 3.3.1, step 7)",
        ));
    }
    let system = p.linear_system(&residuals, &unknown_ids).map_err(|e| match e {
        LinearError::NotLinear { equation, unknown } => derr(
            format!(
                "equation `{}` is not linear in `{}`",
                equations[equation].label,
                p.to_text(unknown)
            ),
            "forces may depend on positions and velocities but not on accelerations or products of reactions",
        ),
        other => derr(other.to_string(), "check the model's forces"),
    })?;
    Ok((equations, system))
}
