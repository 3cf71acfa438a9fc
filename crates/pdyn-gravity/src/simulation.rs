//! [`Simulation`]: bodies, `G`, integrator, step, events; the type upper layers drive.

use std::collections::HashMap;

use pdyn_particles::{Particle, Particles, Vec3};

use crate::error::{GravityError, Warning};
use crate::forces::{direct, Forces, Gravity};
use crate::integrators::{Integrator, Workspace};
use crate::orbit::{cartesian_to_orbit, elements_to_cartesian, Elements, Orbit};
use crate::units::Units;

/// The body (or bodies) an orbit is measured about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Primary {
    /// The centre of mass of all bodies with a smaller index (Jacobi elements; REBOUND's
    /// default for `sim.add(...)`).
    #[default]
    Interior,
    /// One body.
    Body(usize),
}

/// What stopped [`Simulation::integrate`].
///
/// Events are checked after every step on the positions the step leaves in the particle
/// arrays: the end-of-step positions for IAS15 and leapfrog, the mid-step (kick) positions
/// for WHFast, which keeps Jacobi coordinates between steps. The particles are synchronised
/// before `integrate` returns, so [`Simulation::particles`] is the state at the reported time;
/// WHFast synchronises a copy and continues from its own state, so integrating to `t₁` and
/// then to `t₂` is bit for bit integrating to `t₂` (when `t₁` is on the step grid).
/// Collision detection is a direct `O(N²)` pair test, run only when some radius is positive.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Outcome {
    /// The requested end time was reached.
    Reached,
    /// Two bodies touch: `|rᵢ − rⱼ| < Rᵢ + Rⱼ` (checked after every step).
    Collision {
        /// Time of the step that found it.
        t: f64,
        /// The lower index.
        i: usize,
        /// The higher index.
        j: usize,
    },
    /// A body is farther from the origin than [`EventParams::escape_distance`].
    Escape {
        /// Time of the step that found it.
        t: f64,
        /// The body.
        index: usize,
        /// Its distance from the origin.
        distance: f64,
    },
}

/// Which events stop an integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventParams {
    /// Detect collisions between bodies with positive radii.
    pub collisions: bool,
    /// Report the first body beyond this distance from the origin (`None`: never).
    pub escape_distance: Option<f64>,
}

impl Default for EventParams {
    fn default() -> Self {
        EventParams {
            collisions: true,
            escape_distance: None,
        }
    }
}

/// A step of an adaptive integrator at most this fraction of the time (the larger of the
/// current and the end time) is a crawl: 10¹² of them to double `t`. A close encounter takes a
/// few; [`MAX_CRAWL_STEPS`] in a row stop the run ([`GravityError::StepSizeUnderflow`]).
pub const MIN_RELATIVE_STEP: f64 = 1e-12;
/// Consecutive steps below [`MIN_RELATIVE_STEP`] that stop a run.
pub const MAX_CRAWL_STEPS: u64 = 10_000;

/// Everything a [`Simulation`] needs to continue bit for bit (a checkpoint, issue 29), as
/// plain numbers: the particles, the radii, the clock, the step and the integrator's
/// workspace (WHFast's Jacobi state, IAS15's predictor and compensated sums). The layout is
/// this crate's; a reader stores the numbers exactly (as bits) and hands them back to
/// [`Simulation::restore`] on a simulation built from the same model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Snapshot {
    /// `none` (no step taken yet), `whfast`, `ias15` or `leapfrog`.
    pub workspace: String,
    /// `t`, `dt`, `t_origin`, then the workspace's own.
    pub scalars: Vec<f64>,
    /// `steps`, `crawl`, `n_fixed`, then the workspace's own.
    pub counters: Vec<u64>,
    /// `x, y, z, vx, vy, vz, ax, ay, az, m`, radii, then the workspace's arrays.
    pub arrays: Vec<Vec<f64>>,
}

/// A self-gravitating system of point masses and how to integrate it.
#[derive(Debug, Clone)]
pub struct Simulation {
    particles: Particles,
    radii: Vec<f64>,
    seen: HashMap<[u64; 3], usize>,
    t: f64,
    dt: f64,
    forces: Forces,
    integrator: Integrator,
    events: EventParams,
    workspace: Option<Workspace>,
    warnings: Vec<Warning>,
    steps: u64,
    /// Consecutive adaptive steps of at most [`MIN_RELATIVE_STEP`] of the time.
    crawl: u64,
    /// Fixed-step time keeping: `t = t_origin + n_fixed · dt` (no accumulated round-off).
    t_origin: f64,
    n_fixed: u64,
}

fn key(v: Vec3) -> [u64; 3] {
    // +0.0 folds −0.0 onto 0.0 so both spell the same position.
    v.0.map(|c| (c + 0.0).to_bits())
}

impl Simulation {
    /// An empty simulation in the given units, integrated by WHFast (no corrector) with
    /// `dt = 0.01` and direct-summation forces.
    pub fn new(units: Units) -> Self {
        Simulation {
            particles: Particles::new(),
            radii: Vec::new(),
            seen: HashMap::new(),
            t: 0.0,
            dt: 0.01,
            forces: Forces {
                g: units.g(),
                eps2: 0.0,
                kind: Gravity::Direct,
                tree: crate::forces::Octree::new(),
                direct: crate::forces::direct::DirectWorkspace::new(),
            },
            integrator: Integrator::default(),
            events: EventParams::default(),
            workspace: None,
            warnings: Vec::new(),
            steps: 0,
            crawl: 0,
            t_origin: 0.0,
            n_fixed: 0,
        }
    }

    /// Adds a point mass; returns its index. Refuses non-finite or negative masses, non-finite
    /// states and a position identical to an existing body's.
    pub fn add(&mut self, p: Particle) -> Result<usize, GravityError> {
        self.add_with_radius(p, 0.0)
    }

    /// Adds a body with a collision radius (≥ 0).
    pub fn add_with_radius(&mut self, p: Particle, radius: f64) -> Result<usize, GravityError> {
        let index = self.particles.len();
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(GravityError::InvalidRadius { index, radius });
        }
        if let Some(&other) = self.seen.get(&key(p.pos)) {
            if p.pos.is_finite() {
                return Err(GravityError::Coincident { index, other });
            }
        }
        self.synchronize()?;
        self.particles.push(p)?;
        self.seen.insert(key(p.pos), index);
        self.radii.push(radius);
        self.reset_workspace();
        Ok(index)
    }

    /// Adds a body of mass `mass` on the orbit `el` about `primary`, with
    /// `μ = G (M_primary + mass)`; returns its index.
    pub fn add_orbit(
        &mut self,
        mass: f64,
        el: &Elements,
        primary: Primary,
    ) -> Result<usize, GravityError> {
        self.add_orbit_with_radius(mass, el, primary, 0.0)
    }

    /// [`Simulation::add_orbit`] for a body with a collision radius (≥ 0).
    pub fn add_orbit_with_radius(
        &mut self,
        mass: f64,
        el: &Elements,
        primary: Primary,
        radius: f64,
    ) -> Result<usize, GravityError> {
        let index = self.particles.len();
        let (mp, rp, vp) = self.primary_state(index, primary)?;
        let (r, v) = elements_to_cartesian(self.forces.g * (mp + mass), el)?;
        self.add_with_radius(
            Particle {
                mass,
                pos: rp + r,
                vel: vp + v,
            },
            radius,
        )
    }

    fn primary_state(
        &self,
        index: usize,
        primary: Primary,
    ) -> Result<(f64, Vec3, Vec3), GravityError> {
        let p = &self.particles;
        let (m, r, v) = match primary {
            Primary::Body(j) => {
                if j >= p.len() {
                    return Err(GravityError::NoSuchBody {
                        index: j,
                        len: p.len(),
                    });
                }
                if j == index {
                    return Err(GravityError::InvalidPrimary { index });
                }
                (p.m[j], p.pos(j), p.vel(j))
            }
            Primary::Interior => {
                let n = index.min(p.len());
                let m: f64 = p.m[..n].iter().sum();
                if m <= 0.0 {
                    return Err(GravityError::InvalidPrimary { index });
                }
                let (mut r, mut v) = (Vec3::ZERO, Vec3::ZERO);
                for j in 0..n {
                    r += p.m[j] * p.pos(j);
                    v += p.m[j] * p.vel(j);
                }
                (m, (1.0 / m) * r, (1.0 / m) * v)
            }
        };
        if m <= 0.0 {
            return Err(GravityError::InvalidPrimary { index });
        }
        Ok((m, r, v))
    }

    fn reset_workspace(&mut self) {
        self.workspace = None;
        self.t_origin = self.t;
        self.n_fixed = 0;
    }

    /// Orbital elements of body `index` about `primary`.
    pub fn orbit(&self, index: usize, primary: Primary) -> Result<Orbit, GravityError> {
        if index >= self.particles.len() {
            return Err(GravityError::NoSuchBody {
                index,
                len: self.particles.len(),
            });
        }
        let (mp, rp, vp) = self.primary_state(index, primary)?;
        let p = &self.particles;
        cartesian_to_orbit(
            self.forces.g * (mp + p.m[index]),
            p.pos(index) - rp,
            p.vel(index) - vp,
        )
        .ok_or(GravityError::InvalidPrimary { index })
    }

    /// Sets the (initial) step; must be finite and > 0. IAS15 adapts it afterwards.
    pub fn set_dt(&mut self, dt: f64) -> Result<(), GravityError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(GravityError::InvalidTimeStep { dt });
        }
        self.synchronize()?;
        self.dt = dt;
        self.reset_workspace();
        Ok(())
    }

    /// Chooses the integrator (takes effect at the next [`Simulation::integrate`]).
    pub fn set_integrator(&mut self, integrator: Integrator) -> Result<(), GravityError> {
        self.synchronize()?;
        self.integrator = integrator;
        self.reset_workspace();
        Ok(())
    }

    /// Chooses the force computation.
    pub fn set_gravity(&mut self, gravity: Gravity) -> Result<(), GravityError> {
        if let Gravity::Tree(t) = gravity {
            if !(t.theta.is_finite() && t.theta >= 0.0) {
                return Err(GravityError::InvalidParameter {
                    name: "theta",
                    value: t.theta,
                });
            }
        }
        self.synchronize()?;
        self.forces.kind = gravity;
        self.reset_workspace();
        Ok(())
    }

    /// Plummer softening length `ε ≥ 0` (default 0).
    pub fn set_softening(&mut self, eps: f64) -> Result<(), GravityError> {
        if !(eps.is_finite() && eps >= 0.0) {
            return Err(GravityError::InvalidParameter {
                name: "softening",
                value: eps,
            });
        }
        self.synchronize()?;
        self.forces.eps2 = eps * eps;
        self.reset_workspace();
        Ok(())
    }

    /// Chooses which events stop [`Simulation::integrate`].
    pub fn set_events(&mut self, events: EventParams) {
        self.events = events;
    }

    /// Moves to the centre-of-mass frame.
    pub fn move_to_center_of_mass(&mut self) -> Result<(), GravityError> {
        self.synchronize()?;
        self.particles.move_to_center_of_mass();
        self.seen = (0..self.particles.len())
            .map(|i| (key(self.particles.pos(i)), i))
            .collect();
        self.reset_workspace();
        Ok(())
    }

    /// The state to continue from, exactly ([`Snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        let p = &self.particles;
        let mut s = Snapshot {
            workspace: "none".into(),
            scalars: vec![self.t, self.dt, self.t_origin],
            counters: vec![self.steps, self.crawl, self.n_fixed],
            arrays: [
                &p.x, &p.y, &p.z, &p.vx, &p.vy, &p.vz, &p.ax, &p.ay, &p.az, &p.m,
            ]
            .into_iter()
            .cloned()
            .chain(std::iter::once(self.radii.clone()))
            .collect(),
        };
        if let Some(ws) = &self.workspace {
            s.workspace = ws
                .save(&mut s.scalars, &mut s.counters, &mut s.arrays)
                .into();
        }
        s
    }

    /// Continues from `s`, taken by [`Simulation::snapshot`] of a simulation built the same
    /// way (integrator, forces, units). A snapshot that does not fit is refused and the
    /// simulation is left as it was.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), GravityError> {
        let bad = |what: &'static str| GravityError::BadSnapshot { what };
        if s.scalars.len() < 3 || s.counters.len() < 3 || s.arrays.len() < 11 {
            return Err(bad("too few numbers"));
        }
        let n = s.arrays[0].len();
        if s.arrays[..11].iter().any(|a| a.len() != n) {
            return Err(bad("particle arrays of different lengths"));
        }
        let mut particles = Particles::new();
        {
            let p = &mut particles;
            for (dst, src) in [
                &mut p.x, &mut p.y, &mut p.z, &mut p.vx, &mut p.vy, &mut p.vz, &mut p.ax,
                &mut p.ay, &mut p.az, &mut p.m,
            ]
            .into_iter()
            .zip(&s.arrays)
            {
                dst.clone_from(src);
            }
        }
        let mut warnings = Vec::new();
        let workspace = match s.workspace.as_str() {
            "none" => None,
            name => {
                if name != Workspace::name_of(self.integrator) {
                    return Err(bad("another integrator"));
                }
                let mut ws = Workspace::new(
                    self.integrator,
                    &particles,
                    self.forces.g,
                    s.scalars[1],
                    &mut warnings,
                )?;
                ws.load(&s.scalars[3..], &s.counters[3..], &s.arrays[11..])
                    .map_err(bad)?;
                Some(ws)
            }
        };
        self.particles = particles;
        self.radii.clone_from(&s.arrays[10]);
        self.seen.clear();
        self.t = s.scalars[0];
        self.dt = s.scalars[1];
        self.t_origin = s.scalars[2];
        self.steps = s.counters[0];
        self.crawl = s.counters[1];
        self.n_fixed = s.counters[2];
        self.workspace = workspace;
        self.warnings.extend(warnings);
        Ok(())
    }

    /// Integrates to `t_end` (≥ the current time), stopping early at an event. An adaptive
    /// integrator whose step stays at [`MIN_RELATIVE_STEP`] of the time or less for
    /// [`MAX_CRAWL_STEPS`] steps in a row is stopped with
    /// [`GravityError::StepSizeUnderflow`]. Fixed-step
    /// integrators shorten their last step to land on `t_end` exactly. On return the
    /// particles are synchronised to [`Simulation::t`].
    pub fn integrate(&mut self, t_end: f64) -> Result<Outcome, GravityError> {
        if !(t_end.is_finite() && t_end >= self.t) {
            return Err(GravityError::InvalidEndTime { t: self.t, t_end });
        }
        if self.particles.is_empty() {
            self.t = t_end;
            return Ok(Outcome::Reached);
        }
        let ws = match &mut self.workspace {
            Some(ws) => ws,
            slot @ None => slot.insert(Workspace::new(
                self.integrator,
                &self.particles,
                self.forces.g,
                self.dt,
                &mut self.warnings,
            )?),
        };
        let check_collisions = self.events.collisions && self.radii.iter().any(|&r| r > 0.0);
        let mut outcome = Outcome::Reached;
        let tol = 1e-12 * t_end.abs().max(self.dt);
        while t_end - self.t > tol {
            let dt_before = self.dt;
            let h = ws.step(
                &mut self.particles,
                &mut self.forces,
                self.t,
                &mut self.dt,
                t_end - self.t,
                &mut self.warnings,
            )?;
            if h == dt_before && ws.is_fixed_step() {
                self.n_fixed += 1;
                self.t = self.t_origin + self.n_fixed as f64 * self.dt;
            } else {
                self.t += h;
            }
            if (t_end - self.t).abs() <= tol.max(1e-9 * h) {
                self.t = t_end;
            }
            if h != self.dt || self.t == t_end {
                self.t_origin = self.t;
                self.n_fixed = 0;
            }
            self.steps += 1;
            // An adaptive step that stays collapsed near the round-off of the time cannot
            // finish: at 10⁻¹² of t it would take 10¹² steps to double t (the figure-eight
            // with vx3 = 1e20 crawled on for minutes at steps of 10⁻²⁴ with t ≈ 10⁻⁸). A close
            // encounter takes such steps too, briefly: only a long run of them stops.
            if !ws.is_fixed_step()
                && self.dt.abs() <= MIN_RELATIVE_STEP * self.t.abs().max(t_end.abs())
            {
                self.crawl += 1;
                if self.crawl > MAX_CRAWL_STEPS {
                    return Err(GravityError::StepSizeUnderflow {
                        t: self.t,
                        dt: self.dt,
                    });
                }
            } else {
                self.crawl = 0;
            }
            if let Some(i) = first_non_finite_pos(&self.particles) {
                return Err(GravityError::NonFinite {
                    t: self.t,
                    index: i,
                });
            }
            if check_collisions {
                if let Some((i, j)) = first_collision(&self.particles, &self.radii) {
                    outcome = Outcome::Collision { t: self.t, i, j };
                    break;
                }
            }
            if let Some(dmax) = self.events.escape_distance {
                if let Some((index, distance)) = first_escape(&self.particles, dmax) {
                    outcome = Outcome::Escape {
                        t: self.t,
                        index,
                        distance,
                    };
                    break;
                }
            }
        }
        // The particles show the state at `self.t`; the integrator goes on from its own
        // (for WHFast: unsynchronised, uncorrected) state, so outputs do not perturb the run.
        ws.synchronized_view(&mut self.particles, &mut self.forces, self.t)?;
        if let Some(i) = self.particles.first_non_finite() {
            return Err(GravityError::NonFinite {
                t: self.t,
                index: i,
            });
        }
        Ok(outcome)
    }

    /// Brings the particles to the current time (WHFast keeps Jacobi coordinates between
    /// steps); [`Simulation::integrate`] does this before returning.
    pub fn synchronize(&mut self) -> Result<(), GravityError> {
        if let Some(ws) = self.workspace.as_mut() {
            ws.synchronize(&mut self.particles, &mut self.forces, self.t)?;
        }
        Ok(())
    }

    /// The bodies (synchronised after [`Simulation::integrate`]).
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// Collision radii, one per body.
    pub fn radii(&self) -> &[f64] {
        &self.radii
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Whether there are no bodies.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current (nominal) step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The gravitational constant.
    pub fn g(&self) -> f64 {
        self.forces.g
    }

    /// Steps taken so far (accepted steps for adaptive integrators).
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Warnings raised so far.
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// Total energy `T + V` (kinetic plus softened pairwise potential).
    pub fn energy(&self) -> f64 {
        self.particles.kinetic_energy()
            + direct::potential_energy(&self.particles, self.forces.g, self.forces.eps2)
    }

    /// Angular momentum about the origin.
    pub fn angular_momentum(&self) -> Vec3 {
        self.particles.angular_momentum()
    }

    /// Linear momentum.
    pub fn momentum(&self) -> Vec3 {
        self.particles.momentum()
    }
}

fn first_non_finite_pos(p: &Particles) -> Option<usize> {
    (0..p.len()).find(|&i| !p.pos(i).is_finite())
}

fn first_collision(p: &Particles, radii: &[f64]) -> Option<(usize, usize)> {
    let n = p.len();
    for i in 0..n {
        for j in i + 1..n {
            let s = radii[i] + radii[j];
            if s > 0.0 && (p.pos(i) - p.pos(j)).norm2() < s * s {
                return Some((i, j));
            }
        }
    }
    None
}

fn first_escape(p: &Particles, dmax: f64) -> Option<(usize, f64)> {
    (0..p.len()).find_map(|i| {
        let d = p.pos(i).norm();
        (d > dmax).then_some((i, d))
    })
}
