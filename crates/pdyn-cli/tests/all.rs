//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` (in
//! crates/pdyn-cli/tests/all.rs) checks every crate.
// The files share helpers (`mod common;`, `#[path = "common/..."]`) as they did when each
// was its own binary: each file keeps its own copy of them.
#![allow(clippy::duplicate_mod)]

#[path = "check_scale.rs"]
mod check_scale;
#[path = "cli.rs"]
mod cli;
#[path = "cli_data.rs"]
mod cli_data;
#[path = "cli_dsolve.rs"]
mod cli_dsolve;
#[path = "cli_fit.rs"]
mod cli_fit;
#[path = "cli_kin.rs"]
mod cli_kin;
#[path = "cli_optimize.rs"]
mod cli_optimize;
#[path = "cli_solve_numeric.rs"]
mod cli_solve_numeric;
#[path = "derive_newton_cli.rs"]
mod derive_newton_cli;
#[path = "derive_print.rs"]
mod derive_print;
#[path = "derived_parameters.rs"]
mod derived_parameters;
#[path = "examples_snapshot.rs"]
mod examples_snapshot;
#[path = "exit_codes.rs"]
mod exit_codes;
#[path = "large_examples.rs"]
mod large_examples;
#[path = "long_runs.rs"]
mod long_runs;
#[path = "long_runs_md.rs"]
mod long_runs_md;
#[path = "long_runs_mechanics.rs"]
mod long_runs_mechanics;
#[path = "md_cli.rs"]
mod md_cli;
#[path = "mutations.rs"]
mod mutations;
#[path = "nbody_cli.rs"]
mod nbody_cli;
#[path = "statics_cli.rs"]
mod statics_cli;
#[path = "summary_schema.rs"]
mod summary_schema;
#[path = "tables_cli.rs"]
mod tables_cli;

/// A file under a crate's tests/ that is not a module of its `all.rs` would never be compiled
/// or run (`autotests = false`): checked here for every crate of the workspace that has one.
#[test]
fn every_test_file_is_a_module() {
    let crates = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut checked = 0;
    for krate in std::fs::read_dir(&crates).unwrap() {
        let tests = krate.unwrap().path().join("tests");
        let Ok(listed) = std::fs::read_to_string(tests.join("all.rs")) else {
            continue;
        };
        checked += 1;
        for entry in std::fs::read_dir(&tests).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            if name.ends_with(".rs") && name != "all.rs" {
                assert!(
                    listed.contains(&format!("#[path = \"{name}\"]")),
                    "{}/{name} is not a module of its all.rs: add it there",
                    tests.display()
                );
            }
        }
    }
    assert!(checked >= 8, "only {checked} crates have tests/all.rs");
}
