//! Leapfrog (drift–kick–drift, Störmer–Verlet): second order, fixed step, symplectic,
//! time-reversible, one force evaluation per step.
//!
//! `x ← x + (h/2) v;  v ← v + h a(x);  x ← x + (h/2) v`. The method of choice for large `N`
//! with the Barnes–Hut tree, where forces are approximate anyway and cost dominates. See
//! e.g. Hairer, Lubich & Wanner (2003), *Geometric numerical integration illustrated by the
//! Störmer–Verlet method*, Acta Numerica 12, 399–450.

use pdyn_particles::Particles;

use crate::forces::Forces;

/// Drift–kick–drift leapfrog; it needs no workspace beyond the particles themselves.
#[derive(Debug, Clone, Default)]
pub(crate) struct Leapfrog;

impl Leapfrog {
    /// One step of length `h`.
    pub fn step(&mut self, p: &mut Particles, f: &mut Forces, h: f64) {
        p.drift(0.5 * h);
        f.compute(p, false);
        p.kick(h);
        p.drift(0.5 * h);
    }
}
