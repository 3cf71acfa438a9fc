//! MSD and RDF on their own schedules (`msd_every`, `rdf_every`, `rdf_range`, `rdf_bins`), the
//! RDF's block error bars, and located errors for schedules that cannot be honoured.

use pdyn::md::{self, RunOptions};
use pdyn_jit::JitMode;
use std::path::Path;

fn model(extra: &str) -> String {
    format!(
        "name = \"lj\"\n[md]\ndt = 0.005\nsteps = 60\nthermo_every = 20\nmsd = true\nrdf = true\n{extra}\n\
         [md.species.Ar]\nmass = 1.0\n\n\
         [[md.pairs]]\nkind = \"lj\"\nepsilon = 1.0\nsigma = 1.0\ncutoff = 2.5\n\n\
         [md.lattice]\nkind = \"fcc\"\ndensity = 0.8442\ncells = 4\n\n\
         [md.velocities]\ntemperature = 1.44\nseed = 3\n"
    )
}

fn run(text: &str) -> Result<md::MdResult, String> {
    let spec = md::load(text, "m.toml", &[]).map_err(|e| e.to_string())?;
    let mut prep = md::build(&spec, Path::new("."), JitMode::Auto).map_err(|e| e.message)?;
    md::run(&mut prep, &RunOptions::default(), &mut |_| {}).map_err(|e| e.to_string())
}

#[test]
fn msd_follows_msd_every_not_thermo_every() {
    let res = run(&model("msd_every = 7")).unwrap();
    let steps: Vec<u64> = res.msd.iter().map(|m| m[0] as u64).collect();
    // every 7 steps from 0, and the last step
    assert_eq!(steps, vec![0, 7, 14, 21, 28, 35, 42, 49, 56, 60]);
    assert_eq!(res.msd[0][2], 0.0);
    assert!(res.msd.windows(2).all(|w| w[1][1] > w[0][1]));
    // block error bars beside every value: zero at the origin, then positive and well below
    // the MSD itself (256 atoms, 5 blocks)
    assert_eq!(res.msd_error.len(), res.msd.len());
    assert_eq!(res.msd_error[0], 0.0);
    for (m, e) in res.msd.iter().zip(&res.msd_error).skip(1) {
        assert!(*e > 0.0 && *e < 0.5 * m[2], "msd {} ± {e}", m[2]);
    }
    // thermo records are unchanged by the MSD's schedule
    let rec: Vec<u64> = res.records.iter().map(|r| r.step).collect();
    assert_eq!(rec, vec![0, 20, 40, 60]);
    // by default, at the thermo steps, as before
    let res = run(&model("")).unwrap();
    let steps: Vec<u64> = res.msd.iter().map(|m| m[0] as u64).collect();
    assert_eq!(steps, vec![0, 20, 40, 60]);
}

#[test]
fn rdf_every_range_and_bins_set_the_histogram_with_block_errors() {
    let res = run(&model("rdf_every = 3\nrdf_range = 2.0\nrdf_bins = 40")).unwrap();
    // multiples of 3 in [30, 60]: 30, 33, …, 60
    assert_eq!(res.rdf_frames, 11);
    let (r, g) = res.rdf.as_ref().unwrap();
    assert_eq!(r.len(), 40);
    assert!(
        (r[39] - (2.0 - 0.025)).abs() < 1e-12,
        "last bin centre {}",
        r[39]
    );
    let e = res
        .rdf_error
        .as_ref()
        .expect("block errors with 11 frames in 5 blocks");
    assert_eq!(e.len(), 40);
    // no pairs inside the core: g = 0 exactly with zero spread; the first peak has a spread
    assert_eq!((g[5], e[5]), (0.0, 0.0));
    let peak = (0..40).max_by(|&a, &b| g[a].total_cmp(&g[b])).unwrap();
    assert!(
        g[peak] > 2.0 && e[peak] > 0.0 && e[peak] < 0.5 * g[peak],
        "{} ± {}",
        g[peak],
        e[peak]
    );
}

#[test]
fn impossible_schedules_are_located_errors() {
    let text = model("rdf_range = 9.0");
    let e = run(&text).unwrap_err();
    assert!(e.contains("more than half the shortest box edge"), "{e}");
    let e = run(&model("rdf_every = 3\nrdf_frames = 4")).unwrap_err();
    assert!(e.contains("both `rdf_every` and `rdf_frames`"), "{e}");
    for bad in ["msd_every = 0", "rdf_every = -2", "rdf_range = 0"] {
        let e = run(&model(bad)).unwrap_err();
        let key = bad.split(' ').next().unwrap();
        assert!(e.contains(key), "{bad}: {e}");
    }
}

/// The steps at which `md::run` reports frames (`Progress::Frame`), and whether it writes
/// `traj.xyz` (it must not without a directory).
fn frame_steps(text: &str, frame_every: u64) -> (Vec<u64>, u64) {
    let spec = md::load(text, "m.toml", &[]).unwrap();
    let mut prep = md::build(&spec, Path::new("."), JitMode::Auto).unwrap();
    let opts = RunOptions {
        frame_every,
        ..RunOptions::default()
    };
    let mut steps = Vec::new();
    let res = md::run(&mut prep, &opts, &mut |p| {
        if let md::Progress::Frame { step, system } = p {
            assert_eq!(system.particles.len(), 256);
            steps.push(step);
        }
    })
    .unwrap();
    (steps, res.frames)
}

#[test]
fn frames_for_a_display_follow_frame_every_else_dump_every_and_write_no_file() {
    // asked for: every 25 steps from 0 (the thermo and dump schedules do not matter)
    let (steps, files) = frame_steps(&model("dump_every = 30"), 25);
    assert_eq!(steps, vec![0, 25, 50]);
    assert_eq!(files, 0, "no directory: no traj.xyz frame written");
    // not asked for: the model's dump_every
    let (steps, _) = frame_steps(&model("dump_every = 30"), 0);
    assert_eq!(steps, vec![0, 30, 60]);
    // neither: no frames
    let (steps, _) = frame_steps(&model(""), 0);
    assert!(steps.is_empty(), "{steps:?}");
}

/// The thermo records of a Langevin run whose target temperature ramps, with frames asked
/// every `frame_every` steps (0: none), printed exactly (`{:?}` of an f64 round-trips).
fn ramp_records(frame_every: u64) -> String {
    let text = model(
        "[md.thermostat]\nkind = \"langevin\"\ntemperature = 1.0\nfinal_temperature = 2.0\ndamping = 0.5\nseed = 11",
    );
    let spec = md::load(&text, "m.toml", &[]).unwrap();
    let mut prep = md::build(&spec, Path::new("."), JitMode::Auto).unwrap();
    let opts = RunOptions {
        frame_every,
        ..RunOptions::default()
    };
    let res = md::run(&mut prep, &opts, &mut |_| {}).unwrap();
    format!("{:?}", res.records)
}

#[test]
fn watching_a_ramped_run_does_not_change_it() {
    // A display asking for frames every 5 steps cuts the run into shorter stretches than the
    // thermo blocks; the thermostat's ramp must not follow those cuts (it did: the page's
    // argon melting ended 23 kcal/mol away from the CLI's).
    let plain = ramp_records(0);
    assert_eq!(ramp_records(5), plain);
    assert_eq!(ramp_records(7), plain);
}
