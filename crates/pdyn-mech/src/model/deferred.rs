//! Members of `[[forces]]` families left unexpanded: one representative member built as any
//! force, the others as index arrays of their particles (issue 33).
//!
//! A family such as a net's springs has tens of thousands of members whose loads are the
//! same function of their ends' coordinates: building each member's expressions (its line
//! of action, force, potential) was most of the time and memory of loading a 10^4-particle
//! cloth. With [`super::load_deferring`], a member is *deferred* when its loads are the
//! representative's with other particles: same family (same `[[forces]]` entry, so the same
//! fields), a kind whose loads depend only on its ends (`spring`, `damper`, `linear_drag`
//! without `length`, `direction` or `wind`), fields that do not use the family's indices,
//! ends that are particles, and particles of the same shape as the representative's (the
//! same mass expression; each position component a coordinate, or the same constant). The
//! families are recognised by their identity (the entry they come from), not by comparing
//! expressions.
//!
//! A deferred model is complete only for a consumer that reads [`Model::deferred`]: the run
//! path for free particles (`pdyn::sim::net`) turns each family into one kernel over its
//! index array. Anything else calls [`Model::expand_deferred`] first (the file loaded again
//! in full: the loads are then exactly those of [`super::load`]), or
//! [`Model::materialize_deferred`] (each member's loads, potential and axial force
//! substituted from the representative's into the same pool: the same values, for the
//! conservation laws of a run that already holds ids of this pool).

use super::families::End;
use super::raw::{RawForce, Sv};
use super::{AxialForce, Load, Model, ModelError, Particle, PotentialTerm, Target};
use crate::derive::DeriveError;
use pdyn_expr::{Id, Node, Pool, SymId};
use rustc_hash::FxHashMap;
use toml::Spanned;

/// The members of one force family that share one representative's loads.
#[derive(Clone, Debug)]
pub struct DeferredForces {
    /// The family's name (`horizontal`, or its kind): the label of materialized loads.
    pub family: String,
    /// Index in [`Model::loads`] of the representative's first load; it has `loads` of them,
    /// in order: on its first particle, then (a two-body force) the opposite on its second.
    pub first_load: usize,
    /// How many loads the representative pushed (1 or 2).
    pub loads: usize,
    /// Index in [`Model::potentials`] of the representative's potential energy, if any.
    pub potential: Option<usize>,
    /// Index in [`Model::axial`] of the representative's tension, if any.
    pub axial: Option<usize>,
    /// The representative's particles (indices into [`Model::particles`]): its two ends, or
    /// the particle a one-body force acts on.
    pub ends: Vec<u32>,
    /// The other members' particles, `ends.len()` per member, in the order of `ends`.
    pub members: Vec<u32>,
}

impl DeferredForces {
    /// How many members are deferred (the representative not counted).
    pub fn len(&self) -> usize {
        self.members.len() / self.ends.len().max(1)
    }

    /// True when no member is deferred.
    pub fn is_empty(&self) -> bool {
        self.members.is_empty()
    }

    /// Each deferred member's particles.
    pub fn each(&self) -> impl Iterator<Item = &[u32]> {
        self.members.chunks(self.ends.len().max(1))
    }
}

/// What decides whether two members share a representative: the family (its entry's place
/// in the file) and the shape of each of its particles.
pub(crate) type Key = (usize, Vec<Shape>);

/// A particle's shape: its mass expression, and per component `None` for a coordinate or the
/// constant expression it is.
pub(crate) type Shape = (Id, [Option<Id>; 3]);

/// The shape of a particle, or `None` when a component of its position is neither one
/// coordinate nor constant in time (its loads are then not the representative's with other
/// coordinates).
pub(crate) fn shape(pool: &Pool, mass: Id, position: &[Id; 3]) -> Option<Shape> {
    let mut out = [None; 3];
    for (o, &c) in out.iter_mut().zip(position) {
        match pool.node(c) {
            Node::Coord(_, 0) => {}
            // A leaf that is no coordinate nor `t` is constant (a family's `0` components:
            // walking them with `any_node` was a quarter of reading a chain's forces).
            Node::Num(_) | Node::Const(_) | Node::Sym(_) => *o = Some(c),
            _ if pool.any_node(c, &|n| matches!(n, Node::Coord(..) | Node::Time)) => return None,
            _ => *o = Some(c),
        }
    }
    Some((mass, out))
}

/// The coordinates of particle `p`'s position that are coordinates: `(axis, symbol)`.
fn coordinate_symbols(pool: &Pool, position: &[Id; 3]) -> Vec<(usize, SymId)> {
    position
        .iter()
        .enumerate()
        .filter_map(|(axis, &c)| match pool.node(c) {
            Node::Coord(s, 0) => Some((axis, *s)),
            _ => None,
        })
        .collect()
}

impl Model {
    /// True when some force families were left unexpanded ([`super::load_deferring`]).
    pub fn has_deferred(&self) -> bool {
        self.deferred.iter().any(|d| !d.is_empty())
    }

    /// The model as [`super::load`] reads it: when families were deferred, the file is loaded
    /// again in full, with the parameter values (and the initial conditions that follow from
    /// them) this model has now. Ids of the old pool are not valid afterwards.
    /// A file that loaded with deferral loads in full as well; should it not, the error says
    /// so as one of the derivation.
    pub fn expand_deferred(&mut self) -> Result<(), DeriveError> {
        if !self.has_deferred() {
            self.deferred.clear();
            return Ok(());
        }
        let mut full = super::load(&self.source, &self.origin).map_err(|e: ModelError| {
            let (line, column) = pdyn_expr::error::line_col(&self.source, e.span.start);
            DeriveError {
                message: format!("loading the model's families in full: {}", e.message),
                help: e.help,
                location: Some((line as u32, column as u32)),
            }
        })?;
        for (new, old) in full.parameters.iter_mut().zip(&self.parameters) {
            new.value = old.value;
            if old.definition.is_none() {
                new.definition = None;
            }
        }
        crate::parameters::refresh_initial_values(&mut full);
        *self = full;
        Ok(())
    }

    /// Every deferred member's loads, potential energy and tension, substituted from its
    /// representative's (the representative's particles' coordinates and rates replaced by
    /// the member's) into this model's pool, after the other loads. Afterwards the model
    /// has no deferred families. The expressions equal [`super::load`]'s as functions, not
    /// necessarily node for node.
    pub fn materialize_deferred(&mut self) {
        let deferred = std::mem::take(&mut self.deferred);
        for d in &deferred {
            let pool = &mut self.pool;
            let rep_symbols: Vec<Vec<(usize, SymId)>> = d
                .ends
                .iter()
                .map(|&i| coordinate_symbols(pool, &self.particles[i as usize].position))
                .collect();
            let rep_loads: Vec<Load> = self.loads[d.first_load..d.first_load + d.loads].to_vec();
            let rep_potential = d.potential.map(|k| self.potentials[k].energy);
            let rep_axial = d.axial.map(|k| self.axial[k].tension);
            for member in d.each() {
                let mut map: FxHashMap<Id, Id> = FxHashMap::default();
                for (slot, &i) in member.iter().enumerate() {
                    let to = coordinate_symbols(pool, &self.particles[i as usize].position);
                    for (&(axis, from), &(axis_to, to)) in rep_symbols[slot].iter().zip(&to) {
                        debug_assert_eq!(axis, axis_to);
                        for order in 0..2 {
                            let a = pool.coord(from, order);
                            let b = pool.coord(to, order);
                            map.insert(a, b);
                        }
                    }
                }
                let names: Vec<&str> = member
                    .iter()
                    .map(|&i| self.particles[i as usize].name.as_str())
                    .collect();
                let pair = names.join(", ");
                for (k, load) in rep_loads.iter().enumerate() {
                    let on = member[k.min(member.len() - 1)] as usize;
                    let force = load.force.map(|f| pool.subs(f, &map));
                    self.loads.push(Load {
                        label: format!(
                            "{} ({pair}) on {}",
                            d.family,
                            names[k.min(names.len() - 1)]
                        ),
                        target: Target::Particle(on),
                        force,
                    });
                }
                if let Some(e) = rep_potential {
                    let energy = pool.subs(e, &map);
                    self.potentials.push(PotentialTerm {
                        label: d.family.clone(),
                        energy,
                    });
                }
                if let Some(e) = rep_axial {
                    let tension = pool.subs(e, &map);
                    self.axial.push(AxialForce {
                        label: format!("{} ({pair})", d.family),
                        tension,
                    });
                }
            }
        }
    }
}

/// What to do with one `[[forces]]` entry while loading with deferral.
pub(crate) enum Decision {
    /// A member of a family whose representative is built: recorded, nothing built.
    Deferred,
    /// The first member of its kind: build it, then [`Deferrer::represent`] it.
    Representative(Key, Vec<u32>),
    /// Build it as any force (not a family member, or not of a deferrable shape).
    Build,
}

/// The fields each deferrable kind may have (besides `kind` and `name`), and its ends.
fn deferrable_fields(raw: &RawForce) -> Option<&'static str> {
    let kind = raw.kind.as_ref()?.get_ref().as_str();
    let common_absent = raw.at.is_none()
        && raw.force.is_none()
        && raw.direction.is_none()
        && raw.length.is_none()
        && raw.coefficient.is_none()
        && raw.rho.is_none()
        && raw.cd.is_none()
        && raw.area.is_none()
        && raw.wind.is_none()
        && raw.strength.is_none()
        && raw.potential.is_none()
        && raw.mu.is_none()
        && raw.mu_s.is_none()
        && raw.mu_k.is_none()
        && raw.normal.is_none()
        && raw.tangent.is_none()
        && raw.mode.is_none()
        && raw.opposes.is_none()
        && raw.surface_velocity.is_none()
        && raw.normal_force.is_none()
        && raw.friction_force.is_none()
        && raw.one_sided.is_none();
    if !common_absent {
        return None;
    }
    let two_body = raw.between.is_some() && raw.on.is_none() && raw.to.is_none();
    match kind {
        "spring" if two_body && raw.c.is_none() => Some("spring"),
        "damper" if two_body && raw.k.is_none() && raw.l0.is_none() => Some("damper"),
        "linear_drag"
            if raw.on.is_some()
                && raw.between.is_none()
                && raw.to.is_none()
                && raw.k.is_none()
                && raw.l0.is_none() =>
        {
            Some("linear_drag")
        }
        _ => None,
    }
}

/// Whether an expression field is the same expression for every member: a number, or text
/// naming no index (`k`, `sqrt(2)*a`, not `k0*(1+i)` nor `k[i]`).
fn same_for_every_member(field: &Option<Sv>, indices: &[&str]) -> bool {
    match field.as_ref().map(|sv| sv.get_ref()) {
        None | Some(toml::Value::Integer(_)) | Some(toml::Value::Float(_)) => true,
        Some(toml::Value::String(text)) => {
            !text.contains('[') && identifiers(text).all(|name| !indices.contains(&name))
        }
        Some(_) => false,
    }
}

/// The identifiers in an expression's text.
fn identifiers(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| {
            w.chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
        })
}

/// The families found so far while reading `[[forces]]` with deferral.
#[derive(Default)]
pub(crate) struct Deferrer {
    /// The families, in order of their representatives.
    pub families: Vec<DeferredForces>,
    /// Per entry (its span's start), the shapes of each of its representatives and the
    /// family it leads (one in a uniform net).
    by_key: FxHashMap<usize, Vec<(Vec<Shape>, usize)>>,
    /// Per `[[forces]]` entry (its span's start): whether its members may be deferred.
    entry_ok: FxHashMap<usize, bool>,
    /// Each particle's [`shape`], found once: a chain's particle ends two springs, a net's
    /// eight (looking through its position's expressions each time was 23 of the 53 million
    /// instructions of reading a 10^4-mass chain's forces).
    shapes: FxHashMap<usize, Option<Shape>>,
}

impl Deferrer {
    /// Decides for a member of the family `f` (the file's entry) whose ends (`between`'s or
    /// `on`'s, [`ForceEntry::ends`]) are `ends`; `indices` gives the names of its indices and
    /// of every index (none: not a member), asked for at the entry's first member only.
    /// `particle` finds the particle an end names.
    pub fn decide<'n, 'e>(
        &mut self,
        pool: &Pool,
        particles: &[Particle],
        particle: impl Fn(End<'e>) -> Option<usize>,
        f: &Spanned<RawForce>,
        ends: Option<([End<'e>; 2], usize)>,
        indices: impl FnOnce() -> Vec<&'n str>,
    ) -> Decision {
        let raw = f.get_ref();
        let entry = f.span().start;
        let ok = match self.entry_ok.get(&entry) {
            Some(&ok) => ok,
            None => {
                let indices = indices();
                if indices.is_empty() {
                    return Decision::Build;
                }
                let ok = deferrable_fields(raw).is_some()
                    && [&raw.k, &raw.l0, &raw.c]
                        .iter()
                        .all(|field| same_for_every_member(field, &indices));
                self.entry_ok.insert(entry, ok);
                ok
            }
        };
        if !ok {
            return Decision::Build;
        }
        // One or two ends (the deferrable kinds have no more): on the stack, nothing
        // allocated for a member that joins its family's representative.
        let Some((names, n)) = ends else {
            return Decision::Build;
        };
        let mut ends = [0u32; 2];
        let mut shapes: [Shape; 2] = [(Pool::ZERO, [None; 3]); 2];
        for (k, &name) in names[..n].iter().enumerate() {
            let Some(i) = particle(name) else {
                return Decision::Build;
            };
            if ends[..k].contains(&(i as u32)) {
                // `between` joins a particle to itself: the build says so.
                return Decision::Build;
            }
            let s = self.shapes.entry(i).or_insert_with(|| {
                let p = &particles[i];
                shape(pool, p.mass, &p.position)
            });
            let Some(s) = *s else {
                return Decision::Build;
            };
            ends[k] = i as u32;
            shapes[k] = s;
        }
        if n != 2 && raw.between.is_some() {
            return Decision::Build;
        }
        let shapes = &shapes[..n];
        let known = self.by_key.get(&entry).and_then(|families| {
            families
                .iter()
                .find(|(s, _)| s.as_slice() == shapes)
                .map(|&(_, family)| family)
        });
        match known {
            Some(k) => {
                self.families[k].members.extend(&ends[..n]);
                Decision::Deferred
            }
            None => Decision::Representative((entry, shapes.to_vec()), ends[..n].to_vec()),
        }
    }

    /// Records the representative just built: its loads from `first_load` (`loads` of them),
    /// its potential and tension if it pushed one. A representative that pushed other than
    /// one load per particle is not one (its members are then built as it was).
    #[allow(clippy::too_many_arguments)]
    pub fn represent(
        &mut self,
        key: Key,
        ends: Vec<u32>,
        family: String,
        first_load: usize,
        loads: usize,
        potential: Option<usize>,
        axial: Option<usize>,
    ) {
        if loads != ends.len() {
            return;
        }
        let (entry, shapes) = key;
        self.by_key
            .entry(entry)
            .or_default()
            .push((shapes, self.families.len()));
        self.families.push(DeferredForces {
            family,
            first_load,
            loads,
            potential,
            axial,
            ends,
            members: Vec::new(),
        });
    }
}
