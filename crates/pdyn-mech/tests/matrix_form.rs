//! `matrix_form` on the n-link chain: every entry of `M` and `f` comes out collected and
//! factored in one canonical form, the one a textbook (or SymPy's KanesMethod) prints, and
//! equal to the derivation's own `A x = b` entry.

#[path = "common/chain.rs"]
mod chain;

use chain::chain_toml;
use pdyn_mech::matrix_form::{depends_on_state, matrix_form};

/// `m{from} + … + m{n}`, parenthesised when it has more than one term.
fn masses(from: usize, n: usize) -> String {
    let ms: Vec<String> = (from..=n).map(|i| format!("m{i}")).collect();
    // The pool orders names as strings: m10 before m2.
    let mut sorted = ms.clone();
    sorted.sort();
    if sorted.len() == 1 {
        sorted[0].clone()
    } else {
        format!("({})", sorted.join(" + "))
    }
}

#[test]
fn chain_mass_matrix_and_forcing_are_collected_and_factored() {
    for n in [2, 3, 5, 12] {
        let mut model = pdyn_mech::load(&chain_toml(n), "chain.toml").unwrap();
        let d = pdyn_mech::derive(&mut model, &pdyn_mech::DeriveOptions::default()).unwrap();
        let m = matrix_form(&mut model.pool, &d).unwrap();
        assert_eq!(m.n, n);
        assert!(m.symmetric);
        let p = &mut model.pool;
        for j in 1..=n {
            for k in j..=n {
                let e = &m.mass[(j - 1) * n + (k - 1)];
                let text = e.render(p, false);
                let expected = if j == k {
                    format!("l{j}^2*{}", masses(j, n))
                } else {
                    // Names in string order (l10 before l2), as the pool sorts them.
                    let (a, b) = if j.to_string() < k.to_string() {
                        (j, k)
                    } else {
                        (k, j)
                    };
                    format!("l{a}*l{b}*{}*cos(q{a} - q{b})", masses(k, n))
                };
                assert_eq!(text, expected, "chain {n}, M[{j},{k}]");
                // Equal to the derivation's entry, and collecting again changes nothing.
                let raw = d.system.coeff(j - 1, k - 1);
                assert!(p.provably_equal(e.expr, raw), "chain {n}, M[{j},{k}]");
                assert_eq!(p.collect_by(e.expr, &depends_on_state), e.expr);
            }
        }
        // f[1] starts with the gravity term, all masses collected: -g*l1*(m1 + … + mn)*sin(q1).
        let f1 = m.forcing[0].render(p, false);
        assert!(
            f1.starts_with(&format!("-g*l1*{}*sin(q1)", masses(1, n))),
            "chain {n}: f[1] = {f1}"
        );
        if n <= 5 {
            // Each q_k'^2 appears once in f[1], its coefficient factored.
            for k in 2..=n {
                let term = format!("l1*l{k}*{}*q{k}'^2*sin(q1 - q{k})", masses(k, n));
                assert_eq!(f1.matches(&term).count(), 1, "chain {n}: f[1] = {f1}");
            }
            let raw = d.system.b[0];
            let tidy = m.forcing[0].expr;
            assert!(p.provably_equal(tidy, raw), "chain {n}: f[1]");
        }
    }
}
