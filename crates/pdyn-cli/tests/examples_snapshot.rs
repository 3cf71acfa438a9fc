//! Every shipped example through the binary, compared byte for byte with a stored snapshot.
//!
//! The cases are the `pdyn ...` lines of `examples/kin/*.sh` and `examples/dsolve/*.sh`, and
//! `derive` / `forces` / `run` on every `examples/*.toml` (whichever the model supports), plus
//! some failures. Each snapshot holds the exit code, stdout and stderr. A refactoring must leave
//! them unchanged; a deliberate change of output is recorded with
//! `PDYN_UPDATE_SNAPSHOTS=1 cargo test -p pdyn --test examples_snapshot` and reviewed in the diff.
//! (`pdyn sweep` is left out: it prints its wall time.)

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Splits a shell command line: words, with `"..."` and `'...'` quoting (what the examples use).
fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut cur = String::new();
    let mut quote: Option<char> = None;
    let mut in_word = false;
    for c in line.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => cur.push(c),
            None if c == '"' || c == '\'' => {
                quote = Some(c);
                in_word = true;
            }
            // A comment or a `|| true` ends the command.
            None if c == '#' && !in_word => break,
            None if c == '|' && !in_word => break,
            None if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut cur));
                    in_word = false;
                }
            }
            None => {
                cur.push(c);
                in_word = true;
            }
        }
    }
    if in_word {
        words.push(cur);
    }
    words
}

fn cases() -> Vec<Vec<String>> {
    let mut cases = Vec::new();
    for dir in ["examples/kin", "examples/dsolve"] {
        let mut files: Vec<_> = std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap().replace("\\\n", " ");
            for line in text.lines() {
                // Lines inside shell loops use shell variables: not reproducible here.
                if line.contains('$') {
                    continue;
                }
                if let Some(rest) = line.trim().strip_prefix("pdyn ") {
                    cases.push(shell_words(rest));
                }
            }
        }
    }
    let mut models: Vec<_> = std::fs::read_dir(root().join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    models.sort();
    for m in &models {
        let rel = format!("examples/{}", m.file_name().unwrap().to_string_lossy());
        let text = std::fs::read_to_string(m).unwrap();
        cases.push(vec!["derive".into(), rel.clone()]);
        if text.contains("[simulate]") {
            cases.push(vec!["run".into(), rel.clone()]);
        } else {
            cases.push(vec!["forces".into(), rel.clone()]);
        }
        if text.contains("[[checks]]") || text.contains("[unknowns]") {
            cases.push(vec!["forces".into(), rel.clone()]);
        }
    }
    let extra: &[&[&str]] = &[
        &["derive", "examples/pulley.toml", "--json"],
        &["derive", "examples/suspension.toml", "--latex"],
        &["forces", "examples/aircraft_turn.toml", "--set", "V=102"],
        &["forces", "examples/rotating_bar_block.toml", "--json"],
        &[
            "run",
            "examples/satellite.toml",
            "--method",
            "symplectic",
            "--dt",
            "0.1",
            "--t-end",
            "20",
        ],
        &["run", "--method", "help", "examples/satellite.toml"],
        &["check", "examples/building.toml"],
        &["run", "examples/building.toml", "--method", "exact"],
        &["run", "examples/no_such_file.toml"],
        &["run", "examples/satellite.toml", "--rtol", "-1"],
        &["eval", "sqrt(x^2 + y^2)", "--at", "x=3,y=4"],
        &["eval", "sqrt(x^2 + ", "--at", "x=3"],
        &[
            "simplify",
            "dot([R*cos(th(t)), R*sin(th(t)), 0]'', [R*cos(th(t)), R*sin(th(t)), 0]'')",
        ],
        &["diff", "[R*cos(th(t)), R*sin(th(t)), 0]", "-n", "2"],
        &[
            "solve",
            "--for",
            "T,N",
            "--",
            "-T*cos(phi - theta) - N*cos(theta) = -m*R*omega^2*cos(theta)",
            "-N*sin(theta) + T*sin(phi - theta) - m*g = -m*R*omega^2*sin(theta)",
        ],
        &["kin", "[R*cos(omega*t), R*sin(omega*t)]", "--at", "t=zz"],
        &["dsolve", "x'' = -x*y"],
    ];
    for e in extra {
        cases.push(e.iter().map(|s| s.to_string()).collect());
    }
    cases
}

fn slug(args: &[String]) -> String {
    let s: String = args
        .join("_")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let s = s.replace("examples_", "");
    // Long expression arguments: keep the file name short but unique.
    if s.len() > 80 {
        let h = args
            .iter()
            .flat_map(|a| a.bytes())
            .fold(0xcbf29ce484222325u64, |h, b| {
                (h ^ b as u64).wrapping_mul(0x100000001b3)
            });
        format!("{}_{h:016x}", &s[..60])
    } else {
        s
    }
}

#[test]
fn every_example_prints_what_it_printed_before() {
    let dir = root().join("crates/pdyn-cli/tests/snapshots");
    let update = std::env::var_os("PDYN_UPDATE_SNAPSHOTS").is_some();
    let mut failures = Vec::new();
    let cases = cases();
    assert!(cases.len() > 40, "only {} cases found", cases.len());
    for args in &cases {
        let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
            .args(args)
            .current_dir(root())
            .output()
            .expect("run pdyn");
        let got = format!(
            "$ pdyn {}\nexit: {}\n--- stdout\n{}--- stderr\n{}",
            args.join(" "),
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        let file = dir.join(format!("{}.snap", slug(args)));
        if update {
            std::fs::write(&file, &got).unwrap();
            continue;
        }
        match std::fs::read_to_string(&file) {
            Ok(want) if want == got => {}
            Ok(want) => {
                let line = want
                    .lines()
                    .zip(got.lines())
                    .position(|(a, b)| a != b)
                    .unwrap_or(want.lines().count().min(got.lines().count()));
                failures.push(format!(
                    "{}: differs from line {}:\n  want: {:?}\n  got:  {:?}",
                    file.display(),
                    line + 1,
                    want.lines().nth(line),
                    got.lines().nth(line)
                ));
            }
            Err(_) => failures.push(format!("{}: no snapshot", file.display())),
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} snapshots differ:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
