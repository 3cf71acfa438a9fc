//! Model files: a system of particles described the way the chapter does — parameters,
//! coordinates, position vectors, masses, forces, reactions, constraints — read from TOML into
//! symbolic form. See `docs/model-format.md` for the format.
//!
//! Loading resolves every name (with "did you mean" suggestions), checks shapes (vectors where
//! vectors belong), evaluates parameter values (with unit literals such as `"25 mph"`), and
//! turns each force declaration into loads on particles or massless frames. Every error carries
//! the file, line and column of the offending text.

pub mod constants;
mod forces;
pub(crate) mod raw;
pub mod spec;

use crate::units::{looks_like_quantity, parse_quantity};
use pdyn_expr::error::{render_diagnostic, suggest};
use pdyn_expr::lower::{lower, Binding, Scope};
use pdyn_expr::{ExprError, Id, Number, Pool, Program, SymId, Value};
use raw::{RawModel, Sv};
use rustc_hash::FxHashMap;
use std::ops::Range;

/// A located problem in a model file.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ModelError {
    /// File name (or `<input>`).
    pub origin: String,
    /// Byte range in the file.
    pub span: Range<usize>,
    /// What is wrong.
    pub message: String,
    /// What would be valid.
    pub help: Option<String>,
}

impl ModelError {
    /// An error at `span`.
    pub fn new(origin: &str, span: Range<usize>, message: impl Into<String>) -> ModelError {
        ModelError {
            origin: origin.to_string(),
            span,
            message: message.into(),
            help: None,
        }
    }
    /// Adds a help line.
    pub fn help(mut self, h: impl Into<String>) -> ModelError {
        self.help = Some(h.into());
        self
    }
    /// `file:line:col: error: message`, the line, a caret, and the help.
    pub fn render(&self, source: &str) -> String {
        render_diagnostic(
            source,
            &self.origin,
            &self.span,
            &self.message,
            self.help.as_deref(),
        )
    }
}

impl std::fmt::Display for ModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.origin, self.message)
    }
}

impl std::error::Error for ModelError {}

/// A named constant with a numeric value (its symbol stays symbolic in derived equations).
#[derive(Clone, Debug)]
pub struct Parameter {
    /// Name.
    pub name: String,
    /// The symbol's expression.
    pub id: Id,
    /// Value in SI units.
    pub value: f64,
}

/// How a coordinate evolves.
#[derive(Clone, Debug)]
pub enum CoordinateKind {
    /// Unknown function of time, found by solving the equations of motion.
    Free {
        /// Value at t = 0.
        initial: f64,
        /// Rate at t = 0.
        rate: f64,
    },
    /// A given function of time.
    Prescribed {
        /// The function of `t`.
        expr: Id,
    },
}

/// A generalized coordinate.
#[derive(Clone, Debug)]
pub struct Coordinate {
    /// Name.
    pub name: String,
    /// Its symbol (as a coordinate: `Coord(sym, k)` is its k-th derivative).
    pub sym: SymId,
    /// Free or prescribed.
    pub kind: CoordinateKind,
}

/// A particle.
#[derive(Clone, Debug)]
pub struct Particle {
    /// Name.
    pub name: String,
    /// Mass expression (positive).
    pub mass: Id,
    /// Position vector in the inertial frame.
    pub position: [Id; 3],
}

/// A massless frame carrying one particle: ΣF = m a for the pair and ΣM = 0 about the particle.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Name.
    pub name: String,
    /// Index of the particle it carries.
    pub particle: usize,
}

/// Where a load acts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// On a particle.
    Particle(usize),
    /// On a massless frame, at a point.
    Frame {
        /// Index of the frame.
        frame: usize,
        /// Point of application.
        at: [Id; 3],
    },
}

/// One force acting on one particle or frame.
#[derive(Clone, Debug)]
pub struct Load {
    /// Human-readable origin, e.g. `spring (floor1, ground) on floor1`.
    pub label: String,
    /// Where it acts.
    pub target: Target,
    /// The force vector.
    pub force: [Id; 3],
}

/// An unknown reaction magnitude (or vector component).
#[derive(Clone, Debug)]
pub struct Reaction {
    /// Name, e.g. `N`, `T`, `R_x`.
    pub name: String,
    /// Its symbol's expression.
    pub id: Id,
}

/// An extra equation among coordinates, enforced at acceleration level.
#[derive(Clone, Debug)]
pub struct Constraint {
    /// Name or the equation's text.
    pub label: String,
    /// `f(q, t)` meaning `f = 0`.
    pub equation: Id,
}

/// A quantity to solve for (thrust, bank angle, ...), with a search range if it enters
/// nonlinearly.
#[derive(Clone, Debug)]
pub struct UnknownQuantity {
    /// Name.
    pub name: String,
    /// Its symbol's expression.
    pub id: Id,
    /// Search interval.
    pub range: Option<(f64, f64)>,
}

/// A potential energy term of a conservative force, for energy monitors.
#[derive(Clone, Debug)]
pub struct PotentialTerm {
    /// Which force.
    pub label: String,
    /// Potential energy expression.
    pub energy: Id,
}

/// A loaded model.
#[derive(Clone, Debug)]
pub struct Model {
    /// Title.
    pub name: String,
    /// File name used in messages.
    pub origin: String,
    /// The file's text.
    pub source: String,
    /// All expressions live here.
    pub pool: Pool,
    /// Parameters, in file order.
    pub parameters: Vec<Parameter>,
    /// Coordinates, in file order.
    pub coordinates: Vec<Coordinate>,
    /// Named definitions, in file order.
    pub definitions: Vec<(String, Value)>,
    /// Named points (fixed or prescribed positions).
    pub points: Vec<(String, [Id; 3])>,
    /// Particles, in file order.
    pub particles: Vec<Particle>,
    /// Massless frames.
    pub frames: Vec<Frame>,
    /// Every force, split into loads.
    pub loads: Vec<Load>,
    /// Unknown reaction magnitudes.
    pub reactions: Vec<Reaction>,
    /// Constraint equations.
    pub constraints: Vec<Constraint>,
    /// Potential energies of the conservative forces.
    pub potentials: Vec<PotentialTerm>,
    /// True when every force has a potential or is a reaction (energy is then conserved
    /// unless something is prescribed as a function of time).
    pub conservative: bool,
    /// `[simulate]`, `[[events]]`, `[monitors]`, `[sweep]`.
    pub run: spec::RunSpec,
    /// Quantities to solve for in `pdyn forces` (`[unknowns]`).
    pub unknowns: Vec<UnknownQuantity>,
    /// Accelerations given for free coordinates (`acceleration = ...`): a state with known
    /// accelerations at an instant.
    pub known_accelerations: Vec<(usize, Id)>,
    /// Design criteria (`[[checks]]`).
    pub checks: Vec<spec::CheckSpec>,
    /// Names of the unknown (sticking) friction forces.
    pub friction_forces: Vec<String>,
    /// `(coordinate index, initial value, initial rate)` as expressions of the parameters, so
    /// that a sweep over a parameter recomputes the initial conditions that depend on it.
    pub initial_exprs: Vec<(usize, Id, Id)>,
}

/// Name resolution for expressions in a model file.
#[derive(Default)]
pub(crate) struct ModelScope {
    names: FxHashMap<String, (Binding, Range<usize>, &'static str)>,
    order: Vec<String>,
    local: FxHashMap<String, Binding>,
}

impl Scope for ModelScope {
    fn resolve(&mut self, _pool: &mut Pool, name: &str) -> Option<Binding> {
        if let Some((b, _, _)) = self.names.get(name) {
            return Some(*b);
        }
        self.local.get(name).copied()
    }
    fn names(&self) -> Vec<String> {
        let mut v = self.order.clone();
        v.extend(self.local.keys().cloned());
        v
    }
}

const RESERVED: [&str; 2] = ["t", "pi"];

pub(crate) struct Loader<'a> {
    pub origin: &'a str,
    pub source: &'a str,
    pub pool: Pool,
    pub scope: ModelScope,
    pub params: Vec<Parameter>,
}

impl Loader<'_> {
    pub fn err(&self, span: Range<usize>, msg: impl Into<String>) -> ModelError {
        ModelError::new(self.origin, span, msg)
    }

    pub(crate) fn declare(
        &mut self,
        name: &str,
        span: Range<usize>,
        what: &'static str,
        b: Binding,
    ) -> Result<(), ModelError> {
        if let Some((_, prev, kind)) = self.scope.names.get(name) {
            let (line, _) = pdyn_expr::error::line_col(self.source, prev.start);
            return Err(self
                .err(span, format!("duplicate name `{name}`: already a {kind} (line {line})"))
                .help("every parameter, coordinate, definition, point, particle and reaction needs its own name"));
        }
        let reserved = (RESERVED.contains(&name) && what != "reaction")
            || pdyn_expr::Func::from_name(name).is_some()
            || ["sqrt", "dot", "cross", "norm", "unit"].contains(&name);
        if reserved || !is_identifier(name) {
            return Err(self
                .err(span, format!("`{name}` cannot be used as a {what} name"))
                .help("names are letters, digits and `_`, not starting with a digit, and not t, pi or a function name"));
        }
        self.scope.names.insert(name.to_string(), (b, span, what));
        self.scope.order.push(name.to_string());
        Ok(())
    }

    /// Text of an expression-valued field and the byte offset of that text in the file.
    pub fn expr_text(&self, sv: &Sv) -> Result<(String, usize), ModelError> {
        let span = sv.span();
        match sv.get_ref() {
            toml::Value::String(s) => {
                let raw = &self.source[span.start..];
                let quote = if raw.starts_with("\"\"\"") || raw.starts_with("'''") {
                    3
                } else {
                    1
                };
                Ok((s.clone(), span.start + quote))
            }
            toml::Value::Integer(_) | toml::Value::Float(_) => {
                let text = self.source[span.clone()].replace('_', "");
                let text = if pdyn_expr::lower::literal(&text).is_some() {
                    text
                } else {
                    match sv.get_ref() {
                        toml::Value::Float(f) => format!("{f:e}"),
                        other => other.to_string(),
                    }
                };
                Ok((text, span.start))
            }
            other => Err(self
                .err(span, format!("expected a number or an expression in quotes, found a {}", other.type_str()))
                .help("write numbers plainly (9.81) and expressions in quotes (\"m*g\", \"[x, y, 0]\", \"25 mph\")")),
        }
    }

    pub(crate) fn located(&self, e: ExprError, offset: usize) -> ModelError {
        let e = e.offset(offset);
        ModelError {
            origin: self.origin.to_string(),
            span: e.span,
            message: e.message,
            help: e.help,
        }
    }

    /// Parses an expression-valued field.
    pub fn value(&mut self, sv: &Sv) -> Result<Value, ModelError> {
        let (text, off) = self.expr_text(sv)?;
        if looks_like_quantity(&text) {
            let x = parse_quantity(&text).map_err(|e| {
                let mut me = self.err(e.span.start + off..e.span.end + off, e.message);
                me.help = e.help;
                me
            })?;
            return Ok(Value::Scalar(self.pool.num(Number::Float(x))));
        }
        let ast = pdyn_expr::syntax::parse(&text).map_err(|e| self.located(e, off))?;
        lower(&mut self.pool, &ast, &mut self.scope).map_err(|e| self.located(e, off))
    }

    /// Parses a field that must be a scalar.
    pub fn scalar(&mut self, sv: &Sv, what: &str) -> Result<Id, ModelError> {
        match self.value(sv)? {
            Value::Scalar(s) => Ok(s),
            Value::Vector(_) => Err(self.err(
                sv.span(),
                format!("{what} must be a scalar, but this is a vector"),
            )),
        }
    }

    /// Parses a field that must be a vector.
    pub fn vector(&mut self, sv: &Sv, what: &str) -> Result<[Id; 3], ModelError> {
        match self.value(sv)? {
            Value::Vector(v) => Ok(v),
            Value::Scalar(_) => Err(self
                .err(
                    sv.span(),
                    format!("{what} must be a vector, but this is a scalar"),
                )
                .help("write vectors as \"[x, y, z]\" (or \"[x, y]\" in the plane)")),
        }
    }

    /// Evaluates an expression that may only involve parameters.
    pub fn constant(&mut self, e: Id, span: Range<usize>, what: &str) -> Result<f64, ModelError> {
        let inputs: Vec<Id> = self.params.iter().map(|p| p.id).collect();
        let values: Vec<f64> = self.params.iter().map(|p| p.value).collect();
        let prog = Program::compile(&mut self.pool, &inputs, &[e]).map_err(|err| {
            self.err(span.clone(), format!("{what} must be a number here: {err}"))
                .help("only parameters (and numbers, pi, units) may appear here")
        })?;
        let mut ws = prog.workspace();
        let mut out = [0.0];
        prog.eval(&values, &mut ws, &mut out);
        if !out[0].is_finite() {
            return Err(self.err(span, format!("{what} evaluates to {}", out[0])));
        }
        Ok(out[0])
    }
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_alphabetic() || c == '_')
        && chars.all(|c| c.is_alphanumeric() || c == '_')
}

/// Reads a model from TOML text. `origin` names it in error messages.
pub fn load(source: &str, origin: &str) -> Result<Model, ModelError> {
    let raw: RawModel = toml::from_str(source).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        ModelError::new(origin, span, e.message().trim().to_string())
            .help("see docs/model-format.md for the tables a model file may contain")
    })?;
    let mut ld = Loader {
        origin,
        source,
        pool: Pool::new(),
        scope: ModelScope::default(),
        params: Vec::new(),
    };

    for (name, sv) in &raw.parameters {
        let id = ld.scalar(sv, "a parameter")?;
        let value = ld.constant(id, sv.span(), "a parameter")?;
        let sym = ld.pool.symbol(name.get_ref(), value > 0.0);
        let sid = ld.pool.sym(sym);
        ld.declare(
            name.get_ref(),
            name.span(),
            "parameter",
            Binding::Value(Value::Scalar(sid)),
        )?;
        ld.params.push(Parameter {
            name: name.get_ref().clone(),
            id: sid,
            value,
        });
    }

    // Unknown quantities of `pdyn forces` are symbols without values.
    let mut unknowns = Vec::new();
    for (name, su) in &raw.unknowns {
        let s = ld.pool.symbol(name.get_ref(), false);
        let id = ld.pool.sym(s);
        ld.declare(
            name.get_ref(),
            name.span(),
            "unknown",
            Binding::Value(Value::Scalar(id)),
        )?;
        let range = match &su.get_ref().range {
            None => None,
            Some(r) => {
                if r.get_ref().len() != 2 {
                    return Err(ld.err(r.span(), "`range` is [low, high]"));
                }
                let lo = ld.scalar(&r.get_ref()[0], "a range bound")?;
                let lo = ld.constant(lo, r.span(), "a range bound")?;
                let hi = ld.scalar(&r.get_ref()[1], "a range bound")?;
                let hi = ld.constant(hi, r.span(), "a range bound")?;
                if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
                    return Err(ld.err(r.span(), format!("empty range [{lo}, {hi}]")));
                }
                Some((lo, hi))
            }
        };
        unknowns.push(UnknownQuantity {
            name: name.get_ref().clone(),
            id,
            range,
        });
    }

    let mut coordinates = Vec::new();
    let mut initial_exprs = Vec::new();
    let mut known_accelerations = Vec::new();
    for (name, sv) in &raw.coordinates {
        let n = name.get_ref();
        let kind = match sv.get_ref() {
            toml::Value::String(_) => {
                let expr = ld.scalar(sv, "a prescribed coordinate")?;
                CoordinateKind::Prescribed { expr }
            }
            toml::Value::Table(t) => {
                let get = |k: &str| t.get(k);
                for key in t.keys() {
                    if !["initial", "rate", "prescribed", "acceleration"].contains(&key.as_str()) {
                        return Err(ld
                            .err(sv.span(), format!("unknown key `{key}` in coordinate `{n}`"))
                            .help("a coordinate is { initial = ..., rate = ... } or a prescribed \"f(t)\""));
                    }
                }
                if let Some(p) = get("prescribed") {
                    let text = match p {
                        toml::Value::String(s) => s.clone(),
                        other => other.to_string(),
                    };
                    let ast = pdyn_expr::syntax::parse(&text)
                        .map_err(|e| ld.err(sv.span(), format!("in `prescribed`: {}", e.message)))?;
                    let v = lower(&mut ld.pool, &ast, &mut ld.scope)
                        .map_err(|e| ld.err(sv.span(), format!("in `prescribed`: {}", e.message)))?;
                    match v {
                        Value::Scalar(expr) => CoordinateKind::Prescribed { expr },
                        Value::Vector(_) => return Err(ld.err(sv.span(), "a coordinate is a scalar")),
                    }
                } else {
                    let num = |ld: &mut Loader, key: &str| -> Result<(f64, Id), ModelError> {
                        let Some(v) = t.get(key) else {
                            let hint = if key == "rate" {
                                format!("give `{n}`'s initial rate d{n}/dt, e.g. rate = 0 if it starts at rest")
                            } else {
                                format!("give `{n}`'s value at t = 0, e.g. initial = 0")
                            };
                            return Err(ld
                                .err(sv.span(), format!("coordinate `{n}` has no `{key}` (initial condition)"))
                                .help(hint));
                        };
                        let text = match v {
                            toml::Value::String(s) => s.clone(),
                            toml::Value::Integer(i) => i.to_string(),
                            toml::Value::Float(f) => format!("{f:e}"),
                            other => {
                                return Err(ld.err(sv.span(), format!("`{key}` must be a number, found {}", other.type_str())))
                            }
                        };
                        let x = if looks_like_quantity(&text) {
                            let q = parse_quantity(&text).map_err(|e| ld.err(sv.span(), format!("in `{key}`: {}", e.message)))?;
                            (q, ld.pool.num(Number::Float(q)))
                        } else {
                            let ast = pdyn_expr::syntax::parse(&text)
                                .map_err(|e| ld.err(sv.span(), format!("in `{key}`: {}", e.message)))?;
                            let v = lower(&mut ld.pool, &ast, &mut ld.scope)
                                .map_err(|e| ld.err(sv.span(), format!("in `{key}` of `{n}`: {}", e.message)).help(e.help.unwrap_or_default()))?;
                            let Value::Scalar(id) = v else {
                                return Err(ld.err(sv.span(), format!("`{key}` must be a scalar")));
                            };
                            (ld.constant(id, sv.span(), &format!("`{key}` of `{n}`"))?, id)
                        };
                        Ok(x)
                    };
                    let (initial, initial_expr) = num(&mut ld, "initial")?;
                    let (rate, rate_expr) = num(&mut ld, "rate")?;
                    initial_exprs.push((coordinates.len(), initial_expr, rate_expr));
                    if let Some(acc) = t.get("acceleration") {
                        let text = match acc {
                            toml::Value::String(s) => s.clone(),
                            toml::Value::Integer(i) => i.to_string(),
                            toml::Value::Float(f) => format!("{f:e}"),
                            other => return Err(ld.err(sv.span(), format!("`acceleration` must be a number or an expression, found {}", other.type_str()))),
                        };
                        let ast = pdyn_expr::syntax::parse(&text)
                            .map_err(|e| ld.err(sv.span(), format!("in `acceleration`: {}", e.message)))?;
                        let v = lower(&mut ld.pool, &ast, &mut ld.scope)
                            .map_err(|e| ld.err(sv.span(), format!("in `acceleration` of `{n}`: {}", e.message)).help(e.help.unwrap_or_default()))?;
                        let Value::Scalar(id) = v else {
                            return Err(ld.err(sv.span(), "`acceleration` must be a scalar"));
                        };
                        known_accelerations.push((coordinates.len(), id));
                    }
                    CoordinateKind::Free { initial, rate }
                }
            }
            other => {
                return Err(ld
                    .err(sv.span(), format!("coordinate `{n}` must be a table or a string, found a {}", other.type_str()))
                    .help("write `x = { initial = 1.0, rate = 0.0 }` for an unknown coordinate, or `theta = \"omega*t\"` for a prescribed one"))
            }
        };
        let sym = ld.pool.symbol(n, false);
        let binding = match &kind {
            CoordinateKind::Free { .. } => Binding::Coordinate(sym),
            CoordinateKind::Prescribed { expr } => Binding::Value(Value::Scalar(*expr)),
        };
        ld.declare(n, name.span(), "coordinate", binding)?;
        coordinates.push(Coordinate {
            name: n.clone(),
            sym,
            kind,
        });
    }

    let mut definitions = Vec::new();
    for (name, sv) in &raw.definitions {
        let v = ld.value(sv)?;
        ld.declare(name.get_ref(), name.span(), "definition", Binding::Value(v))?;
        definitions.push((name.get_ref().clone(), v));
    }

    let mut points = Vec::new();
    for (name, sv) in &raw.points {
        let v = ld.vector(sv, &format!("point `{}`", name.get_ref()))?;
        ld.declare(
            name.get_ref(),
            name.span(),
            "point",
            Binding::Value(Value::Vector(v)),
        )?;
        points.push((name.get_ref().clone(), v));
    }

    let mut particles = Vec::new();
    for (name, sp) in &raw.particles {
        let n = name.get_ref();
        let p = sp.get_ref();
        let Some(msv) = &p.mass else {
            return Err(ld
                .err(name.span(), format!("particle `{n}` has no mass"))
                .help("add mass = ... (a number or a parameter)"));
        };
        let Some(psv) = &p.position else {
            return Err(ld
                .err(name.span(), format!("particle `{n}` has no position"))
                .help("add position = \"[x, y, z]\" in terms of the coordinates"));
        };
        let mass = ld.scalar(msv, "a mass")?;
        let mv = ld.constant(mass, msv.span(), "a mass")?;
        if mv <= 0.0 {
            return Err(ld
                .err(
                    msv.span(),
                    format!("the mass of `{n}` must be positive, it is {mv}"),
                )
                .help("a massless body is a frame: declare it under [frames]"));
        }
        let position = ld.vector(psv, &format!("the position of `{n}`"))?;
        let vel = position.map(|c| ld.pool.dt(c));
        for (prefix, v) in [("r_", position), ("v_", vel)] {
            let key = format!("{prefix}{n}");
            if !ld.scope.names.contains_key(&key) {
                ld.scope.local.insert(key, Binding::Value(Value::Vector(v)));
            }
        }
        ld.declare(
            n,
            name.span(),
            "particle",
            Binding::Value(Value::Vector(position)),
        )?;
        particles.push(Particle {
            name: n.clone(),
            mass,
            position,
        });
    }
    if particles.is_empty() {
        return Err(ld
            .err(0..0, "the model has no particles")
            .help("add a [particles.NAME] table with mass and position"));
    }

    let mut frames = Vec::new();
    for (name, sf) in &raw.frames {
        let Some(pn) = &sf.get_ref().particle else {
            return Err(ld
                .err(
                    name.span(),
                    format!("frame `{}` names no particle", name.get_ref()),
                )
                .help("add particle = \"NAME\""));
        };
        let Some(pi) = particles.iter().position(|p| &p.name == pn.get_ref()) else {
            let s = suggest(pn.get_ref(), particles.iter().map(|p| p.name.as_str()));
            let mut e = ld.err(pn.span(), format!("unknown particle `{}`", pn.get_ref()));
            if let Some(s) = s {
                e = e.help(format!("did you mean `{s}`?"));
            }
            return Err(e);
        };
        frames.push(Frame {
            name: name.get_ref().clone(),
            particle: pi,
        });
    }

    let gravity = match &raw.gravity {
        Some(g) => Some(ld.vector(g, "gravity")?),
        None => None,
    };

    let mut fb = forces::ForceBuilder::new(&particles, &frames, &points);
    if let Some(g) = gravity {
        fb.gravity(&mut ld, g);
    }
    for f in &raw.forces {
        fb.force(&mut ld, f)?;
    }
    let forces::Built {
        friction_forces,
        loads,
        reactions,
        potentials,
        conservative,
    } = fb.finish();

    for r in &reactions {
        if !ld.scope.names.contains_key(&r.name) {
            ld.scope.order.push(r.name.clone());
            ld.scope.names.insert(
                r.name.clone(),
                (Binding::Value(Value::Scalar(r.id)), 0..0, "reaction"),
            );
        }
    }

    let mut constraints = Vec::new();
    for sc in &raw.constraints {
        let c = sc.get_ref();
        let Some(eq) = &c.equation else {
            return Err(ld
                .err(sc.span(), "a constraint has no `equation`")
                .help("write equation = \"yA + yB = 2*h\" (a relation among coordinates)"));
        };
        let (text, off) = ld.expr_text(eq)?;
        let v = ld
            .pool
            .parse_equation_in(&text, &mut ld.scope)
            .map_err(|e| ld.located(e, off))?;
        let Value::Scalar(e) = v else {
            return Err(ld.err(eq.span(), "a constraint equation must be scalar"));
        };
        let label = c
            .name
            .as_ref()
            .map_or(text.clone(), |n| n.get_ref().clone());
        constraints.push(Constraint { label, equation: e });
    }

    let params = ld.params.clone();
    let run = spec::read(&mut ld, &raw, &params)?;

    let checks = spec::read_checks(&mut ld, &raw)?;

    Ok(Model {
        run,
        initial_exprs,
        unknowns,
        known_accelerations,
        checks,
        friction_forces,
        name: raw.name.clone().unwrap_or_else(|| origin.to_string()),
        origin: origin.to_string(),
        source: source.to_string(),
        pool: ld.pool,
        parameters: ld.params,
        coordinates,
        definitions,
        points,
        particles,
        frames,
        loads,
        reactions,
        constraints,
        potentials,
        conservative,
    })
}

/// Reads a model file.
pub fn load_file(path: &std::path::Path) -> Result<Model, ModelError> {
    let origin = path.display().to_string();
    let source = std::fs::read_to_string(path)
        .map_err(|e| ModelError::new(&origin, 0..0, format!("cannot read the model file: {e}")))?;
    load(&source, &origin)
}
