//! Exit codes (0 success, 1 numerical failure after partial output, 2 bad input, 3 internal
//! error) and `--json` on failure: every command prints a JSON error object on stdout with
//! `error.kind` set, as well as the human message on stderr.

#[path = "common/in_root.rs"]
mod in_root;
use in_root::{pdyn, pdyn_env};

fn json_error(stdout: &str) -> serde_json::Value {
    let v: serde_json::Value = serde_json::from_str(stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON ({e}):\n{stdout}"));
    v["error"].clone()
}

#[test]
fn success_is_zero() {
    let (code, out, _) = pdyn(&["eval", "sqrt(x^2 + y^2)", "--at", "x=3,y=4"]);
    assert_eq!((code, out.trim()), (0, "5"));
}

#[test]
fn every_command_answers_bad_input_with_exit_2_and_a_json_error() {
    let broken = std::env::temp_dir().join(format!("pdyn-broken-{}.toml", std::process::id()));
    std::fs::write(&broken, "name = \"broken\"\n[parameters]\nm = \"2 *\"\n").unwrap();
    let b = broken.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["simplify", "sin(x"], "expression"),
        (vec!["diff", "x^2", "--wrt", "[x, y]"], "argument"),
        (vec!["solve", "--for", "x", "sin(x) = x/2"], "argument"),
        (vec!["eval", "x + 1"], "argument"),
        (vec!["derive", b], "model"),
        (vec!["forces", b], "model"),
        (vec!["run", b], "model"),
        (vec!["check", "examples/satellite.toml"], "simulation"),
        (vec!["sweep", "examples/satellite.toml"], "argument"),
        (vec!["dsolve", "x'' = -x^2"], "dsolve"),
        (vec!["kin", "[t, t^2, 0]", "--at", "t=zz(1"], "expression"),
        (vec!["run", "examples/no_such_model.toml"], "io"),
        (
            vec!["run", "examples/satellite.toml", "--method", "rk4"],
            "simulation",
        ),
    ];
    for (args, kind) in cases {
        let mut a = args.clone();
        a.push("--json");
        let (code, out, err) = pdyn(&a);
        assert_eq!(code, 2, "{args:?}: exit {code}\n{err}");
        let e = json_error(&out);
        assert_eq!(e["kind"], kind, "{args:?}: {e}");
        assert_eq!(e["exit_code"], 2);
        assert!(
            !err.trim().is_empty(),
            "{args:?}: the human message goes to stderr too"
        );
        assert_eq!(
            e["message"].as_str().unwrap().trim_end(),
            err.trim_end(),
            "{args:?}"
        );
    }
    std::fs::remove_file(&broken).ok();
}

#[test]
fn model_errors_carry_file_line_and_column_in_json() {
    let broken = std::env::temp_dir().join(format!("pdyn-located-{}.toml", std::process::id()));
    std::fs::write(&broken, "name = \"broken\"\n[parameters]\nm = \"2 *\"\n").unwrap();
    let (code, out, err) = pdyn(&["derive", broken.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    let loc = &json_error(&out)["location"];
    assert_eq!(loc["file"], broken.to_str().unwrap());
    assert_eq!(loc["line"], 3, "{loc}");
    assert!(loc["column"].as_u64().unwrap() >= 5, "{loc}");
    std::fs::remove_file(&broken).ok();
}

#[test]
fn contradictory_constraints_and_dimension_errors_are_located_in_json() {
    let rails = "name = \"rails\"\ngravity = \"[0, -g, 0]\"\n[parameters]\ng = 9.81\n\
                 [coordinates]\nx = { initial = 0, rate = 0 }\ny = { initial = 0, rate = 0 }\n\
                 [particles.a]\nmass = 1\nposition = \"[x, y, 0]\"\n\
                 [[constraints]]\nequation = \"x + y = 0\"\n\
                 [[constraints]]\nequation = \"x + y = 1\"\n";
    let units = "[parameters]\nm = \"2 kg\"\nk = \"100 N/m\"\n\
                 [coordinates]\nx = { initial = 0, rate = 0 }\n\
                 [particles.a]\nmass = \"m\"\nposition = \"[x, 0, 0]\"\n\
                 [[forces]]\nkind = \"applied\"\non = \"a\"\nforce = \"[-k*x + x', 0, 0]\"\n";
    for (name, text, line, kind) in [
        ("rails", rails, 14, "derivation"),
        ("units", units, 12, "model"),
    ] {
        let path = std::env::temp_dir().join(format!("pdyn-{name}-{}.toml", std::process::id()));
        std::fs::write(&path, text).unwrap();
        let (code, out, err) = pdyn(&["derive", path.to_str().unwrap(), "--json"]);
        assert_eq!(code, 2, "{err}");
        let e = json_error(&out);
        assert_eq!(e["kind"], kind, "{e}");
        assert_eq!(e["location"]["line"], line, "{e}");
        assert!(e["location"]["column"].as_u64().is_some(), "{e}");
        std::fs::remove_file(&path).ok();
    }
}

#[test]
fn usage_errors_are_json_too() {
    let (code, out, _) = pdyn(&["run", "--no-such-flag", "--json"]);
    assert_eq!(code, 2);
    assert_eq!(json_error(&out)["kind"], "argument");
}

#[test]
fn a_failed_integration_exits_1_with_partial_output_and_a_json_error() {
    let dir = std::env::temp_dir().join(format!("pdyn-exit1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("radial_fall.toml");
    std::fs::write(
        &model,
        "name = \"radial fall\"\n[parameters]\nGM = 1.0\n[coordinates]\n\
         x = { initial = 1.0, rate = 0.0 }\ny = { initial = 0.0, rate = 0.0 }\n\
         [particles.p]\nmass = 1\nposition = \"[x, y, 0]\"\n[points]\nO = \"[0, 0, 0]\"\n\
         [[forces]]\nkind = \"inverse_square\"\non = \"p\"\nto = \"O\"\nstrength = \"GM\"\n\
         [simulate]\nt_end = 10\nmethod = \"dopri5\"\n",
    )
    .unwrap();
    let (code, out, err) = pdyn(&["run", model.to_str().unwrap(), "--json"]);
    assert_eq!(code, 1, "{err}");
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(summary["ok"], false);
    assert_eq!(summary["error"]["kind"], "integration");
    assert_eq!(summary["error"]["exit_code"], 1);
    assert!(
        summary["final"]["x"].as_f64().unwrap() < 1.0,
        "partial results are kept"
    );
    assert!(err.contains("integration failed at t = "), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_internal_error_exits_3_without_a_backtrace() {
    // A deliberate panic (see `main.rs`) stands for a bug.
    let (code, out, err) = pdyn_env(
        &["eval", "1", "--json"],
        &[("PDYN_DEBUG_PANIC", "1"), ("RUST_BACKTRACE", "1")],
    );
    assert_eq!(code, 3, "{err}");
    assert!(err.contains("internal error"), "{err}");
    assert!(!err.contains("stack backtrace"), "{err}");
    assert_eq!(json_error(&out)["kind"], "internal");
}

#[test]
fn run_options_are_validated_where_read_and_named() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["--dt", "-0.1", "--method", "rk4"],
            "--dt must be a finite time > 0, got -0.1",
        ),
        (&["--points", "0"], "--points must be between 2 and"),
        (
            &["--points", "100000000000"],
            "--points must be between 2 and",
        ),
        (
            &["--output-dt", "0"],
            "--output-dt must be a finite time > 0",
        ),
        (&["--output-dt", "1e-12"], "at most 10000000 output rows"),
        (
            &["--rtol", "-1"],
            "--rtol must be a finite number >= 0, got -1",
        ),
        (
            &["--dt", "1e-15", "--method", "verlet"],
            "--dt must be at least",
        ),
        (&["--t-end", "-3"], "t_end must be a positive time, got -3"),
        (&["--drift-tolerance", "0"], "--drift-tolerance must be"),
    ];
    for (opts, want) in cases {
        let mut args = vec!["run", "examples/satellite.toml", "--json"];
        args.extend_from_slice(opts);
        let (code, out, err) = pdyn(&args);
        assert_eq!(code, 2, "{opts:?}: {err}");
        assert!(err.contains(want), "{opts:?}: {err}");
        assert_eq!(json_error(&out)["kind"], "simulation", "{opts:?}");
    }
}

#[test]
fn non_finite_results_are_flagged_never_printed_as_if_right() {
    // (`1/0` written out is now a located division-by-zero error, exit 2: an overflow here.)
    let (code, out, err) = pdyn(&["eval", "[exp(1000), 2, log(-1)]", "--json"]);
    assert_eq!(code, 1, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["value"], serde_json::json!(["inf", 2.0, "NaN"]));
    assert_eq!(v["non_finite"], serde_json::json!([0, 2]));
    assert!(err.contains("not finite"), "{err}");
    // Non-finite inputs are refused where they are read.
    let (code, _, err) = pdyn(&["eval", "x + 1", "--at", "x=1/0"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = pdyn(&["forces", "examples/takeoff.toml", "--set", "m=nan"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not a finite number"), "{err}");
}

#[test]
fn a_mass_set_to_a_non_positive_value_is_refused_with_the_particle_named() {
    for cmd in ["run", "check", "sweep", "forces"] {
        let model = if cmd == "forces" {
            "examples/pulley.toml"
        } else {
            "examples/building.toml"
        };
        let param = if cmd == "forces" { "mA=0" } else { "m=-1" };
        let (code, out, err) = pdyn(&[cmd, model, "--set", param, "--json"]);
        assert_eq!(code, 2, "{cmd}: {err}");
        assert_eq!(json_error(&out)["kind"], "value", "{cmd}");
        assert!(err.contains("must be finite and > 0"), "{cmd}: {err}");
    }
}

#[test]
fn set_accepts_quantities_with_units_as_model_files_do() {
    let (code, out, err) = pdyn(&[
        "forces",
        "examples/takeoff.toml",
        "--set",
        "v_t=150 knot",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let thrust = v["solutions"][0]["F_T"].as_f64().unwrap();
    let vt = 150.0 * 1852.0 / 3600.0;
    assert!(
        (thrust - 15000.0 * vt * vt / 400.0).abs() < 1e-6 * thrust,
        "{thrust}"
    );
    let (code, _, err) = pdyn(&["forces", "examples/takeoff.toml", "--set", "v_t=150 parsec"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown unit `parsec`"), "{err}");
}

#[test]
fn a_run_that_tabulates_nan_is_a_failure_naming_the_columns() {
    // x/L with L = 0: the state stays finite (nothing accelerates x) but the position column
    // and the energy are not; that must not pass as a run with a conserved energy.
    let dir = std::env::temp_dir().join(format!("pdyn-nan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("nan.toml");
    std::fs::write(
        &path,
        r#"
name = "division by zero in a position"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
L = 0
[coordinates]
x = { initial = 1, rate = 0 }
[particles.a]
mass = 1
position = "[x/L, 0, 0]"
[simulate]
t_end = 1
"#,
    )
    .unwrap();
    let p = path.to_str().unwrap();
    let (code, out, err) = pdyn(&["run", p, "--json"]);
    assert_eq!(code, 1, "{err}");
    let e = json_error(&out);
    assert_eq!(e["kind"], "non_finite");
    let msg = e["message"].as_str().unwrap();
    assert!(msg.contains("`a.x`") && msg.contains("`energy`"), "{msg}");
    assert!(
        err.contains("energy should be conserved but is not finite"),
        "{err}"
    );
    let (code, out, _) = pdyn(&["run", p]);
    assert_eq!(code, 1);
    assert!(out.contains("DRIFTING"), "{out}");
}

#[test]
fn a_non_finite_state_names_what_is_not_finite() {
    // sqrt(x - 2) at x = 1: the acceleration is NaN from the start; the failure says which
    // acceleration and which columns, not only "non-finite state" next to a finite state.
    let dir = std::env::temp_dir().join(format!("pdyn-nan-state-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sqrt.toml");
    std::fs::write(
        &path,
        r#"
name = "a function outside its domain"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
[coordinates]
x = { initial = 1, rate = 0 }
[particles.a]
mass = 1
position = "[x, sqrt(x - 2), 0]"
[simulate]
t_end = 1
"#,
    )
    .unwrap();
    let (code, _, err) = pdyn(&["run", path.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("not finite at that state: x'', a.y"), "{err}");
}

/// Runs `pdyn` with arguments that may not be UTF-8: (exit code, stdout, stderr).
#[cfg(unix)]
fn pdyn_os(args: &[std::ffi::OsString]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .current_dir(in_root::root())
        .output()
        .expect("run pdyn");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A non-UTF-8 byte anywhere on the command line (an expression, an option's value, `--set`,
/// `--json` beside it) is bad input, exit 2 with the argument named, never a panic (it was
/// `std::env::args`, which panics on such bytes, exit 101).
#[cfg(unix)]
#[test]
fn a_non_utf8_argument_is_bad_input_not_a_panic() {
    use std::ffi::OsString;
    use std::os::unix::ffi::OsStringExt;
    let bad = |prefix: &str| {
        let mut b = prefix.as_bytes().to_vec();
        b.push(0xFF);
        OsString::from_vec(b)
    };
    let s = |t: &str| OsString::from(t);
    let cases: Vec<Vec<OsString>> = vec![
        vec![s("simplify"), bad("x")],
        vec![s("simplify"), bad("x"), s("--json")],
        vec![s("diff"), s("x^2"), s("--wrt"), bad("")],
        vec![s("eval"), s("x"), s("--at"), bad("x=")],
        vec![s("kin"), bad("[t, t"), s("--json")],
        vec![
            s("run"),
            s("examples/satellite.toml"),
            s("--set"),
            bad("m="),
        ],
        vec![bad("simplify")],
    ];
    for args in cases {
        let (code, out, err) = pdyn_os(&args);
        assert_eq!(code, 2, "{args:?}: exit {code}\n{err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        // An unknown subcommand is clap's "unrecognized subcommand"; any other argument is named.
        if args.len() > 1 {
            assert!(err.contains("not valid UTF-8"), "{args:?}: {err}");
        }
        if args.iter().any(|a| a == "--json") {
            assert_eq!(json_error(&out)["kind"], "argument", "{args:?}: {out}");
        }
    }
}

/// A file name is any bytes: a model file whose name is not UTF-8 is read; a missing one is an
/// I/O error (exit 2) naming it.
#[cfg(unix)]
#[test]
fn a_non_utf8_file_name_is_a_file_name() {
    use std::ffi::OsString;
    use std::os::unix::ffi::OsStringExt;
    let dir = std::env::temp_dir().join(format!("pdyn-utf8-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut name = dir.as_os_str().to_os_string().into_vec();
    name.extend_from_slice(b"/sat\xFF.toml");
    let path = std::path::PathBuf::from(OsString::from_vec(name));
    std::fs::copy(in_root::root().join("examples/satellite.toml"), &path).unwrap();
    let (code, out, err) = pdyn_os(&["derive".into(), path.clone().into_os_string()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("Satellite"), "{out}");
    let mut missing = dir.as_os_str().to_os_string().into_vec();
    missing.extend_from_slice(b"/none\xFE.toml");
    let (code, _, err) = pdyn_os(&["run".into(), OsString::from_vec(missing)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("none") && err.contains("cannot read"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `simplify`, `eval` and `diff` refuse a division by zero with its location (exit 2): where it
/// is written (`1/0`, `x/(x-x)`), or the whole expression when simplification reveals it.
/// They printed `1/0`, `1/0*x` and `-1/0` with exit 0.
#[test]
fn a_division_by_zero_is_a_located_error() {
    for (args, column) in [
        (vec!["simplify", "1/0"], 3),
        (vec!["simplify", "x/(x-x)"], 3),
        (vec!["simplify", "2 + 0^-1"], 5),
        (vec!["simplify", "1/((x+1)^2 - x^2 - 2*x - 1)"], 1),
        (vec!["simplify", "[x, 1/((x+1)^2 - x^2 - 2*x - 1), 0]"], 1),
        (vec!["diff", "sin(x)/(x-x)", "--wrt", "x"], 8),
        (vec!["eval", "1/(2-2)"], 3),
    ] {
        let mut a = args.clone();
        a.push("--json");
        let (code, out, err) = pdyn(&a);
        assert_eq!(code, 2, "{args:?}: exit {code}\n{out}{err}");
        let e = json_error(&out);
        assert_eq!(e["kind"], "expression", "{args:?}: {e}");
        assert!(err.contains("division by zero"), "{args:?}: {err}");
        assert_eq!(e["location"]["column"], column, "{args:?}: {e}");
    }
    let (code, out, _) = pdyn(&["simplify", "x/(x-y) + 0/x"]);
    assert_eq!((code, out.trim()), (0, "x/(x - y)"));
}

/// A model file with bytes that are not UTF-8 is a model error at the first of them (line and
/// column), for every kind of model file and every command that reads one; it was "cannot
/// read the model file: stream did not contain valid UTF-8" with no place.
#[test]
fn non_utf8_bytes_in_a_model_file_are_located() {
    let dir = std::env::temp_dir().join(format!("pdyn-bytes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let root = in_root::root();
    let cases = [
        ("examples/satellite.toml", "derive"),
        ("examples/satellite.toml", "run"),
        ("examples/nbody/figure_eight.toml", "run"),
        ("examples/md/lj_liquid.toml", "run"),
    ];
    for (k, (example, command)) in cases.iter().enumerate() {
        let text = std::fs::read_to_string(root.join(example)).unwrap();
        // A Latin-1 byte at the end of the third line.
        let lines: Vec<&str> = text.lines().collect();
        let mut bytes = Vec::new();
        for (i, l) in lines.iter().enumerate() {
            bytes.extend_from_slice(l.as_bytes());
            if i == 2 {
                bytes.extend_from_slice(b" # caf\xE9");
            }
            bytes.push(b'\n');
        }
        let path = dir.join(format!("m{k}.toml"));
        std::fs::write(&path, &bytes).unwrap();
        let p = path.to_str().unwrap();
        let (code, out, err) = pdyn(&[command, p, "--json"]);
        assert_eq!(code, 2, "{example}: {err}");
        let e = json_error(&out);
        assert_eq!(e["kind"], "model", "{example}: {e}");
        assert_eq!(e["location"]["line"], 3, "{example}: {e}");
        assert_eq!(
            e["location"]["column"],
            lines[2].chars().count() + 7,
            "{example}: {e}"
        );
        assert!(err.contains("0xE9") && err.contains("UTF-8"), "{err}");
    }
    // The bodies file of an N-body model: located in the CSV.
    std::fs::copy(
        root.join("examples/nbody/outer_solar_system_csv.toml"),
        dir.join("csv.toml"),
    )
    .unwrap();
    let csv = std::fs::read(root.join("examples/nbody/outer_solar_system.csv")).unwrap();
    let mut lines: Vec<Vec<u8>> = csv.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let col = lines[2].len() + 1;
    lines[2].push(0xFE);
    std::fs::write(dir.join("outer_solar_system.csv"), lines.join(&b'\n')).unwrap();
    let (code, out, err) = pdyn(&["run", dir.join("csv.toml").to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    let e = json_error(&out);
    assert!(
        e["location"]["file"].as_str().unwrap().ends_with(".csv"),
        "{e}"
    );
    assert_eq!(
        (
            e["location"]["line"].clone(),
            e["location"]["column"].clone()
        ),
        (3.into(), col.into()),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A bad `t_end`, `output_dt`, `dt`, `points` in `[simulate]` is shown at its key (it was
/// "t_end must be a positive time, got -5" or "--output-dt must be ..." with no place); the
/// same value given on the command line is still named by its option.
#[test]
fn bad_simulate_values_in_a_model_file_are_located_at_their_key() {
    let root = in_root::root();
    let text = std::fs::read_to_string(root.join("examples/projectile_drag.toml")).unwrap();
    let dir = std::env::temp_dir().join(format!("pdyn-sim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (k, (key, value)) in [
        ("t_end", "-5"),
        ("t_end", "0"),
        ("t_end", "\"-2 s\""),
        ("output_dt", "1e-12"),
        ("output_dt", "-1"),
        ("output_dt", "0"),
        ("dt", "1e-15"),
        ("points", "100000000"),
    ]
    .into_iter()
    .enumerate()
    {
        let mut lines: Vec<String> = text
            .lines()
            .filter(|l| !l.starts_with(&format!("{key} =")))
            .map(str::to_string)
            .collect();
        let at = lines.iter().position(|l| l == "[simulate]").unwrap() + 1;
        lines.insert(at, format!("{key} = {value}"));
        let path = dir.join(format!("s{k}.toml"));
        std::fs::write(&path, lines.join("\n")).unwrap();
        let p = path.to_str().unwrap();
        let (code, out, err) = pdyn(&["run", p, "--json", "--out", dir.to_str().unwrap()]);
        assert_eq!(code, 2, "{key} = {value}: {err}");
        let e = json_error(&out);
        assert_eq!(e["kind"], "model", "{key} = {value}: {e}");
        assert_eq!(e["location"]["line"], at + 1, "{key} = {value}: {e}");
        assert_eq!(
            e["location"]["column"],
            key.len() + 4,
            "{key} = {value}: {e}"
        );
        assert!(err.contains(&format!("`{key}`")), "{err}");
    }
    // On the command line: the option is named.
    let (code, _, err) = pdyn(&[
        "run",
        "examples/projectile_drag.toml",
        "--output-dt",
        "1e-13",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("--output-dt must be"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
