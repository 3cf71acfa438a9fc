//! Mean-squared displacement `MSD(t) = (1/N) Σᵢ |rᵢ(t) − rᵢ(0)|²` from unwrapped positions
//! (`x + image·L`), single time origin. For a liquid `MSD ≈ 6 D t` at long times (Einstein).

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
}
