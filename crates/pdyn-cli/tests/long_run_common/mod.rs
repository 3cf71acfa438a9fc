//! What the long-run tests (`long_runs.rs`: N-body, `long_runs_md.rs`, `long_runs_mechanics.rs`)
//! share: the binary, the examples, scratch directories and the seeded kill instants.

use std::path::{Path, PathBuf};

/// The `pdyn` binary under test.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_pdyn")
}

/// A file of the repository (`examples/...`).
pub fn example(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

/// A scratch directory of this test process, removed first (not created: `--out` creates it).
pub fn fresh_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdyn-longrun-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A small seeded generator (SplitMix64): the kill instants are the same on every run.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// The run `args` (writing into `dir`) started `kills` times, each killed with SIGKILL after
/// 50 ms plus a seeded random delay below `window_ms`, each continuing with `--restart
/// DIR/checkpoint.json` once a checkpoint exists; `after_kill(k)` checks the files after kill
/// `k` (1-based). Returns the arguments of the run that finishes (from the last checkpoint,
/// if any) and how many of the runs, that one included, were restarts.
pub fn kill_repeatedly(
    dir: &Path,
    args: &[String],
    kills: usize,
    window_ms: u64,
    seed: u64,
    after_kill: impl Fn(usize),
) -> (Vec<String>, usize) {
    let ckpt = dir.join("checkpoint.json");
    let mut rng = Rng(seed);
    let mut restarts = 0;
    let with_restart = |restarts: &mut usize| {
        let mut a = args.to_vec();
        if ckpt.exists() {
            a.extend(["--restart".to_string(), ckpt.display().to_string()]);
            *restarts += 1;
        }
        a
    };
    for k in 0..kills {
        let a = with_restart(&mut restarts);
        let mut child = std::process::Command::new(bin())
            .args(&a)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("start pdyn");
        std::thread::sleep(std::time::Duration::from_millis(50 + rng.below(window_ms)));
        // SIGKILL: no handler runs, nothing is flushed.
        let _ = child.kill();
        let _ = child.wait();
        after_kill(k + 1);
    }
    let last = with_restart(&mut restarts);
    (last, restarts)
}

/// `pdyn run MODEL EXTRA… --out OUT`.
pub fn run_args(model: &Path, extra: &[&str], out: &Path) -> Vec<String> {
    let mut a = vec!["run".to_string(), model.display().to_string()];
    a.extend(extra.iter().map(|s| s.to_string()));
    a.extend(["--out".to_string(), out.display().to_string()]);
    a
}

/// `summary.json` of `dir` without what only says how the run was carried out (the
/// checkpoint file, where it restarted from).
pub fn summary_without_bookkeeping(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    let mut v: serde_json::Value = serde_json::from_str(&text).expect("summary is JSON");
    let m = v.as_object_mut().expect("an object");
    m.remove("checkpoint");
    m.remove("restarted_from");
    v
}

/// The text up to its last newline, and whether something follows it.
pub fn whole_lines(text: &str) -> (&str, bool) {
    match text.rfind('\n') {
        Some(i) => (&text[..=i], i + 1 < text.len()),
        None => ("", !text.is_empty()),
    }
}

/// The CSV file `name` of `dir`, when present: every line up to the last newline is a whole
/// row (the header's number of cells; every cell a number when `all_numbers`, else the first,
/// the time). After a SIGKILL (`after_kill`) the file may end with a fragment without a
/// newline (Linux checks for a fatal signal between the pages of one `write`); after a clean
/// stop it must end with a newline.
pub fn assert_whole_csv(dir: &Path, name: &str, when: &str, after_kill: bool, all_numbers: bool) {
    let Ok(text) = std::fs::read_to_string(dir.join(name)) else {
        return;
    };
    let (whole, rest) = whole_lines(&text);
    assert!(
        after_kill || !rest,
        "{when}: {name} ends inside a row: {:?}",
        &text[text.len().saturating_sub(80)..]
    );
    let mut lines = whole.lines();
    let columns = lines.next().map_or(0, |h| h.split(',').count());
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(
            cells.len(),
            columns,
            "{when}: {name} row {} has other columns: {line}",
            k + 2
        );
        let checked = if all_numbers { &cells[..] } else { &cells[..1] };
        assert!(
            checked.iter().all(|c| c.parse::<f64>().is_ok()),
            "{when}: {name} row {} holds something that is not a number: {line}",
            k + 2
        );
    }
}
