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
