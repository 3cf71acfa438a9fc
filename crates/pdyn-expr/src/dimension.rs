//! Physical dimensions: exponents of length, mass, time and temperature (SI's m, kg, s, K;
//! angles are dimensionless, as in SI). Exponents are rationals so that `sqrt(k/m)` has a
//! dimension; every operation is checked, so that `x^(10^18)` reports an overflow instead of
//! wrapping.

use num_rational::Ratio;
use num_traits::{CheckedAdd, CheckedMul, CheckedSub, Zero};

/// An exponent of a base dimension.
pub type Exponent = Ratio<i64>;

/// Exponents of (length, mass, time, temperature).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Dimension(pub [Exponent; 4]);

const fn int(n: i64) -> Exponent {
    Ratio::new_raw(n, 1)
}

/// Named dimensions, for messages: "kg·m/s^2 (force)".
const NAMED: &[([i64; 4], &str)] = &[
    ([0, 0, 0, 0], "dimensionless"),
    ([1, 0, 0, 0], "length"),
    ([0, 1, 0, 0], "mass"),
    ([0, 0, 1, 0], "time"),
    ([0, 0, 0, 1], "temperature"),
    ([1, 0, -1, 0], "velocity"),
    ([1, 0, -2, 0], "acceleration"),
    ([1, 1, -2, 0], "force"),
    ([2, 1, -2, 0], "energy"),
    ([2, 1, -3, 0], "power"),
    ([-1, 1, -2, 0], "pressure"),
    ([0, 1, -2, 0], "stiffness"),
    ([0, 1, -1, 0], "damping coefficient"),
    ([1, 1, -1, 0], "momentum"),
    ([0, 0, -1, 0], "frequency"),
    ([0, 0, -2, 0], "frequency squared"),
    ([2, 0, 0, 0], "area"),
    ([3, 0, 0, 0], "volume"),
    ([-3, 1, 0, 0], "density"),
    ([-1, 1, 0, 0], "mass per length"),
    ([3, 1, -2, 0], "force times area (G m1 m2)"),
    ([3, 0, -2, 0], "gravitational parameter"),
];

impl Dimension {
    /// A pure number.
    pub const NONE: Dimension = Dimension([int(0), int(0), int(0), int(0)]);
    /// Length (m).
    pub const LENGTH: Dimension = Dimension([int(1), int(0), int(0), int(0)]);
    /// Mass (kg).
    pub const MASS: Dimension = Dimension([int(0), int(1), int(0), int(0)]);
    /// Time (s).
    pub const TIME: Dimension = Dimension([int(0), int(0), int(1), int(0)]);
    /// Force (N = kg·m/s²).
    pub const FORCE: Dimension = Dimension([int(1), int(1), int(-2), int(0)]);
    /// Energy (J = kg·m²/s²).
    pub const ENERGY: Dimension = Dimension([int(2), int(1), int(-2), int(0)]);
    /// Acceleration (m/s²).
    pub const ACCELERATION: Dimension = Dimension([int(1), int(0), int(-2), int(0)]);
    /// Velocity (m/s).
    pub const VELOCITY: Dimension = Dimension([int(1), int(0), int(-1), int(0)]);

    /// From integer exponents of (length, mass, time, temperature).
    pub const fn from_ints(e: [i8; 4]) -> Dimension {
        Dimension([
            int(e[0] as i64),
            int(e[1] as i64),
            int(e[2] as i64),
            int(e[3] as i64),
        ])
    }

    /// True for a pure number.
    pub fn is_none(&self) -> bool {
        self.0.iter().all(Zero::is_zero)
    }

    /// `self · other`; `None` on overflow.
    pub fn mul(&self, other: &Dimension) -> Option<Dimension> {
        self.zip(other, |a, b| match (a.is_integer(), b.is_integer()) {
            // Integer exponents, the usual case, without the rational arithmetic's gcds
            // (which made dimensions a tenth of loading a 100-link chain).
            (true, true) => Some(int(a.numer().checked_add(b.numer())?)),
            _ => a.checked_add(b),
        })
    }

    /// `self / other`; `None` on overflow.
    pub fn div(&self, other: &Dimension) -> Option<Dimension> {
        self.zip(other, |a, b| match (a.is_integer(), b.is_integer()) {
            (true, true) => Some(int(a.numer().checked_sub(b.numer())?)),
            _ => a.checked_sub(b),
        })
    }

    /// `self^p`; `None` on overflow.
    pub fn pow(&self, p: Exponent) -> Option<Dimension> {
        let mut out = Dimension::NONE;
        for (o, e) in out.0.iter_mut().zip(&self.0) {
            *o = match (e.is_integer(), p.is_integer()) {
                (true, true) => int(e.numer().checked_mul(p.numer())?),
                _ => e.checked_mul(&p)?,
            };
        }
        Some(out)
    }

    fn zip(
        &self,
        other: &Dimension,
        f: impl Fn(&Exponent, &Exponent) -> Option<Exponent>,
    ) -> Option<Dimension> {
        let mut out = Dimension::NONE;
        for i in 0..4 {
            out.0[i] = f(&self.0[i], &other.0[i])?;
        }
        Some(out)
    }

    /// The quantity's name when it has a common one ("force", "velocity").
    pub fn name(&self) -> Option<&'static str> {
        NAMED
            .iter()
            .find(|(e, _)| (0..4).all(|i| self.0[i] == int(e[i])))
            .map(|(_, n)| *n)
    }

    /// `kg·m/s^2 (force)`, or just the units when the quantity has no common name.
    pub fn describe(&self) -> String {
        match self.name() {
            Some("dimensionless") => "dimensionless".to_string(),
            Some(n) => format!("{self} ({n})"),
            None => self.to_string(),
        }
    }
}

impl std::fmt::Display for Dimension {
    /// SI units: `kg·m/s^2`, `1/s`, `m^(1/2)`; `1` for a pure number.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Mass first, as engineers write kg·m/s^2.
        let order = [(1, "kg"), (0, "m"), (2, "s"), (3, "K")];
        let power = |e: &Exponent| -> String {
            if *e == int(1) {
                String::new()
            } else if e.is_integer() {
                format!("^{e}")
            } else {
                format!("^({e})")
            }
        };
        let num: Vec<String> = order
            .iter()
            .filter(|(i, _)| self.0[*i] > int(0))
            .map(|(i, s)| format!("{s}{}", power(&self.0[*i])))
            .collect();
        let den: Vec<String> = order
            .iter()
            .filter(|(i, _)| self.0[*i] < int(0))
            .map(|(i, s)| format!("{s}{}", power(&-self.0[*i])))
            .collect();
        let top = if num.is_empty() {
            "1".to_string()
        } else {
            num.join("·")
        };
        match den.len() {
            0 => write!(f, "{top}"),
            1 => write!(f, "{top}/{}", den[0]),
            _ => write!(f, "{top}/({})", den.join("·")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_and_names() {
        let v = Dimension::LENGTH.div(&Dimension::TIME).unwrap();
        assert_eq!(v, Dimension::VELOCITY);
        assert_eq!(v.describe(), "m/s (velocity)");
        let f = Dimension::MASS
            .mul(&v.div(&Dimension::TIME).unwrap())
            .unwrap();
        assert_eq!(f.describe(), "kg·m/s^2 (force)");
        let k = f.div(&Dimension::LENGTH).unwrap();
        let w = k
            .div(&Dimension::MASS)
            .unwrap()
            .pow(Ratio::new(1, 2))
            .unwrap();
        assert_eq!(w.describe(), "1/s (frequency)");
        assert_eq!(
            Dimension::LENGTH.pow(Ratio::new(1, 2)).unwrap().to_string(),
            "m^(1/2)"
        );
        assert_eq!(Dimension::NONE.describe(), "dimensionless");
        assert!(Dimension::LENGTH
            .pow(int(i64::MAX))
            .unwrap()
            .pow(int(2))
            .is_none());
    }

    /// The integer shortcut agrees with rational arithmetic, overflow included.
    #[test]
    fn integer_exponents_agree_with_rationals() {
        let exps = [
            int(0),
            int(1),
            int(-2),
            int(3),
            Ratio::new(1, 2),
            Ratio::new(-3, 4),
            int(i64::MAX),
            int(i64::MIN + 1),
        ];
        for &a in &exps {
            for &b in &exps {
                let (x, y) = (Dimension([a, b, a, b]), Dimension([b, a, int(1), a]));
                let rational = |f: fn(&Exponent, &Exponent) -> Option<Exponent>| {
                    (0..4)
                        .map(|i| f(&x.0[i], &y.0[i]))
                        .collect::<Option<Vec<_>>>()
                };
                let mul = rational(|p, q| p.checked_add(q));
                assert_eq!(x.mul(&y).map(|d| d.0.to_vec()), mul);
                let div = rational(|p, q| p.checked_sub(q));
                assert_eq!(x.div(&y).map(|d| d.0.to_vec()), div);
                let pow: Option<Vec<Exponent>> = x.0.iter().map(|e| e.checked_mul(&b)).collect();
                assert_eq!(x.pow(b).map(|d| d.0.to_vec()), pow);
            }
        }
    }
}
