//! A mechanics run whose table is streamed into `trajectory.csv` as it goes (`pdyn run --out`,
//! issue 29) writes the same bytes as the run that keeps the whole table and writes it at the
//! end (Python's `Model.run(out=...)`, a run with plots): the table, and `summary.json` (but
//! for the `checkpoint` field, which only a streamed run has). The running aggregates of the
//! streamed run (drift references and worst drifts, conservation scales, events) must agree
//! with the whole table's, bit for bit. Models: one with a terminal event and dense output
//! (`points`), one with output at every step, one with a one-sided reaction watched.

use pdyn::engine::{run, run_long, LongRun};
use pdyn::model_file::ModelFile;
use pdyn::Request;
use std::path::{Path, PathBuf};

fn example(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdyn-streamed-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn without_checkpoint(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("checkpoint");
    v
}

fn same_files(model: &str, method: &str, points: Option<usize>, t_end: Option<f64>) {
    let file = ModelFile::read(&example(model)).unwrap();
    let stem = Path::new(model).file_stem().unwrap().to_string_lossy();
    let (kept, streamed) = (
        dir(&format!("{stem}-kept")),
        dir(&format!("{stem}-streamed")),
    );
    let req = |out: &Path| Request {
        method: Some(method.to_string()),
        points,
        t_end,
        out: Some(out.to_path_buf()),
        ..Default::default()
    };
    let whole = run(&file, &req(&kept), &mut |_| {}).unwrap();
    let long = LongRun {
        stream_only: true,
        ..Default::default()
    };
    let part = run_long(&file, &req(&streamed), &long, &mut |_| {}).unwrap();
    let a = std::fs::read(kept.join("trajectory.csv")).unwrap();
    let b = std::fs::read(streamed.join("trajectory.csv")).unwrap();
    assert!(a.len() > 1000, "{model}: a table of {} bytes", a.len());
    assert!(
        a == b,
        "{model}: trajectory.csv differs ({} vs {} bytes)",
        a.len(),
        b.len()
    );
    let (sa, sb) = (
        without_checkpoint(&kept.join("summary.json")),
        without_checkpoint(&streamed.join("summary.json")),
    );
    assert_eq!(sa, sb, "{model}: summary.json differs");
    assert!(
        part.summary()["checkpoint"].is_object(),
        "the streamed run checkpoints by default"
    );
    assert!(whole.summary()["checkpoint"].is_null());
    // The streamed run kept only its last row, and counted them all.
    let (RunOutput::Mechanics(w), RunOutput::Mechanics(p)) = (whole, part) else {
        panic!("mechanics runs")
    };
    assert_eq!(p.result.rows.len(), 1);
    assert_eq!(p.result.outputs, w.result.rows.len());
    assert_eq!(p.result.rows[0], *w.result.rows.last().unwrap());
    let _ = std::fs::remove_dir_all(&kept);
    let _ = std::fs::remove_dir_all(&streamed);
}

use pdyn::engine::RunOutput;

#[test]
fn a_terminal_event_with_dense_output() {
    same_files("examples/kremlin_stone.toml", "dop853", Some(500), None);
}

#[test]
fn output_at_every_step_with_conserved_quantities() {
    same_files("examples/satellite.toml", "dopri5", None, None);
}

#[test]
fn a_watched_one_sided_reaction() {
    same_files("examples/rotating_rod_block.toml", "tsit5", Some(300), None);
}

#[test]
fn a_chain_with_energy_drift_monitored() {
    same_files(
        "examples/pendulum_chain_3.toml",
        "dopri5",
        Some(2001),
        Some(30.0),
    );
}
