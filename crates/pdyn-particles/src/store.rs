//! [`Particles`]: positions, velocities, accelerations and masses as separate contiguous arrays.
//!
//! Structure of arrays rather than an array of structs: a force loop reads `x`, `y`, `z` of
//! every particle and writes `ax`, `ay`, `az`, so contiguous components let the compiler
//! vectorise it and let rayon split it into disjoint mutable chunks.

use crate::{ParticleError, Vec3};

/// One particle, as given by the user (array-of-structs form, for construction and output).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Particle {
    /// Mass (≥ 0; zero marks a test particle that feels but exerts no gravity).
    pub mass: f64,
    /// Position.
    pub pos: Vec3,
    /// Velocity.
    pub vel: Vec3,
}

/// A system of point masses in structure-of-arrays form.
///
/// Invariant: every array has length [`Particles::len`]; masses are finite and ≥ 0; positions
/// and velocities are finite when added (integrators may later produce non-finite values, which
/// [`Particles::first_non_finite`] finds).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Particles {
    /// Positions, one array per Cartesian component.
    pub x: Vec<f64>,
    /// See [`Particles::x`].
    pub y: Vec<f64>,
    /// See [`Particles::x`].
    pub z: Vec<f64>,
    /// Velocities, one array per component.
    pub vx: Vec<f64>,
    /// See [`Particles::vx`].
    pub vy: Vec<f64>,
    /// See [`Particles::vx`].
    pub vz: Vec<f64>,
    /// Accelerations, filled by a force computation.
    pub ax: Vec<f64>,
    /// See [`Particles::ax`].
    pub ay: Vec<f64>,
    /// See [`Particles::ax`].
    pub az: Vec<f64>,
    /// Masses.
    pub m: Vec<f64>,
}

impl Particles {
    /// An empty system.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty system with room for `n` particles, refused if `n > limit` (so a size from a
    /// file is checked before anything is allocated).
    pub fn with_capacity(n: usize, limit: usize) -> Result<Self, ParticleError> {
        if n > limit {
            return Err(ParticleError::TooMany {
                requested: n,
                limit,
            });
        }
        let v = || Vec::with_capacity(n);
        Ok(Particles {
            x: v(),
            y: v(),
            z: v(),
            vx: v(),
            vy: v(),
            vz: v(),
            ax: v(),
            ay: v(),
            az: v(),
            m: v(),
        })
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.m.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.m.is_empty()
    }

    /// Adds a particle after checking its mass and state; returns its index.
    pub fn push(&mut self, p: Particle) -> Result<usize, ParticleError> {
        let index = self.len();
        if !(p.mass.is_finite() && p.mass >= 0.0) {
            return Err(ParticleError::InvalidMass {
                index,
                mass: p.mass,
            });
        }
        for (what, v) in [("position", p.pos), ("velocity", p.vel)] {
            if !v.is_finite() {
                return Err(ParticleError::NonFinite {
                    index,
                    what,
                    value: v.0,
                });
            }
        }
        self.x.push(p.pos.0[0]);
        self.y.push(p.pos.0[1]);
        self.z.push(p.pos.0[2]);
        self.vx.push(p.vel.0[0]);
        self.vy.push(p.vel.0[1]);
        self.vz.push(p.vel.0[2]);
        self.ax.push(0.0);
        self.ay.push(0.0);
        self.az.push(0.0);
        self.m.push(p.mass);
        Ok(index)
    }

    /// Particle `i` in array-of-structs form.
    pub fn get(&self, i: usize) -> Particle {
        Particle {
            mass: self.m[i],
            pos: self.pos(i),
            vel: self.vel(i),
        }
    }

    /// Position of particle `i`.
    pub fn pos(&self, i: usize) -> Vec3 {
        Vec3([self.x[i], self.y[i], self.z[i]])
    }

    /// Velocity of particle `i`.
    pub fn vel(&self, i: usize) -> Vec3 {
        Vec3([self.vx[i], self.vy[i], self.vz[i]])
    }

    /// Acceleration of particle `i` (as last computed).
    pub fn acc(&self, i: usize) -> Vec3 {
        Vec3([self.ax[i], self.ay[i], self.az[i]])
    }

    /// Sets the position of particle `i`.
    pub fn set_pos(&mut self, i: usize, r: Vec3) {
        [self.x[i], self.y[i], self.z[i]] = r.0;
    }

    /// Sets the velocity of particle `i`.
    pub fn set_vel(&mut self, i: usize, v: Vec3) {
        [self.vx[i], self.vy[i], self.vz[i]] = v.0;
    }

    /// Sets every acceleration to zero.
    pub fn clear_acc(&mut self) {
        for a in [&mut self.ax, &mut self.ay, &mut self.az] {
            a.iter_mut().for_each(|v| *v = 0.0);
        }
    }

    /// Kick: `v ← v + h a` for every particle (the momentum half of a splitting step).
    pub fn kick(&mut self, h: f64) {
        axpy(&mut self.vx, h, &self.ax);
        axpy(&mut self.vy, h, &self.ay);
        axpy(&mut self.vz, h, &self.az);
    }

    /// Drift: `x ← x + h v` for every particle (the position half of a splitting step).
    pub fn drift(&mut self, h: f64) {
        axpy(&mut self.x, h, &self.vx);
        axpy(&mut self.y, h, &self.vy);
        axpy(&mut self.z, h, &self.vz);
    }

    /// Total mass `Σ mᵢ`.
    pub fn total_mass(&self) -> f64 {
        self.m.iter().sum()
    }

    /// Kinetic energy `½ Σ mᵢ |vᵢ|²`.
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * (0..self.len())
            .map(|i| self.m[i] * self.vel(i).norm2())
            .sum::<f64>()
    }

    /// Linear momentum `Σ mᵢ vᵢ`.
    pub fn momentum(&self) -> Vec3 {
        (0..self.len()).fold(Vec3::ZERO, |p, i| p + self.m[i] * self.vel(i))
    }

    /// Angular momentum about the origin `Σ mᵢ rᵢ × vᵢ`.
    pub fn angular_momentum(&self) -> Vec3 {
        (0..self.len()).fold(Vec3::ZERO, |l, i| {
            l + self.m[i] * self.pos(i).cross(self.vel(i))
        })
    }

    /// Centre of mass and its velocity; `None` when the total mass is zero.
    pub fn center_of_mass(&self) -> Option<(Vec3, Vec3)> {
        let mt = self.total_mass();
        if mt <= 0.0 {
            return None;
        }
        let r = (0..self.len()).fold(Vec3::ZERO, |s, i| s + self.m[i] * self.pos(i));
        Some(((1.0 / mt) * r, (1.0 / mt) * self.momentum()))
    }

    /// Moves to the centre-of-mass frame (position and velocity of the centre of mass become
    /// zero), as orbit codes do before integrating. No-op when the total mass is zero.
    pub fn move_to_center_of_mass(&mut self) {
        if let Some((r, v)) = self.center_of_mass() {
            for i in 0..self.len() {
                self.set_pos(i, self.pos(i) - r);
                self.set_vel(i, self.vel(i) - v);
            }
        }
    }

    /// The first particle whose position or velocity is not finite, if any.
    pub fn first_non_finite(&self) -> Option<usize> {
        (0..self.len()).find(|&i| !(self.pos(i).is_finite() && self.vel(i).is_finite()))
    }
}

fn axpy(y: &mut [f64], h: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += h * xi;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two() -> Particles {
        let mut p = Particles::new();
        p.push(Particle {
            mass: 1.0,
            pos: Vec3::new(1.0, 0.0, 0.0),
            vel: Vec3::new(0.0, 2.0, 0.0),
        })
        .unwrap();
        p.push(Particle {
            mass: 3.0,
            pos: Vec3::new(-1.0, 1.0, 0.0),
            vel: Vec3::new(1.0, 0.0, 0.0),
        })
        .unwrap();
        p
    }

    #[test]
    fn invariants_match_hand_computation() {
        let p = two();
        // T = ½(1·4 + 3·1) = 3.5; P = (3, 2, 0); L = 1·(1,0,0)×(0,2,0) + 3·(−1,1,0)×(1,0,0)
        //   = (0,0,2) + 3·(0,0,−1) = (0,0,−1)
        assert_eq!(p.kinetic_energy(), 3.5);
        assert_eq!(p.momentum(), Vec3::new(3.0, 2.0, 0.0));
        assert_eq!(p.angular_momentum(), Vec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn center_of_mass_frame_has_zero_momentum() {
        let mut p = two();
        p.move_to_center_of_mass();
        let (r, v) = p.center_of_mass().unwrap();
        assert!(r.norm() < 1e-15 && v.norm() < 1e-15);
        assert!(p.momentum().norm() < 1e-15);
    }

    #[test]
    fn kick_and_drift_are_explicit_euler_halves() {
        let mut p = two();
        p.ax[0] = 1.0;
        p.kick(0.5);
        assert_eq!(p.vel(0), Vec3::new(0.5, 2.0, 0.0));
        p.drift(2.0);
        assert_eq!(p.pos(0), Vec3::new(2.0, 4.0, 0.0));
    }

    #[test]
    fn bad_particles_are_refused_with_their_index() {
        let mut p = two();
        let bad = Particle {
            mass: -1.0,
            pos: Vec3::ZERO,
            vel: Vec3::ZERO,
        };
        assert_eq!(
            p.push(bad),
            Err(ParticleError::InvalidMass {
                index: 2,
                mass: -1.0
            })
        );
        let nan = Particle {
            mass: 1.0,
            pos: Vec3::new(f64::NAN, 0.0, 0.0),
            vel: Vec3::ZERO,
        };
        assert!(matches!(
            p.push(nan),
            Err(ParticleError::NonFinite {
                index: 2,
                what: "position",
                ..
            })
        ));
        assert_eq!(p.len(), 2);
        assert!(matches!(
            Particles::with_capacity(10, 5),
            Err(ParticleError::TooMany { .. })
        ));
    }
}
