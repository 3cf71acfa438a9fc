//! Orthorhombic periodic box `[0, Lx) × [0, Ly) × [0, Lz)`.
//!
//! Minimum image: a separation component `d` is replaced by `d − L·round(d/L)`, the nearest
//! periodic image, valid for interactions shorter than `L/2`.

use crate::MdError;
use pdyn_particles::Vec3;

/// An orthorhombic periodic box with edge lengths `l = [Lx, Ly, Lz]` (length units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimBox {
    /// Edge lengths.
    pub l: [f64; 3],
}

impl SimBox {
    /// A box with positive, finite edges.
    pub fn new(lx: f64, ly: f64, lz: f64) -> Result<Self, MdError> {
        let l = [lx, ly, lz];
        if l.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(MdError::InvalidBox { lengths: l });
        }
        Ok(SimBox { l })
    }

    /// A cube of edge `l`.
    pub fn cube(l: f64) -> Result<Self, MdError> {
        Self::new(l, l, l)
    }

    /// Volume `Lx Ly Lz`.
    pub fn volume(&self) -> f64 {
        self.l[0] * self.l[1] * self.l[2]
    }

    /// Shortest edge.
    pub fn min_edge(&self) -> f64 {
        self.l[0].min(self.l[1]).min(self.l[2])
    }

    /// Minimum-image separation of a raw difference `d`.
    #[inline]
    pub fn minimum_image(&self, d: [f64; 3]) -> [f64; 3] {
        let mut o = d;
        for k in 0..3 {
            // below a quarter box (the common case: bonds, special pairs) round(d/L) is ±0 and
            // the result is d: skip the division and the call `round` is on the baseline
            // x86-64 target; likewise when d/L is below one half
            if d[k].abs() < 0.25 * self.l[k] {
                continue;
            }
            let q = d[k] / self.l[k];
            if q.abs() >= 0.5 {
                o[k] -= self.l[k] * q.round();
            }
        }
        o
    }

    /// Minimum-image vector from `b` to `a`.
    pub fn delta(&self, a: Vec3, b: Vec3) -> Vec3 {
        Vec3(self.minimum_image((a - b).0))
    }

    /// Wraps a coordinate into `[0, L)` along axis `k`; returns the wrapped value and the number
    /// of box lengths removed.
    #[inline]
    pub fn wrap(&self, k: usize, x: f64) -> (f64, i32) {
        let q = x / self.l[k];
        if 0.0 < q && q < 1.0 {
            // inside already (nearly always at a list build): what the general path gives,
            // without the call `floor` is on the baseline x86-64 target
            return (x, 0);
        }
        let n = q.floor();
        let mut w = x - n * self.l[k];
        let mut n = n as i32;
        if w >= self.l[k] {
            w -= self.l[k];
            n += 1;
        }
        (w, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_image_picks_nearest_image() {
        let b = SimBox::new(10.0, 20.0, 5.0).unwrap();
        let d = b.minimum_image([9.0, -11.0, 2.0]);
        assert_eq!(d, [-1.0, 9.0, 2.0]);
        // below a quarter, between a quarter and a half, beyond a half, several boxes away
        assert_eq!(b.minimum_image([2.0, 6.0, -2.6]), [2.0, 6.0, 2.4]);
        assert_eq!(b.minimum_image([-4.9, -31.0, 12.0]), [-4.9, 9.0, 2.0]);
        assert_eq!(b.wrap(0, -0.5), (9.5, -1));
        assert_eq!(b.wrap(2, 12.0), (2.0, 2));
        assert_eq!(b.wrap(2, 4.5), (4.5, 0));
        assert_eq!(b.wrap(2, 5.0), (0.0, 1));
        assert!(SimBox::new(1.0, 0.0, 1.0).is_err());
    }
}
