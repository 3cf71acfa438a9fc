//! Every integration test of this crate in one binary: one link instead of one per file
//! (each linked the whole library with its debug information; that was most of CI's
//! test build). Run one file's tests with `cargo test -p CRATE --test all FILE::`.
//! A new file under tests/ must be added here: `every_test_file_is_a_module` (in
//! crates/pdyn-cli/tests/all.rs) checks every crate.
// The files share helpers (`mod common;`, `#[path = "common/..."]`) as they did when each
// was its own binary: each file keeps its own copy of them.
#![allow(clippy::duplicate_mod)]

#[path = "budgets.rs"]
mod budgets;
#[path = "classical_damping.rs"]
mod classical_damping;
#[path = "complexity.rs"]
mod complexity;
#[path = "derive_chapter.rs"]
mod derive_chapter;
#[path = "derive_newton_classics.rs"]
mod derive_newton_classics;
#[path = "dimensions.rs"]
mod dimensions;
#[path = "dsolve_chapter.rs"]
mod dsolve_chapter;
#[path = "dsolve_modal.rs"]
mod dsolve_modal;
#[path = "dsolve_rules.rs"]
mod dsolve_rules;
#[path = "dsolve_rules_symbolic.rs"]
mod dsolve_rules_symbolic;
#[path = "families.rs"]
mod families;
#[path = "family_initials.rs"]
mod family_initials;
#[path = "family_templates.rs"]
mod family_templates;
#[path = "forces_chapter.rs"]
mod forces_chapter;
#[path = "kin_chapter.rs"]
mod kin_chapter;
#[path = "matrix_form.rs"]
mod matrix_form;
#[path = "model_errors.rs"]
mod model_errors;
#[path = "net_scaling.rs"]
mod net_scaling;
#[path = "participation.rs"]
mod participation;
#[path = "row_tables.rs"]
mod row_tables;
#[path = "sparse_modes.rs"]
mod sparse_modes;
#[path = "statics.rs"]
mod statics;
#[path = "unknown_rates.rs"]
mod unknown_rates;
