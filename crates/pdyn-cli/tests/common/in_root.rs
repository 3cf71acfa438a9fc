//! Shared by the end-to-end tests that look at exit codes: run the `pdyn` binary in the
//! repository root (so that `examples/...` paths work) and read its JSON output.
#![allow(dead_code)] // each test file uses what it needs

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `pdyn ARGS` in the repository root with extra environment variables:
/// (exit code, stdout, stderr).
pub fn pdyn_env(args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(root())
        .output()
        .expect("run pdyn");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `pdyn ARGS` in the repository root: (exit code, stdout, stderr).
pub fn pdyn(args: &[&str]) -> (i32, String, String) {
    pdyn_env(args, &[])
}

/// Stdout parsed as JSON (the test fails, showing the text, when it is not).
pub fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout).unwrap_or_else(|e| panic!("stdout is not JSON ({e}):\n{stdout}"))
}
