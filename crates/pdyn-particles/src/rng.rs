//! The seeded random-number generators of every many-particle set-up (Plummer spheres,
//! Maxwell–Boltzmann velocities, random lattices), in one place. Written here (a few lines)
//! rather than taken from `rand`, so that a model's initial conditions are the same on every
//! platform and across dependency upgrades: a seed in a model file names one trajectory.
//!
//! - [`SplitMix64`] (Steele, Lea & Flood 2014): one `u64` of state, passes BigCrush; also the
//!   seeding function of the other.
//! - [`Rng`]: xoshiro256** (Blackman & Vigna, ACM TOMS 47, 36 (2021)) seeded by SplitMix64,
//!   with standard normals by the Marsaglia polar method.

/// SplitMix64: `state += 0x9E3779B97F4A7C15`, then a 64-bit mix of the state.
#[derive(Debug, Clone)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started from `seed` (same seed, same sequence, on every platform).
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        unit_interval(self.next_u64())
    }

    /// Uniform in `[lo, hi)`.
    pub fn uniform_in(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}

/// The top 53 bits of `bits` as a float in `[0, 1)`.
fn unit_interval(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Seeded pseudo-random generator (xoshiro256**), with normal deviates.
#[derive(Debug, Clone)]
pub struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl Rng {
    /// A generator whose whole stream is fixed by `seed` (its state: the first four outputs
    /// of [`SplitMix64`] from `seed`, as the xoshiro authors recommend).
    pub fn new(seed: u64) -> Self {
        let mut seeder = SplitMix64::new(seed);
        Rng {
            s: [
                seeder.next_u64(),
                seeder.next_u64(),
                seeder.next_u64(),
                seeder.next_u64(),
            ],
            spare: None,
        }
    }

    /// The generator's whole state: the four xoshiro256** words and the normal deviate the
    /// polar method holds back for the next call, if any (a checkpoint saves them to continue
    /// the stream exactly: [`Rng::from_state`]).
    pub fn state(&self) -> ([u64; 4], Option<f64>) {
        (self.s, self.spare)
    }

    /// The generator whose state [`Rng::state`] returned.
    pub fn from_state(words: [u64; 4], spare: Option<f64>) -> Self {
        Rng { s: words, spare }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let r = self.s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = self.s[1] << 17;
        self.s[2] ^= self.s[0];
        self.s[3] ^= self.s[1];
        self.s[1] ^= self.s[2];
        self.s[0] ^= self.s[3];
        self.s[2] ^= t;
        self.s[3] = self.s[3].rotate_left(45);
        r
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        unit_interval(self.next_u64())
    }

    /// Standard normal deviate (mean 0, variance 1).
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        loop {
            let u = 2.0 * self.uniform() - 1.0;
            let v = 2.0 * self.uniform() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let k = (-2.0 * libm::log(s) / s).sqrt();
                self.spare = Some(v * k);
                return u * k;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_have_unit_variance() {
        let mut r = Rng::new(7);
        let n = 200_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let z = r.normal();
            s1 += z;
            s2 += z * z;
        }
        assert!((s1 / n as f64).abs() < 0.01);
        assert!((s2 / n as f64 - 1.0).abs() < 0.01);
    }

    /// The published first outputs: SplitMix64 from seed 0 (Vigna's reference `splitmix64.c`)
    /// and xoshiro256** from the state [1, 2, 3, 4] (its reference `xoshiro256starstar.c`).
    #[test]
    fn reference_outputs() {
        let mut s = SplitMix64::new(0);
        assert_eq!(s.next_u64(), 0xe220_a839_7b1d_cdaf);
        let mut x = Rng {
            s: [1, 2, 3, 4],
            spare: None,
        };
        assert_eq!(x.next_u64(), 11520);
        assert_eq!(x.next_u64(), 0);
        assert_eq!(x.next_u64(), 1_509_978_240);
    }
}
