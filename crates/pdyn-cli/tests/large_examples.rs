//! The models under `examples/large/` (thousands of particles, kept out of the every-example
//! tests): each runs for a short time and is checked against a closed form.

#[path = "common/in_root.rs"]
mod in_root;
use in_root::{json, pdyn, root};

/// Free fall from rest with linear drag `c` on a mass `m`: the height lost at `t`.
fn drag_fall(g: f64, m: f64, c: f64, t: f64) -> f64 {
    let tau = m / c;
    g * tau * (t - tau * (1.0 - libm::exp(-t / tau)))
}

/// The 100 × 100 cloth: 9,998 free particles (29,994 coordinates, each with its rate), and at
/// t = 0.01 s its far corner, a tenth of a metre from any node that feels the pins' pull, is
/// in free fall with drag (m = 0.05, c = 0.02, g = 9.81).
#[test]
fn the_100_by_100_cloth_sets_up_and_falls_freely_far_from_its_pins() {
    let (code, out, err) = pdyn(&[
        "run",
        "examples/large/cloth_100x100.toml",
        "--t-end",
        "0.01",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    assert_eq!(v["ok"], true, "{out:.2000}");
    let fin = v["final"].as_object().unwrap();
    let states = fin.keys().filter(|k| k.contains('[')).count();
    assert_eq!(states, 2 * 3 * (100 * 100 - 2));
    let z = fin["far_corner_z"].as_f64().unwrap();
    let want = -drag_fall(9.81, 0.05, 0.02, 0.01);
    assert!(
        (z - want).abs() <= 1e-6 * want.abs(),
        "z = {z}, closed form {want}"
    );
}

/// `pdyn derive` of the cloth is refused at once (it would lay out a 29,994² system and print
/// 105 MB), saying why and what to do, in text and in JSON.
#[test]
fn deriving_the_cloth_is_refused_at_once_with_what_to_do() {
    let (code, out, err) = pdyn(&["derive", "examples/large/cloth_100x100.toml"]);
    assert_eq!(code, 2, "{out:.500}");
    assert!(
        err.contains("29994 coordinates") && err.contains("smaller instance"),
        "{err}"
    );
    let (code, out, _) = pdyn(&["derive", "examples/large/cloth_100x100.toml", "--json"]);
    assert_eq!(code, 2);
    let v = json(&out);
    assert_eq!(v["error"]["kind"], "derivation");
    assert_eq!(
        v["error"]["location"]["file"],
        "examples/large/cloth_100x100.toml"
    );
}

/// Every model here is run by a test of this file (a new one needs its own).
#[test]
fn every_large_example_has_a_test() {
    let mut files: Vec<String> = std::fs::read_dir(root().join("examples/large"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".toml"))
        .collect();
    files.sort();
    let this = include_str!("large_examples.rs");
    for f in files {
        assert!(
            this.contains(&format!("examples/large/{f}")),
            "examples/large/{f} is run by no test in large_examples.rs"
        );
    }
}
