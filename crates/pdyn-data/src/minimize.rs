//! One-dimensional minimisation on an interval.

/// The minimum of `f` on `[a, b]` by Brent's method (golden section with parabolic steps;
/// Brent 1973, ch. 5), to the tolerance `tol = rel·|x| + abs`: about ten evaluations where golden
/// section alone needs twenty. Non-finite values fall back to golden steps. Returns the
/// point and its value. Used by the smoothing spline's GCV and by `pdyn optimize`.
pub fn brent_min(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, rel: f64, abs: f64) -> (f64, f64) {
    let x = a + golden() * (b - a);
    let fx = f(x);
    brent_from(f, a, b, [(x, fx); 3], 0.0, rel, abs)
}

/// [`brent_min`] on `[a, b]` when `f` is already known at `a < x < b` with `f(x)` below both
/// ends (a grid's best point and its neighbours): the first step is the parabola through the
/// three, not a golden section, and no value is computed twice. Returns the point and value.
pub fn brent_min_bracketed(
    f: &mut impl FnMut(f64) -> f64,
    (a, fa): (f64, f64),
    (x, fx): (f64, f64),
    (b, fb): (f64, f64),
    rel: f64,
    abs: f64,
) -> (f64, f64) {
    // Brent's w (second best) and v (the one before): the better end, then the other.
    let (w, v) = if fa <= fb {
        ((a, fa), (b, fb))
    } else {
        ((b, fb), (a, fa))
    };
    brent_from(f, a, b, [(x, fx), w, v], b - a, rel, abs)
}

/// The golden-section fraction `(3 − √5)/2`.
fn golden() -> f64 {
    (3.0 - 5f64.sqrt()) / 2.0
}

/// Brent's iteration on `[a, b]` from its state: `[x, w, v]` with their values (best, second
/// best, previous second best) and `e`, the step before last (0 forces a golden step first).
fn brent_from(
    f: &mut impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    [(x, fx), (w, fw), (v, fv)]: [(f64, f64); 3],
    e: f64,
    rel: f64,
    abs: f64,
) -> (f64, f64) {
    let c = golden();
    let (mut a, mut b) = (a, b);
    let (mut x, mut fx, mut w, mut fw, mut v, mut fv) = (x, fx, w, fw, v, fv);
    let (mut d, mut e): (f64, f64) = (0.0, e);
    for _ in 0..500 {
        let m = 0.5 * (a + b);
        let tol = rel * x.abs() + abs;
        let tol2 = 2.0 * tol;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let e_prev = e;
            e = d;
            if p.abs() < (0.5 * q * e_prev).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if m >= x { tol } else { -tol };
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= m { a - x } else { b - x };
            d = c * e;
        }
        let u = if d.abs() >= tol {
            x + d
        } else if d >= 0.0 {
            x + tol
        } else {
            x - tol
        };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv) = (w, fw);
            (w, fw) = (x, fx);
            (x, fx) = (u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv) = (w, fw);
                (w, fw) = (u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

#[cfg(test)]
mod brent_tests {
    /// Brent's method finds the minimum of a smooth function and of one with a kink, within
    /// its tolerance and in few evaluations.
    #[test]
    fn brent_finds_minima() {
        let mut calls = 0;
        let mut f = |x: f64| {
            calls += 1;
            (x - 0.7).powi(2) + 0.1 * (x - 0.7).powi(4)
        };
        let (x, _) = super::brent_min(&mut f, -2.0, 2.0, 0.0, 1e-4);
        assert!((x - 0.7).abs() < 3e-4, "{x}");
        assert!(calls < 20, "{calls} evaluations");
        let mut g = |x: f64| (x + 0.3).abs();
        let (x, _) = super::brent_min(&mut g, -2.0, 2.0, 0.0, 1e-4);
        assert!((x + 0.3).abs() < 1e-3, "{x}");
    }

    /// Seeded with three known points of a bracket, Brent's first step is their parabola:
    /// on a quartic-perturbed parabola it needs fewer new evaluations than from scratch, and
    /// it never evaluates the known points again.
    #[test]
    fn bracketed_start_reuses_the_known_points() {
        let f0 = |x: f64| (x - 0.7).powi(2) + 0.1 * (x - 0.7).powi(4);
        let mut seen = Vec::new();
        let mut f = |x: f64| {
            seen.push(x);
            f0(x)
        };
        let (x, fx) = super::brent_min_bracketed(
            &mut f,
            (-1.0, f0(-1.0)),
            (1.0, f0(1.0)),
            (3.0, f0(3.0)),
            0.0,
            1e-4,
        );
        assert!((x - 0.7).abs() < 3e-4, "{x}");
        assert_eq!(fx, f0(x));
        assert!(!seen.iter().any(|&s| s == -1.0 || s == 1.0 || s == 3.0));
        let seeded = seen.len();
        let mut calls = 0;
        let mut g = |x: f64| {
            calls += 1;
            f0(x)
        };
        super::brent_min(&mut g, -1.0, 3.0, 0.0, 1e-4);
        assert!(
            seeded < calls,
            "{seeded} new evaluations seeded, {calls} from scratch"
        );
        // The minimum at an end's side of the middle point, and a kink: still found.
        let mut h = |x: f64| (x + 0.3).abs();
        let (x, _) =
            super::brent_min_bracketed(&mut h, (-2.0, 1.7), (0.0, 0.3), (2.0, 2.3), 0.0, 1e-4);
        assert!((x + 0.3).abs() < 1e-3, "{x}");
    }

    /// With a relative tolerance the minimum is found to about that share of |x|.
    #[test]
    fn relative_tolerance() {
        let mut f = |x: f64| (x - 1234.5).powi(2);
        let (x, _) = super::brent_min(&mut f, 0.0, 1e4, 1e-10, 0.0);
        assert!((x - 1234.5).abs() < 1e-6, "{x}");
    }
}
