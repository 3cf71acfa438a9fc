//! Integrators, one per file; each file opens with its method, order and paper.

pub mod ias15;
pub mod leapfrog;
pub mod whfast;

use pdyn_particles::Particles;

use crate::error::{GravityError, Warning};
use crate::forces::Forces;

pub use ias15::Ias15Params;
pub use whfast::WhFastParams;

/// The integrator of a [`crate::Simulation`] and its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Integrator {
    /// Wisdom–Holman in Jacobi coordinates with symplectic correctors (fixed step): planetary
    /// systems dominated by one mass.
    WhFast(WhFastParams),
    /// IAS15, adaptive 15th-order Gauss–Radau (the step given to the simulation is the first
    /// trial step): close encounters, high eccentricities, machine-precision runs.
    Ias15(Ias15Params),
    /// Drift–kick–drift leapfrog (fixed step): large `N`, with direct or tree forces.
    Leapfrog,
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::WhFast(WhFastParams::default())
    }
}

/// A running integrator with its workspace.
#[derive(Debug, Clone)]
pub(crate) enum Workspace {
    WhFast(whfast::WhFast),
    Ias15(Box<ias15::Ias15>),
    Leapfrog(leapfrog::Leapfrog),
}

impl Workspace {
    pub fn new(
        integrator: Integrator,
        p: &Particles,
        g: f64,
        dt: f64,
        warnings: &mut Vec<Warning>,
    ) -> Result<Self, GravityError> {
        Ok(match integrator {
            Integrator::WhFast(params) => {
                Workspace::WhFast(whfast::WhFast::new(params, p, g, dt, warnings)?)
            }
            Integrator::Ias15(params) => {
                Workspace::Ias15(Box::new(ias15::Ias15::new(params, p.len())?))
            }
            Integrator::Leapfrog => Workspace::Leapfrog(leapfrog::Leapfrog),
        })
    }

    /// Takes one step of at most `h_max` from `t`; returns the step length taken.
    /// `full` says whether `h_max` is the nominal step (otherwise it is a final partial one).
    pub fn step(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
        dt: &mut f64,
        h_max: f64,
        warnings: &mut Vec<Warning>,
    ) -> Result<f64, GravityError> {
        if let Workspace::Ias15(w) = self {
            return w.step(p, f, t, dt, h_max, warnings);
        }
        let dt = *dt;
        match self {
            Workspace::Ias15(_) => unreachable!("handled above"),
            Workspace::WhFast(w) => {
                // A remainder within round-off of dt is a full step (keeps the corrector).
                if h_max < dt * (1.0 - 1e-9) {
                    w.partial_step(p, f, t, h_max)?;
                    Ok(h_max)
                } else {
                    w.step(p, f, t)?;
                    Ok(dt)
                }
            }
            Workspace::Leapfrog(l) => {
                let h = if h_max < dt * (1.0 - 1e-9) { h_max } else { dt };
                l.step(p, f, h);
                Ok(h)
            }
        }
    }

    /// The name a snapshot gives the workspace of `integrator`.
    pub fn name_of(integrator: Integrator) -> &'static str {
        match integrator {
            Integrator::WhFast(_) => "whfast",
            Integrator::Ias15(_) => "ias15",
            Integrator::Leapfrog => "leapfrog",
        }
    }

    /// Appends the state that carries over from step to step to a snapshot's numbers;
    /// returns the workspace's name.
    pub fn save(
        &self,
        scalars: &mut Vec<f64>,
        counters: &mut Vec<u64>,
        arrays: &mut Vec<Vec<f64>>,
    ) -> &'static str {
        match self {
            Workspace::WhFast(w) => {
                w.save(scalars, counters, arrays);
                "whfast"
            }
            Workspace::Ias15(w) => {
                w.save(scalars, counters, arrays);
                "ias15"
            }
            Workspace::Leapfrog(_) => "leapfrog",
        }
    }

    /// Takes back what [`Workspace::save`] wrote (a freshly made workspace of the same
    /// integrator and size).
    pub fn load(
        &mut self,
        scalars: &[f64],
        counters: &[u64],
        arrays: &[Vec<f64>],
    ) -> Result<(), &'static str> {
        match self {
            Workspace::WhFast(w) => w.load(scalars, counters, arrays),
            Workspace::Ias15(w) => w.load(scalars, counters, arrays),
            Workspace::Leapfrog(_) => Ok(()),
        }
    }

    /// Writes the state at the current time into `p` without changing what the next step
    /// starts from (WHFast synchronises a copy; the others are always synchronised).
    pub fn synchronized_view(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
    ) -> Result<(), GravityError> {
        match self {
            Workspace::WhFast(w) => w.synchronized_view(p, f, t),
            Workspace::Leapfrog(_) | Workspace::Ias15(_) => Ok(()),
        }
    }

    /// Whether the step is fixed (the simulation then keeps time as `t₀ + n dt`).
    pub fn is_fixed_step(&self) -> bool {
        matches!(self, Workspace::WhFast(_) | Workspace::Leapfrog(_))
    }

    /// Brings positions and velocities in `p` to the current time.
    pub fn synchronize(
        &mut self,
        p: &mut Particles,
        f: &mut Forces,
        t: f64,
    ) -> Result<(), GravityError> {
        match self {
            Workspace::WhFast(w) => w.synchronize(p, f, t),
            Workspace::Leapfrog(_) | Workspace::Ias15(_) => Ok(()),
        }
    }
}

/// Copies `src` into `dst` when the lengths agree.
pub(crate) fn load_array(dst: &mut [f64], src: &[f64]) -> Result<(), &'static str> {
    if dst.len() != src.len() {
        return Err("an integrator array of another length");
    }
    dst.copy_from_slice(src);
    Ok(())
}

/// `[x, y, z]` rows flattened, and back.
pub(crate) fn flatten3(v: &[[f64; 3]]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

pub(crate) fn load3(dst: &mut [[f64; 3]], src: &[f64]) -> Result<(), &'static str> {
    if 3 * dst.len() != src.len() {
        return Err("an integrator array of another length");
    }
    for (d, s) in dst.iter_mut().zip(src.chunks_exact(3)) {
        d.copy_from_slice(s);
    }
    Ok(())
}
