//! The recursive form of a tree of point masses: the projected equations `M(q) q'' = f` of a
//! model whose particles hang from one another link by link, solved in `O(n)` per evaluation
//! instead of assembling and factoring the dense `M` (`O(n²)` entries, `O(n³)` Cholesky).
//!
//! A model is such a tree when every particle's position is its parent particle's position
//! (or a fixed point, for a root) plus a *link vector* `s_k(q_k)` that depends on one free
//! coordinate of its own and on parameters only: an n-link pendulum chain, a branching
//! mobile of pendulums. Then `a_k = a_parent + s_k' q_k'' + s_k'' q_k'²`, and Lagrange's
//! equation of `q_k` is `s_k'·f_k = 0`, where `f_k = Σ_{j in subtree(k)} (m_j a_j − F_j)` is
//! the force the link transmits into the subtree. The articulated-body recursion (Featherstone's
//! algorithm, here for point masses and one translational degree of freedom per link) writes
//! `f_k = I_k a_parent + p_k` with a 3×3 articulated inertia `I_k` and a bias `p_k`, from the
//! leaves to the roots, then finds each `q_k''` from the roots to the leaves: a few dozen
//! operations per particle ([`TreeForm::solve`]).
//!
//! [`detect`] finds the tree in a model's symbols; the numbers each evaluation needs per node
//! (`m_k`, `s_k'`, `s_k'' q_k'²`, the resultant applied force `F_k`) are plain expressions a
//! caller compiles into one program of `O(n)` size.

use crate::derive::ParticleKinematics;
use crate::model::{CoordinateKind, Model};
use pdyn_expr::{vector, Id, Pool};
use rustc_hash::{FxHashMap, FxHashSet};

/// One particle of the tree, with the link that carries it.
#[derive(Clone, Debug)]
pub struct TreeNode {
    /// Index into [`Model::particles`].
    pub particle: usize,
    /// Index into [`TreeForm::nodes`] of the parent (always smaller); `None` for a root,
    /// whose link starts at a fixed point.
    pub parent: Option<usize>,
    /// Index of the link's coordinate among the free coordinates (state order).
    pub coordinate: usize,
    /// The particle's mass.
    pub mass: Id,
    /// `∂s/∂q` of the link vector `s` by its coordinate.
    pub direction: [Id; 3],
    /// `∂²s/∂q² · q'²`: the link's centripetal acceleration.
    pub centripetal: [Id; 3],
    /// The resultant applied force on the particle.
    pub force: [Id; 3],
}

/// A model's particles as a tree of links, parents before children.
#[derive(Clone, Debug)]
pub struct TreeForm {
    /// The nodes, each after its parent.
    nodes: Vec<TreeNode>,
    /// Each node's coordinate, in node order: what the forward pass reads per node, kept
    /// apart from the nodes' expressions (a cache line per node).
    coordinates: Vec<usize>,
    /// Every node is the child of the one before (a chain): [`TreeForm::solve`] then
    /// carries each link's result to the next in registers.
    chain: bool,
    /// Every link direction, centripetal acceleration and force has no `z` component
    /// (symbolically zero): a chain then runs the recursion in the `xy` plane
    /// ([`articulate_planar`]), half the arithmetic of the spatial one.
    planar: bool,
}

/// Numbers per node that [`TreeForm::solve`] reads: `m, s'(3), s''q'²(3), F(3)`.
pub const NODE_INPUTS: usize = 10;

/// The arithmetic [`TreeForm::solve`] runs on: `f64` for runs, and a type that counts its
/// operations for the test that the solve's work is linear in the nodes.
pub trait Scalar:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    /// The value `x`.
    fn of(x: f64) -> Self;
}

impl Scalar for f64 {
    #[inline(always)]
    fn of(x: f64) -> f64 {
        x
    }
}

/// Why [`TreeForm::solve`] could not give the accelerations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SingularTree {
    /// The node whose link carries no inertia along its own direction.
    pub node: usize,
}

/// Reusable buffers of [`TreeForm::solve`] (no allocation per evaluation).
#[derive(Clone, Debug)]
pub struct TreeWorkspace<T = f64> {
    /// Per node: the children's articulated inertia (symmetric 3×3 as xx, yy, zz, xy, xz,
    /// yz) and bias force, accumulated in the backward pass.
    acc_in: Vec<[T; 9]>,
    /// Per node, what the forward pass needs: the node's acceleration is the affine map
    /// `A a_parent + b` of its parent's, and `q'' = −wᵀ a_parent − g` (see [`Joint`]).
    joint: Vec<Joint<T>>,
    /// Each particle's acceleration in the forward pass.
    acc: Vec<[T; 3]>,
    /// A planar chain's [`PlanarJoint`]s.
    planar_joint: Vec<PlanarJoint<T>>,
}

/// One link's result of the backward pass, for the forward pass: with `u = Î s`,
/// `D = sᵀ Î s`, `w = u/D` and `g = (uᵀc + sᵀp̂)/D`, the link's acceleration is
/// `q'' = −wᵀ a_parent − g` and its particle's `a = A a_parent + b` with `A = 1 − s wᵀ`,
/// `b = c − s g`. The affine map keeps the forward pass's dependency chain (one particle's
/// acceleration waiting for its parent's) at one multiply and two adds per link.
#[derive(Clone, Copy, Debug)]
struct Joint<T> {
    w: [T; 3],
    g: T,
    /// `A` by rows.
    a: [[T; 3]; 3],
    b: [T; 3],
}

impl<T> Default for TreeWorkspace<T> {
    fn default() -> Self {
        TreeWorkspace {
            acc_in: Vec::new(),
            joint: Vec::new(),
            acc: Vec::new(),
            planar_joint: Vec::new(),
        }
    }
}

#[inline(always)]
fn sym_mul<T: Scalar>(i: &[T; 6], v: [T; 3]) -> [T; 3] {
    [
        i[0] * v[0] + i[3] * v[1] + i[4] * v[2],
        i[3] * v[0] + i[1] * v[1] + i[5] * v[2],
        i[4] * v[0] + i[5] * v[1] + i[2] * v[2],
    ]
}

#[inline(always)]
fn dot<T: Scalar>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The backward step of one node: from its per-node numbers `v` ([`NODE_INPUTS`]) and its
/// children's accumulated contribution `a` (inertia and bias, as in
/// [`TreeWorkspace::acc_in`]), the contribution it passes to its parent,
/// `Î − u uᵀ/D` and `Î c + p̂ − u g` (the joint transmits no force along `s`), and its
/// [`Joint`]. `None` when `D = sᵀ Î s` is not positive (or NaN).
///
/// Ordered for a short dependency chain from `a` to the result (a chain's links run one
/// after another): `D` as a sum of independent products `Î_ij (s_i s_j)` rather than
/// `sᵀ(Î s)`, the node's mass folded in as `m |s|²`, and `u uᵀ` formed while `1/D` is
/// computed.
#[inline(always)]
fn articulate<T: Scalar>(v: &[T], a: &[T; 9]) -> Option<([T; 9], Joint<T>)> {
    let zero = T::of(0.0);
    let one = T::of(1.0);
    let (m, s, c) = (v[0], [v[1], v[2], v[3]], [v[4], v[5], v[6]]);
    let ih = [a[0] + m, a[1] + m, a[2] + m, a[3], a[4], a[5]];
    let ph = [a[6] - v[7], a[7] - v[8], a[8] - v[9]];
    let (s00, s11, s22) = (s[0] * s[0], s[1] * s[1], s[2] * s[2]);
    let two = T::of(2.0);
    let (s01, s02, s12) = (two * s[0] * s[1], two * s[0] * s[2], two * s[1] * s[2]);
    let d = ((a[0] * s00 + a[1] * s11) + (a[2] * s22 + a[3] * s01))
        + ((a[4] * s02 + a[5] * s12) + m * ((s00 + s11) + s22));
    // NaN is refused too (`partial_cmp` is `None` then).
    if d.partial_cmp(&zero) != Some(std::cmp::Ordering::Greater) {
        // No inertia along the link's direction (a massless subtree, a zero-length link):
        // the dense form's M is singular there too.
        return None;
    }
    let r = one / d;
    let u = sym_mul(&ih, s);
    let uu = [
        u[0] * u[0],
        u[1] * u[1],
        u[2] * u[2],
        u[0] * u[1],
        u[0] * u[2],
        u[1] * u[2],
    ];
    let g = (dot(u, c) + dot(s, ph)) * r;
    let w = [u[0] * r, u[1] * r, u[2] * r];
    let ic = sym_mul(&ih, c);
    let out = [
        ih[0] - uu[0] * r,
        ih[1] - uu[1] * r,
        ih[2] - uu[2] * r,
        ih[3] - uu[3] * r,
        ih[4] - uu[4] * r,
        ih[5] - uu[5] * r,
        (ic[0] + ph[0]) - u[0] * g,
        (ic[1] + ph[1]) - u[1] * g,
        (ic[2] + ph[2]) - u[2] * g,
    ];
    let row = |i: usize| {
        let e = |j: usize| if i == j { one } else { zero };
        [e(0) - s[i] * w[0], e(1) - s[i] * w[1], e(2) - s[i] * w[2]]
    };
    let joint = Joint {
        w,
        g,
        a: [row(0), row(1), row(2)],
        b: [c[0] - s[0] * g, c[1] - s[1] * g, c[2] - s[2] * g],
    };
    Some((out, joint))
}

/// [`Joint`] in the `xy` plane: `w`, `b` and `A` without their `z` parts.
#[derive(Clone, Copy, Debug)]
struct PlanarJoint<T> {
    w: [T; 2],
    g: T,
    a: [[T; 2]; 2],
    b: [T; 2],
}

/// What a planar chain's link passes to its parent besides its contribution `Î − u uᵀ/D`:
/// its `Î` (`xx, yy, xy`), `u = Î s` and `1/D`, all zero below the last link.
#[derive(Clone, Copy, Debug)]
struct Child<T> {
    ih: [T; 3],
    u: [T; 2],
    r: T,
}

/// [`articulate`] for a link, its particle's load and its subtree in the `xy` plane:
/// `v` as there (its `z` entries zero and not read), the contribution `a` as the inertia's
/// `xx, yy, xy` and the bias force's `x, y` (the `zz` inertia never meets a non-zero
/// direction, the `xz`, `yz` entries and the bias's `z` stay zero); the terms in `z` of
/// [`articulate`] are exact zeros (`x + 0 = x`, `x·0 = 0`) left out.
///
/// `D = sᵀ(Î_c − u_c u_cᵀ/D_c)s + m|s|²` is computed as `A − B²/D_c` with
/// `A = sᵀ Î_c s + m|s|²` and `B = u_cᵀ s` from the child `c`'s numbers, known before its
/// `1/D_c`: a chain's dependency from one link's division to the next is then a multiply and
/// a subtraction, not the contribution's six entries and a quadratic form. Equal to
/// [`articulate`]'s `D` to round-off (not to the bit).
#[inline(always)]
fn articulate_planar<T: Scalar>(
    v: &[T],
    a: &[T; 5],
    child: &Child<T>,
) -> Option<([T; 5], PlanarJoint<T>, Child<T>)> {
    let zero = T::of(0.0);
    let one = T::of(1.0);
    let (m, s, c) = (v[0], [v[1], v[2]], [v[4], v[5]]);
    let ih = [a[0] + m, a[1] + m, a[2]];
    let ph = [a[3] - v[7], a[4] - v[8]];
    let (s00, s11) = (s[0] * s[0], s[1] * s[1]);
    let s01 = T::of(2.0) * s[0] * s[1];
    let along = ((child.ih[0] * s00 + child.ih[1] * s11) + child.ih[2] * s01) + m * (s00 + s11);
    let across = child.u[0] * s[0] + child.u[1] * s[1];
    let d = along - (across * across) * child.r;
    if d.partial_cmp(&zero) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let r = one / d;
    let u = [ih[0] * s[0] + ih[2] * s[1], ih[2] * s[0] + ih[1] * s[1]];
    let uu = [u[0] * u[0], u[1] * u[1], u[0] * u[1]];
    let g = ((u[0] * c[0] + u[1] * c[1]) + (s[0] * ph[0] + s[1] * ph[1])) * r;
    let w = [u[0] * r, u[1] * r];
    let ic = [ih[0] * c[0] + ih[2] * c[1], ih[2] * c[0] + ih[1] * c[1]];
    let out = [
        ih[0] - uu[0] * r,
        ih[1] - uu[1] * r,
        ih[2] - uu[2] * r,
        (ic[0] + ph[0]) - u[0] * g,
        (ic[1] + ph[1]) - u[1] * g,
    ];
    let joint = PlanarJoint {
        w,
        g,
        a: [
            [one - s[0] * w[0], zero - s[0] * w[1]],
            [zero - s[1] * w[0], one - s[1] * w[1]],
        ],
        b: [c[0] - s[0] * g, c[1] - s[1] * g],
    };
    Some((out, joint, Child { ih, u, r }))
}

/// [`accelerate`] in the `xy` plane (the same bits, as [`articulate_planar`]).
#[inline(always)]
fn accelerate_planar<T: Scalar>(j: &PlanarJoint<T>, ap: [T; 2]) -> (T, [T; 2]) {
    let x = -(j.w[0] * ap[0] + j.w[1] * ap[1]) - j.g;
    let row = |r: [T; 2], b: T| (r[0] * ap[0] + r[1] * ap[1]) + b;
    (x, [row(j.a[0], j.b[0]), row(j.a[1], j.b[1])])
}

/// The forward step of one node: its coordinate's acceleration and its particle's, from the
/// parent particle's acceleration `ap`.
#[inline(always)]
fn accelerate<T: Scalar>(j: &Joint<T>, ap: [T; 3]) -> (T, [T; 3]) {
    let x = -((j.w[0] * ap[0] + j.w[1] * ap[1]) + j.w[2] * ap[2]) - j.g;
    let row = |r: [T; 3], b: T| (r[0] * ap[0] + r[1] * ap[1]) + (r[2] * ap[2] + b);
    let acc = [
        row(j.a[0], j.b[0]),
        row(j.a[1], j.b[1]),
        row(j.a[2], j.b[2]),
    ];
    (x, acc)
}

impl TreeForm {
    /// The tree of `nodes` (each after its parent).
    pub fn new(nodes: Vec<TreeNode>) -> TreeForm {
        let coordinates = nodes.iter().map(|nd| nd.coordinate).collect();
        let chain = nodes
            .iter()
            .enumerate()
            .all(|(k, nd)| nd.parent == k.checked_sub(1));
        let planar = nodes.iter().all(|nd| {
            [nd.direction[2], nd.centripetal[2], nd.force[2]]
                .iter()
                .all(|&z| z == Pool::ZERO)
        });
        TreeForm {
            nodes,
            coordinates,
            chain,
            planar,
        }
    }

    /// The nodes, each after its parent.
    pub fn nodes(&self) -> &[TreeNode] {
        &self.nodes
    }

    /// Whether no link direction, centripetal term or force has a `z` component: a chain
    /// then runs the recursion in the plane.
    pub fn is_planar(&self) -> bool {
        self.planar
    }

    /// Number of nodes (= free coordinates).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the tree has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The expressions each evaluation needs, [`NODE_INPUTS`] per node in node order.
    pub fn inputs(&self) -> Vec<Id> {
        let mut out = Vec::with_capacity(NODE_INPUTS * self.nodes.len());
        for nd in &self.nodes {
            out.push(nd.mass);
            out.extend(nd.direction);
            out.extend(nd.centripetal);
            out.extend(nd.force);
        }
        out
    }

    /// The accelerations `qdd[coordinate]` from the per-node numbers `values` (laid out as
    /// [`TreeForm::inputs`]), in `O(n)`: the articulated-body recursion.
    ///
    /// A chain (every node the child of the one before) carries each link's result to the
    /// next in registers; other trees accumulate the children's contributions per node.
    pub fn solve<T: Scalar>(
        &self,
        values: &[T],
        ws: &mut TreeWorkspace<T>,
        qdd: &mut [T],
    ) -> Result<(), SingularTree> {
        self.solve_inlined(values, ws, qdd)
    }

    /// [`TreeForm::solve`] on `f64`, compiled for AVX where the processor has it: the same
    /// operations in the same order (no fused multiply-add: Rust never contracts `a * b + c`),
    /// hence the same bits, in three-operand instructions. The recursion's SSE2 code spent
    /// many of its ~160 instructions per link copying registers before the two-operand
    /// `mulpd`, `addpd` that overwrite one (the 100-link chain's profile, a third of its run).
    pub fn solve_f64(
        &self,
        values: &[f64],
        ws: &mut TreeWorkspace,
        qdd: &mut [f64],
    ) -> Result<(), SingularTree> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the processor has AVX (checked just above).
            return unsafe { self.solve_avx(values, ws, qdd) };
        }
        self.solve_inlined(values, ws, qdd)
    }

    /// [`TreeForm::solve_inlined`] compiled with AVX.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn solve_avx(
        &self,
        values: &[f64],
        ws: &mut TreeWorkspace,
        qdd: &mut [f64],
    ) -> Result<(), SingularTree> {
        self.solve_inlined(values, ws, qdd)
    }

    /// The body of [`TreeForm::solve`], inlined into each caller so that it is compiled with
    /// the caller's target features.
    #[inline(always)]
    fn solve_inlined<T: Scalar>(
        &self,
        values: &[T],
        ws: &mut TreeWorkspace<T>,
        qdd: &mut [T],
    ) -> Result<(), SingularTree> {
        let n = self.nodes.len();
        let zero = T::of(0.0);
        if values.len() < NODE_INPUTS * n || qdd.len() < n {
            return Err(SingularTree { node: 0 });
        }
        let none = Joint {
            w: [zero; 3],
            g: zero,
            a: [[zero; 3]; 3],
            b: [zero; 3],
        };
        ws.joint.resize(n, none);
        let node_values = |k: usize| &values[NODE_INPUTS * k..NODE_INPUTS * (k + 1)];
        if self.chain && self.planar {
            let none = PlanarJoint {
                w: [zero; 2],
                g: zero,
                a: [[zero; 2]; 2],
                b: [zero; 2],
            };
            ws.planar_joint.resize(n, none);
            let mut carried = [zero; 5];
            let mut child = Child {
                ih: [zero; 3],
                u: [zero; 2],
                r: zero,
            };
            for k in (0..n).rev() {
                let (out, joint, this) = articulate_planar(node_values(k), &carried, &child)
                    .ok_or(SingularTree { node: k })?;
                ws.planar_joint[k] = joint;
                carried = out;
                child = this;
            }
            let mut ap = [zero; 2];
            for k in 0..n {
                let (x, a) = accelerate_planar(&ws.planar_joint[k], ap);
                qdd[self.coordinates[k]] = x;
                ap = a;
            }
            return Ok(());
        }
        if self.chain {
            // Leaves to root, then root to leaves, the running contribution and acceleration
            // in registers.
            let mut carried = [zero; 9];
            for k in (0..n).rev() {
                let (out, joint) =
                    articulate(node_values(k), &carried).ok_or(SingularTree { node: k })?;
                ws.joint[k] = joint;
                carried = out;
            }
            let mut ap = [zero; 3];
            for k in 0..n {
                let (x, a) = accelerate(&ws.joint[k], ap);
                qdd[self.coordinates[k]] = x;
                ap = a;
            }
            return Ok(());
        }
        ws.acc_in.clear();
        ws.acc_in.resize(n, [zero; 9]);
        ws.acc.resize(n, [zero; 3]);
        // Leaves to roots: each node adds its contribution to its parent's `acc_in`.
        for k in (0..n).rev() {
            let (out, joint) =
                articulate(node_values(k), &ws.acc_in[k]).ok_or(SingularTree { node: k })?;
            ws.joint[k] = joint;
            if let Some(par) = self.nodes[k].parent {
                let pa = &mut ws.acc_in[par];
                for (x, y) in pa.iter_mut().zip(out) {
                    *x = *x + y;
                }
            }
        }
        // Roots to leaves.
        for k in 0..n {
            let ap = match self.nodes[k].parent {
                Some(par) => ws.acc[par],
                None => [zero; 3],
            };
            let (x, a) = accelerate(&ws.joint[k], ap);
            qdd[self.coordinates[k]] = x;
            ws.acc[k] = a;
        }
        Ok(())
    }
}

/// The tree of `model`'s particles, when its projected equations have that structure (see
/// the module's documentation): no constraints, frames, reactions or given accelerations;
/// positions free of time and of prescribed coordinates; every free coordinate the
/// coordinate of exactly one link, whose vector depends on it alone. `parts` are the
/// particles' kinematics and resultant forces ([`crate::derive::newton_equations`]); `free`
/// and `qd` the free coordinates (indices into [`Model::coordinates`]) and their rates.
pub fn detect(
    model: &mut Model,
    parts: &[ParticleKinematics],
    free: &[usize],
    qd: &[Id],
) -> Option<TreeForm> {
    if !model.constraints.is_empty()
        || !model.frames.is_empty()
        || !model.reactions.is_empty()
        || !model.known_accelerations.is_empty()
        || !model.contacts.is_empty()
        || free.is_empty()
    {
        return None;
    }
    let p = &mut model.pool;
    let q: Vec<Id> = free
        .iter()
        .map(|&i| p.coord(model.coordinates[i].sym, 0))
        .collect();
    let index: FxHashMap<Id, usize> = q.iter().enumerate().map(|(k, &c)| (c, k)).collect();
    // Leaves that must not occur in a position: time, the rates and accelerations of the free
    // coordinates, and every prescribed coordinate at any order.
    let mut forbidden: FxHashSet<Id> = FxHashSet::default();
    forbidden.insert(p.time());
    for (i, c) in model.coordinates.iter().enumerate() {
        let free_here = matches!(c.kind, CoordinateKind::Free { .. }) && free.contains(&i);
        for order in 0..3u8 {
            if order > 0 || !free_here {
                forbidden.insert(p.coord(c.sym, order));
            }
        }
    }
    let accelerations: FxHashSet<Id> = model
        .coordinates
        .iter()
        .map(|c| p.coord(c.sym, 2))
        .collect();
    if parts.iter().any(|pk| {
        pk.force
            .iter()
            .any(|&f| !p.occurring(f, &accelerations).is_empty())
    }) {
        return None;
    }
    let wanted: FxHashSet<Id> = q.iter().copied().collect();
    // Each moving particle's set of coordinates, sorted.
    let mut deps: Vec<(usize, Vec<usize>)> = Vec::new();
    for (k, part) in model.particles.iter().enumerate() {
        let mut set: Vec<usize> = Vec::new();
        for &c in &part.position {
            if !p.occurring(c, &forbidden).is_empty() {
                return None;
            }
            set.extend(p.occurring(c, &wanted).iter().map(|x| index[x]));
        }
        set.sort_unstable();
        set.dedup();
        if !set.is_empty() {
            deps.push((k, set));
        }
    }
    if deps.len() != q.len() {
        return None;
    }
    // Parents have one coordinate fewer: shortest sets first.
    deps.sort_by_key(|(k, set)| (set.len(), *k));
    let mut node_of: FxHashMap<Vec<usize>, usize> = FxHashMap::default();
    let mut owned = vec![false; q.len()];
    let mut nodes: Vec<TreeNode> = Vec::with_capacity(deps.len());
    for (k, set) in deps {
        // The parent is the node whose set is this one without one coordinate.
        let (parent, own) = if set.len() == 1 {
            (None, set[0])
        } else {
            let mut found = None;
            for (a, &own) in set.iter().enumerate() {
                let mut rest = set.clone();
                rest.remove(a);
                if let Some(&par) = node_of.get(&rest) {
                    found = Some((Some(par), own));
                    break;
                }
            }
            found?
        };
        if owned[own] {
            return None;
        }
        owned[own] = true;
        let r = model.particles[k].position;
        let link = match parent {
            Some(par) => vector::sub(p, r, model.particles[nodes[par].particle].position),
            None => r,
        };
        // The link vector must move with its own coordinate only.
        let others: FxHashSet<Id> = q
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != own)
            .map(|(_, &c)| c)
            .collect();
        if link.iter().any(|&c| !p.occurring(c, &others).is_empty()) {
            return None;
        }
        let direction = link.map(|c| p.diff(c, q[own]));
        let curvature = direction.map(|c| p.diff(c, q[own]));
        let rate2 = p.mul2(qd[own], qd[own]);
        let centripetal = curvature.map(|c| p.mul2(c, rate2));
        node_of.insert(set, nodes.len());
        nodes.push(TreeNode {
            particle: k,
            parent,
            coordinate: own,
            mass: parts[k].mass,
            direction,
            centripetal,
            force: parts[k].force,
        });
    }
    Some(TreeForm::new(nodes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(k: usize, parent: Option<usize>) -> TreeNode {
        let z = Pool::ZERO;
        TreeNode {
            particle: k,
            parent,
            coordinate: k,
            mass: z,
            direction: [z; 3],
            centripetal: [z; 3],
            force: [z; 3],
        }
    }

    /// A chain's registers path gives the bits of the general path (per-node accumulators)
    /// on the same links: spatial directions, unequal masses, forces in every component.
    #[test]
    fn a_chain_solves_as_the_general_tree_path_does() {
        let n = 9;
        let chain = TreeForm::new((0..n).map(|k| node(k, k.checked_sub(1))).collect());
        assert!(chain.chain);
        // Spatial values on nodes whose symbols are all zero: not the planar path.
        let chain = TreeForm {
            planar: false,
            ..chain
        };
        let general = TreeForm {
            chain: false,
            ..chain.clone()
        };
        let mut values = Vec::new();
        for k in 0..n {
            let a = 0.37 * k as f64 + 0.2;
            let b = 0.11 * k as f64 - 0.4;
            let (sa, ca, sb, cb) = (libm::sin(a), libm::cos(a), libm::sin(b), libm::cos(b));
            values.extend([1.0 + 0.3 * k as f64, ca * cb, ca * sb, sa]);
            values.extend([-0.2 * sa, 0.1 * ca, 0.05 * sb]);
            values.extend([0.3 * cb, -9.81 + 0.1 * k as f64, 0.02 * sa]);
        }
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
        chain
            .solve(&values, &mut TreeWorkspace::default(), &mut x)
            .unwrap();
        general
            .solve(&values, &mut TreeWorkspace::default(), &mut y)
            .unwrap();
        assert!(x.iter().all(|v| v.is_finite() && *v != 0.0));
        let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&x), bits(&y));
    }

    /// A planar chain's recursion in the plane gives the spatial one's accelerations on the
    /// same links (with zero `z` numbers) to round-off: unequal masses and lengths, forces
    /// in `x` and `y`.
    #[test]
    fn a_planar_chain_solves_in_the_plane_as_in_space() {
        let n = 12;
        let planar = TreeForm::new((0..n).map(|k| node(k, k.checked_sub(1))).collect());
        assert!(planar.chain && planar.planar);
        let spatial = TreeForm {
            planar: false,
            ..planar.clone()
        };
        let mut values = Vec::new();
        for k in 0..n {
            let (q, l, rate) = (
                0.3 * k as f64 - 1.1,
                0.5 + 0.13 * k as f64,
                0.7 - 0.2 * k as f64,
            );
            let (sq, cq) = (libm::sin(q), libm::cos(q));
            values.extend([1.0 + 0.3 * k as f64, l * cq, l * sq, 0.0]);
            values.extend([-l * sq * rate * rate, l * cq * rate * rate, 0.0]);
            values.extend([
                0.4 * cq - 0.1 * k as f64,
                -9.81 * (1.0 + 0.3 * k as f64),
                0.0,
            ]);
        }
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
        planar
            .solve(&values, &mut TreeWorkspace::default(), &mut x)
            .unwrap();
        spatial
            .solve(&values, &mut TreeWorkspace::default(), &mut y)
            .unwrap();
        assert!(x.iter().all(|v| v.is_finite() && *v != 0.0));
        for (k, (a, b)) in x.iter().zip(&y).enumerate() {
            assert!(
                (a - b).abs() <= 1e-13 * b.abs().max(1.0),
                "link {k}: {a} vs {b}"
            );
        }
        // A massless last link is refused on the planar path too.
        values[NODE_INPUTS * (n - 1)] = 0.0;
        let e = planar.solve(&values, &mut TreeWorkspace::default(), &mut x);
        assert_eq!(e, Err(SingularTree { node: n - 1 }));
    }

    /// `solve_f64` (AVX where the processor has it) gives `solve`'s bits on the three paths
    /// (a planar chain, a spatial chain, a general tree), on links whose numbers span signs
    /// and magnitudes, and refuses the same singular node.
    #[test]
    fn solve_f64_gives_the_bits_of_solve() {
        let n = 23;
        let planar = TreeForm::new((0..n).map(|k| node(k, k.checked_sub(1))).collect());
        let spatial = TreeForm {
            planar: false,
            ..planar.clone()
        };
        let general = TreeForm {
            chain: false,
            ..spatial.clone()
        };
        let mut values = Vec::new();
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for k in 0..n {
            let (q, l, rate) = (7.0 * next(), 0.5 + next(), 20.0 * next());
            let (sq, cq) = (libm::sin(q), libm::cos(q));
            let m = 1.0 + next();
            values.extend([m, l * cq, l * sq, 0.0]);
            values.extend([-l * sq * rate * rate, l * cq * rate * rate, 0.0]);
            values.extend([next() * k as f64, -9.81 * m, 0.0]);
        }
        let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        for (tree, z) in [(&planar, 0.0), (&spatial, 0.3), (&general, -0.2)] {
            let mut v = values.clone();
            for k in 0..n {
                v[NODE_INPUTS * k + 3] = z * next();
                v[NODE_INPUTS * k + 6] = z * next();
                v[NODE_INPUTS * k + 9] = z * next();
            }
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            tree.solve(&v, &mut TreeWorkspace::default(), &mut a)
                .unwrap();
            tree.solve_f64(&v, &mut TreeWorkspace::default(), &mut b)
                .unwrap();
            assert!(a.iter().all(|v| v.is_finite() && *v != 0.0));
            assert_eq!(bits(&a), bits(&b));
            v[NODE_INPUTS * (n - 1)] = 0.0;
            let e = tree.solve_f64(&v, &mut TreeWorkspace::default(), &mut b);
            assert_eq!(e, Err(SingularTree { node: n - 1 }));
        }
    }

    /// A link with no inertia along its direction is refused, naming the node.
    #[test]
    fn a_massless_end_is_singular() {
        let tree = TreeForm::new(vec![node(0, None), node(1, Some(0))]);
        let mut values = vec![1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -9.81, 0.0];
        values.extend([0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let mut x = vec![0.0; 2];
        let e = tree.solve(&values, &mut TreeWorkspace::default(), &mut x);
        assert_eq!(e, Err(SingularTree { node: 1 }));
    }
}
