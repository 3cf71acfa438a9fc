//! Bounded mutation test: every shipped example, mutated deterministically a few dozen ways
//! (one TOML value replaced by a hostile one: zero, negative, huge, NaN, empty, unbalanced,
//! a division by zero, a vector where a scalar belongs...), through `derive`, `run` (short)
//! and `forces`. Each case must end with exit 0, 1 or 2 — never a panic (exit 3, the panic
//! hook), never a hang (a case still running after `HANG` is killed and reported).

#[path = "common/toml_values.rs"]
mod toml_values;
use toml_values::value_spans;

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A case still running after this long is a hang (not a speed goal: debug builds are slow).
const HANG: Duration = Duration::from_secs(60);

/// Mutations per example.
const PER_EXAMPLE: usize = 40;

const HOSTILE: &[&str] = &[
    "0",
    "-1",
    "1e308",
    "-1e-308",
    "\"nan\"",
    "\"1/0\"",
    "\"\"",
    "\"((((x\"",
    "\"sin(\"",
    "\"[1, 2, 3]\"",
    "\"x'\"",
    "\"1e400\"",
    "\"-m\"",
    "\"2^100000\"",
    "\"sqrt(-1)\"",
    "\"log(0)\"",
    "\"t\"",
    "[]",
    "{}",
    "true",
    "\"150 knot\"",
    "\"3 kg*m\"",
];

fn xorshift(s: &mut u64) -> u64 {
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    *s
}

/// Runs the binary with a hang guard: Some(exit code), or None when it had to be killed.
fn run_guarded(args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn pdyn");
    let start = Instant::now();
    loop {
        match child.try_wait().expect("wait") {
            Some(status) => {
                let mut err = String::new();
                if let Some(mut e) = child.stderr.take() {
                    let _ = e.read_to_string(&mut err);
                }
                return (status.code(), err);
            }
            None if start.elapsed() > HANG => {
                let _ = child.kill();
                let _ = child.wait();
                return (None, String::new());
            }
            None => std::thread::sleep(Duration::from_millis(5)),
        }
    }
}

#[test]
fn mutated_examples_never_panic_or_hang() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let dir = std::env::temp_dir().join(format!("pdyn-mutations-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The top-level examples, and the hybrid ones (contacts, impacts, friction that sticks).
    let mut models: Vec<_> = [root.clone(), root.join("contact")]
        .iter()
        .flat_map(|d| std::fs::read_dir(d).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    models.sort();
    let mut failures = Vec::new();
    let mut cases = 0;
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    for model in &models {
        let src = std::fs::read_to_string(model).unwrap();
        let spans = value_spans(&src);
        assert!(!spans.is_empty(), "{}", model.display());
        let simulates = src.contains("[simulate]");
        for k in 0..PER_EXAMPLE {
            let (s, e) = spans[xorshift(&mut seed) as usize % spans.len()];
            let hostile = HOSTILE[xorshift(&mut seed) as usize % HOSTILE.len()];
            let mutated = format!("{}{}{}", &src[..s], hostile, &src[e..]);
            let path = dir.join(format!("m{k}.toml"));
            std::fs::write(&path, &mutated).unwrap();
            let p = path.to_str().unwrap();
            let commands: Vec<Vec<&str>> = if simulates {
                vec![
                    vec!["derive", p],
                    vec![
                        "run",
                        p,
                        "--t-end",
                        "0.05",
                        "--max-steps",
                        "20000",
                        "--json",
                    ],
                ]
            } else {
                vec![vec!["forces", p, "--json"]]
            };
            for args in commands {
                cases += 1;
                let (code, err) = run_guarded(&args);
                let what = format!(
                    "{} with `{}` -> `{hostile}`: pdyn {}",
                    model.file_name().unwrap().to_string_lossy(),
                    &src[s..e],
                    args[0]
                );
                match code {
                    Some(0..=2) => {}
                    Some(c) => failures.push(format!("{what}: exit {c}\n{err}")),
                    None => failures.push(format!("{what}: still running after {HANG:?}")),
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        failures.is_empty(),
        "{} of {cases} mutated cases panicked or hung:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
