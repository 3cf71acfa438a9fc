//! LAMMPS data files (`read_data`) of `atom_style` atomic, bond, angle, molecular and full.
//!
//! Header: counts (`N atoms`, `N bonds`, `N angles`, `N dihedrals`, `N impropers`, `T atom
//! types`, `T bond types`, `T angle types`, …), box bounds (`xlo xhi` …, orthogonal only: tilt
//! factors must be zero). Sections: `Masses`, `Atoms`, `Velocities`, `Bonds` (`id type i j`),
//! `Angles` (`id type i j k`); `… Coeffs` sections are skipped (the model gives the
//! coefficients); `Dihedrals` and `Impropers` are refused (pdyn-md has no such terms).
//!
//! `Atoms` lines by style (image flags `ix iy iz` optional at the end):
//! atomic `id type x y z`; bond, angle, molecular `id mol type x y z`; full
//! `id mol type q x y z`. The style is the section's comment (`Atoms # full`, as LAMMPS writes
//! it) or, without one, inferred from the column count (5/8 atomic, 6/9 bond, 7/10 full). Atom
//! ids must be `1..=N`, each once. Positions are shifted so that the box starts at the origin;
//! atom, bond and angle types become 0-based.
//!
//! Every error names the 1-based line and what would be valid there.

use super::perr;
use crate::{MdError, SimBox, System};
use pdyn_particles::{Particle, Particles, Vec3};
use std::io::{BufRead, Write};

const F: &str = "lammps-data";

/// Type, position and image flags of one `Atoms` line.
type AtomLine = (u32, [f64; 3], [i32; 3]);

/// Most bonds (or angles) per atom a file may declare (checked before allocating).
const MAX_TOPOLOGY_PER_ATOM: usize = 16;

/// `atom_style` of a data file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AtomStyle {
    /// `id type x y z`.
    Atomic,
    /// `id mol type x y z` (bonds).
    Bond,
    /// `id mol type x y z` (bonds, angles).
    Angle,
    /// `id mol type x y z` (bonds, angles, dihedrals, impropers).
    Molecular,
    /// `id mol type q x y z`.
    Full,
}

impl AtomStyle {
    /// The style's name in LAMMPS.
    pub fn name(self) -> &'static str {
        match self {
            AtomStyle::Atomic => "atomic",
            AtomStyle::Bond => "bond",
            AtomStyle::Angle => "angle",
            AtomStyle::Molecular => "molecular",
            AtomStyle::Full => "full",
        }
    }

    fn from_name(s: &str) -> Option<Self> {
        Some(match s {
            "atomic" => AtomStyle::Atomic,
            "bond" => AtomStyle::Bond,
            "angle" => AtomStyle::Angle,
            "molecular" => AtomStyle::Molecular,
            "full" => AtomStyle::Full,
            _ => return None,
        })
    }

    /// Columns before the position: id [mol] type [q].
    fn leading(self) -> usize {
        match self {
            AtomStyle::Atomic => 2,
            AtomStyle::Full => 4,
            _ => 3,
        }
    }
}

/// A bond of a data file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataBond {
    /// 0-based bond type.
    pub bond_type: usize,
    /// 0-based atoms.
    pub atoms: [usize; 2],
    /// 1-based line of the file.
    pub line: usize,
}

/// An angle of a data file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataAngle {
    /// 0-based angle type.
    pub angle_type: usize,
    /// 0-based atoms, the vertex in the middle.
    pub atoms: [usize; 3],
    /// 1-based line of the file.
    pub line: usize,
}

/// Everything a data file says.
#[derive(Debug, Clone)]
pub struct LammpsData {
    /// Particles (masses from `Masses`, 1 for a type without an entry: see
    /// [`LammpsData::masses`]), types, box, image flags. No bonds: those are in [`LammpsData::bonds`], untyped until the model gives the
    /// coefficients.
    pub system: System,
    /// The style of the `Atoms` section.
    pub atom_style: AtomStyle,
    /// Declared atom types.
    pub atom_types: usize,
    /// Mass of each atom type, when the `Masses` section gives it.
    pub masses: Vec<Option<f64>>,
    /// Declared bond types.
    pub bond_types: usize,
    /// Declared angle types.
    pub angle_types: usize,
    /// Molecule id of each atom (0 for `atomic`).
    pub molecules: Vec<u64>,
    /// Charge of each atom (0 unless `full`).
    pub charges: Vec<f64>,
    /// 1-based line of each atom's `Atoms` entry.
    pub atom_lines: Vec<usize>,
    /// Bonds, in file order.
    pub bonds: Vec<DataBond>,
    /// Angles, in file order.
    pub angles: Vec<DataAngle>,
}

fn bad(line: usize, message: String) -> MdError {
    MdError::InvalidInput {
        format: F,
        line,
        message,
    }
}

/// Tokens of line `i` (0-based) without its comment.
fn tokens(lines: &[String], i: usize) -> Vec<&str> {
    lines[i]
        .split('#')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect()
}

/// Header counts and box.
#[derive(Default)]
struct Header {
    atoms: Option<usize>,
    bonds: usize,
    angles: usize,
    dihedrals: usize,
    impropers: usize,
    atom_types: Option<usize>,
    bond_types: usize,
    angle_types: usize,
    lo: [f64; 3],
    hi: [f64; 3],
    bounds: [bool; 3],
}

/// Reads a data file with at most `limit` atoms (every count is checked before allocating).
pub fn read_lammps_data_file<R: BufRead>(r: R, limit: usize) -> Result<LammpsData, MdError> {
    let lines: Vec<String> = r.lines().collect::<Result<_, _>>()?;
    let num = |s: &str, no: usize| s.parse::<f64>().map_err(|_| perr(F, no, "a number"));
    let count = |s: &str, no: usize| {
        s.parse::<usize>()
            .map_err(|_| perr(F, no, "a count (a non-negative integer)"))
    };
    let mut h = Header::default();
    let mut i = 1; // the first line is a comment
    while i < lines.len() {
        let t = tokens(&lines, i);
        let no = i + 1;
        if t.is_empty() {
            i += 1;
            continue;
        }
        if t[0].chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
            break; // the first section
        }
        match t[1..] {
            ["atoms"] => h.atoms = Some(count(t[0], no)?),
            ["bonds"] => h.bonds = count(t[0], no)?,
            ["angles"] => h.angles = count(t[0], no)?,
            ["dihedrals"] => h.dihedrals = count(t[0], no)?,
            ["impropers"] => h.impropers = count(t[0], no)?,
            ["atom", "types"] => h.atom_types = Some(count(t[0], no)?),
            ["bond", "types"] => h.bond_types = count(t[0], no)?,
            ["angle", "types"] => h.angle_types = count(t[0], no)?,
            [_, lo, hi] if lo.ends_with("lo") && hi.ends_with("hi") => {
                let k = match lo {
                    "xlo" => 0,
                    "ylo" => 1,
                    "zlo" => 2,
                    _ => return Err(perr(F, no, "xlo xhi, ylo yhi or zlo zhi")),
                };
                h.lo[k] = num(t[0], no)?;
                h.hi[k] = num(t[1], no)?;
                h.bounds[k] = true;
            }
            [_, _, "xy", "xz", "yz"]
                if t[..3].iter().any(|s| s.parse::<f64>().ok() != Some(0.0)) =>
            {
                return Err(perr(F, no, "an orthogonal box (zero tilt factors)"));
            }
            // dihedral/improper types, extra per-atom counts, ellipsoids, …: nothing to keep
            _ => {}
        }
        i += 1;
    }
    let n = h
        .atoms
        .ok_or(perr(F, i.min(lines.len()), "an 'N atoms' header line"))?;
    if let Some(k) = (0..3).find(|&k| !h.bounds[k]) {
        return Err(perr(
            F,
            i.min(lines.len()),
            ["an 'xlo xhi' line", "a 'ylo yhi' line", "a 'zlo zhi' line"][k],
        ));
    }
    let ntypes = h.atom_types.unwrap_or(1);
    if n > limit {
        return Err(MdError::Particle(pdyn_particles::ParticleError::TooMany {
            requested: n,
            limit,
        }));
    }
    for (what, c) in [("bonds", h.bonds), ("angles", h.angles)] {
        if c > n.saturating_mul(MAX_TOPOLOGY_PER_ATOM) {
            return Err(bad(
                1,
                format!("{c} {what} for {n} atoms: more than {MAX_TOPOLOGY_PER_ATOM} per atom"),
            ));
        }
    }
    if ntypes > limit.max(1) || h.bond_types > limit.max(1) || h.angle_types > limit.max(1) {
        return Err(bad(1, "more types than the atom limit".into()));
    }
    let sim_box = SimBox::new(h.hi[0] - h.lo[0], h.hi[1] - h.lo[1], h.hi[2] - h.lo[2])?;

    let mut masses: Vec<Option<f64>> = vec![None; ntypes];
    let mut atoms: Vec<Option<AtomLine>> = vec![None; n];
    let mut molecules = vec![0u64; n];
    let mut charges = vec![0.0; n];
    let mut atom_lines = vec![0usize; n];
    let mut vels = vec![[0.0; 3]; n];
    let mut bonds = Vec::with_capacity(h.bonds);
    let mut angles = Vec::with_capacity(h.angles);
    let mut style: Option<AtomStyle> = None;
    let mut atoms_line = 0;
    // 1-based id in 1..=len, else a located error naming `what`
    let id = |s: &str, len: usize, no: usize, what: &str| -> Result<usize, MdError> {
        let v: usize = s.parse().map_err(|_| {
            bad(
                no,
                format!("expected {what} (a positive integer), got `{s}`"),
            )
        })?;
        if v == 0 || v > len {
            return Err(bad(
                no,
                format!("{what} {v} does not exist: the header declares {len} (valid: 1 to {len})"),
            ));
        }
        Ok(v - 1)
    };
    while i < lines.len() {
        let full_head = lines[i].trim().to_string();
        let head = full_head.split('#').next().unwrap_or("").trim().to_string();
        let head_no = i + 1;
        i += 1;
        if head.is_empty() {
            continue;
        }
        let rows = match head.as_str() {
            "Masses" => ntypes,
            "Atoms" | "Velocities" => n,
            "Bonds" => h.bonds,
            "Angles" => h.angles,
            "Dihedrals" | "Impropers" => {
                return Err(bad(
                    head_no,
                    format!(
                        "{head}: pdyn-md has no dihedral or improper terms (supported sections: \
                         Masses, Atoms, Velocities, Bonds, Angles, and … Coeffs, which are skipped)"
                    ),
                ))
            }
            s if s.ends_with("Coeffs") => 0, // coefficients come from the model
            _ => {
                return Err(bad(
                    head_no,
                    format!(
                        "unknown section `{head}` (expected Masses, Atoms, Velocities, Bonds, \
                         Angles or a … Coeffs section)"
                    ),
                ))
            }
        };
        if head == "Atoms" {
            atoms_line = head_no;
            if let Some(c) = full_head.split_once('#').map(|(_, c)| c.trim()) {
                if !c.is_empty() {
                    style = Some(AtomStyle::from_name(c).ok_or_else(|| {
                        bad(
                            head_no,
                            format!(
                                "unsupported atom_style `{c}` (supported: atomic, bond, angle, \
                                 molecular, full)"
                            ),
                        )
                    })?);
                }
            }
        }
        while i < lines.len() && lines[i].trim().is_empty() {
            i += 1;
        }
        if rows == 0 {
            if !head.ends_with("Coeffs") && i < lines.len() && !tokens(&lines, i).is_empty() {
                let first = tokens(&lines, i)[0];
                if first.parse::<f64>().is_ok() {
                    return Err(bad(
                        head_no,
                        format!("a {head} section, but the header declares none of them"),
                    ));
                }
            }
            while i < lines.len() && !lines[i].trim().is_empty() {
                i += 1;
            }
            continue;
        }
        for _ in 0..rows {
            let no = i + 1;
            if i >= lines.len() {
                return Err(bad(
                    lines.len(),
                    format!(
                        "the file ends inside the {head} section (line {head_no}), which should \
                         have {rows} lines"
                    ),
                ));
            }
            let t = tokens(&lines, i);
            match head.as_str() {
                "Masses" => {
                    if t.len() < 2 {
                        return Err(perr(F, no, "a Masses line `type mass`"));
                    }
                    let m = num(t[1], no)?;
                    if !(m.is_finite() && m > 0.0) {
                        return Err(bad(no, format!("mass {m}: a mass must be finite and > 0")));
                    }
                    masses[id(t[0], ntypes, no, "atom type")?] = Some(m);
                }
                "Atoms" => {
                    let st = match style {
                        Some(s) => s,
                        None => {
                            let s = match t.len() {
                                5 | 8 => AtomStyle::Atomic,
                                6 | 9 => AtomStyle::Bond,
                                7 | 10 => AtomStyle::Full,
                                c => {
                                    return Err(bad(
                                        no,
                                        format!(
                                            "{c} columns: without an `Atoms # style` comment \
                                             the style is inferred from 5 or 8 (atomic), 6 or 9 \
                                             (bond, angle, molecular), 7 or 10 (full) columns"
                                        ),
                                    ))
                                }
                            };
                            style = Some(s);
                            s
                        }
                    };
                    let lead = st.leading();
                    if t.len() != lead + 3 && t.len() != lead + 6 {
                        return Err(bad(
                            no,
                            format!(
                                "{} columns; atom_style {} has {} (or {} with image flags)",
                                t.len(),
                                st.name(),
                                lead + 3,
                                lead + 6
                            ),
                        ));
                    }
                    let a = id(t[0], n, no, "atom id")?;
                    if atoms[a].is_some() {
                        return Err(bad(
                            no,
                            format!(
                                "atom id {} appears twice (also line {})",
                                a + 1,
                                atom_lines[a]
                            ),
                        ));
                    }
                    let type_col = if st == AtomStyle::Atomic { 1 } else { 2 };
                    let ty = id(t[type_col], ntypes, no, "atom type")? as u32;
                    if st != AtomStyle::Atomic {
                        molecules[a] = t[1]
                            .parse()
                            .map_err(|_| perr(F, no, "a molecule id (a non-negative integer)"))?;
                    }
                    if st == AtomStyle::Full {
                        charges[a] = num(t[3], no)?;
                    }
                    let r = [
                        num(t[lead], no)? - h.lo[0],
                        num(t[lead + 1], no)? - h.lo[1],
                        num(t[lead + 2], no)? - h.lo[2],
                    ];
                    let mut im = [0; 3];
                    if t.len() == lead + 6 {
                        for k in 0..3 {
                            im[k] = t[lead + 3 + k]
                                .parse()
                                .map_err(|_| perr(F, no, "an image flag (an integer)"))?;
                        }
                    }
                    atoms[a] = Some((ty, r, im));
                    atom_lines[a] = no;
                }
                "Velocities" => {
                    if t.len() < 4 {
                        return Err(perr(F, no, "a Velocities line `id vx vy vz`"));
                    }
                    vels[id(t[0], n, no, "atom id")?] =
                        [num(t[1], no)?, num(t[2], no)?, num(t[3], no)?];
                }
                "Bonds" => {
                    if t.len() != 4 {
                        return Err(perr(F, no, "a Bonds line `id type atom1 atom2`"));
                    }
                    let bond_type = id(t[1], h.bond_types, no, "bond type")?;
                    let atoms = [id(t[2], n, no, "atom")?, id(t[3], n, no, "atom")?];
                    if atoms[0] == atoms[1] {
                        return Err(bad(
                            no,
                            format!("a bond of atom {} to itself", atoms[0] + 1),
                        ));
                    }
                    bonds.push(DataBond {
                        bond_type,
                        atoms,
                        line: no,
                    });
                }
                "Angles" => {
                    if t.len() != 5 {
                        return Err(perr(F, no, "an Angles line `id type atom1 atom2 atom3`"));
                    }
                    let angle_type = id(t[1], h.angle_types, no, "angle type")?;
                    let atoms = [
                        id(t[2], n, no, "atom")?,
                        id(t[3], n, no, "atom")?,
                        id(t[4], n, no, "atom")?,
                    ];
                    angles.push(DataAngle {
                        angle_type,
                        atoms,
                        line: no,
                    });
                }
                _ => unreachable!("only sections with rows reach here"),
            }
            i += 1;
        }
    }
    if h.bonds > 0 && bonds.is_empty() {
        return Err(bad(
            lines.len(),
            format!(
                "the header declares {} bonds but there is no Bonds section",
                h.bonds
            ),
        ));
    }
    if h.angles > 0 && angles.is_empty() {
        return Err(bad(
            lines.len(),
            format!(
                "the header declares {} angles but there is no Angles section",
                h.angles
            ),
        ));
    }
    let _ = (h.dihedrals, h.impropers); // refused at their sections
    let mut p = Particles::with_capacity(n, limit)?;
    let mut types = Vec::with_capacity(n);
    let mut images = Vec::with_capacity(n);
    for (k, a) in atoms.iter().enumerate() {
        let Some((ty, r, im)) = a else {
            return Err(bad(
                atoms_line.max(1),
                format!(
                    "atom id {} is missing from the Atoms section (ids must be 1 to {n}, each once)",
                    k + 1
                ),
            ));
        };
        p.push(Particle {
            mass: masses[*ty as usize].unwrap_or(1.0),
            pos: Vec3(*r),
            vel: Vec3(vels[k]),
        })?;
        types.push(*ty);
        images.push(*im);
    }
    let mut system = System::new(p, sim_box);
    system.types = types;
    system.images = images;
    Ok(LammpsData {
        system,
        atom_style: style.unwrap_or(AtomStyle::Atomic),
        atom_types: ntypes,
        masses,
        bond_types: h.bond_types,
        angle_types: h.angle_types,
        molecules,
        charges,
        atom_lines,
        bonds,
        angles,
    })
}

/// Reads the particles of a data file with at most `limit` atoms; every type needs a `Masses`
/// entry. Bonds, angles and charges are read (and checked) but dropped: see
/// [`read_lammps_data_file`] for all of it.
pub fn read_lammps_data<R: BufRead>(r: R, limit: usize) -> Result<System, MdError> {
    let d = read_lammps_data_file(r, limit)?;
    if let Some(i) =
        (0..d.system.particles.len()).find(|&i| d.masses[d.system.types[i] as usize].is_none())
    {
        return Err(bad(
            d.atom_lines[i],
            format!(
                "atom type {} has no entry in the Masses section",
                d.system.types[i] + 1
            ),
        ));
    }
    Ok(d.system)
}

/// Writes `system` as an atomic-style data file with masses per type (taken from the first
/// particle of each type), image flags and velocities, at full precision.
pub fn write_lammps_data<W: Write>(w: &mut W, system: &System) -> Result<(), MdError> {
    let p = &system.particles;
    let ntypes = system
        .types
        .iter()
        .map(|&t| t as usize + 1)
        .max()
        .unwrap_or(1);
    let l = system.sim_box.l;
    writeln!(w, "LAMMPS data file written by pdyn-md\n")?;
    writeln!(w, "{} atoms\n{ntypes} atom types\n", p.len())?;
    writeln!(
        w,
        "0 {:.17e} xlo xhi\n0 {:.17e} ylo yhi\n0 {:.17e} zlo zhi\n",
        l[0], l[1], l[2]
    )?;
    writeln!(w, "Masses\n")?;
    for t in 0..ntypes {
        let m = (0..p.len())
            .find(|&i| system.types[i] as usize == t)
            .map_or(1.0, |i| p.m[i]);
        writeln!(w, "{} {m:.17e}", t + 1)?;
    }
    writeln!(w, "\nAtoms # atomic\n")?;
    for i in 0..p.len() {
        let im = system.images[i];
        writeln!(
            w,
            "{} {} {:.17e} {:.17e} {:.17e} {} {} {}",
            i + 1,
            system.types[i] + 1,
            p.x[i],
            p.y[i],
            p.z[i],
            im[0],
            im[1],
            im[2]
        )?;
    }
    writeln!(w, "\nVelocities\n")?;
    for i in 0..p.len() {
        writeln!(
            w,
            "{} {:.17e} {:.17e} {:.17e}",
            i + 1,
            p.vx[i],
            p.vy[i],
            p.vz[i]
        )?;
    }
    Ok(())
}
