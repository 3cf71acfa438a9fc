//! The interrupt (Ctrl-C in Python) stops an MD run within a step, not at the end of the
//! current stretch between thermo records, and the steps taken are those of an uninterrupted
//! run.

use pdyn::md::{self, Progress, RunOptions};
use pdyn_jit::JitMode;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// One stretch of 400 steps: records only at steps 0 and 400.
const MODEL: &str = "name = \"lj\"\n[md]\ndt = 0.005\nsteps = 400\nthermo_every = 400\n\
     [md.species.Ar]\nmass = 1.0\n\n\
     [[md.pairs]]\nkind = \"lj\"\nepsilon = 1.0\nsigma = 1.0\ncutoff = 2.5\n\n\
     [md.lattice]\nkind = \"fcc\"\ndensity = 0.8442\ncells = 4\n\n\
     [md.velocities]\ntemperature = 1.44\nseed = 3\n";

fn prepared() -> md::Prepared {
    let spec = md::load(MODEL, "m.toml", &[]).unwrap();
    md::build(&spec, Path::new("."), JitMode::Auto).unwrap()
}

#[test]
fn interrupt_stops_inside_a_stretch_after_one_step() {
    let flag = Arc::new(AtomicBool::new(false));
    let opts = RunOptions {
        interrupt: Some(flag.clone()),
        ..RunOptions::default()
    };
    let mut prep = prepared();
    // the request arrives with the first record (step 0), before any step is taken
    let res = md::run(&mut prep, &opts, &mut |p| {
        if let Progress::Record(r) = p {
            if r.step == 0 {
                flag.store(true, Ordering::Relaxed);
            }
        }
    })
    .unwrap();
    assert!(res.interrupted);
    assert_eq!(res.steps, 1, "stopped after {} steps", res.steps);
    // the last record is that of step 1, and equals step 1 of an uninterrupted run of 1 step
    let last = res.records.last().unwrap();
    assert_eq!(last.step, 1);
    let spec = md::load(
        &MODEL.replace("steps = 400\n", "steps = 1\n"),
        "m.toml",
        &[],
    )
    .unwrap();
    let mut one = md::build(&spec, Path::new("."), JitMode::Auto).unwrap();
    let reference = md::run(&mut one, &RunOptions::default(), &mut |_| {}).unwrap();
    let r1 = reference.records.last().unwrap();
    assert_eq!(
        (r1.step, r1.total, r1.pressure),
        (1, last.total, last.pressure)
    );
}
