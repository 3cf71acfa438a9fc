//! From an [`MdSpec`] to a ready [`pdyn_md::Simulation`]: units, potentials, the starting
//! configuration (lattice or file), bonds, velocities, an optional FIRE minimisation, the
//! thermostat; every set-up failure of pdyn-md (a box too small for the cutoff, overlapping
//! atoms, a stretched bond) is turned into a [`ModelError`] at the part of the file that
//! caused it.

use super::formula::{FormulaError, FormulaPair};
use super::pair::Pair;
use super::spec::{
    Ensemble, FileFormat, LatticeKind, MdSpec, Mode, Num, PairKind, Start, Units, MAX_ATOMS,
};
use pdyn_jit::JitMode;
use pdyn_md::potential::{CutoffMode, LennardJones, Morse, Truncated};
use pdyn_md::thermostat::{
    Berendsen, BerendsenParams, Langevin, LangevinParams, NoseHooverChain, NoseHooverParams,
    Thermostat,
};
use pdyn_md::{
    Bond, FireParams, ForceField, MdError, MinimizeReport, SimParams, Simulation, System,
};
use pdyn_mech::ModelError;
use std::ops::Range;
use std::path::Path;

/// Most thermodynamic records one run keeps (each is 64 bytes, and one MSD value each).
pub const MAX_RECORDS: u64 = 10_000_000;

/// Conversions between the file's units and the engine's (which needs `m v²` in energy units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitSystem {
    /// Which.
    pub units: Units,
    /// Boltzmann constant in energy units per temperature unit.
    pub boltzmann: f64,
    /// One engine time unit in file time units (LJ: 1; real: √(g/mol·Å²/(kcal/mol)) =
    /// 48.888 fs, LAMMPS's `1/sqrt(ftm2v)`).
    pub time: f64,
    /// One engine pressure unit (energy/volume) in file pressure units (real: kcal/mol/Å³ in
    /// atm, LAMMPS's `nktv2p` = 68568.415).
    pub pressure: f64,
}

impl UnitSystem {
    /// The conversions of `units`.
    pub fn of(units: Units) -> UnitSystem {
        match units {
            Units::Lj => UnitSystem {
                units,
                boltzmann: 1.0,
                time: 1.0,
                pressure: 1.0,
            },
            // LAMMPS src/update.cpp, `real`: boltz = 0.0019872067, ftm2v = 1/48.88821291²,
            // nktv2p = 68568.415.
            Units::Real => UnitSystem {
                units,
                boltzmann: 0.0019872067,
                time: 48.88821291,
                pressure: 68568.415,
            },
        }
    }
}

/// A simulation, typed by its potentials: the built-in LJ kernel alone gets its own
/// monomorphic force loop.
#[derive(Debug, Clone)]
pub enum Engine {
    /// Only Lennard-Jones between all species.
    Lj(Box<Simulation<Truncated<LennardJones>>>),
    /// Anything else.
    General(Box<Simulation<Pair>>),
}

/// Everything a run needs, built from a spec.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The simulation.
    pub engine: Engine,
    /// The spec it came from.
    pub spec: MdSpec,
    /// Unit conversions.
    pub units: UnitSystem,
    /// The result of `minimize = true`, if asked.
    pub minimized: Option<MinimizeReport>,
    /// Whether every formula potential runs as native code (true when there is none).
    pub native: bool,
    /// The largest cutoff.
    pub cutoff: f64,
}

/// Refuses a model whose estimated memory ([`super::memory::estimate`]) exceeds the limit
/// ([`super::memory::limit`]), at the table of its configuration, naming both sizes.
fn fits_in_memory(
    spec: &MdSpec,
    atoms: u64,
    edges: [f64; 3],
    cutoff: f64,
    span: &Range<usize>,
) -> Result<(), ModelError> {
    use super::memory::{estimate, human, limit};
    let need = estimate(atoms, edges, cutoff + spec.skin.value, spec.msd);
    let (have, source) = limit();
    if need.bytes > have as f64 {
        return Err(ModelError::new(
            &spec.origin,
            span.clone(),
            format!(
                "{atoms} atoms need about {} ({:.0} bytes per atom), more than the {} available \
                 ({source})",
                human(need.bytes),
                need.per_atom,
                human(have as f64),
            ),
        )
        .help("use a smaller system (fewer cells or atoms), or set PDYN_MEMORY_LIMIT if the estimate is too cautious (docs/md.md)"));
    }
    Ok(())
}

/// Builds the simulation; `source` is the file's text (for located errors only) and `base` the
/// directory relative to which `[md.read] file` is found.
pub fn build(spec: &MdSpec, base: &Path, jit: JitMode) -> Result<Prepared, ModelError> {
    let u = UnitSystem::of(spec.units);
    let err = |span: &Range<usize>, msg: String| ModelError::new(&spec.origin, span.clone(), msg);
    let md_err = |span: &Range<usize>, e: MdError| err(span, e.to_string());

    // Thermo records are kept in memory: their number is checked before the run.
    let records = spec.steps / spec.thermo_every.max(1);
    if records > MAX_RECORDS {
        return Err(err(&spec.span, format!(
            "{} steps with thermo_every = {} would keep {records} thermo records (more than {MAX_RECORDS})",
            spec.steps, spec.thermo_every
        ))
        .help("raise thermo_every"));
    }

    // Potentials.
    let mut pairs = Vec::with_capacity(spec.pairs.len());
    let mut native = true;
    for p in &spec.pairs {
        let rc = p.cutoff.value;
        let mode = match p.mode {
            Mode::Plain => CutoffMode::Plain,
            Mode::ShiftedEnergy => CutoffMode::ShiftedEnergy,
            Mode::ShiftedForce => CutoffMode::ShiftedForce,
        };
        let at_cutoff = |e: MdError, what: &Range<usize>| match e {
            MdError::InvalidParameter { name, value } if name.contains("cutoff") => err(
                what,
                format!(
                    "the potential has no finite value at the cutoff r = {}: {name} = {value}",
                    short(rc)
                ),
            )
            .help("choose a cutoff where u(r) and u'(r) are finite"),
            e => md_err(&p.cutoff.span, e),
        };
        let pair = match &p.kind {
            PairKind::Lj { epsilon, sigma } => {
                let lj = LennardJones::try_new(epsilon.value, sigma.value).map_err(|e| {
                    param_err(&spec.origin, e, &[("epsilon", epsilon), ("sigma", sigma)])
                })?;
                Pair::Lj(Truncated::try_new(lj, rc, mode).map_err(|e| at_cutoff(e, &p.span))?)
            }
            PairKind::Morse { depth, alpha, r0 } => {
                let m = Morse::try_new(depth.value, alpha.value, r0.value).map_err(|e| {
                    param_err(
                        &spec.origin,
                        e,
                        &[("depth", depth), ("alpha", alpha), ("r0", r0)],
                    )
                })?;
                Pair::Morse(Truncated::try_new(m, rc, mode).map_err(|e| at_cutoff(e, &p.span))?)
            }
            PairKind::Formula { text, offset, span } => {
                let f = FormulaPair::compile(text, &spec.parameters, jit).map_err(
                    |e: FormulaError| {
                        let mut me = ModelError::new(
                            &spec.origin,
                            e.span.start + offset..e.span.end + offset,
                            e.message,
                        );
                        me.help = e.help;
                        me
                    },
                )?;
                native &= f.is_native();
                Pair::Formula(Truncated::try_new(f, rc, mode).map_err(|e| at_cutoff(e, span))?)
            }
        };
        pairs.push(pair);
    }
    let nt = spec.species.len();
    let mut ff = ForceField::uniform(nt, pairs[0].clone()).map_err(|e| md_err(&spec.span, e))?;
    for (p, pair) in spec.pairs.iter().zip(&pairs) {
        ff.set(p.between[0], p.between[1], pair.clone())
            .map_err(|e| md_err(&p.span, e))?;
    }
    let cutoff = ff.max_cutoff();

    // Configuration.
    let (mut system, start_span, data_bond_lines) = match &spec.start {
        Start::Lattice {
            kind,
            density,
            cells,
            species,
            span,
        } => {
            let k = match kind {
                LatticeKind::Sc => pdyn_md::Lattice::Sc,
                LatticeKind::Bcc => pdyn_md::Lattice::Bcc,
                LatticeKind::Fcc => pdyn_md::Lattice::Fcc,
            };
            let c = cells.map(|c| c as usize);
            // Before the lattice is generated: does the model fit in memory?
            let basis = match kind {
                LatticeKind::Sc => 1.0,
                LatticeKind::Bcc => 2.0,
                LatticeKind::Fcc => 4.0,
            };
            let a = libm::cbrt(basis / density.value);
            let atoms = cells.iter().product::<u64>() * basis as u64;
            fits_in_memory(spec, atoms, cells.map(|c| c as f64 * a), cutoff, span)?;
            let (p, bx) = pdyn_md::lattice(
                k,
                density.value,
                c,
                spec.species[*species].mass.value,
                MAX_ATOMS as usize,
            )
            .map_err(|e| md_err(span, e))?;
            let mut s = System::new(p, bx);
            s.types = vec![*species as u32; s.particles.len()];
            (s, span.clone(), vec![])
        }
        Start::File { path, format, span } => {
            let full = base.join(path);
            let file = std::fs::File::open(&full).map_err(|e| {
                err(span, format!("cannot read {}: {e}", full.display()))
                    .help("the path is relative to the model file")
            })?;
            let r = std::io::BufReader::new(file);
            let located = |e: MdError| err(span, format!("{}: {e}", full.display()));
            let mut data_bond_lines = vec![];
            let mut s = match format {
                FileFormat::Xyz => {
                    let frame =
                        pdyn_md::io::read_xyz(r, MAX_ATOMS as usize, 1.0).map_err(located)?;
                    // The file's species names are mapped to the model's by name.
                    let mut map = Vec::with_capacity(frame.names.len());
                    for n in &frame.names {
                        let k = spec.species.iter().position(|s| &s.name == n).ok_or_else(|| {
                            let names: Vec<&str> = spec.species.iter().map(|s| s.name.as_str()).collect();
                            err(span, format!("{} has atoms of species `{n}`, which the model does not declare", full.display()))
                                .help(format!("declared species: {}", names.join(", ")))
                        })?;
                        map.push(k as u32);
                    }
                    let mut s = frame.system;
                    for t in &mut s.types {
                        *t = map[*t as usize];
                    }
                    s
                }
                FileFormat::LammpsData => {
                    let data = pdyn_md::io::read_lammps_data_file(r, MAX_ATOMS as usize)
                        .map_err(located)?;
                    let at = |line: usize, msg: String| {
                        err(
                            span,
                            format!("{}: lammps-data line {line}: {msg}", full.display()),
                        )
                    };
                    let (s, lines) = super::data_file::with_topology(data, spec, &at)?;
                    data_bond_lines = lines;
                    if let Some(&t) = s.types.iter().find(|&&t| t as usize >= nt) {
                        return Err(err(span, format!(
                            "{} has atom type {}, but the model declares {nt} species (types 1..{nt} in declaration order)",
                            full.display(),
                            t + 1
                        )));
                    }
                    s
                }
            };
            // Masses come from the species (one source of truth for the model); velocities
            // in the file are in file units.
            for i in 0..s.particles.len() {
                s.particles.m[i] = spec.species[s.types[i] as usize].mass.value;
                s.particles.vx[i] *= u.time;
                s.particles.vy[i] *= u.time;
                s.particles.vz[i] *= u.time;
            }
            (s, span.clone(), data_bond_lines)
        }
    };
    let n = system.particles.len();
    if n == 0 {
        return Err(err(
            &start_span,
            "the initial configuration has no atoms".into(),
        ));
    }
    if matches!(spec.start, Start::File { .. }) {
        let l = system.sim_box.l;
        fits_in_memory(spec, n as u64, l, cutoff, &start_span)?;
    }

    // Bonds: consecutive atoms in chains of `chain_length`.
    if let (Some(b), false) = (&spec.bonds, system.bonds.is_empty()) {
        return Err(err(
            &b.span,
            "[md.bonds] makes chains, but the data file has its own bonds".into(),
        )
        .help("give the data file's bond coefficients as [[md.bond_types]] instead"));
    }
    if let Some(b) = &spec.bonds {
        let l = b.chain_length as usize;
        if n % l != 0 {
            return Err(err(
                &b.span,
                format!("{n} atoms do not divide into chains of {l} beads"),
            )
            .help("choose a chain_length that divides the number of atoms"));
        }
        let kind = super::data_file::bond_kind(b.kind);
        system.bonds.reserve(n / l * (l - 1));
        for c in 0..n / l {
            for k in 0..l - 1 {
                let i = c * l + k;
                system
                    .add_bond(Bond { i, j: i + 1, kind })
                    .map_err(|e| md_err(&b.span, e))?;
            }
        }
    }

    // Velocities.
    if let Some((t, seed)) = &spec.velocities {
        pdyn_md::maxwell_boltzmann(&mut system.particles, t.value, u.boltzmann, *seed)
            .map_err(|e| md_err(&t.span, e))?;
    }

    if let (Some(t), true) = (spec.bond_types.first(), data_bond_lines.is_empty()) {
        return Err(err(
            &t.span,
            "[[md.bond_types]] gives bond coefficients, but the configuration has no bonds".into(),
        )
        .help("bond types apply to the Bonds section of a LAMMPS data file ([md.read])"));
    }
    if let (Some(r), true) = (&spec.rdf_range, spec.rdf) {
        let half = 0.5 * system.sim_box.min_edge();
        if r.value > half {
            return Err(err(
                &r.span,
                format!(
                    "rdf_range = {} is more than half the shortest box edge ({}): the minimum image cannot count pairs that far",
                    short(r.value),
                    short(half)
                ),
            )
            .help("leave rdf_range out for the largest range the box allows"));
        }
    }
    system.special_lj = spec.special_lj.0;
    let params = SimParams {
        neighbor_every: spec.neighbor_every,
        neighbor_check: spec.neighbor_check,
        dt: spec.dt.value / u.time,
        skin: spec.skin.value,
        thermo_every: spec.thermo_every,
        boltzmann: u.boltzmann,
        overlap_distance: spec.overlap_distance.as_ref().map_or(
            match spec.units {
                Units::Lj => SimParams::default().overlap_distance,
                Units::Real => 1.0,
            },
            |d| d.value,
        ),
        ..SimParams::default()
    };
    let box_check = |e: MdError| {
        match e {
        MdError::BoxTooSmall {
            axis,
            length,
            required,
        } => err(&start_span, format!(
            "the box is {length:.6} long along {}, shorter than 2·(cutoff + skin) = 2·({} + {}) = {required:.6}: the minimum image would miss interactions",
            ["x", "y", "z"][axis.min(2)],
            short(cutoff),
            short(spec.skin.value)
        ))
        .help("use more cells (or a larger box in the file), or a shorter cutoff or skin"),
        e => md_err(&spec.span, e),
    }
    };
    // The box is checked before a minimisation, which builds a neighbour list of its own.
    pdyn_md::NeighborList::new(cutoff, params.skin)
        .and_then(|nl| nl.check_box(&system.sim_box))
        .map_err(box_check)?;

    let minimized = if spec.minimize {
        let fp = FireParams {
            skin: params.skin,
            ..FireParams::default()
        };
        let rep =
            pdyn_md::minimize_fire(&mut system, &ff, &fp).map_err(|e| md_err(&spec.span, e))?;
        if let Some((t, seed)) = &spec.velocities {
            // FIRE leaves the atoms at rest: draw the velocities again.
            pdyn_md::maxwell_boltzmann(&mut system.particles, t.value, u.boltzmann, *seed)
                .map_err(|e| md_err(&t.span, e))?;
        }
        Some(rep)
    } else {
        None
    };

    let th = &spec.thermostat;
    let t0 = th.temperature.as_ref().map(|t| t.value);
    let thermostat = match &th.ensemble {
        Ensemble::Nve => Ok(Thermostat::None),
        Ensemble::Langevin {
            damping,
            seed,
            scheme,
        } => Langevin::new(LangevinParams {
            temperature: t0,
            damping: damping.value / u.time,
            seed: *seed,
        })
        .map(|l| Thermostat::Langevin(l.with_scheme(*scheme))),
        Ensemble::NoseHoover { tau, chain } => NoseHooverChain::new(NoseHooverParams {
            temperature: t0,
            tau: tau.value / u.time,
            chain: *chain,
        })
        .map(Thermostat::NoseHooverChain),
        Ensemble::Berendsen { tau } => Berendsen::new(BerendsenParams {
            temperature: t0,
            tau: tau.value / u.time,
        })
        .map(Thermostat::Berendsen),
    }
    .map_err(|e| md_err(&th.span, e))?;

    let start_err = |e: MdError| {
        match e {
        MdError::Overlap {
            i,
            j,
            distance,
            threshold,
        } => err(&start_span, format!(
            "atoms {i} and {j} overlap at the start: distance {distance:.6} < {threshold} (overlap_distance)"
        ))
        .help(if spec.minimize {
            "the minimisation did not separate them: check the density and the configuration"
        } else {
            "add `minimize = true` to [md] to relax the configuration (FIRE) before the run, or fix the file"
        }),
        MdError::BondBroken { bond, atoms, length, max, .. } if bond < data_bond_lines.len() => err(
            &start_span,
            format!(
                "lammps-data line {}: the FENE bond between atoms {} and {} starts at length {length:.6} ≥ r_max = {max}",
                data_bond_lines[bond], atoms[0] + 1, atoms[1] + 1
            ),
        )
        .help("check the bond list and the box of the data file, or r_max in [[md.bond_types]]"),
        MdError::BondBroken { atoms, length, max, .. } => err(
            spec.bonds.as_ref().map_or(&spec.span, |b| &b.span),
            format!(
                "the FENE bond between atoms {} and {} starts at length {length:.6} ≥ r_max = {max}",
                atoms[0], atoms[1]
            ),
        )
        .help("atoms of a chain are consecutive in the configuration: they must start closer than r_max"),
        e => box_check(e),
    }
    };
    let engine = if pairs.iter().all(|p| matches!(p, Pair::Lj(_))) {
        let mut lf =
            ForceField::uniform(nt, lj_of(&pairs[0])).map_err(|e| md_err(&spec.span, e))?;
        for (p, pair) in spec.pairs.iter().zip(&pairs) {
            lf.set(p.between[0], p.between[1], lj_of(pair))
                .map_err(|e| md_err(&p.span, e))?;
        }
        Engine::Lj(Box::new(
            Simulation::new(system, lf, thermostat, params).map_err(start_err)?,
        ))
    } else {
        Engine::General(Box::new(
            Simulation::new(system, ff, thermostat, params).map_err(start_err)?,
        ))
    };
    Ok(Prepared {
        engine,
        spec: spec.clone(),
        units: u,
        minimized,
        native,
        cutoff,
    })
}

/// `x` plainly when it reads well so, in scientific notation otherwise (`1e-300`, not 300 zeros).
fn short(x: f64) -> String {
    if x == 0.0 || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn lj_of(p: &Pair) -> Truncated<LennardJones> {
    match p {
        Pair::Lj(t) => *t,
        // `build` only calls this when every pair is LJ; a neutral value keeps it total.
        _ => LennardJones::new(1.0, 1.0).truncated(1.0, CutoffMode::Plain),
    }
}

/// An invalid kernel parameter, located at the field that holds it.
fn param_err(origin: &str, e: MdError, fields: &[(&str, &Num)]) -> ModelError {
    let (name, value) = match &e {
        MdError::InvalidParameter { name, value } => (*name, *value),
        _ => ("", f64::NAN),
    };
    let span = fields
        .iter()
        .find(|(n, _)| *n == name)
        .or(fields.first())
        .map_or(0..0, |(_, num)| num.span.clone());
    ModelError::new(
        origin,
        span,
        format!("`{name}` must be finite and > 0, got {value}"),
    )
}

/// The periodic box's edge lengths (file units).
pub fn box_edges(p: &Prepared) -> [f64; 3] {
    match &p.engine {
        Engine::Lj(s) => s.system.sim_box.l,
        Engine::General(s) => s.system.sim_box.l,
    }
}

/// Number of atoms of the prepared system.
pub fn atoms(p: &Prepared) -> usize {
    match &p.engine {
        Engine::Lj(s) => s.system.particles.len(),
        Engine::General(s) => s.system.particles.len(),
    }
}
