//! One-dimensional minimisation on an interval.

/// The minimum of `f` on `[a, b]` by Brent's method (golden section with parabolic steps;
/// Brent 1973, ch. 5), to the tolerance `tol = rel·|x| + abs`: about ten evaluations where golden
/// section alone needs twenty. Non-finite values fall back to golden steps. Returns the
/// point and its value. Used by the smoothing spline's GCV and by `pdyn optimize`.
pub fn brent_min(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, rel: f64, abs: f64) -> (f64, f64) {
    let c = (3.0 - 5f64.sqrt()) / 2.0;
    let (mut a, mut b) = (a, b);
    let mut x = a + c * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e): (f64, f64) = (0.0, 0.0);
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

    /// With a relative tolerance the minimum is found to about that share of |x|.
    #[test]
    fn relative_tolerance() {
        let mut f = |x: f64| (x - 1234.5).powi(2);
        let (x, _) = super::brent_min(&mut f, 0.0, 1e4, 1e-10, 0.0);
        assert!((x - 1234.5).abs() < 1e-6, "{x}");
    }
}
