//! Published statistics of Hairer's codes, reproduced exactly.
mod common;
use common::*;
use pdyn_ode::{solve, Method, Options};

#[test]
fn dopri5_arenstorf_matches_dopri5f_statistics() {
    let opts = Options {
        h0: Some(1e-4),
        ..Options::with_tol(1e-7)
    };
    let sol = solve(Method::Dopri5, &arenstorf(), (0.0, AREN_T), &AREN_Y0, &opts).unwrap();
    let s = &sol.stats;
    assert_eq!((s.accepted, s.rejected, s.fevals), (217, 21, 1429), "{s:?}");
    let (t, y) = sol.last().unwrap();
    assert_eq!(t, AREN_T);
    assert!(max_err(y, &AREN_DOPRI5_YT) < 1e-9, "{y:?}");
}

#[test]
fn dop853_van_der_pol_matches_dop853f_statistics() {
    let opts = Options {
        h0: Some(1e-6),
        t_eval: Some((0..=20).map(|k| k as f64 * 0.1).collect()),
        ..Options::with_tol(1e-9)
    };
    let sol = solve(
        Method::Dop853,
        &van_der_pol(1e-3),
        (0.0, 2.0),
        &[2.0, 0.0],
        &opts,
    )
    .unwrap();
    let s = &sol.stats;
    assert_eq!((s.accepted, s.rejected), (1348, 121), "{s:?}");
    // dop853.f counts 1 + 11 per attempt + 1 per accepted step (+3 per step with dense output,
    // which it computes on every step when dense output is on: 21551 + its 2 initial calls).
    // pdyn computes the 3 dense stages only on steps containing an output time.
    let dense_steps = s.fevals - (1 + 11 * (1348 + 121) + 1348);
    assert_eq!(dense_steps % 3, 0);
    assert!(dense_steps / 3 <= 20, "{s:?}");
    assert_eq!(sol.t.len(), 21);
    let (t, y) = sol.last().unwrap();
    assert_eq!(t, 2.0);
    assert!(max_err(y, &VDP_NONSTIFF_Y2) < 1e-8, "{y:?}");
}
