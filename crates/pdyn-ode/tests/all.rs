//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` (in
//! crates/pdyn-cli/tests/all.rs) checks every crate.
// The files share helpers (`mod common;`, `#[path = "common/..."]`) as they did when each
// was its own binary: each file keeps its own copy of them.
#![allow(clippy::duplicate_mod)]

#[path = "api.rs"]
mod api;
#[path = "bdf.rs"]
mod bdf;
#[path = "convergence.rs"]
mod convergence;
#[path = "dense_solution.rs"]
mod dense_solution;
#[path = "events.rs"]
mod events;
#[path = "implicit_sparse.rs"]
mod implicit_sparse;
#[path = "kepler_energy.rs"]
mod kepler_energy;
#[path = "published_stats.rs"]
mod published_stats;
#[path = "reference_solutions.rs"]
mod reference_solutions;
#[path = "resume.rs"]
mod resume;
