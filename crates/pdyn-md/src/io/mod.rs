//! Reading and writing configurations: extended XYZ (ASE, OVITO) and LAMMPS data files
//! (read: `atom_style` atomic, bond, angle, molecular, full; written: atomic).

mod lammps_data;
mod xyz;

pub use lammps_data::{
    read_lammps_data, read_lammps_data_file, write_lammps_data, AtomStyle, DataAngle, DataBond,
    LammpsData,
};
pub use xyz::{read_xyz, write_xyz, XyzFrame};

use crate::MdError;

fn perr(format: &'static str, line: usize, expected: &'static str) -> MdError {
    MdError::Parse {
        format,
        line,
        expected,
    }
}
