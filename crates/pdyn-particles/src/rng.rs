//! The seeded random-number generators of every many-particle set-up (Plummer spheres,
//! Maxwell–Boltzmann velocities, random lattices), in one place. Written here (a few lines)
//! rather than taken from `rand`, so that a model's initial conditions are the same on every
//! platform and across dependency upgrades: a seed in a model file names one trajectory.
//!
//! - [`SplitMix64`] (Steele, Lea & Flood 2014): one `u64` of state, passes BigCrush; also the
//!   seeding function of the other.
//! - [`Rng`]: xoshiro256** (Blackman & Vigna, ACM TOMS 47, 36 (2021)) seeded by SplitMix64,
//!   with standard normals by the Marsaglia polar method ([`Rng::normal`], for initial
//!   conditions) or by the ziggurat method ([`Rng::normal_ziggurat`], about three times
//!   faster, for the thermostat noise drawn at every step).

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

/// Layers of the ziggurat.
const ZIG_LAYERS: usize = 256;
/// Right edge `R` of the base layer for 256 layers of area `V` under `e^{−x²/2}`: the root
/// of "the recursion `x_{i+1} = √(−2 ln(V/x_i + e^{−x_i²/2}))` from `x_1 = R` closes the top
/// layer with area `V`" (solved by bisection in double precision; Marsaglia & Tsang, J. Stat.
/// Softw. 5(8) (2000) give 3.6541528853610088).
const ZIG_R: f64 = 3.654_152_885_361_009;

/// The ziggurat's layer edges `x` (`x[0] = V/f(R)`, the base layer's virtual width with its
/// tail; `x[1] = R`; … `x[256] = 0`) and the ratios `x[i+1]/x[i]` below which a point of layer
/// `i` lies under the curve for sure (Doornik's ZIGNOR layout, "An Improved Ziggurat Method
/// to Generate Normal Random Samples", 2005).
struct Ziggurat {
    x: [f64; ZIG_LAYERS + 1],
    ratio: [f64; ZIG_LAYERS],
}

fn ziggurat() -> &'static Ziggurat {
    static TABLES: std::sync::OnceLock<Ziggurat> = std::sync::OnceLock::new();
    TABLES.get_or_init(|| {
        let r = ZIG_R;
        let mut f = libm::exp(-0.5 * r * r);
        // area of every layer: the base rectangle R·f(R) plus the tail ∫_R^∞ e^{−x²/2} dx
        let v =
            r * f + (std::f64::consts::PI / 2.0).sqrt() * libm::erfc(r / std::f64::consts::SQRT_2);
        let mut x = [0.0; ZIG_LAYERS + 1];
        x[0] = v / f;
        x[1] = r;
        for i in 2..ZIG_LAYERS {
            // min: round-off must not push the top layers' argument past 1
            let a = (v / x[i - 1] + f).min(1.0);
            x[i] = (-2.0 * libm::log(a)).sqrt();
            f = libm::exp(-0.5 * x[i] * x[i]);
        }
        x[ZIG_LAYERS] = 0.0;
        let mut ratio = [0.0; ZIG_LAYERS];
        for i in 0..ZIG_LAYERS {
            ratio[i] = x[i + 1] / x[i];
        }
        Ziggurat { x, ratio }
    })
}

impl Rng {
    /// Standard normal deviate by the ziggurat method (Marsaglia & Tsang 2000, in Doornik's
    /// form): one 64-bit draw picks the layer (low 8 bits) and the abscissa (top 53 bits),
    /// and about 99 % of draws return at once; the rest go through the wedge test or
    /// Marsaglia's tail algorithm. Exact in distribution like [`Rng::normal`], but a different
    /// sequence from the same state; it neither uses nor sets the polar method's held-back
    /// deviate.
    #[inline]
    pub fn normal_ziggurat(&mut self) -> f64 {
        let z = ziggurat();
        loop {
            let bits = self.next_u64();
            let i = (bits & (ZIG_LAYERS as u64 - 1)) as usize;
            let u = 2.0 * unit_interval(bits) - 1.0;
            if u.abs() < z.ratio[i] {
                return u * z.x[i];
            }
            if let Some(x) = self.ziggurat_slow(z, i, u) {
                return x;
            }
        }
    }

    /// The base layer's tail and the other layers' wedges (about 1 % of draws).
    #[cold]
    fn ziggurat_slow(&mut self, z: &Ziggurat, i: usize, u: f64) -> Option<f64> {
        if i == 0 {
            // Marsaglia (1964): x = R + e/R with e ~ Exp(1), accepted with e^{−x²/2}'s share
            loop {
                let e = -libm::log(1.0 - self.uniform()) / ZIG_R;
                let y = -libm::log(1.0 - self.uniform());
                if 2.0 * y >= e * e {
                    return Some(if u < 0.0 { -(ZIG_R + e) } else { ZIG_R + e });
                }
            }
        }
        let x = u * z.x[i];
        let f0 = libm::exp(-0.5 * (z.x[i] * z.x[i] - x * x));
        let f1 = libm::exp(-0.5 * (z.x[i + 1] * z.x[i + 1] - x * x));
        (f1 + self.uniform() * (f0 - f1) < 1.0).then_some(x)
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

    /// The standard normal's probability between `a` and `b` (from `erfc`, independent of
    /// the ziggurat's tables).
    fn normal_mass(a: f64, b: f64) -> f64 {
        let upper = |x: f64| 0.5 * libm::erfc(x / std::f64::consts::SQRT_2);
        upper(a) - upper(b)
    }

    /// 4·10^6 ziggurat deviates against the normal distribution: the moments, and a χ² test
    /// over 80 bins, fine ones over [−R, R] (where the layer edges and the wedges lie) and
    /// three on each tail beyond the base layer's edge R (drawn by the tail algorithm, whose
    /// two sides must also hold their share).
    #[test]
    fn ziggurat_normals_follow_the_normal_distribution() {
        let mut r = Rng::new(11);
        let n = 4_000_000usize;
        let mut edges = vec![f64::NEG_INFINITY, -4.2, -3.9, -ZIG_R];
        edges.extend(
            (0..=80)
                .map(|k| -4.0 + 0.1 * k as f64)
                .filter(|x| x.abs() < ZIG_R),
        );
        edges.extend([ZIG_R, 3.9, 4.2, f64::INFINITY]);
        let mut count = vec![0u64; edges.len() - 1];
        let (mut s1, mut s2, mut s4) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let z = r.normal_ziggurat();
            s1 += z;
            s2 += z * z;
            s4 += z * z * z * z;
            let k = edges.partition_point(|&e| e <= z) - 1;
            count[k] += 1;
        }
        let nf = n as f64;
        // standard errors: 5e-4 (mean), 7e-4 (variance), 5e-3 (fourth moment)
        assert!((s1 / nf).abs() < 3e-3, "mean {}", s1 / nf);
        assert!((s2 / nf - 1.0).abs() < 4e-3, "variance {}", s2 / nf);
        assert!((s4 / nf - 3.0).abs() < 3e-2, "fourth moment {}", s4 / nf);
        let mut chi2 = 0.0;
        for (k, &c) in count.iter().enumerate() {
            let expected = nf * normal_mass(edges[k], edges[k + 1]);
            chi2 += (c as f64 - expected).powi(2) / expected;
        }
        let df = (count.len() - 1) as f64;
        // mean df, standard deviation √(2 df) ≈ 13: a 5σ bound
        assert!(
            chi2 < df + 5.0 * (2.0 * df).sqrt(),
            "chi2 {chi2} with {df} dof"
        );
        // the tails beyond R: expected 4e6 · 1.29e-4 = 516 each
        let m = count.len();
        for c in [
            count[0] + count[1] + count[2],
            count[m - 3] + count[m - 2] + count[m - 1],
        ] {
            let expected = nf * normal_mass(ZIG_R, f64::INFINITY);
            assert!(
                (c as f64 - expected).abs() < 5.0 * expected.sqrt(),
                "tail {c}"
            );
        }
    }

    /// The tables close: the top layer `[0, x₂₅₅] × [f(x₂₅₅), 1]` has the same area as every
    /// other, `V = R f(R) + ∫_R^∞ f` (checks `ZIG_R` independently of its bisection).
    #[test]
    fn ziggurat_layers_have_equal_areas() {
        let z = ziggurat();
        let f = |x: f64| libm::exp(-0.5 * x * x);
        let v = z.x[0] * f(ZIG_R);
        let top = z.x[ZIG_LAYERS - 1] * (1.0 - f(z.x[ZIG_LAYERS - 1]));
        assert!((top - v).abs() < 1e-12 * v, "top {top} against {v}");
        for i in 1..ZIG_LAYERS - 1 {
            let area = z.x[i] * (f(z.x[i + 1]) - f(z.x[i]));
            assert!((area - v).abs() < 1e-11 * v, "layer {i}: {area}");
        }
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
