//! Numbers in expressions: exact rationals, with a floating-point fallback.
//!
//! Literals such as `1.5e-3` are exact (`3/2000`), so that `0.1 + 0.2 - 0.3` folds to
//! exactly zero and printed coefficients stay readable. A rational whose numerator or
//! denominator would overflow `i64` becomes an `f64`; floats absorb whatever they touch.

use std::cmp::Ordering;
use std::fmt;

/// An exact rational `num/den` in lowest terms with `den > 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Rational {
    num: i64,
    den: i64,
}

/// Greatest common divisor (Euclid); `gcd(0, 0) = 0`. The one integer gcd of the workspace:
/// callers with signed values pass `unsigned_abs()`.
pub fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        let r = a % b;
        a = b;
        b = r;
    }
    a
}

impl Rational {
    /// Zero.
    pub const ZERO: Rational = Rational { num: 0, den: 1 };
    /// One.
    pub const ONE: Rational = Rational { num: 1, den: 1 };
    /// Minus one.
    pub const MINUS_ONE: Rational = Rational { num: -1, den: 1 };

    /// The integer `n`.
    pub const fn int(n: i64) -> Rational {
        Rational { num: n, den: 1 }
    }

    /// `num/den` reduced; `None` when `den == 0` or the reduced parts do not fit `i64`.
    pub fn new(num: i128, den: i128) -> Option<Rational> {
        if den == 0 {
            return None;
        }
        let g = gcd(num.unsigned_abs(), den.unsigned_abs()).max(1) as i128;
        let (mut n, mut d) = (num / g, den / g);
        if d < 0 {
            n = -n;
            d = -d;
        }
        Some(Rational {
            num: i64::try_from(n).ok()?,
            den: i64::try_from(d).ok()?,
        })
    }

    /// Numerator (carries the sign).
    pub fn numer(self) -> i64 {
        self.num
    }
    /// Denominator (always positive).
    pub fn denom(self) -> i64 {
        self.den
    }
    /// True for integers.
    pub fn is_integer(self) -> bool {
        self.den == 1
    }
    /// The value as `f64`.
    pub fn to_f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }

    /// Sum, `None` on overflow.
    pub fn checked_add(self, o: Rational) -> Option<Rational> {
        let n = self.num as i128 * o.den as i128 + o.num as i128 * self.den as i128;
        Rational::new(n, self.den as i128 * o.den as i128)
    }
    /// Product, `None` on overflow.
    pub fn checked_mul(self, o: Rational) -> Option<Rational> {
        Rational::new(
            self.num as i128 * o.num as i128,
            self.den as i128 * o.den as i128,
        )
    }
    /// Reciprocal, `None` for zero.
    pub fn recip(self) -> Option<Rational> {
        Rational::new(self.den as i128, self.num as i128)
    }
    /// Negation (never overflows for reduced rationals except `i64::MIN`).
    pub fn checked_neg(self) -> Option<Rational> {
        Some(Rational {
            num: self.num.checked_neg()?,
            den: self.den,
        })
    }
    /// Integer power, `None` on overflow or `0^negative`.
    pub fn checked_powi(self, e: i64) -> Option<Rational> {
        let base = if e < 0 { self.recip()? } else { self };
        let mut e = e.unsigned_abs();
        let mut acc = Rational::ONE;
        let mut b = base;
        while e > 0 {
            if e & 1 == 1 {
                acc = acc.checked_mul(b)?;
            }
            e >>= 1;
            if e > 0 {
                b = b.checked_mul(b)?;
            }
        }
        Some(acc)
    }
    /// The exact `q`-th root when it exists (`q > 0`), e.g. `(9/4)^(1/2) = 3/2`.
    pub fn exact_root(self, q: i64) -> Option<Rational> {
        if q <= 0 || (self.num < 0 && q % 2 == 0) {
            return None;
        }
        let n = int_root(self.num.unsigned_abs(), q as u32)?;
        let d = int_root(self.den as u64, q as u32)?;
        let n = if self.num < 0 {
            -(n as i128)
        } else {
            n as i128
        };
        Rational::new(n, d as i128)
    }
    /// Sign: -1, 0 or 1.
    pub fn signum(self) -> i64 {
        self.num.signum()
    }
}

fn int_root(x: u64, q: u32) -> Option<u64> {
    if q == 1 {
        return Some(x);
    }
    let guess = (x as f64).powf(1.0 / q as f64).round() as u64;
    (guess.saturating_sub(1)..=guess + 1).find(|&r| r.checked_pow(q) == Some(x))
}

impl Ord for Rational {
    fn cmp(&self, o: &Self) -> Ordering {
        (self.num as i128 * o.den as i128).cmp(&(o.num as i128 * self.den as i128))
    }
}
impl PartialOrd for Rational {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// A numeric constant in an expression.
#[derive(Clone, Copy, Debug)]
pub enum Number {
    /// Exact rational.
    Rat(Rational),
    /// Inexact value (overflowed rationals, or results of operations on them).
    Float(f64),
}

impl PartialEq for Number {
    fn eq(&self, o: &Self) -> bool {
        match (self, o) {
            (Number::Rat(a), Number::Rat(b)) => a == b,
            (Number::Float(a), Number::Float(b)) => a.to_bits() == b.to_bits(),
            _ => false,
        }
    }
}
impl Eq for Number {}
impl std::hash::Hash for Number {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        match self {
            Number::Rat(r) => {
                0u8.hash(h);
                r.hash(h)
            }
            Number::Float(f) => {
                1u8.hash(h);
                f.to_bits().hash(h)
            }
        }
    }
}

#[allow(clippy::should_implement_trait)] // by-value helpers named like the math; no operator overloading wanted
impl Number {
    /// Zero.
    pub const ZERO: Number = Number::Rat(Rational::ZERO);
    /// One.
    pub const ONE: Number = Number::Rat(Rational::ONE);
    /// Minus one.
    pub const MINUS_ONE: Number = Number::Rat(Rational::MINUS_ONE);

    /// The integer `n`.
    pub const fn int(n: i64) -> Number {
        Number::Rat(Rational::int(n))
    }
    /// `p/q` (floats when it does not fit; `q = 0` gives ±inf or NaN).
    pub fn ratio(p: i64, q: i64) -> Number {
        match Rational::new(p as i128, q as i128) {
            Some(r) => Number::Rat(r),
            None => Number::Float(p as f64 / q as f64),
        }
    }
    /// The value as `f64`.
    pub fn to_f64(self) -> f64 {
        match self {
            Number::Rat(r) => r.to_f64(),
            Number::Float(f) => f,
        }
    }
    /// The rational, if exact.
    pub fn as_rational(self) -> Option<Rational> {
        match self {
            Number::Rat(r) => Some(r),
            Number::Float(_) => None,
        }
    }
    /// The integer value, if exact and integral.
    pub fn as_integer(self) -> Option<i64> {
        match self {
            Number::Rat(r) if r.is_integer() => Some(r.numer()),
            _ => None,
        }
    }
    /// True for exact zero or float zero.
    pub fn is_zero(self) -> bool {
        match self {
            Number::Rat(r) => r.numer() == 0,
            Number::Float(f) => f == 0.0,
        }
    }
    /// True for exact one.
    pub fn is_one(self) -> bool {
        self == Number::ONE
    }
    /// Strictly negative (NaN is not).
    pub fn is_negative(self) -> bool {
        match self {
            Number::Rat(r) => r.numer() < 0,
            Number::Float(f) => f < 0.0,
        }
    }
    /// Strictly positive.
    pub fn is_positive(self) -> bool {
        match self {
            Number::Rat(r) => r.numer() > 0,
            Number::Float(f) => f > 0.0,
        }
    }
    /// Sum.
    pub fn add(self, o: Number) -> Number {
        if let (Number::Rat(a), Number::Rat(b)) = (self, o) {
            if let Some(r) = a.checked_add(b) {
                return Number::Rat(r);
            }
        }
        Number::Float(self.to_f64() + o.to_f64())
    }
    /// Product.
    pub fn mul(self, o: Number) -> Number {
        if let (Number::Rat(a), Number::Rat(b)) = (self, o) {
            if let Some(r) = a.checked_mul(b) {
                return Number::Rat(r);
            }
        }
        Number::Float(self.to_f64() * o.to_f64())
    }
    /// Negation.
    pub fn neg(self) -> Number {
        match self {
            Number::Rat(r) => match r.checked_neg() {
                Some(n) => Number::Rat(n),
                None => Number::Float(-r.to_f64()),
            },
            Number::Float(f) => Number::Float(-f),
        }
    }
    /// Reciprocal (`1/0` is `inf`, as in floating point).
    pub fn recip(self) -> Number {
        match self {
            Number::Rat(r) => match r.recip() {
                Some(x) => Number::Rat(x),
                None => Number::Float(1.0 / r.to_f64()),
            },
            Number::Float(f) => Number::Float(1.0 / f),
        }
    }
    /// `self^e` when the result is exact or either side is a float; `None` when an exact
    /// base with a fractional exponent has no exact root (the power stays symbolic).
    pub fn pow(self, e: Number) -> Option<Number> {
        match (self, e) {
            (Number::Rat(b), Number::Rat(x)) => {
                if x.is_integer() {
                    if b.numer() == 0 && x.numer() < 0 {
                        return Some(Number::Float(f64::INFINITY));
                    }
                    return Some(match b.checked_powi(x.numer()) {
                        Some(r) => Number::Rat(r),
                        None => Number::Float(b.to_f64().powf(x.to_f64())),
                    });
                }
                let root = b.exact_root(x.denom())?;
                Some(match root.checked_powi(x.numer()) {
                    Some(r) => Number::Rat(r),
                    None => Number::Float(root.to_f64().powi(x.numer() as i32)),
                })
            }
            _ => Some(Number::Float(self.to_f64().powf(e.to_f64()))),
        }
    }
    /// Total order used for canonical sorting (floats after rationals of equal value).
    pub fn total_cmp(self, o: Number) -> Ordering {
        match (self, o) {
            (Number::Rat(a), Number::Rat(b)) => a.cmp(&b),
            _ => self
                .to_f64()
                .total_cmp(&o.to_f64())
                .then_with(|| matches!(self, Number::Float(_)).cmp(&matches!(o, Number::Float(_)))),
        }
    }
}

impl fmt::Display for Number {
    /// Prints so that the parser reads back the same number.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Number::Rat(r) if r.is_integer() => write!(f, "{}", r.numer()),
            Number::Rat(r) => write!(f, "{}/{}", r.numer(), r.denom()),
            Number::Float(x) if x.is_nan() => write!(f, "0/0"),
            Number::Float(x) if x.is_infinite() => {
                write!(f, "{}1/0", if *x < 0.0 { "-" } else { "" })
            }
            Number::Float(x) => write!(f, "{x:e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rationals_reduce_and_fold() {
        let a = Number::ratio(6, -4);
        assert_eq!(a, Number::ratio(-3, 2));
        assert_eq!(a.add(Number::ratio(3, 2)), Number::ZERO);
        assert_eq!(
            Number::ratio(9, 4).pow(Number::ratio(1, 2)),
            Some(Number::ratio(3, 2))
        );
        assert_eq!(Number::int(2).pow(Number::ratio(1, 2)), None);
        assert_eq!(
            Number::int(2).pow(Number::int(-3)),
            Some(Number::ratio(1, 8))
        );
    }

    #[test]
    fn overflow_falls_back_to_float() {
        let big = Number::int(i64::MAX);
        match big.mul(big) {
            Number::Float(f) => assert!((f / 8.507e37 - 1.0).abs() < 1e-3),
            other => panic!("expected float, got {other:?}"),
        }
        assert!(matches!(Number::ZERO.recip(), Number::Float(f) if f.is_infinite()));
    }
}
