//! A parameter defined by others (`m = "4/3*pi*a^3*rho"`) follows them when they change, on
//! every path a value arrives by: `--set` and a sweep. The nanoparticle of the chapter rises to
//! h = kB T/(m g) (energy: m v0²/2 = kB T), so h ∝ a⁻³ for a sphere of radius a.

use std::process::Command;

fn pdyn_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pdyn"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run pdyn");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const MODEL: &str = r#"
name = "nanoparticle"
gravity = "[0, 0, -g]"
[parameters]
g = 9.81
kB = 1.3806503e-23
T = "293 K"
a = "20 nm"
rho = "2330 kg/m^3"
m = "4/3*pi*a^3*rho"
[coordinates]
z = { initial = 0.0, rate = "sqrt(2*kB*T/m)" }
[particles.particle]
mass = "m"
position = "[0, 0, z]"
[[events]]
name = "apex"
when = "z'"
direction = "falling"
terminal = true
[simulate]
t_end = 1.0
rtol = 1e-10
atol = 1e-14
[sweep]
parameter = "a"
values = [1e-8, 2e-8, 4e-8]
[sweep.measures]
height = { of = "z", stat = "max" }
"#;

fn apex_height(a: f64) -> f64 {
    let m = 4.0 / 3.0 * std::f64::consts::PI * a.powi(3) * 2330.0;
    1.3806503e-23 * 293.0 / (m * 9.81)
}

/// A fresh directory holding `np.toml` (one per test: they run in parallel).
fn setup(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pdyn-derived-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("np.toml"), MODEL).unwrap();
    dir
}

#[test]
fn set_recomputes_a_derived_mass() {
    let dir = setup("set");
    for a in [1e-8, 4e-8] {
        let (code, out, err) = pdyn_in(
            &dir,
            &["run", "np.toml", "--set", &format!("a={a}"), "--json"],
        );
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let z = v["final"]["z"].as_f64().unwrap();
        let h = apex_height(a);
        assert!((z - h).abs() < 1e-6 * h, "a = {a}: z = {z}, expected {h}");
    }
}

#[test]
fn a_sweep_over_the_radius_recomputes_the_mass_of_every_run() {
    let dir = setup("sweep");
    let (code, out, err) = pdyn_in(&dir, &["sweep", "np.toml", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let heights = &v["slices"][0]["measures"][0]["values"];
    for (i, a) in [1e-8, 2e-8, 4e-8].into_iter().enumerate() {
        let z = heights[i].as_f64().unwrap_or(f64::NAN);
        let h = apex_height(a);
        assert!(
            (z - h).abs() < 1e-6 * h,
            "a = {a}: height {z}, expected {h}"
        );
    }
}
