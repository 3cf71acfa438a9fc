//! Shared by the end-to-end tests: run the `pdyn` binary.

use std::process::Command;

/// Runs `pdyn ARGS`: (exit status success, stdout, stderr).
pub fn pdyn(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .output()
        .expect("run pdyn");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
