//! LAMMPS data files of every supported `atom_style`: what is read and kept, and a located
//! error (the line, and what would be valid) for each kind of bad input.

use pdyn_md::io::{read_lammps_data, read_lammps_data_file, AtomStyle};
use pdyn_md::MdError;

/// The layout of LAMMPS's `bench/data.chain` (written by its `tools/chain` generator):
/// no style comment, `id mol type x y z ix iy iz`, zero angles/dihedrals/impropers declared,
/// dihedral and improper type counts in the header.
const CHAIN: &str = "\
LAMMPS FENE chain data file

          6  atoms
          4  bonds
          0  angles
          0  dihedrals
          0  impropers

          1  atom types
          1  bond types
          0  angle types
          0  dihedral types
          0  improper types

 -5.0   5.0 xlo xhi
 -5.0   5.0 ylo yhi
 -5.0   5.0 zlo zhi

Masses

      1   1.000000

Atoms

      1      1      1  -4.5    0.0    0.0       0   0   0
      2      1      1   4.6    0.0    0.0      -1   0   0
      3      1      1   3.7    0.0    0.0      -1   0   0
      4      2      1   0.0    1.0    1.0       0   0   0
      5      2      1   0.0    2.0    1.0       0   0   0
      6      2      1   0.0    3.0    1.0       0   0   0

Bonds

      1   1      1      2
      2   1      2      3
      3   1      4      5
      4   1      5      6
";

#[test]
fn data_chain_layout_loads_with_molecules_and_bonds() {
    let d = read_lammps_data_file(CHAIN.as_bytes(), 100).unwrap();
    assert_eq!(d.atom_style, AtomStyle::Bond);
    assert_eq!(d.system.particles.len(), 6);
    assert_eq!(d.molecules, vec![1, 1, 1, 2, 2, 2]);
    assert_eq!(d.bonds.len(), 4);
    assert_eq!(d.bonds[1].atoms, [1, 2]);
    assert_eq!(d.bonds[1].bond_type, 0);
    assert_eq!(d.bonds[1].line, 35);
    assert_eq!(d.system.images[1], [-1, 0, 0]);
    assert_eq!(d.system.particles.x[0], 0.5); // shifted by xlo = −5
    assert_eq!(d.charges, vec![0.0; 6]);
    assert_eq!(d.atom_lines[0], 25);
}

const FULL: &str = "\
full style: a branched molecule, two bond types, an angle

4 atoms
3 bonds
1 angles
2 atom types
2 bond types
1 angle types
0 10 xlo xhi
0 10 ylo yhi
0 10 zlo zhi

Masses

1 12.0
2 1.0

Bond Coeffs # harmonic

1 100 1.0
2 200 1.5

Atoms # full

1 7 1 0.0 5.0 5.0 5.0
2 7 2 0.0 6.0 5.0 5.0
3 7 2 0.0 5.0 6.0 5.0 0 0 1
4 7 2 0.0 4.0 5.0 5.0

Bonds

1 1 1 2
2 2 1 3
3 2 1 4

Angles

1 1 2 1 3
";

#[test]
fn full_style_keeps_charges_bond_types_and_angles() {
    let d = read_lammps_data_file(FULL.as_bytes(), 100).unwrap();
    assert_eq!(d.atom_style, AtomStyle::Full);
    assert_eq!(d.bond_types, 2);
    let types: Vec<usize> = d.bonds.iter().map(|b| b.bond_type).collect();
    assert_eq!(types, vec![0, 1, 1]);
    assert_eq!(d.angles.len(), 1);
    assert_eq!(d.angles[0].atoms, [1, 0, 2]);
    assert_eq!(d.masses, vec![Some(12.0), Some(1.0)]);
    assert_eq!(d.system.particles.m[1], 1.0);
    assert_eq!(d.molecules, vec![7; 4]);
    assert_eq!(d.system.images[2], [0, 0, 1]);
    let charged = FULL.replace("2 7 2 0.0 6.0", "2 7 2 -0.4 6.0");
    let d = read_lammps_data_file(charged.as_bytes(), 100).unwrap();
    assert_eq!(d.charges[1], -0.4); // kept: refusing it is the model's business
    assert_eq!(d.atom_lines[1], 26);
}

#[test]
fn angle_and_molecular_styles_read_like_bond() {
    for style in ["angle", "molecular", "bond"] {
        let text = CHAIN.replace("Atoms\n", &format!("Atoms # {style}\n"));
        let d = read_lammps_data_file(text.as_bytes(), 100).unwrap();
        assert_eq!(d.atom_style.name(), style);
        assert_eq!(d.bonds.len(), 4);
    }
}

/// The line of a located error, and its message.
fn located(text: &str) -> (usize, String) {
    match read_lammps_data_file(text.as_bytes(), 100) {
        Err(e @ MdError::InvalidInput { line, .. }) => (line, e.to_string()),
        Err(e @ MdError::Parse { line, .. }) => (line, e.to_string()),
        other => panic!("expected a located error, got {other:?}"),
    }
}

#[test]
fn bad_data_files_are_located_errors() {
    // an unsupported style
    let (line, msg) = located(&FULL.replace("Atoms # full", "Atoms # charge"));
    assert_eq!(line, 23, "{msg}");
    assert!(
        msg.contains("unsupported atom_style `charge`") && msg.contains("full"),
        "{msg}"
    );
    // a bond to a missing atom
    let (line, msg) =
        located(&CHAIN.replace("      4   1      5      6", "      4   1      5      9"));
    assert_eq!(line, 37, "{msg}");
    assert!(
        msg.contains("atom 9 does not exist") && msg.contains("1 to 6"),
        "{msg}"
    );
    // a dangling bond type
    let (line, msg) =
        located(&CHAIN.replace("      3   1      4      5", "      3   2      4      5"));
    assert_eq!(line, 36, "{msg}");
    assert!(msg.contains("bond type 2 does not exist"), "{msg}");
    // a dangling atom type
    let (line, msg) =
        located(&CHAIN.replace("      5      2      1   0.0", "      5      2      3   0.0"));
    assert_eq!(line, 29, "{msg}");
    assert!(msg.contains("atom type 3 does not exist"), "{msg}");
    // a dangling angle type
    let (line, msg) = located(&FULL.replace("1 1 2 1 3", "1 4 2 1 3"));
    assert_eq!(line, 38, "{msg}");
    assert!(msg.contains("angle type 4"), "{msg}");
    // the wrong number of columns for the style
    let (line, msg) = located(&FULL.replace("4 7 2 0.0 4.0 5.0 5.0", "4 7 2 4.0 5.0 5.0"));
    assert_eq!(line, 28, "{msg}");
    assert!(msg.contains("atom_style full has 7"), "{msg}");
    // an atom twice, an atom missing
    let (line, msg) = located(&CHAIN.replace("      6      2      1", "      5      2      1"));
    assert_eq!(line, 30, "{msg}");
    assert!(msg.contains("appears twice"), "{msg}");
    // a bond to itself
    let (line, _) =
        located(&CHAIN.replace("      4   1      5      6", "      4   1      5      5"));
    assert_eq!(line, 37);
    // dihedrals are refused at their section
    let text = format!("{CHAIN}\nDihedrals\n\n1 1 1 2 3 4\n");
    let (line, msg) = located(&text);
    assert_eq!(line, 39, "{msg}");
    assert!(msg.contains("no dihedral"), "{msg}");
    // a section the header does not count
    let text = CHAIN.replace("          4  bonds", "          0  bonds");
    let (line, msg) = located(&text);
    assert_eq!(line, 32, "{msg}");
    assert!(msg.contains("declares none"), "{msg}");
    // a truncated section
    let text = CHAIN.replace("          4  bonds", "          5  bonds");
    let (line, msg) = located(&text);
    assert!(
        msg.contains("ends inside the Bonds section"),
        "{line}: {msg}"
    );
    // a missing Masses entry is refused when the masses are needed
    let text = FULL.replace("Masses\n\n1 12.0\n2 1.0\n\n", "");
    assert!(matches!(
        read_lammps_data(text.as_bytes(), 100),
        Err(MdError::InvalidInput { line: 20, .. })
    ));
}

#[test]
fn huge_counts_are_refused_before_allocating() {
    let text = CHAIN.replace("          4  bonds", "  100000000000  bonds");
    assert!(matches!(
        read_lammps_data_file(text.as_bytes(), 100),
        Err(MdError::InvalidInput { line: 1, .. })
    ));
    let text = CHAIN.replace("          6  atoms", "  100000000000  atoms");
    assert!(matches!(
        read_lammps_data_file(text.as_bytes(), 100),
        Err(MdError::Particle(_))
    ));
}
