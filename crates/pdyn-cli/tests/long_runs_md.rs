//! Long MD runs (issue 29): a run killed with SIGKILL at random (seeded) instants and
//! restarted from its last checkpoint each time ends with the files of the same run left
//! alone, byte for byte (`thermo.csv`, `traj.xyz`, `rdf.csv`, `msd.csv`, `summary.json` but
//! for its bookkeeping and wall-clock fields), for NVE, Langevin (a temperature ramp, whose
//! noise must continue from the saved generator) and Nosé–Hoover; after every kill the files
//! end with whole rows and frames; SIGTERM stops a run with a checkpoint it continues from;
//! bad checkpoints are refused (exit 2).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

mod long_run_common;
use long_run_common::{
    assert_whole_csv, bin, example, fresh_dir, kill_repeatedly, run_args, whole_lines, Rng,
};

const FILES: [&str; 4] = ["thermo.csv", "traj.xyz", "rdf.csv", "msd.csv"];

/// A model derived from an example by text replacements (each must apply), written into
/// `dir`: the examples are the models; the tests only add outputs or a thermostat.
fn derived_model(dir: &Path, example_path: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(example(example_path)).expect("the example");
    for (from, to) in edits {
        assert!(text.contains(from), "{example_path} has no `{from}`");
        text = text.replacen(from, to, 1);
    }
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("model.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// `thermo.csv`: every line up to the last newline is a whole row (the header's columns,
/// numbers); `traj.xyz`: whole frames (count, comment, that many atom lines), but after a
/// kill the last frame may be cut. A SIGKILL can cut a `write` between pages (see
/// docs/long-runs.md), leaving part of a row at the end: allowed only `after_kill` (the
/// restart truncates it); after a clean stop both files end with a whole row or frame.
fn assert_whole_rows(dir: &Path, when: &str, after_kill: bool) {
    assert_whole_csv(dir, "thermo.csv", when, after_kill, true);
    if let Ok(text) = std::fs::read_to_string(dir.join("traj.xyz")) {
        let (whole, rest) = whole_lines(&text);
        assert!(after_kill || !rest, "{when}: traj.xyz ends inside a line");
        let lines: Vec<&str> = whole.lines().collect();
        let mut k = 0;
        while k < lines.len() {
            let n: usize = lines[k]
                .trim()
                .parse()
                .unwrap_or_else(|_| panic!("{when}: traj.xyz line {} is no atom count", k + 1));
            let end = k + 2 + n;
            if end > lines.len() {
                assert!(after_kill, "{when}: traj.xyz ends inside a frame");
                break;
            }
            for line in &lines[k + 2..end] {
                let cells: Vec<&str> = line.split_whitespace().collect();
                assert!(
                    cells.len() >= 4 && cells[1..4].iter().all(|c| c.parse::<f64>().is_ok()),
                    "{when}: traj.xyz atom line: {line}"
                );
            }
            k = end;
        }
    }
}

/// `summary.json` without what says how the run was carried out: the checkpoint file, where
/// it restarted from, and the wall-clock time (which differs between any two runs).
fn summary_without_bookkeeping(dir: &Path) -> serde_json::Value {
    let mut v = long_run_common::summary_without_bookkeeping(dir);
    let m = v.as_object_mut().expect("an object");
    if let Some(md) = m.get_mut("md").and_then(|x| x.as_object_mut()) {
        md.remove("loop_seconds");
        md.remove("atom_steps_per_second");
    }
    m.remove("loop_seconds");
    m.remove("atom_steps_per_second");
    v
}

fn reference_run(tag: &str, model: &Path, extra: &[&str]) -> PathBuf {
    let reference = fresh_dir(&format!("{tag}-ref"));
    let st = Command::new(bin())
        .args(run_args(model, extra, &reference))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("run pdyn");
    assert!(st.success(), "{tag}: the reference run failed: {st:?}");
    reference
}

/// Every output file and the summary of `dir` are the reference's, byte for byte.
fn assert_same_files(tag: &str, reference: &Path, dir: &Path) {
    let mut compared = 0;
    for name in FILES {
        let a = std::fs::read(reference.join(name)).ok();
        let b = std::fs::read(dir.join(name)).ok();
        compared += usize::from(a.is_some());
        assert!(
            a == b,
            "{tag}: {name} differs from the uninterrupted run's ({:?} vs {:?} bytes)",
            a.map(|x| x.len()),
            b.map(|x| x.len())
        );
    }
    assert!(compared >= 2, "{tag}: too few files to compare");
    let (a, b) = (
        summary_without_bookkeeping(reference),
        summary_without_bookkeeping(dir),
    );
    assert_eq!(a, b, "{tag}: summary.json differs");
}

/// Runs `model` once uninterrupted, then again killed `kills` times at seeded random instants
/// within `window_ms`, each time restarted from its last checkpoint (or from the start when
/// none was written yet), and compares the files.
fn killed_and_restarted_equals_uninterrupted(
    tag: &str,
    model: &Path,
    extra: &[&str],
    kills: usize,
    window_ms: u64,
    seed: u64,
) {
    let reference = reference_run(tag, model, extra);
    let dir = fresh_dir(&format!("{tag}-killed"));
    let (args, restarts) = kill_repeatedly(
        &dir,
        &run_args(model, extra, &dir),
        kills,
        window_ms,
        seed,
        |k| assert_whole_rows(&dir, &format!("{tag}: after kill {k}"), true),
    );
    let out = Command::new(bin()).args(&args).output().expect("run pdyn");
    assert!(
        out.status.success(),
        "{tag}: the last restart failed: {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(restarts > 0, "{tag}: no checkpoint was ever written");
    assert_whole_rows(&dir, &format!("{tag}: at the end"), false);
    assert_same_files(tag, &reference, &dir);
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}

/// LAMMPS's `bench/in.lj` liquid (500 atoms), NVE, with frames, MSD and RDF added.
fn nve_model(dir: &Path) -> PathBuf {
    derived_model(
        dir,
        "examples/md/lj_liquid.toml",
        &[(
            "thermo_every = 50",
            "thermo_every = 20\ndump_every = 500\nmsd = true\nmsd_every = 100\nrdf = true",
        )],
    )
}

#[test]
fn md_nve_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    let models = fresh_dir("nve-model");
    let model = nve_model(&models);
    killed_and_restarted_equals_uninterrupted(
        "nve",
        &model,
        &[
            "--set",
            "n=5",
            "--t-end",
            "20",
            "--checkpoint-every",
            "300steps",
        ],
        4,
        1200,
        29,
    );
    let _ = std::fs::remove_dir_all(&models);
}

/// Argon melting: Langevin with a temperature ramp, frames, MSD, RDF (256 atoms, 6,000 steps).
#[test]
fn md_langevin_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    killed_and_restarted_equals_uninterrupted(
        "langevin",
        &example("examples/md/argon_melting.toml"),
        &["--checkpoint-every", "500steps"],
        4,
        1200,
        2017,
    );
}

/// The same under Langevin's LAMMPS scheme (`scheme = "lammps"`: the friction and noise drawn
/// at a step live in the saved accelerations).
#[test]
fn md_langevin_lammps_scheme_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    let models = fresh_dir("langevin-lammps-model");
    let model = derived_model(
        &models,
        "examples/md/argon_melting.toml",
        &[(
            "kind = \"langevin\"",
            "kind = \"langevin\"\nscheme = \"lammps\"",
        )],
    );
    killed_and_restarted_equals_uninterrupted(
        "langevin-lammps",
        &model,
        &["--checkpoint-every", "500steps"],
        3,
        1200,
        2018,
    );
    let _ = std::fs::remove_dir_all(&models);
}

#[test]
fn md_nose_hoover_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    let models = fresh_dir("nh-model");
    let model = derived_model(
        &models,
        "examples/md/lj_liquid.toml",
        &[
            ("thermo_every = 50", "thermo_every = 25\ndump_every = 400"),
            (
                "[md.velocities]",
                "[md.thermostat]\nkind = \"nose-hoover\"\ntemperature = 1.2\ntau = 0.2\n\n[md.velocities]",
            ),
        ],
    );
    killed_and_restarted_equals_uninterrupted(
        "nose-hoover",
        &model,
        &[
            "--set",
            "n=5",
            "--t-end",
            "15",
            "--checkpoint-every",
            "250steps",
        ],
        3,
        1000,
        97,
    );
    let _ = std::fs::remove_dir_all(&models);
}

/// SIGTERM stops the run cleanly (exit 4, whole files) at whatever step it reached, inside a
/// stretch between two records; the checkpoint it writes there continues to the files of the
/// uninterrupted run (the restart falls back onto the same stretches).
#[cfg(unix)]
#[test]
fn md_sigterm_writes_a_checkpoint_that_continues_bit_for_bit() {
    let model = example("examples/md/argon_melting.toml");
    // the default: a checkpoint every 15 minutes, none due in a run of seconds
    let extra: [&str; 0] = [];
    let reference = reference_run("sigterm", &model, &extra);
    let dir = fresh_dir("sigterm");
    let mut rng = Rng(4);
    let ckpt = dir.join("checkpoint.json");
    let mut stopped = 0;
    for _ in 0..2 {
        let mut args = run_args(&model, &extra, &dir);
        if ckpt.exists() {
            args.extend(["--restart".to_string(), ckpt.display().to_string()]);
        }
        let mut child = Command::new(bin())
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start pdyn");
        std::thread::sleep(Duration::from_millis(250 + rng.below(600)));
        let st = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .expect("kill");
        assert!(st.success());
        let status = child.wait().expect("wait");
        if status.code() == Some(0) {
            break; // finished before the signal (a very fast machine)
        }
        assert_eq!(status.code(), Some(4), "exit code of an interrupted run");
        stopped += 1;
        assert_whole_rows(&dir, "after SIGTERM", false);
        let sum: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(sum["status"], "interrupted");
        assert!(
            ckpt.exists(),
            "the stop writes a checkpoint though none was due"
        );
    }
    assert!(stopped > 0, "the run was never stopped");
    let mut args = run_args(&model, &extra, &dir);
    args.extend(["--restart".to_string(), ckpt.display().to_string()]);
    let out = Command::new(bin()).args(&args).output().expect("run pdyn");
    assert!(
        out.status.success(),
        "the restart failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_same_files("sigterm", &reference, &dir);
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_md_checkpoints_are_refused_saying_what_differs() {
    let model = example("examples/md/argon_melting.toml");
    let extra = ["--t-end", "10000", "--checkpoint-every", "400steps"];
    let dir = fresh_dir("bad");
    let st = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let ckpt = dir.join("checkpoint.json");
    let good = std::fs::read_to_string(&ckpt).unwrap();
    let restart_with = |model: &Path, args: &[&str], expect: &str| {
        let mut a = run_args(model, args, &dir);
        a.extend(["--restart".to_string(), ckpt.display().to_string()]);
        let out = Command::new(bin()).args(&a).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{expect}: {err}");
        assert!(err.contains(expect), "expected `{expect}` in: {err}");
    };
    let restart = |args: &[&str], expect: &str| restart_with(&model, args, expect);
    // tampered: one digit of the state changed, the length kept
    let pos = good.rfind("\"done\":").unwrap() + 7;
    let mut bytes = good.clone().into_bytes();
    bytes[pos] = if bytes[pos] == b'1' { b'2' } else { b'1' };
    std::fs::write(&ckpt, &bytes).unwrap();
    restart(&extra, "checksum");
    // truncated
    std::fs::write(&ckpt, &good[..good.len() - 10]).unwrap();
    restart(&extra, "truncated");
    // other options: the run length, a parameter
    std::fs::write(&ckpt, &good).unwrap();
    restart(
        &["--t-end", "20000", "--checkpoint-every", "400steps"],
        "t_end",
    );
    restart(
        &[
            "--t-end",
            "10000",
            "--set",
            "n=5",
            "--checkpoint-every",
            "400steps",
        ],
        "set",
    );
    // another MD model
    restart_with(
        &example("examples/md/lj_liquid.toml"),
        &["--set", "n=5"],
        "another model",
    );
    // an N-body checkpoint given to an MD run
    let nbody_dir = fresh_dir("bad-nbody");
    let st = Command::new(bin())
        .args(run_args(
            &example("examples/nbody/outer_solar_system.toml"),
            &["--t-end", "40000", "--checkpoint-every", "100steps"],
            &nbody_dir,
        ))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    std::fs::copy(nbody_dir.join("checkpoint.json"), &ckpt).unwrap();
    restart(&extra, "checkpoint of a nbody run");
    // a checkpoint whose files lost rows
    std::fs::write(&ckpt, &good).unwrap();
    std::fs::write(dir.join("thermo.csv"), "step\n").unwrap();
    let mut a = run_args(&model, &extra, &dir);
    a.extend(["--restart".to_string(), ckpt.display().to_string()]);
    let out = Command::new(bin()).args(&a).output().unwrap();
    assert_ne!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stderr).contains("rows are missing"));
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&nbody_dir);
}
