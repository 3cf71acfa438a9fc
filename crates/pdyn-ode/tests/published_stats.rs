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
