//! Molecular-dynamics model files (`examples/md/`) through the binary: every example runs
//! (shrunk with `--set n=...` and a short `--t-end`), the formula and built-in LJ kernels agree,
//! NVE conserves energy, and every class of bad input is refused with exit code 2 and a
//! located error (file:line:col, and a JSON error object with `--json`), or, for a run that
//! explodes, exit code 1 with the output up to that step kept.

use std::path::PathBuf;

#[path = "common/in_root.rs"]
mod in_root;
use in_root::{json, pdyn, root};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pdyn-md-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn md_examples() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("examples/md"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

/// Every example: 20 steps at its own dt with `n = 5` (every md example sizes itself by a
/// parameter `n`), checked for a sane summary, thermo.csv and, where dumped, traj.xyz.
#[test]
fn every_md_example_runs_shrunk() {
    let files = md_examples();
    assert!(files.len() >= 4, "examples/md has {} files", files.len());
    for f in files {
        let src = std::fs::read_to_string(&f).unwrap();
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        let spec = pdyn::md::parse(&src, &name, &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            spec.parameters.iter().any(|(n, _)| n == "n"),
            "{name}: md examples size themselves with a parameter `n` (the test shrinks it)"
        );
        let t_end = format!("{}", 20.0 * spec.dt.value);
        let out = scratch(&name);
        let (code, stdout, stderr) = pdyn(&[
            "run",
            f.to_str().unwrap(),
            "--set",
            "n=5",
            "--t-end",
            &t_end,
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(code, 0, "{name}: {stderr}");
        let s = json(&stdout);
        assert_eq!(s["steps"], 20, "{name}");
        let atoms = s["atoms"].as_u64().unwrap();
        assert!((100..=600).contains(&atoms), "{name}: {atoms} atoms");
        let t = s["final"]["temperature"].as_f64().unwrap();
        assert!(t.is_finite() && t > 0.0, "{name}: T = {t}");
        let thermo = std::fs::read_to_string(out.join("thermo.csv")).unwrap();
        let rows: Vec<&str> = thermo.lines().collect();
        assert!(rows[0].starts_with("step,time,temperature"), "{name}");
        assert!(rows.len() >= 3, "{name}: {} thermo rows", rows.len());
        assert_eq!(rows.last().unwrap().split(',').next(), Some("20"), "{name}");
        if spec.dump_every > 0 {
            let traj = std::fs::read_to_string(out.join("traj.xyz")).unwrap();
            let first: usize = traj.lines().next().unwrap().trim().parse().unwrap();
            assert_eq!(first as u64, atoms, "{name}");
            assert!(
                traj.lines().nth(1).unwrap().contains("Lattice=\""),
                "{name}"
            );
        }
        if spec.rdf {
            let rdf = std::fs::read_to_string(out.join("rdf.csv")).unwrap();
            assert_eq!(rdf.lines().count(), spec.rdf_bins + 1, "{name}");
            let g_max = rdf
                .lines()
                .skip(1)
                .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
                .fold(0.0, f64::max);
            // a crystal or a liquid has a first peak well above the ideal gas's 1
            assert!(g_max > 2.0, "{name}: max g(r) = {g_max}");
        }
        if spec.msd {
            let msd = std::fs::read_to_string(out.join("msd.csv")).unwrap();
            let last: f64 = msd
                .lines()
                .last()
                .unwrap()
                .split(',')
                .nth(2)
                .unwrap()
                .parse()
                .unwrap();
            assert!(
                last > 0.0 && last < 1.0,
                "{name}: msd after 20 steps {last}"
            );
        }
        if let Some((t0, _)) = &spec.velocities {
            // Maxwell–Boltzmann velocities are scaled to exactly T with 3N − 3 degrees of
            // freedom, in the file's units (K in `real`, ε/k_B in `lj`); under Langevin, which
            // does not conserve momentum, the temperature counts 3N
            let first: f64 = rows[1].split(',').nth(2).unwrap().parse().unwrap();
            let n3 = 3.0 * atoms as f64;
            let expected = match spec.thermostat.ensemble {
                pdyn::md::spec::Ensemble::Langevin { .. } => t0.value * (n3 - 3.0) / n3,
                _ => t0.value,
            };
            assert!(
                (first - expected).abs() < 1e-9 * expected,
                "{name}: T(0) = {first}"
            );
        }
        let on_disk = json(&std::fs::read_to_string(out.join("summary.json")).unwrap());
        assert_eq!(on_disk["atoms"], s["atoms"]);
    }
}

fn run_json(file: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["run", file, "--json"];
    args.extend_from_slice(extra);
    let (code, out, err) = pdyn(&args);
    assert_eq!(code, 0, "{file}: {err}");
    json(&out)
}

/// The same start (lattice, seed), the same steps: the formula `4*eps*((sigma/r)^12 -
/// (sigma/r)^6)`, derived and compiled, gives the built-in kernel's energies to round-off.
#[test]
fn formula_lj_equals_builtin_lj() {
    for steps in ["0", "0.05"] {
        let a = run_json(
            "examples/md/lj_liquid.toml",
            &["--set", "n=5", "--t-end", steps],
        );
        let b = run_json(
            "examples/md/lj_formula.toml",
            &["--set", "n=5", "--t-end", steps],
        );
        for key in ["potential", "kinetic", "total", "pressure"] {
            let (x, y) = (
                a["final"][key].as_f64().unwrap(),
                b["final"][key].as_f64().unwrap(),
            );
            assert!(
                (x - y).abs() <= 1e-11 * x.abs().max(1.0),
                "{key} after {steps}: built-in {x} vs formula {y}"
            );
        }
        assert_eq!(a["atoms"], 500);
    }
}

/// `--no-jit` runs the formula in the batch kernel's interpreter, with the native kernel's bits:
/// the same final state to the last digit (and `formula_native` says which ran).
#[test]
fn formula_without_jit_gives_the_same_bits() {
    let args = ["--set", "n=5", "--t-end", "0.05"];
    let native = run_json("examples/md/lj_formula.toml", &args);
    let mut off = args.to_vec();
    off.push("--no-jit");
    let interp = run_json("examples/md/lj_formula.toml", &off);
    assert_eq!(native["formula_native"], true);
    assert_eq!(interp["formula_native"], false);
    assert_eq!(native["final"], interp["final"]);
}

/// NVE, 500 atoms of the in.lj liquid with the energy shifted at the cutoff, 200 steps:
/// measured max |E − E₀| = 4.4e-5 of the mean kinetic energy, slope 4.5e-5 ε/τ per atom.
/// Bounds 1e-3 and 1e-3; no drift warning.
#[test]
fn nve_energy_is_conserved() {
    let src = std::fs::read_to_string(root().join("examples/md/lj_liquid.toml")).unwrap();
    let d = scratch("nve");
    let f = d.join("lj_shifted.toml");
    std::fs::write(
        &f,
        src.replace("mode = \"plain\"", "mode = \"shifted-energy\""),
    )
    .unwrap();
    let s = run_json(f.to_str().unwrap(), &["--set", "n=5", "--t-end", "1.0"]);
    let rel = s["energy_drift"]["relative"].as_f64().unwrap();
    let slope = s["energy_drift"]["slope_per_atom"].as_f64().unwrap();
    assert!(rel < 1e-3, "relative drift {rel}");
    assert!(slope.abs() < 1e-3, "slope {slope}");
    assert_eq!(
        s["warnings"].as_array().unwrap().len(),
        0,
        "{}",
        s["warnings"]
    );
    // and the plain cutoff of in.lj, whose energy jumps at r_c, is flagged when it drifts
    let t = run_json(
        "examples/md/lj_liquid.toml",
        &["--set", "n=5", "--t-end", "1.0"],
    );
    let rel_plain = t["energy_drift"]["relative"].as_f64().unwrap();
    assert!(rel_plain > rel, "plain {rel_plain} vs shifted {rel}");
}

/// A bad-input file derived from an example: (exit code, JSON error object).
fn bad(name: &str, text: &str, extra: &[&str]) -> (i32, serde_json::Value, String) {
    let d = scratch(name);
    let f = d.join(format!("{name}.toml"));
    std::fs::write(&f, text).unwrap();
    let mut args = vec!["run", f.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let (code, out, err) = pdyn(&args);
    let v = json(&out);
    (code, v["error"].clone(), err)
}

fn lj() -> String {
    std::fs::read_to_string(root().join("examples/md/lj_liquid.toml")).unwrap()
}

/// Asserts exit 2, a model error at `line` (and a column), and `needle` in the message.
fn assert_located(
    name: &str,
    (code, e, stderr): (i32, serde_json::Value, String),
    line: u64,
    needle: &str,
) {
    assert_eq!(code, 2, "{name}: {stderr}");
    assert_eq!(e["kind"], "model", "{name}: {e}");
    assert_eq!(e["exit_code"], 2, "{name}");
    assert_eq!(e["location"]["line"], line, "{name}: {e}");
    assert!(
        e["location"]["column"].as_u64().is_some_and(|c| c >= 1),
        "{name}: {e}"
    );
    let msg = e["message"].as_str().unwrap();
    assert!(msg.contains(needle), "{name}: `{needle}` not in {msg}");
    // the human message on stderr is file:line:col
    let file_line = format!("{name}.toml:{line}:");
    assert!(stderr.contains(&file_line), "{name}: {stderr}");
}

fn line_of(text: &str, needle: &str) -> u64 {
    text.lines().position(|l| l.starts_with(needle)).unwrap() as u64 + 1
}

/// The fields of `[md]` are read by the same reader as every model kind (pdyn-mech's
/// `Constants`, issue 25): expressions of parameters, `pi`, a misspelt name located with a
/// suggestion; and a unit literal, which that reader would convert to SI, is refused, since an
/// MD model is in reduced or `real` units.
#[test]
fn md_fields_use_the_common_reader_and_refuse_units() {
    let text = lj().replace("cutoff = \"2.5*sigma\"", "cutoff = \"2.5*sigmaa\"");
    let line = line_of(&text, "cutoff = ");
    assert_located(
        "misspelt",
        bad("misspelt", &text, &["--set", "n=5"]),
        line,
        "sigmaa",
    );
    let text = lj().replace("dt = 0.005", "dt = \"0.005 s\"");
    let line = line_of(&text, "dt = ");
    assert_located(
        "unit",
        bad("unit", &text, &["--set", "n=5"]),
        line,
        "carries a unit",
    );
    let text = lj().replace("sigma = 1.0", "sigma = \"1 angstrom\"");
    let line = line_of(&text, "sigma = \"1");
    assert_located(
        "unitparam",
        bad("unitparam", &text, &["--set", "n=5"]),
        line,
        "carries a unit",
    );
    // `--set` of a name that is not a parameter: refused by the library's `md::load`, as
    // for N-body models.
    let (code, e, _) = bad("setx", &lj(), &["--set", "n=5,epsilon=2"]);
    assert_eq!(code, 2);
    let msg = e["message"].as_str().unwrap();
    assert!(
        msg.contains("`epsilon` is not a parameter (parameters: n, eps, sigma)"),
        "{msg}"
    );
    // An expression with pi and a parameter runs (cutoff 2.5 written as 5*sigma*pi/(2*pi); 10 steps).
    let text = lj().replace("cutoff = \"2.5*sigma\"", "cutoff = \"5*sigma*pi/(2*pi)\"");
    let (code, _, err) = bad("pi", &text, &["--set", "n=5", "--t-end", "0.05"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn bad_parameters_of_builtin_kernels_are_located() {
    for (value, needle) in [
        ("-1.0", "must be > 0"),
        ("0", "must be > 0"),
        ("nan", "nan"),
    ] {
        let text = lj().replace("sigma = \"sigma\"", &format!("sigma = {value}"));
        let line = line_of(&text, &format!("sigma = {value}"));
        assert_located(
            "sigma",
            bad("sigma", &text, &["--set", "n=5"]),
            line,
            needle,
        );
    }
    let text = lj().replace("epsilon = \"eps\"", "epsilon = \"-eps\"");
    let line = line_of(&text, "epsilon = ");
    assert_located(
        "epsilon",
        bad("epsilon", &text, &["--set", "n=5"]),
        line,
        "epsilon",
    );
    // a parameter set to a bad value on the command line is caught at its use
    let text = lj();
    let line = line_of(&text, "sigma = \"sigma\"");
    assert_located(
        "setsigma",
        bad("setsigma", &text, &["--set", "n=5,sigma=-2"]),
        line,
        "sigma",
    );
}

#[test]
fn formula_of_other_symbols_or_infinite_at_cutoff_is_located() {
    let f = |pot: &str| {
        lj().replace("kind = \"lj\"", &format!("potential = \"{pot}\""))
            .replace("epsilon = \"eps\"\n", "")
            .replace("sigma = \"sigma\"\n", "")
    };
    let text = f("4*eps*((sigma/r)^12 - (s/x)^6)");
    let line = line_of(&text, "potential");
    let r = bad("formula", &text, &["--set", "n=5"]);
    assert!(
        r.1["message"].as_str().unwrap().contains("`s`, `x`"),
        "{}",
        r.1
    );
    assert_located("formula", r, line, "function of r alone");
    let text = f("eps/(r - 2.5)");
    assert_located(
        "cutoff",
        bad("cutoff", &text, &["--set", "n=5"]),
        line,
        "no finite value at the cutoff",
    );
}

#[test]
fn box_shorter_than_twice_cutoff_plus_skin_is_located() {
    let text = lj();
    let line = line_of(&text, "[md.lattice]");
    assert_located(
        "box",
        bad("box", &text, &["--set", "n=2"]),
        line,
        "2·(cutoff + skin)",
    );
}

#[test]
fn thermostat_without_temperature_is_located() {
    let text = lj() + "\n[md.thermostat]\nkind = \"nose-hoover\"\ntau = 0.5\n";
    let line = line_of(&text, "kind = \"nose-hoover\"");
    assert_located(
        "thermostat",
        bad("thermostat", &text, &["--set", "n=5"]),
        line,
        "needs a `temperature`",
    );
}

/// `scheme` and `noise` of `[md.thermostat]`: "lammps" selects LAMMPS's fix langevin + fix nve
/// (uniform noise unless `noise = "gaussian"`), "baoab" is the default; an unknown value, a
/// noise for BAOAB, or either key on another thermostat is an error at its line.
#[test]
fn langevin_scheme_and_noise_parse_and_bad_values_are_located() {
    use pdyn_md::thermostat::{LangevinNoise, LangevinScheme};
    let base = lj() + "\n[md.thermostat]\nkind = \"langevin\"\ntemperature = 1.0\n";
    for (extra, expected) in [
        ("", LangevinScheme::Baoab),
        ("scheme = \"baoab\"\n", LangevinScheme::Baoab),
        (
            "scheme = \"lammps\"\n",
            LangevinScheme::Lammps {
                noise: LangevinNoise::Uniform,
            },
        ),
        (
            "scheme = \"lammps\"\nnoise = \"gaussian\"\n",
            LangevinScheme::Lammps {
                noise: LangevinNoise::Gaussian,
            },
        ),
    ] {
        let spec = pdyn::md::load(&(base.clone() + extra), "t.toml", &[]).unwrap();
        match spec.thermostat.ensemble {
            pdyn::md::spec::Ensemble::Langevin { scheme, .. } => {
                assert_eq!(scheme, expected, "{extra}")
            }
            other => panic!("{other:?}"),
        }
    }
    for (name, extra, needle_line, message) in [
        (
            "scheme_unknown",
            "scheme = \"verlet\"\n",
            "scheme =",
            "unknown Langevin scheme `verlet`",
        ),
        (
            "noise_unknown",
            "scheme = \"lammps\"\nnoise = \"pink\"\n",
            "noise =",
            "unknown Langevin noise `pink`",
        ),
        (
            "noise_for_baoab",
            "noise = \"uniform\"\n",
            "noise =",
            "applies to scheme = \"lammps\" only",
        ),
    ] {
        let text = base.clone() + extra;
        let line = line_of(&text, needle_line);
        assert_located(name, bad(name, &text, &["--set", "n=5"]), line, message);
    }
    let text = lj()
        + "\n[md.thermostat]\nkind = \"nose-hoover\"\ntemperature = 1.0\nscheme = \"lammps\"\n";
    let line = line_of(&text, "scheme =");
    assert_located(
        "scheme_nh",
        bad("scheme_nh", &text, &["--set", "n=5"]),
        line,
        "applies to the Langevin thermostat only",
    );
}

/// Two atoms 0.3σ apart in a file: refused with the pair and the distance and a hint at
/// `minimize = true`, which then relaxes them and the run succeeds.
#[test]
fn overlapping_atoms_are_reported_and_minimize_resolves_them() {
    let d = scratch("overlap");
    let xyz = "4\nLattice=\"8 0 0 0 8 0 0 0 8\" Properties=species:S:1:pos:R:3\n\
               Ar 1.0 1.0 1.0\nAr 1.3 1.0 1.0\nAr 5.0 5.0 5.0\nAr 1.0 5.0 3.0\n";
    std::fs::write(d.join("start.xyz"), xyz).unwrap();
    let model =
        "name = \"overlap\"\n[md]\ndt = 0.002\nsteps = 10\n\n[md.species.Ar]\nmass = 1.0\n\n\
                 [[md.pairs]]\nkind = \"lj\"\nepsilon = 1.0\nsigma = 1.0\ncutoff = 2.5\n\n\
                 [md.read]\nfile = \"start.xyz\"\n";
    let f = d.join("overlap.toml");
    std::fs::write(&f, model).unwrap();
    let (code, out, err) = pdyn(&["run", f.to_str().unwrap(), "--json"]);
    let e = json(&out)["error"].clone();
    assert_eq!(code, 2, "{err}");
    assert_eq!(e["location"]["line"], line_of(model, "file = "), "{e}");
    let msg = e["message"].as_str().unwrap();
    assert!(
        msg.contains("atoms 0 and 1") && msg.contains("0.3"),
        "{msg}"
    );
    assert!(msg.contains("minimize = true"), "{msg}");
    std::fs::write(
        &f,
        model.replace("steps = 10\n", "steps = 10\nminimize = true\n"),
    )
    .unwrap();
    let (code, out, err) = pdyn(&["run", f.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let s = json(&out);
    assert!(
        s["minimized"]["energy"].as_f64().unwrap() < 0.0,
        "{}",
        s["minimized"]
    );
}

/// dt = 0.05 (ten times in.lj's): the run explodes within a few steps; exit 1, the step and
/// the atoms in the message, and thermo.csv with the records up to there.
#[test]
fn energy_explosion_is_reported_with_step_and_atoms_and_partial_output() {
    let out = scratch("explode");
    let (code, stdout, stderr) = pdyn(&[
        "run",
        "examples/md/lj_liquid.toml",
        "--set",
        "n=5",
        "--dt",
        "0.05",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 1, "{stderr}");
    let s = json(&stdout);
    let e = &s["error"];
    assert_eq!(e["kind"], "md_run");
    let msg = e["message"].as_str().unwrap();
    assert!(
        msg.contains("unstable at step") && msg.contains("particle"),
        "{msg}"
    );
    let step = s["steps"].as_u64().unwrap();
    assert!((1..=10).contains(&step), "detected at step {step}");
    let thermo = std::fs::read_to_string(out.join("thermo.csv")).unwrap();
    assert!(thermo.lines().count() >= 2, "{thermo}");
    assert!(stderr.contains("unstable at step"), "{stderr}");
}

#[test]
fn options_without_meaning_for_md_are_refused_by_name() {
    for opt in [["--rtol", "1e-3"], ["--method", "rk4"], ["--points", "10"]] {
        let (code, out, _) = pdyn(&[
            "run",
            "examples/md/lj_liquid.toml",
            opt[0],
            opt[1],
            "--json",
        ]);
        assert_eq!(code, 2);
        let e = json(&out)["error"].clone();
        assert_eq!(e["kind"], "argument");
        assert!(e["message"].as_str().unwrap().starts_with(opt[0]), "{e}");
    }
    let (code, out, _) = pdyn(&[
        "run",
        "examples/md/lj_liquid.toml",
        "--set",
        "nope=1",
        "--json",
    ]);
    assert_eq!(code, 2);
    assert!(json(&out)["error"]["message"]
        .as_str()
        .unwrap()
        .contains("`nope`"));
}

#[test]
fn other_commands_on_an_md_model_say_to_use_run() {
    for command in ["derive", "forces", "check", "sweep"] {
        let (code, out, err) = pdyn(&[command, "examples/md/lj_liquid.toml", "--json"]);
        assert_eq!(code, 2, "{command}: {err}");
        let e = json(&out)["error"].clone();
        assert!(
            e["message"].as_str().unwrap().contains("use `pdyn run`"),
            "{command}: {e}"
        );
        assert_eq!(e["location"]["line"], line_of(&lj(), "[md]"), "{command}");
    }
}

#[test]
fn plot_writes_the_thermo_figure() {
    let out = scratch("plot");
    let (code, _, err) = pdyn(&[
        "run",
        "examples/md/lj_liquid.toml",
        "--set",
        "n=4",
        "--t-end",
        "0.1",
        "--out",
        out.to_str().unwrap(),
        "--plot",
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(out.join("thermo.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("temperature"));
    assert!(std::fs::metadata(out.join("thermo.png")).unwrap().len() > 1000);
}

/// `dump_every = 5` over 20 steps: frames at steps 0, 5, 10, 15, 20, each a complete extended
/// XYZ frame that pdyn-md reads back (species, box, positions inside it).
#[test]
fn trajectory_has_one_frame_per_dump() {
    let d = scratch("traj");
    let f = d.join("lj_dump.toml");
    std::fs::write(
        &f,
        lj().replace("thermo_every = 50", "thermo_every = 5\ndump_every = 5"),
    )
    .unwrap();
    let out = d.join("out");
    let (code, _, err) = pdyn(&[
        "run",
        f.to_str().unwrap(),
        "--set",
        "n=4",
        "--t-end",
        "0.1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(out.join("traj.xyz")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let (mut at, mut steps) = (0, vec![]);
    while at < lines.len() {
        let n: usize = lines[at].trim().parse().unwrap();
        assert_eq!(n, 256);
        let step = lines[at + 1]
            .split_whitespace()
            .find_map(|w| w.strip_prefix("Step="))
            .unwrap();
        steps.push(step.parse::<u64>().unwrap());
        at += n + 2;
    }
    assert_eq!(steps, [0, 5, 10, 15, 20]);
    let frame = pdyn_md::io::read_xyz(std::io::BufReader::new(text.as_bytes()), 1000, 1.0).unwrap();
    assert_eq!(frame.names, ["Ar"]);
    let l = frame.system.sim_box.l[0];
    assert!(
        (l - 4.0 * libm::cbrt(4.0f64 / 0.8442)).abs() < 1e-12,
        "box {l}"
    );
    let p = &frame.system.particles;
    assert!((0..p.len()).all(|i| (0.0..l).contains(&p.x[i])));
}

/// Morse: the built-in kernel and the formula `D*((1 - exp(-a*(r - r0)))^2 - 1)` on the same
/// start give the same energies to round-off, in every cutoff mode.
#[test]
fn formula_morse_equals_builtin_morse() {
    let d = scratch("morse");
    for mode in ["plain", "shifted-energy", "shifted-force"] {
        let base = lj()
            .replace("eps = 1.0", "D = 0.8\nalpha = 1.7\nr0 = 1.1")
            .replace("mode = \"plain\"", &format!("mode = \"{mode}\""));
        let builtin = base
            .replace(
                "kind = \"lj\"",
                "kind = \"morse\"\ndepth = \"D\"\nalpha = \"alpha\"\nr0 = \"r0\"",
            )
            .replace("epsilon = \"eps\"\n", "")
            .replace("sigma = \"sigma\"\n", "");
        let formula = base
            .replace(
                "kind = \"lj\"",
                "potential = \"D*((1 - exp(-alpha*(r - r0)))^2 - 1)\"",
            )
            .replace("epsilon = \"eps\"\n", "")
            .replace("sigma = \"sigma\"\n", "");
        let (fa, fb) = (d.join("builtin.toml"), d.join("formula.toml"));
        std::fs::write(&fa, builtin).unwrap();
        std::fs::write(&fb, formula).unwrap();
        let a = run_json(fa.to_str().unwrap(), &["--set", "n=5", "--t-end", "0.05"]);
        let b = run_json(fb.to_str().unwrap(), &["--set", "n=5", "--t-end", "0.05"]);
        for key in ["potential", "total", "pressure"] {
            let (x, y) = (
                a["final"][key].as_f64().unwrap(),
                b["final"][key].as_f64().unwrap(),
            );
            assert!(x != 0.0, "{mode} {key}");
            assert!(
                (x - y).abs() <= 1e-10 * x.abs().max(1.0),
                "{mode} {key}: built-in {x} vs formula {y}"
            );
        }
    }
}

/// Two species from a file (extended XYZ by name, LAMMPS data by type order), one pair
/// potential per pair of species (one of them a formula); a missing pair is a located error.
#[test]
fn two_species_from_xyz_and_lammps_data() {
    let d = scratch("species");
    // 4 x 4 x 4 simple cubic, spacing 1.5 in a box of 6: A and B alternate
    let mut xyz =
        String::from("64\nLattice=\"6 0 0 0 6 0 0 0 6\" Properties=species:S:1:pos:R:3\n");
    let mut data = String::from("test\n\n64 atoms\n2 atom types\n\n0 6 xlo xhi\n0 6 ylo yhi\n0 6 zlo zhi\n\nMasses\n\n1 1.0\n2 2.0\n\nAtoms # atomic\n\n");
    let mut k = 0;
    for i in 0..4 {
        for j in 0..4 {
            for l in 0..4 {
                let (x, y, z) = (
                    0.75 + 1.5 * i as f64,
                    0.75 + 1.5 * j as f64,
                    0.75 + 1.5 * l as f64,
                );
                let sp = if (i + j + l) % 2 == 0 { "A" } else { "B" };
                xyz += &format!("{sp} {x} {y} {z}\n");
                k += 1;
                data += &format!("{k} {} {x} {y} {z}\n", if sp == "A" { 1 } else { 2 });
            }
        }
    }
    std::fs::write(d.join("mix.xyz"), &xyz).unwrap();
    std::fs::write(d.join("mix.data"), &data).unwrap();
    let model = |file: &str, with_ab: bool| {
        let ab = if with_ab {
            "[[md.pairs]]\nbetween = [\"A\", \"B\"]\nkind = \"lj\"\nepsilon = 1.5\nsigma = 0.8\ncutoff = 2.0\n\n"
        } else {
            ""
        };
        format!(
            "name = \"mixture\"\n[parameters]\neps_bb = 0.5\n\n[md]\ndt = 0.002\nsteps = 10\n\n\
             [md.species.A]\nmass = 1.0\n\n[md.species.B]\nmass = 2.0\n\n\
             [[md.pairs]]\nbetween = [\"A\", \"A\"]\nkind = \"lj\"\nepsilon = 1.0\nsigma = 1.0\ncutoff = 2.5\n\n{ab}\
             [[md.pairs]]\nbetween = [\"B\", \"B\"]\npotential = \"4*eps_bb*((0.88/r)^12 - (0.88/r)^6)\"\ncutoff = 2.2\n\n\
             [md.read]\nfile = \"{file}\"\n\n[md.velocities]\ntemperature = 1.0\nseed = 5\n"
        )
    };
    let mut energies = vec![];
    for file in ["mix.xyz", "mix.data"] {
        let f = d.join("mix.toml");
        std::fs::write(&f, model(file, true)).unwrap();
        let s = run_json(f.to_str().unwrap(), &[]);
        assert_eq!(s["atoms"], 64);
        assert!(s["formula_native"].as_bool().is_some());
        energies.push(s["final"]["potential"].as_f64().unwrap());
    }
    // the same atoms, species and velocities from both files: the same run
    assert_eq!(energies[0], energies[1]);
    let text = model("mix.xyz", false);
    assert_located(
        "mix",
        {
            let f = d.join("mix.toml");
            std::fs::write(&f, &text).unwrap();
            let (code, out, err) = pdyn(&["run", f.to_str().unwrap(), "--json"]);
            (code, json(&out)["error"].clone(), err)
        },
        line_of(&text, "[md]"),
        "no pair potential between A and B",
    );
    // A configuration read from a file is sized once read, before anything else is built:
    // over the memory limit it is refused at its `file`.
    for file in ["mix.xyz", "mix.data"] {
        let text = model(file, true);
        let f = d.join("mix.toml");
        std::fs::write(&f, &text).unwrap();
        let (code, out, err) = in_root::pdyn_env(
            &["run", f.to_str().unwrap(), "--json"],
            &[("PDYN_MEMORY_LIMIT", "10K")],
        );
        assert_located(
            "mix",
            (code, json(&out)["error"].clone(), err),
            line_of(&text, "file = "),
            "64 atoms need about",
        );
    }
}

/// `rdf_frames` sets how many frames the RDF averages: exactly `min(rdf_frames, R)`, with `R`
/// the thermo records of the second half of the run (here steps 100, 102, …, 200: 51), as
/// `summary.json` reports; the default stays "up to 20"; a count out of range is located.
#[test]
fn rdf_frames_sets_the_number_of_frames_averaged() {
    let base = lj()
        .replace("steps = 100", "steps = 200")
        .replace("thermo_every = 50", "thermo_every = 2\nrdf = true");
    let records = 51;
    for frames in [
        None,
        Some(1),
        Some(5),
        Some(7),
        Some(50),
        Some(51),
        Some(200),
    ] {
        let text = match frames {
            Some(f) => base.replace("rdf = true", &format!("rdf = true\nrdf_frames = {f}")),
            None => base.clone(),
        };
        let d = scratch(&format!("rdf{frames:?}"));
        let f = d.join("m.toml");
        std::fs::write(&f, text).unwrap();
        let (code, out, err) = pdyn(&[
            "run",
            f.to_str().unwrap(),
            "--set",
            "n=4",
            "--json",
            "--out",
            d.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{frames:?}: {err}");
        let v = json(&out);
        let want = frames.unwrap_or(20).min(records) as u64;
        assert_eq!(v["rdf_frames"], want, "{frames:?}");
        let warned = v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("rdf_frames"));
        assert_eq!(
            warned,
            frames.is_some_and(|f| f > records),
            "{frames:?}: {v}"
        );
        assert!(d.join("rdf.csv").exists());
    }
    for bad_value in ["0", "1000000", "\"many\"", "-3"] {
        let text = base.replace(
            "rdf = true",
            &format!("rdf = true\nrdf_frames = {bad_value}"),
        );
        let line = line_of(&text, "rdf_frames");
        assert_located(
            "rdf_frames",
            bad("rdf_frames", &text, &["--set", "n=4"]),
            line,
            "",
        );
    }
}

/// A model too large for the memory is refused before anything is allocated, at its
/// `[md.lattice]`, with the atoms, the estimate (200 + 156·ghosts + 8·pairs bytes per atom,
/// recomputed here from the lattice) and the limit; under the limit it runs. The limit is set
/// by PDYN_MEMORY_LIMIT here (MemAvailable otherwise). It died with "memory allocation of
/// 128000000 bytes failed" at 32 million atoms.
#[test]
fn a_model_larger_than_the_memory_is_refused_with_both_sizes() {
    use in_root::pdyn_env;
    for (kind, basis) in [("sc", 1u64), ("bcc", 2), ("fcc", 4)] {
        let cells = 30u64;
        let text = lj()
            .replace("kind = \"fcc\"", &format!("kind = \"{kind}\""))
            .replace("cells = \"n\"", &format!("cells = {cells}"));
        let d = scratch(&format!("mem-{kind}"));
        let f = d.join("m.toml");
        std::fs::write(&f, &text).unwrap();
        let args = [
            "run",
            f.to_str().unwrap(),
            "--json",
            "--t-end",
            "0.005",
            "--out",
            d.to_str().unwrap(),
        ];
        let (code, out, err) = pdyn_env(&args, &[("PDYN_MEMORY_LIMIT", "10M")]);
        assert_eq!(code, 2, "{kind}: {err}");
        let e = json(&out)["error"].clone();
        assert_eq!(e["location"]["line"], line_of(&text, "[md.lattice]"), "{e}");
        let atoms = basis * cells.pow(3);
        let msg = e["message"].as_str().unwrap();
        assert!(msg.contains(&format!("{atoms} atoms need about")), "{msg}");
        assert!(
            msg.contains("10.5 MB available (PDYN_MEMORY_LIMIT)"),
            "{msg}"
        );
        // bytes per atom, from the lattice: edge = cells·(basis/ρ)^(1/3), reach 2.5 + 0.3
        let edge = cells as f64 * libm::cbrt(basis as f64 / 0.8442);
        let ghosts = ((edge + 5.6) / edge).powi(3);
        let pairs = 2.0 * std::f64::consts::PI / 3.0 * 0.8442 * 2.8f64.powi(3);
        let per_atom = 200.0 + 156.0 * ghosts + 8.0 * pairs;
        assert!(
            msg.contains(&format!("({per_atom:.0} bytes per atom)")),
            "{msg}"
        );
        // Enough memory: it runs.
        let (code, _, err) = pdyn_env(&args, &[("PDYN_MEMORY_LIMIT", "4G")]);
        assert_eq!(code, 0, "{kind}: {err}");
    }
}

/// The thermo plot's axes carry the units of the model (`energy per atom [ε]`, `T [ε/k_B]`,
/// `P [ε/σ³]` in LJ units; kcal/mol, K, atm in real units): they were `energy / atom`, `T`, `P`.
#[test]
fn thermo_plot_axes_carry_the_units_of_the_model() {
    for (file, t_end, energy, temperature, pressure) in [
        ("examples/md/lj_liquid.toml", "0.05", "ε", "ε/k_B", "ε/σ³"),
        (
            "examples/md/argon_melting.toml",
            "200",
            "kcal/mol",
            "K",
            "atm",
        ),
    ] {
        let d = scratch(&format!("axes-{}", file.len()));
        let (code, _, err) = pdyn(&[
            "run",
            file,
            "--set",
            "n=4",
            "--t-end",
            t_end,
            "--out",
            d.to_str().unwrap(),
            "--plot",
        ]);
        assert_eq!(code, 0, "{file}: {err}");
        let svg = std::fs::read_to_string(d.join("thermo.svg"))
            .unwrap_or_else(|e| panic!("{file}: no thermo.svg ({e})"));
        for label in [
            format!("energy per atom [{energy}]"),
            format!("T [{temperature}]"),
            format!("P [{pressure}]"),
        ] {
            assert!(svg.contains(&label), "{file}: no `{label}`");
        }
    }
}
