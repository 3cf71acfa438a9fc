//! `pdyn derive` on small classic systems in Newton form prints their solved accelerations by
//! default (issue 34, item 3), in the textbook's factored form and within the printing
//! budget; on a model whose motion is prescribed by an `acceleration` it prints the
//! reactions solved (item 4).

#[path = "common/in_root.rs"]
mod in_root;
#[path = "../../pdyn-mech/tests/common/newton_classics.rs"]
mod newton_classics;

use in_root::pdyn;
use pdyn_expr::budget::PRINT_CHARS;

/// `pdyn derive` of a model written to a temporary file: its stdout (exit code 0).
fn derive_text(name: &str, toml: &str) -> String {
    let path = std::env::temp_dir().join(format!("pdyn-{name}-{}.toml", std::process::id()));
    std::fs::write(&path, toml).unwrap();
    let (code, stdout, stderr) = pdyn(&["derive", &path.to_string_lossy()]);
    assert_eq!(code, 0, "{stderr}");
    stdout
}

fn assert_solved(text: &str, accelerations: &[&str]) {
    assert!(text.contains("\nSolved:\n"), "{text}");
    assert!(!text.contains("A⁻¹ b"), "{text}");
    assert!(!text.contains("expensive"), "{text}");
    for a in accelerations {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("  {a} = ")))
            .unwrap_or_else(|| panic!("no `{a} = ` line:\n{text}"));
        assert!(!line.contains("explicit form"), "{line}");
    }
    for line in text.lines() {
        assert!(line.chars().count() <= PRINT_CHARS, "{line}");
    }
}

#[test]
fn double_pendulum_in_newton_form_prints_its_accelerations() {
    let text = derive_text("double-pendulum-newton", newton_classics::DOUBLE_PENDULUM);
    assert_solved(&text, &["th1''", "th2''", "T1", "T2"]);
    let th1 = text.lines().find(|l| l.starts_with("  th1'' = ")).unwrap();
    assert!(th1.ends_with("/(L1*(m1 + m2*sin(th1 - th2)^2))"), "{th1}");
    assert!(text.contains("  d/dt th1' = "), "{text}");
    // The note on closed forms names the coefficient's size, not the coefficient.
    let note = text
        .lines()
        .find(|l| l.starts_with("No closed form"))
        .unwrap();
    assert!(note.chars().count() < 300, "{note}");
}

#[test]
fn pendulum_with_a_rod_tension_and_the_pulley_print_their_accelerations() {
    let text = derive_text("pendulum-newton", newton_classics::PENDULUM);
    assert_solved(&text, &["th''", "T"]);
    let (code, text, stderr) = pdyn(&["derive", "examples/pulley.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert_solved(&text, &["yA''", "yB''", "T"]);
    assert!(text.contains("  yA'' = -g*(mA - mB)/(mA + mB)\n"), "{text}");
}

#[test]
fn prescribed_motion_prints_the_reactions() {
    let (code, text, stderr) = pdyn(&["derive", "examples/rotating_bar_block.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(text.contains("the motion is prescribed"), "{text}");
    assert!(text.contains("pdyn forces"), "{text}");
    assert!(text.contains("  N = g*m*cos(theta)\n"), "{text}");
    assert!(
        text.contains("  T = g*m*sin(theta) - m*r*theta'^2\n"),
        "{text}"
    );
}

/// A run of the prescribed motion claims no conservation law (it warned that the driven
/// bar's energy "drifted").
#[test]
fn prescribed_motion_runs_without_a_false_drift_warning() {
    let out = std::env::temp_dir().join(format!("pdyn-rbb-run-{}", std::process::id()));
    let (code, stdout, stderr) = pdyn(&[
        "run",
        "examples/rotating_bar_block.toml",
        "--t-end",
        "1",
        "--out",
        &out.to_string_lossy(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stdout.contains("DRIFTING"), "{stdout}");
    assert!(!stderr.contains("should be conserved"), "{stderr}");
    let _ = std::fs::remove_dir_all(&out);
}
