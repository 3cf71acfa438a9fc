//! `pdyn check` measures each state column's error against the size of the whole state (the
//! largest `max |exact|` of the columns of the same derivative order), and reports the
//! absolute error, the column's size, the scale and the relative error. A column at rest by
//! symmetry (a node of a mode) is round-off in both the numerical and the closed form: it was
//! compared with itself and reported a relative error of 1.0, hiding the real accuracy.

#[path = "common/in_root.rs"]
mod in_root;
use in_root::{json, pdyn};

/// `n` equal masses on springs between two walls (x_i measured from equilibrium), started in
/// the antisymmetric shape `x_i = a·(1 − 2i/(n−1))`-like: first +a, last −a, others 0 — the
/// middle mass of an odd chain is a node of every antisymmetric mode and stays at rest.
fn chain(n: usize, a: f64) -> String {
    let mut s = String::from("name = \"chain\"\n[parameters]\nk = 100.0\nm = 1.0\n[coordinates]\n");
    for i in 1..=n {
        let x0 = if i == 1 {
            a
        } else if i == n {
            -a
        } else {
            0.0
        };
        s += &format!("x{i} = {{ initial = {x0:?}, rate = 0.0 }}\n");
    }
    s += "[points]\nleft = \"[0, 0, 0]\"\nright = \"[0, 0, 0]\"\n";
    for i in 1..=n {
        s += &format!("[particles.p{i}]\nmass = \"m\"\nposition = \"[x{i}, 0, 0]\"\n");
    }
    let mut spring = |a: &str, b: &str, len: String| {
        s += &format!(
            "[[forces]]\nkind = \"spring\"\nbetween = [\"{a}\", \"{b}\"]\nk = \"k\"\nl0 = 0\nlength = \"{len}\"\n"
        );
    };
    spring("p1", "left", "x1".into());
    for i in 2..=n {
        spring(
            &format!("p{i}"),
            &format!("p{}", i - 1),
            format!("x{i} - x{}", i - 1),
        );
    }
    spring("right", &format!("p{n}"), format!("-x{n}"));
    s + "[simulate]\nt_end = 3.0\nmethod = \"dop853\"\nrtol = 1e-9\natol = 1e-12\n"
}

#[test]
fn a_column_at_rest_is_measured_against_the_whole_state() {
    let dir = std::env::temp_dir().join(format!("pdyn-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (n, a) in [(3usize, 0.1), (5, 0.1), (3, 2.0), (7, 1e-3)] {
        let path = dir.join(format!("chain{n}-{a}.toml"));
        std::fs::write(&path, chain(n, a)).unwrap();
        let (code, out, err) = pdyn(&["check", path.to_str().unwrap(), "--json"]);
        assert_eq!(code, 0, "{err}");
        let v = json(&out);
        let errors = v["errors"].as_array().unwrap();
        let get = |name: &str, key: &str| {
            errors
                .iter()
                .find(|e| e["name"] == name)
                .unwrap_or_else(|| panic!("{name} in {out}"))[key]
                .as_f64()
                .unwrap()
        };
        let mid = n / 2 + 1;
        let node = format!("x{mid}");
        // The node is at rest: its values are round-off of the size of the state.
        assert!(get(&node, "max_abs_value") < 1e-12 * a, "{out}");
        // The scale of a coordinate is the largest coordinate amplitude, `a` (the end masses
        // start at ±a, at rest, and nothing exceeds it in this mode), for every column.
        for i in 1..=n {
            let s = get(&format!("x{i}"), "scale");
            assert!((s - a).abs() <= 1e-9 * a, "x{i}: scale {s} vs {a}\n{out}");
        }
        // Relative = absolute / scale, for every column, rates against the largest rate.
        let rate_scale = (1..=n)
            .map(|i| get(&format!("x{i}'"), "max_abs_value"))
            .fold(0.0, f64::max);
        for i in 1..=n {
            for (c, s) in [(format!("x{i}"), a), (format!("x{i}'"), rate_scale)] {
                let want = get(&c, "max_abs_error") / s;
                let got = get(&c, "relative_error");
                assert!(
                    (got - want).abs() <= 1e-12 * want.max(1e-300),
                    "{c}: {got} vs {want}"
                );
            }
        }
        // The worst is the integrator's accuracy (rtol 1e-9), not the 1.0 of round-off over
        // round-off.
        let worst = v["max_relative_error"].as_f64().unwrap();
        assert!(worst < 1e-6, "n = {n}, a = {a}: {worst}\n{out}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
