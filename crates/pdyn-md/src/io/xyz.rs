//! Extended XYZ (as written by ASE and read by OVITO): line 1 the count `N`, line 2
//! `Lattice="Lx 0 0 0 Ly 0 0 0 Lz" Properties=species:S:1:pos:R:3:velo:R:3 pbc="T T T"
//! Time=t Step=n`, then `N` lines `name x y z vx vy vz`. Only orthorhombic lattices are read.

use super::perr;
use crate::{MdError, SimBox, System};
use pdyn_particles::{Particle, Particles, Vec3};
use std::io::{BufRead, Write};

const F: &str = "xyz";

/// Writes one frame. `names[t]` names type `t` (missing names become `T<t>`).
pub fn write_xyz<W: Write>(
    w: &mut W,
    system: &System,
    names: &[&str],
    step: u64,
    time: f64,
) -> Result<(), MdError> {
    let p = &system.particles;
    let l = system.sim_box.l;
    writeln!(w, "{}", p.len())?;
    writeln!(
        w,
        "Lattice=\"{} 0 0 0 {} 0 0 0 {}\" Properties=species:S:1:pos:R:3:velo:R:3:mass:R:1 \
         pbc=\"T T T\" Time={time} Step={step}",
        l[0], l[1], l[2]
    )?;
    for i in 0..p.len() {
        let t = system.types[i] as usize;
        let fallback;
        let name = match names.get(t) {
            Some(n) => *n,
            None => {
                fallback = format!("T{t}");
                &fallback
            }
        };
        writeln!(
            w,
            "{name} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e} {}",
            p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i], p.vz[i], p.m[i]
        )?;
    }
    Ok(())
}

/// A frame read from an extended XYZ file.
#[derive(Debug, Clone)]
pub struct XyzFrame {
    /// Particles (type = index of the species name in `names`), box and no bonds.
    pub system: System,
    /// Species names in order of first appearance.
    pub names: Vec<String>,
}

/// Reads the first frame; at most `limit` particles (checked before allocating). Missing
/// velocities are zero, missing masses `default_mass`.
pub fn read_xyz<R: BufRead>(r: R, limit: usize, default_mass: f64) -> Result<XyzFrame, MdError> {
    let mut lines = r.lines();
    let mut next = |no: usize, what: &'static str| -> Result<String, MdError> {
        match lines.next() {
            Some(l) => Ok(l?),
            None => Err(perr(F, no, what)),
        }
    };
    let n: usize = next(1, "particle count")?
        .trim()
        .parse()
        .map_err(|_| perr(F, 1, "particle count"))?;
    let header = next(2, "comment line")?;
    let lat = value_of(&header, "Lattice").ok_or(perr(F, 2, "Lattice=\"...\""))?;
    let m: Vec<f64> = lat
        .split_whitespace()
        .map(|s| s.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| perr(F, 2, "9 lattice numbers"))?;
    if m.len() != 9 || [1, 2, 3, 5, 6, 7].iter().any(|&k| m[k] != 0.0) {
        return Err(perr(F, 2, "an orthorhombic Lattice (off-diagonal zeros)"));
    }
    let sim_box = SimBox::new(m[0], m[4], m[8])?;
    // columns
    let props = value_of(&header, "Properties").unwrap_or_else(|| "species:S:1:pos:R:3".into());
    let f: Vec<&str> = props.split(':').collect();
    let (mut col, mut cols) = (0usize, vec![]);
    for c in f.chunks(3) {
        if c.len() != 3 {
            return Err(perr(F, 2, "Properties=name:type:count triples"));
        }
        let k: usize = c[2].parse().map_err(|_| perr(F, 2, "a column count"))?;
        cols.push((c[0].to_string(), col, k));
        col += k;
    }
    let find = |name: &[&str]| {
        cols.iter()
            .find(|c| name.contains(&c.0.as_str()))
            .map(|c| (c.1, c.2))
    };
    let sp = find(&["species"]).ok_or(perr(F, 2, "a species column"))?;
    let pos = find(&["pos"])
        .filter(|c| c.1 == 3)
        .ok_or(perr(F, 2, "a pos:R:3 column"))?;
    let vel = find(&["velo", "vel", "velocities"]).filter(|c| c.1 == 3);
    let mass = find(&["mass", "masses"]);
    let mut p = Particles::with_capacity(n, limit)?;
    let mut names: Vec<String> = vec![];
    let mut types = Vec::with_capacity(n);
    for i in 0..n {
        let no = i + 3;
        let line = next(no, "a particle line")?;
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.len() < col {
            return Err(perr(F, no, "as many columns as Properties declares"));
        }
        let num = |k: usize| t[k].parse::<f64>().map_err(|_| perr(F, no, "a number"));
        let name = t[sp.0];
        let ty = match names.iter().position(|s| s == name) {
            Some(k) => k,
            None => {
                names.push(name.to_string());
                names.len() - 1
            }
        };
        types.push(ty as u32);
        let r = Vec3::new(num(pos.0)?, num(pos.0 + 1)?, num(pos.0 + 2)?);
        let v = match vel {
            Some((c, _)) => Vec3::new(num(c)?, num(c + 1)?, num(c + 2)?),
            None => Vec3::ZERO,
        };
        let mass = match mass {
            Some((c, _)) => num(c)?,
            None => default_mass,
        };
        p.push(Particle {
            mass,
            pos: r,
            vel: v,
        })?;
    }
    let mut system = System::new(p, sim_box);
    system.types = types;
    Ok(XyzFrame { system, names })
}

/// The value of `key=value` or `key="a b c"` in an extended-XYZ comment line.
fn value_of(header: &str, key: &str) -> Option<String> {
    let start = header.find(&format!("{key}="))? + key.len() + 1;
    let rest = &header[start..];
    if let Some(q) = rest.strip_prefix('"') {
        q.find('"').map(|e| q[..e].to_string())
    } else {
        Some(rest.split_whitespace().next().unwrap_or("").to_string())
    }
}
