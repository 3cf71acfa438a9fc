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
