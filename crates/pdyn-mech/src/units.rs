//! Unit literals in model files: `"25 mph"`, `"45 deg"`, `"9.81 m/s^2"`, `"20 nm"`, converted to
//! SI (m, kg, s, rad, N, K).
//!
//! Grammar: `number unit-expression`, where a unit expression is a product/quotient of unit
//! names with optional integer powers: `km/h`, `m/s^2`, `kg*m/s^2`, `N/m`. The dimension is not
//! checked against its use (a parameter has no declared dimension); the conversion factor is.

/// Known units and their factor to SI.
const UNITS: &[(&str, f64)] = &[
    // length
    ("m", 1.0),
    ("km", 1e3),
    ("cm", 1e-2),
    ("mm", 1e-3),
    ("um", 1e-6),
    ("µm", 1e-6),
    ("nm", 1e-9),
    ("ft", 0.3048),
    ("in", 0.0254),
    ("mi", 1609.344),
    ("nmi", 1852.0),
    // time
    ("s", 1.0),
    ("ms", 1e-3),
    ("min", 60.0),
    ("h", 3600.0),
    ("hr", 3600.0),
    // speed
    ("mph", 0.44704),
    ("knot", 1852.0 / 3600.0),
    ("knots", 1852.0 / 3600.0),
    ("kn", 1852.0 / 3600.0),
    ("kt", 1852.0 / 3600.0),
    ("kmh", 1.0 / 3.6),
    ("kph", 1.0 / 3.6),
    // mass
    ("kg", 1.0),
    ("g", 1e-3),
    ("mg", 1e-6),
    ("t", 1e3),
    ("tonne", 1e3),
    ("lb", 0.45359237),
    // force
    ("N", 1.0),
    ("kN", 1e3),
    ("MN", 1e6),
    ("lbf", 4.4482216152605),
    // angle
    ("rad", 1.0),
    ("deg", std::f64::consts::PI / 180.0),
    ("°", std::f64::consts::PI / 180.0),
    ("rev", 2.0 * std::f64::consts::PI),
    ("rpm", 2.0 * std::f64::consts::PI / 60.0),
    // frequency, temperature, energy, pressure, density helpers
    ("Hz", 1.0),
    ("K", 1.0),
    ("J", 1.0),
    ("W", 1.0),
    ("Pa", 1.0),
    ("kPa", 1e3),
    ("bar", 1e5),
];

/// Names of all known units, for error messages.
pub fn unit_names() -> Vec<&'static str> {
    UNITS.iter().map(|(n, _)| *n).collect()
}

/// A unit literal that could not be read; `at` is a byte offset into the literal.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitError {
    /// Byte range in the literal.
    pub span: std::ops::Range<usize>,
    /// What is wrong.
    pub message: String,
    /// What would be valid.
    pub help: Option<String>,
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

/// Parses `number unit` into an SI value.
pub fn parse_quantity(text: &str) -> Result<f64, UnitError> {
    let lead = text.len() - text.trim_start().len();
    let t = text.trim();
    let n = number_prefix(t);
    let value: f64 = t[..n].parse().map_err(|_| UnitError {
        span: lead..lead + n.max(1),
        message: format!("expected a number at the start of `{t}`"),
        help: None,
    })?;
    let rest_start = lead + n + (t[n..].len() - t[n..].trim_start().len());
    let factor = parse_unit(&text[rest_start..]).map_err(|mut e| {
        e.span = e.span.start + rest_start..e.span.end + rest_start;
        e
    })?;
    Ok(value * factor)
}

/// Parses a unit expression such as `m/s^2` into its SI factor.
pub fn parse_unit(u: &str) -> Result<f64, UnitError> {
    let mut factor = 1.0;
    let mut divide = false;
    let mut pos = 0;
    let bytes = u.as_bytes();
    while pos < u.len() {
        let c = u[pos..].chars().next().unwrap_or(' ');
        if c == ' ' || c == '*' {
            pos += c.len_utf8();
            continue;
        }
        if c == '/' {
            divide = true;
            pos += 1;
            continue;
        }
        let start = pos;
        while pos < u.len() {
            let ch = u[pos..].chars().next().unwrap_or(' ');
            if ch.is_alphabetic() || ch == '°' || ch == 'µ' {
                pos += ch.len_utf8();
            } else {
                break;
            }
        }
        if pos == start {
            return Err(UnitError {
                span: start..start + c.len_utf8(),
                message: format!("unexpected `{c}` in a unit"),
                help: Some("units look like `mph`, `km/h`, `m/s^2`, `deg`".into()),
            });
        }
        let name = &u[start..pos];
        let Some(&(_, f)) = UNITS.iter().find(|(n, _)| *n == name) else {
            let suggestion = pdyn_expr::error::suggest(name, unit_names());
            return Err(UnitError {
                span: start..pos,
                message: format!("unknown unit `{name}`"),
                help: Some(match suggestion {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => format!("known units: {}", unit_names().join(" ")),
                }),
            });
        };
        let mut power = 1i32;
        if pos < u.len() && bytes[pos] == b'^' {
            let pstart = pos + 1;
            let mut pend = pstart;
            if pend < u.len() && bytes[pend] == b'-' {
                pend += 1;
            }
            while pend < u.len() && bytes[pend].is_ascii_digit() {
                pend += 1;
            }
            power = u[pstart..pend].parse().map_err(|_| UnitError {
                span: pos..pend.max(pos + 1),
                message: "expected an integer power after `^`".into(),
                help: None,
            })?;
            pos = pend;
        }
        let f = f.powi(power);
        if divide {
            factor /= f;
            divide = false;
        } else {
            factor *= f;
        }
    }
    Ok(factor)
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
    }

    #[test]
    fn errors_point_at_the_unit() {
        let e = parse_quantity("25 mhp").unwrap_err();
        assert_eq!(e.span, 3..6);
        assert_eq!(e.help.as_deref(), Some("did you mean `mph`?"));
        assert!(looks_like_quantity("25 mph"));
        assert!(!looks_like_quantity("2*g"));
        assert!(!looks_like_quantity("omega*t"));
    }
}
