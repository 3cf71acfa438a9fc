//! Barnes–Hut octree: `O(N log N)` approximate gravity for large `N`.
//!
//! Barnes & Hut (1986), *A hierarchical O(N log N) force-calculation algorithm*, Nature 324,
//! 446. The bounding cube of the particles is split recursively into octants until each leaf
//! holds one particle. Each cell stores its mass `M`, centre of mass `R` and (optionally) its
//! traceless quadrupole `Q_ij = Σ m (3 dᵢ dⱼ − |d|² δᵢⱼ)` about `R`. The acceleration of a
//! particle at `r` sums, walking down from the root, either a cell's multipole expansion —
//! when the cell is seen under an angle `w/|r − R| < θ` (`w` the cell's side) and `r` lies
//! outside the cell — or the cell's children:
//!
//! ```text
//! a = G [ −M d/|d|³ + Q d/|d|⁵ − (5/2) (dᵀ Q d) d/|d|⁷ ],   d = r − R
//! ```
//!
//! (the quadrupole terms are dropped when disabled). Each particle's walk is a fixed
//! depth-first order, done by one thread, so the result does not depend on the number of
//! threads. The node arena is reused between force evaluations (no allocation once it has
//! grown to size).

#![allow(clippy::needless_range_loop)]

use pdyn_particles::Particles;
use rayon::prelude::*;

/// Barnes–Hut parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeParams {
    /// Opening angle θ: a cell of side `w` at distance `d` is approximated when `w/d < θ`.
    /// Default 0.5 (REBOUND's default).
    pub theta: f64,
    /// Include the quadrupole moment of cells. Default `true`.
    pub quadrupole: bool,
}

impl Default for TreeParams {
    fn default() -> Self {
        TreeParams {
            theta: 0.5,
            quadrupole: true,
        }
    }
}

const NONE: u32 = u32::MAX;
/// Cells are not split beyond this depth; coincident particles share a leaf (as a list).
const MAX_DEPTH: usize = 60;

#[derive(Debug, Clone)]
struct Node {
    center: [f64; 3],
    half: f64,
    mass: f64,
    com: [f64; 3],
    quad: [f64; 6], // xx, yy, zz, xy, xz, yz
    children: [u32; 8],
    /// First particle of a leaf's list (`NONE` for internal cells and empty leaves).
    body: u32,
    leaf: bool,
}

impl Node {
    fn new(center: [f64; 3], half: f64) -> Self {
        Node {
            center,
            half,
            mass: 0.0,
            com: [0.0; 3],
            quad: [0.0; 6],
            children: [NONE; 8],
            body: NONE,
            leaf: true,
        }
    }
}

/// An octree over a set of particles, rebuilt by [`Octree::accelerations`].
#[derive(Debug, Clone, Default)]
pub struct Octree {
    nodes: Vec<Node>,
    next: Vec<u32>,
    /// Scratch arena for the depth-first relayout.
    spare: Vec<Node>,
    /// Particles in depth-first leaf order (walks in this order share cached cells).
    order: Vec<u32>,
    /// Accelerations by position in `order`.
    acc: Vec<[f64; 3]>,
    stack: Vec<(u32, u32)>,
}

impl Octree {
    /// An empty tree.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of cells in the last tree built.
    pub fn cells(&self) -> usize {
        self.nodes.len()
    }

    fn build(&mut self, p: &Particles) {
        let n = p.len();
        self.nodes.clear();
        self.next.clear();
        self.next.resize(n, NONE);
        if n == 0 {
            return;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for i in 0..n {
            for (k, c) in [p.x[i], p.y[i], p.z[i]].into_iter().enumerate() {
                lo[k] = lo[k].min(c);
                hi[k] = hi[k].max(c);
            }
        }
        let center = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let half = (0..3).map(|k| 0.5 * (hi[k] - lo[k])).fold(0.0, f64::max);
        let half = half * (1.0 + 1e-9) + f64::MIN_POSITIVE;
        self.nodes.push(Node::new(center, half));
        for i in 0..n {
            self.insert(p, i as u32);
        }
        self.relayout();
        self.moments(p);
    }

    /// Renumbers cells in depth-first preorder (children stay after parents, neighbours in
    /// space become neighbours in memory) and lists the particles in the same order.
    fn relayout(&mut self) {
        self.spare.clear();
        self.order.clear();
        self.stack.clear();
        // (old index, new parent index + 1, or 0 for the root); children pushed in reverse
        // so that they pop in octant order.
        self.stack.push((0, 0));
        while let Some((old, parent_plus_oct)) = self.stack.pop() {
            let new = self.spare.len() as u32;
            let mut node = self.nodes[old as usize].clone();
            let children = node.children;
            node.children = [NONE; 8];
            self.spare.push(node);
            if parent_plus_oct != 0 {
                let parent = (parent_plus_oct >> 3) - 1;
                let oct = parent_plus_oct & 7;
                self.spare[parent as usize].children[oct as usize] = new;
            }
            if self.nodes[old as usize].leaf {
                let mut j = self.nodes[old as usize].body;
                while j != NONE {
                    self.order.push(j);
                    j = self.next[j as usize];
                }
            }
            for oct in (0..8u32).rev() {
                let c = children[oct as usize];
                if c != NONE {
                    self.stack.push((c, ((new + 1) << 3) | oct));
                }
            }
        }
        std::mem::swap(&mut self.nodes, &mut self.spare);
    }

    fn octant(c: [f64; 3], r: [f64; 3]) -> usize {
        (r[0] > c[0]) as usize | ((r[1] > c[1]) as usize) << 1 | ((r[2] > c[2]) as usize) << 2
    }

    fn child(&mut self, node: usize, oct: usize) -> usize {
        let c = self.nodes[node].children[oct];
        if c != NONE {
            return c as usize;
        }
        let parent = &self.nodes[node];
        let h = 0.5 * parent.half;
        let center =
            std::array::from_fn(|k| parent.center[k] + if (oct >> k) & 1 == 1 { h } else { -h });
        let idx = self.nodes.len();
        self.nodes.push(Node::new(center, h));
        self.nodes[node].children[oct] = idx as u32;
        idx
    }

    fn insert(&mut self, p: &Particles, i: u32) {
        let pos = |j: u32| [p.x[j as usize], p.y[j as usize], p.z[j as usize]];
        let ri = pos(i);
        let mut node = 0usize;
        let mut depth = 0usize;
        loop {
            if self.nodes[node].leaf {
                let b = self.nodes[node].body;
                if b == NONE {
                    self.nodes[node].body = i;
                    return;
                }
                if depth >= MAX_DEPTH {
                    self.next[i as usize] = b;
                    self.nodes[node].body = i;
                    return;
                }
                // Split: push the resident (list) one level down, then continue with i.
                self.nodes[node].leaf = false;
                self.nodes[node].body = NONE;
                let oct = Self::octant(self.nodes[node].center, pos(b));
                let c = self.child(node, oct);
                self.nodes[c].body = b;
            }
            let oct = Self::octant(self.nodes[node].center, ri);
            node = self.child(node, oct);
            depth += 1;
        }
    }

    fn moments(&mut self, p: &Particles) {
        // Children always come after their parent in the arena: reverse order is post-order.
        for idx in (0..self.nodes.len()).rev() {
            let (mut m, mut s) = (0.0, [0.0; 3]);
            let mut quad = [0.0; 6];
            if self.nodes[idx].leaf {
                let mut j = self.nodes[idx].body;
                while j != NONE {
                    let ju = j as usize;
                    m += p.m[ju];
                    s[0] += p.m[ju] * p.x[ju];
                    s[1] += p.m[ju] * p.y[ju];
                    s[2] += p.m[ju] * p.z[ju];
                    j = self.next[ju];
                }
                let com = if m > 0.0 {
                    s.map(|v| v / m)
                } else {
                    self.nodes[idx].center
                };
                let mut j = self.nodes[idx].body;
                while j != NONE {
                    let ju = j as usize;
                    let d = [p.x[ju] - com[0], p.y[ju] - com[1], p.z[ju] - com[2]];
                    add_quad(&mut quad, p.m[ju], d);
                    j = self.next[ju];
                }
                let node = &mut self.nodes[idx];
                node.mass = m;
                node.com = com;
                node.quad = quad;
            } else {
                let children = self.nodes[idx].children;
                for &c in children.iter().filter(|&&c| c != NONE) {
                    let ch = &self.nodes[c as usize];
                    m += ch.mass;
                    for k in 0..3 {
                        s[k] += ch.mass * ch.com[k];
                    }
                }
                let com = if m > 0.0 {
                    s.map(|v| v / m)
                } else {
                    self.nodes[idx].center
                };
                for &c in children.iter().filter(|&&c| c != NONE) {
                    let ch = &self.nodes[c as usize];
                    for k in 0..6 {
                        quad[k] += ch.quad[k];
                    }
                    let d = [ch.com[0] - com[0], ch.com[1] - com[1], ch.com[2] - com[2]];
                    add_quad(&mut quad, ch.mass, d);
                }
                let node = &mut self.nodes[idx];
                node.mass = m;
                node.com = com;
                node.quad = quad;
            }
        }
    }

    /// Rebuilds the tree for `p` and overwrites `ax, ay, az` with the approximate
    /// accelerations (`eps2`: squared Plummer softening, applied to monopole and direct terms).
    pub fn accelerations(&mut self, p: &mut Particles, g: f64, eps2: f64, params: TreeParams) {
        self.build(p);
        let mut acc = std::mem::take(&mut self.acc);
        acc.clear();
        acc.resize(p.len(), [0.0; 3]);
        let tree = &*self;
        let (x, y, z, m) = (&p.x, &p.y, &p.z, &p.m);
        let theta2 = params.theta * params.theta;
        acc.par_iter_mut()
            .zip(tree.order.par_iter())
            .with_min_len(64)
            .for_each(|(a, &iu)| {
                let i = iu as usize;
                *a = tree.walk(
                    i,
                    [x[i], y[i], z[i]],
                    x,
                    y,
                    z,
                    m,
                    eps2,
                    theta2,
                    params.quadrupole,
                );
            });
        for (a, &i) in acc.iter().zip(&self.order) {
            let i = i as usize;
            p.ax[i] = g * a[0];
            p.ay[i] = g * a[1];
            p.az[i] = g * a[2];
        }
        self.acc = acc;
    }

    #[allow(clippy::too_many_arguments)]
    fn walk(
        &self,
        i: usize,
        r: [f64; 3],
        x: &[f64],
        y: &[f64],
        z: &[f64],
        m: &[f64],
        eps2: f64,
        theta2: f64,
        quadrupole: bool,
    ) -> [f64; 3] {
        let mut a = [0.0; 3];
        let mut stack = [0u32; 8 * MAX_DEPTH + 8];
        let mut top = 1;
        stack[0] = 0;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if node.mass == 0.0 {
                continue;
            }
            if node.leaf {
                let mut j = node.body;
                while j != NONE {
                    let ju = j as usize;
                    if ju != i {
                        let d = [x[ju] - r[0], y[ju] - r[1], z[ju] - r[2]];
                        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2;
                        let f = m[ju] / (r2 * r2.sqrt());
                        for k in 0..3 {
                            a[k] += f * d[k];
                        }
                    }
                    j = self.next[ju];
                }
                continue;
            }
            let d = [r[0] - node.com[0], r[1] - node.com[1], r[2] - node.com[2]];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let w = 2.0 * node.half;
            let inside = (0..3).all(|k| (r[k] - node.center[k]).abs() <= node.half);
            if !inside && w * w < theta2 * d2 {
                let r2 = d2 + eps2;
                let inv_r = 1.0 / r2.sqrt();
                let inv_r3 = inv_r * inv_r * inv_r;
                for k in 0..3 {
                    a[k] -= node.mass * inv_r3 * d[k];
                }
                if quadrupole {
                    let q = &node.quad;
                    let qd = [
                        q[0] * d[0] + q[3] * d[1] + q[4] * d[2],
                        q[3] * d[0] + q[1] * d[1] + q[5] * d[2],
                        q[4] * d[0] + q[5] * d[1] + q[2] * d[2],
                    ];
                    let dqd = d[0] * qd[0] + d[1] * qd[1] + d[2] * qd[2];
                    let inv_r5 = inv_r3 * inv_r * inv_r;
                    let inv_r7 = inv_r5 * inv_r * inv_r;
                    for k in 0..3 {
                        a[k] += qd[k] * inv_r5 - 2.5 * dqd * d[k] * inv_r7;
                    }
                }
                continue;
            }
            for &c in node.children.iter().rev() {
                if c != NONE {
                    stack[top] = c;
                    top += 1;
                }
            }
        }
        a
    }
}

fn add_quad(q: &mut [f64; 6], m: f64, d: [f64; 3]) {
    let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    q[0] += m * (3.0 * d[0] * d[0] - d2);
    q[1] += m * (3.0 * d[1] * d[1] - d2);
    q[2] += m * (3.0 * d[2] * d[2] - d2);
    q[3] += m * 3.0 * d[0] * d[1];
    q[4] += m * 3.0 * d[0] * d[2];
    q[5] += m * 3.0 * d[1] * d[2];
}
