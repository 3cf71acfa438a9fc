//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` (in
//! crates/pdyn-cli/tests/all.rs) checks every crate.
// The files share helpers (`mod common;`, `#[path = "common/..."]`) as they did when each
// was its own binary: each file keeps its own copy of them.
#![allow(clippy::duplicate_mod)]

#[path = "direct.rs"]
mod direct;
#[path = "events.rs"]
mod events;
#[path = "figure_eight.rs"]
mod figure_eight;
#[path = "ias15.rs"]
mod ias15;
#[path = "kepler_solver.rs"]
mod kepler_solver;
#[path = "plummer.rs"]
mod plummer;
#[path = "tree.rs"]
mod tree;
#[path = "whfast.rs"]
mod whfast;
