//! What `pdyn derive` prints (issue 12, "readable equations"):
//! - the printed `M[j,k]`, `f[j]` and explicit solutions parse back, in the model's scope, to
//!   expressions equal to the derivation's at random points (a printer that dropped a term,
//!   a sign or a parenthesis fails here);
//! - no line of its text or LaTeX output is longer than `PRINT_CHARS`, on every shipped
//!   example and on the n-link chain up to n = 100.

#[path = "../../pdyn-mech/tests/common/chain.rs"]
mod chain;
#[path = "common/in_root.rs"]
mod in_root;

use in_root::{pdyn, root};
use pdyn_expr::budget::PRINT_CHARS;
use pdyn_expr::{FreeScope, Id, Node, Pool, Program};
use std::path::{Path, PathBuf};

/// The mechanics examples (`examples/*.toml`; the `[nbody]` and `[md]` ones live in
/// subdirectories and are refused by `pdyn derive`).
fn examples() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 10, "{v:?}");
    v
}

/// The n-link chain's model file, written once per process.
fn chain_file(n: usize) -> PathBuf {
    let path = std::env::temp_dir().join(format!(
        "pdyn-derive-print-chain{n}-{}.toml",
        std::process::id()
    ));
    std::fs::write(&path, chain::chain_toml(n)).unwrap();
    path
}

/// `pdyn derive FILE EXTRA...`: its stdout when it succeeds, `Err(stderr)` when it refuses
/// the model (exit code 2).
fn derive_output(file: &Path, extra: &[&str]) -> Result<String, String> {
    let file_arg = file.to_string_lossy();
    let mut args = vec!["derive", &file_arg];
    args.extend(extra);
    match pdyn(&args) {
        (0, stdout, _) => Ok(stdout),
        (2, _, stderr) => Err(stderr),
        (code, _, stderr) => panic!("{}: exit {code}: {stderr}", file.display()),
    }
}

fn assert_lines_within_budget(file: &Path, extra: &[&str]) {
    // A refusal's message is held to the same budget.
    let text = derive_output(file, extra).unwrap_or_else(|e| e);
    for (i, line) in text.lines().enumerate() {
        let n = line.chars().count();
        // The last-resort clipping of `pdyn::derivation::bounded` would hide an expression printed
        // whole: it must never be needed.
        assert!(
            !line.contains("⟨line clipped"),
            "{} {extra:?}, line {} was clipped",
            file.display(),
            i + 1
        );
        assert!(
            n <= PRINT_CHARS,
            "{} {extra:?}, line {}: {n} characters (budget {PRINT_CHARS}): {}…",
            file.display(),
            i + 1,
            line.chars().take(200).collect::<String>()
        );
    }
}

/// `a` and `b` agree at three random points (every symbol, coordinate, rate and `t` drawn in
/// [0.3, 1.3]), relatively to 1e-9.
fn assert_equal_at_random_points(p: &mut Pool, a: Id, b: Id, what: &str) {
    let mut leaves: Vec<Id> = p
        .topo_order(&[a, b])
        .into_iter()
        .filter(|&x| matches!(p.node(x), Node::Sym(_) | Node::Coord(..) | Node::Time))
        .collect();
    leaves.sort();
    leaves.dedup();
    let prog = Program::compile(p, &leaves, &[a, b]).unwrap();
    let mut ws = prog.workspace();
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d ^ (a.index() as u64) << 20 ^ b.index() as u64;
    for _ in 0..3 {
        let x: Vec<f64> = leaves
            .iter()
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                0.3 + (seed % 10_000) as f64 / 10_000.0
            })
            .collect();
        let mut out = [0.0; 2];
        prog.eval(&x, &mut ws, &mut out);
        let tol = 1e-9 * out[0].abs().max(out[1].abs()).max(1.0);
        assert!(
            (out[0] - out[1]).abs() <= tol,
            "{what}: printed {} vs derived {}",
            out[1],
            out[0]
        );
    }
}

/// Parses the printed expression `text` in the model's scope (its coordinates are functions
/// of time: `q1`, `q1'`, `q1''`).
fn parse(p: &mut Pool, coords: &[String], text: &str, what: &str) -> Id {
    let mut scope = FreeScope::with_coordinates(coords.iter().map(String::as_str));
    p.parse_in(text, &mut scope)
        .unwrap_or_else(|e| panic!("{what}: `{text}` does not parse: {e:?}"))
        .scalar()
        .unwrap()
}

/// Checks every `M[j,k] = …`, `f[j] = …` and explicit `x = …` under "Solved:" that `pdyn
/// derive` prints for `file` against the library's derivation. Returns how many were checked.
fn round_trip(file: &Path) -> usize {
    let Ok(text) = derive_output(file, &[]) else {
        return 0;
    };
    let mut model = pdyn_mech::load_file(file).unwrap();
    let d = pdyn_mech::derive(&mut model, &pdyn_mech::DeriveOptions::default()).unwrap();
    let coords: Vec<String> = model.coordinates.iter().map(|c| c.name.clone()).collect();
    let p = &mut model.pool;
    let mut checked = 0;
    let mut in_solved = false;
    for line in text.lines() {
        if line.starts_with("Solved:") {
            in_solved = true;
            continue;
        }
        if !line.starts_with("  ") {
            in_solved = false;
        }
        let Some((lhs, rhs)) = line.trim().split_once(" = ") else {
            continue;
        };
        if rhs.contains('⟨') || rhs.contains('⁻') {
            continue; // over the budget, or by reference: nothing to parse
        }
        let what = format!("{}: {lhs}", file.display());
        let derived = if let Some(jk) = lhs.strip_prefix("M[").and_then(|s| s.strip_suffix(']')) {
            let (j, k) = jk.split_once(',').unwrap();
            let (j, k): (usize, usize) = (j.parse().unwrap(), k.parse().unwrap());
            // A symmetric M is listed once: the printed entry stands for both.
            assert_eq!(d.system.coeff(j - 1, k - 1), d.system.coeff(k - 1, j - 1));
            d.system.coeff(j - 1, k - 1)
        } else if let Some(j) = lhs.strip_prefix("f[").and_then(|s| s.strip_suffix(']')) {
            d.system.b[j.parse::<usize>().unwrap() - 1]
        } else if in_solved {
            let k = d.unknowns.iter().position(|u| u.name == lhs).unwrap();
            d.solution.as_ref().unwrap()[k]
        } else {
            continue;
        };
        let printed = parse(p, &coords, rhs, &what);
        assert_equal_at_random_points(p, derived, printed, &what);
        checked += 1;
    }
    // Entries of M that are not printed are 0.
    if text.contains("entries not listed are 0") {
        for j in 0..d.system.cols() {
            for k in 0..d.system.cols() {
                let name = format!("  M[{},{}] = ", j.min(k) + 1, j.max(k) + 1);
                if !text.contains(&name) {
                    let e = d.system.coeff(j, k);
                    assert_equal_at_random_points(p, e, Pool::ZERO, &name);
                }
            }
        }
    }
    checked
}

#[test]
fn printed_equations_of_the_examples_parse_back_to_the_derived_ones() {
    let mut total = 0;
    for f in examples() {
        total += round_trip(&f);
    }
    // The chains' M and f, the double pendulum's explicit accelerations, the Newton-form
    // examples' solutions.
    assert!(total >= 20, "only {total} expressions checked");
}

#[test]
fn printed_matrix_form_of_chains_parses_back_to_the_derived_one() {
    for n in [2, 3, 5, 16] {
        let f = chain_file(n);
        let checked = round_trip(&f);
        // Every M[j,k] with j ≤ k (the chain's M is dense) and every f[j], whole at these
        // sizes (at n = 16, f[1] is 17 terms `l1*l2*(m2 + … + m16)*q2'^2*sin(q1 - q2)`: it
        // was over the printing budget while f was summed particle by particle).
        assert!(
            checked >= n * (n + 1) / 2 + n,
            "chain {n}: only {checked} expressions checked"
        );
        let _ = std::fs::remove_file(f);
    }
}

#[test]
fn no_line_of_derive_output_on_the_examples_is_over_the_budget() {
    for f in examples() {
        assert_lines_within_budget(&f, &[]);
        assert_lines_within_budget(&f, &["--latex"]);
    }
}

#[test]
fn no_line_of_derive_output_on_chains_is_over_the_budget() {
    for n in [2, 3, 8, 16] {
        let f = chain_file(n);
        assert_lines_within_budget(&f, &[]);
        assert_lines_within_budget(&f, &["--latex"]);
        assert_lines_within_budget(&f, &["--solve"]);
        let _ = std::fs::remove_file(f);
    }
}

#[test]
fn no_line_of_derive_output_on_the_100_link_chain_is_over_the_budget() {
    let f = chain_file(100);
    assert_lines_within_budget(&f, &[]);
    assert_lines_within_budget(&f, &["--latex"]);
    let _ = std::fs::remove_file(f);
}

/// The "No closed form" reason quotes a short coefficient (the satellite's, 70 characters)
/// and names a long one with its size (the double pendulum's, 738 characters, was quoted
/// whole): the equation, the symbol and the size, never the long expression.
#[test]
fn no_closed_form_names_a_long_coefficient_by_its_size() {
    let reason = |name: &str| -> String {
        let text = derive_output(&root().join(format!("examples/{name}.toml")), &[]).unwrap();
        text.lines()
            .find(|l| l.starts_with("No closed form:"))
            .unwrap_or_else(|| panic!("{name}: no 'No closed form' line:\n{text}"))
            .to_string()
    };
    let chain = reason("pendulum_chain_2");
    assert!(
        chain.contains("equation 1 is not linear in `q1`")
            && chain.contains("its coefficient, ")
            && chain.contains(" characters, depends on the coordinates"),
        "{chain}"
    );
    // Nothing quoted: no expression of the pendulum (its sines) in the line.
    assert!(!chain.contains("sin("), "{chain}");
    assert!(chain.chars().count() < 250, "{chain}");
    let satellite = reason("satellite");
    assert!(
        satellite.contains("its coefficient `-3*GM*x^2/(x^2 + y^2)^(5/2) + GM/(x^2 + y^2)^(3/2)`"),
        "{satellite}"
    );
}
