//! Unit literals: `"25 mph"`, `"45 deg"`, `"9.81 m/s^2"`, `2*pi/(120 s)`, each converted to
//! SI (m, kg, s, K; angles in rad) with its [`Dimension`].
//!
//! A unit expression is a product/quotient of unit names with optional integer powers: `km/h`,
//! `m/s^2`, `kg*m/s^2`, `N/m`. Everything after a `/` is in the denominator (`J/kg*K` is
//! J/(kg·K), as engineers write it). Two contexts read it with one scanner ([`scan_unit`]):
//! - a whole field (`k = "100 N/m"`, `--set vt="150 knot"`): spaces are allowed and an unknown
//!   unit is an error with a suggestion;
//! - inside an expression (`2*pi/(120 s)`): the unit follows its number, its parts are joined
//!   without spaces, and it ends at the first name that is not a unit, so `3 m/s * t` and
//!   `3 m/s*t` both mean (3 m/s)·t. There is no tonne `t` for that reason (write `tonne`).

use crate::dimension::Dimension;
use crate::number::{Number, Rational};

/// A known unit: its SI factor `num/den · π^pi` and its dimension.
#[derive(Debug, PartialEq)]
pub struct Unit {
    /// The name as written.
    pub name: &'static str,
    num: i64,
    den: i64,
    pi: i8,
    /// Exponents of (length, mass, time, temperature).
    dim: [i8; 4],
}

const fn u(name: &'static str, num: i64, den: i64, pi: i8, dim: [i8; 4]) -> Unit {
    Unit {
        name,
        num,
        den,
        pi,
        dim,
    }
}

const L: [i8; 4] = [1, 0, 0, 0];
const M: [i8; 4] = [0, 1, 0, 0];
const T: [i8; 4] = [0, 0, 1, 0];
const V: [i8; 4] = [1, 0, -1, 0];
const F: [i8; 4] = [1, 1, -2, 0];
const E: [i8; 4] = [2, 1, -2, 0];
const P: [i8; 4] = [2, 1, -3, 0];
const PRESSURE: [i8; 4] = [-1, 1, -2, 0];
const HZ: [i8; 4] = [0, 0, -1, 0];
const ONE: [i8; 4] = [0, 0, 0, 0];

/// Known units. Factors are exact where the definition is (1 ft = 0.3048 m, 1 lb =
/// 0.45359237 kg, 1 knot = 1852/3600 m/s), so that quantities stay exact numbers.
const UNITS: &[Unit] = &[
    // length
    u("m", 1, 1, 0, L),
    u("km", 1000, 1, 0, L),
    u("cm", 1, 100, 0, L),
    u("mm", 1, 1000, 0, L),
    u("um", 1, 1_000_000, 0, L),
    u("µm", 1, 1_000_000, 0, L),
    u("nm", 1, 1_000_000_000, 0, L),
    u("angstrom", 1, 10_000_000_000, 0, L),
    u("Å", 1, 10_000_000_000, 0, L),
    u("ft", 3048, 10_000, 0, L),
    u("in", 254, 10_000, 0, L),
    u("mi", 1_609_344, 1000, 0, L),
    u("nmi", 1852, 1, 0, L),
    u("au", 149_597_870_700, 1, 0, L),
    // time
    u("s", 1, 1, 0, T),
    u("ms", 1, 1000, 0, T),
    u("us", 1, 1_000_000, 0, T),
    u("µs", 1, 1_000_000, 0, T),
    u("ns", 1, 1_000_000_000, 0, T),
    u("ps", 1, 1_000_000_000_000, 0, T),
    u("min", 60, 1, 0, T),
    u("h", 3600, 1, 0, T),
    u("hr", 3600, 1, 0, T),
    u("day", 86_400, 1, 0, T),
    u("yr", 31_557_600, 1, 0, T), // Julian year, as the IAU uses
    // speed
    u("mph", 44_704, 100_000, 0, V),
    u("knot", 1852, 3600, 0, V),
    u("knots", 1852, 3600, 0, V),
    u("kn", 1852, 3600, 0, V),
    u("kt", 1852, 3600, 0, V),
    u("kmh", 10, 36, 0, V),
    u("kph", 10, 36, 0, V),
    // mass
    u("kg", 1, 1, 0, M),
    u("g", 1, 1000, 0, M),
    u("mg", 1, 1_000_000, 0, M),
    u("tonne", 1000, 1, 0, M),
    u("lb", 45_359_237, 100_000_000, 0, M),
    // force
    u("N", 1, 1, 0, F),
    u("kN", 1000, 1, 0, F),
    u("MN", 1_000_000, 1, 0, F),
    u("lbf", 44_482_216_152_605, 10_000_000_000_000, 0, F),
    // angle (dimensionless in SI)
    u("rad", 1, 1, 0, ONE),
    u("deg", 1, 180, 1, ONE),
    u("°", 1, 180, 1, ONE),
    u("rev", 2, 1, 1, ONE),
    u("rpm", 2, 60, 1, HZ),
    // frequency, temperature, energy, power, pressure
    u("Hz", 1, 1, 0, HZ),
    u("K", 1, 1, 0, [0, 0, 0, 1]),
    u("J", 1, 1, 0, E),
    u("kJ", 1000, 1, 0, E),
    u("W", 1, 1, 0, P),
    u("kW", 1000, 1, 0, P),
    u("Pa", 1, 1, 0, PRESSURE),
    u("kPa", 1000, 1, 0, PRESSURE),
    u("MPa", 1_000_000, 1, 0, PRESSURE),
    u("GPa", 1_000_000_000, 1, 0, PRESSURE),
    u("bar", 100_000, 1, 0, PRESSURE),
];

impl Unit {
    /// The SI factor as a float.
    pub fn factor(&self) -> f64 {
        self.num as f64 / self.den as f64 * std::f64::consts::PI.powi(self.pi as i32)
    }
    /// The dimension.
    pub fn dimension(&self) -> Dimension {
        Dimension::from_ints(self.dim)
    }
}

/// The unit called `name`, if pdyn knows it.
pub fn lookup(name: &str) -> Option<&'static Unit> {
    UNITS.iter().find(|u| u.name == name)
}

/// Names of all known units, for error messages.
pub fn unit_names() -> Vec<&'static str> {
    UNITS.iter().map(|u| u.name).collect()
}

/// One factor of a unit expression: `s^2` in the denominator of `m/s^2`.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitFactor {
    /// The unit.
    pub unit: &'static Unit,
    /// Its power, negative in the denominator.
    pub power: i32,
}

/// A parsed unit expression (`m/s^2`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct UnitExpr {
    /// The factors in the order written.
    pub factors: Vec<UnitFactor>,
}

impl UnitExpr {
    /// The SI factor as a float.
    pub fn factor(&self) -> f64 {
        self.factors
            .iter()
            .map(|f| f.unit.factor().powi(f.power))
            .product()
    }

    /// The SI factor exactly: `(rational, power of π)`; `None` if it exceeds exact numbers.
    pub fn exact(&self) -> Option<(Rational, i64)> {
        let mut r = Rational::new(1, 1)?;
        let mut pi = 0i64;
        for f in &self.factors {
            let q = Rational::new(f.unit.num as i128, f.unit.den as i128)?;
            r = r.checked_mul(&q.pow(f.power as i64)?)?;
            pi = pi.checked_add((f.unit.pi as i64).checked_mul(f.power as i64)?)?;
        }
        Some((r, pi))
    }

    /// The dimension; `None` on exponent overflow (`m^99999999999`).
    pub fn dimension(&self) -> Option<Dimension> {
        let mut d = Dimension::NONE;
        for f in &self.factors {
            d = d.mul(&f.unit.dimension().pow((f.power as i64).into())?)?;
        }
        Some(d)
    }
}

impl std::fmt::Display for UnitExpr {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut first = true;
        let mut divided = false;
        for u in &self.factors {
            if !first {
                write!(f, "{}", if u.power < 0 && !divided { "/" } else { "*" })?;
            }
            if u.power < 0 {
                divided = true;
            }
            let p = if divided { -u.power } else { u.power };
            write!(f, "{}", u.unit.name)?;
            if p != 1 {
                write!(f, "^{p}")?;
            }
            first = false;
        }
        Ok(())
    }
}

/// A unit literal that could not be read.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitError {
    /// Byte range in the text given.
    pub span: std::ops::Range<usize>,
    /// What is wrong.
    pub message: String,
    /// What would be valid.
    pub help: Option<String>,
}

fn is_unit_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_' || c == '°' || c == 'Å'
}

/// The name starting at `pos` (letters, digits, `_`, `°`), and its end.
fn name_at(text: &str, pos: usize) -> (&str, usize) {
    let mut end = pos;
    for (i, c) in text[pos..].char_indices() {
        if (i == 0 && !(c.is_alphabetic() || c == '°')) || !is_unit_char(c) {
            break;
        }
        end = pos + i + c.len_utf8();
    }
    (&text[pos..end], end)
}

/// An integer power `^2`, `^-1` at `pos`; its value and end.
fn power_at(text: &str, pos: usize) -> Option<(i32, usize)> {
    let b = text.as_bytes();
    if b.get(pos) != Some(&b'^') {
        return None;
    }
    let mut end = pos + 1;
    if b.get(end) == Some(&b'-') {
        end += 1;
    }
    let digits = end;
    while end < b.len() && b[end].is_ascii_digit() {
        end += 1;
    }
    if end == digits {
        return None;
    }
    text[pos + 1..end].parse().ok().map(|p| (p, end))
}

/// Scans a unit expression at the start of `text`.
///
/// `loose` (a whole field): spaces separate factors and anything that is not a known unit is an
/// error. Strict (inside an expression): `Ok(None)` when `text` does not start with a unit name;
/// otherwise the unit ends before the first space or the first part that is not a unit, and the
/// length scanned is returned with it.
pub fn scan_unit(text: &str, loose: bool) -> Result<Option<(usize, UnitExpr)>, UnitError> {
    let mut out = UnitExpr::default();
    let mut pos = 0;
    let mut divide = false;
    let bytes = text.as_bytes();
    loop {
        // An operator joining the next factor (none before the first).
        let mut next = pos;
        let mut op = None;
        if loose {
            while next < text.len() && (bytes[next] == b' ' || bytes[next] == b'*') {
                next += 1;
            }
            if next < text.len() && bytes[next] == b'/' {
                op = Some('/');
                next += 1;
                while next < text.len() && bytes[next] == b' ' {
                    next += 1;
                }
            }
            if next >= text.len() {
                if op.is_some() {
                    return Err(UnitError {
                        span: pos..text.len(),
                        message: "a unit is missing after `/`".into(),
                        help: None,
                    });
                }
                break;
            }
        } else if !out.factors.is_empty() {
            match bytes.get(pos) {
                Some(b'/') => op = Some('/'),
                Some(b'*') if bytes.get(pos + 1) != Some(&b'*') => op = Some('*'),
                _ => break,
            }
            next = pos + 1;
        }
        let (name, end) = name_at(text, next);
        let unit = lookup(name).filter(|_| !text[end..].starts_with('('));
        let Some(unit) = unit else {
            if !loose {
                // Not a unit: the expression goes on from `pos` (`3 m/s*x`, `2 x`).
                break;
            }
            let c = text[next..].chars().next().unwrap_or(' ');
            return Err(if name.is_empty() {
                UnitError {
                    span: next..next + c.len_utf8(),
                    message: format!("unexpected `{c}` in a unit"),
                    help: Some("units look like `mph`, `km/h`, `m/s^2`, `deg`".into()),
                }
            } else {
                let help = match crate::error::suggest(name, unit_names()) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => format!("known units: {}", unit_names().join(" ")),
                };
                UnitError {
                    span: next..end,
                    message: format!("unknown unit `{name}`"),
                    help: Some(help),
                }
            });
        };
        if op == Some('/') {
            divide = true;
        }
        let (power, end) = match power_at(text, end) {
            Some(pe) => pe,
            None if loose && bytes.get(end) == Some(&b'^') => {
                return Err(UnitError {
                    span: end..(end + 1).max(text.len().min(end + 2)),
                    message: "expected an integer power after `^`".into(),
                    help: None,
                })
            }
            None => (1, end),
        };
        out.factors.push(UnitFactor {
            unit,
            power: if divide { -power } else { power },
        });
        pos = end;
    }
    Ok((!out.factors.is_empty()).then_some((pos, out)))
}

/// True when `text` looks like `number unit` (a number followed by letters), as opposed to an
/// expression.
pub fn looks_like_quantity(text: &str) -> bool {
    let t = text.trim();
    let num_end = number_prefix(t);
    num_end > 0 && num_end < t.len() && {
        let rest = t[num_end..].trim_start();
        rest.starts_with(|c: char| c.is_alphabetic() || c == '°')
            && rest
                .chars()
                .all(|c| c.is_alphanumeric() || "/*^-° ".contains(c) || c == 'µ')
    }
}

/// Length of the number at the start of `t` (`-1.5e3`), 0 if there is none.
fn number_prefix(t: &str) -> usize {
    let b = t.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
        i += 1;
    }
    let start = i;
    while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
        i += 1;
    }
    if i == start {
        return 0;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'-' || b[j] == b'+') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            i = j;
        }
    }
    i
}

/// A whole field `number unit`: its SI value and dimension.
pub fn parse_quantity_with_dimension(text: &str) -> Result<(f64, Dimension), UnitError> {
    let lead = text.len() - text.trim_start().len();
    let t = text.trim();
    let n = number_prefix(t);
    let value: f64 = t[..n].parse().map_err(|_| UnitError {
        span: lead..lead + n.max(1),
        message: format!("expected a number at the start of `{t}`"),
        help: None,
    })?;
    let rest_start = lead + n + (t[n..].len() - t[n..].trim_start().len());
    let unit = parse_unit_expr(&text[rest_start..]).map_err(|mut e| {
        e.span = e.span.start + rest_start..e.span.end + rest_start;
        e
    })?;
    let dim = unit.dimension().ok_or_else(|| UnitError {
        span: rest_start..text.len(),
        message: "the unit's powers are too large".into(),
        help: None,
    })?;
    Ok((value * unit.factor(), dim))
}

/// A whole field `number unit` in SI.
pub fn parse_quantity(text: &str) -> Result<f64, UnitError> {
    parse_quantity_with_dimension(text).map(|(v, _)| v)
}

/// A whole unit expression such as `m/s^2`.
pub fn parse_unit_expr(u: &str) -> Result<UnitExpr, UnitError> {
    match scan_unit(u, true)? {
        Some((_, e)) => Ok(e),
        None => Err(UnitError {
            span: 0..u.len(),
            message: "expected a unit".into(),
            help: Some("units look like `mph`, `km/h`, `m/s^2`, `deg`".into()),
        }),
    }
}

/// The SI factor of a whole unit expression such as `m/s^2`.
pub fn parse_unit(u: &str) -> Result<f64, UnitError> {
    parse_unit_expr(u).map(|e| e.factor())
}

/// The exact value of `number unit` as a [`Number`] times `π^k`.
pub fn exact_quantity(value: &Number, unit: &UnitExpr) -> Option<(Number, i64)> {
    let (r, pi) = unit.exact()?;
    Some((value.mul(&Number::Rat(r)), pi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_the_chapters_quantities() {
        assert!((parse_quantity("25 mph").unwrap() - 11.176).abs() < 1e-12);
        assert!((parse_quantity("150 knots").unwrap() - 77.1666).abs() < 1e-3);
        assert!((parse_quantity("45 deg").unwrap() - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        assert!((parse_quantity("20 nm").unwrap() - 2e-8).abs() < 1e-22);
        assert!((parse_quantity("9.81 m/s^2").unwrap() - 9.81).abs() < 1e-15);
        assert!((parse_quantity("36 km/h").unwrap() - 10.0).abs() < 1e-12);
        assert!((parse_quantity("2330 kg/m^3").unwrap() - 2330.0).abs() < 1e-9);
        assert!((parse_quantity("1 kg*m/s^2").unwrap() - 1.0).abs() < 1e-15);
        let (v, d) = parse_quantity_with_dimension("100 N/m").unwrap();
        assert_eq!(v, 100.0);
        assert_eq!(d.describe(), "kg/s^2 (stiffness)");
    }

    #[test]
    fn errors_point_at_the_unit() {
        let e = parse_quantity("25 mhp").unwrap_err();
        assert_eq!(e.span, 3..6);
        assert_eq!(e.help.as_deref(), Some("did you mean `mph`?"));
        assert!(looks_like_quantity("25 mph"));
        assert!(!looks_like_quantity("2*g"));
        assert!(!looks_like_quantity("omega*t"));
        assert!(parse_quantity("3 m^").is_err());
        assert!(parse_quantity("3 m/").is_err());
    }

    #[test]
    fn strict_scanning_stops_where_the_unit_ends() {
        let scan = |s: &str| {
            scan_unit(s, false)
                .unwrap()
                .map(|(n, e)| (n, e.to_string()))
        };
        assert_eq!(scan("s)"), Some((1, "s".into())));
        assert_eq!(scan("m/s^2 + x"), Some((5, "m/s^2".into())));
        assert_eq!(scan("m/s*x"), Some((3, "m/s".into())));
        assert_eq!(scan("kg*m/s^2"), Some((8, "kg*m/s^2".into())));
        assert_eq!(scan("x"), None);
        assert_eq!(scan("min(a, b)"), None);
        assert_eq!(scan("m_1"), None);
        assert_eq!(scan("m**2"), Some((1, "m".into())));
    }

    #[test]
    fn exact_factors() {
        let e = parse_unit_expr("knot").unwrap();
        let (r, pi) = e.exact().unwrap();
        assert_eq!((r.to_string(), pi), ("463/900".to_string(), 0));
        let (r, pi) = parse_unit_expr("deg").unwrap().exact().unwrap();
        assert_eq!((r.to_string(), pi), ("1/180".to_string(), 1));
        assert_eq!(
            parse_unit_expr("rpm")
                .unwrap()
                .dimension()
                .unwrap()
                .describe(),
            "1/s (frequency)"
        );
    }
}
