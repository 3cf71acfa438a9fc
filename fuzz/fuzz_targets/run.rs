//! Structure-aware fuzzing of `pdyn run` (derive, compile, integrate a short span, tabulate,
//! monitor) on mutated shipped examples.
//! Run: `RUSTC_BOOTSTRAP=1 cargo fuzz run run -- -max_total_time=1800 -timeout=30`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pdyn::sim::{self, RunSettings};

#[path = "examples.rs"]
mod examples;

fuzz_target!(|data: &[u8]| {
    let Some((name, src)) = examples::mutate(data) else { return };
    let Ok(mut model) = pdyn_mech::load(&src, name) else { return };
    let Ok(mut set) = RunSettings::from_spec(&model.run.simulate) else { return };
    // A short run with a step budget: the fuzzer looks for crashes, not long integrations.
    set.t_end = set.t_end.min(0.05);
    set.max_steps = Some(20_000);
    set.points = set.points.map(|p| p.min(1000));
    set.output_dt = None;
    let Ok(prep) = sim::prepare(&mut model) else { return };
    let _ = sim::run(&prep, &set);
});
