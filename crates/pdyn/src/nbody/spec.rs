//! The `[nbody]` table read from TOML into an [`NbodySpec`]: every value evaluated (numbers,
//! expressions of `[parameters]`, unit literals through [`pdyn_mech::model::constants`]) and
//! every problem a located [`ModelError`]. Nothing here integrates; [`super::build`] turns the
//! spec into a `pdyn_gravity::Simulation`. The format is documented in `docs/nbody.md`.

use indexmap::IndexMap;
use pdyn_mech::model::constants::{Constants, SpannedValue as Sv};
use pdyn_mech::ModelError;
use serde::Deserialize;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

type Name = Spanned<String>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // `description` is read through serde only
struct RawFile {
    name: Option<String>,
    description: Option<String>,
    #[serde(default)]
    parameters: IndexMap<Name, Sv>,
    nbody: Spanned<RawNbody>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNbody {
    units: Option<Name>,
    #[serde(rename = "G")]
    g: Option<Sv>,
    integrator: Option<Name>,
    dt: Option<Sv>,
    corrector: Option<Spanned<i64>>,
    epsilon: Option<Sv>,
    gravity: Option<Name>,
    theta: Option<Sv>,
    quadrupole: Option<Spanned<bool>>,
    softening: Option<Sv>,
    t_end: Option<Sv>,
    output_dt: Option<Sv>,
    points: Option<Spanned<i64>>,
    drift_tolerance: Option<Sv>,
    collisions: Option<Name>,
    escape_radius: Option<Sv>,
    escape: Option<Name>,
    center_of_mass: Option<Spanned<bool>>,
    trajectory: Option<Spanned<bool>>,
    bodies_file: Option<Name>,
    plummer: Option<Spanned<RawPlummer>>,
    #[serde(default)]
    bodies: Vec<Spanned<RawBody>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlummer {
    n: Option<Sv>,
    seed: Option<Spanned<i64>>,
    mass: Option<Sv>,
    scale: Option<Sv>,
    rescale: Option<Spanned<bool>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
struct RawBody {
    name: Option<Name>,
    mass: Option<Sv>,
    radius: Option<Sv>,
    position: Option<Sv>,
    velocity: Option<Sv>,
    primary: Option<Name>,
    a: Option<Sv>,
    e: Option<Sv>,
    inc: Option<Sv>,
    Omega: Option<Sv>,
    omega: Option<Sv>,
    M: Option<Sv>,
    f: Option<Sv>,
}

/// Where a value came from: a file (the model or a bodies CSV) and a byte range in it, so
/// that a problem found later (while building the simulation) is still located.
#[derive(Debug, Clone)]
pub struct Origin {
    /// File name as given to the user.
    pub file: String,
    /// Byte range in that file.
    pub span: Range<usize>,
}

/// A named unit system, or a value of `G`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitsSpec {
    /// The engine's units.
    pub units: pdyn_gravity::Units,
    /// Whether lengths, times and masses are SI (then unit literals such as `"5 km"` are
    /// allowed everywhere; otherwise only in angles).
    pub si: bool,
    /// Name printed in reports (`au-day-msun`, `G = 1`...).
    pub label: &'static str,
}

impl UnitsSpec {
    /// The units of length and time for axis labels and reports: `("AU", "days")`, `("m",
    /// "s")`; for `G = 1` (Hénon) and a custom `G`, the model's own units.
    pub fn length_time(&self) -> (&'static str, &'static str) {
        match self.units {
            pdyn_gravity::Units::AuDaySolarMass => ("AU", "days"),
            pdyn_gravity::Units::AuYearSolarMass => ("AU", "yr"),
            pdyn_gravity::Units::Si => ("m", "s"),
            pdyn_gravity::Units::GEqualsOne => ("N-body length", "N-body time"),
            _ => ("length unit", "time unit"),
        }
    }
}

/// The unit systems `units = "..."` accepts: name, engine units, SI, label.
pub const UNIT_SYSTEMS: &[(&str, pdyn_gravity::Units, bool)] = &[
    ("nbody", pdyn_gravity::Units::GEqualsOne, false),
    ("henon", pdyn_gravity::Units::GEqualsOne, false),
    ("G=1", pdyn_gravity::Units::GEqualsOne, false),
    ("au-day-msun", pdyn_gravity::Units::AuDaySolarMass, false),
    ("au-year-msun", pdyn_gravity::Units::AuYearSolarMass, false),
    ("si", pdyn_gravity::Units::Si, true),
];

/// The integrator named in the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntegratorKind {
    /// WHFast (fixed step, Jacobi coordinates, correctors).
    WhFast,
    /// IAS15 (adaptive, 15th order).
    Ias15,
    /// Leapfrog (fixed step; direct or tree forces).
    Leapfrog,
}

impl IntegratorKind {
    /// The names `integrator = ...` and `--method` accept.
    pub const NAMES: [(&'static str, IntegratorKind); 3] = [
        ("whfast", IntegratorKind::WhFast),
        ("ias15", IntegratorKind::Ias15),
        ("leapfrog", IntegratorKind::Leapfrog),
    ];

    /// From its name (case-insensitive).
    pub fn from_name(name: &str) -> Option<IntegratorKind> {
        let n = name.to_ascii_lowercase();
        Self::NAMES.iter().find(|(s, _)| *s == n).map(|(_, k)| *k)
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, k)| *k == self)
            .map_or("?", |(s, _)| s)
    }
}

/// What a collision (bodies with radii that touch) does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CollisionMode {
    /// Stop the run at the first collision (an event).
    Stop,
    /// Merge the two bodies conserving mass and momentum, and go on.
    Merge,
}

/// What an escape (a body beyond `escape_radius`) does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EscapeMode {
    /// Stop the run (an event).
    Stop,
    /// Remove the body and go on.
    Remove,
}

/// How a body's initial state is given.
#[derive(Debug, Clone, PartialEq)]
pub enum InitialState {
    /// Position and velocity in the inertial frame.
    Cartesian {
        /// Position.
        position: [f64; 3],
        /// Velocity.
        velocity: [f64; 3],
    },
    /// Keplerian elements relative to a primary.
    Orbit {
        /// The elements (angles in radians).
        elements: pdyn_gravity::Elements,
        /// Index of the primary body among the bodies before this one, or `None`: the centre
        /// of mass of all the bodies before it (Jacobi elements, REBOUND's default).
        primary: Option<usize>,
    },
}

/// One body.
#[derive(Debug, Clone)]
pub struct BodySpec {
    /// Its name (unique).
    pub name: String,
    /// Mass (> 0).
    pub mass: f64,
    /// Collision radius (≥ 0; 0: never collides).
    pub radius: f64,
    /// Initial state.
    pub state: InitialState,
    /// Where it was declared.
    pub origin: Origin,
}

/// `plummer = { n, seed, mass, scale }`: a generated Plummer sphere.
#[derive(Debug, Clone)]
pub struct PlummerSpec {
    /// Number of stars.
    pub n: usize,
    /// Seed of the generator.
    pub seed: u64,
    /// Total mass (default 1).
    pub mass: f64,
    /// Length scale: positions are the Hénon-unit sphere's times `scale` (default 1, which
    /// is the virial radius), velocities times `√(G mass/scale)`.
    pub scale: f64,
    /// Whether each realization is rescaled exactly to standard Hénon units (`E = −1/4`,
    /// virial ratio 1) before `mass` and `scale` apply (`rescale = true`, the default), or
    /// kept as drawn (`rescale = false`).
    pub rescale: bool,
    /// Where it was declared.
    pub origin: Origin,
}

/// Everything the `[nbody]` table says, evaluated.
#[derive(Debug, Clone)]
pub struct NbodySpec {
    /// Model name (top-level `name`).
    pub name: String,
    /// The file.
    pub origin: String,
    /// Units.
    pub units: UnitsSpec,
    /// Integrator.
    pub integrator: IntegratorKind,
    /// Where `integrator` was written (for errors about it).
    pub integrator_span: Range<usize>,
    /// Step (initial step for IAS15); `None`: the default for the integrator.
    pub dt: Option<(f64, Range<usize>)>,
    /// WHFast corrector order.
    pub corrector: u32,
    /// IAS15 accuracy parameter.
    pub epsilon: Option<f64>,
    /// Barnes–Hut opening angle when the tree is used.
    pub tree: Option<pdyn_gravity::TreeParams>,
    /// Plummer softening length.
    pub softening: f64,
    /// End time.
    pub t_end: Option<f64>,
    /// Output interval.
    pub output_dt: Option<f64>,
    /// Number of output times.
    pub points: Option<usize>,
    /// Drift tolerance of the conservation monitors.
    pub drift_tolerance: Option<f64>,
    /// Collisions.
    pub collisions: CollisionMode,
    /// Escape radius and what it does.
    pub escape: Option<(f64, EscapeMode)>,
    /// Move to the centre-of-mass frame before integrating (default true).
    pub center_of_mass: bool,
    /// Write per-body trajectories (`None`: when N ≤ [`super::run::TRAJECTORY_LIMIT`]).
    pub trajectory: Option<bool>,
    /// Bodies from the table and the CSV file, in order.
    pub bodies: Vec<BodySpec>,
    /// A generated cluster, added after the bodies.
    pub plummer: Option<PlummerSpec>,
    /// The parameters with their final values.
    pub parameters: Vec<(String, f64)>,
    /// Where the `[nbody]` table is.
    pub table_span: Range<usize>,
}

/// A located error in one of the files of the model: the error and the text it points into.
#[derive(Debug, Clone)]
pub struct SpecError {
    /// The problem.
    pub error: ModelError,
    /// The text of the file it is located in (the model or the bodies CSV).
    pub source: String,
}

/// Where the top-level `[nbody]` table is, when there is one.
pub fn nbody_table_span(source: &str) -> Option<Range<usize>> {
    #[derive(Deserialize)]
    struct Probe {
        nbody: Option<Spanned<toml::Value>>,
    }
    let probe: Probe = toml::from_str(source).ok()?;
    let span = probe.nbody?.span();
    // A `[nbody]` header's value span covers the table body; point at the header when there is
    // one, which is what a reader looks for.
    let mut at = 0;
    for line in source.split_inclusive('\n') {
        let lead = line.len() - line.trim_start().len();
        if line.trim_start().starts_with("[nbody]") {
            return Some(at + lead..at + lead + 7);
        }
        at += line.len();
    }
    Some(span)
}

/// Reads the N-body model in `source` (the file `origin`, whose directory anchors
/// `bodies_file`). `set` overrides parameter values (`--set`); a name that is not a parameter
/// is returned in the error as `Err(Unknown)`.
pub fn parse(
    source: &str,
    origin: &str,
    set: &[(String, f64)],
) -> Result<NbodySpec, Box<SetOrSpecError>> {
    let in_model = |error: ModelError| {
        Box::new(SetOrSpecError::Spec(SpecError {
            error,
            source: source.to_string(),
        }))
    };
    let raw: RawFile = toml::from_str(source).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        in_model(
            ModelError::new(origin, span, e.message().trim().to_string())
                .help("see docs/nbody.md for the keys of an N-body model"),
        )
    })?;
    for (k, _) in set {
        if !raw.parameters.keys().any(|n| n.get_ref() == k) {
            let names: Vec<&str> = raw
                .parameters
                .keys()
                .map(|n| n.get_ref().as_str())
                .collect();
            return Err(Box::new(SetOrSpecError::UnknownParameter {
                name: k.clone(),
                parameters: names.join(", "),
            }));
        }
    }
    let mut c = Constants::new(source, origin);
    for (name, sv) in &raw.parameters {
        let value = set
            .iter()
            .rev()
            .find(|(k, _)| k == name.get_ref())
            .map(|(_, v)| *v);
        c.parameter(name, sv, value).map_err(in_model)?;
    }
    let nb = raw.nbody.get_ref();
    let table_span = nbody_table_span(source).unwrap_or(raw.nbody.span());
    let mut r = Reader {
        c,
        units: UnitsSpec {
            units: pdyn_gravity::Units::GEqualsOne,
            si: false,
            label: "G = 1",
        },
    };
    r.units = units(&mut r, nb).map_err(in_model)?;
    let spec = r
        .table(&raw, nb, origin, table_span.clone())
        .map_err(in_model)?;
    let mut spec = spec;
    if let Some(file) = &nb.bodies_file {
        let dir = Path::new(origin).parent().unwrap_or(Path::new(""));
        let path: PathBuf = dir.join(file.get_ref());
        let bytes = std::fs::read(&path).map_err(|e| {
            in_model(
                ModelError::new(
                    origin,
                    file.span(),
                    format!("cannot read the bodies file {}: {e}", path.display()),
                )
                .help("bodies_file is relative to the model file"),
            )
        })?;
        let csv_origin = path.display().to_string();
        // Bytes that are not UTF-8: an error at the first of them, in the CSV.
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let byte = e.as_bytes()[at];
            Box::new(SetOrSpecError::Spec(SpecError {
                error: ModelError::new(
                    &csv_origin,
                    at..at + char::REPLACEMENT_CHARACTER.len_utf8(),
                    format!("the byte 0x{byte:02X} is not UTF-8: a bodies file must be UTF-8 text"),
                ),
                source: String::from_utf8_lossy(e.as_bytes()).into_owned(),
            }))
        })?;
        let first = spec.bodies.len();
        let csv_bodies =
            super::csv::bodies(&text, &csv_origin, r.units, &spec.bodies).map_err(|error| {
                Box::new(SetOrSpecError::Spec(SpecError {
                    error,
                    source: text.clone(),
                }))
            })?;
        spec.bodies.extend(csv_bodies);
        debug_assert!(spec.bodies.len() >= first);
    }
    if spec.bodies.is_empty() && spec.plummer.is_none() {
        return Err(in_model(
            ModelError::new(origin, table_span, "the [nbody] table has no bodies").help(
                "add [[nbody.bodies]] entries, bodies_file = \"...\" or plummer = { n = ... }",
            ),
        ));
    }
    Ok(spec)
}

/// A problem with the model file or with a `--set` value.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum SetOrSpecError {
    /// A located problem in a file.
    Spec(SpecError),
    /// `--set NAME=...` where NAME is not a parameter.
    UnknownParameter {
        /// The name given.
        name: String,
        /// The parameters there are.
        parameters: String,
    },
}

fn units(r: &mut Reader<'_>, nb: &RawNbody) -> Result<UnitsSpec, ModelError> {
    match (&nb.units, &nb.g) {
        (Some(u), Some(g)) => Err(r
            .c
            .err(g.span(), "give either `units` or `G`, not both")
            .help(format!("units = \"{}\" fixes G", u.get_ref()))),
        (None, None) => Ok(UnitsSpec {
            units: pdyn_gravity::Units::GEqualsOne,
            si: false,
            label: "G = 1",
        }),
        (None, Some(g)) => {
            let v = r.plain(g, "G", false)?;
            if !(v.is_finite() && v > 0.0) {
                return Err(r.c.err(g.span(), format!("G must be > 0 (got {v})")));
            }
            Ok(UnitsSpec {
                units: pdyn_gravity::Units::Custom(v),
                si: false,
                label: "custom G",
            })
        }
        (Some(u), None) => {
            let name = u.get_ref().to_ascii_lowercase().replace(' ', "");
            UNIT_SYSTEMS
                .iter()
                .find(|(n, _, _)| n.to_ascii_lowercase() == name)
                .map(|&(n, units, si)| UnitsSpec {
                    units,
                    si,
                    label: n,
                })
                .ok_or_else(|| {
                    let names: Vec<&str> = UNIT_SYSTEMS.iter().map(|u| u.0).collect();
                    r.c.err(u.span(), format!("unknown unit system `{}`", u.get_ref()))
                        .help(format!("one of: {}; or G = <value>", names.join(", ")))
                })
        }
    }
}

struct Reader<'a> {
    c: Constants<'a>,
    units: UnitsSpec,
}

fn positive_int(v: &Spanned<i64>, what: &str, c: &Constants<'_>) -> Result<u64, ModelError> {
    u64::try_from(*v.get_ref())
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| c.err(v.span(), format!("{what} must be a positive integer")))
}

impl Reader<'_> {
    /// A scalar; `angle` fields accept any unit literal (`"1.3 deg"`), others only in SI.
    fn plain(&mut self, sv: &Sv, what: &str, angle: bool) -> Result<f64, ModelError> {
        if !angle && !self.units.si {
            if let Some(text) = self.c.unit_literal(sv) {
                return Err(self
                    .c
                    .err(
                        sv.span(),
                        format!(
                            "`{text}`: unit literals convert to SI, but this model's units are {}",
                            self.units.label
                        ),
                    )
                    .help("write the number in the model's units (or units = \"si\"); angles may use deg"));
            }
        }
        self.c.scalar(sv, what)
    }

    fn positive(&mut self, sv: &Sv, what: &str) -> Result<f64, ModelError> {
        let v = self.plain(sv, what, false)?;
        if !(v.is_finite() && v > 0.0) {
            return Err(self
                .c
                .err(sv.span(), format!("{what} must be > 0 (got {v})")));
        }
        Ok(v)
    }

    fn non_negative(&mut self, sv: &Sv, what: &str) -> Result<f64, ModelError> {
        let v = self.plain(sv, what, false)?;
        if !(v.is_finite() && v >= 0.0) {
            return Err(self
                .c
                .err(sv.span(), format!("{what} must be >= 0 (got {v})")));
        }
        Ok(v)
    }

    fn table(
        &mut self,
        raw: &RawFile,
        nb: &RawNbody,
        origin: &str,
        table_span: Range<usize>,
    ) -> Result<NbodySpec, ModelError> {
        let (integrator, integrator_span) = match &nb.integrator {
            None => (IntegratorKind::Ias15, table_span.clone()),
            Some(n) => (
                IntegratorKind::from_name(n.get_ref()).ok_or_else(|| {
                    self.c
                        .err(n.span(), format!("unknown integrator `{}`", n.get_ref()))
                        .help("whfast, ias15 or leapfrog")
                })?,
                n.span(),
            ),
        };
        let dt = match &nb.dt {
            None => None,
            Some(sv) => Some((self.positive(sv, "dt")?, sv.span())),
        };
        let corrector = match &nb.corrector {
            None => 0,
            Some(v) => {
                let k = *v.get_ref();
                if ![0, 3, 5, 7, 11, 17].contains(&k) {
                    return Err(self
                        .c
                        .err(v.span(), format!("no symplectic corrector of order {k}"))
                        .help("0 (none), 3, 5, 7, 11 or 17"));
                }
                if integrator != IntegratorKind::WhFast {
                    return Err(self.c.err(
                        v.span(),
                        "corrector applies to integrator = \"whfast\" only",
                    ));
                }
                k as u32
            }
        };
        let epsilon = match &nb.epsilon {
            None => None,
            Some(sv) => {
                if integrator != IntegratorKind::Ias15 {
                    return Err(self
                        .c
                        .err(sv.span(), "epsilon applies to integrator = \"ias15\" only"));
                }
                Some(self.non_negative(sv, "epsilon")?)
            }
        };
        let tree = match &nb.gravity {
            None => None,
            Some(g) => match g.get_ref().as_str() {
                "direct" => None,
                "tree" => Some(pdyn_gravity::TreeParams::default()),
                other => {
                    return Err(self
                        .c
                        .err(g.span(), format!("unknown gravity `{other}`"))
                        .help("\"direct\" (exact, O(N²)) or \"tree\" (Barnes–Hut, O(N log N))"))
                }
            },
        };
        let tree = match (tree, &nb.theta, &nb.quadrupole) {
            (None, Some(sv), _) => {
                return Err(self
                    .c
                    .err(sv.span(), "theta applies to gravity = \"tree\" only"))
            }
            (None, None, Some(q)) => {
                return Err(self
                    .c
                    .err(q.span(), "quadrupole applies to gravity = \"tree\" only"))
            }
            (None, None, None) => None,
            (Some(mut t), theta, q) => {
                if let Some(sv) = theta {
                    t.theta = self.positive(sv, "theta")?;
                }
                if let Some(q) = q {
                    t.quadrupole = *q.get_ref();
                }
                Some(t)
            }
        };
        if tree.is_some() && integrator == IntegratorKind::WhFast {
            return Err(self
                .c
                .err(
                    integrator_span.clone(),
                    "WHFast with the tree is not supported",
                )
                .help("use integrator = \"leapfrog\" with gravity = \"tree\""));
        }
        let softening = match &nb.softening {
            None => 0.0,
            Some(sv) => self.non_negative(sv, "softening")?,
        };
        let t_end = nb
            .t_end
            .as_ref()
            .map(|sv| self.positive(sv, "t_end"))
            .transpose()?;
        let output_dt = nb
            .output_dt
            .as_ref()
            .map(|sv| self.positive(sv, "output_dt"))
            .transpose()?;
        let points = nb
            .points
            .as_ref()
            .map(|p| {
                let n = positive_int(p, "points", &self.c)?;
                if n < 2 {
                    return Err(self.c.err(p.span(), "points must be at least 2"));
                }
                Ok(n as usize)
            })
            .transpose()?;
        if let (Some(_), Some(p)) = (&nb.output_dt, &nb.points) {
            return Err(self
                .c
                .err(p.span(), "give either points or output_dt, not both"));
        }
        let drift_tolerance = nb
            .drift_tolerance
            .as_ref()
            .map(|sv| self.positive(sv, "drift_tolerance"))
            .transpose()?;
        let collisions = match &nb.collisions {
            None => CollisionMode::Stop,
            Some(n) => match n.get_ref().as_str() {
                "stop" => CollisionMode::Stop,
                "merge" => CollisionMode::Merge,
                other => {
                    return Err(self
                        .c
                        .err(n.span(), format!("unknown collision mode `{other}`"))
                        .help("\"stop\" (an event that ends the run) or \"merge\""))
                }
            },
        };
        let escape_mode = match &nb.escape {
            None => EscapeMode::Stop,
            Some(n) => match n.get_ref().as_str() {
                "stop" => EscapeMode::Stop,
                "remove" => EscapeMode::Remove,
                other => {
                    return Err(self
                        .c
                        .err(n.span(), format!("unknown escape mode `{other}`"))
                        .help("\"stop\" or \"remove\""))
                }
            },
        };
        let escape = match (&nb.escape_radius, &nb.escape) {
            (Some(sv), _) => Some((self.positive(sv, "escape_radius")?, escape_mode)),
            (None, Some(n)) => {
                return Err(self.c.err(n.span(), "escape needs escape_radius"));
            }
            (None, None) => None,
        };
        let mut bodies: Vec<BodySpec> = Vec::new();
        for b in &nb.bodies {
            let body = self.body(b, &bodies, origin)?;
            bodies.push(body);
        }
        let plummer = match &nb.plummer {
            None => None,
            Some(p) => Some(self.plummer(p, origin)?),
        };
        Ok(NbodySpec {
            name: raw.name.clone().unwrap_or_else(|| "N-body model".into()),
            origin: origin.to_string(),
            units: self.units,
            integrator,
            integrator_span,
            dt,
            corrector,
            epsilon,
            tree,
            softening,
            t_end,
            output_dt,
            points,
            drift_tolerance,
            collisions,
            escape,
            center_of_mass: nb.center_of_mass.as_ref().is_none_or(|b| *b.get_ref()),
            trajectory: nb.trajectory.as_ref().map(|b| *b.get_ref()),
            bodies,
            plummer,
            parameters: self.c.parameters(),
            table_span,
        })
    }

    fn plummer(
        &mut self,
        p: &Spanned<RawPlummer>,
        origin: &str,
    ) -> Result<PlummerSpec, ModelError> {
        let raw = p.get_ref();
        let n_sv = raw.n.as_ref().ok_or_else(|| {
            self.c
                .err(p.span(), "plummer needs n, the number of stars")
                .help("plummer = { n = 10000, seed = 1 }")
        })?;
        let n = self.positive(n_sv, "n")?;
        if n.fract() != 0.0 || n > super::build::MAX_BODIES as f64 {
            return Err(self.c.err(
                n_sv.span(),
                format!(
                    "n must be a whole number of stars up to {} (got {n})",
                    super::build::MAX_BODIES
                ),
            ));
        }
        let seed = raw
            .seed
            .as_ref()
            .map(|s| {
                u64::try_from(*s.get_ref()).map_err(|_| self.c.err(s.span(), "seed must be >= 0"))
            })
            .transpose()?
            .unwrap_or(1);
        let mass = raw
            .mass
            .as_ref()
            .map(|sv| self.positive(sv, "mass"))
            .transpose()?;
        let scale = raw
            .scale
            .as_ref()
            .map(|sv| self.positive(sv, "scale"))
            .transpose()?;
        Ok(PlummerSpec {
            n: n as usize,
            seed,
            mass: mass.unwrap_or(1.0),
            scale: scale.unwrap_or(1.0),
            rescale: raw.rescale.as_ref().is_none_or(|r| *r.get_ref()),
            origin: Origin {
                file: origin.to_string(),
                span: p.span(),
            },
        })
    }

    fn body(
        &mut self,
        b: &Spanned<RawBody>,
        before: &[BodySpec],
        origin: &str,
    ) -> Result<BodySpec, ModelError> {
        let raw = b.get_ref();
        let span = b.span();
        let index = before.len();
        let name = match &raw.name {
            Some(n) => {
                if before.iter().any(|o| &o.name == n.get_ref()) {
                    return Err(self
                        .c
                        .err(n.span(), format!("two bodies are named `{}`", n.get_ref()))
                        .help("names identify primaries and output columns: make them unique"));
                }
                n.get_ref().clone()
            }
            None => format!("body{index}"),
        };
        let mass_sv = raw.mass.as_ref().ok_or_else(|| {
            self.c
                .err(span.clone(), format!("body `{name}` has no mass"))
                .help("mass = <value> (> 0)")
        })?;
        let mass = self.positive(mass_sv, "mass")?;
        let radius = raw
            .radius
            .as_ref()
            .map(|sv| self.non_negative(sv, "radius"))
            .transpose()?
            .unwrap_or(0.0);
        let elements = [
            &raw.a, &raw.e, &raw.inc, &raw.Omega, &raw.omega, &raw.M, &raw.f,
        ];
        let has_elements = elements.iter().any(|x| x.is_some()) || raw.primary.is_some();
        let state = match (&raw.position, &raw.velocity, has_elements) {
            (Some(p), Some(v), false) => InitialState::Cartesian {
                position: self.c.vector(p, "position")?,
                velocity: self.c.vector(v, "velocity")?,
            },
            (None, None, true) => self.orbit(raw, &span, &name, before)?,
            (Some(_), Some(_), true) | (Some(_), None, true) | (None, Some(_), true) => {
                return Err(self
                    .c
                    .err(span, format!("body `{name}` has both a Cartesian state and orbital elements"))
                    .help("give position and velocity, or a, e, ... relative to a primary"))
            }
            (Some(_), None, false) | (None, Some(_), false) => {
                return Err(self
                    .c
                    .err(span, format!("body `{name}` needs both position and velocity"))
                    .help("velocity = [0, 0, 0] for a body at rest"))
            }
            (None, None, false) => {
                return Err(self
                    .c
                    .err(span, format!("body `{name}` has no initial state"))
                    .help("give position and velocity, or orbital elements a, e, inc, Omega, omega and M or f"))
            }
        };
        Ok(BodySpec {
            name,
            mass,
            radius,
            state,
            origin: Origin {
                file: origin.to_string(),
                span: b.span(),
            },
        })
    }

    fn orbit(
        &mut self,
        raw: &RawBody,
        span: &Range<usize>,
        name: &str,
        before: &[BodySpec],
    ) -> Result<InitialState, ModelError> {
        let a_sv = raw.a.as_ref().ok_or_else(|| {
            self.c.err(
                span.clone(),
                format!("body `{name}`: orbital elements need a (semi-major axis)"),
            )
        })?;
        let a = self.plain(a_sv, "a", false)?;
        let e = match &raw.e {
            None => 0.0,
            Some(sv) => self.plain(sv, "e", false)?,
        };
        let e_span = raw.e.as_ref().map_or(span.clone(), |sv| sv.span());
        check_elements(a, e).map_err(|msg| {
            let at = if msg.blames_eccentricity() {
                e_span.clone()
            } else {
                a_sv.span()
            };
            self.c.err(at, format!("body `{name}`: {msg}"))
        })?;
        let mut angle = |sv: &Option<Sv>, what: &str| -> Result<f64, ModelError> {
            match sv {
                None => Ok(0.0),
                Some(sv) => self.plain(sv, what, true),
            }
        };
        let inc = angle(&raw.inc, "inc")?;
        let big_omega = angle(&raw.Omega, "Omega")?;
        let omega = angle(&raw.omega, "omega")?;
        let anomaly = match (&raw.M, &raw.f) {
            (Some(_), Some(f)) => {
                return Err(self.c.err(
                    f.span(),
                    "give the mean anomaly M or the true anomaly f, not both",
                ))
            }
            (Some(m), None) => pdyn_gravity::Anomaly::Mean(self.plain(m, "M", true)?),
            (None, Some(f)) => pdyn_gravity::Anomaly::True(self.plain(f, "f", true)?),
            (None, None) => pdyn_gravity::Anomaly::True(0.0),
        };
        if let pdyn_gravity::Anomaly::True(f) = anomaly {
            if e > 1.0 && (1.0 + e * libm::cos(f)) <= 0.0 {
                let at = raw.f.as_ref().map_or(span.clone(), |sv| sv.span());
                return Err(self.c.err(
                    at,
                    format!("body `{name}`: true anomaly f = {f} is beyond the asymptotes of a hyperbola with e = {e}"),
                ));
            }
        }
        let primary = match &raw.primary {
            None => {
                if before.is_empty() {
                    return Err(self
                        .c
                        .err(
                            span.clone(),
                            format!(
                                "body `{name}`: orbital elements need a body before it to orbit"
                            ),
                        )
                        .help("give the first body a position and velocity"));
                }
                None
            }
            Some(p) => match before.iter().position(|b| &b.name == p.get_ref()) {
                Some(j) => Some(j),
                None => {
                    let names: Vec<&str> = before.iter().map(|b| b.name.as_str()).collect();
                    let mut err = self
                        .c
                        .err(p.span(), format!("unknown primary `{}`", p.get_ref()));
                    err = match pdyn_expr::error::suggest(p.get_ref(), names.iter().copied()) {
                        Some(s) => err.help(format!(
                            "did you mean `{s}`? (a primary must be declared before the body)"
                        )),
                        None if names.is_empty() => {
                            err.help("a primary must be a body declared before this one")
                        }
                        None => err.help(format!(
                            "bodies declared before this one: {}",
                            names.join(", ")
                        )),
                    };
                    return Err(err);
                }
            },
        };
        Ok(InitialState::Orbit {
            elements: pdyn_gravity::Elements {
                a,
                e,
                inc,
                Omega: big_omega,
                omega,
                anomaly,
            },
            primary,
        })
    }
}

/// Why `a` and `e` do not describe a Kepler orbit.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum ElementsError {
    /// `e` negative or not finite.
    Eccentricity(f64),
    /// `e = 1`.
    Parabola,
    /// `e < 1` with `a ≤ 0`.
    BoundNeedsPositiveAxis {
        /// Semi-major axis.
        a: f64,
        /// Eccentricity.
        e: f64,
    },
    /// `e > 1` with `a ≥ 0`.
    HyperbolaNeedsNegativeAxis {
        /// Semi-major axis.
        a: f64,
        /// Eccentricity.
        e: f64,
    },
}

impl ElementsError {
    /// Whether the eccentricity is at fault (the error points at `e`; else at `a`).
    pub fn blames_eccentricity(&self) -> bool {
        matches!(
            self,
            ElementsError::Eccentricity(_) | ElementsError::Parabola
        )
    }
}

impl std::fmt::Display for ElementsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            ElementsError::Eccentricity(e) => write!(f, "e = {e}: the eccentricity must be >= 0"),
            ElementsError::Parabola => {
                f.write_str("e = 1: a parabola has no semi-major axis; give a Cartesian state")
            }
            ElementsError::BoundNeedsPositiveAxis { a, e } => {
                write!(
                    f,
                    "a = {a} <= 0 with e = {e} < 1: a bound orbit needs a > 0"
                )
            }
            ElementsError::HyperbolaNeedsNegativeAxis { a, e } => write!(
                f,
                "a = {a} >= 0 with e = {e} > 1: a hyperbola has a < 0 (REBOUND's convention)"
            ),
        }
    }
}

impl std::error::Error for ElementsError {}

/// The conditions for `a` and `e` to describe a Kepler orbit (`e` checked first).
pub fn check_elements(a: f64, e: f64) -> Result<(), ElementsError> {
    if !(e.is_finite() && e >= 0.0) {
        return Err(ElementsError::Eccentricity(e));
    }
    if e == 1.0 {
        return Err(ElementsError::Parabola);
    }
    if e < 1.0 && !(a.is_finite() && a > 0.0) {
        return Err(ElementsError::BoundNeedsPositiveAxis { a, e });
    }
    if e > 1.0 && !(a.is_finite() && a < 0.0) {
        return Err(ElementsError::HyperbolaNeedsNegativeAxis { a, e });
    }
    Ok(())
}
