//! Long mechanics runs (issue 29): `trajectory.csv` written as the run goes, checkpoints, and
//! `--restart`. A run killed with SIGKILL at seeded random instants and restarted from its last
//! checkpoint each time ends with the files of the same run left alone, byte for byte (and
//! `summary.json` but for the checkpoint's own fields); after every kill the table ends with
//! a whole row (up to the kernel's caveat, see `long_runs.rs`); SIGTERM stops cleanly with a
//! checkpoint to continue from; what cannot be checkpointed is refused by name.
//!
//! The reference is the uninterrupted run of the same binary: what a restart must reproduce.
//! That the streamed table is the table the run wrote before streaming existed is checked in
//! `crates/pdyn/tests/streamed_mechanics.rs` (the library's two paths side by side).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

mod long_run_common;
use long_run_common::{
    assert_whole_csv, bin, example, fresh_dir, kill_repeatedly, run_args,
    summary_without_bookkeeping,
};

/// `trajectory.csv` holds whole rows of numbers ([`assert_whole_csv`]).
fn assert_whole_rows(dir: &Path, when: &str, after_kill: bool) {
    assert_whole_csv(dir, "trajectory.csv", when, after_kill, true);
}

fn assert_same_files(reference: &Path, dir: &Path, tag: &str) {
    let a = std::fs::read(reference.join("trajectory.csv")).ok();
    let b = std::fs::read(dir.join("trajectory.csv")).ok();
    assert!(a.is_some(), "{tag}: the reference wrote no trajectory.csv");
    assert!(
        a == b,
        "{tag}: trajectory.csv differs from the uninterrupted run's ({:?} vs {:?} bytes)",
        a.map(|x| x.len()),
        b.map(|x| x.len())
    );
    assert_eq!(
        summary_without_bookkeeping(reference),
        summary_without_bookkeeping(dir),
        "{tag}: summary.json differs"
    );
}

/// Runs `model` with `extra` once uninterrupted, then killed `kills` times at seeded random
/// instants within `window_ms`, each time restarted from its last checkpoint (or from the
/// start when none was written yet), and compares the files.
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
    let sum = summary_without_bookkeeping(&reference);
    assert!(
        sum["ok"] == true,
        "{tag}: the reference run is not ok: {sum}"
    );

    let dir = fresh_dir(&format!("{tag}-killed"));
    let (args, restarts) = kill_repeatedly(
        &dir,
        &run_args(&model, extra, &dir),
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
    assert_same_files(&reference, &dir, tag);
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn dopri5_with_dense_output_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    killed_and_restarted_equals_uninterrupted(
        "dopri5",
        "examples/pendulum_chain_3.toml",
        &[
            "--method",
            "dopri5",
            "--t-end",
            "400",
            "--points",
            "40001",
            "--checkpoint-every",
            "300steps",
        ],
        5,
        1200,
        29,
    );
}

#[test]
fn dop853_at_every_step_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    // Output at every step (no --points): the rows are the steps themselves.
    killed_and_restarted_equals_uninterrupted(
        "dop853",
        "examples/satellite.toml",
        &[
            "--method",
            "dop853",
            "--rtol",
            "1e-11",
            "--t-end",
            "15000",
            "--checkpoint-every",
            "3000steps",
        ],
        4,
        1200,
        1981,
    );
}

/// The default method, `auto` (DOP853 at the example's rtol 1e-9): streamed, checkpointed,
/// restarted bit for bit as the explicit pair it runs.
#[test]
fn auto_killed_at_random_and_restarted_matches_the_uninterrupted_run() {
    killed_and_restarted_equals_uninterrupted(
        "auto",
        "examples/pendulum_chain_3.toml",
        &[
            "--t-end",
            "300",
            "--points",
            "30001",
            "--checkpoint-every",
            "300steps",
        ],
        3,
        1000,
        7,
    );
}

/// SIGTERM: the run stops after its current step with exit 4, an "interrupted" summary,
/// whole rows, and a checkpoint at the stop; `--restart` from it finishes with the files of
/// the run never stopped.
#[cfg(unix)]
#[test]
fn sigterm_stops_cleanly_with_a_checkpoint_and_the_restart_finishes_the_run() {
    let model = example("examples/pendulum_chain_3.toml");
    // Long enough (about a second) that the signal comes mid-run: at t_end = 400 the run
    // took 0.17 s, and finished first under a loaded test machine now and then.
    let extra = ["--method", "dopri5", "--t-end", "4000", "--points", "40001"];
    let reference = fresh_dir("term-ref");
    let st = Command::new(bin())
        .args(run_args(&model, &extra, &reference))
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let dir = fresh_dir("term");
    let mut child = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start pdyn");
    // Until the run has written rows (the table exists), then a little longer.
    for _ in 0..400 {
        if std::fs::metadata(dir.join("trajectory.csv")).is_ok_and(|m| m.len() > 100) {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(100));
    let st = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(st.success());
    let status = child.wait().expect("wait");
    assert_eq!(status.code(), Some(4), "exit code of an interrupted run");
    let sum = summary_without_bookkeeping(&dir);
    assert_eq!(sum["status"], "interrupted");
    assert_eq!(sum["ok"], false);
    let t = sum["t_reached"].as_f64().expect("t_reached");
    assert!(t > 0.0 && t < 4000.0, "t_reached = {t}");
    assert_whole_rows(&dir, "after SIGTERM", false);
    // The default checkpoint interval (15 min) has not passed: this one is the stop's.
    let ckpt = dir.join("checkpoint.json");
    assert!(ckpt.exists(), "the stop writes a checkpoint");
    let out = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .args(["--restart", &ckpt.display().to_string()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_same_files(&reference, &dir, "SIGTERM then --restart");
    let restarted = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&restarted).unwrap();
    assert_eq!(v["restarted_from"]["t"].as_f64(), Some(t), "{v}");
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `pdyn run MODEL ARGS --out DIR` and returns (exit code, stderr).
fn refused(model: &str, args: &[&str], dir: &Path) -> (Option<i32>, String) {
    let out = Command::new(bin())
        .args(run_args(&example(model), args, dir))
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn what_cannot_be_checkpointed_is_refused_by_name() {
    let dir = fresh_dir("refuse");
    // A hybrid model (contacts, impacts).
    for flag in [
        &["--checkpoint-every", "100steps"][..],
        &["--restart", "x.json"][..],
    ] {
        let (code, err) = refused("examples/contact/bouncing_ball.toml", flag, &dir);
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains(flag[0]) && err.contains("hybrid") && err.contains("dopri5"),
            "{err}"
        );
    }
    // Methods whose state is not saved: the stiff ones, fixed steps, the closed form.
    for method in ["radau5", "bdf", "rk4", "exact"] {
        let mut args = vec!["--method", method, "--checkpoint-every", "100steps"];
        if method == "rk4" {
            args.extend(["--dt", "0.01"]);
        }
        let (code, err) = refused("examples/pendulum_chain_3.toml", &args, &dir);
        assert_eq!(code, Some(2), "{method}: {err}");
        assert!(
            err.contains(&format!("`{method}`")) && err.contains("dop853"),
            "{method}: {err}"
        );
    }
    // Without them, those runs go on as before (the table written at the end).
    let (code, err) = refused(
        "examples/pendulum_chain_3.toml",
        &["--method", "radau5", "--t-end", "1"],
        &dir,
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(dir.join("trajectory.csv").exists());
    assert!(!dir.join("checkpoint.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn foreign_and_mismatched_checkpoints_are_refused() {
    let model = "examples/pendulum_chain_3.toml";
    let extra = [
        "--method",
        "dopri5",
        "--t-end",
        "20",
        "--checkpoint-every",
        "50steps",
    ];
    let dir = fresh_dir("mismatch");
    let (code, err) = refused(model, &extra, &dir);
    assert_eq!(code, Some(0), "{err}");
    let ckpt = dir.join("checkpoint.json");
    let text = std::fs::read_to_string(&ckpt).expect("a checkpoint was written");
    assert!(text.contains("\"kind\":\"mechanics\""), "{text:.200}");
    let with_restart = |args: &[&str]| {
        let mut a: Vec<&str> = args.to_vec();
        let path = ckpt.display().to_string();
        a.extend(["--restart", &path]);
        let (code, err) = refused(model, &a, &dir);
        (code, err)
    };
    // Other options: named with both values.
    let mut other = extra.to_vec();
    other[3] = "30";
    let (code, err) = with_restart(&other);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("t_end"), "{err}");
    // Another method.
    let mut other = extra.to_vec();
    other[1] = "dop853";
    let (code, err) = with_restart(&other);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("method"), "{err}");
    // A restart with --plot (the plots need the whole history).
    let mut plot = extra.to_vec();
    plot.push("--plot");
    let (code, err) = with_restart(&plot);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--plot"), "{err}");
    // A mechanics checkpoint for another model.
    let path = ckpt.display().to_string();
    let (code, err) = refused(
        "examples/pendulum_chain_2.toml",
        &[&extra[..], &["--restart", &path]].concat(),
        &dir,
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("another model"), "{err}");
    // The table shorter than the checkpoint says: rows are missing.
    let csv = dir.join("trajectory.csv");
    let table = std::fs::read(&csv).unwrap();
    std::fs::write(&csv, &table[..table.len() / 3]).unwrap();
    let (code, err) = with_restart(&extra);
    assert_ne!(code, Some(0), "{err}");
    assert!(err.contains("rows are missing"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A full disk, simulated by a file-size limit (`ulimit -f`, 512-byte blocks): the streamed
/// run stops with exit 1 and an error naming the table, its last whole row and the intact
/// checkpoint; once the limit is gone, `--restart` finishes with the table of a run that
/// never hit it.
#[cfg(unix)]
#[test]
fn a_full_disk_stops_the_run_with_a_whole_table_and_the_restart_finishes_it() {
    let model = example("examples/pendulum_chain_3.toml");
    let extra = [
        "--method",
        "dopri5",
        "--t-end",
        "200",
        "--points",
        "20001",
        "--checkpoint-every",
        "1000steps",
    ];
    let reference = fresh_dir("fsize-ref");
    let st = Command::new(bin())
        .args(run_args(&model, &extra, &reference))
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let full = std::fs::metadata(reference.join("trajectory.csv"))
        .unwrap()
        .len();
    let dir = fresh_dir("fsize");
    let blocks = full * 2 / 5 / 512;
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -f {blocks} && exec \"$0\" \"$@\""))
        .arg(bin())
        .args(run_args(&model, &extra, &dir))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("trajectory.csv")
            && err.contains("last whole row")
            && err.contains("--restart"),
        "{err}"
    );
    assert_whole_rows(&dir, "after the file-size limit", false);
    let ckpt = dir.join("checkpoint.json");
    assert!(ckpt.exists());
    let st = Command::new(bin())
        .args(run_args(&model, &extra, &dir))
        .args(["--restart", &ckpt.display().to_string()])
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    assert_same_files(&reference, &dir, "after the full disk");
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&dir);
}
