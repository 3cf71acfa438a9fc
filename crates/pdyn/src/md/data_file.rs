//! What a LAMMPS data file brings besides atoms: its bonds, typed by the model's
//! `[[md.bond_types]]`; and the refusal, at the file's line, of what pdyn-md cannot model yet
//! (charges without electrostatics, angles without angle potentials) rather than running
//! without it.

use super::spec::{BondSpecKind, MdSpec};
use pdyn_md::io::LammpsData;
use pdyn_md::{Bond, BondKind, System};
use pdyn_mech::ModelError;

/// The engine's bond of a spec's bond kind.
pub fn bond_kind(k: BondSpecKind) -> BondKind {
    match k {
        BondSpecKind::Harmonic { k, r0 } => BondKind::Harmonic { k, r0 },
        BondSpecKind::Fene { k, r_max } => BondKind::Fene { k, r_max },
        BondSpecKind::FeneWca {
            k,
            r_max,
            epsilon,
            sigma,
        } => BondKind::FeneWca {
            k,
            r_max,
            epsilon,
            sigma,
        },
    }
}

/// The system of `data` with its bonds (coefficients from `spec.bond_types`), and the file
/// line of each bond (for errors found later, such as a FENE bond stretched beyond `r_max`).
/// `at(line, message)` makes the error located at that line of the data file.
pub fn with_topology(
    data: LammpsData,
    spec: &MdSpec,
    at: &dyn Fn(usize, String) -> ModelError,
) -> Result<(System, Vec<usize>), ModelError> {
    if let Some(i) = data.charges.iter().position(|&q| q != 0.0) {
        let nonzero = data.charges.iter().filter(|&&q| q != 0.0).count();
        return Err(at(
            data.atom_lines[i],
            format!(
                "atom {} has charge {} ({nonzero} atoms are charged): pdyn-md has no \
                 electrostatics, and running without them would be a different model",
                i + 1,
                data.charges[i]
            ),
        )
        .help("set the charges to 0 in the file to run without electrostatics"));
    }
    if let Some(a) = data.angles.first() {
        return Err(at(
            a.line,
            format!(
                "the file has {} angles, but pdyn-md has no angle potentials",
                data.angles.len()
            ),
        )
        .help("remove the Angles section (and the `angles` count) to run without angle terms"));
    }
    let mut system = data.system;
    if data.bonds.is_empty() {
        return Ok((system, vec![]));
    }
    let declared = spec.bond_types.len();
    if declared < data.bond_types {
        let first = data
            .bonds
            .iter()
            .find(|b| b.bond_type >= declared)
            .map_or(data.bonds[0].line, |b| b.line);
        return Err(at(
            first,
            format!(
                "the file has {} bonds of {} bond type(s), and the model gives coefficients for {declared}",
                data.bonds.len(),
                data.bond_types
            ),
        )
        .help("add one [[md.bond_types]] entry per bond type, in type order (kind = \"fene\", k, r_max, …)"));
    }
    let mut lines = Vec::with_capacity(data.bonds.len());
    system.bonds.reserve(data.bonds.len());
    for b in &data.bonds {
        let kind = bond_kind(spec.bond_types[b.bond_type].kind);
        // the reader checked both atoms exist and differ
        system
            .add_bond(Bond {
                i: b.atoms[0],
                j: b.atoms[1],
                kind,
            })
            .map_err(|e| at(b.line, e.to_string()))?;
        lines.push(b.line);
    }
    Ok((system, lines))
}
