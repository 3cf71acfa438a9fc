//! One method per table of a model file, in the order [`super::load`] reads them: each
//! declares the names it introduces (so later tables can use them) and returns what it built.

use super::deferred::Decision;
use super::families::{End, Table};
use super::forces;
use super::loader::Loader;
use super::raw::{RawModel, Sv};
use super::{
    Constraint, Coordinate, CoordinateKind, Frame, ModelError, Parameter, Particle, UnknownQuantity,
};
use crate::dimensions::{Form, Source};
use crate::units::{looks_like_quantity, parse_quantity_with_dimension};
use pdyn_expr::error::suggest;
use pdyn_expr::lower::{lower, Binding};
use pdyn_expr::{Dimension, Id, Number, Value};

/// What `[coordinates]` declares.
pub(super) struct Coordinates {
    pub coordinates: Vec<Coordinate>,
    /// `(coordinate index, initial value, initial rate)` as expressions of the parameters.
    pub initial_exprs: Vec<(usize, Id, Id)>,
    /// `acceleration = ...` given for a free coordinate.
    pub known_accelerations: Vec<(usize, Id)>,
}

impl Loader<'_> {
    /// `[parameters]`: named constants. A parameter written in terms of earlier ones keeps
    /// that definition, so that it follows them when they change (`--set`, sweeps).
    pub(super) fn read_parameters(&mut self, raw: &RawModel) -> Result<(), ModelError> {
        for (name, sv) in &raw.parameters {
            let id = self.scalar(sv, "a parameter")?;
            let value = self.constant(id, sv.span(), "a parameter")?;
            let definition = self.depends_on_parameters(id).then_some(id);
            let form = self.last_for(name.get_ref());
            self.dims.bind(name.get_ref(), form);
            let sym = self.pool.symbol(name.get_ref(), value > 0.0);
            let sid = self.pool.sym(sym);
            self.declare(
                name.get_ref(),
                name.span(),
                "parameter",
                Binding::Value(Value::Scalar(sid)),
            )?;
            self.params.push(Parameter {
                name: name.get_ref().clone(),
                id: sid,
                value,
                definition,
            });
        }
        Ok(())
    }

    /// Whether `e` mentions one of the parameters declared so far.
    fn depends_on_parameters(&self, e: Id) -> bool {
        self.params.iter().any(|p| self.pool.contains(e, p.id))
    }

    /// `[unknowns]`: the quantities of `pdyn forces`, symbols without values.
    pub(super) fn read_unknowns(
        &mut self,
        raw: &RawModel,
    ) -> Result<Vec<UnknownQuantity>, ModelError> {
        let mut unknowns = Vec::new();
        for (name, su) in &raw.unknowns {
            let s = self.pool.symbol(name.get_ref(), false);
            let id = self.pool.sym(s);
            self.dims.bind_unknown(name.get_ref());
            self.declare(
                name.get_ref(),
                name.span(),
                "unknown",
                Binding::Value(Value::Scalar(id)),
            )?;
            let range = match &su.get_ref().range {
                None => None,
                Some(r) => {
                    if r.get_ref().len() != 2 {
                        return Err(self.err(r.span(), "`range` is [low, high]"));
                    }
                    let what = format!("a range bound of `{}`", name.get_ref());
                    let own = self.dims.of(name.get_ref()).unwrap_or_default();
                    let lo = self.scalar(&r.get_ref()[0], "a range bound")?;
                    self.want(&r.get_ref()[0], own.clone(), &what);
                    let lo = self.constant(lo, r.span(), "a range bound")?;
                    let hi = self.scalar(&r.get_ref()[1], "a range bound")?;
                    self.want(&r.get_ref()[1], own, &what);
                    let hi = self.constant(hi, r.span(), "a range bound")?;
                    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
                        return Err(self.err(r.span(), format!("empty range [{lo}, {hi}]")));
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
        Ok(unknowns)
    }

    /// `[coordinates]`: free ones with initial conditions, prescribed ones as functions of t.
    pub(super) fn read_coordinates(&mut self, raw: &RawModel) -> Result<Coordinates, ModelError> {
        let mut out = Coordinates {
            coordinates: Vec::with_capacity(raw.coordinates.len()),
            initial_exprs: Vec::new(),
            known_accelerations: Vec::new(),
        };
        self.scope.reserve(raw.coordinates.len(), 0);
        self.coordinate_names.reserve(raw.coordinates.len());
        for (k, (name, sv)) in raw.coordinates.iter().enumerate() {
            let sv = raw.shared.coordinates.get(k, sv);
            self.enter(Table::Coordinates, k);
            let n = name.get_ref();
            let index = out.coordinates.len();
            let kind = match sv.get_ref() {
                toml::Value::String(_) => {
                    let expr = self.scalar(sv, "a prescribed coordinate")?;
                    let form = self.last_for(n);
                    self.dims.bind(n, form);
                    CoordinateKind::Prescribed { expr }
                }
                toml::Value::Table(t) => {
                    // A member of a family whose dimension is known shares it (the members'
                    // key, `x[]`, holds it since the first member): no unknown of its own.
                    if self.member.is_none() || self.family_form(sv).is_none() {
                        self.dims.bind_unknown(n);
                    }
                    self.coordinate_table(n, sv, t, index, &mut out)?
                }
                other => {
                    return Err(self
                        .err(sv.span(), format!("coordinate `{n}` must be a table or a string, found a {}", other.type_str()))
                        .help("write `x = { initial = 1.0, rate = 0.0 }` for an unknown coordinate, or `theta = \"omega*t\"` for a prescribed one"))
                }
            };
            let sym = self.pool.symbol(n, false);
            let binding = match &kind {
                CoordinateKind::Free { .. } => Binding::Coordinate(sym),
                CoordinateKind::Prescribed { expr } => Binding::Value(Value::Scalar(*expr)),
            };
            self.declare(n, name.span(), "coordinate", binding)?;
            self.coordinate_names
                .push((n.clone(), matches!(kind, CoordinateKind::Free { .. })));
            out.coordinates.push(Coordinate {
                name: n.clone(),
                sym,
                kind,
            });
        }
        self.leave();
        Ok(out)
    }

    /// Whether the coordinate table's `key` names a definition not declared yet.
    fn names_pending_definition(&self, t: &toml::Table, key: &str) -> bool {
        if self.definition_names.is_empty() {
            return false;
        }
        let Some(v) = t.get(key) else { return false };
        let Ok(text) = number_text(v) else {
            return false;
        };
        if looks_like_quantity(&text) {
            return false;
        }
        let Ok(ast) = pdyn_expr::syntax::parse(&text) else {
            return false;
        };
        ast.any_name(&|name| {
            self.definition_names.iter().any(|d| d == name) && !self.scope.names.contains_key(name)
        })
    }

    /// The initial conditions that name definitions, read now that `[definitions]` is: a
    /// definition of the parameters (`x0 = "L/2"`) is a number at t = 0; one of the
    /// coordinates is refused as any non-constant initial value is.
    pub(super) fn resolve_deferred_initials(
        &mut self,
        coords: &mut Coordinates,
    ) -> Result<(), ModelError> {
        for (index, n, sv, t, key) in std::mem::take(&mut self.deferred_initials) {
            self.enter(Table::Coordinates, index);
            let (value, expr) = self.initial_condition(&n, &sv, &t, key)?;
            if let CoordinateKind::Free { initial, rate } = &mut coords.coordinates[index].kind {
                if key == "rate" {
                    *rate = value;
                } else {
                    *initial = value;
                }
            }
            if let Some(e) = coords.initial_exprs.iter_mut().find(|e| e.0 == index) {
                if key == "rate" {
                    e.2 = expr;
                } else {
                    e.1 = expr;
                }
            }
        }
        self.leave();
        Ok(())
    }

    /// One coordinate written as a table: `{ initial, rate [, acceleration] }` or
    /// `{ prescribed = "f(t)" }`.
    fn coordinate_table(
        &mut self,
        n: &str,
        sv: &Sv,
        t: &toml::Table,
        index: usize,
        out: &mut Coordinates,
    ) -> Result<CoordinateKind, ModelError> {
        for key in t.keys() {
            if !["initial", "rate", "prescribed", "acceleration"].contains(&key.as_str()) {
                return Err(self
                    .err(
                        sv.span(),
                        format!("unknown key `{key}` in coordinate `{n}`"),
                    )
                    .help(
                        "a coordinate is { initial = ..., rate = ... } or a prescribed \"f(t)\"",
                    ));
            }
        }
        if let Some(p) = t.get("prescribed") {
            let text = match p {
                toml::Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            let ast = pdyn_expr::syntax::parse(&text)
                .map_err(|e| self.err(sv.span(), format!("in `prescribed`: {}", e.message)))?;
            let v = lower(&mut self.pool, &ast, &mut self.scope)
                .map_err(|e| self.err(sv.span(), format!("in `prescribed`: {}", e.message)))?;
            let before = self.dims.errors.len();
            let form = self.dims.infer(
                &ast,
                Source {
                    text: &text,
                    offset: sv.span().start,
                },
            );
            for e in &mut self.dims.errors[before..] {
                e.span = sv.span();
            }
            self.dims.bind(n, form);
            return match v {
                Value::Scalar(expr) => Ok(CoordinateKind::Prescribed { expr }),
                Value::Vector(_) => Err(self.err(sv.span(), "a coordinate is a scalar")),
            };
        }
        // A family member whose texts its family compiled once: numbers, no expressions.
        if let Some((initial, rate)) = self.family_initial(sv, t, index)? {
            // The same texts give every member the same dimension: inferred and checked for
            // the first, whose own unknown dimension the check solved, or equated with the
            // texts' (an error is the first member's, as when each was checked; only the
            // first error is reported). Numbers alone check nothing: each member keeps its own.
            match self.family_form(sv) {
                // Bound by the first member (`read_coordinates`): the key is the family's.
                Some(_) => {}
                None => {
                    if self.coordinate_dimensions_of(n, sv, t) {
                        let form = self.dims.of(n).unwrap_or_default();
                        self.set_family_form(sv, form);
                    }
                }
            }
            self.known_acceleration(n, sv, t, index, out)?;
            return Ok(CoordinateKind::Free { initial, rate });
        }
        let read = |ld: &mut Self, key: &'static str| {
            if ld.names_pending_definition(t, key) {
                ld.deferred_initials
                    .push((index, n.to_string(), sv.clone(), t.clone(), key));
                return Ok((f64::NAN, pdyn_expr::Pool::ZERO));
            }
            ld.initial_condition(n, sv, t, key)
        };
        let (initial, initial_expr) = read(self, "initial")?;
        let (rate, rate_expr) = read(self, "rate")?;
        out.initial_exprs.push((index, initial_expr, rate_expr));
        self.known_acceleration(n, sv, t, index, out)?;
        Ok(CoordinateKind::Free { initial, rate })
    }

    /// A free coordinate's `acceleration = ...`, if given.
    fn known_acceleration(
        &mut self,
        n: &str,
        sv: &Sv,
        t: &toml::Table,
        index: usize,
        out: &mut Coordinates,
    ) -> Result<(), ModelError> {
        if let Some(acc) = t.get("acceleration") {
            let text = number_text(acc).map_err(|found| {
                self.err(
                    sv.span(),
                    format!("`acceleration` must be a number or an expression, found {found}"),
                )
            })?;
            let ast = pdyn_expr::syntax::parse(&text)
                .map_err(|e| self.err(sv.span(), format!("in `acceleration`: {}", e.message)))?;
            let v = lower(&mut self.pool, &ast, &mut self.scope).map_err(|e| {
                self.err(
                    sv.span(),
                    format!("in `acceleration` of `{n}`: {}", e.message),
                )
                .help(e.help.unwrap_or_default())
            })?;
            let Value::Scalar(id) = v else {
                return Err(self.err(sv.span(), "`acceleration` must be a scalar"));
            };
            self.coordinate_dimension(n, sv, &ast, &text, 2, "acceleration");
            out.known_accelerations.push((index, id));
        }
        Ok(())
    }

    /// The dimension checks [`Loader::initial_condition`] makes of `initial` and `rate`, for
    /// values read by their family's compiled texts (parsed, inferred once per family).
    /// Whether either was more than a number (and so checked).
    fn coordinate_dimensions_of(&mut self, n: &str, sv: &Sv, t: &toml::Table) -> bool {
        let mut checked = false;
        for (key, order) in [("initial", 0), ("rate", 1)] {
            let Some(Ok(text)) = t.get(key).map(number_text) else {
                continue;
            };
            if let Ok(ast) = self.parse(&text, sv.span().start) {
                checked |= !ast_is_number(&ast);
                self.coordinate_dimension(n, sv, &ast, &text, order, key);
            }
        }
        checked
    }

    /// A coordinate's `initial` or `rate`: its value now and its expression in the parameters.
    fn initial_condition(
        &mut self,
        n: &str,
        sv: &Sv,
        t: &toml::Table,
        key: &str,
    ) -> Result<(f64, Id), ModelError> {
        let Some(v) = t.get(key) else {
            let hint = if key == "rate" {
                format!("give `{n}`'s initial rate d{n}/dt, e.g. rate = 0 if it starts at rest")
            } else {
                format!("give `{n}`'s value at t = 0, e.g. initial = 0")
            };
            return Err(self
                .err(
                    sv.span(),
                    format!("coordinate `{n}` has no `{key}` (initial condition)"),
                )
                .help(hint));
        };
        let text = number_text(v).map_err(|found| {
            self.err(
                sv.span(),
                format!("`{key}` must be a number, found {found}"),
            )
        })?;
        let order = if key == "rate" { 1 } else { 0 };
        if looks_like_quantity(&text) {
            let (q, dim) = parse_quantity_with_dimension(&text)
                .map_err(|e| self.err(sv.span(), format!("in `{key}`: {}", e.message)))?;
            self.dims.has_units |= dim != Dimension::NONE;
            let want = self.coordinate_form(n, order);
            let what = format!("`{key}` of `{n}`");
            self.dims.require(&dim.into(), &want, sv.span(), &what, "");
            return Ok((q, self.pool.num(Number::Float(q))));
        }
        let ast = self
            .parse(&text, sv.span().start)
            .map_err(|e| self.err(sv.span(), format!("in `{key}`: {}", e.message)))?;
        let v = lower(&mut self.pool, &ast, &mut self.scope).map_err(|e| {
            self.err(sv.span(), format!("in `{key}` of `{n}`: {}", e.message))
                .help(e.help.unwrap_or_default())
        })?;
        let Value::Scalar(id) = v else {
            return Err(self.err(sv.span(), format!("`{key}` must be a scalar")));
        };
        self.coordinate_dimension(n, sv, &ast, &text, order, key);
        let what = format!("`{key}` of `{n}`");
        let unknowns = self.unknowns_in(id);
        if unknowns.is_empty() {
            return Ok((self.constant(id, sv.span(), &what)?, id));
        }
        // `rate = "omega"` with `omega` in [unknowns]: `pdyn forces` solves for it, so the
        // expression is kept and the number is NaN until then (a run refuses it, located).
        self.constant_in_unknowns(id, sv.span(), &what)?;
        let index = self.coordinate_names.len();
        let key = if key == "rate" { "rate" } else { "initial" };
        self.unknown_initials.push(super::UnknownInitial {
            coordinate: self.coordinate_index(n).map_or(index, |(k, _)| k),
            name: n.to_string(),
            key,
            text: text.trim().to_string(),
            unknowns,
            span: sv.span(),
        });
        Ok((f64::NAN, id))
    }

    /// The dimension of coordinate `n`'s `order`-th time derivative.
    fn coordinate_form(&mut self, n: &str, order: i64) -> Form {
        let own = self.dims.of(n).unwrap_or_default();
        Form::from(Dimension::TIME)
            .pow(order.into())
            .and_then(|t| own.div(&t))
            .unwrap_or(own)
    }

    /// Checks an initial value, rate or acceleration written for coordinate `n` (a bare number
    /// takes the coordinate's dimension).
    fn coordinate_dimension(
        &mut self,
        n: &str,
        sv: &Sv,
        ast: &pdyn_expr::syntax::Ast,
        text: &str,
        order: i64,
        key: &str,
    ) {
        if ast_is_number(ast) {
            return;
        }
        // The table's values carry no spans of their own: errors inside point at the table.
        let before = self.dims.errors.len();
        let got = self.infer(
            ast,
            Source {
                text,
                offset: sv.span().start,
            },
        );
        for e in &mut self.dims.errors[before..] {
            e.span = sv.span();
        }
        let want = self.coordinate_form(n, order);
        let what = format!("`{key}` of `{n}`");
        self.dims.require(&got, &want, sv.span(), &what, "");
    }

    /// `[definitions]`: named expressions.
    pub(super) fn read_definitions(
        &mut self,
        raw: &RawModel,
    ) -> Result<Vec<(String, Value)>, ModelError> {
        let mut definitions = Vec::new();
        for (k, (name, sv)) in raw.definitions.iter().enumerate() {
            let sv = raw.shared.definitions.get(k, sv);
            self.enter(Table::Definitions, k);
            let v = self.value(sv)?;
            let form = self.last_for(name.get_ref());
            self.dims.bind(name.get_ref(), form);
            self.declare(name.get_ref(), name.span(), "definition", Binding::Value(v))?;
            definitions.push((name.get_ref().clone(), v));
        }
        self.leave();
        Ok(definitions)
    }

    /// `[points]`: named fixed or prescribed positions.
    pub(super) fn read_points(
        &mut self,
        raw: &RawModel,
    ) -> Result<Vec<(String, [Id; 3])>, ModelError> {
        let mut points = Vec::new();
        for (k, (name, sv)) in raw.points.iter().enumerate() {
            let sv = raw.shared.points.get(k, sv);
            self.enter(Table::Points, k);
            let v = self.vector(sv, &format!("point `{}`", name.get_ref()))?;
            self.want(
                sv,
                Dimension::LENGTH,
                &format!("point `{}`", name.get_ref()),
            );
            self.dims.bind(name.get_ref(), Dimension::LENGTH.into());
            self.declare(
                name.get_ref(),
                name.span(),
                "point",
                Binding::Value(Value::Vector(v)),
            )?;
            points.push((name.get_ref().clone(), v));
        }
        self.leave();
        Ok(points)
    }

    /// `[particles.NAME]`: mass and position; declares `NAME` (the position), `r_NAME` and
    /// `v_NAME`. A model needs at least one.
    pub(super) fn read_particles(&mut self, raw: &RawModel) -> Result<Vec<Particle>, ModelError> {
        let mut particles = Vec::with_capacity(raw.particles.len());
        let mut bound: Option<std::rc::Rc<str>> = None;
        // Each particle declares its name, `r_NAME` and `v_NAME`: the tables sized once (a
        // family's 10^4 members grew them step by step, each step rehashing every name).
        self.scope
            .reserve(raw.particles.len(), 2 * raw.particles.len());
        for (k, (name, sp)) in raw.particles.iter().enumerate() {
            let sp = raw.shared.particles.get(k, sp);
            self.enter(Table::Particles, k);
            let n = name.get_ref();
            let p = sp.get_ref();
            let Some(msv) = &p.mass else {
                return Err(self
                    .err(name.span(), format!("particle `{n}` has no mass"))
                    .help("add mass = ... (a number or a parameter)"));
            };
            let Some(psv) = &p.position else {
                return Err(self
                    .err(name.span(), format!("particle `{n}` has no position"))
                    .help("add position = \"[x, y, z]\" in terms of the coordinates"));
            };
            let mass = self.scalar(msv, "a mass")?;
            self.want_with(msv, Dimension::MASS, || format!("the mass of `{n}`"));
            let mv = self.constant(mass, msv.span(), "a mass")?;
            if mv <= 0.0 {
                return Err(self
                    .err(
                        msv.span(),
                        format!("the mass of `{n}` must be positive, it is {mv}"),
                    )
                    .help("a massless body is a frame: declare it under [frames]"));
            }
            let position = self.vector_with(psv, || format!("the position of `{n}`"))?;
            self.want_with(psv, Dimension::LENGTH, || format!("the position of `{n}`"));
            // The members of a family share their dimensions (`P[]`): bound once.
            let family = self.member.clone();
            if family.is_none() || family != bound {
                for (prefix, d) in [
                    ("", Dimension::LENGTH),
                    ("r_", Dimension::LENGTH),
                    ("v_", Dimension::VELOCITY),
                ] {
                    self.dims.bind(&format!("{prefix}{n}"), d.into());
                }
                bound = family;
            }
            let vel = position.map(|c| super::member_template::dt(&mut self.pool, c));
            for (prefix, v) in [("r_", position), ("v_", vel)] {
                // Concatenated, not `format!`: once per particle.
                let mut key = String::with_capacity(prefix.len() + n.len());
                key.push_str(prefix);
                key.push_str(n);
                if !self.scope.names.contains_key(key.as_str()) {
                    self.scope
                        .local
                        .insert(key, Binding::Value(Value::Vector(v)));
                }
            }
            self.declare(
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
        self.leave();
        if particles.is_empty() {
            return Err(self
                .err(0..0, "the model has no particles")
                .help("add a [particles.NAME] table with mass and position"));
        }
        Ok(particles)
    }

    /// `[frames.NAME]`: massless frames, each carrying one particle.
    pub(super) fn read_frames(
        &mut self,
        raw: &RawModel,
        particles: &[Particle],
    ) -> Result<Vec<Frame>, ModelError> {
        let mut frames = Vec::new();
        for (name, sf) in &raw.frames {
            let Some(pn) = &sf.get_ref().particle else {
                return Err(self
                    .err(
                        name.span(),
                        format!("frame `{}` names no particle", name.get_ref()),
                    )
                    .help("add particle = \"NAME\""));
            };
            let Some(pi) = particles.iter().position(|p| &p.name == pn.get_ref()) else {
                let s = suggest(pn.get_ref(), particles.iter().map(|p| p.name.as_str()));
                let mut e = self.err(pn.span(), format!("unknown particle `{}`", pn.get_ref()));
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
        Ok(frames)
    }

    /// `gravity` and `[[forces]]`, split into loads; the reactions they introduce become names
    /// that constraints, events and monitors may use.
    pub(super) fn read_forces(
        &mut self,
        raw: &RawModel,
        particles: &[Particle],
        frames: &[Frame],
        points: &[(String, [Id; 3])],
    ) -> Result<forces::Built, ModelError> {
        let gravity = match &raw.gravity {
            Some(g) => {
                let v = self.vector(g, "gravity")?;
                self.want(g, Dimension::ACCELERATION, "gravity");
                Some(v)
            }
            None => None,
        };
        let mut fb = forces::ForceBuilder::new(particles, frames, points);
        if let Some(g) = gravity {
            fb.gravity(self, g);
        }
        let mut deferrer = super::deferred::Deferrer::default();
        // A field naming an index or a table's column differs from member to member: such
        // a family is built in full, never deferred to its representative.
        let mut index_names: Vec<String> = self.scope.indices.ranges.keys().cloned().collect();
        index_names.extend(self.scope.indices.columns.keys().cloned());
        let entries = std::mem::take(&mut self.members.force_entries);
        for (k, fe) in entries.iter().enumerate() {
            self.enter(Table::Forces, k);
            let original = &raw.forces[fe.entry];
            let decision = if self.defer && !self.scope.bindings.is_empty() {
                // The names of the indices, made only for the first member of an entry (the
                // others' decision about the entry is the first's).
                let bindings = &self.scope.bindings;
                let names = || {
                    let mut names: Vec<&str> = index_names.iter().map(String::as_str).collect();
                    names.extend(bindings.iter().map(|b| b.0.as_str()));
                    names
                };
                // A member by index is found by index when its family's particles are
                // known that way (no name made), else by its name, as any other end.
                let indices = &self.scope.indices;
                let particle = |end: End| match end {
                    End::Name(n) => fb.particle_named(n),
                    End::Member(r) => indices
                        .particle_of(r)
                        .or_else(|| fb.particle_named(&r.name())),
                };
                deferrer.decide(&self.pool, particles, particle, original, fe.ends(), names)
            } else {
                Decision::Build
            };
            match decision {
                Decision::Deferred => {}
                Decision::Build => {
                    let force = fe.raw(&raw.forces, &self.scope.bindings);
                    fb.force(self, &force)?
                }
                Decision::Representative(key, ends) => {
                    let before = fb.counts();
                    let force = fe.raw(&raw.forces, &self.scope.bindings);
                    fb.force(self, &force)?;
                    let after = fb.counts();
                    let f = original.get_ref();
                    let family = force.get_ref().name.as_ref().map_or_else(
                        || {
                            f.kind
                                .as_ref()
                                .map_or(String::new(), |k| k.get_ref().clone())
                        },
                        |n| {
                            n.get_ref()
                                .split('[')
                                .next()
                                .unwrap_or_default()
                                .to_string()
                        },
                    );
                    let one = |a: usize, b: usize| (b == a + 1).then_some(a);
                    deferrer.represent(
                        key,
                        ends,
                        family,
                        before.0,
                        after.0 - before.0,
                        one(before.1, after.1),
                        one(before.2, after.2),
                    );
                }
            }
        }
        self.leave();
        self.deferred = deferrer.families;
        let built = fb.finish();
        let friction_names = built.contacts.iter().flat_map(|c| {
            let (n, ids) = &c.friction_force;
            [(n.clone(), ids[0]), (format!("{n}_2"), ids[1])]
        });
        let friction_names: Vec<(String, Id)> = friction_names.collect();
        for (name, id) in friction_names {
            if !self.scope.names.contains_key(name.as_str()) {
                let name: std::rc::Rc<str> = std::rc::Rc::from(name.as_str());
                self.scope.order.push(std::rc::Rc::clone(&name));
                self.scope
                    .names
                    .insert(name, (Binding::Value(Value::Scalar(id)), 0..0, "reaction"));
            }
        }
        for r in &built.reactions {
            if !self.scope.names.contains_key(r.name.as_str()) {
                let name: std::rc::Rc<str> = std::rc::Rc::from(r.name.as_str());
                self.scope.order.push(std::rc::Rc::clone(&name));
                self.scope.names.insert(
                    name,
                    (Binding::Value(Value::Scalar(r.id)), 0..0, "reaction"),
                );
            }
        }
        Ok(built)
    }

    /// `[[constraints]]`: equations among the coordinates.
    pub(super) fn read_constraints(
        &mut self,
        raw: &RawModel,
    ) -> Result<Vec<Constraint>, ModelError> {
        let mut constraints = Vec::new();
        for sc in &raw.constraints {
            let c = sc.get_ref();
            let Some(eq) = &c.equation else {
                return Err(self
                    .err(sc.span(), "a constraint has no `equation`")
                    .help("write equation = \"yA + yB = 2*h\" (a relation among coordinates)"));
            };
            let (text, off) = self.expr_text(eq)?;
            let v = self
                .pool
                .parse_equation_in(&text, &mut self.scope)
                .map_err(|e| self.located(e, off))?;
            if let Ok((lhs, Some(rhs))) = pdyn_expr::syntax::parse_equation(&text) {
                let src = Source {
                    text: &text,
                    offset: off,
                };
                let a = self.dims.infer(&lhs, src);
                let b = self.dims.infer(&rhs, src);
                self.dims.mismatch(
                    src,
                    (&lhs, &a),
                    (&rhs, &b),
                    " between the two sides of a constraint",
                );
            }
            let Value::Scalar(e) = v else {
                return Err(self.err(eq.span(), "a constraint equation must be scalar"));
            };
            let label = c
                .name
                .as_ref()
                .map_or(text.clone(), |n| n.get_ref().clone());
            constraints.push(Constraint {
                label,
                equation: e,
                derivatives: 2,
                span: eq.span(),
            });
        }
        Ok(constraints)
    }
}

/// `2`, `-0.5`: a number without units.
fn ast_is_number(ast: &pdyn_expr::syntax::Ast) -> bool {
    match ast {
        pdyn_expr::syntax::Ast::Num { .. } => true,
        pdyn_expr::syntax::Ast::Neg { expr, .. } => ast_is_number(expr),
        _ => false,
    }
}

/// The text of a value inside a coordinate's table: an expression string, or a number written
/// as one; otherwise the TOML type found.
fn number_text(v: &toml::Value) -> Result<String, &'static str> {
    match v {
        toml::Value::String(s) => Ok(s.clone()),
        toml::Value::Integer(i) => Ok(i.to_string()),
        toml::Value::Float(f) => Ok(format!("{f:e}")),
        other => Err(other.type_str()),
    }
}
