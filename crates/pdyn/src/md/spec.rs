//! The `[md]` table of a model file, read with byte spans and resolved to numbers.
//!
//! Reading is two steps: serde turns the TOML into the raw tables below (every field optional,
//! unknown keys refused, spans kept), then [`parse`] evaluates every numeric field — a number
//! or an expression of `[parameters]`, after `--set` — and checks what each field needs,
//! reporting a [`ModelError`] at the offending text. Nothing here knows about particles or
//! forces: [`super::build`] turns an [`MdSpec`] into a simulation.

use indexmap::IndexMap;
use pdyn_mech::model::constants::Constants;
use pdyn_mech::ModelError;
use serde::Deserialize;
use std::ops::Range;
use toml::Spanned;

/// A value with its span (a number, or a string holding an expression).
type Sv = Spanned<toml::Value>;
/// A name with its span.
type Name = Spanned<String>;

/// Frames the RDF averages by default (`rdf_frames`).
pub const RDF_FRAMES: usize = 20;
/// Most frames `rdf_frames` may ask for: each is an all-pairs histogram of up to
/// [`super::run::RDF_MAX_ATOMS`] atoms.
pub const MAX_RDF_FRAMES: u64 = 100_000;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // `description` is read by serde only
struct RawFile {
    name: Option<String>,
    description: Option<String>,
    #[serde(default)]
    parameters: IndexMap<Name, Sv>,
    md: Spanned<RawMd>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMd {
    units: Option<Name>,
    dt: Option<Sv>,
    steps: Option<Sv>,
    thermo_every: Option<Sv>,
    dump_every: Option<Sv>,
    skin: Option<Sv>,
    overlap_distance: Option<Sv>,
    minimize: Option<Spanned<bool>>,
    rdf: Option<Spanned<bool>>,
    rdf_bins: Option<Sv>,
    rdf_frames: Option<Sv>,
    rdf_every: Option<Sv>,
    rdf_range: Option<Sv>,
    msd: Option<Spanned<bool>>,
    msd_every: Option<Sv>,
    equilibrate: Option<Sv>,
    #[serde(default)]
    species: IndexMap<Name, Spanned<RawSpecies>>,
    #[serde(default)]
    pairs: Vec<Spanned<RawPair>>,
    lattice: Option<Spanned<RawLattice>>,
    read: Option<Spanned<RawRead>>,
    velocities: Option<Spanned<RawVelocities>>,
    thermostat: Option<Spanned<RawThermostat>>,
    bonds: Option<Spanned<RawBonds>>,
    #[serde(default)]
    bond_types: Vec<Spanned<RawBonds>>,
    special_lj: Option<Spanned<Vec<Sv>>>,
    neighbor_every: Option<Sv>,
    neighbor_check: Option<Spanned<bool>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpecies {
    mass: Option<Sv>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPair {
    between: Option<Spanned<Vec<Name>>>,
    kind: Option<Name>,
    potential: Option<Sv>,
    epsilon: Option<Sv>,
    sigma: Option<Sv>,
    depth: Option<Sv>,
    alpha: Option<Sv>,
    r0: Option<Sv>,
    cutoff: Option<Sv>,
    mode: Option<Name>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLattice {
    kind: Option<Name>,
    density: Option<Sv>,
    constant: Option<Sv>,
    cells: Option<Sv>,
    species: Option<Name>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRead {
    file: Option<Name>,
    format: Option<Name>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVelocities {
    temperature: Option<Sv>,
    seed: Option<Sv>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawThermostat {
    kind: Option<Name>,
    temperature: Option<Sv>,
    final_temperature: Option<Sv>,
    damping: Option<Sv>,
    tau: Option<Sv>,
    chain: Option<Sv>,
    seed: Option<Sv>,
    scheme: Option<Name>,
    noise: Option<Name>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBonds {
    kind: Option<Name>,
    k: Option<Sv>,
    r0: Option<Sv>,
    r_max: Option<Sv>,
    epsilon: Option<Sv>,
    sigma: Option<Sv>,
    chain_length: Option<Sv>,
    #[serde(rename = "type")]
    bond_type: Option<Sv>,
}

/// A number read from the file, with the span of its text (for later, located, checks).
#[derive(Debug, Clone, PartialEq)]
pub struct Num {
    /// The value.
    pub value: f64,
    /// Where it was written (or the enclosing table when it was defaulted).
    pub span: Range<usize>,
}

/// Unit system of the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// Reduced Lennard-Jones units: σ, ε, m, τ = σ√(m/ε), k_B = 1.
    Lj,
    /// LAMMPS `real`: Å, kcal/mol, g/mol, fs, K; pressure in atm.
    Real,
}

impl Units {
    /// Name as written in files.
    pub fn name(self) -> &'static str {
        match self {
            Units::Lj => "lj",
            Units::Real => "real",
        }
    }
}

/// How a pair potential is given.
#[derive(Debug, Clone, PartialEq)]
pub enum PairKind {
    /// Built-in Lennard-Jones kernel.
    Lj {
        /// Well depth ε.
        epsilon: Num,
        /// Diameter σ.
        sigma: Num,
    },
    /// Built-in Morse kernel.
    Morse {
        /// Well depth D.
        depth: Num,
        /// Stiffness a.
        alpha: Num,
        /// Equilibrium distance r₀.
        r0: Num,
    },
    /// A formula in `r`: its text and the byte offset of that text in the file.
    Formula {
        /// The formula.
        text: String,
        /// Byte offset of `text` in the file.
        offset: usize,
        /// Span of the whole value.
        span: Range<usize>,
    },
}

/// Truncation at the cutoff (see `pdyn_md::potential::CutoffMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// `u(r)` as is.
    Plain,
    /// `u(r) − u(r_c)`.
    ShiftedEnergy,
    /// Energy and force both zero at `r_c`.
    ShiftedForce,
}

/// One `[[md.pairs]]` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct PairSpec {
    /// The two species (indices into [`MdSpec::species`]).
    pub between: [usize; 2],
    /// The potential.
    pub kind: PairKind,
    /// Cutoff radius.
    pub cutoff: Num,
    /// Truncation mode.
    pub mode: Mode,
    /// Span of the entry.
    pub span: Range<usize>,
}

/// A species.
#[derive(Debug, Clone, PartialEq)]
pub struct Species {
    /// Name.
    pub name: String,
    /// Mass.
    pub mass: Num,
}

/// Crystal lattice type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LatticeKind {
    /// Simple cubic.
    Sc,
    /// Body-centred cubic.
    Bcc,
    /// Face-centred cubic.
    Fcc,
}

/// Where the atoms start.
#[derive(Debug, Clone, PartialEq)]
pub enum Start {
    /// A lattice filling the box.
    Lattice {
        /// sc, bcc, fcc.
        kind: LatticeKind,
        /// Number density (computed from the lattice constant when that was given).
        density: Num,
        /// Unit cells along x, y, z.
        cells: [u64; 3],
        /// Species of every atom.
        species: usize,
        /// Span of the `[md.lattice]` table.
        span: Range<usize>,
    },
    /// A file.
    File {
        /// Path as written (relative to the model file).
        path: String,
        /// Extended XYZ or LAMMPS data.
        format: FileFormat,
        /// Span of `file = "..."`.
        span: Range<usize>,
    },
}

/// Configuration file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    /// Extended XYZ (first frame).
    Xyz,
    /// LAMMPS data file (atom_style atomic, bond, angle, molecular, full).
    LammpsData,
}

/// Thermostat choice.
#[derive(Debug, Clone, PartialEq)]
pub enum Ensemble {
    /// No thermostat.
    Nve,
    /// Langevin (BAOAB, or LAMMPS's `fix langevin` + `fix nve` with `scheme = "lammps"`).
    Langevin {
        /// Damping time 1/γ.
        damping: Num,
        /// Seed of the random forces.
        seed: u64,
        /// Integration scheme (`scheme = "baoab"` default, or `"lammps"` with
        /// `noise = "uniform"` default or `"gaussian"`).
        scheme: pdyn_md::thermostat::LangevinScheme,
    },
    /// Nosé–Hoover chain.
    NoseHoover {
        /// Relaxation time.
        tau: Num,
        /// Chain length.
        chain: usize,
    },
    /// Berendsen weak coupling.
    Berendsen {
        /// Relaxation time.
        tau: Num,
    },
}

/// `[md.thermostat]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermostatSpec {
    /// Which one.
    pub ensemble: Ensemble,
    /// Target temperature at the start (None only for NVE).
    pub temperature: Option<Num>,
    /// Target at the end of the run (linear ramp), if any.
    pub final_temperature: Option<Num>,
    /// Span of the table.
    pub span: Range<usize>,
}

/// Bond types.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BondSpecKind {
    /// `½ k (r − r₀)²`.
    Harmonic {
        /// Stiffness.
        k: f64,
        /// Rest length.
        r0: f64,
    },
    /// FENE `−½ k R₀² ln(1 − (r/R₀)²)`.
    Fene {
        /// Stiffness.
        k: f64,
        /// Maximum extension R₀.
        r_max: f64,
    },
    /// FENE plus the WCA repulsion `4ε[(σ/r)¹² − (σ/r)⁶] + ε` below `2^{1/6} σ` (LAMMPS's
    /// `bond_style fene`, `kind = "fene"` with `epsilon` and `sigma`).
    FeneWca {
        /// Stiffness.
        k: f64,
        /// Maximum extension R₀.
        r_max: f64,
        /// WCA energy.
        epsilon: f64,
        /// WCA length.
        sigma: f64,
    },
}

/// `[[md.bond_types]]`: the coefficients of one bond type of a LAMMPS data file.
#[derive(Debug, Clone, PartialEq)]
pub struct BondTypeSpec {
    /// The bond potential.
    pub kind: BondSpecKind,
    /// Span of the entry.
    pub span: Range<usize>,
}

/// `[md.bonds]`: atoms `0..L`, `L..2L`, … form linear chains of `chain_length` beads.
#[derive(Debug, Clone, PartialEq)]
pub struct BondsSpec {
    /// The bond potential.
    pub kind: BondSpecKind,
    /// Beads per chain.
    pub chain_length: u64,
    /// Span of the table.
    pub span: Range<usize>,
}

/// A resolved `[md]` model.
#[derive(Debug, Clone, PartialEq)]
pub struct MdSpec {
    /// Model name.
    pub name: String,
    /// The file name (for errors).
    pub origin: String,
    /// Units.
    pub units: Units,
    /// Time step (file units).
    pub dt: Num,
    /// Number of steps.
    pub steps: u64,
    /// Thermodynamic output interval (steps).
    pub thermo_every: u64,
    /// Trajectory frame interval (steps; 0 = none).
    pub dump_every: u64,
    /// Neighbour-list skin.
    pub skin: Num,
    /// Closest allowed distance at the start.
    pub overlap_distance: Option<Num>,
    /// Relax the start by FIRE before running.
    pub minimize: bool,
    /// Radial distribution function post-processing.
    pub rdf: bool,
    /// Histogram bins of the RDF.
    pub rdf_bins: usize,
    /// Frames the RDF averages, equally spaced over the thermo records of the second half of
    /// the run (`rdf_frames`, default [`RDF_FRAMES`]; fewer when there are fewer records).
    pub rdf_frames: usize,
    /// A frame every this many steps of the second half of the run (`rdf_every`), instead of
    /// the `rdf_frames` thermo records.
    pub rdf_every: Option<u64>,
    /// Largest distance of the RDF (`rdf_range`, default half the shortest box edge, which is
    /// also its upper limit).
    pub rdf_range: Option<Num>,
    /// Mean-squared displacement post-processing.
    pub msd: bool,
    /// Steps between MSD samples (`msd_every`, default `thermo_every`).
    pub msd_every: u64,
    /// Records before this step are left out of the averages (equilibration).
    pub equilibrate: u64,
    /// Species in declaration order.
    pub species: Vec<Species>,
    /// Pair potentials.
    pub pairs: Vec<PairSpec>,
    /// Initial configuration.
    pub start: Start,
    /// Maxwell–Boltzmann temperature and seed, if velocities are drawn.
    pub velocities: Option<(Num, u64)>,
    /// Thermostat.
    pub thermostat: ThermostatSpec,
    /// Bonds.
    pub bonds: Option<BondsSpec>,
    /// Coefficients of the bond types of a data file, by type (`[[md.bond_types]]`).
    pub bond_types: Vec<BondTypeSpec>,
    /// Pair-interaction factors of 1-2, 1-3, 1-4 bonded neighbours (`special_lj`, LAMMPS
    /// `special_bonds lj`; default `[1, 1, 1]`), and where they were written.
    pub special_lj: ([f64; 3], Range<usize>),
    /// The neighbour list is considered every this many steps (`neighbor_every`, default 1).
    pub neighbor_every: u64,
    /// Rebuild only when the exact displacement check asks (`neighbor_check`, default true);
    /// false rebuilds at every considered step without checking (LAMMPS `check no`).
    pub neighbor_check: bool,
    /// Parameters (name, value) after `--set`, for formulas.
    pub parameters: Vec<(String, f64)>,
    /// Span of `[md]` (for errors about the whole table).
    pub span: Range<usize>,
}

/// Most atoms a model may ask for (a lattice's cells are checked against it before anything
/// is allocated): 50 million atoms need about 10 GB.
pub const MAX_ATOMS: u64 = 50_000_000;

/// Most steps of one run.
pub const MAX_STEPS: u64 = 1_000_000_000_000;

/// Reads the `[md]` table of `source`; `overrides` are `--set name=value` pairs for
/// `[parameters]`, applied before anything is evaluated (names that are not parameters are
/// ignored here: the caller compares them with [`MdSpec::parameters`]).
pub fn parse(
    source: &str,
    origin: &str,
    overrides: &[(String, f64)],
) -> Result<MdSpec, ModelError> {
    let raw: RawFile = toml::from_str(source).map_err(|e| {
        ModelError::new(
            origin,
            e.span().unwrap_or(0..0),
            e.message().trim().to_string(),
        )
        .help("see docs/md.md for the keys of a molecular-dynamics model")
    })?;
    let mut r = Resolver {
        c: Constants::new(source, origin),
        values: vec![],
    };
    for (name, sv) in &raw.parameters {
        let n = name.get_ref();
        if r.values.iter().any(|(m, _)| m == n) {
            return Err(r.err(name.span(), format!("duplicate parameter `{n}`")));
        }
        if n == "r" {
            return Err(r
                .err(name.span(), "`r` cannot be a parameter name")
                .help("`r` is the pair distance in potential formulas"));
        }
        r.refuse_units(sv, "a parameter")?;
        let given = overrides.iter().find(|(k, _)| k == n).map(|(_, v)| *v);
        let value = r.c.parameter(name, sv, given)?;
        r.values.push((n.clone(), value));
    }
    let md = &raw.md;
    let m = md.get_ref();
    let units = match &m.units {
        None => Units::Lj,
        Some(u) => match u.get_ref().as_str() {
            "lj" => Units::Lj,
            "real" => Units::Real,
            other => {
                return Err(r
                    .err(u.span(), format!("unknown units `{other}`"))
                    .help("units are \"lj\" (reduced) or \"real\" (Å, kcal/mol, g/mol, fs, K)"))
            }
        },
    };
    let mspan = md.span();
    let dt = r.positive_or(&m.dt, "dt", &mspan, None)?;
    let steps = r.count_or(&m.steps, "steps", &mspan, None, MAX_STEPS)?;
    let thermo_every = match &m.thermo_every {
        Some(sv) => r.count(sv, "thermo_every", 1, MAX_STEPS)?,
        // about 10 lines of thermo by default
        None => (steps / 10).max(1),
    };
    let dump_every = r.count_or(&m.dump_every, "dump_every", &mspan, Some(0), MAX_STEPS)?;
    let skin = match &m.skin {
        Some(sv) => r.nonneg(sv, "skin")?,
        None => Num {
            value: if units == Units::Real { 2.0 } else { 0.3 },
            span: mspan.clone(),
        },
    };
    let overlap_distance = m
        .overlap_distance
        .as_ref()
        .map(|sv| r.positive(sv, "overlap_distance"))
        .transpose()?;
    let rdf_bins = r.count_or(&m.rdf_bins, "rdf_bins", &mspan, Some(100), 1 << 20)? as usize;
    let rdf_bins = rdf_bins.max(1);
    let rdf_frames = r.count_or(
        &m.rdf_frames,
        "rdf_frames",
        &mspan,
        Some(RDF_FRAMES as u64),
        MAX_RDF_FRAMES,
    )?;
    if rdf_frames == 0 {
        let span = m.rdf_frames.as_ref().map_or(mspan.clone(), |sv| sv.span());
        return Err(r.err(span, "`rdf_frames` must be at least 1"));
    }
    let rdf_frames = rdf_frames as usize;
    let rdf_every = m
        .rdf_every
        .as_ref()
        .map(|sv| r.count(sv, "rdf_every", 1, MAX_STEPS))
        .transpose()?;
    if let (Some(_), Some(sv)) = (rdf_every, &m.rdf_frames) {
        return Err(r
            .err(sv.span(), "both `rdf_every` and `rdf_frames`: they are two ways to choose the RDF's frames")
            .help("keep `rdf_every` (a frame every so many steps) or `rdf_frames` (that many thermo records)"));
    }
    let rdf_range = m
        .rdf_range
        .as_ref()
        .map(|sv| r.positive(sv, "rdf_range"))
        .transpose()?;
    let msd_every = match &m.msd_every {
        Some(sv) => r.count(sv, "msd_every", 1, MAX_STEPS)?,
        None => thermo_every,
    };
    let equilibrate = r.count_or(&m.equilibrate, "equilibrate", &mspan, Some(0), MAX_STEPS)?;

    if m.species.is_empty() {
        return Err(r
            .err(mspan.clone(), "an [md] model needs at least one species")
            .help("add e.g. `[md.species.Ar]` with `mass = 1.0`"));
    }
    let mut species = vec![];
    for (name, sp) in &m.species {
        let mass = match &sp.get_ref().mass {
            Some(sv) => r.positive(sv, "mass")?,
            None => {
                return Err(r.err(
                    sp.span(),
                    format!("species `{}` needs a `mass`", name.get_ref()),
                ))
            }
        };
        species.push(Species {
            name: name.get_ref().clone(),
            mass,
        });
    }
    let species_index = |r: &Resolver, n: &Name| -> Result<usize, ModelError> {
        species
            .iter()
            .position(|s| &s.name == n.get_ref())
            .ok_or_else(|| {
                let names: Vec<&str> = species.iter().map(|s| s.name.as_str()).collect();
                r.err(n.span(), format!("unknown species `{}`", n.get_ref()))
                    .help(format!("species declared: {}", names.join(", ")))
            })
    };

    if m.pairs.is_empty() {
        return Err(r
            .err(
                mspan.clone(),
                "an [md] model needs at least one [[md.pairs]] potential",
            )
            .help("e.g. kind = \"lj\", epsilon = 1, sigma = 1, cutoff = 2.5"));
    }
    let mut pairs: Vec<PairSpec> = vec![];
    for p in &m.pairs {
        let span = p.span();
        let q = p.get_ref();
        let between = match &q.between {
            Some(b) => {
                if b.get_ref().len() != 2 {
                    return Err(r.err(b.span(), "`between` names two species, e.g. [\"A\", \"B\"]"));
                }
                [
                    species_index(&r, &b.get_ref()[0])?,
                    species_index(&r, &b.get_ref()[1])?,
                ]
            }
            None if species.len() == 1 => [0, 0],
            None => {
                return Err(r.err(
                    span.clone(),
                    "with several species, each pair potential needs `between = [\"A\", \"B\"]`",
                ))
            }
        };
        if let Some(prev) = pairs
            .iter()
            .find(|o| o.between == between || o.between == [between[1], between[0]])
        {
            let (line, _) = pdyn_expr::error::line_col(source, prev.span.start);
            return Err(r.err(
                span,
                format!(
                    "a second potential between {} and {} (the first is at line {line})",
                    species[between[0]].name, species[between[1]].name
                ),
            ));
        }
        let kind = match (&q.kind, &q.potential) {
            (Some(_), Some(f)) => {
                return Err(r
                    .err(f.span(), "give either `kind` (a built-in kernel) or `potential` (a formula), not both"))
            }
            (None, None) => {
                return Err(r
                    .err(span, "a pair potential needs `kind` (\"lj\", \"morse\") or `potential` (a formula in r)"))
            }
            (None, Some(f)) => {
                let toml::Value::String(text) = f.get_ref() else {
                    return Err(r.err(f.span(), "`potential` is a formula in quotes, e.g. \"4*eps*((sigma/r)^12 - (sigma/r)^6)\""));
                };
                let off = f.span().start + quote_len(&source[f.span().start..]);
                PairKind::Formula {
                    text: text.clone(),
                    offset: off,
                    span: f.span(),
                }
            }
            (Some(k), None) => match k.get_ref().as_str() {
                "lj" | "lennard-jones" => PairKind::Lj {
                    epsilon: r.required_positive(&q.epsilon, "epsilon", &span, "lj")?,
                    sigma: r.required_positive(&q.sigma, "sigma", &span, "lj")?,
                },
                "morse" => PairKind::Morse {
                    depth: r.required_positive(&q.depth, "depth", &span, "morse")?,
                    alpha: r.required_positive(&q.alpha, "alpha", &span, "morse")?,
                    r0: r.required_positive(&q.r0, "r0", &span, "morse")?,
                },
                other => {
                    return Err(r
                        .err(k.span(), format!("unknown pair kind `{other}`"))
                        .help("built-in kinds are \"lj\" and \"morse\"; any other potential can be a formula: potential = \"...\""))
                }
            },
        };
        // Keys of the other kinds are mistakes, not silently ignored values.
        let stray: &[(&Option<Sv>, &str)] = match &kind {
            PairKind::Lj { .. } => &[(&q.depth, "depth"), (&q.alpha, "alpha"), (&q.r0, "r0")],
            PairKind::Morse { .. } => &[(&q.epsilon, "epsilon"), (&q.sigma, "sigma")],
            PairKind::Formula { .. } => &[
                (&q.epsilon, "epsilon"),
                (&q.sigma, "sigma"),
                (&q.depth, "depth"),
                (&q.alpha, "alpha"),
                (&q.r0, "r0"),
            ],
        };
        for (v, key) in stray {
            if let Some(sv) = v {
                return Err(r.err(sv.span(), format!("`{key}` does not belong to this kind of potential")).help(
                    "formulas take their constants from [parameters]; lj takes epsilon, sigma; morse takes depth, alpha, r0",
                ));
            }
        }
        let cutoff = match &q.cutoff {
            Some(sv) => r.positive(sv, "cutoff")?,
            None => {
                return Err(r.err(
                    span,
                    "a pair potential needs a `cutoff` (e.g. \"2.5*sigma\")",
                ))
            }
        };
        let mode = match &q.mode {
            None => Mode::Plain,
            Some(mo) => match mo.get_ref().as_str() {
                "plain" | "cut" => Mode::Plain,
                "shift" | "shifted" | "shifted-energy" => Mode::ShiftedEnergy,
                "shifted-force" | "force-shift" => Mode::ShiftedForce,
                other => {
                    return Err(r
                        .err(mo.span(), format!("unknown cutoff mode `{other}`"))
                        .help("modes: \"plain\", \"shifted-energy\", \"shifted-force\""))
                }
            },
        };
        pairs.push(PairSpec {
            between,
            kind,
            cutoff,
            mode,
            span: p.span(),
        });
    }
    for a in 0..species.len() {
        for b in a..species.len() {
            if !pairs
                .iter()
                .any(|p| p.between == [a, b] || p.between == [b, a])
            {
                return Err(r
                    .err(
                        mspan.clone(),
                        format!(
                            "no pair potential between {} and {}",
                            species[a].name, species[b].name
                        ),
                    )
                    .help("every pair of species needs one [[md.pairs]] entry"));
            }
        }
    }

    let start = match (&m.lattice, &m.read) {
        (Some(_), Some(rd)) => {
            return Err(r.err(rd.span(), "give either [md.lattice] or [md.read], not both"))
        }
        (None, None) => {
            return Err(r
                .err(mspan.clone(), "no initial configuration")
                .help("add [md.lattice] (kind, density or constant, cells) or [md.read] (file)"))
        }
        (Some(l), None) => {
            let q = l.get_ref();
            let span = l.span();
            let kind = match &q.kind {
                None => {
                    return Err(r.err(span, "[md.lattice] needs `kind` (\"sc\", \"bcc\", \"fcc\")"))
                }
                Some(k) => match k.get_ref().as_str() {
                    "sc" => LatticeKind::Sc,
                    "bcc" => LatticeKind::Bcc,
                    "fcc" => LatticeKind::Fcc,
                    other => {
                        return Err(r
                            .err(k.span(), format!("unknown lattice `{other}`"))
                            .help("lattices: \"sc\", \"bcc\", \"fcc\""))
                    }
                },
            };
            let basis = match kind {
                LatticeKind::Sc => 1.0,
                LatticeKind::Bcc => 2.0,
                LatticeKind::Fcc => 4.0,
            };
            let density = match (&q.density, &q.constant) {
                (Some(d), None) => r.positive(d, "density")?,
                (None, Some(a)) => {
                    let a = r.positive(a, "constant")?;
                    Num {
                        value: basis / a.value.powi(3),
                        span: a.span,
                    }
                }
                (Some(_), Some(a)) => {
                    return Err(r.err(a.span(), "give either `density` or `constant` (lattice constant), not both"))
                }
                (None, None) => {
                    return Err(r.err(span, "[md.lattice] needs `density` (number density) or `constant` (lattice constant)"))
                }
            };
            let cells = match &q.cells {
                None => {
                    return Err(r.err(
                        span,
                        "[md.lattice] needs `cells` (a count, or [nx, ny, nz])",
                    ))
                }
                Some(sv) => match sv.get_ref() {
                    toml::Value::Array(items) => {
                        if items.len() != 3 {
                            return Err(
                                r.err(sv.span(), "`cells` is one count or three, [nx, ny, nz]")
                            );
                        }
                        let mut c = [0; 3];
                        for (k, it) in items.iter().enumerate() {
                            // array items have no spans of their own: errors point at the array
                            let item = Spanned::new(sv.span(), it.clone());
                            c[k] = r.count(&item, "cells", 1, MAX_ATOMS)?;
                        }
                        c
                    }
                    _ => [r.count(sv, "cells", 1, MAX_ATOMS)?; 3],
                },
            };
            let n = cells
                .iter()
                .try_fold(basis as u64, |a, &c| a.checked_mul(c))
                .filter(|&n| n <= MAX_ATOMS);
            if n.is_none() {
                let at = q.cells.as_ref().map_or(span.clone(), |c| c.span());
                return Err(r.err(
                    at,
                    format!(
                        "{} × {} × {} cells of {} atoms is more than {MAX_ATOMS} atoms",
                        cells[0], cells[1], cells[2], basis as u64
                    ),
                ));
            }
            let sp = match &q.species {
                Some(n) => species_index(&r, n)?,
                None if species.len() == 1 => 0,
                None => {
                    return Err(r.err(span, "with several species, [md.lattice] needs `species`"))
                }
            };
            Start::Lattice {
                kind,
                density,
                cells,
                species: sp,
                span,
            }
        }
        (None, Some(rd)) => {
            let q = rd.get_ref();
            let Some(file) = &q.file else {
                return Err(r.err(
                    rd.span(),
                    "[md.read] needs `file` (extended XYZ or LAMMPS data)",
                ));
            };
            let path = file.get_ref().clone();
            let format = match &q.format {
                Some(f) => match f.get_ref().as_str() {
                    "xyz" | "extxyz" => FileFormat::Xyz,
                    "lammps-data" | "data" => FileFormat::LammpsData,
                    other => {
                        return Err(r
                            .err(f.span(), format!("unknown format `{other}`"))
                            .help("formats: \"xyz\" (extended XYZ), \"lammps-data\""))
                    }
                },
                None if path.ends_with(".xyz") || path.ends_with(".extxyz") => FileFormat::Xyz,
                None if path.ends_with(".data")
                    || path.ends_with(".lmp")
                    || path.contains("data.") =>
                {
                    FileFormat::LammpsData
                }
                None => {
                    return Err(r
                        .err(
                            file.span(),
                            format!("cannot tell the format of `{path}` from its name"),
                        )
                        .help("add format = \"xyz\" or format = \"lammps-data\""))
                }
            };
            Start::File {
                path,
                format,
                span: file.span(),
            }
        }
    };

    let velocities = match &m.velocities {
        None => None,
        Some(v) => {
            let q = v.get_ref();
            let t = match &q.temperature {
                Some(sv) => r.nonneg(sv, "temperature")?,
                None => return Err(r.err(v.span(), "[md.velocities] needs `temperature`")),
            };
            let seed = r.count_or(&q.seed, "seed", &v.span(), Some(1), u64::MAX)?;
            Some((t, seed))
        }
    };

    let thermostat = match &m.thermostat {
        None => ThermostatSpec {
            ensemble: Ensemble::Nve,
            temperature: None,
            final_temperature: None,
            span: mspan.clone(),
        },
        Some(t) => {
            let q = t.get_ref();
            let span = t.span();
            let kind = q.kind.as_ref().map_or("nve", |k| k.get_ref().as_str());
            let kspan = q.kind.as_ref().map_or(span.clone(), |k| k.span());
            let ensemble = match kind {
                "nve" | "none" => Ensemble::Nve,
                "langevin" => Ensemble::Langevin {
                    damping: r.positive_or(
                        &q.damping,
                        "damping",
                        &span,
                        Some(if units == Units::Real { 100.0 } else { 1.0 }),
                    )?,
                    seed: r.count_or(&q.seed, "seed", &span, Some(1), u64::MAX)?,
                    scheme: langevin_scheme(&r, q)?,
                },
                "nose-hoover" | "nvt" => Ensemble::NoseHoover {
                    tau: r.positive_or(
                        &q.tau,
                        "tau",
                        &span,
                        Some(if units == Units::Real { 100.0 } else { 0.5 }),
                    )?,
                    chain: r.count_or(&q.chain, "chain", &span, Some(3), 64)?.max(1) as usize,
                },
                "berendsen" => Ensemble::Berendsen {
                    tau: r.positive_or(
                        &q.tau,
                        "tau",
                        &span,
                        Some(if units == Units::Real { 100.0 } else { 0.5 }),
                    )?,
                },
                other => {
                    return Err(r.err(kspan, format!("unknown thermostat `{other}`")).help(
                        "thermostats: \"nve\", \"langevin\", \"nose-hoover\", \"berendsen\"",
                    ))
                }
            };
            if !matches!(ensemble, Ensemble::Langevin { .. }) {
                if let Some(k) = q.scheme.as_ref().or(q.noise.as_ref()) {
                    let key = if q.scheme.is_some() {
                        "scheme"
                    } else {
                        "noise"
                    };
                    return Err(r
                        .err(
                            k.span(),
                            format!("`{key}` applies to the Langevin thermostat only"),
                        )
                        .help("set kind = \"langevin\", or remove the key"));
                }
            }
            let temperature = q
                .temperature
                .as_ref()
                .map(|sv| r.positive(sv, "temperature"))
                .transpose()?;
            let final_temperature = q
                .final_temperature
                .as_ref()
                .map(|sv| r.positive(sv, "final_temperature"))
                .transpose()?;
            if ensemble != Ensemble::Nve && temperature.is_none() {
                return Err(r
                    .err(
                        kspan,
                        format!("the {kind} thermostat needs a `temperature`"),
                    )
                    .help("add temperature = ... to [md.thermostat] (the target temperature)"));
            }
            if ensemble == Ensemble::Nve {
                for (v, key) in [
                    (&q.temperature, "temperature"),
                    (&q.final_temperature, "final_temperature"),
                    (&q.damping, "damping"),
                    (&q.tau, "tau"),
                ] {
                    if let Some(sv) = v {
                        return Err(r
                            .err(
                                sv.span(),
                                format!(
                                    "`{key}` has no meaning without a thermostat (kind = \"nve\")"
                                ),
                            )
                            .help("set kind = \"langevin\", \"nose-hoover\" or \"berendsen\""));
                    }
                }
            }
            ThermostatSpec {
                ensemble,
                temperature,
                final_temperature,
                span,
            }
        }
    };

    let bonds = match &m.bonds {
        None => None,
        Some(b) => {
            let q = b.get_ref();
            let span = b.span();
            if let Some(t) = &q.bond_type {
                return Err(r
                    .err(t.span(), "`type` belongs to [[md.bond_types]], not [md.bonds]")
                    .help("[md.bonds] makes chains of consecutive atoms; the bond types of a data file are [[md.bond_types]]"));
            }
            let kind = bond_kind(&mut r, q, &span, "[md.bonds]")?;
            let chain_length = match &q.chain_length {
                Some(sv) => r.count(sv, "chain_length", 2, MAX_ATOMS)?,
                None => {
                    return Err(r
                        .err(span, "[md.bonds] needs `chain_length` (beads per chain)")
                        .help("bonds listed in a LAMMPS data file take their coefficients from [[md.bond_types]] instead"))
                }
            };
            Some(BondsSpec {
                kind,
                chain_length,
                span,
            })
        }
    };
    let mut bond_types = vec![];
    for (k, b) in m.bond_types.iter().enumerate() {
        let q = b.get_ref();
        let span = b.span();
        if let Some(sv) = &q.chain_length {
            return Err(r
                .err(sv.span(), "`chain_length` belongs to [md.bonds]: [[md.bond_types]] gives the coefficients of a data file's bonds")
                .help("remove it"));
        }
        if let Some(sv) = &q.bond_type {
            let t = r.count(sv, "type", 1, MAX_ATOMS)?;
            if t != k as u64 + 1 {
                return Err(r
                    .err(
                        sv.span(),
                        format!(
                            "this is entry {} of [[md.bond_types]], so its type is {}",
                            k + 1,
                            k + 1
                        ),
                    )
                    .help("list the bond types in order 1, 2, …"));
            }
        }
        let kind = bond_kind(&mut r, q, &span, "[[md.bond_types]]")?;
        bond_types.push(BondTypeSpec { kind, span });
    }
    if bonds.is_some() && !bond_types.is_empty() {
        return Err(r
            .err(
                m.bond_types[0].span(),
                "both [md.bonds] (generated chains) and [[md.bond_types]] (a data file's bonds)",
            )
            .help("keep one: chains of consecutive atoms, or the bonds of the data file"));
    }
    let special_lj = match &m.special_lj {
        None => ([1.0; 3], mspan.clone()),
        Some(v) => {
            let span = v.span();
            if v.get_ref().len() != 3 {
                return Err(r
                    .err(
                        span,
                        "`special_lj` has three factors: 1-2, 1-3 and 1-4 neighbours",
                    )
                    .help("e.g. special_lj = [0, 1, 1] (LAMMPS `special_bonds lj 0 1 1`)"));
            }
            let mut f = [1.0; 3];
            for (k, sv) in v.get_ref().iter().enumerate() {
                let x = r.nonneg(sv, "special_lj")?;
                if x.value > 1.0 {
                    return Err(r.err(
                        sv.span(),
                        format!("a factor of {} (factors are 0 to 1)", x.value),
                    ));
                }
                f[k] = x.value;
            }
            (f, span)
        }
    };
    let neighbor_every = r.count_or(
        &m.neighbor_every,
        "neighbor_every",
        &mspan,
        Some(1),
        MAX_STEPS,
    )?;
    if neighbor_every == 0 {
        let span = m
            .neighbor_every
            .as_ref()
            .map_or(mspan.clone(), |sv| sv.span());
        return Err(r.err(span, "`neighbor_every` must be at least 1"));
    }
    let neighbor_check = m.neighbor_check.as_ref().is_none_or(|b| *b.get_ref());

    Ok(MdSpec {
        name: raw.name.clone().unwrap_or_else(|| origin.to_string()),
        origin: origin.to_string(),
        units,
        dt,
        steps,
        thermo_every,
        dump_every,
        skin,
        overlap_distance,
        minimize: m.minimize.as_ref().is_some_and(|b| *b.get_ref()),
        rdf: m.rdf.as_ref().is_some_and(|b| *b.get_ref()),
        rdf_bins,
        rdf_frames,
        rdf_every,
        rdf_range,
        msd: m.msd.as_ref().is_some_and(|b| *b.get_ref()),
        msd_every,
        equilibrate,
        species,
        pairs,
        start,
        velocities,
        thermostat,
        bonds,
        bond_types,
        special_lj,
        neighbor_every,
        neighbor_check,
        parameters: r.values,
        span: mspan,
    })
}

/// The potential of a `[md.bonds]` or `[[md.bond_types]]` entry (`table` names it in errors).
fn bond_kind(
    r: &mut Resolver,
    q: &RawBonds,
    span: &Range<usize>,
    table: &str,
) -> Result<BondSpecKind, ModelError> {
    let wca = |r: &mut Resolver, which: &str| -> Result<(), ModelError> {
        for (key, v) in [("epsilon", &q.epsilon), ("sigma", &q.sigma)] {
            if let Some(sv) = v {
                return Err(r
                    .err(
                        sv.span(),
                        format!("`{key}` has no meaning for a {which} bond"),
                    )
                    .help("epsilon and sigma add LAMMPS's WCA term to a \"fene\" bond"));
            }
        }
        Ok(())
    };
    Ok(
        match q.kind.as_ref().map(|k| (k.get_ref().as_str(), k.span())) {
            Some(("harmonic", _)) => {
                wca(r, "harmonic")?;
                BondSpecKind::Harmonic {
                    k: r.required_positive(&q.k, "k", span, "harmonic")?.value,
                    r0: r.required_positive(&q.r0, "r0", span, "harmonic")?.value,
                }
            }
            Some(("fene", _)) => {
                let k = r.required_positive(&q.k, "k", span, "fene")?.value;
                let r_max = r.required_positive(&q.r_max, "r_max", span, "fene")?.value;
                match (&q.epsilon, &q.sigma) {
                (None, None) => BondSpecKind::Fene { k, r_max },
                (Some(e), Some(sg)) => BondSpecKind::FeneWca {
                    k,
                    r_max,
                    epsilon: r.positive(e, "epsilon")?.value,
                    sigma: r.positive(sg, "sigma")?.value,
                },
                (Some(sv), None) | (None, Some(sv)) => {
                    return Err(r
                        .err(sv.span(), "a FENE bond's WCA term needs both `epsilon` and `sigma`")
                        .help("LAMMPS `bond_coeff 1 30.0 1.5 1.0 1.0` is k = 30, r_max = 1.5, epsilon = 1, sigma = 1"))
                }
            }
            }
            Some((other, ks)) => return Err(r
                .err(ks, format!("unknown bond kind `{other}`"))
                .help(
                "bond kinds: \"harmonic\" (k, r0), \"fene\" (k, r_max, optional epsilon and sigma)",
            )),
            None => {
                return Err(r.err(
                    span.clone(),
                    format!("{table} needs `kind` (\"harmonic\" or \"fene\")"),
                ))
            }
        },
    )
}

/// Length of the opening quote of a TOML string at the start of `raw`.
fn quote_len(raw: &str) -> usize {
    if raw.starts_with("\"\"\"") || raw.starts_with("'''") {
        3
    } else {
        1
    }
}

/// Evaluates the numeric fields of `[md]` with pdyn-mech's [`Constants`] (the reader of every
/// model kind: numbers, expressions of `[parameters]`, `pi`, located errors), refusing unit
/// literals: an MD model's units are reduced (`lj`) or `real`, never SI.
struct Resolver<'a> {
    c: Constants<'a>,
    /// The parameters' names and values, in file order (after `--set`).
    values: Vec<(String, f64)>,
}

impl Resolver<'_> {
    fn err(&self, span: Range<usize>, msg: impl Into<String>) -> ModelError {
        self.c.err(span, msg)
    }

    /// A unit literal (`"3.4 angstrom"`) would be converted to SI, which an MD model is not in.
    fn refuse_units(&self, sv: &Sv, what: &str) -> Result<(), ModelError> {
        match self.c.unit_literal(sv) {
            Some(text) => Err(self
                .err(sv.span(), format!("{what}: `{text}` carries a unit"))
                .help("an [md] model is in the units of `units` (\"lj\" reduced, or \"real\": Å, kcal/mol, g/mol, fs, K); write plain numbers")),
            None => Ok(()),
        }
    }

    /// A numeric field's finite value.
    fn number(&mut self, sv: &Sv, what: &str) -> Result<f64, ModelError> {
        self.refuse_units(sv, what)?;
        let v = self.c.scalar(sv, what)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(sv.span(), format!("{what} evaluates to {v}")))
        }
    }

    fn positive(&mut self, sv: &Sv, what: &str) -> Result<Num, ModelError> {
        let v = self.number(sv, what)?;
        if v > 0.0 {
            Ok(Num {
                value: v,
                span: sv.span(),
            })
        } else {
            Err(self.err(sv.span(), format!("`{what}` must be > 0, got {v}")))
        }
    }

    fn nonneg(&mut self, sv: &Sv, what: &str) -> Result<Num, ModelError> {
        let v = self.number(sv, what)?;
        if v >= 0.0 {
            Ok(Num {
                value: v,
                span: sv.span(),
            })
        } else {
            Err(self.err(sv.span(), format!("`{what}` must be ≥ 0, got {v}")))
        }
    }

    fn positive_or(
        &mut self,
        sv: &Option<Sv>,
        what: &str,
        table: &Range<usize>,
        default: Option<f64>,
    ) -> Result<Num, ModelError> {
        match (sv, default) {
            (Some(sv), _) => self.positive(sv, what),
            (None, Some(v)) => Ok(Num {
                value: v,
                span: table.clone(),
            }),
            (None, None) => Err(self.err(table.clone(), format!("missing `{what}`"))),
        }
    }

    fn required_positive(
        &mut self,
        sv: &Option<Sv>,
        what: &str,
        table: &Range<usize>,
        kind: &str,
    ) -> Result<Num, ModelError> {
        match sv {
            Some(sv) => self.positive(sv, what),
            None => Err(self.err(table.clone(), format!("{kind} needs `{what}`"))),
        }
    }

    /// A whole number in `min..=max`.
    fn count(&mut self, sv: &Sv, what: &str, min: u64, max: u64) -> Result<u64, ModelError> {
        let v = self.number(sv, what)?;
        if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
            return Err(self.err(
                sv.span(),
                format!("`{what}` must be a whole number in {min}..={max}, got {v}"),
            ));
        }
        Ok(v as u64)
    }

    fn count_or(
        &mut self,
        sv: &Option<Sv>,
        what: &str,
        table: &Range<usize>,
        default: Option<u64>,
        max: u64,
    ) -> Result<u64, ModelError> {
        match (sv, default) {
            (Some(sv), _) => self.count(sv, what, 0, max),
            (None, Some(v)) => Ok(v),
            (None, None) => Err(self.err(table.clone(), format!("[md] needs `{what}`"))),
        }
    }
}

/// `scheme` and `noise` of a Langevin `[md.thermostat]`.
fn langevin_scheme(
    r: &Resolver,
    q: &RawThermostat,
) -> Result<pdyn_md::thermostat::LangevinScheme, ModelError> {
    use pdyn_md::thermostat::{LangevinNoise, LangevinScheme};
    let noise = match &q.noise {
        None => LangevinNoise::Uniform,
        Some(n) => match n.get_ref().as_str() {
            "uniform" => LangevinNoise::Uniform,
            "gaussian" => LangevinNoise::Gaussian,
            other => {
                return Err(r
                    .err(n.span(), format!("unknown Langevin noise `{other}`"))
                    .help("noise: \"uniform\" (LAMMPS's default) or \"gaussian\""))
            }
        },
    };
    match q.scheme.as_ref().map(|s| (s.get_ref().as_str(), s.span())) {
        None | Some(("baoab", _)) => match &q.noise {
            Some(n) => Err(r
                .err(
                    n.span(),
                    "`noise` applies to scheme = \"lammps\" only (BAOAB's noise is Gaussian)",
                )
                .help("add scheme = \"lammps\", or remove `noise`")),
            None => Ok(LangevinScheme::Baoab),
        },
        Some(("lammps", _)) => Ok(LangevinScheme::Lammps { noise }),
        Some((other, span)) => Err(r
            .err(span, format!("unknown Langevin scheme `{other}`"))
            .help("schemes: \"baoab\" (default) or \"lammps\" (LAMMPS's fix langevin + fix nve)")),
    }
}
