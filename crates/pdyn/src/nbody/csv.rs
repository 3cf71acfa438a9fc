//! Bodies from a CSV file (`bodies_file = "..."`): a header line naming the columns, then one
//! body per line. Columns: `name` (optional), `mass`, `radius` (optional), and
//! `x, y, z, vx, vy, vz` (Cartesian) and/or `primary` (optional), `a, e, inc, Omega, omega`
//! and `M` or `f` (elements; angles in radians, or with a unit such as `12 deg`). Each line
//! fills one set and leaves the other's cells empty; empty element cells other than `a` are
//! 0. Empty lines and lines starting with `#` are skipped. Every problem is located at its
//! cell.

use super::spec::{check_elements, BodySpec, InitialState, Origin, UnitsSpec};
use pdyn_mech::ModelError;
use std::ops::Range;

const KNOWN: [&str; 17] = [
    "name", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "primary", "a", "e", "inc", "Omega",
    "omega", "M", "f",
];

/// Cells of one line with their byte ranges in the file.
fn cells(line: &str, start: usize) -> Vec<(&str, Range<usize>)> {
    let mut out = Vec::new();
    let mut pos = 0;
    for cell in line.split(',') {
        let lead = cell.len() - cell.trim_start().len();
        let t = cell.trim();
        let s = start + pos + lead;
        out.push((t, s..s + t.len().max(1)));
        pos += cell.len() + 1;
    }
    out
}

/// Reads the bodies of a CSV text; `before` are the bodies declared in the model file (names
/// must stay unique, and primaries may name them).
pub fn bodies(
    text: &str,
    origin: &str,
    units: UnitsSpec,
    before: &[BodySpec],
) -> Result<Vec<BodySpec>, ModelError> {
    let err = |span: Range<usize>, msg: String| ModelError::new(origin, span, msg);
    let mut lines = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let body = line.trim_end_matches(['\n', '\r']);
        if !body.trim().is_empty() && !body.trim_start().starts_with('#') {
            lines.push((body, offset));
        }
        offset += line.len();
    }
    let Some(&(head, head_at)) = lines.first() else {
        return Err(err(0..0, "the bodies file is empty".into())
            .help("a header line (name,mass,x,y,z,vx,vy,vz) and one line per body"));
    };
    let header = cells(head, head_at);
    let mut col = std::collections::HashMap::new();
    for (k, (name, span)) in header.iter().enumerate() {
        if !KNOWN.contains(name) {
            return Err(err(span.clone(), format!("unknown column `{name}`"))
                .help(format!("columns: {}", KNOWN.join(", "))));
        }
        if col.insert(*name, k).is_some() {
            return Err(err(span.clone(), format!("column `{name}` appears twice")));
        }
    }
    let has = |c: &str| col.contains_key(c);
    let cart = ["x", "y", "z", "vx", "vy", "vz"];
    let cartesian = cart.iter().all(|c| has(c));
    let elements = has("a");
    let head_span = head_at..head_at + head.len();
    if !has("mass") {
        return Err(err(
            head_span,
            "the bodies file has no `mass` column".into(),
        ));
    }
    if !cartesian && !elements {
        return Err(err(
            head_span,
            "the header must have the columns x,y,z,vx,vy,vz or the elements a,e,... (or both)"
                .into(),
        ));
    }
    if cart.iter().any(|c| has(c)) && !cartesian {
        return Err(err(
            head_span,
            "a Cartesian state needs all of x,y,z,vx,vy,vz".into(),
        ));
    }
    if has("M") && has("f") {
        return Err(err(head_span, "give the column M or f, not both".into()));
    }
    let mut out: Vec<BodySpec> = Vec::new();
    for &(line, at) in &lines[1..] {
        let row = cells(line, at);
        if row.len() != header.len() {
            return Err(err(
                at..at + line.len().max(1),
                format!("{} cells, but the header has {}", row.len(), header.len()),
            ));
        }
        let cell = |c: &str| col.get(c).map(|&k| &row[k]);
        let number = |c: &str, angle: bool| -> Result<Option<f64>, ModelError> {
            let Some((t, span)) = cell(c).filter(|(t, _)| !t.is_empty()) else {
                return Ok(None);
            };
            let v = if angle && pdyn_mech::units::looks_like_quantity(t) {
                pdyn_mech::units::parse_quantity(t)
                    .map_err(|e| err(span.clone(), format!("`{t}`: {}", e.message)))?
            } else {
                t.parse::<f64>().map_err(|_| {
                    err(span.clone(), format!("`{t}` is not a number")).help(if angle || units.si {
                        "a number, e.g. 1.5e-3 (angles may be `12 deg`)"
                    } else {
                        "a number in the model's units, e.g. 1.5e-3"
                    })
                })?
            };
            if !v.is_finite() {
                return Err(err(span.clone(), format!("`{t}` is not finite")));
            }
            Ok(Some(v))
        };
        let index = before.len() + out.len();
        let name = match cell("name") {
            Some((t, span)) if !t.is_empty() => {
                if before.iter().chain(out.iter()).any(|b| b.name == *t) {
                    return Err(err(span.clone(), format!("two bodies are named `{t}`")));
                }
                t.to_string()
            }
            _ => format!("body{index}"),
        };
        // The header was checked for a mass column; the row's span is the fallback all the same.
        let row_span = at..at + line.len().max(1);
        let mass_span = cell("mass").map_or(row_span.clone(), |(_, s)| s.clone());
        let mass = number("mass", false)?.unwrap_or(0.0);
        if !(mass.is_finite() && mass > 0.0) {
            return Err(err(
                mass_span.clone(),
                format!("mass must be > 0 (got {mass})"),
            ));
        }
        let radius = number("radius", false)?.unwrap_or(0.0);
        if !(radius.is_finite() && radius >= 0.0) {
            let span = cell("radius").map_or(mass_span.clone(), |c| c.1.clone());
            return Err(err(span, format!("radius must be >= 0 (got {radius})")));
        }
        let get = |c: &str| -> Result<f64, ModelError> { Ok(number(c, false)?.unwrap_or(0.0)) };
        // Each line uses the columns it fills: a Cartesian state, or elements.
        let filled = |c: &str| cell(c).is_some_and(|(t, _)| !t.is_empty());
        let row_cartesian = cartesian && cart.iter().any(|c| filled(c));
        if !row_cartesian && !filled("a") {
            return Err(err(
                at..at + line.len().max(1),
                format!("body `{name}` has no initial state: fill x,y,z,vx,vy,vz or a,e,..."),
            ));
        }
        let state = if row_cartesian {
            InitialState::Cartesian {
                position: [get("x")?, get("y")?, get("z")?],
                velocity: [get("vx")?, get("vy")?, get("vz")?],
            }
        } else {
            let (a, e) = (get("a")?, get("e")?);
            check_elements(a, e).map_err(|msg| {
                let c = if msg.blames_eccentricity() { "e" } else { "a" };
                err(
                    cell(c).map_or(row_span.clone(), |(_, s)| s.clone()),
                    format!("body `{name}`: {msg}"),
                )
            })?;
            let angle =
                |c: &str| -> Result<f64, ModelError> { Ok(number(c, true)?.unwrap_or(0.0)) };
            let anomaly = if has("M") {
                pdyn_gravity::Anomaly::Mean(angle("M")?)
            } else {
                pdyn_gravity::Anomaly::True(angle("f")?)
            };
            let primary = match cell("primary") {
                Some((t, span)) if !t.is_empty() => {
                    let all: Vec<&BodySpec> = before.iter().chain(out.iter()).collect();
                    match all.iter().position(|b| b.name == *t) {
                        Some(j) => Some(j),
                        None => {
                            return Err(err(span.clone(), format!("unknown primary `{t}`"))
                                .help("a primary must be a body declared before this one"))
                        }
                    }
                }
                _ if index == 0 => {
                    return Err(err(
                        at..at + line.len().max(1),
                        format!("body `{name}`: orbital elements need a body before it to orbit"),
                    ))
                }
                _ => None,
            };
            InitialState::Orbit {
                elements: pdyn_gravity::Elements {
                    a,
                    e,
                    inc: angle("inc")?,
                    Omega: angle("Omega")?,
                    omega: angle("omega")?,
                    anomaly,
                },
                primary,
            }
        };
        out.push(BodySpec {
            name,
            mass,
            radius,
            state,
            origin: Origin {
                file: origin.to_string(),
                span: at..at + line.len().max(1),
            },
        });
    }
    Ok(out)
}
