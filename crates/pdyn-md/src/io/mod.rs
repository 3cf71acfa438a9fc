//! Reading and writing configurations: extended XYZ (ASE, OVITO) and LAMMPS data files
//! (`atom_style atomic`).

mod lammps_data;
mod xyz;

pub use lammps_data::{read_lammps_data, write_lammps_data};
pub use xyz::{read_xyz, write_xyz, XyzFrame};

use crate::MdError;

fn perr(format: &'static str, line: usize, expected: &'static str) -> MdError {
    MdError::Parse {
        format,
        line,
        expected,
    }
}
