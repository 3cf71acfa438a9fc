//! The model file as written: TOML tables deserialised with their byte spans, before any name
//! is resolved. Every field is optional here; [`super::load`] checks what each kind needs and
//! reports what is missing at the right place.

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

/// A value with its span: a number, or a string holding an expression or a quantity.
pub type Sv = Spanned<toml::Value>;
/// A name with its span.
pub type Name = Spanned<String>;

/// A table of named entries that families expand (`[coordinates]`, `[points]`,
/// `[definitions]`, `[particles]`): 10^4 members' names are hashed into it, with FxHash (the
/// default SipHash was a sixth of expanding a chain's particles).
pub type Keyed<V> = IndexMap<Name, V, rustc_hash::FxBuildHasher>;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // `name`, `description` are read through serde only
pub struct RawModel {
    pub name: Option<String>,
    pub description: Option<String>,
    /// Uniform gravitational acceleration vector, applied to every particle.
    pub gravity: Option<Sv>,
    /// Sizes and index ranges of the families ([`super::families`]).
    #[serde(default)]
    pub indices: IndexMap<Name, Sv>,
    #[serde(default)]
    pub parameters: IndexMap<Name, Sv>,
    #[serde(default)]
    pub coordinates: Keyed<Sv>,
    #[serde(default)]
    pub definitions: Keyed<Sv>,
    #[serde(default)]
    pub points: Keyed<Sv>,
    #[serde(default)]
    pub particles: Keyed<Spanned<RawParticle>>,
    #[serde(default)]
    pub frames: IndexMap<Name, Spanned<RawFrame>>,
    #[serde(default)]
    pub forces: Vec<Spanned<RawForce>>,
    #[serde(default)]
    pub constraints: Vec<Spanned<RawConstraint>>,
    #[serde(default)]
    pub contacts: Vec<Spanned<RawContact>>,
    pub simulate: Option<Spanned<RawSimulate>>,
    #[serde(default)]
    pub events: Vec<Spanned<RawEvent>>,
    #[serde(default)]
    pub monitors: IndexMap<Name, Sv>,
    pub sweep: Option<Spanned<RawSweep>>,
    #[serde(default)]
    pub unknowns: IndexMap<Name, Spanned<RawUnknown>>,
    #[serde(default)]
    pub checks: Vec<Spanned<RawCheck>>,
    /// `[data.NAME]`: measured time series ([`super::data`]).
    #[serde(default)]
    pub data: IndexMap<Name, Spanned<RawData>>,
    /// `[tables.NAME]`: node and element tables that families run over
    /// ([`super::row_tables`]).
    #[serde(default)]
    pub tables: IndexMap<Name, Spanned<RawTable>>,
    /// After expansion ([`super::families::expand`]): the values the members of each family
    /// share (a member's own value in its table is a placeholder).
    #[serde(skip)]
    pub(crate) shared: super::families::SharedValues,
}

/// `[tables.NAME]`: a CSV (or Parquet) file of rows, one family member per row.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTable {
    /// The file, relative to the model file.
    pub file: Option<Spanned<String>>,
    /// The integer column that names the rows (`id`); without it a row is named by its
    /// 0-based number.
    pub key: Option<Name>,
    /// The columns read (default: every column; each must hold numbers).
    pub columns: Option<Spanned<Vec<Name>>>,
}

/// `[data.NAME]`: a CSV time series whose columns become functions of time.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawData {
    /// The CSV file, relative to the model file.
    pub file: Option<Spanned<String>>,
    /// The time column's name (default `t`).
    pub time: Option<Name>,
    /// The value columns used (default: every other column).
    pub columns: Option<Spanned<Vec<Name>>>,
    /// `linear` (default), `cubic` or `pchip`.
    pub interpolation: Option<Name>,
}

/// `[unknowns]`: a quantity to solve for in `pdyn forces` (thrust, bank angle...).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawUnknown {
    /// Search interval for a nonlinear unknown, `[lo, hi]` (expressions allowed).
    pub range: Option<Spanned<Vec<Sv>>>,
}

/// `[[checks]]`: a design criterion solved for a parameter.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCheck {
    pub name: Option<Name>,
    pub condition: Option<Sv>,
    pub solve_for: Option<Name>,
    pub range: Option<Spanned<Vec<Sv>>>,
    pub over: Option<Name>,
    pub from: Option<Sv>,
    pub to: Option<Sv>,
}

/// `[simulate]`: how `pdyn run` integrates (command-line options override it).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSimulate {
    pub t_end: Option<Sv>,
    pub method: Option<Name>,
    pub rtol: Option<Sv>,
    pub atol: Option<Sv>,
    pub dt: Option<Sv>,
    pub h0: Option<Sv>,
    pub max_step: Option<Sv>,
    pub max_steps: Option<Spanned<i64>>,
    pub points: Option<Spanned<i64>>,
    pub output_dt: Option<Sv>,
    pub drift_tolerance: Option<Sv>,
}

/// `[[events]]`: a zero crossing of `when`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEvent {
    pub name: Option<Name>,
    pub when: Option<Sv>,
    pub direction: Option<Name>,
    pub terminal: Option<Spanned<toml::Value>>,
    /// Assignments made when the event fires: `["y' = -e*y'", "thrust = 0"]`.
    pub set: Option<Spanned<Vec<Sv>>>,
}

/// `[sweep]`: runs over parameter values, with response measures.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSweep {
    pub parameter: Option<Name>,
    pub values: Option<Spanned<Vec<toml::Value>>>,
    pub from: Option<Sv>,
    pub to: Option<Sv>,
    pub steps: Option<Spanned<i64>>,
    #[serde(default)]
    pub measures: IndexMap<Name, Spanned<RawMeasure>>,
    /// More parameters, each a list of values or `{ from, to, steps }`: the runs cover the grid.
    #[serde(default)]
    pub also: IndexMap<Name, Sv>,
}

/// A response measure of a sweep: a statistic of an expression over each run.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMeasure {
    pub of: Option<Sv>,
    pub stat: Option<Name>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawParticle {
    pub mass: Option<Sv>,
    pub position: Option<Sv>,
    /// A family's ranges, when not those of `[indices]`.
    #[serde(rename = "for")]
    pub for_list: Option<Sv>,
    /// A family's condition: which members exist.
    #[serde(rename = "where")]
    pub condition: Option<Sv>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFrame {
    /// The particle the massless frame carries; moments are taken about it.
    pub particle: Option<Name>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConstraint {
    pub equation: Option<Sv>,
    pub name: Option<Name>,
}

/// One `[[forces]]` entry; which fields apply depends on `kind`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawForce {
    pub kind: Option<Name>,
    /// A family of forces: `"i in 0..n-2, j"`.
    #[serde(rename = "for")]
    pub for_list: Option<Sv>,
    /// Which members of the family exist: `"j > 0 or i != 0"`.
    #[serde(rename = "where")]
    pub condition: Option<Sv>,
    pub name: Option<Name>,
    pub on: Option<Name>,
    pub at: Option<Sv>,
    pub to: Option<Name>,
    pub between: Option<Spanned<Vec<Name>>>,
    pub force: Option<Sv>,
    pub direction: Option<Sv>,
    pub k: Option<Sv>,
    pub l0: Option<Sv>,
    pub length: Option<Sv>,
    pub c: Option<Sv>,
    pub coefficient: Option<Sv>,
    pub rho: Option<Sv>,
    pub cd: Option<Sv>,
    pub area: Option<Sv>,
    pub wind: Option<Sv>,
    pub strength: Option<Sv>,
    pub potential: Option<Sv>,
    pub mu: Option<Sv>,
    pub mu_s: Option<Sv>,
    pub mu_k: Option<Sv>,
    pub normal: Option<Sv>,
    pub tangent: Option<Sv>,
    pub mode: Option<Name>,
    pub opposes: Option<Sv>,
    pub surface_velocity: Option<Sv>,
    pub normal_force: Option<Name>,
    pub friction_force: Option<Name>,
    /// A reaction that can only push (a normal force): a run warns when it pulls.
    pub one_sided: Option<Spanned<bool>>,
}

/// `[[contacts]]`: a particle against a surface, or two particles, that may touch, separate,
/// stick, slide and collide.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawContact {
    pub name: Option<Name>,
    pub on: Option<Name>,
    pub between: Option<Spanned<Vec<Name>>>,
    /// `phi(r)`: apart where it is positive, touching where it is zero.
    pub surface: Option<Sv>,
    /// For `between`: the centre distance at contact (the sum of the radii).
    pub distance: Option<Sv>,
    pub e: Option<Sv>,
    pub mu: Option<Sv>,
    pub mu_s: Option<Sv>,
    pub mu_k: Option<Sv>,
    pub surface_velocity: Option<Sv>,
    pub normal_force: Option<Name>,
    pub friction_force: Option<Name>,
}
