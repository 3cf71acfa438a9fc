//! Every example's `summary.json` has the fields every model kind shares (issue 25, item 4;
//! `docs/summary.md`): `kind`, `model`, `ok`, `failure`, `warnings`, `stats.steps`, and
//! `monitors` entries with `name`, `initial`, `final`, `drift`, `relative`, `scale`,
//! `tolerance`, `conserved`, `ok` — whether the model is mechanics, N-body or MD.

#[path = "common/in_root.rs"]
mod in_root;
use in_root::{json, pdyn, root};
use pdyn::summary::{COMMON_FIELDS, KINDS, MONITOR_FIELDS};
use std::path::{Path, PathBuf};

fn examples(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().collect();
    entries.sort_by_key(|e| e.path());
    for e in entries {
        let p = e.path();
        if p.is_dir() {
            examples(&p, out);
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
}

/// The kind a file declares by its top-level table.
fn kind_of(path: &Path) -> &'static str {
    let t: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
    if t.contains_key("nbody") {
        "nbody"
    } else if t.contains_key("md") {
        "md"
    } else {
        "mechanics"
    }
}

#[test]
fn every_examples_summary_has_the_common_schema() {
    let mut files = Vec::new();
    examples(&root().join("examples"), &mut files);
    let mut checked = std::collections::BTreeMap::<&str, usize>::new();
    let mut monitors = 0;
    for f in &files {
        let kind = kind_of(f);
        let p = f.to_str().unwrap();
        // Short runs: the schema, not the physics. MD examples are shrunk to a few cells
        // where they have an `n`, as `md_cli.rs` does.
        let mut args = vec!["run", p, "--json"];
        match kind {
            "md" => args.extend(["--t-end", "0.02"]),
            _ => args.extend(["--t-end", "0.05"]),
        }
        let src = std::fs::read_to_string(f).unwrap();
        if kind == "md" && src.contains("\nn = ") {
            args.extend(["--set", "n=4"]);
        }
        let (code, out, err) = pdyn(&args);
        if code == 2 {
            // Not a runnable model (a prescribed motion asking for `pdyn forces`, a rate left
            // to `[unknowns]`, a plotting gallery...): refused with a located error.
            continue;
        }
        let s = json(&out);
        let s = if s.get("error").is_some() && s.get("kind").is_none() {
            panic!("{p}: {out}\n{err}")
        } else {
            s
        };
        for field in COMMON_FIELDS {
            assert!(s.get(field).is_some(), "{p}: no `{field}` in {out}");
        }
        assert!(KINDS.contains(&s["kind"].as_str().unwrap()));
        assert_eq!(s["kind"], kind, "{p}");
        assert_eq!(s["ok"], s["failure"].is_null(), "{p}");
        assert!(s["stats"]["steps"].is_u64(), "{p}: {}", s["stats"]);
        for m in s["monitors"].as_array().unwrap() {
            for field in MONITOR_FIELDS {
                assert!(
                    m.get(field).is_some(),
                    "{p}: monitor without `{field}`: {m}"
                );
            }
            let verdict = !m["conserved"].as_bool().unwrap()
                || m["drift"]
                    .as_f64()
                    .is_some_and(|d| d <= m["tolerance"].as_f64().unwrap());
            assert_eq!(m["ok"], verdict, "{p}: {m}");
            monitors += 1;
        }
        *checked.entry(kind).or_default() += 1;
    }
    eprintln!("checked {checked:?}, {monitors} monitors");
    // Every kind is covered, with conserved quantities among them.
    for kind in KINDS {
        assert!(checked.get(kind).copied().unwrap_or(0) >= 2, "{checked:?}");
    }
    assert!(monitors >= 10, "{monitors} monitors in {checked:?}");
}
