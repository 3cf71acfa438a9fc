//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` (in
//! crates/pdyn-cli/tests/all.rs) checks every crate.
// The files share helpers (`mod common;`, `#[path = "common/..."]`) as they did when each
// was its own binary: each file keeps its own copy of them.
#![allow(clippy::duplicate_mod)]

#[path = "contact.rs"]
mod contact;
#[path = "data_tables.rs"]
mod data_tables;
#[path = "ensemble_no_table.rs"]
mod ensemble_no_table;
#[path = "fit.rs"]
mod fit;
#[path = "many_dof_closed_forms.rs"]
mod many_dof_closed_forms;
#[path = "md_data_file.rs"]
mod md_data_file;
#[path = "md_interrupt.rs"]
mod md_interrupt;
#[path = "md_sampling.rs"]
mod md_sampling;
#[path = "md_thermo_csv.rs"]
mod md_thermo_csv;
#[path = "optimize.rs"]
mod optimize;
#[path = "particle_net.rs"]
mod particle_net;
#[path = "resonance.rs"]
mod resonance;
#[path = "run.rs"]
mod run;
#[path = "si_twins.rs"]
mod si_twins;
#[path = "streamed_mechanics.rs"]
mod streamed_mechanics;
#[path = "table_net.rs"]
mod table_net;
