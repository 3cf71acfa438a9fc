//! Model files: a system of particles described the way the chapter does — parameters,
//! coordinates, position vectors, masses, forces, reactions, constraints — read from TOML into
//! symbolic form. See `docs/model-format.md` for the format.
//!
//! Loading resolves every name (with "did you mean" suggestions), checks shapes (vectors where
//! vectors belong), evaluates parameter values (with unit literals such as `"25 mph"`), and
//! turns each force declaration into loads on particles or massless frames. Every error carries
//! the file, line and column of the offending text.

pub mod constants;
mod contacts;
pub mod data;
pub mod deferred;
pub mod families;
mod family_initials;
mod forces;
pub mod index_expr;
mod index_program;
mod loader;
mod member_template;
pub(crate) mod raw;
mod row_tables;
pub mod spec;
mod tables;
mod unknown_initials;

pub use contacts::Contact;
pub use family_initials::InitialFamily;
pub(crate) use loader::Loader;
use pdyn_expr::error::render_diagnostic;
use pdyn_expr::{Id, Pool, SymId, Value};
use raw::RawModel;
use std::ops::Range;
pub use unknown_initials::UnknownInitial;

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
    /// The expression in earlier parameters it was defined by (`m = "4/3*pi*a^3*rho"`), if
    /// any: its value is recomputed from it whenever they change
    /// ([`crate::parameters::set_values`]).
    pub definition: Option<Id>,
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

/// The scalar force of a spring or damper along its line: positive in tension (pulling its
/// ends together), negative in compression. `pdyn equilibrium` reports it (a truss's bar
/// forces).
#[derive(Clone, Debug)]
pub struct AxialForce {
    /// `NAME (A, B)`: the entry's name (or family member) and its two ends.
    pub label: String,
    /// `k (l − l0)` of a spring, `c l'` of a damper.
    pub tension: Id,
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

/// A two-body force's pull on a fixed or moving point (a spring anchored at a pin): what the
/// support holding the point must react.
#[derive(Clone, Debug)]
pub struct PointLoad {
    /// Human-readable origin, e.g. `horizontal[i=0, j=0] (P[0,0], P[1,0]) on P[0,0]`.
    pub label: String,
    /// The point's name.
    pub point: String,
    /// The force on the point.
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
    /// `f(q, t)` meaning `f = 0` (or `f(q, q', t) = 0` when `derivatives` is 1).
    pub equation: Id,
    /// How often it is differentiated to enter the equations at acceleration level: 2 for a
    /// relation among coordinates, 1 for one among rates (a contact that sticks: its slip
    /// velocity is zero).
    pub derivatives: usize,
    /// Where it is written in the model file.
    pub span: Range<usize>,
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
    /// The two-body forces' pulls on points (the reactions of their supports are minus
    /// their sum).
    pub point_loads: Vec<PointLoad>,
    /// Unknown reaction magnitudes.
    pub reactions: Vec<Reaction>,
    /// Constraint equations.
    pub constraints: Vec<Constraint>,
    /// `[[contacts]]` and Coulomb `friction` forces: what may open, close, stick, slide and
    /// collide ([`crate::hybrid`]).
    pub contacts: Vec<Contact>,
    /// Potential energies of the conservative forces.
    pub potentials: Vec<PotentialTerm>,
    /// The tension of every spring and damper (a bar of a truss is a stiff spring).
    pub axial: Vec<AxialForce>,
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
    /// `(label, F·v_slip, |F| |v_slip|)` of each sliding friction whose direction was drawn
    /// by hand (`opposes`): a run warns when the power turns positive (friction driving the
    /// motion).
    pub friction_power: Vec<(String, Id, Id)>,
    /// Reactions that can only push (`one_sided = true`): a run warns when one pulls.
    pub one_sided: Vec<String>,
    /// `(coordinate index, initial value, initial rate)` as expressions of the parameters, so
    /// that a sweep over a parameter recomputes the initial conditions that depend on it.
    /// Family members leave this list to [`Model::initial_families`] in a model from
    /// [`load_deferring`]: [`Model::materialize_initials`] writes them in.
    pub initial_exprs: Vec<(usize, Id, Id)>,
    /// The coordinate families whose members' initial values and rates are one expression
    /// in the parameters and the indices ([`InitialFamily`]); empty from [`load`].
    pub initial_families: Vec<InitialFamily>,
    /// Initial values and rates written in `[unknowns]` (`rate = "omega"`): `pdyn forces`
    /// solves for them; their numeric copies in [`CoordinateKind::Free`] are NaN.
    pub unknown_initials: Vec<UnknownInitial>,
    /// Force families left unexpanded by [`load_deferring`] (empty from [`load`]): their
    /// members' loads, potentials and tensions are not in `loads`, `potentials`, `axial`.
    pub deferred: Vec<deferred::DeferredForces>,
}

/// Reads a model from TOML text. `origin` names it in error messages.
///
/// The tables are read in dependency order — each may use the names the earlier ones declared.
pub fn load(source: &str, origin: &str) -> Result<Model, ModelError> {
    let mut model = load_with(source, origin, false)?;
    model.materialize_initials();
    Ok(model)
}

/// [`load`], leaving the members of force families that share one representative's loads
/// unexpanded ([`deferred`]): for a consumer that reads [`Model::deferred`] (a run of free
/// particles), or calls [`Model::expand_deferred`] first. The same errors as [`load`]. The
/// initial values of coordinate families are left as [`Model::initial_families`] (numbers in
/// the coordinates, one expression per family): [`Model::materialize_initials`] writes each
/// member's into [`Model::initial_exprs`] for a consumer that reads those.
pub fn load_deferring(source: &str, origin: &str) -> Result<Model, ModelError> {
    load_with(source, origin, true)
}

fn load_with(source: &str, origin: &str, defer: bool) -> Result<Model, ModelError> {
    let raw: RawModel = toml::from_str(source).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        ModelError::new(origin, span, e.message().trim().to_string())
            .help("see docs/model-format.md for the tables a model file may contain")
    })?;
    let mut ld = Loader::new(origin, source);
    ld.defer = defer;
    let (raw, members) = families::expand(&mut ld, raw)?;
    ld.members = members;
    // An error met inside a family member names the member (`spring[i=3, j=19]: ...`).
    read(&mut ld, &raw).map_err(|e| ld.in_member(e))
}

fn read(ld: &mut Loader, raw: &RawModel) -> Result<Model, ModelError> {
    ld.read_data(raw)?;
    ld.read_parameters(raw)?;
    let unknowns = ld.read_unknowns(raw)?;
    ld.unknown_ids = unknowns.iter().map(|u| (u.name.clone(), u.id)).collect();
    ld.definition_names = raw
        .definitions
        .keys()
        .map(|k| k.get_ref().clone())
        .collect();
    let mut coords = ld.read_coordinates(raw)?;
    let definitions = ld.read_definitions(raw)?;
    ld.resolve_deferred_initials(&mut coords)?;
    let tables::Coordinates {
        coordinates,
        initial_exprs,
        known_accelerations,
    } = coords;
    let points = ld.read_points(raw)?;
    let particles = ld.read_particles(raw)?;
    let frames = ld.read_frames(raw, &particles)?;
    let forces::Built {
        friction_forces,
        contacts: mut friction_contacts,
        friction_power,
        one_sided,
        loads,
        point_loads,
        reactions,
        potentials,
        axial,
        conservative,
    } = ld.read_forces(raw, &particles, &frames, &points)?;
    let constraints = ld.read_constraints(raw)?;
    friction_contacts.extend(ld.read_contacts(raw, &particles, &reactions)?);
    let contacts = friction_contacts;
    let params = ld.params.clone();
    let run = spec::read(ld, raw, &params)?;
    let checks = spec::read_checks(ld, raw)?;
    if let Some(e) = ld.dimension_error() {
        return Err(e);
    }

    Ok(Model {
        run,
        initial_exprs,
        initial_families: std::mem::take(&mut ld.initial_families),
        unknown_initials: std::mem::take(&mut ld.unknown_initials),
        deferred: std::mem::take(&mut ld.deferred),
        unknowns,
        known_accelerations,
        checks,
        friction_forces,
        friction_power,
        one_sided,
        name: raw.name.clone().unwrap_or_else(|| ld.origin.to_string()),
        origin: ld.origin.to_string(),
        source: ld.source.to_string(),
        pool: std::mem::take(&mut ld.pool),
        parameters: std::mem::take(&mut ld.params),
        coordinates,
        definitions,
        points,
        particles,
        frames,
        loads,
        point_loads,
        reactions,
        constraints,
        contacts,
        potentials,
        axial,
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
