//! Participation factors and effective modal masses of `pdyn modes` (issue 33, item 5),
//! against closed forms derived by hand, on the dense and the sparse paths.

use pdyn_mech::statics::{modes_about, About, ModesRequest, Solver};
use pdyn_mech::{load, Model};

fn model(src: &str) -> Model {
    load(src, "model.toml").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

/// The example's chain of `n` unit masses between two walls.
fn chain(n: usize) -> Model {
    let text = include_str!("../../../examples/chain_modes.toml");
    model(&text.replacen("n = 30", &format!("n = {n}"), 1))
}

/// Mode j of the fixed–fixed chain is φ_i = sin(i θ), θ = jπ/(n+1). Its modal mass is
/// Σ sin²(iθ) = (n+1)/2 and φᵀ M r = Σ sin(iθ), which is cot(θ/2) for odd j and 0 for even
/// j; so the effective mass along the chain is 2 cot²(θ/2)/(n+1) for odd j, 0 for even j,
/// and the modes' effective masses add up to the n unit masses.
fn chain_effective_mass(j: usize, n: usize) -> f64 {
    if j % 2 == 0 {
        return 0.0;
    }
    let half = j as f64 * std::f64::consts::PI / (2.0 * (n as f64 + 1.0));
    let cot = libm::cos(half) / libm::sin(half);
    2.0 * cot * cot / (n as f64 + 1.0)
}

#[test]
fn the_chains_effective_masses_follow_the_closed_form_on_both_paths() {
    for (n, solver, count) in [(30, Solver::Dense, None), (400, Solver::Sparse, Some(12))] {
        let mut m = chain(n);
        let report = modes_about(
            &mut m,
            &ModesRequest {
                about: About::Equilibrium,
                solver,
                count,
            },
        )
        .unwrap();
        let modes = &report.modes;
        // Only x moves: the total mass along x is every mass, none along y or z.
        assert!(
            (modes.total_mass[0] - n as f64).abs() < 1e-10 * n as f64,
            "{:?}",
            modes.total_mass
        );
        assert_eq!(modes.total_mass[1], 0.0);
        assert_eq!(modes.total_mass[2], 0.0);
        for (k, mode) in modes.modes.iter().enumerate() {
            let exact = chain_effective_mass(k + 1, n);
            assert!(
                (mode.effective_mass[0] - exact).abs() < 1e-9 * n as f64,
                "n = {n}, mode {}: {} vs {exact}",
                k + 1,
                mode.effective_mass[0]
            );
            // Γ = φᵀMr / φᵀMφ: Γ² times the modal mass is the effective mass.
            let g = mode.participation[0];
            assert!((g * g * mode.modal_mass - mode.effective_mass[0]).abs() < 1e-9 * n as f64);
        }
        if count.is_none() {
            let sum: f64 = modes.modes.iter().map(|m| m.effective_mass[0]).sum();
            assert!((sum - n as f64).abs() < 1e-9 * n as f64, "{sum}");
        }
    }
}

/// The chapter's two-storey building (k = 100, m = 1, columns of stiffness 2k per storey):
/// K = [[400, −200], [−200, 200]], M = I, so ω² = 300 ∓ 100√5; mode 1 is (y1, y2) ∝ (1/ϕ, 1)
/// and mode 2 ∝ (1, −1/ϕ), ϕ the golden ratio. The effective mass along y of a shape (a, b)
/// is (a + b)²/(a² + b²): 1.8944 and 0.1056, adding up to the two floors.
#[test]
fn the_buildings_effective_masses_match_the_hand_solution() {
    let mut m = model(include_str!("../../../examples/building.toml"));
    let report = modes_about(
        &mut m,
        &ModesRequest {
            about: About::Equilibrium,
            solver: Solver::Dense,
            count: None,
        },
    )
    .unwrap();
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    // Mode 1: (y1, y2) ∝ (1/ϕ, 1); mode 2: ∝ (1, −1/ϕ).
    let eff = |a: f64, b: f64| (a + b) * (a + b) / (a * a + b * b);
    let exact = [eff(inv_phi, 1.0), eff(1.0, -inv_phi)];
    let modes = &report.modes;
    assert!((modes.total_mass[1] - 2.0).abs() < 1e-12);
    for (mode, e) in modes.modes.iter().zip(exact) {
        assert!(
            (mode.effective_mass[1] - e).abs() < 1e-10,
            "{} vs {e}",
            mode.effective_mass[1]
        );
        assert_eq!(mode.effective_mass[0], 0.0);
    }
    assert!(
        (exact[0] - 1.894_427_191).abs() < 1e-9,
        "hand value: 94.72 % of 2"
    );
}
