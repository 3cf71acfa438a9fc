//! Structure-aware fuzzing of the model loader, the derivation (`pdyn derive`) and the forces
//! of a prescribed motion (`pdyn forces`) on mutated shipped examples.
//! Run: `RUSTC_BOOTSTRAP=1 cargo fuzz run model -- -max_total_time=1800 -timeout=30`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "examples.rs"]
mod examples;

fuzz_target!(|data: &[u8]| {
    let Some((name, src)) = examples::mutate(data) else { return };
    let Ok(mut model) = pdyn_mech::load(&src, name) else { return };
    if model.run.simulate.t_end.is_some() || !model.checks.is_empty() || model.unknowns.is_empty() {
        let _ = pdyn_mech::derive(&mut model, &pdyn_mech::DeriveOptions::default());
    }
    if let Ok(mut model) = pdyn_mech::load(&src, name) {
        let _ = pdyn_mech::prescribed::solve_forces(&mut model, &Default::default());
    }
});
