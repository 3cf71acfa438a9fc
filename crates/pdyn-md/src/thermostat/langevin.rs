//! Langevin dynamics `m v̇ = F − γ m v + √(2γ m k_B T) η(t)` integrated by BAOAB (Leimkuhler &
//! Matthews, Appl. Math. Res. Express 2013, 34 (2013)): the O step is the exact
//! Ornstein–Uhlenbeck update `v ← c₁ v + √((1 − c₁²) k_B T/m) ξ`, `c₁ = e^{−γh}`, with one
//! seeded normal deviate per component drawn in particle order (reproducible, thread-count
//! independent), by the ziggurat method ([`Rng::normal_ziggurat`]: Gaussian noise as BAOAB
//! requires, at a fraction of the polar method's cost, which was a sixth of an in.chain
//! step). Configurational averages carry an `O(h²)` error only.
//!
//! Opt-in, [`LangevinScheme::Lammps`]: LAMMPS's `fix langevin` + `fix nve`, to reproduce a
//! LAMMPS run's numbers at its own step. Plain velocity Verlet whose force, after the pair and
//! bond forces of each step (LAMMPS `post_force`, also once at set-up), gains a friction and
//! a random force evaluated with the velocities of that moment, the half-step ones
//! `v(t + h/2)` (at set-up, `v(0)`):
//! `F ← F − (m/damp) v + √(24 k_B T m/(h·damp)) (u − ½)`, `u` uniform in `[0, 1)` per
//! component (LAMMPS's default; variance `2 k_B T m/(h·damp)`), or with
//! [`LangevinNoise::Gaussian`] `√(2 k_B T m/(h·damp)) ξ`. The sum then enters both half-kicks
//! around the step's end. Its configurational error is larger than BAOAB's (measured on
//! LAMMPS's in.chain at dt = 0.012: bond lengths 2 % wider, PE/N 0.03 higher than at small
//! steps), which is why BAOAB is the default.

use super::{positive, target};
use crate::{MdError, Rng};
use pdyn_particles::Particles;

/// Langevin parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LangevinParams {
    /// Target temperature (required; default `None`).
    pub temperature: Option<f64>,
    /// Damping time `1/γ` (time units; default 1.0, i.e. 200 steps of 0.005).
    pub damping: f64,
    /// Seed of the noise (default 1).
    pub seed: u64,
}

/// How the Langevin equation is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LangevinScheme {
    /// BAOAB (default): exact Ornstein–Uhlenbeck step between two half-drifts.
    #[default]
    Baoab,
    /// LAMMPS's `fix langevin` + `fix nve`: friction and noise added to the force.
    Lammps {
        /// Distribution of the random force.
        noise: LangevinNoise,
    },
}

/// Distribution of the random force of [`LangevinScheme::Lammps`] (same variance either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LangevinNoise {
    /// Uniform on a symmetric interval (LAMMPS's default).
    #[default]
    Uniform,
    /// Normal.
    Gaussian,
}

impl Default for LangevinParams {
    fn default() -> Self {
        LangevinParams {
            temperature: None,
            damping: 1.0,
            seed: 1,
        }
    }
}

/// Langevin thermostat state.
#[derive(Debug, Clone)]
pub struct Langevin {
    /// Target temperature.
    pub temperature: f64,
    gamma: f64,
    rng: Rng,
    scheme: LangevinScheme,
    /// Friction plus random force of the last draw ([`LangevinScheme::Lammps`] only), read by
    /// the force sum of the same step (not saved: a checkpoint keeps the accelerations that
    /// include it).
    post_force: Vec<[f64; 3]>,
}

impl Langevin {
    /// Checks the parameters.
    pub fn new(p: LangevinParams) -> Result<Self, MdError> {
        Ok(Langevin {
            temperature: target(p.temperature, "langevin")?,
            gamma: 1.0 / positive("damping", p.damping)?,
            rng: Rng::new(p.seed),
            scheme: LangevinScheme::Baoab,
            post_force: Vec::new(),
        })
    }

    /// The same thermostat integrated by `scheme` (default [`LangevinScheme::Baoab`]).
    pub fn with_scheme(mut self, scheme: LangevinScheme) -> Self {
        self.scheme = scheme;
        self
    }

    /// The integration scheme.
    pub fn scheme(&self) -> LangevinScheme {
        self.scheme
    }

    /// Whether the O step of BAOAB runs (else the forces carry friction and noise).
    pub(crate) fn is_baoab(&self) -> bool {
        self.scheme == LangevinScheme::Baoab
    }

    /// [`LangevinScheme::Lammps`]: draws the friction and random force of every particle
    /// from the velocities now (LAMMPS `FixLangevin::post_force`: `γ₁ = −m/damp`,
    /// `γ₂ = √m·√(24 k_B T/(damp·h))`, `F += γ₁ v + γ₂ (u − ½)` per component, in particle
    /// order x, y, z). Does nothing under BAOAB.
    pub(crate) fn draw_post_force(&mut self, p: &Particles, h: f64, kb: f64) {
        let LangevinScheme::Lammps { noise } = self.scheme else {
            return;
        };
        let damp = 1.0 / self.gamma;
        let n = p.len();
        self.post_force.resize(n, [0.0; 3]);
        for i in 0..n {
            let m = p.m[i];
            if m <= 0.0 {
                self.post_force[i] = [0.0; 3];
                continue;
            }
            let gamma1 = -m / damp;
            let v = [p.vx[i], p.vy[i], p.vz[i]];
            let mut f = [0.0; 3];
            for (fk, vk) in f.iter_mut().zip(v) {
                let random = match noise {
                    LangevinNoise::Uniform => {
                        m.sqrt()
                            * (24.0 * kb * self.temperature / damp / h).sqrt()
                            * (self.rng.uniform() - 0.5)
                    }
                    LangevinNoise::Gaussian => {
                        m.sqrt()
                            * (2.0 * kb * self.temperature / damp / h).sqrt()
                            * self.rng.normal_ziggurat()
                    }
                };
                *fk = gamma1 * vk + random;
            }
            self.post_force[i] = f;
        }
    }

    /// The forces of the last [`Langevin::draw_post_force`] (`None` under BAOAB).
    pub(crate) fn post_force(&self) -> Option<&[[f64; 3]]> {
        match self.scheme {
            LangevinScheme::Lammps { .. } => Some(&self.post_force),
            LangevinScheme::Baoab => None,
        }
    }

    /// The noise generator's state (xoshiro256** words, the held-back normal deviate).
    pub(crate) fn rng_state(&self) -> ([u64; 4], Option<f64>) {
        self.rng.state()
    }

    /// Continues the noise from a saved [`Langevin::rng_state`].
    pub(crate) fn set_rng_state(&mut self, words: [u64; 4], spare: Option<f64>) {
        self.rng = Rng::from_state(words, spare);
    }

    /// The O step over `h`.
    pub(crate) fn ou_step(&mut self, p: &mut Particles, h: f64, kb: f64) {
        let c1 = libm::exp(-self.gamma * h);
        let c2 = (1.0 - c1 * c1).sqrt();
        for i in 0..p.len() {
            if p.m[i] <= 0.0 {
                continue;
            }
            let s = c2 * (kb * self.temperature / p.m[i]).sqrt();
            p.vx[i] = c1 * p.vx[i] + s * self.rng.normal_ziggurat();
            p.vy[i] = c1 * p.vy[i] + s * self.rng.normal_ziggurat();
            p.vz[i] = c1 * p.vz[i] + s * self.rng.normal_ziggurat();
        }
    }
}
