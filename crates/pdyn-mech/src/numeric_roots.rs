//! Numeric roots of equations that have no closed form (`pdyn solve --in`, `--start`):
//! Kepler's `E − e sin E = M`, `sin x = x/10`, `tan x = x`.
//!
//! # One equation in an interval: every root, each certified
//! `f` and its symbolic derivatives `f'`, `f''` are compiled once. The interval is sampled
//! (`samples` equal steps, 2,000 by default); every step whose ends have opposite signs holds
//! an odd number of roots, and Brent's method (bisection, secant and inverse quadratic
//! interpolation, never leaving the bracket) narrows it to adjacent floating-point numbers:
//! the root is **certified by the sign change** of `f` across that final bracket. A step
//! where `f` keeps its sign but `f'` changes it holds a critical point, found by Brent on
//! `f'`; if `f` is zero there to within its rounding (see [`Certificate::Residual`]) it is a
//! **double root, certified by a residual bound** (a sign change of `f'` brackets the
//! critical point; `|f|` there is below the bound on `f`'s rounding error). A sign change of
//! `f` across a pole (`tan x`) converges to a point where `|f|` is not small: it is reported
//! as a discontinuity, not a root. Roots closer together than the sampling step can be
//! missed in pairs (a sign change each, cancelling): the report states the step.
//!
//! # Small systems: Newton from given starts
//! `F(x) = 0` with the symbolic Jacobian, damped Newton (the step halved until `|F|`
//! decreases) from each start; a converged point is reported with its residual `|F|∞` and
//! the size of its last Newton step, the same solution from several starts once.

use pdyn_expr::{Id, Pool, Program};
use std::fmt;

/// Default number of sampling steps of the interval.
pub const DEFAULT_SAMPLES: usize = 2000;

/// Largest number of sampling steps accepted.
pub const MAX_SAMPLES: usize = 10_000_000;

/// Newton iterations per start.
const MAX_NEWTON: usize = 100;

/// Why numeric roots could not be sought.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum RootsError {
    /// The interval is empty, reversed or not finite.
    BadInterval {
        /// What is wrong.
        message: String,
    },
    /// An expression depends on something besides the unknowns.
    NotNumeric {
        /// The leaf without a value, printed.
        name: String,
    },
    /// A start point is not a point of the unknowns.
    BadStart {
        /// What is wrong.
        message: String,
    },
}

impl fmt::Display for RootsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RootsError::BadInterval { message } | RootsError::BadStart { message } => {
                f.write_str(message)
            }
            RootsError::NotNumeric { name } => write!(
                f,
                "`{name}` has no value: numeric roots need every name but the unknowns given \
                 a number (--at {name}=...)"
            ),
        }
    }
}

impl std::error::Error for RootsError {}

/// Why a root is one.
#[derive(Clone, Debug, PartialEq)]
pub enum Certificate {
    /// `f` is exactly zero there.
    Exact,
    /// `f(lo)` and `f(hi)` have opposite signs; the root is in `[lo, hi]`.
    SignChange {
        /// Lower end of the final bracket.
        lo: f64,
        /// Upper end of the final bracket.
        hi: f64,
    },
    /// A double (even-multiplicity) root: `f'` changes sign across `[lo, hi]` and `|f|` at
    /// the critical point is at most `bound`, the estimate of `f`'s rounding error: 64 ε
    /// times the largest `|f|` sampled in the interval (the size of the terms that cancel).
    /// Two simple roots closer than about `sqrt(bound / |f''|)` look the same.
    Residual {
        /// Lower end of the bracket of `f'`'s sign change.
        lo: f64,
        /// Upper end.
        hi: f64,
        /// The rounding bound `|f|` is below.
        bound: f64,
    },
}

/// A root of one equation.
#[derive(Clone, Debug, PartialEq)]
pub struct Root {
    /// Where.
    pub x: f64,
    /// `f(x)`.
    pub residual: f64,
    /// `f'(x)` (zero or tiny at a double root).
    pub slope: f64,
    /// Why it is a root.
    pub certificate: Certificate,
}

/// Every root found in an interval, and what was not a root.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarRoots {
    /// The roots, increasing.
    pub roots: Vec<Root>,
    /// Sign changes of `f` that are not roots (poles, jumps): the bracket of each.
    pub discontinuities: Vec<(f64, f64)>,
    /// The sampling step: roots closer than it may be missed in pairs.
    pub step: f64,
    /// Sample points where `f` is not a number (outside its domain, `sqrt` of a negative):
    /// no root can be found there, and saying "no root" alone would be silent about it.
    pub undefined: usize,
    /// Sample points, `samples + 1`.
    pub sampled: usize,
}

/// One equation's compiled `f`, `f'`, `f''`.
struct Scalar {
    prog: Program,
    ws: Vec<f64>,
    out: [f64; 3],
}

impl Scalar {
    fn new(pool: &mut Pool, f: Id, x: Id) -> Result<Scalar, RootsError> {
        let d1 = pool.diff(f, x);
        let d2 = pool.diff(d1, x);
        let prog = Program::compile(pool, &[x], &[f, d1, d2]).map_err(|e| match e {
            pdyn_expr::compile::CompileError::MissingInput { name } => {
                RootsError::NotNumeric { name }
            }
            other => RootsError::NotNumeric {
                name: other.to_string(),
            },
        })?;
        let ws = prog.workspace();
        Ok(Scalar {
            prog,
            ws,
            out: [0.0; 3],
        })
    }

    /// `(f, f', f'')` at `x`.
    fn at(&mut self, x: f64) -> [f64; 3] {
        self.prog.eval(&[x], &mut self.ws, &mut self.out);
        self.out
    }
}

/// Brent's method for a zero of `g` in `[a, b]`, `g(a) g(b) < 0`: the final bracket
/// `(lo, hi)` (adjacent or within `4 ε |x|`) with the signs still opposite.
pub fn brent_root(mut g: impl FnMut(f64) -> f64, a: f64, b: f64, ga: f64, gb: f64) -> (f64, f64) {
    let (mut a, mut b, mut fa, mut fb) = (a, b, ga, gb);
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..400 {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + f64::MIN_POSITIVE;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            break;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = g(b);
    }
    if fb == 0.0 {
        return (b, b);
    }
    (b.min(c), b.max(c))
}

/// Every root of `f(x) = 0` in `[lo, hi]`; see the module documentation.
pub fn scalar_roots(
    pool: &mut Pool,
    f: Id,
    x: Id,
    lo: f64,
    hi: f64,
    samples: usize,
) -> Result<ScalarRoots, RootsError> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(RootsError::BadInterval {
            message: format!("the interval [{lo}, {hi}] is not finite"),
        });
    }
    if lo >= hi {
        return Err(RootsError::BadInterval {
            message: format!("the interval's lower end {lo} is not below its upper end {hi}"),
        });
    }
    if !(2..=MAX_SAMPLES).contains(&samples) {
        return Err(RootsError::BadInterval {
            message: format!("{samples} sampling steps: between 2 and {MAX_SAMPLES}"),
        });
    }
    let mut s = Scalar::new(pool, f, x)?;
    let step = (hi - lo) / samples as f64;
    let xs: Vec<f64> = (0..=samples)
        .map(|i| {
            if i == samples {
                hi
            } else {
                lo + step * i as f64
            }
        })
        .collect();
    let vals: Vec<[f64; 3]> = xs.iter().map(|&v| s.at(v)).collect();
    let magnitude = vals
        .iter()
        .map(|v| v[0].abs())
        .filter(|v| v.is_finite())
        .fold(f64::MIN_POSITIVE, f64::max);
    let mut roots = Vec::new();
    let mut discontinuities = Vec::new();
    for i in 0..=samples {
        let [fx, d1, _] = vals[i];
        if fx == 0.0 {
            roots.push(Root {
                x: xs[i],
                residual: 0.0,
                slope: d1,
                certificate: Certificate::Exact,
            });
        }
    }
    for i in 0..samples {
        let (a, b) = (xs[i], xs[i + 1]);
        let ([fa, da, _], [fb, db, _]) = (vals[i], vals[i + 1]);
        if !(fa.is_finite() && fb.is_finite()) || fa == 0.0 || fb == 0.0 {
            continue;
        }
        // The scale of f nearby, for "small": its rounding cannot be below ε times it.
        let scale = fa.abs().max(fb.abs());
        if fa.signum() != fb.signum() {
            let (l, h) = brent_root(|v| s.at(v)[0], a, b, fa, fb);
            let mid = if l == h { l } else { 0.5 * (l + h) };
            let at = s.at(mid);
            let [fl, ..] = s.at(l);
            // A pole's sign change leaves |f| large next to it: both ends of the final
            // bracket far from zero compared with the samples' scale.
            let [fh, ..] = s.at(h);
            if fl.abs().min(fh.abs()) > 1e-6 * scale.max(1.0) {
                discontinuities.push((l, h));
                continue;
            }
            let (x, fx) = if fl.abs() <= fh.abs() {
                (l, fl)
            } else {
                (h, fh)
            };
            roots.push(Root {
                x,
                residual: fx,
                slope: at[1],
                certificate: if l == h {
                    Certificate::Exact
                } else {
                    Certificate::SignChange { lo: l, hi: h }
                },
            });
        } else if da.is_finite()
            && db.is_finite()
            && da != 0.0
            && db != 0.0
            && da.signum() != db.signum()
        {
            // f keeps its sign, f' changes it: a critical point, perhaps a double root.
            let (l, h) = brent_root(|v| s.at(v)[1], a, b, da, db);
            let xc = if s.at(l)[0].abs() <= s.at(h)[0].abs() {
                l
            } else {
                h
            };
            let [fc, dc, _] = s.at(xc);
            let bound = 64.0 * f64::EPSILON * magnitude;
            if fc.abs() <= bound {
                roots.push(Root {
                    x: xc,
                    residual: fc,
                    slope: dc,
                    certificate: Certificate::Residual {
                        lo: l,
                        hi: h,
                        bound,
                    },
                });
            } else if fc.signum() != fa.signum() && fc.is_finite() {
                // f crosses zero twice within the step: two simple roots around xc.
                for (p, q, fp, fq) in [(a, xc, fa, fc), (xc, b, fc, fb)] {
                    let (l, h) = brent_root(|v| s.at(v)[0], p, q, fp, fq);
                    let [fl, ..] = s.at(l);
                    let [fh, ..] = s.at(h);
                    let (x, fx) = if fl.abs() <= fh.abs() {
                        (l, fl)
                    } else {
                        (h, fh)
                    };
                    roots.push(Root {
                        x,
                        residual: fx,
                        slope: s.at(x)[1],
                        certificate: Certificate::SignChange { lo: l, hi: h },
                    });
                }
            }
        }
    }
    roots.sort_by(|a, b| a.x.total_cmp(&b.x));
    roots.dedup_by(|b, a| b.x == a.x);
    Ok(ScalarRoots {
        roots,
        discontinuities,
        step,
        undefined: vals.iter().filter(|v| !v[0].is_finite()).count(),
        sampled: vals.len(),
    })
}

/// A solution of a system found by Newton's method.
#[derive(Clone, Debug, PartialEq)]
pub struct SystemRoot {
    /// The unknowns' values.
    pub x: Vec<f64>,
    /// `max |F_i(x)|`.
    pub residual: f64,
    /// The size (max norm) of the last Newton step: the distance to the root, to first order.
    pub last_step: f64,
    /// The starts (indices) that converged to it.
    pub from_starts: Vec<usize>,
}

/// A start that did not converge.
#[derive(Clone, Debug, PartialEq)]
pub struct Diverged {
    /// Which start.
    pub start: usize,
    /// Why.
    pub reason: String,
}

/// Newton's method on `F(x) = 0` from each start; see the module documentation.
pub fn newton_system(
    pool: &mut Pool,
    equations: &[Id],
    unknowns: &[Id],
    starts: &[Vec<f64>],
) -> Result<(Vec<SystemRoot>, Vec<Diverged>), RootsError> {
    let n = unknowns.len();
    if equations.len() != n {
        return Err(RootsError::BadStart {
            message: format!(
                "{} equation(s) for {n} unknown(s): Newton's method needs as many equations as unknowns",
                equations.len()
            ),
        });
    }
    if let Some(s) = starts
        .iter()
        .find(|s| s.len() != n || s.iter().any(|v| !v.is_finite()))
    {
        return Err(RootsError::BadStart {
            message: format!("a start needs {n} finite value(s), got {s:?}"),
        });
    }
    let jac = pool.jacobian(equations, unknowns);
    let mut outs = equations.to_vec();
    outs.extend(jac);
    let prog = Program::compile(pool, unknowns, &outs).map_err(|e| match e {
        pdyn_expr::compile::CompileError::MissingInput { name } => RootsError::NotNumeric { name },
        other => RootsError::NotNumeric {
            name: other.to_string(),
        },
    })?;
    let mut ws = prog.workspace();
    let mut out = vec![0.0; n + n * n];
    let mut eval = |x: &[f64], out: &mut Vec<f64>| {
        prog.eval(x, &mut ws, out);
        out[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let mut found: Vec<SystemRoot> = Vec::new();
    let mut diverged = Vec::new();
    'starts: for (k, start) in starts.iter().enumerate() {
        let mut x = start.clone();
        let mut r = eval(&x, &mut out);
        let mut last_step = f64::INFINITY;
        for _ in 0..MAX_NEWTON {
            if !r.is_finite() {
                break;
            }
            let f: Vec<f64> = out[..n].to_vec();
            let mut a = out[n..].to_vec();
            let Some(dx) = solve_dense(&mut a, &f, n) else {
                diverged.push(Diverged {
                    start: k,
                    reason: format!("the Jacobian is singular at {x:?}"),
                });
                continue 'starts;
            };
            // Damped: halve the step until the residual decreases (or the step is tiny).
            let mut t = 1.0;
            loop {
                let trial: Vec<f64> = x.iter().zip(&dx).map(|(xi, di)| xi - t * di).collect();
                let rt = eval(&trial, &mut out);
                if rt <= r || t < 1e-10 {
                    last_step = dx.iter().fold(0.0f64, |m, d| m.max((t * d).abs()));
                    x = trial;
                    r = rt;
                    break;
                }
                t *= 0.5;
            }
            let size = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            if last_step <= 4.0 * f64::EPSILON * size || r == 0.0 {
                break;
            }
        }
        let size = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        if !(r.is_finite() && last_step <= 1e-10 * size) {
            diverged.push(Diverged {
                start: k,
                reason: format!("no convergence in {MAX_NEWTON} Newton steps (|F| = {r:e})"),
            });
            continue;
        }
        if let Some(same) = found.iter_mut().find(|s| {
            s.x.iter()
                .zip(&x)
                .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + a.abs()))
        }) {
            same.from_starts.push(k);
            continue;
        }
        found.push(SystemRoot {
            x,
            residual: r,
            last_step,
            from_starts: vec![k],
        });
    }
    Ok((found, diverged))
}

/// `A x = b` by Gaussian elimination with partial pivoting (`a` row-major `n × n`); `None`
/// when singular.
fn solve_dense(a: &mut [f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut x = b.to_vec();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))?;
        if a[p * n + c] == 0.0 || !a[p * n + c].is_finite() {
            return None;
        }
        if p != c {
            for j in 0..n {
                a.swap(p * n + j, c * n + j);
            }
            x.swap(p, c);
        }
        for i in c + 1..n {
            let m = a[i * n + c] / a[c * n + c];
            for j in c..n {
                a[i * n + j] -= m * a[c * n + j];
            }
            x[i] -= m * x[c];
        }
    }
    for c in (0..n).rev() {
        let mut s = x[c];
        for j in c + 1..n {
            s -= a[c * n + j] * x[j];
        }
        x[c] = s / a[c * n + c];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roots_of(src: &str, lo: f64, hi: f64) -> ScalarRoots {
        let mut p = Pool::new();
        let f = p.parse_scalar(src).unwrap();
        let x = p.var("x");
        scalar_roots(&mut p, f, x, lo, hi, DEFAULT_SAMPLES).unwrap()
    }

    #[test]
    fn kepler_has_one_root_and_it_gives_back_m() {
        // E − e sin E = M is increasing for e < 1: exactly one root; M recomputed from it.
        for (e, m) in [(0.3, 1.0), (0.9, 0.1), (0.99, 3.0)] {
            let r = roots_of(
                &format!("x - {e}*sin(x) - {m}"),
                0.0,
                2.0 * std::f64::consts::PI,
            );
            assert_eq!(r.roots.len(), 1, "{e} {m}: {:?}", r.roots);
            let big_e = r.roots[0].x;
            assert!(
                (big_e - e * libm::sin(big_e) - m).abs() < 4e-16 * 8.0,
                "{big_e}"
            );
            assert!(matches!(
                r.roots[0].certificate,
                Certificate::SignChange { .. } | Certificate::Exact
            ));
        }
    }

    #[test]
    fn sin_x_equals_x_over_10_has_seven_roots() {
        // The line x/10 crosses sin x at 0 and three times on each side within |x| ≤ 10
        // (in (2π, 3π) twice: sin reaches 1 > 0.7... and back; once in (π/2, π)).
        let r = roots_of("sin(x) - x/10", -10.0, 10.0);
        assert_eq!(r.roots.len(), 7, "{:?}", r.roots);
        for k in 0..7 {
            assert!(
                (r.roots[k].x + r.roots[6 - k].x).abs() < 1e-14,
                "odd symmetry"
            );
            let x = r.roots[k].x;
            assert!((libm::sin(x) - x / 10.0).abs() < 1e-15);
        }
    }

    #[test]
    fn a_double_root_is_certified_by_its_residual_and_a_pole_is_not_a_root() {
        let r = roots_of("(x - 1)^2*(x + 2)", -3.0, 3.1);
        assert_eq!(r.roots.len(), 2, "{:?}", r.roots);
        assert!((r.roots[0].x + 2.0).abs() < 1e-15);
        assert!(matches!(
            r.roots[1].certificate,
            Certificate::Residual { .. }
        ));
        assert!((r.roots[1].x - 1.0).abs() < 1e-7, "{}", r.roots[1].x);
        let r = roots_of("tan(x) - x", 0.1, 7.0);
        // tan x = x: 4.4934 and the poles at π/2, 3π/2 are not roots.
        assert_eq!(r.roots.len(), 1, "{:?}", r.roots);
        assert!((r.roots[0].x - 4.493_409_457_909_064).abs() < 1e-13);
        assert_eq!(r.discontinuities.len(), 2, "{:?}", r.discontinuities);
        // Expanded, the double root's value cancels terms of size 1: still found.
        let r = roots_of("x^3 - 3*x + 2", -3.0, 3.1);
        assert_eq!(r.roots.len(), 2, "{:?}", r.roots);
    }

    #[test]
    fn bad_intervals_are_refused() {
        let mut p = Pool::new();
        let f = p.parse_scalar("x - 1").unwrap();
        let x = p.var("x");
        assert!(scalar_roots(&mut p, f, x, 2.0, 1.0, 10).is_err());
        assert!(scalar_roots(&mut p, f, x, 0.0, f64::INFINITY, 10).is_err());
        let g = p.parse_scalar("x - a").unwrap();
        let e = scalar_roots(&mut p, g, x, 0.0, 1.0, 10).unwrap_err();
        assert!(e.to_string().contains("`a` has no value"), "{e}");
    }

    #[test]
    fn newton_finds_the_circle_and_line_intersections() {
        // x² + y² = 4, y = x: (±√2, ±√2).
        let mut p = Pool::new();
        let f1 = p.parse_scalar("x^2 + y^2 - 4").unwrap();
        let f2 = p.parse_scalar("y - x").unwrap();
        let (x, y) = (p.var("x"), p.var("y"));
        let starts = vec![vec![1.0, 2.0], vec![3.0, 1.0], vec![-1.0, -0.5]];
        let (found, diverged) = newton_system(&mut p, &[f1, f2], &[x, y], &starts).unwrap();
        assert!(diverged.is_empty(), "{diverged:?}");
        assert_eq!(found.len(), 2);
        let s2 = std::f64::consts::SQRT_2;
        assert!((found[0].x[0] - s2).abs() < 1e-15 && (found[0].x[1] - s2).abs() < 1e-15);
        assert_eq!(found[0].from_starts, vec![0, 1]);
        assert!((found[1].x[0] + s2).abs() < 1e-15);
    }
}
