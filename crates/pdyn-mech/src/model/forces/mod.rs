//! Force declarations → loads on particles and frames.
//!
//! Each kind of `[[forces]]` entry is one file here holding a [`Kind`]: its name, its doc
//! (the TOML fields it reads, the force on the first body, its potential energy) and its
//! `build`, which reads the fields of [`RawForce`] it needs and pushes loads, reaction
//! unknowns and potential energies on the [`ForceBuilder`]. [`KINDS`] lists them; adding a
//! kind is one file and one line there (and its fields in `raw.rs::RawForce`). A test checks
//! the table of `docs/model-format.md` against [`KINDS`].
//!
//! | file | kinds |
//! |---|---|
//! | `applied.rs` | `applied`: a given vector (may use the particle's `r`, `v`) |
//! | `spring.rs`, `damper.rs` | `spring`, `damper`: along the line between two ends |
//! | `drag.rs` | `drag`, `linear_drag`: against the velocity relative to the wind |
//! | `inverse_square.rs`, `potential.rs` | `inverse_square`, `potential`: central forces from a potential of the distance |
//! | `reaction.rs`, `friction.rs` | `reaction`, `friction`: unknown forces (stick) or `mu N` (slip) |
//! | `gravity.rs` | the top-level `gravity = g` (`m g` on every particle, potential `-m g·r`) |
//!
//! What is shared lives here: finding the bodies (`on`/`at`, `between`/`to`), pushing
//! two-body forces equal and opposite on the second body when it is a particle, registering
//! reaction unknowns, and binding `r`, `v` while a force expression is read.

mod applied;
mod damper;
mod drag;
mod friction;
mod gravity;
mod inverse_square;
mod potential;
mod reaction;
mod spring;

use super::raw::{Name, RawForce, Sv};
use super::{
    Frame, Load, Loader, ModelError, Particle, PointLoad, PotentialTerm, Reaction, Target,
};
use pdyn_expr::error::suggest;
use pdyn_expr::lower::{Binding, Scope};
use pdyn_expr::vector;
use pdyn_expr::{Id, Pool, Value};
use std::ops::Range;
use toml::Spanned;

/// One kind of `[[forces]]` entry.
// `fields`, `force`, `potential` are documentation, checked against docs/model-format.md by a
// test.
#[cfg_attr(not(test), allow(dead_code))]
pub(super) struct Kind {
    /// The `kind = "..."` string.
    pub name: &'static str,
    /// The TOML fields it reads (the `fields` column of docs/model-format.md).
    pub fields: &'static str,
    /// The force on the first body (the last column of docs/model-format.md).
    pub force: &'static str,
    /// Its potential energy, or `—` when it has none.
    pub potential: &'static str,
    /// Reads the entry and pushes its loads, reactions and potentials.
    pub build: fn(&mut ForceBuilder, &mut Loader, &Entry) -> Result<(), ModelError>,
}

/// Every kind, in the order error messages list them.
pub(super) const KINDS: [&Kind; 10] = [
    &applied::APPLIED,
    &spring::SPRING,
    &damper::DAMPER,
    &drag::DRAG,
    &drag::LINEAR_DRAG,
    &inverse_square::INVERSE_SQUARE,
    &potential::POTENTIAL,
    &reaction::REACTION,
    &friction::FRICTION,
    &gravity::GRAVITY,
];

fn kind_names() -> [&'static str; KINDS.len()] {
    KINDS.map(|k| k.name)
}

/// One `[[forces]]` entry being built.
pub(super) struct Entry<'f> {
    /// The entry with its span.
    pub f: &'f Spanned<RawForce>,
    /// Its fields.
    pub raw: &'f RawForce,
    /// Its kind's name.
    pub kind: &'static str,
    /// The span of its `kind` value.
    pub kind_span: Range<usize>,
    /// Its `name`, or the kind's name: the label of its loads and potentials.
    pub label: String,
}

impl Entry<'_> {
    /// A required expression field.
    fn need<'s>(&self, ld: &Loader, v: &'s Option<Sv>, field: &str) -> Result<&'s Sv, ModelError> {
        v.as_ref().ok_or_else(|| {
            ld.err(
                self.f.span(),
                format!("a `{}` force needs `{field}`", self.kind),
            )
            .help(format!("add {field} = ... to this [[forces]] entry"))
        })
    }

    /// A required name field.
    fn need_name<'s>(
        &self,
        ld: &Loader,
        v: &'s Option<Name>,
        field: &str,
    ) -> Result<&'s Name, ModelError> {
        v.as_ref().ok_or_else(|| {
            ld.err(
                self.f.span(),
                format!("a `{}` force needs `{field}`", self.kind),
            )
            .help(format!("add {field} = \"...\" to this [[forces]] entry"))
        })
    }

    /// The span of an optional name field, or of `kind` when absent.
    fn span_or_kind(&self, n: &Option<Name>) -> Range<usize> {
        n.as_ref().map_or(self.kind_span.clone(), |n| n.span())
    }
}

#[derive(Clone, Copy)]
enum Endpoint {
    Particle(usize),
    Point,
}

/// One end of a two-body force: the body, its position, its name.
type End = (Endpoint, [Id; 3], String);

pub(super) struct Built {
    pub friction_forces: Vec<String>,
    /// Coulomb `friction` forces, as held contacts.
    pub contacts: Vec<super::Contact>,
    /// `(label, F·v_slip, |F| |v_slip|)` of each sliding friction drawn with `opposes`.
    pub friction_power: Vec<(String, Id, Id)>,
    /// Reactions declared `one_sided`.
    pub one_sided: Vec<String>,
    pub loads: Vec<Load>,
    pub point_loads: Vec<PointLoad>,
    pub reactions: Vec<Reaction>,
    pub potentials: Vec<PotentialTerm>,
    pub axial: Vec<super::AxialForce>,
    pub conservative: bool,
}

pub(super) struct ForceBuilder<'a> {
    particles: &'a [Particle],
    frames: &'a [Frame],
    points: &'a [(String, [Id; 3])],
    /// Particle and point indices by name: a net's tens of thousands of springs each find
    /// their two ends (searching the lists was quadratic in the number of particles).
    particle_index: rustc_hash::FxHashMap<&'a str, usize>,
    point_index: rustc_hash::FxHashMap<&'a str, usize>,
    loads: Vec<Load>,
    point_loads: Vec<PointLoad>,
    reactions: Vec<Reaction>,
    potentials: Vec<PotentialTerm>,
    axial: Vec<super::AxialForce>,
    conservative: bool,
    friction_forces: Vec<String>,
    contacts: Vec<super::Contact>,
    friction_power: Vec<(String, Id, Id)>,
    one_sided: Vec<String>,
    /// Unknown forces `name * direction` pushed so far, by `reaction` and by `friction`'s
    /// normal force, to refuse one unknown declared twice on one body along one line.
    directed: Vec<Directed>,
}

/// An unknown force `name * direction` on a body, and which entry declared it.
struct Directed {
    name: String,
    target: Target,
    direction: [Id; 3],
    span: Range<usize>,
    kind: &'static str,
}

impl<'a> ForceBuilder<'a> {
    pub fn new(
        particles: &'a [Particle],
        frames: &'a [Frame],
        points: &'a [(String, [Id; 3])],
    ) -> Self {
        // The first of two equal names wins, as the searches it replaces found it.
        let mut particle_index = rustc_hash::FxHashMap::default();
        for (i, p) in particles.iter().enumerate() {
            particle_index.entry(p.name.as_str()).or_insert(i);
        }
        let mut point_index = rustc_hash::FxHashMap::default();
        for (i, p) in points.iter().enumerate() {
            point_index.entry(p.0.as_str()).or_insert(i);
        }
        ForceBuilder {
            particles,
            frames,
            points,
            particle_index,
            point_index,
            loads: Vec::new(),
            point_loads: Vec::new(),
            reactions: Vec::new(),
            potentials: Vec::new(),
            axial: Vec::new(),
            conservative: true,
            friction_forces: Vec::new(),
            contacts: Vec::new(),
            friction_power: Vec::new(),
            one_sided: Vec::new(),
            directed: Vec::new(),
        }
    }

    /// The particle named `name`.
    pub fn particle_named(&self, name: &str) -> Option<usize> {
        self.particle_index.get(name).copied()
    }

    /// How many loads, potentials and tensions are pushed so far.
    pub fn counts(&self) -> (usize, usize, usize) {
        (self.loads.len(), self.potentials.len(), self.axial.len())
    }

    pub fn finish(self) -> Built {
        Built {
            friction_forces: self.friction_forces,
            contacts: self.contacts,
            friction_power: self.friction_power,
            one_sided: self.one_sided,
            loads: self.loads,
            point_loads: self.point_loads,
            reactions: self.reactions,
            potentials: self.potentials,
            axial: self.axial,
            conservative: self.conservative,
        }
    }

    fn unknown_body(&self, ld: &Loader, name: &Name, frames_ok: bool) -> ModelError {
        let mut names: Vec<&str> = self.particles.iter().map(|p| p.name.as_str()).collect();
        if frames_ok {
            names.extend(self.frames.iter().map(|f| f.name.as_str()));
        } else {
            names.extend(self.points.iter().map(|p| p.0.as_str()));
        }
        let mut e = ld.err(
            name.span(),
            format!("unknown particle `{}`", name.get_ref()),
        );
        e = match suggest(name.get_ref(), names.iter().copied()) {
            Some(s) => e.help(format!("did you mean `{s}`?")),
            None => e.help(format!("declared: {}", names.join(", "))),
        };
        e
    }

    /// The body a one-body force acts on: a particle, or a frame (then `at` is required).
    fn target(&self, ld: &mut Loader, e: &Entry) -> Result<(Target, [Id; 3]), ModelError> {
        let on = e.need_name(ld, &e.raw.on, "on")?;
        if let Some(&i) = self.particle_index.get(on.get_ref().as_str()) {
            return Ok((Target::Particle(i), self.particles[i].position));
        }
        if let Some(j) = self.frames.iter().position(|fr| &fr.name == on.get_ref()) {
            let at = match &e.raw.at {
                Some(sv) => {
                    let at = ld.vector(sv, "`at`")?;
                    ld.want(
                        sv,
                        pdyn_expr::Dimension::LENGTH,
                        "the point of application `at`",
                    );
                    at
                }
                None => {
                    return Err(ld
                        .err(
                            on.span(),
                            format!(
                                "a force on frame `{}` needs `at`, its point of application",
                                on.get_ref()
                            ),
                        )
                        .help("add at = \"[x, y, z]\""))
                }
            };
            return Ok((Target::Frame { frame: j, at }, at));
        }
        Err(self.unknown_body(ld, on, true))
    }

    fn endpoint(&self, ld: &mut Loader, name: &Name) -> Result<(Endpoint, [Id; 3]), ModelError> {
        if let Some(&i) = self.particle_index.get(name.get_ref().as_str()) {
            return Ok((Endpoint::Particle(i), self.particles[i].position));
        }
        if let Some(&k) = self.point_index.get(name.get_ref().as_str()) {
            return Ok((Endpoint::Point, self.points[k].1));
        }
        Err(self
            .unknown_body(ld, name, false)
            .help("an end is a particle or a point declared under [points]"))
    }

    fn pair(&self, ld: &mut Loader, e: &Entry) -> Result<[End; 2], ModelError> {
        let raw = e.raw;
        if let Some(b) = &raw.between {
            if b.get_ref().len() != 2 {
                return Err(ld.err(
                    b.span(),
                    format!("`between` lists {} names; it needs two", b.get_ref().len()),
                ));
            }
            if b.get_ref()[0].get_ref() == b.get_ref()[1].get_ref() {
                return Err(ld
                    .err(
                        b.span(),
                        format!("`between` joins `{}` to itself", b.get_ref()[0].get_ref()),
                    )
                    .help("a two-body force joins two different bodies (in a family, check the index arithmetic)"));
            }
            let (e0, r0) = self.endpoint(ld, &b.get_ref()[0])?;
            let (e1, r1) = self.endpoint(ld, &b.get_ref()[1])?;
            if matches!((e0, e1), (Endpoint::Point, Endpoint::Point)) {
                return Err(ld.err(
                    b.span(),
                    "both ends are fixed points: this force acts on no particle",
                ));
            }
            return Ok([
                (e0, r0, b.get_ref()[0].get_ref().clone()),
                (e1, r1, b.get_ref()[1].get_ref().clone()),
            ]);
        }
        if let (Some(on), Some(to)) = (&raw.on, &raw.to) {
            if on.get_ref() == to.get_ref() {
                return Err(ld
                    .err(
                        to.span(),
                        format!("`to` names `{}`, the body the force is on", on.get_ref()),
                    )
                    .help("a two-body force joins two different bodies"));
            }
            let (e0, r0) = self.endpoint(ld, on)?;
            let (e1, r1) = self.endpoint(ld, to)?;
            return Ok([
                (e0, r0, on.get_ref().clone()),
                (e1, r1, to.get_ref().clone()),
            ]);
        }
        Err(ld
            .err(
                e.f.span(),
                format!(
                    "a `{}` force needs `between = [\"A\", \"B\"]` (or `on` and `to`)",
                    e.kind
                ),
            )
            .help("each end is a particle or a point declared under [points]"))
    }

    /// Pushes `force` on the first end and `-force` on the second (if a particle).
    fn push_pair(&mut self, ld: &mut Loader, ends: &[End; 2], label: &str, force: [Id; 3]) {
        if let Endpoint::Particle(i) = ends[0].0 {
            self.loads.push(Load {
                label: format!("{label} on {}", ends[0].2),
                target: Target::Particle(i),
                force,
            });
        }
        let neg = force.map(|c| ld.pool.neg(c));
        if let Endpoint::Particle(j) = ends[1].0 {
            self.loads.push(Load {
                label: format!("{label} on {}", ends[1].2),
                target: Target::Particle(j),
                force: neg,
            });
        }
        // What the force does to a point: the pin holding it must take it (`pdyn
        // equilibrium` reports the reactions at the points).
        for (end, on_it) in [(&ends[0], force), (&ends[1], neg)] {
            if let Endpoint::Point = end.0 {
                self.point_loads.push(PointLoad {
                    label: format!("{label} on {}", end.2),
                    point: end.2.clone(),
                    force: on_it,
                });
            }
        }
    }

    /// Pushes a two-body force labelled `label (A, B)`.
    fn push_pair_labelled(&mut self, ld: &mut Loader, e: &Entry, ends: &[End; 2], force: [Id; 3]) {
        let lbl = format!("{} ({}, {})", e.label, ends[0].2, ends[1].2);
        self.push_pair(ld, ends, &lbl, force);
    }

    /// The length `l` between the ends (or `length`) and the unit vector `e` from the second
    /// end to the first (or `direction`): the line a spring or damper acts along.
    fn line_of_action(
        &self,
        ld: &mut Loader,
        e: &Entry,
        ends: &[End; 2],
    ) -> Result<(Id, [Id; 3]), ModelError> {
        let rel = vector::sub(&mut ld.pool, ends[0].1, ends[1].1);
        let l = match &e.raw.length {
            Some(sv) => {
                let l = ld.scalar(sv, "`length`")?;
                ld.want(sv, pdyn_expr::Dimension::LENGTH, "the `length`");
                l
            }
            None => vector::norm(&mut ld.pool, rel),
        };
        // Attachments away from the particles' positions: the user gives the unit
        // direction (from the second end to the first) along with the length.
        let dir = match &e.raw.direction {
            Some(d) => {
                let dir = ld.vector(d, "`direction`")?;
                ld.want(d, pdyn_expr::Dimension::NONE, "the unit vector `direction`");
                dir
            }
            None => rel.map(|c| ld.pool.div(c, l)),
        };
        Ok((l, dir))
    }

    /// Pushes `-mag dir` on the first end and the opposite on the second.
    fn push_axial(&mut self, ld: &mut Loader, e: &Entry, ends: &[End; 2], mag: Id, dir: [Id; 3]) {
        self.axial.push(super::AxialForce {
            label: format!("{} ({}, {})", e.label, ends[0].2, ends[1].2),
            tension: mag,
        });
        let neg = ld.pool.neg(mag);
        let force = vector::scale(&mut ld.pool, neg, dir);
        self.push_pair_labelled(ld, e, ends, force);
    }

    fn reaction(
        &mut self,
        ld: &mut Loader,
        name: &str,
        span: std::ops::Range<usize>,
    ) -> Result<Id, ModelError> {
        if let Some(r) = self.reactions.iter().find(|r| r.name == name) {
            return Ok(r.id);
        }
        if ld.scope.resolve(&mut ld.pool, name).is_some() {
            return Err(ld
                .err(span, format!("reaction `{name}` has the name of an existing parameter, coordinate or definition"))
                .help("give the unknown force its own name"));
        }
        if !name.chars().next().is_some_and(|c| c.is_alphabetic())
            || !name.chars().all(|c| c.is_alphanumeric() || c == '_')
        {
            return Err(ld.err(span, format!("`{name}` is not a valid name")));
        }
        let s = ld.pool.symbol(name, false);
        let id = ld.pool.sym(s);
        ld.dims.bind_unknown(name);
        self.reactions.push(Reaction {
            name: name.to_string(),
            id,
        });
        Ok(id)
    }

    /// Records the unknown force `name * direction` on `target`, declared by a `kind` entry
    /// at `span`; refuses it when an entry of the other kind (`reaction` and `friction`)
    /// already applies the same unknown to the same body along the same line: a free body
    /// diagram that draws the normal force both as a reaction and as a friction's normal
    /// force would count it twice (and halve it).
    fn directed(
        &mut self,
        ld: &mut Loader,
        name: &str,
        target: &Target,
        direction: [Id; 3],
        span: Range<usize>,
        kind: &'static str,
    ) -> Result<(), ModelError> {
        for d in &self.directed {
            if d.name != name || &d.target != target || d.kind == kind {
                continue;
            }
            let c = vector::cross(&mut ld.pool, d.direction, direction);
            if c.iter().all(|&x| ld.pool.provably_equal(x, Pool::ZERO)) {
                let (line, _) = pdyn_expr::error::line_col(ld.source, d.span.start);
                return Err(ld
                    .err(span, format!("`{name}` already acts on this body along the same line (the {} on line {line}): declared twice, it would be counted twice", d.kind))
                    .help("a `friction` force applies its own normal force `normal_force` (default N): remove the `reaction`, or give the two forces different names"));
            }
        }
        self.directed.push(Directed {
            name: name.to_string(),
            target: target.clone(),
            direction,
            span,
            kind,
        });
        Ok(())
    }

    fn with_local<T>(
        &self,
        ld: &mut Loader,
        r: [Id; 3],
        body: impl FnOnce(&mut Loader) -> Result<T, ModelError>,
    ) -> Result<T, ModelError> {
        let v = r.map(|c| ld.pool.dt(c));
        ld.scope
            .local
            .insert("r".into(), Binding::Value(Value::Vector(r)));
        ld.scope
            .local
            .insert("v".into(), Binding::Value(Value::Vector(v)));
        ld.dims.bind("r", pdyn_expr::Dimension::LENGTH.into());
        ld.dims.bind("v", pdyn_expr::Dimension::VELOCITY.into());
        let out = body(ld);
        ld.dims.unbind("r");
        ld.dims.unbind("v");
        ld.scope.local.remove("r");
        ld.scope.local.remove("v");
        out
    }

    /// Builds one `[[forces]]` entry: finds its kind in [`KINDS`] and lets the kind's
    /// `build` push loads, reaction unknowns and potential energies.
    pub fn force(&mut self, ld: &mut Loader, f: &Spanned<RawForce>) -> Result<(), ModelError> {
        let raw = f.get_ref();
        let Some(kind_n) = &raw.kind else {
            return Err(ld
                .err(f.span(), "a [[forces]] entry needs `kind`")
                .help(format!("kinds: {}", kind_names().join(", "))));
        };
        let name = kind_n.get_ref().as_str();
        let Some(kind) = KINDS.iter().find(|k| k.name == name) else {
            let mut e = ld.err(kind_n.span(), format!("unknown force kind `{name}`"));
            e = match suggest(name, kind_names()) {
                Some(s) => e.help(format!("did you mean `{s}`?")),
                None => e.help(format!("kinds: {}", kind_names().join(", "))),
            };
            return Err(e);
        };
        let entry = Entry {
            f,
            raw,
            kind: kind.name,
            kind_span: kind_n.span(),
            label: raw
                .name
                .as_ref()
                .map_or(kind.name.to_string(), |n| n.get_ref().clone()),
        };
        (kind.build)(self, ld, &entry)
    }
}

#[cfg(test)]
mod tests {
    use super::KINDS;

    /// The table of `[[forces]]` kinds in docs/model-format.md is the registry's.
    #[test]
    fn model_format_table_lists_every_kind() {
        let doc = include_str!("../../../../../docs/model-format.md");
        for k in KINDS.iter().filter(|k| k.name != "gravity") {
            let row = format!("| `{}` | {} | {} |", k.name, k.fields, k.force);
            assert!(
                doc.contains(&row),
                "docs/model-format.md lacks the row\n{row}"
            );
            assert!(!k.potential.is_empty());
        }
    }
}
