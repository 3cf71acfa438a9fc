//! Numbers in expressions: exact rationals of any size within a budget, and explicit floats.
//!
//! Literals such as `1.5e-3` are exact (`3/2000`), so that `0.1 + 0.2 - 0.3` folds to
//! exactly zero and printed coefficients stay readable. A [`Rational`] keeps numerator and
//! denominator inline as `i64` while they fit (the hot path of derivations: small integer
//! coefficients, checked `i128` arithmetic, no allocation) and promotes itself to an
//! arbitrary-precision `num_rational::BigRational` when they do not, so `2^64 + 1 - 2^64` is
//! exactly 1. Exact numbers are bounded by [`MAX_BITS`] (about [`MAX_DIGITS`] decimal digits):
//! an exact power that would exceed it is not computed ([`Rational::pow`] says `None`; the
//! expression stays a symbolic power and the parser reports [`NumberTooLarge`]).
//!
//! [`Number::Float`] exists only where a value is explicitly floating point: a model value
//! given as a TOML float, a numeric root, a value substituted at run time. Exact arithmetic
//! never falls back to it silently; floats absorb whatever they touch, and print in `e`
//! notation so that a reader can tell them from exact values.

use num_bigint::BigInt;
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use std::cmp::Ordering;
use std::fmt;
use std::sync::Arc;

/// The largest exact number, in bits of numerator plus denominator (about [`MAX_DIGITS`]
/// decimal digits): `2^100000` (100,001 bits) is exact, `2^1000000` is refused.
pub const MAX_BITS: u64 = 332_193;
/// [`MAX_BITS`] in decimal digits, for messages.
pub const MAX_DIGITS: u64 = 100_000;

/// An exact number would exceed [`MAX_BITS`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NumberTooLarge {
    /// What was being computed, e.g. `2^1000000`.
    pub what: String,
    /// Estimated size of the exact result, in decimal digits.
    pub digits: u64,
}

impl fmt::Display for NumberTooLarge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the exact value of {} would have about {} digits, over the limit of {} digits for exact numbers",
            self.what, self.digits, MAX_DIGITS
        )
    }
}

impl std::error::Error for NumberTooLarge {}

/// Decimal digits of a number of `bits` bits (rounded up).
pub fn bits_to_digits(bits: u64) -> u64 {
    (bits as f64 * std::f64::consts::LOG10_2).ceil() as u64
}

/// An exact rational `num/den` in lowest terms with `den > 0`.
///
/// Canonical representation: inline while both parts fit `i64`, big otherwise, so the derived
/// equality and hash are equality and hash of values.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Rational(Repr);

#[derive(Clone, Debug)]
enum Repr {
    /// `num/den`, reduced, `den > 0`.
    Small(i64, i64),
    /// Reduced, `den > 0`, and at least one part does not fit `i64`. Shared: cloning a node's
    /// number must not copy thousands of digits.
    Big(Arc<BigRational>),
}

// Equality and hashing compare the (reduced, canonical) parts directly: num-rational's own
// `Eq`/`Hash` go through continued fractions, quadratic in the number of digits.
impl PartialEq for Repr {
    fn eq(&self, o: &Repr) -> bool {
        match (self, o) {
            (Repr::Small(a, b), Repr::Small(c, d)) => a == c && b == d,
            (Repr::Big(x), Repr::Big(y)) => x.numer() == y.numer() && x.denom() == y.denom(),
            _ => false,
        }
    }
}
impl Eq for Repr {}
impl std::hash::Hash for Repr {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        match self {
            Repr::Small(n, d) => (0u8, n, d).hash(h),
            Repr::Big(r) => (1u8, r.numer(), r.denom()).hash(h),
        }
    }
}

/// `gcd(a, b)`, skipping the work when either is ±1 (num-bigint's binary gcd is quadratic in
/// the number of bits, even against 1).
fn gcd_big(a: &BigInt, b: &BigInt) -> BigInt {
    if a.magnitude().is_one() || b.magnitude().is_one() {
        return BigInt::one();
    }
    let (mut x, mut y) = (a.magnitude().clone(), b.magnitude().clone());
    if x < y {
        std::mem::swap(&mut x, &mut y);
    }
    // Euclid's remainder while one number is much shorter than the other: num-bigint's binary
    // gcd removes about one bit per pass, so gcd(10^99990, 3) took seconds (fuzzing found
    // `1/3 + 7e-99990`); one division brings both to the shorter one's size.
    while !y.is_zero() && x.bits() > 2 * y.bits() + 64 {
        let r = &x % &y;
        x = std::mem::replace(&mut y, r);
    }
    if y.is_zero() {
        return BigInt::from(x);
    }
    BigInt::from(x.gcd(&y))
}

/// Greatest common divisor (Euclid); `gcd(0, 0) = 0`. The one machine-integer gcd of the
/// workspace: callers with signed values pass `unsigned_abs()`.
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
    pub const ZERO: Rational = Rational(Repr::Small(0, 1));
    /// One.
    pub const ONE: Rational = Rational(Repr::Small(1, 1));
    /// Minus one.
    pub const MINUS_ONE: Rational = Rational(Repr::Small(-1, 1));
    /// One half.
    pub const HALF: Rational = Rational(Repr::Small(1, 2));

    /// The integer `n`.
    pub const fn int(n: i64) -> Rational {
        Rational(Repr::Small(n, 1))
    }

    /// `num/den` reduced; `None` when `den == 0`.
    pub fn new(num: i128, den: i128) -> Option<Rational> {
        if den == 0 {
            return None;
        }
        let g = gcd(num.unsigned_abs(), den.unsigned_abs()).max(1);
        // `g` divides both, so the quotients of the magnitudes fit; the sign goes on top.
        let (n, d) = (num.unsigned_abs() / g, den.unsigned_abs() / g);
        let negative = (num < 0) != (den < 0) && n != 0;
        if let (Ok(n), Ok(d)) = (i64::try_from(n), i64::try_from(d)) {
            return Some(Rational(Repr::Small(if negative { -n } else { n }, d)));
        }
        let n = BigInt::from(n);
        let n = if negative { -n } else { n };
        Some(Rational::from_big(BigRational::new_raw(n, BigInt::from(d))))
    }

    /// The integer `n` of any size.
    pub fn from_bigint(n: BigInt) -> Rational {
        Rational::from_big(BigRational::from_integer(n))
    }

    /// `num/den` of any size, reduced; `None` when `den == 0`.
    pub fn from_parts(num: BigInt, den: BigInt) -> Option<Rational> {
        if den.is_zero() {
            return None;
        }
        Some(Rational::from_big(BigRational::new(num, den)))
    }

    /// From a reduced big rational: inline when it fits.
    fn from_big(r: BigRational) -> Rational {
        match (r.numer().to_i64(), r.denom().to_i64()) {
            (Some(n), Some(d)) => Rational(Repr::Small(n, d)),
            _ => Rational(Repr::Big(Arc::new(r))),
        }
    }

    fn big(&self) -> BigRational {
        match &self.0 {
            Repr::Small(n, d) => BigRational::new_raw(BigInt::from(*n), BigInt::from(*d)),
            Repr::Big(r) => (**r).clone(),
        }
    }

    /// `(numerator, denominator)` when both fit `i64` (the denominator is positive).
    pub fn small(&self) -> Option<(i64, i64)> {
        match self.0 {
            Repr::Small(n, d) => Some((n, d)),
            Repr::Big(_) => None,
        }
    }
    /// Numerator (carries the sign), any size.
    pub fn numer_big(&self) -> BigInt {
        match &self.0 {
            Repr::Small(n, _) => BigInt::from(*n),
            Repr::Big(r) => r.numer().clone(),
        }
    }
    /// Denominator (positive), any size.
    pub fn denom_big(&self) -> BigInt {
        match &self.0 {
            Repr::Small(_, d) => BigInt::from(*d),
            Repr::Big(r) => r.denom().clone(),
        }
    }
    /// The value when it is an integer that fits `i64`.
    pub fn to_i64(&self) -> Option<i64> {
        match self.0 {
            Repr::Small(n, 1) => Some(n),
            _ => None,
        }
    }
    /// True for integers (of any size).
    pub fn is_integer(&self) -> bool {
        match &self.0 {
            Repr::Small(_, d) => *d == 1,
            Repr::Big(r) => r.is_integer(),
        }
    }
    /// True for 0.
    pub fn is_zero(&self) -> bool {
        matches!(self.0, Repr::Small(0, _))
    }
    /// Sign: -1, 0 or 1.
    pub fn signum(&self) -> i64 {
        match &self.0 {
            Repr::Small(n, _) => n.signum(),
            Repr::Big(r) => {
                if r.is_negative() {
                    -1
                } else {
                    1 // a big rational is never zero
                }
            }
        }
    }
    /// Size in bits: numerator plus denominator.
    pub fn bits(&self) -> u64 {
        match &self.0 {
            Repr::Small(n, d) => {
                (64 - n.unsigned_abs().leading_zeros() + 64 - d.unsigned_abs().leading_zeros())
                    as u64
            }
            Repr::Big(r) => r.numer().bits() + r.denom().bits(),
        }
    }
    /// The nearest `f64` (±inf past its range; a big value is rounded correctly, not by
    /// dividing two rounded parts).
    pub fn to_f64(&self) -> f64 {
        match &self.0 {
            Repr::Small(n, d) => *n as f64 / *d as f64,
            Repr::Big(r) => r.to_f64().unwrap_or_else(|| {
                // Past f64's range: the sign and magnitude decide.
                let mag = r.numer().bits() as i64 - r.denom().bits() as i64;
                let s = if r.is_negative() { -1.0 } else { 1.0 };
                if mag > 0 {
                    s * f64::INFINITY
                } else {
                    s * 0.0
                }
            }),
        }
    }

    /// Sum (exact, any size).
    pub fn add(&self, o: &Rational) -> Rational {
        if let (Repr::Small(a, b), Repr::Small(c, d)) = (&self.0, &o.0) {
            if *b == 1 && *d == 1 {
                if let Some(s) = a.checked_add(*c) {
                    return Rational::int(s);
                }
            }
            // |a*d|, |c*b| < 2^126: the sum fits i128.
            let n = *a as i128 * *d as i128 + *c as i128 * *b as i128;
            return Rational::new(n, *b as i128 * *d as i128).unwrap_or(Rational::ZERO);
        }
        let (x, y) = (self.big(), o.big());
        if x.is_integer() && y.is_integer() {
            return Rational::from_bigint(x.numer() + y.numer());
        }
        // n/d + m = (n + m d)/d is reduced when n/d is (gcd(n + m d, d) = gcd(n, d)): no gcd
        // of two 100,000-digit numbers (fuzzing found `888/8888888284E88882-8824-4`).
        for (f, i) in [(&x, &y), (&y, &x)] {
            if i.is_integer() {
                let n = f.numer() + i.numer() * f.denom();
                return Rational::from_big(BigRational::new_raw(n, f.denom().clone()));
            }
        }
        if x.denom() == y.denom() {
            let n = x.numer() + y.numer();
            let g = gcd_big(&n, x.denom());
            if g.is_one() {
                return Rational::from_big(BigRational::new_raw(n, x.denom().clone()));
            }
            return Rational::from_big(BigRational::new_raw(&n / &g, x.denom() / &g));
        }
        // Henrici: with g = gcd(b, d), a/b + c/d = (a d/g + c b/g) / (b d/g), and only the gcd
        // of that numerator with g remains to cancel, never a gcd of the two full results.
        let (b, d) = (x.denom(), y.denom());
        let g = gcd_big(b, d);
        let (b1, d1) = (b / &g, d / &g);
        let t = x.numer() * &d1 + y.numer() * &b1;
        let g2 = gcd_big(&t, &g);
        let (t, d2) = if g2.is_one() {
            (t, d.clone())
        } else {
            (&t / &g2, d / &g2)
        };
        if t.is_zero() {
            return Rational::ZERO;
        }
        Rational::from_big(BigRational::new_raw(t, b1 * d2))
    }
    /// Difference.
    pub fn sub(&self, o: &Rational) -> Rational {
        self.add(&o.neg())
    }
    /// Product (exact, any size).
    pub fn mul(&self, o: &Rational) -> Rational {
        if let (Repr::Small(a, b), Repr::Small(c, d)) = (&self.0, &o.0) {
            if *b == 1 && *d == 1 {
                if let Some(p) = a.checked_mul(*c) {
                    return Rational::int(p);
                }
            }
            return Rational::new(*a as i128 * *c as i128, *b as i128 * *d as i128)
                .unwrap_or(Rational::ZERO);
        }
        if self.is_zero() || o.is_zero() {
            return Rational::ZERO;
        }
        // Cross-cancellation: (a/b)(c/d) = (a/g1)(c/g2) / ((b/g2)(d/g1)), already reduced.
        let (x, y) = (self.big(), o.big());
        let g1 = gcd_big(x.numer(), y.denom());
        let g2 = gcd_big(y.numer(), x.denom());
        let div = |v: &BigInt, g: &BigInt| if g.is_one() { v.clone() } else { v / g };
        let n = div(x.numer(), &g1) * div(y.numer(), &g2);
        let d = div(x.denom(), &g2) * div(y.denom(), &g1);
        Rational::from_big(BigRational::new_raw(n, d))
    }
    /// Negation (exact: `-i64::MIN` becomes big).
    pub fn neg(&self) -> Rational {
        match &self.0 {
            Repr::Small(n, d) => match n.checked_neg() {
                Some(m) => Rational(Repr::Small(m, *d)),
                None => Rational::from_big(-self.big()),
            },
            Repr::Big(r) => Rational::from_big(-(**r).clone()),
        }
    }
    /// Absolute value.
    pub fn abs(&self) -> Rational {
        if self.signum() < 0 {
            self.neg()
        } else {
            self.clone()
        }
    }
    /// Reciprocal, `None` for zero.
    pub fn recip(&self) -> Option<Rational> {
        match &self.0 {
            Repr::Small(n, d) => Rational::new(*d as i128, *n as i128),
            Repr::Big(r) => Some(Rational::from_big(r.recip())),
        }
    }
    /// Sum, `None` when the result would exceed [`MAX_BITS`] (for callers that must stay
    /// small, such as the polynomial arithmetic of `simplify`, which then gives up).
    pub fn checked_add(&self, o: &Rational) -> Option<Rational> {
        let r = self.add(o);
        (r.bits() <= MAX_BITS).then_some(r)
    }
    /// Product, `None` when the result would exceed [`MAX_BITS`].
    pub fn checked_mul(&self, o: &Rational) -> Option<Rational> {
        if self.bits() + o.bits() > 2 * MAX_BITS {
            return None;
        }
        let r = self.mul(o);
        (r.bits() <= MAX_BITS).then_some(r)
    }
    /// Estimated decimal digits of `self^e` (numerator plus denominator), for messages.
    pub fn pow_digits(&self, e: i64) -> u64 {
        let log10 = match &self.0 {
            Repr::Small(n, d) => libm::log10(n.unsigned_abs() as f64) + libm::log10(*d as f64),
            Repr::Big(_) => self.bits() as f64 * std::f64::consts::LOG10_2,
        };
        (log10 * e.unsigned_abs() as f64)
            .ceil()
            .min(u64::MAX as f64) as u64
    }
    /// Integer power; `None` for `0^negative` or when the result would exceed [`MAX_BITS`]
    /// (checked before computing anything).
    pub fn pow(&self, e: i64) -> Option<Rational> {
        if self.is_zero() {
            return match e.cmp(&0) {
                Ordering::Less => None,
                Ordering::Equal => Some(Rational::ONE),
                Ordering::Greater => Some(Rational::ZERO),
            };
        }
        // ±1 to any power stays small; other bases grow by at least one bit per factor.
        if let Repr::Small(n, 1) = self.0 {
            if n == 1 {
                return Some(Rational::ONE);
            }
            if n == -1 {
                return Some(if e % 2 == 0 {
                    Rational::ONE
                } else {
                    Rational::MINUS_ONE
                });
            }
        }
        let base = if e < 0 { self.recip()? } else { self.clone() };
        // The exact size is (bits - 1) * e + 1 at least: refuse before allocating.
        let lower = (base.bits().saturating_sub(2)) as u128 * e.unsigned_abs() as u128;
        if lower > MAX_BITS as u128 {
            return None;
        }
        let mut e = e.unsigned_abs();
        let mut acc = Rational::ONE;
        let mut b = base;
        while e > 0 {
            if e & 1 == 1 {
                acc = acc.mul(&b);
            }
            e >>= 1;
            if e > 0 {
                b = b.mul(&b);
            }
        }
        (acc.bits() <= MAX_BITS).then_some(acc)
    }
    /// The exact `q`-th root when it exists (`q > 0`), e.g. `(9/4)^(1/2) = 3/2`.
    pub fn exact_root(&self, q: i64) -> Option<Rational> {
        if q <= 0 || (self.signum() < 0 && q % 2 == 0) {
            return None;
        }
        let q = u32::try_from(q).ok()?;
        if q == 1 {
            return Some(self.clone());
        }
        if let Repr::Small(n, d) = self.0 {
            let r = int_root(n.unsigned_abs(), q)?;
            let s = int_root(d as u64, q)?;
            let r = if n < 0 { -(r as i128) } else { r as i128 };
            return Rational::new(r, s as i128);
        }
        let root = |x: &BigInt| -> Option<BigInt> {
            let r = x.nth_root(q);
            (num_traits::pow(r.clone(), q as usize) == *x).then_some(r)
        };
        let n = self.numer_big();
        let r = root(&n)?;
        let s = root(&self.denom_big())?;
        Rational::from_parts(r, s)
    }
}

fn int_root(x: u64, q: u32) -> Option<u64> {
    if q == 1 {
        return Some(x);
    }
    let guess = libm::pow(x as f64, 1.0 / q as f64).round() as u64;
    (guess.saturating_sub(1)..=guess + 1).find(|&r| r.checked_pow(q) == Some(x))
}

impl Ord for Rational {
    fn cmp(&self, o: &Self) -> Ordering {
        match (&self.0, &o.0) {
            (Repr::Small(a, b), Repr::Small(c, d)) => {
                (*a as i128 * *d as i128).cmp(&(*c as i128 * *b as i128))
            }
            _ => {
                // Cross-multiplication (denominators are positive).
                let (x, y) = (self.big(), o.big());
                (x.numer() * y.denom()).cmp(&(y.numer() * x.denom()))
            }
        }
    }
}
impl PartialOrd for Rational {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl fmt::Display for Rational {
    /// `n` or `n/d`, exactly; a big value with a terminating decimal expansion prints in `e`
    /// notation when that is shorter (`1.3806503e-23`, `1e30`), still exact and re-parsable.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Repr::Small(n, 1) => write!(f, "{n}"),
            Repr::Small(n, d) => write!(f, "{n}/{d}"),
            Repr::Big(r) => {
                let plain = if r.is_integer() {
                    r.numer().to_string()
                } else {
                    format!("{}/{}", r.numer(), r.denom())
                };
                match decimal_e(r) {
                    Some(e) if e.len() < plain.len() => f.write_str(&e),
                    _ => f.write_str(&plain),
                }
            }
        }
    }
}

/// `r` as an exact decimal in `e` notation (`-1.25e-30`), when its denominator is `2^a 5^b`.
fn decimal_e(r: &BigRational) -> Option<String> {
    let mut den = r.denom().clone();
    let (two, five) = (BigInt::from(2), BigInt::from(5));
    // Powers of 2 by one shift, powers of 5 by 5^27 at a time (one machine word): dividing by
    // 2 and 5 one at a time took 10 s on `9e-99999` (fuzzing found it).
    let a = den.trailing_zeros().unwrap_or(0);
    den >>= a;
    let mut b = 0u64;
    let five_27 = BigInt::from(5u64.pow(27));
    while (&den % &five_27).is_zero() {
        den /= &five_27;
        b += 27;
    }
    while (&den % &five).is_zero() {
        den /= &five;
        b += 1;
    }
    if !den.is_one() {
        return None;
    }
    // r = m / 10^k with k = max(a, b).
    let k = a.max(b);
    let pow = |b: &BigInt, e: u64| -> Option<BigInt> { Some(b.pow(u32::try_from(e).ok()?)) };
    let m = r.numer() * pow(&two, k - a)? * pow(&five, k - b)?;
    let neg = m.is_negative();
    let mut digits = m.abs().to_string();
    let mut exp = -(k as i64);
    let trimmed = digits.trim_end_matches('0').len();
    exp += (digits.len() - trimmed) as i64;
    digits.truncate(trimmed.max(1));
    // The parser refuses a literal whose digits plus its exponent pass the limit, which a value
    // within the limit can reach as a decimal (5^-88000 has 61,000 digits as a fraction, 88,000
    // as `…e-88000`; fuzzing found one): print such a value as a fraction instead.
    if exp.unsigned_abs() + digits.len() as u64 > MAX_DIGITS {
        return None;
    }
    // digits × 10^exp = d.ddd × 10^(exp + len - 1)
    let e10 = exp + digits.len() as i64 - 1;
    let (head, tail) = digits.split_at(1);
    let sign = if neg { "-" } else { "" };
    Some(if tail.is_empty() {
        format!("{sign}{head}e{e10}")
    } else {
        format!("{sign}{head}.{tail}e{e10}")
    })
}

/// A numeric constant in an expression.
#[derive(Clone, Debug)]
pub enum Number {
    /// Exact rational.
    Rat(Rational),
    /// Explicitly floating-point value (a TOML float, a numeric root, a substituted value).
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

#[allow(clippy::should_implement_trait)] // helpers named like the math; no operator overloading wanted
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
    /// `p/q` exactly (`q = 0` gives ±inf or NaN, as in floating point).
    pub fn ratio(p: i64, q: i64) -> Number {
        match Rational::new(p as i128, q as i128) {
            Some(r) => Number::Rat(r),
            None => Number::Float(p as f64 / q as f64),
        }
    }
    /// The value as `f64`.
    pub fn to_f64(&self) -> f64 {
        match self {
            Number::Rat(r) => r.to_f64(),
            Number::Float(f) => *f,
        }
    }
    /// The rational, if exact.
    pub fn as_rational(&self) -> Option<&Rational> {
        match self {
            Number::Rat(r) => Some(r),
            Number::Float(_) => None,
        }
    }
    /// The integer value, if exact, integral and within `i64`.
    pub fn as_integer(&self) -> Option<i64> {
        match self {
            Number::Rat(r) => r.to_i64(),
            Number::Float(_) => None,
        }
    }
    /// True for exact zero or float zero.
    pub fn is_zero(&self) -> bool {
        match self {
            Number::Rat(r) => r.is_zero(),
            Number::Float(f) => *f == 0.0,
        }
    }
    /// True for exact one.
    pub fn is_one(&self) -> bool {
        *self == Number::ONE
    }
    /// True for a floating-point value.
    pub fn is_float(&self) -> bool {
        matches!(self, Number::Float(_))
    }
    /// Strictly negative (NaN is not).
    pub fn is_negative(&self) -> bool {
        match self {
            Number::Rat(r) => r.signum() < 0,
            Number::Float(f) => *f < 0.0,
        }
    }
    /// Strictly positive.
    pub fn is_positive(&self) -> bool {
        match self {
            Number::Rat(r) => r.signum() > 0,
            Number::Float(f) => *f > 0.0,
        }
    }
    /// Sum: exact for two rationals, floating point when either is a float.
    pub fn add(&self, o: &Number) -> Number {
        match (self, o) {
            (Number::Rat(a), Number::Rat(b)) => Number::Rat(a.add(b)),
            _ => Number::Float(self.to_f64() + o.to_f64()),
        }
    }
    /// Product: exact for two rationals, floating point when either is a float.
    pub fn mul(&self, o: &Number) -> Number {
        match (self, o) {
            (Number::Rat(a), Number::Rat(b)) => Number::Rat(a.mul(b)),
            _ => Number::Float(self.to_f64() * o.to_f64()),
        }
    }
    /// Negation.
    pub fn neg(&self) -> Number {
        match self {
            Number::Rat(r) => Number::Rat(r.neg()),
            Number::Float(f) => Number::Float(-f),
        }
    }
    /// Reciprocal (`1/0` is `inf`, as in floating point).
    pub fn recip(&self) -> Number {
        match self {
            Number::Rat(r) => match r.recip() {
                Some(x) => Number::Rat(x),
                None => Number::Float(f64::INFINITY),
            },
            Number::Float(f) => Number::Float(1.0 / f),
        }
    }
    /// `self^e` when the result is exact or either side is a float; `None` when an exact
    /// base with a fractional exponent has no exact root, or the exact result would exceed
    /// [`MAX_BITS`] (the power then stays symbolic, never silently a float).
    pub fn pow(&self, e: &Number) -> Option<Number> {
        match (self, e) {
            (Number::Rat(b), Number::Rat(x)) => {
                let (p, q) = x.small()?;
                if q == 1 {
                    if b.is_zero() && p < 0 {
                        return Some(Number::Float(f64::INFINITY));
                    }
                    return b.pow(p).map(Number::Rat);
                }
                let root = b.exact_root(q)?;
                root.pow(p).map(Number::Rat)
            }
            _ => Some(Number::Float(libm::pow(self.to_f64(), e.to_f64()))),
        }
    }
    /// Total order used for canonical sorting (floats after rationals of equal value).
    pub fn total_cmp(&self, o: &Number) -> Ordering {
        match (self, o) {
            (Number::Rat(a), Number::Rat(b)) => a.cmp(b),
            _ => self
                .to_f64()
                .total_cmp(&o.to_f64())
                .then_with(|| self.is_float().cmp(&o.is_float())),
        }
    }
}

impl fmt::Display for Number {
    /// Prints so that the parser reads back the same number.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Number::Rat(r) => write!(f, "{r}"),
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
        assert_eq!(a.add(&Number::ratio(3, 2)), Number::ZERO);
        assert_eq!(
            Number::ratio(9, 4).pow(&Number::ratio(1, 2)),
            Some(Number::ratio(3, 2))
        );
        assert_eq!(Number::int(2).pow(&Number::ratio(1, 2)), None);
        assert_eq!(
            Number::int(2).pow(&Number::int(-3)),
            Some(Number::ratio(1, 8))
        );
    }

    #[test]
    fn overflow_promotes_to_big_and_back() {
        let big = Number::int(i64::MAX);
        let sq = big.mul(&big);
        assert!(matches!(&sq, Number::Rat(r) if r.small().is_none()));
        assert_eq!(sq.to_string(), "85070591730234615847396907784232501249");
        // Back to the inline form when the value fits again.
        let back = sq.mul(&big.recip());
        assert_eq!(back, big);
        assert!(matches!(&back, Number::Rat(r) if r.small().is_some()));
        // 2^64 + 1 - 2^64 = 1 exactly.
        let two64 = Number::int(2).pow(&Number::int(64)).unwrap();
        assert_eq!(two64.add(&Number::ONE).add(&two64.neg()), Number::ONE);
        assert_eq!(
            Number::int(i64::MIN).neg().to_string(),
            "9223372036854775808"
        );
        assert!(matches!(Number::ZERO.recip(), Number::Float(f) if f.is_infinite()));
    }

    #[test]
    fn powers_are_exact_within_the_budget() {
        let r = Number::ratio(2, 3).pow(&Number::int(200)).unwrap();
        let Number::Rat(r) = r else {
            panic!("not exact")
        };
        assert_eq!(r.numer_big(), num_traits::pow(BigInt::from(2), 200));
        assert_eq!(r.denom_big(), num_traits::pow(BigInt::from(3), 200));
        let p = Number::int(2).pow(&Number::int(100_000)).unwrap();
        assert_eq!(p.to_string().len(), 30_103);
        // Over the budget: not computed (and not a float either).
        assert_eq!(Number::int(2).pow(&Number::int(1_000_000)), None);
        assert_eq!(Number::int(10).pow(&Number::int(-200_000)), None);
        assert_eq!(
            Number::MINUS_ONE.pow(&Number::int(i64::MAX)),
            Some(Number::MINUS_ONE)
        );
        // Exact roots of big values.
        let p2 = Number::int(3).pow(&Number::int(100)).unwrap();
        assert_eq!(
            p2.pow(&Number::ratio(1, 2)),
            Some(Number::int(3).pow(&Number::int(50)).unwrap())
        );
    }

    #[test]
    fn big_values_print_exactly_and_compare() {
        let k = Rational::from_parts(
            BigInt::from(13806503),
            num_traits::pow(BigInt::from(10), 30),
        )
        .unwrap();
        assert_eq!(k.to_string(), "1.3806503e-23");
        assert!((k.to_f64() - 1.3806503e-23).abs() < 1e-37);
        let e30 = Rational::from_bigint(num_traits::pow(BigInt::from(10), 30));
        assert_eq!(e30.to_string(), "1e30");
        assert!(e30 > Rational::int(i64::MAX) && k < Rational::ONE && k > Rational::ZERO);
        let huge = Rational::from_bigint(num_traits::pow(BigInt::from(7), 1000));
        assert_eq!(huge.to_f64(), f64::INFINITY);
        assert_eq!(huge.neg().to_f64(), f64::NEG_INFINITY);
        assert_eq!(huge.recip().unwrap().to_f64(), 0.0);
    }

    #[test]
    fn numbers_at_the_size_limit_print_in_e_notation() {
        // Fuzzing found `9g^33333` (9 grams to the 33333rd power, 9e-99999 in SI) spending
        // over 35 s in printing: the denominator was divided by 2 and by 5 one at a time.
        let mut p = crate::Pool::new();
        for (src, want) in [("9 g^33332", "9e-99996"), ("-3e-99990/8", "-3.75e-99991")] {
            let e = p.parse_scalar(src).unwrap();
            assert_eq!(p.to_text(e), want);
        }
        // One power further is over the limit (4 + 332,190 bits), as a quantity or a literal.
        for src in ["9 g^33333", "9e-99999"] {
            let e = p.parse_scalar(src).unwrap_err();
            assert!(e.message.contains("100000 digits"), "{src}: {}", e.message);
        }
    }

    #[test]
    fn a_huge_fraction_plus_an_integer_needs_no_gcd() {
        let mut p = crate::Pool::new();
        let e = p.parse_scalar("7/2^70 + 1 - 1/2^70").unwrap();
        assert_eq!(p.to_text(e), "590295810358705651715/590295810358705651712");
        let e = p.parse_scalar("3 + 5/3^50").unwrap();
        assert_eq!(
            p.to_text(e),
            "2153693963075557766310752/717897987691852588770249"
        );
        // Fuzzing found this spending 37 s (under ASAN) in the gcd of the sum; it is over the
        // size limit and refused.
        let e = p.parse_scalar("888/8888888284E88882-8824-4").unwrap_err();
        assert!(e.message.contains("over the limit"), "{}", e.message);
    }

    #[test]
    fn sums_of_fractions_are_reduced() {
        // Henrici's sum against the definition, on values that need each kind of cancellation.
        let big = |s: &str| crate::lower::literal(s).unwrap();
        let cases = [
            ("1e-30", "1e-31"),
            ("3e-40", "7e-40"),
            ("1.5e-25", "2.5e-25"),
            ("123456789012345678901234567", "0.5"),
        ];
        for (a, b) in cases {
            let (x, y) = (big(a), big(b));
            let (rx, ry) = (x.as_rational().unwrap(), y.as_rational().unwrap());
            let sum = rx.add(ry);
            let want = rx.big() + ry.big();
            assert_eq!(sum.big(), want, "{a} + {b}");
        }
        let third = Rational::new(1, 3).unwrap();
        let tiny = big("7e-99990");
        let s = third.add(tiny.as_rational().unwrap());
        assert!(s.bits() > 300_000);
        assert_eq!(s.sub(tiny.as_rational().unwrap()), third);
    }
}
