//! Gravitational forces: direct summation and the Barnes–Hut tree.

pub mod direct;
pub mod tree;

pub use tree::{Octree, TreeParams};

use pdyn_particles::Particles;

/// How accelerations are computed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub enum Gravity {
    /// Direct summation over all pairs, exact, `O(N²)` (the default).
    #[default]
    Direct,
    /// Barnes–Hut octree with the given opening angle, `O(N log N)`: for `N ≳ 10⁴`.
    Tree(TreeParams),
}

/// The force computation with its parameters and workspace.
#[derive(Debug, Clone)]
pub(crate) struct Forces {
    pub g: f64,
    pub eps2: f64,
    pub kind: Gravity,
    pub tree: Octree,
    pub direct: direct::DirectWorkspace,
}

impl Forces {
    /// Fills the accelerations; see [`direct::accelerations`] for `skip_01`.
    pub fn compute(&mut self, p: &mut Particles, skip_01: bool) -> bool {
        match self.kind {
            Gravity::Direct => {
                direct::accelerations_in(&mut self.direct, p, self.g, self.eps2, skip_01)
            }
            Gravity::Tree(params) => {
                self.tree.accelerations(p, self.g, self.eps2, params);
                false
            }
        }
    }
}
