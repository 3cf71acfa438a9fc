//! Mean-squared displacement `MSD(t) = (1/N) Σᵢ |rᵢ(t) − rᵢ(0)|²` from unwrapped positions
//! (`x + image·L`), single time origin. For a liquid `MSD ≈ 6 D t` at long times (Einstein).
//!
//! Its error bar comes from blocks of particles: the particles are cut into `B` contiguous
//! blocks by index (whole molecules, when molecules are numbered consecutively, as in LAMMPS
//! data files), the MSD of each block is taken, and the standard error of their mean is
//! `sd(blocks)/√B` (the blocks are nearly independent samples of the same displacement law).

use crate::System;
use pdyn_particles::Vec3;

/// MSD relative to the positions at construction.
#[derive(Debug, Clone)]
pub struct Msd {
    origin: Vec<Vec3>,
}

impl Msd {
    /// Takes the unwrapped positions of `s` as the time origin.
    pub fn new(s: &System) -> Self {
        Msd {
            origin: (0..s.particles.len()).map(|i| s.unwrapped(i)).collect(),
        }
    }

    /// The time origin: the unwrapped positions at construction (a checkpoint saves them).
    pub fn origin(&self) -> &[Vec3] {
        &self.origin
    }

    /// The MSD relative to `origin` (unwrapped positions, as [`Msd::origin`] returned them).
    pub fn from_origin(origin: Vec<Vec3>) -> Self {
        Msd { origin }
    }

    /// `MSD` of `s` relative to the origin (particles beyond the origin's count are ignored).
    pub fn value(&self, s: &System) -> f64 {
        let n = self.origin.len().min(s.particles.len());
        if n == 0 {
            return 0.0;
        }
        (0..n)
            .map(|i| (s.unwrapped(i) - self.origin[i]).norm2())
            .sum::<f64>()
            / n as f64
    }

    /// Standard error of [`Msd::value`] from `blocks` contiguous blocks of particles (see the
    /// module documentation); `None` with fewer than two blocks or fewer particles than
    /// blocks. Blocks differ in size by at most one particle; each block's MSD is weighted by
    /// its size in the mean, which then equals [`Msd::value`].
    pub fn block_error(&self, s: &System, blocks: usize) -> Option<f64> {
        let n = self.origin.len().min(s.particles.len());
        if blocks < 2 || n < blocks {
            return None;
        }
        let means: Vec<(f64, f64)> = (0..blocks)
            .map(|b| {
                let part = b * n / blocks..(b + 1) * n / blocks;
                let len = part.len() as f64;
                let sum = part
                    .map(|i| (s.unwrapped(i) - self.origin[i]).norm2())
                    .sum::<f64>();
                (sum / len, len)
            })
            .collect();
        let mean = means.iter().map(|(m, w)| m * w).sum::<f64>() / n as f64;
        let var = means.iter().map(|(m, _)| (m - mean).powi(2)).sum::<f64>()
            / (blocks * (blocks - 1)) as f64;
        Some(var.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::Msd;
    use crate::{Particle, Particles, SimBox, System, Vec3};

    /// Ten particles, moved by 1, 1, 2, 2, 3, 3, 4, 4, 5, 5 along x: five blocks of two have
    /// MSDs 1, 4, 9, 16, 25, mean 11, squared deviations 100 + 49 + 4 + 25 + 196 = 374,
    /// sample variance 374/4 = 93.5, standard error √(93.5/5) = √18.7.
    #[test]
    fn block_error_is_the_standard_error_of_the_block_means() {
        let mut p = Particles::new();
        for i in 0..10 {
            p.push(Particle {
                mass: 1.0,
                pos: Vec3([i as f64, 0.0, 0.0]),
                vel: Vec3::ZERO,
            })
            .unwrap();
        }
        let mut s = System::new(p, SimBox::cube(100.0).unwrap());
        let msd = Msd::new(&s);
        for i in 0..10 {
            s.particles.x[i] += (i / 2 + 1) as f64;
        }
        assert_eq!(msd.value(&s), 11.0);
        let e = msd.block_error(&s, 5).unwrap();
        assert!((e - 18.7f64.sqrt()).abs() < 1e-12, "{e}");
        assert_eq!(msd.block_error(&s, 1), None);
        assert_eq!(msd.block_error(&s, 11), None);
    }
}
