//! An `[md]` model reading a LAMMPS data file with bonds (the layout of LAMMPS's
//! `bench/data.chain`), FENE + WCA bonds and `special_lj = [0, 1, 1]` as `bench/in.chain`
//! sets them: the initial energy equals a direct sum written here from LAMMPS's formulas;
//! what pdyn-md cannot model (charges, angles) and bonds without coefficients are errors at the
//! data file's line; the neighbour-list policy keys are obeyed.

use pdyn::md::{self, RunOptions};
use pdyn_jit::JitMode;
use std::path::{Path, PathBuf};

const CHAINS: usize = 8;
const BEADS: usize = 12;
const L: f64 = 10.0;
const RC: f64 = 1.122_46;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdyn-md-data-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Bead positions: zig-zag chains along x (bond ≈ 0.971), 1.2 apart in y, 3 apart in z.
fn beads() -> Vec<[f64; 3]> {
    let mut r = vec![];
    for c in 0..CHAINS {
        let (a, b) = (c % 4, c / 4);
        for k in 0..BEADS {
            r.push([
                0.5 + 0.8 * k as f64 + 0.01 * ((7 * c + k) % 5) as f64,
                1.0 + 1.2 * a as f64 + 0.55 * (k % 2) as f64,
                2.0 + 3.0 * b as f64,
            ]);
        }
    }
    r
}

/// The data file in `bench/data.chain`'s layout (box from −L/2, no style comment, 9 columns).
fn data_file() -> String {
    let r = beads();
    let n = r.len();
    let nb = CHAINS * (BEADS - 1);
    let h = L / 2.0;
    let mut s = format!(
        "LAMMPS FENE chain data file\n\n{n:>11}  atoms\n{nb:>11}  bonds\n          0  angles\n          0  dihedrals\n          0  impropers\n\n          1  atom types\n          1  bond types\n          0  angle types\n          0  dihedral types\n          0  improper types\n\n {:.4} {h:.4} xlo xhi\n {:.4} {h:.4} ylo yhi\n {:.4} {h:.4} zlo zhi\n\nMasses\n\n      1   1.000000\n\nAtoms\n\n",
        -h, -h, -h
    );
    for (i, p) in r.iter().enumerate() {
        s += &format!(
            "{:>7} {:>6} {:>6} {:>12.6} {:>12.6} {:>12.6} {:>3} {:>3} {:>3}\n",
            i + 1,
            i / BEADS + 1,
            1,
            p[0] - h,
            p[1] - h,
            p[2] - h,
            0,
            0,
            0
        );
    }
    s += "\nBonds\n\n";
    let mut b = 0;
    for c in 0..CHAINS {
        for k in 0..BEADS - 1 {
            b += 1;
            let i = c * BEADS + k + 1;
            s += &format!("{b:>7} {:>3} {i:>6} {:>6}\n", 1, i + 1);
        }
    }
    s
}

fn model(extra: &str) -> String {
    format!(
        "name = \"chain\"\n[md]\ndt = 0.012\nsteps = 20\nthermo_every = 10\nskin = 0.4\n\
         special_lj = [0, 1, 1]\n{extra}\n\
         [md.species.A]\nmass = 1.0\n\n\
         [[md.pairs]]\nkind = \"lj\"\nepsilon = 1.0\nsigma = 1.0\ncutoff = {RC}\nmode = \"shifted-energy\"\n\n\
         [[md.bond_types]]\nkind = \"fene\"\nk = 30.0\nr_max = 1.5\nepsilon = 1.0\nsigma = 1.0\n\n\
         [md.read]\nfile = \"chain.data\"\n\n\
         [md.thermostat]\nkind = \"langevin\"\ntemperature = 1.0\ndamping = 10.0\nseed = 904297\n"
    )
}

fn build(dir: &Path, model_text: &str, data: &str) -> Result<md::Prepared, String> {
    std::fs::write(dir.join("chain.data"), data).unwrap();
    let origin = dir.join("chain.toml");
    let spec = md::load(model_text, origin.to_str().unwrap(), &[]).map_err(|e| e.to_string())?;
    md::build(&spec, dir, JitMode::Auto)
        .map_err(|e| format!("{}: {}", e.message, e.help.unwrap_or_default()))
}

#[test]
fn chain_data_file_with_special_bonds_starts_at_the_direct_energy() {
    let d = scratch("energy");
    // positions pass through the file with 6 decimals: the direct sum uses the same numbers
    let data = data_file();
    let mut prep = build(&d, &model(""), &data).unwrap();
    let res = md::run(&mut prep, &RunOptions::default(), &mut |_| {}).unwrap();
    let n = (CHAINS * BEADS) as f64;
    let u0 = res.records[0].potential;
    let want = direct_energy();
    println!("U/N = {:.15}, direct {:.15}", u0 / n, want / n);
    assert!((u0 - want).abs() / n < 1e-10, "{u0} vs {want}");
    assert!(res.failure.is_none());
    assert_eq!(res.steps, 20);
    // without the exclusion the bonded pairs would also feel the pair potential (the check
    // can fail: the scaling changes the energy here)
    let mut all = build(&d, &model("").replace("[0, 1, 1]", "[1, 1, 1]"), &data).unwrap();
    let res = md::run(&mut all, &RunOptions::default(), &mut |_| {}).unwrap();
    assert!((res.records[0].potential - want).abs() / n > 0.1);
}

/// LAMMPS's energies, written out, at the positions as the file has them (6 decimals):
/// `pair lj/cut` with `pair_modify shift yes` between every pair not bonded (special_bonds lj
/// 0 1 1 excludes 1-2 pairs only), `bond_style fene`
/// `−½KR₀² ln(1 − (r/R₀)²) + 4ε[(σ/r)¹² − (σ/r)⁶] + ε` (r < 2^{1/6}σ) on each bond.
fn direct_energy() -> f64 {
    let r: Vec<[f64; 3]> = beads()
        .iter()
        .map(|p| p.map(|x| format!("{:.6}", x - L / 2.0).parse::<f64>().unwrap() + L / 2.0))
        .collect();
    let n = r.len();
    let lj = |r2: f64| {
        let s6 = 1.0 / (r2 * r2 * r2);
        4.0 * (s6 * s6 - s6)
    };
    let mut u = 0.0;
    for i in 0..n {
        for j in i + 1..n {
            let r2: f64 = r[i]
                .iter()
                .zip(&r[j])
                .map(|(a, b)| {
                    let d = a - b;
                    (d - L * (d / L).round()).powi(2)
                })
                .sum();
            if i / BEADS == j / BEADS && j - i == 1 {
                u += -0.5 * 30.0 * 1.5 * 1.5 * libm::log(1.0 - r2 / 2.25);
                if r2 < libm::pow(2f64, 1.0 / 3.0) {
                    u += lj(r2) + 1.0;
                }
            } else if r2 < RC * RC {
                u += lj(r2) - lj(RC * RC);
            }
        }
    }
    u
}

#[test]
fn charges_angles_and_untyped_bonds_are_errors_at_the_data_files_line() {
    let d = scratch("errors");
    let data = data_file();
    // a charge: atom_style full, atom 3 charged
    let mut full = data.replace("Atoms\n", "Atoms # full\n");
    let lines: Vec<String> = full
        .lines()
        .map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.len() == 9 && !l.contains("Atoms") {
                let q = if t[0] == "3" { "0.5" } else { "0" };
                format!(
                    "{} {} {} {q} {} {} {} {} {} {}",
                    t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], t[8]
                )
            } else {
                l.to_string()
            }
        })
        .collect();
    full = lines.join("\n") + "\n";
    let line_of_atom3 = full
        .lines()
        .position(|l| l.starts_with("3 1 1 0.5"))
        .unwrap()
        + 1;
    let e = build(&d, &model(""), &full).unwrap_err();
    assert!(
        e.contains(&format!(
            "chain.data: lammps-data line {line_of_atom3}: atom 3 has charge 0.5"
        )),
        "{e}"
    );
    // angles
    let with_angles = data
        .replace("          0  angles", "          1  angles")
        .replace("          0  angle types", "          1  angle types")
        + "\nAngles\n\n1 1 1 2 3\n";
    let line = with_angles.lines().count();
    let e = build(&d, &model(""), &with_angles).unwrap_err();
    assert!(
        e.contains(&format!("lammps-data line {line}: the file has 1 angles")),
        "{e}"
    );
    // a second bond type without coefficients
    let two_types = data
        .replace("          1  bond types", "          2  bond types")
        .replace("     12   1     13     14", "     12   2     13     14");
    let line = two_types
        .lines()
        .position(|l| l.starts_with("     12   2"))
        .unwrap()
        + 1;
    let e = build(&d, &model(""), &two_types).unwrap_err();
    assert!(
        e.contains(&format!(
            "lammps-data line {line}: the file has 88 bonds of 2 bond type(s)"
        )),
        "{e}"
    );
    // and with them, it builds
    let second = "\n[[md.bond_types]]\nkind = \"harmonic\"\nk = 100.0\nr0 = 0.97\n";
    let text = model("").replace("[md.read]", &format!("{second}\n[md.read]"));
    build(&d, &text, &two_types).unwrap();
    // an unsupported style, through the model
    let e = build(&d, &model(""), &data.replace("Atoms\n", "Atoms # sphere\n")).unwrap_err();
    assert!(e.contains("unsupported atom_style `sphere`"), "{e}");
}

#[test]
fn neighbour_policy_keys_set_the_rebuild_schedule() {
    let d = scratch("neigh");
    let data = data_file();
    let mut prep = build(
        &d,
        &model("neighbor_every = 5\nneighbor_check = false"),
        &data,
    )
    .unwrap();
    let res = md::run(&mut prep, &RunOptions::default(), &mut |_| {}).unwrap();
    assert_eq!(
        res.builds, 4,
        "every 5 check no: a rebuild at steps 5, 10, 15, 20"
    );
    let e = md::load(&model("neighbor_every = 0"), "m.toml", &[]).unwrap_err();
    assert!(e.to_string().contains("neighbor_every"), "{e}");
    let e = md::load(
        &model("").replace("special_lj = [0, 1, 1]", "special_lj = [0, 1]"),
        "m.toml",
        &[],
    )
    .unwrap_err();
    assert!(e.to_string().contains("three factors"), "{e}");
}
