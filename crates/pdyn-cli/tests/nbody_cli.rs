//! N-body models through the binary: every file in `examples/nbody` runs (shortened where it
//! would be slow in a debug build) and shows a property of its physics; every class of bad
//! input of issue 14 gives exit code 2 with `file:line:col` and a JSON error object; events
//! (close encounters, escapes, mergers) and warnings are reported.

use std::path::PathBuf;
use std::process::Command;

#[path = "common/in_root.rs"]
mod in_root;
use in_root::{json, pdyn, root};

/// `pdyn run FILE ARGS --json`, expecting success: the summary.
fn run_ok(file: &str, args: &[&str]) -> serde_json::Value {
    let mut a = vec!["run", file];
    a.extend_from_slice(args);
    a.push("--json");
    let (code, out, err) = pdyn(&a);
    assert_eq!(code, 0, "{a:?}: exit {code}\n{err}\n{out}");
    json(&out)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pdyn-nbody-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn final_state(sum: &serde_json::Value) -> Vec<[f64; 6]> {
    sum["final_state"]
        .as_array()
        .expect("final_state")
        .iter()
        .map(|b| {
            let g = |k: &str, i: usize| b[k][i].as_f64().unwrap();
            [
                g("position", 0),
                g("position", 1),
                g("position", 2),
                g("velocity", 0),
                g("velocity", 1),
                g("velocity", 2),
            ]
        })
        .collect()
}

/// Extra arguments that keep each example a few seconds in a debug build.
fn quick_args(file: &str) -> Vec<&'static str> {
    match file {
        "plummer_cluster.toml" => vec!["--set", "N=300", "--t-end", "0.05"],
        _ => vec![],
    }
}

#[test]
fn every_nbody_example_runs_and_conserves_energy_and_angular_momentum() {
    let mut files: Vec<String> = std::fs::read_dir(root().join("examples/nbody"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 5, "{files:?}");
    for f in &files {
        let path = format!("examples/nbody/{f}");
        let sum = run_ok(&path, &quick_args(f));
        assert_eq!(sum["ok"], true, "{f}");
        assert!(
            sum["warnings"].as_array().unwrap().is_empty(),
            "{f}: {}",
            sum["warnings"]
        );
        for m in sum["monitors"].as_array().unwrap() {
            assert_eq!(m["ok"], true, "{f}: {m}");
        }
        // The text report works too.
        let (code, out, err) = pdyn(&["run", &path]);
        assert_eq!(code, 0, "{f}: {err}");
        assert!(out.contains("conserved quantities"), "{f}: {out}");
    }
}

#[test]
fn figure_eight_returns_to_its_initial_state_after_one_period() {
    let sum = run_ok("examples/nbody/figure_eight.toml", &["--points", "2"]);
    assert_eq!(sum["integrator"], "ias15");
    let end = final_state(&sum);
    // The published initial state (Chenciner & Montgomery 2000, Simó's 8 digits).
    let (x1, y1, vx3, vy3) = (0.97000436, -0.24308753, -0.93240737, -0.86473146);
    let start = [
        [x1, y1, 0.0, -vx3 / 2.0, -vy3 / 2.0, 0.0],
        [-x1, -y1, 0.0, -vx3 / 2.0, -vy3 / 2.0, 0.0],
        [0.0, 0.0, 0.0, vx3, vy3, 0.0],
    ];
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in end.iter().zip(&start) {
        for k in 0..6 {
            num += (a[k] - b[k]).powi(2);
            den += b[k].powi(2);
        }
    }
    let rel = (num / den).sqrt();
    eprintln!("figure-eight through the CLI: relative state difference after one period {rel:.3e}");
    // 3.6e-8 is the limit of the 8 published digits of the state and the period (REBOUND's
    // IAS15 gives 3.586e-8 on the same data); the integrator's own error is ~1e-14.
    assert!(rel < 4e-8, "{rel:e}");
    assert!(sum["energy"]["relative_error"].as_f64().unwrap().abs() < 1e-14);
}

#[test]
fn outer_solar_system_energy_is_conserved_and_semi_major_axes_stay() {
    let dir = scratch("oss");
    let out = dir.to_str().unwrap();
    let sum = run_ok("examples/nbody/outer_solar_system.toml", &["--out", out]);
    let de = sum["energy"]["relative_error"].as_f64().unwrap();
    let drift = sum["monitors"][0]["drift"].as_f64().unwrap();
    eprintln!("outer Solar System, WHFast dt = P_J/20, corrector 11, 1000 yr: dE/E = {de:.3e}, drift {drift:.3e}");
    assert!(de.abs() < 1e-8, "{de:e}");
    assert_eq!(sum["stats"]["steps"], 1687);
    // Every other step (output_dt = P_J/10), and t_end.
    let outputs = sum["stats"]["outputs"].as_u64().unwrap();
    assert_eq!(outputs, 1 + 1686 / 2 + 1);
    // The osculating (Jacobi) semi-major axes oscillate with the planets' mutual perturbations
    // (the Great Inequality moves Saturn's by ~2e-3 over 1000 yr) but stay bounded.
    let csv = std::fs::read_to_string(dir.join("elements.csv")).unwrap();
    for (planet, bound) in [("Jupiter", 1e-3), ("Saturn", 3e-3)] {
        let a: Vec<f64> = csv
            .lines()
            .skip(1)
            .filter(|l| l.split(',').nth(1) == Some(planet))
            .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
            .collect();
        assert_eq!(a.len() as u64, outputs, "{planet}");
        let worst = a
            .iter()
            .map(|x| (x - a[0]).abs() / a[0])
            .fold(0.0, f64::max);
        eprintln!(
            "{planet}: a0 = {:.6}, largest relative change {worst:.2e}",
            a[0]
        );
        assert!(worst < bound && worst > 0.0, "{planet}: {worst:e}");
    }
    let traj = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    assert_eq!(traj.lines().count() as u64, 1 + outputs * 5);
    assert!(dir.join("conservation.csv").exists() && dir.join("summary.json").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_cli_agrees_with_the_library_on_the_outer_solar_system() {
    // pdyn_gravity's own copy of the same initial conditions, integrated directly.
    let mut sim = pdyn_gravity::systems::outer_solar_system();
    sim.set_integrator(pdyn_gravity::Integrator::WhFast(
        pdyn_gravity::WhFastParams {
            corrector: 11,
            ..Default::default()
        },
    ))
    .unwrap();
    sim.set_dt(4332.59 / 20.0).unwrap();
    sim.integrate(365250.0).unwrap();
    let sum = run_ok("examples/nbody/outer_solar_system.toml", &["--points", "2"]);
    let end = final_state(&sum);
    let p = sim.particles();
    for (i, b) in end.iter().enumerate() {
        let r = p.pos(i).0;
        let d = ((b[0] - r[0]).powi(2) + (b[1] - r[1]).powi(2) + (b[2] - r[2]).powi(2)).sqrt();
        assert!(d < 1e-9 * (1.0 + p.pos(i).norm()), "body {i}: {d:e}");
    }
}

#[test]
fn whfast_agrees_with_ias15_on_the_outer_solar_system() {
    let w = final_state(&run_ok(
        "examples/nbody/outer_solar_system.toml",
        &["--points", "2"],
    ));
    let i = final_state(&run_ok(
        "examples/nbody/outer_solar_system.toml",
        &["--points", "2", "--method", "ias15"],
    ));
    for (k, (a, b)) in w.iter().zip(&i).enumerate().skip(1) {
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        let r = (b[0].powi(2) + b[1].powi(2) + b[2].powi(2)).sqrt();
        eprintln!("planet {k}: WHFast (dt = P_J/20, corrector 11) vs IAS15 after 1000 yr: {:.2e} relative", d / r);
        assert!(d / r < 1e-5, "planet {k}: {:e}", d / r);
    }
}

#[test]
fn bodies_from_csv_give_the_same_run_as_bodies_in_the_table() {
    let a = final_state(&run_ok(
        "examples/nbody/outer_solar_system.toml",
        &["--points", "2"],
    ));
    let b = final_state(&run_ok(
        "examples/nbody/outer_solar_system_csv.toml",
        &["--points", "2"],
    ));
    assert_eq!(a.len(), 5);
    for (x, y) in a.iter().zip(&b) {
        for k in 0..6 {
            assert!(
                (x[k] - y[k]).abs() <= 1e-12 * x[k].abs().max(1e-6),
                "{x:?} vs {y:?}"
            );
        }
    }
}

#[test]
fn the_trojan_librates_about_l4() {
    let dir = scratch("trojan");
    let sum = run_ok(
        "examples/nbody/sun_jupiter_trojan.toml",
        &["--out", dir.to_str().unwrap()],
    );
    assert!(
        sum["events"].as_array().unwrap().is_empty(),
        "{}",
        sum["events"]
    );
    let csv = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for chunk in rows.chunks(3) {
        let xy = |r: &Vec<String>| (r[2].parse::<f64>().unwrap(), r[3].parse::<f64>().unwrap());
        let (sx, sy) = xy(&chunk[0]);
        let (jx, jy) = xy(&chunk[1]);
        let (tx, ty) = xy(&chunk[2]);
        let ang = (libm::atan2(ty - sy, tx - sx) - libm::atan2(jy - sy, jx - sx))
            .rem_euclid(std::f64::consts::TAU);
        lo = lo.min(ang.to_degrees());
        hi = hi.max(ang.to_degrees());
    }
    eprintln!("Trojan: angle ahead of Jupiter between {lo:.1} and {hi:.1} degrees");
    assert!(
        lo > 30.0 && hi < 100.0 && lo < 60.0 && hi > 60.0,
        "{lo} {hi}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_plummer_sphere_stays_in_virial_equilibrium_and_writes_no_trajectories() {
    let dir = scratch("plummer");
    let sum = run_ok(
        "examples/nbody/plummer_cluster.toml",
        &[
            "--set",
            "N=400",
            "--t-end",
            "0.1",
            "--points",
            "6",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(sum["bodies"]["initial"], 400);
    let q = sum["virial_ratio"].as_f64().unwrap();
    assert!((0.8..1.2).contains(&q), "{q}");
    // Hénon units: E = -1/4 up to the sampling noise of 400 stars and the softening.
    let e0 = sum["energy"]["initial"].as_f64().unwrap();
    assert!((e0 + 0.25).abs() < 0.03, "{e0}");
    assert!(sum["energy"]["relative_error"].as_f64().unwrap().abs() < 1e-3);
    assert!(!dir.join("trajectory.csv").exists());
    let cons = std::fs::read_to_string(dir.join("conservation.csv")).unwrap();
    assert_eq!(cons.lines().count(), 1 + 6);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn plots_are_written() {
    let dir = scratch("plots");
    let (code, _, err) = pdyn(&[
        "run",
        "examples/nbody/figure_eight.toml",
        "--out",
        dir.to_str().unwrap(),
        "--plot",
    ]);
    assert_eq!(code, 0, "{err}");
    for f in [
        "orbits.svg",
        "orbits.png",
        "elements.svg",
        "conservation.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    assert!(
        !dir.join("orbits_3d.svg").exists(),
        "the figure-eight is planar"
    );
    std::fs::remove_dir_all(&dir).ok();
}

const SUN: &str =
    "[[nbody.bodies]]\nname = \"Sun\"\nmass = 1\nposition = [0, 0, 0]\nvelocity = [0, 0, 0]\n";

/// A model with the given `[nbody]` settings and bodies after the Sun.
fn model(settings: &str, bodies: &str) -> String {
    format!("name = \"test\"\n[nbody]\nunits = \"au-year-msun\"\nintegrator = \"whfast\"\ndt = 0.01\nt_end = 1\n{settings}\n{SUN}{bodies}")
}

fn planet(extra: &str) -> String {
    format!("[[nbody.bodies]]\nname = \"P\"\n{extra}\n")
}

#[test]
fn bad_input_is_exit_2_with_file_line_column_and_a_json_error() {
    let dir = scratch("bad");
    let elements = |s: &str| planet(&format!("mass = 1e-3\nprimary = \"Sun\"\n{s}"));
    // (model text, the text the error must point at, a word of the message)
    let cases: Vec<(String, &str, &str)> = vec![
        (
            model(
                "",
                &planet("mass = -1e-3\nposition = [1, 0, 0]\nvelocity = [0, 6, 0]"),
            ),
            "-1e-3",
            "mass must be > 0",
        ),
        (
            model(
                "",
                &planet("mass = 0\nposition = [1, 0, 0]\nvelocity = [0, 6, 0]"),
            ),
            "0",
            "mass must be > 0",
        ),
        (
            model(
                "",
                &planet("mass = 1e-3\nposition = [0, 0, 0]\nvelocity = [0, 6, 0]"),
            ),
            "[[nbody.bodies]]\nname = \"P\"",
            "placed exactly on body `Sun`",
        ),
        (
            model("", &elements("a = 1\ne = -0.1")),
            "-0.1",
            "eccentricity must be >= 0",
        ),
        (
            model("", &elements("a = -1\ne = 0.5")),
            "-1",
            "a bound orbit needs a > 0",
        ),
        (
            model("", &elements("a = 0\ne = 0.5")),
            "0",
            "a bound orbit needs a > 0",
        ),
        (
            model("", &planet("mass = 1e-3\nprimary = \"Sunn\"\na = 1")),
            "\"Sunn\"",
            "unknown primary",
        ),
        (
            model("", &planet("mass = 1e-3\nprimary = \"Jupiter\"\na = 1")),
            "\"Jupiter\"",
            "unknown primary",
        ),
        (
            model(
                "",
                &planet("mass = 1e-3\nposition = [1, 0, 0]\nvelocity = [0, 6, 0]"),
            )
            .replace("dt = 0.01", "dt = 0"),
            "0",
            "dt must be > 0",
        ),
        (
            model(
                "",
                &planet("mass = 1e-3\nposition = [1, 0, 0]\nvelocity = [0, 6, 0]"),
            )
            .replace("dt = 0.01", "dt = -0.5"),
            "-0.5",
            "dt must be > 0",
        ),
        (
            model("", &elements("a = \"5 km\"")),
            "\"5 km\"",
            "unit literals convert to SI",
        ),
        (
            model("", &planet("mass = 1e-3\nposition = [1, 0, 0]")),
            "[[nbody.bodies]]\nname = \"P\"",
            "needs both position and velocity",
        ),
        (
            model("", &elements("a = \"2*b\"")),
            "b",
            "undefined name `b`",
        ),
        (
            model("", "").replace("whfast", "rk45"),
            "\"rk45\"",
            "unknown integrator",
        ),
        (model("colour = 1", ""), "colour", "unknown field"),
        (
            model(
                "",
                &planet("mass = 1e-3\nposition = [1, 0, 0]\nvelocity = [0, 6, 0]"),
            )
            .replace("dt = 0.01", "dt = 1e-300"),
            "1e-300",
            "far too small",
        ),
    ];
    for (k, (text, at, words)) in cases.iter().enumerate() {
        let path = dir.join(format!("bad{k}.toml"));
        std::fs::write(&path, text).unwrap();
        let p = path.to_str().unwrap();
        let (code, out, err) = pdyn(&["run", p, "--json"]);
        assert_eq!(code, 2, "case {k}: exit {code}\n{err}\n{text}");
        let e = &json(&out)["error"];
        assert_eq!(e["kind"], "model", "case {k}: {e}");
        assert_eq!(e["exit_code"], 2);
        assert!(
            e["message"].as_str().unwrap().contains(words),
            "case {k}: {e}"
        );
        // The location is where `at` is written (the last occurrence before the error's body
        // is good enough: each case's text appears at the offending place).
        let line = e["location"]["line"].as_u64().unwrap() as usize;
        let col = e["location"]["column"].as_u64().unwrap() as usize;
        let offset: usize = text
            .split_inclusive('\n')
            .take(line - 1)
            .map(str::len)
            .sum::<usize>()
            + col
            - 1;
        assert!(
            text[offset..].starts_with(at),
            "case {k}: points at {:?}, expected {at:?}\n{err}",
            &text[offset..(offset + 20).min(text.len())]
        );
        assert!(
            err.starts_with(&format!("{p}:{line}:{col}: error")),
            "case {k}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_cells_of_a_bodies_file_are_located_in_that_file() {
    let dir = scratch("csv");
    std::fs::write(
        dir.join("bodies.csv"),
        "name,mass,primary,a,e\nP,1e-3,,1,0\n",
    )
    .unwrap();
    let toml = "name = \"csv\"\n[nbody]\nt_end = 1\nbodies_file = \"bodies.csv\"\n";
    let path = dir.join("m.toml");
    std::fs::write(&path, toml).unwrap();
    let (code, out, err) = pdyn(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("orbital elements need a body before it"),
        "{err}"
    );
    std::fs::write(
        dir.join("bodies.csv"),
        "name,mass,x,y,z,vx,vy,vz\nSun,1,0,0,0,0,0,0\nP,1e-3,1,0,0,0,1,zero\n",
    )
    .unwrap();
    let (code, out2, err) = pdyn(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    let e = &json(&out2)["error"];
    let csv = dir.join("bodies.csv");
    assert_eq!(e["location"]["file"], csv.to_str().unwrap(), "{e}");
    assert_eq!(
        (
            e["location"]["line"].as_u64(),
            e["location"]["column"].as_u64()
        ),
        (Some(3), Some(18)),
        "{e}"
    );
    assert!(err.contains("`zero` is not a number"), "{err}");
    let _ = out;
    // Cartesian and element lines in one file: elements about a named primary (declared in
    // the model file), angles in degrees.
    std::fs::write(
        dir.join("bodies.csv"),
        "name,mass,x,y,z,vx,vy,vz,primary,a,e,inc,Omega,omega,f\n\
         Moon,1e-9,2,0,0,0,4,0,,,,,,,\n\
         P,1e-3,,,,,,,Sun,1,0.1,5 deg,0,0,0\n",
    )
    .unwrap();
    let both = "name = \"csv\"\n[nbody]\nt_end = 1\nbodies_file = \"bodies.csv\"\ncenter_of_mass = false\n[[nbody.bodies]]\nname = \"Sun\"\nmass = 1\nposition = [0, 0, 0]\nvelocity = [0, 0, 0]\n";
    std::fs::write(&path, both).unwrap();
    let sum = run_ok(
        path.to_str().unwrap(),
        &["--points", "2", "--out", dir.to_str().unwrap()],
    );
    assert_eq!(sum["bodies"]["initial"], 3);
    let el = std::fs::read_to_string(dir.join("elements.csv")).unwrap();
    let first: Vec<f64> = el
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .skip(2)
        .take(3)
        .map(|x| x.parse().unwrap())
        .collect();
    assert!(
        (first[0] - 1.0).abs() < 1e-12 && (first[1] - 0.1).abs() < 1e-12,
        "{first:?}"
    );
    assert!((first[2] - 5f64.to_radians()).abs() < 1e-12, "{first:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn options_that_do_not_apply_are_refused_by_name() {
    for (args, option) in [
        (vec!["--rtol", "1e-9"], "--rtol"),
        (vec!["--max-steps", "10"], "--max-steps"),
        (vec!["--dt", "0"], "--dt"),
        (vec!["--dt", "-1"], "--dt"),
        (vec!["--method", "dopri5"], "--method"),
        (vec!["--set", "nope=1"], "--set"),
        (vec!["--plot"], "--plot"),
    ] {
        let mut a = vec!["run", "examples/nbody/figure_eight.toml", "--json"];
        a.extend_from_slice(&args);
        let (code, out, err) = pdyn(&a);
        assert_eq!(code, 2, "{args:?}: {err}");
        let e = &json(&out)["error"];
        assert_eq!(e["kind"], "argument", "{args:?}: {e}");
        assert_eq!(e["location"]["file"], option, "{args:?}: {e}");
        assert!(err.contains(option), "{args:?}: {err}");
    }
    // --t-eval: outputs at exactly these times (IAS15 lands on each).
    let sum = run_ok(
        "examples/nbody/figure_eight.toml",
        &["--t-eval", "0,0.5,1.25"],
    );
    assert_eq!(sum["stats"]["outputs"], 3);
    assert_eq!(sum["t_reached"], 1.25);
    // --set and --method do what they say.
    let sum = run_ok(
        "examples/nbody/figure_eight.toml",
        &["--set", "T=1", "--method", "leapfrog", "--dt", "0.001"],
    );
    assert_eq!(sum["t_reached"], 1.0);
    assert_eq!(sum["integrator"], "leapfrog");
    let (code, out, _) = pdyn(&[
        "run",
        "examples/nbody/figure_eight.toml",
        "--method",
        "help",
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("Rein & Tamayo"), "{out}");
}

#[test]
fn derive_and_other_symbolic_commands_refuse_an_nbody_model_clearly() {
    for cmd in ["derive", "forces", "check", "sweep"] {
        let (code, out, err) = pdyn(&[cmd, "examples/nbody/figure_eight.toml", "--json"]);
        assert_eq!(code, 2, "{cmd}: {err}");
        assert!(err.contains("N-body model: use `pdyn run`"), "{cmd}: {err}");
        assert_eq!(json(&out)["error"]["location"]["line"], 18, "{cmd}");
    }
}

#[test]
fn a_long_whfast_step_is_a_warning() {
    let dir = scratch("long");
    let path = dir.join("m.toml");
    // P = 1 year at 1 AU; dt = 0.3 yr is far beyond a twentieth of it.
    let text = model("", &planet("mass = 1e-3\nprimary = \"Sun\"\na = 1"))
        .replace("dt = 0.01", "dt = 0.3");
    std::fs::write(&path, text).unwrap();
    let (code, out, err) = pdyn(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: WHFast step 0.3 is long compared with the period"),
        "{err}"
    );
    assert!(json(&out)["warnings"][0]
        .as_str()
        .unwrap()
        .contains("use IAS15"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_close_encounter_stops_whfast_with_an_event_suggesting_ias15() {
    let dir = scratch("close");
    let path = dir.join("m.toml");
    let two = "[[nbody.bodies]]\nname = \"A\"\nmass = 1e-3\nprimary = \"Sun\"\na = 1\n\
               [[nbody.bodies]]\nname = \"B\"\nmass = 1e-3\nposition = [1.01, 0, 0]\nvelocity = [0, 6.28, 0]\n";
    std::fs::write(&path, model("", two)).unwrap();
    let (code, out, err) = pdyn(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(code, 1, "{err}");
    let sum = json(&out);
    assert_eq!(sum["ok"], false);
    assert_eq!(sum["error"]["kind"], "gravity");
    assert_eq!(sum["error"]["exit_code"], 1);
    let ev = &sum["events"][0];
    assert_eq!(ev["kind"], "close_encounter", "{sum}");
    assert!(
        ev["message"].as_str().unwrap().contains("switch to IAS15"),
        "{ev}"
    );
    // The same system with IAS15 runs through.
    let ok = run_ok(path.to_str().unwrap(), &["--method", "ias15"]);
    assert_eq!(ok["t_reached"], 1.0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_escape_is_an_event_that_stops_or_removes() {
    let dir = scratch("escape");
    let path = dir.join("m.toml");
    let comet =
        "[[nbody.bodies]]\nname = \"comet\"\nmass = 1e-9\nprimary = \"Sun\"\na = -1\ne = 1.5\n";
    std::fs::write(
        &path,
        model("escape_radius = 5\nintegrator = \"ias15\"", comet)
            .replace("integrator = \"whfast\"\n", "")
            .replace("t_end = 1", "t_end = 10"),
    )
    .unwrap();
    let sum = run_ok(path.to_str().unwrap(), &[]);
    assert_eq!(sum["events"][0]["kind"], "escape", "{sum}");
    let t = sum["t_reached"].as_f64().unwrap();
    assert!(t > 0.0 && t < 10.0, "{t}");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "escape_radius = 5",
        "escape_radius = 5\nescape = \"remove\"",
    );
    std::fs::write(&path, text).unwrap();
    let sum = run_ok(path.to_str().unwrap(), &[]);
    assert_eq!(sum["events"][0]["kind"], "removal");
    assert_eq!(sum["t_reached"], 10.0);
    assert_eq!(sum["bodies"]["final"], 1);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn colliding_bodies_stop_or_merge_conserving_momentum() {
    let dir = scratch("merge");
    let path = dir.join("m.toml");
    // Two bodies falling towards each other head-on.
    let pair = "[[nbody.bodies]]\nname = \"A\"\nmass = 1e-3\nradius = 0.01\nposition = [1, 0, 0]\nvelocity = [-1, 0, 0]\n\
                [[nbody.bodies]]\nname = \"B\"\nmass = 2e-3\nradius = 0.01\nposition = [-1, 0, 0]\nvelocity = [1, 0, 0]\n";
    let text = model("integrator = \"ias15\"", pair)
        .replace("integrator = \"whfast\"\n", "")
        .replace(
            "[[nbody.bodies]]\nname = \"Sun\"\nmass = 1\n",
            "[[nbody.bodies]]\nname = \"Sun\"\nmass = 1\nradius = 0.1\n",
        );
    std::fs::write(&path, &text).unwrap();
    let sum = run_ok(path.to_str().unwrap(), &[]);
    assert_eq!(sum["events"][0]["kind"], "collision", "{sum}");
    std::fs::write(
        &path,
        text.replace(
            "integrator = \"ias15\"",
            "integrator = \"ias15\"\ncollisions = \"merge\"",
        ),
    )
    .unwrap();
    let sum = run_ok(path.to_str().unwrap(), &[]);
    let kinds: Vec<&str> = sum["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.iter().all(|k| *k == "merger") && !kinds.is_empty(),
        "{kinds:?}"
    );
    assert_eq!(
        sum["bodies"]["final"].as_u64().unwrap() as usize,
        3 - kinds.len()
    );
    assert_eq!(sum["t_reached"], 1.0);
    // Mass and momentum are conserved through the mergers (the frame is the centre of
    // mass: the total momentum stays zero).
    let (mut m, mut p) = (0.0, [0.0; 3]);
    for b in sum["final_state"].as_array().unwrap() {
        let mb = b["mass"].as_f64().unwrap();
        m += mb;
        for k in 0..3 {
            p[k] += mb * b["velocity"][k].as_f64().unwrap();
        }
    }
    assert!((m - 1.003).abs() < 1e-15, "{m}");
    assert!(p.iter().all(|x| x.abs() < 1e-15), "{p:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[path = "common/toml_values.rs"]
mod toml_values;

/// Every N-body example with one value replaced by a hostile one (as `mutations.rs` does for
/// the mechanics examples): exit 0, 1 or 2, never a panic (exit 3) or a hang.
#[test]
fn mutated_nbody_examples_never_panic_or_hang() {
    const HOSTILE: &[&str] = &[
        "0",
        "-1",
        "1e308",
        "-1e-308",
        "\"nan\"",
        "\"1/0\"",
        "\"\"",
        "\"((((x\"",
        "\"[1, 2, 3]\"",
        "\"1e400\"",
        "\"2^100000\"",
        "\"sqrt(-1)\"",
        "\"t\"",
        "[]",
        "{}",
        "true",
        "\"150 knot\"",
        "[1, 2]",
        "[\"nan\", 0, 0]",
        "\"Sun\"",
        "1.0000001",
    ];
    let dir = scratch("mutations");
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("examples/nbody"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed as usize
    };
    let mut failures = Vec::new();
    for f in &files {
        let src = std::fs::read_to_string(f).unwrap();
        let spans = toml_values::value_spans(&src);
        assert!(!spans.is_empty());
        // The CSV example reads its bodies relative to the model file.
        std::fs::copy(
            root().join("examples/nbody/outer_solar_system.csv"),
            dir.join("outer_solar_system.csv"),
        )
        .unwrap();
        for k in 0..25 {
            let (s, e) = spans[next() % spans.len()];
            let hostile = HOSTILE[next() % HOSTILE.len()];
            let mutated = format!("{}{}{}", &src[..s], hostile, &src[e..]);
            let path = dir.join(format!("m{k}.toml"));
            std::fs::write(&path, &mutated).unwrap();
            let p = path.to_str().unwrap();
            let mut args = vec!["run", p, "--json", "--points", "3"];
            if f.ends_with("plummer_cluster.toml") {
                args.extend(["--set", "N=50", "--t-end", "0.02"]);
            } else {
                // A few steps of each integrator (IAS15 adapts; the others take dt).
                args.extend(["--t-end", "2"]);
            }
            let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
                .args(&args)
                .output()
                .expect("run pdyn");
            let code = out.status.code();
            if !matches!(code, Some(0..=2)) {
                failures.push(format!(
                    "{} with `{}` -> `{hostile}`: exit {code:?}\n{}",
                    f.display(),
                    &src[s..e],
                    String::from_utf8_lossy(&out.stderr)
                ));
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every `[nbody]` Plummer sphere starts in standard Hénon units, whatever the seed: with
/// `softening = 0` the initial energy the run reports is `−G mass²/(4 scale)` to round-off
/// (it was −0.264 on average over 24 seeds of 1,000 stars, never −1/4), and the virial ratio
/// after one tiny step is 1; `rescale = false` keeps the sample as drawn; a bad `rescale` is a
/// located error.
#[test]
fn plummer_spheres_start_in_standard_henon_units() {
    let dir = scratch("plummer-units");
    let model = |seed: u64, extra: &str| {
        format!(
            "name = \"p\"\n[nbody]\nunits = \"nbody\"\nplummer = {{ n = 300, seed = {seed}{extra} }}\n\
             integrator = \"leapfrog\"\ndt = 1e-6\nt_end = 1e-6\npoints = 2\n"
        )
    };
    let run = |text: String, name: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let out = dir.join(format!("{name}-out"));
        run_ok(path.to_str().unwrap(), &["--out", out.to_str().unwrap()])
    };
    let mut natural = Vec::new();
    for seed in 1..=6 {
        for (extra, e_want) in [("", -0.25), (", mass = 2, scale = 3", -1.0 / 3.0)] {
            let sum = run(model(seed, extra), &format!("s{seed}.toml"));
            let e0 = sum["energy"]["initial"].as_f64().unwrap();
            assert!((e0 - e_want).abs() < 1e-12, "seed {seed}{extra}: E = {e0}");
            let q = sum["virial_ratio"].as_f64().unwrap();
            assert!((q - 1.0).abs() < 1e-6, "seed {seed}{extra}: 2T/|W| = {q}");
        }
        let sum = run(model(seed, ", rescale = false"), &format!("n{seed}.toml"));
        natural.push(sum["energy"]["initial"].as_f64().unwrap());
    }
    assert!(
        natural.iter().all(|e| (e + 0.25).abs() > 1e-6),
        "{natural:?}"
    );
    let path = dir.join("bad.toml");
    std::fs::write(&path, model(1, ", rescale = \"yes\"")).unwrap();
    let (code, out, err) = pdyn(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(json(&out)["error"]["location"]["line"], 4, "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Mutations of the figure-eight that IAS15 cannot follow (`vx3` = 10¹⁶ … 10³⁰⁰) end with
/// exit 1, the time, the partial output and what to do; `vx3 = 1e20` ran for more than a
/// minute without a word.
#[test]
fn an_ias15_run_that_cannot_advance_ends_with_a_clear_error() {
    for v in ["1e16", "1e20", "1e300"] {
        let dir = scratch(&format!("collapse-{v}"));
        let (code, out, err) = pdyn(&[
            "run",
            "examples/nbody/figure_eight.toml",
            "--set",
            &format!("vx3={v}"),
            "--t-end",
            "0.01",
            "--out",
            dir.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(code, 1, "vx3 = {v}: {err}");
        assert!(
            err.contains("step size fell to") && err.contains("check the initial state"),
            "{err}"
        );
        let sum = json(&out);
        let t = sum["t_reached"].as_f64().unwrap();
        assert!(t < 0.01, "{t}");
        assert!(dir.join("summary.json").exists());
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// Every plot's axes carry the units of the model's unit system (they were bare `t`, `x`,
/// `a`): `t [yr]`, `x [AU]`, `a [AU]` in au-year-msun, `t [days]` in au-day-msun, `t [s]`
/// and `x [m]` in SI, the model's own units in N-body units.
#[test]
fn plot_axes_carry_the_units_of_the_model() {
    for (units, length, time, scale) in [
        ("au-year-msun", "AU", "yr", "1"),
        ("au-day-msun", "AU", "days", "365.25"),
        ("si", "m", "s", "3.15576e7"),
        ("nbody", "N-body length", "N-body time", "1"),
    ] {
        let dir = scratch(&format!("units-{units}"));
        let path = dir.join("m.toml");
        // A planet on a circle about a star, in whatever units: a 2-body problem.
        let text = format!(
            "name = \"units\"\n[parameters]\nS = {scale}\n[nbody]\nunits = \"{units}\"\n\
             integrator = \"ias15\"\nt_end = \"S/10\"\npoints = 5\n\
             [[nbody.bodies]]\nname = \"Star\"\nmass = 1\nposition = [0, 0, 0]\nvelocity = [0, 0, 0]\n\
             [[nbody.bodies]]\nname = \"P\"\nmass = 1e-3\nprimary = \"Star\"\na = 1\ne = 0.1\n"
        )
        .replace(
            "mass = 1\nposition",
            if units == "si" {
                "mass = 2e30\nposition"
            } else {
                "mass = 1\nposition"
            },
        )
        .replace(
            "mass = 1e-3\nprimary = \"Star\"\na = 1\n",
            if units == "si" {
                "mass = 2e27\nprimary = \"Star\"\na = 1.5e11\n"
            } else {
                "mass = 1e-3\nprimary = \"Star\"\na = 1\n"
            },
        );
        std::fs::write(&path, text).unwrap();
        let out = dir.join("out");
        let (code, _, err) = pdyn(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--plot",
        ]);
        assert_eq!(code, 0, "{units}: {err}");
        let svg = |f: &str| std::fs::read_to_string(out.join(f)).unwrap();
        let (t, x, a) = (
            format!("t [{time}]"),
            format!("x [{length}]"),
            format!("a [{length}]"),
        );
        assert!(svg("orbits.svg").contains(&x), "{units}: orbits");
        assert!(
            svg("elements.svg").contains(&t) && svg("elements.svg").contains(&a),
            "{units}"
        );
        assert!(
            svg("conservation.svg").contains(&t),
            "{units}: conservation"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// The fixed-step limit is the one of every fixed-step run (`sim::MAX_FIXED_STEPS`, 1e10):
/// the N-body command line had its own, 1e11 (issue 25). 2e10 WHFast steps are refused,
/// naming `--dt`, before anything is built.
#[test]
fn the_fixed_step_limit_is_shared_with_mechanics() {
    let (code, out, err) = pdyn(&[
        "run",
        "examples/nbody/outer_solar_system.toml",
        "--t-end",
        "10",
        "--dt",
        "5e-10",
        "--json",
    ]);
    assert_eq!(code, 2, "{err}");
    let e = &json(&out)["error"];
    let msg = e["message"].as_str().unwrap();
    assert!(
        msg.contains("--dt") && msg.contains("more than 1e10"),
        "{msg}"
    );
}
