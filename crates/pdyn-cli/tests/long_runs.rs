//! Long runs (issue 29): a run killed with SIGKILL at random (seeded) instants and restarted
//! from its last checkpoint ends with the same files, byte for byte, as the same run left
//! alone; after every kill the files end with a whole row; a signal stops a run cleanly (exit
//! 4, summary status "interrupted"); bad checkpoints are refused (exit 2).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

mod long_run_common;
use long_run_common::{
    assert_whole_csv, bin, example, fresh_dir, kill_repeatedly, run_args,
    summary_without_bookkeeping,
};

const CSV: [&str; 3] = ["trajectory.csv", "elements.csv", "conservation.csv"];

/// Every CSV file present holds whole rows starting with a time ([`assert_whole_csv`];
/// `elements.csv` has empty cells for bodies without an orbit).
fn assert_whole_rows(dir: &Path, when: &str, after_kill: bool) {
    for name in CSV {
        assert_whole_csv(dir, name, when, after_kill, false);
    }
}

/// Runs `model` with `extra` options once uninterrupted, then again killed `kills` times at
/// seeded random instants within `window_ms`, each time restarted from its last checkpoint
/// (or from the start when none was written yet), and compares the files.
fn killed_and_restarted_equals_uninterrupted(
    tag: &str,
    model: &str,
    extra: &[&str],
    kills: usize,
    window_ms: u64,
    seed: u64,
) {
    let model = example(model);
    let reference = fresh_dir(&format!("{tag}-ref"));
    let st = Command::new(bin())
        .args(run_args(&model, extra, &reference))
        .stdout(Stdio::null())
        .status()
        .expect("run pdyn");
    assert!(st.success(), "the reference run failed: {st:?}");

    let dir = fresh_dir(&format!("{tag}-killed"));
    let (args, restarts) = kill_repeatedly(
        &dir,
        &run_args(&model, extra, &dir),
        kills,
        window_ms,
        seed,
        |k| assert_whole_rows(&dir, &format!("{tag}: after kill {k}"), true),
    );
    let st = Command::new(bin())
        .args(&args)
        .stdout(Stdio::null())
        .status()
        .expect("run pdyn");
    assert!(st.success(), "{tag}: the last restart failed: {st:?}");
    assert!(restarts > 0, "{tag}: no checkpoint was ever written");
    assert_whole_rows(&dir, &format!("{tag}: at the end"), false);
    for name in CSV {
        let a = std::fs::read(reference.join(name)).ok();
        let b = std::fs::read(dir.join(name)).ok();
        assert!(
            a == b,
            "{tag}: {name} differs from the uninterrupted run's ({:?} vs {:?} bytes)",
            a.map(|x| x.len()),
            b.map(|x| x.len())
        );
    }
    assert_eq!(
        summary_without_bookkeeping(&reference),
        summary_without_bookkeeping(&dir),
        "{tag}: summary.json differs"
    );
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn whfast_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    killed_and_restarted_equals_uninterrupted(
        "whfast",
        "examples/nbody/outer_solar_system.toml",
        &["--t-end", "3000000", "--checkpoint-every", "2000steps"],
        4,
        900,
        29,
    );
}

#[test]
fn ias15_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    killed_and_restarted_equals_uninterrupted(
        "ias15",
        "examples/nbody/figure_eight.toml",
        &[
            "--t-end",
            "2000",
            "--points",
            "10001",
            "--checkpoint-every",
            "4000steps",
        ],
        4,
        900,
        2017,
    );
}

#[cfg(unix)]
#[test]
fn sigterm_stops_cleanly_with_an_interrupted_summary_and_whole_files() {
    let model = example("examples/nbody/outer_solar_system.toml");
    let extra = ["--t-end", "40000000", "--checkpoint-every", "off"];
    let dir = fresh_dir("sigterm");
    let mut child = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start pdyn");
    std::thread::sleep(Duration::from_millis(600));
    let st = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(st.success());
    let status = child.wait().expect("wait");
    assert_eq!(status.code(), Some(4), "exit code of an interrupted run");
    let sum: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(sum["status"], "interrupted");
    assert_eq!(sum["ok"], false);
    let t = sum["t_reached"].as_f64().expect("t_reached");
    assert!(t > 0.0 && t < 4e7, "t_reached = {t}");
    assert!(!sum["final_state"].as_array().unwrap().is_empty());
    assert_whole_rows(&dir, "after SIGTERM", false);
    // The last conservation row is the time reached.
    let cons = std::fs::read_to_string(dir.join("conservation.csv")).unwrap();
    let last_t: f64 = cons
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|x| x.parse().ok())
        .unwrap();
    assert_eq!(last_t, t);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_checkpoints_are_refused_saying_what_differs() {
    let model = example("examples/nbody/outer_solar_system.toml");
    let extra = ["--t-end", "400000", "--checkpoint-every", "500steps"];
    let dir = fresh_dir("bad");
    let st = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let ckpt = dir.join("checkpoint.json");
    let good = std::fs::read_to_string(&ckpt).unwrap();
    let restart = |args: &[&str], expect: &str| {
        let mut a = run_args(&model, args, &dir);
        a.extend(["--restart".to_string(), ckpt.display().to_string()]);
        let out = Command::new(bin()).args(&a).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{expect}: {err}");
        assert!(err.contains(expect), "expected `{expect}` in: {err}");
    };
    // truncated
    std::fs::write(&ckpt, &good[..good.len() - 10]).unwrap();
    restart(&extra, "truncated");
    // tampered: one digit changed, the length kept
    let pos = good.rfind("\"steps\":").unwrap() + 8;
    let mut bytes = good.clone().into_bytes();
    bytes[pos] = if bytes[pos] == b'1' { b'2' } else { b'1' };
    std::fs::write(&ckpt, &bytes).unwrap();
    restart(&extra, "checksum");
    // other options
    std::fs::write(&ckpt, &good).unwrap();
    restart(
        &["--t-end", "500000", "--checkpoint-every", "500steps"],
        "t_end",
    );
    // another model
    let other = example("examples/nbody/figure_eight.toml");
    let mut a = run_args(&other, &extra, &dir);
    a.extend(["--restart".to_string(), ckpt.display().to_string()]);
    let out = Command::new(bin()).args(&a).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("another model"));
    // not a checkpoint, and a missing one
    std::fs::write(&ckpt, "hello\n").unwrap();
    restart(&extra, "not a pdyn checkpoint");
    std::fs::remove_file(&ckpt).unwrap();
    restart(&extra, "checkpoint");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_refuses_the_flags_of_long_runs_instead_of_ignoring_them() {
    for flags in [
        &["--restart", "x.json"][..],
        &["--checkpoint-every", "100"][..],
    ] {
        let out = Command::new(bin())
            .arg("check")
            .arg(example("examples/building.toml"))
            .args(flags)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{flags:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flags[0]) && err.contains("pdyn run"), "{err}");
    }
}

/// A full disk, simulated by a file-size limit (`ulimit -f`, in 512-byte blocks): the run
/// stops with exit code 1 and an error naming the file, the last whole row and the intact
/// checkpoint; every file ends with a whole row; and once the limit is gone, `--restart`
/// from that checkpoint ends with the files of a run that never hit the limit, byte for byte.
#[cfg(unix)]
#[test]
fn a_full_disk_stops_the_run_with_whole_files_and_the_last_checkpoint_intact() {
    let model = example("examples/nbody/outer_solar_system.toml");
    let extra = ["--t-end", "3000000", "--checkpoint-every", "1000steps"];
    let reference = fresh_dir("fsize-ref");
    let st = Command::new(bin())
        .args(run_args(&model, &extra, &reference))
        .stdout(Stdio::null())
        .status()
        .expect("run pdyn");
    assert!(st.success());
    let full = std::fs::metadata(reference.join("trajectory.csv"))
        .expect("trajectory.csv")
        .len();

    let dir = fresh_dir("fsize");
    // Room for about 40 % of trajectory.csv (the largest file).
    let blocks = full * 2 / 5 / 512;
    let script = format!("ulimit -f {blocks} && exec \"$0\" \"$@\"",);
    let out = Command::new("sh")
        .arg("-c")
        .arg(&script)
        .arg(bin())
        .args(run_args(&model, &extra, &dir))
        .arg("--json")
        .output()
        .expect("run pdyn under a file-size limit");
    assert_eq!(
        out.status.code(),
        Some(1),
        "a write that fails mid-run is a failure after output (exit 1), not a crash: {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(&text).expect("--json prints JSON on failure");
    let message = v["error"]["message"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    assert_eq!(v["error"]["kind"], "io", "{v}");
    assert!(message.contains("trajectory.csv"), "{message}");
    assert!(message.contains("last whole row"), "{message}");
    assert!(message.contains("--restart"), "{message}");
    assert_whole_rows(&dir, "after the file-size limit", false);
    let ckpt = dir.join("checkpoint.json");
    assert!(ckpt.exists(), "the checkpoint before the failure is kept");

    let st = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .args(["--restart", &ckpt.display().to_string()])
        .stdout(Stdio::null())
        .status()
        .expect("restart pdyn");
    assert!(
        st.success(),
        "the restart after freeing space failed: {st:?}"
    );
    for name in CSV {
        assert!(
            std::fs::read(reference.join(name)).ok() == std::fs::read(dir.join(name)).ok(),
            "{name} differs from the run that never hit the limit"
        );
    }
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same for MD, which streams `thermo.csv` and `traj.xyz`: a file-size limit smaller
/// than one frame stops the run with exit 1, the frame cut back, before any checkpoint.
#[cfg(unix)]
#[test]
fn a_full_disk_stops_an_md_run_with_exit_1_and_whole_files() {
    let model = example("examples/md/argon_melting.toml");
    let dir = fresh_dir("fsize-md");
    let out = Command::new("sh")
        .arg("-c")
        .arg("ulimit -f 20 && exec \"$0\" \"$@\"")
        .arg(bin())
        .args(run_args(&model, &[], &dir))
        .output()
        .expect("run pdyn under a file-size limit");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{:?}\n{err}", out.status);
    assert!(
        err.contains("traj.xyz") && err.contains("last whole row"),
        "{err}"
    );
    assert!(err.contains("no checkpoint was written yet"), "{err}");
    let traj = std::fs::read_to_string(dir.join("traj.xyz")).unwrap_or_default();
    assert!(
        traj.is_empty() || traj.ends_with('\n'),
        "traj.xyz ends inside a line"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
