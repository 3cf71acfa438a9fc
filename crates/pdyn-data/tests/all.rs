//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` (in
//! crates/pdyn-cli/tests/all.rs) checks every crate.
// The files share helpers (`mod common;`, `#[path = "common/..."]`) as they did when each
// was its own binary: each file keeps its own copy of them.
#![allow(clippy::duplicate_mod)]

#[path = "csv_errors.rs"]
mod csv_errors;
#[path = "fusion.rs"]
mod fusion;
#[path = "numerics.rs"]
mod numerics;
#[path = "parquet.rs"]
mod parquet;
