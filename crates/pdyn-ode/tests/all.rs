//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` checks.
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
#[path = "kepler_energy.rs"]
mod kepler_energy;
#[path = "published_stats.rs"]
mod published_stats;
#[path = "radau5_sparse.rs"]
mod radau5_sparse;
#[path = "reference_solutions.rs"]
mod reference_solutions;
#[path = "resume.rs"]
mod resume;

/// A file under tests/ that is not a module above would never be compiled or run.
#[test]
fn every_test_file_is_a_module() {
    let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let listed = include_str!("all.rs");
    for entry in std::fs::read_dir(&here).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.ends_with(".rs") && name != "all.rs" {
            assert!(
                listed.contains(&format!("#[path = \"{name}\"]")),
                "tests/{name} is not a module of tests/all.rs: add it there"
            );
        }
    }
}
