//! LAMMPS data files, `atom_style atomic`: header counts (`N atoms`, `T atom types`), box
//! bounds (`xlo xhi` …, orthogonal only), sections `Masses`, `Atoms # atomic`
//! (`id type x y z [ix iy iz]`) and `Velocities` (`id vx vy vz`). Other sections are skipped.
//! Positions are shifted so that the box starts at the origin; types become 0-based.

use super::perr;
use crate::{MdError, SimBox, System};
use pdyn_particles::{Particle, Particles, Vec3};
use std::io::{BufRead, Write};

const F: &str = "lammps-data";

/// Type, position and image flags of one `Atoms` line.
type AtomLine = (u32, [f64; 3], [i32; 3]);

/// Reads a data file with at most `limit` atoms (checked before allocating).
pub fn read_lammps_data<R: BufRead>(r: R, limit: usize) -> Result<System, MdError> {
    let lines: Vec<String> = r.lines().collect::<Result<_, _>>()?;
    let (mut n, mut ntypes) = (None, None);
    let mut lo = [0.0; 3];
    let mut hi = [f64::NAN; 3];
    let mut i = 1; // first line is a comment
    let num = |s: &str, no: usize| s.parse::<f64>().map_err(|_| perr(F, no, "a number"));
    // header
    while i < lines.len() {
        let l = lines[i].split('#').next().unwrap_or("").trim();
        let t: Vec<&str> = l.split_whitespace().collect();
        let no = i + 1;
        if t.is_empty() {
            i += 1;
            continue;
        }
        if t.len() == 2 && t[1] == "atoms" {
            n = Some(
                t[0].parse::<usize>()
                    .map_err(|_| perr(F, no, "an atom count"))?,
            );
        } else if t.len() == 3 && t[1] == "atom" && t[2] == "types" {
            ntypes = Some(
                t[0].parse::<usize>()
                    .map_err(|_| perr(F, no, "a type count"))?,
            );
        } else if t.len() == 4 && t[3].ends_with("hi") && t[2].ends_with("lo") {
            let k = match t[2] {
                "xlo" => 0,
                "ylo" => 1,
                "zlo" => 2,
                _ => return Err(perr(F, no, "xlo xhi, ylo yhi or zlo zhi")),
            };
            lo[k] = num(t[0], no)?;
            hi[k] = num(t[1], no)?;
        } else if t.len() == 6 && t[3..] == ["xy", "xz", "yz"] {
            if t[..3].iter().any(|s| s.parse::<f64>().ok() != Some(0.0)) {
                return Err(perr(F, no, "an orthogonal box (zero tilt factors)"));
            }
        } else if t[0].chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
            break; // first section
        }
        i += 1;
    }
    let n = n.ok_or(perr(F, i + 1, "an 'N atoms' header line"))?;
    let ntypes = ntypes.unwrap_or(1);
    let sim_box = SimBox::new(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])?;
    if n > limit {
        return Err(MdError::Particle(pdyn_particles::ParticleError::TooMany {
            requested: n,
            limit,
        }));
    }
    let mut masses = vec![f64::NAN; ntypes];
    let mut atoms: Vec<Option<AtomLine>> = vec![None; n];
    let mut vels = vec![[0.0; 3]; n];
    while i < lines.len() {
        let head = lines[i].split('#').next().unwrap_or("").trim().to_string();
        i += 1;
        if head.is_empty() {
            continue;
        }
        let count = match head.as_str() {
            "Masses" => ntypes,
            "Atoms" | "Velocities" => n,
            _ => 0, // unknown section: skip its block
        };
        // skip blank lines after the header
        while i < lines.len() && lines[i].trim().is_empty() {
            i += 1;
        }
        if count == 0 {
            while i < lines.len() && !lines[i].trim().is_empty() {
                i += 1;
            }
            continue;
        }
        for _ in 0..count {
            let no = i + 1;
            let line = lines.get(i).ok_or(perr(F, no, "a section line"))?;
            let t: Vec<&str> = line
                .split('#')
                .next()
                .unwrap_or("")
                .split_whitespace()
                .collect();
            let id = |s: &str, len: usize| -> Result<usize, MdError> {
                let v: usize = s
                    .parse()
                    .map_err(|_| perr(F, no, "a positive integer id"))?;
                if v == 0 || v > len {
                    return Err(MdError::IndexOutOfRange {
                        what: "data-file id",
                        index: v,
                        len,
                    });
                }
                Ok(v - 1)
            };
            match head.as_str() {
                "Masses" if t.len() >= 2 => masses[id(t[0], ntypes)?] = num(t[1], no)?,
                "Atoms" if t.len() == 5 || t.len() == 8 => {
                    let a = id(t[0], n)?;
                    let ty = id(t[1], ntypes)? as u32;
                    let r = [
                        num(t[2], no)? - lo[0],
                        num(t[3], no)? - lo[1],
                        num(t[4], no)? - lo[2],
                    ];
                    let mut im = [0; 3];
                    if t.len() == 8 {
                        for k in 0..3 {
                            im[k] = t[5 + k].parse().map_err(|_| perr(F, no, "an image flag"))?;
                        }
                    }
                    atoms[a] = Some((ty, r, im));
                }
                "Velocities" if t.len() >= 4 => {
                    vels[id(t[0], n)?] = [num(t[1], no)?, num(t[2], no)?, num(t[3], no)?];
                }
                _ => return Err(perr(F, no, "a line of the section (atomic style)")),
            }
            i += 1;
        }
    }
    let mut p = Particles::with_capacity(n, limit)?;
    let mut types = Vec::with_capacity(n);
    let mut images = Vec::with_capacity(n);
    for (k, a) in atoms.iter().enumerate() {
        let (ty, r, im) = a.ok_or(perr(F, lines.len(), "every atom id in the Atoms section"))?;
        let _ = k;
        let mass = masses[ty as usize];
        if mass.is_nan() {
            return Err(perr(F, lines.len(), "a Masses entry for every type"));
        }
        p.push(Particle {
            mass,
            pos: Vec3(r),
            vel: Vec3(vels[k]),
        })?;
        types.push(ty);
        images.push(im);
    }
    let mut s = System::new(p, sim_box);
    s.types = types;
    s.images = images;
    Ok(s)
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
