//! Polynomial roots: exact rational roots (rational root theorem with exact deflation), and
//! numeric roots of real polynomials (Aberth–Ehrlich iteration, grouping of multiple roots
//! and conjugate pairs).

use pdyn_expr::Rational;

/// A complex number (just what the root finder and determinants need).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub(crate) struct C64 {
    pub re: f64,
    pub im: f64,
}

impl C64 {
    pub const fn new(re: f64, im: f64) -> C64 {
        C64 { re, im }
    }
    pub fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
    pub fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
    pub fn mul(self, o: C64) -> C64 {
        C64::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    pub fn scale(self, k: f64) -> C64 {
        C64::new(self.re * k, self.im * k)
    }
    pub fn div(self, o: C64) -> C64 {
        // Smith's algorithm avoids overflow for large |o|.
        if o.re.abs() >= o.im.abs() {
            let r = o.im / o.re;
            let d = o.re + o.im * r;
            C64::new((self.re + self.im * r) / d, (self.im - self.re * r) / d)
        } else {
            let r = o.re / o.im;
            let d = o.re * r + o.im;
            C64::new((self.re * r + self.im) / d, (self.im * r - self.re) / d)
        }
    }
    pub fn abs(self) -> f64 {
        libm::hypot(self.re, self.im)
    }
    pub fn cis(theta: f64) -> C64 {
        C64::new(libm::cos(theta), libm::sin(theta))
    }
}

/// Value and derivative of `Σ c_k z^k` (Horner).
fn eval_with_derivative(coeffs: &[f64], z: C64) -> (C64, C64) {
    let mut p = C64::default();
    let mut dp = C64::default();
    for &c in coeffs.iter().rev() {
        dp = dp.mul(z).add(p);
        p = p.mul(z).add(C64::new(c, 0.0));
    }
    (p, dp)
}

/// A group of equal roots: `re ± i im` (`im >= 0`; `im > 0` stands for the conjugate pair),
/// with multiplicity `mult`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RootGroup {
    pub re: f64,
    pub im: f64,
    pub mult: usize,
}

/// Roots of the real polynomial `Σ coeffs[k] λ^k` (leading coefficient nonzero), grouped.
pub(crate) fn numeric_roots(coeffs: &[f64]) -> Vec<RootGroup> {
    let mut c = coeffs.to_vec();
    while c.len() > 1 && c[c.len() - 1] == 0.0 {
        c.pop();
    }
    let mut zeros = 0;
    while c.len() > 1 && c[0] == 0.0 {
        c.remove(0);
        zeros += 1;
    }
    let n = c.len() - 1;
    let mut groups = Vec::new();
    if zeros > 0 {
        groups.push(RootGroup {
            re: 0.0,
            im: 0.0,
            mult: zeros,
        });
    }
    if n == 0 {
        return groups;
    }
    let lead = c[n];
    let monic: Vec<f64> = c.iter().map(|x| x / lead).collect();
    // Initial guesses on a circle of the Cauchy-bound-like radius, off the real axis.
    let radius = (0..n)
        .map(|k| libm::pow(monic[k].abs(), 1.0 / (n - k) as f64))
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let mut z: Vec<C64> = (0..n)
        .map(|k| C64::cis(2.0 * std::f64::consts::PI * (k as f64 + 0.25) / n as f64).scale(radius))
        .collect();
    // Aberth–Ehrlich: z_k -= w_k / (1 - w_k Σ_{j≠k} 1/(z_k - z_j)), w_k = p/p'.
    for _ in 0..500 {
        let mut moved = 0.0f64;
        for k in 0..n {
            let (p, dp) = eval_with_derivative(&monic, z[k]);
            if p.abs() == 0.0 {
                continue;
            }
            let w = p.div(dp);
            let mut s = C64::default();
            for j in 0..n {
                if j != k {
                    let d = z[k].sub(z[j]);
                    if d.abs() > 0.0 {
                        s = s.add(C64::new(1.0, 0.0).div(d));
                    }
                }
            }
            let denom = C64::new(1.0, 0.0).sub(w.mul(s));
            let step = if denom.abs() > 0.0 { w.div(denom) } else { w };
            if step.re.is_finite() && step.im.is_finite() {
                z[k] = z[k].sub(step);
                moved = moved.max(step.abs() / z[k].abs().max(radius * 1e-3));
            }
        }
        if moved < 1e-15 {
            break;
        }
    }
    group_roots(&mut groups, &z, radius, &monic);
    groups
}

/// Polishes a root of multiplicity `m` as the simple root of the `(m-1)`-th derivative (a
/// multiple root is found by the iteration only to about eps^(1/m)).
fn polish_multiple(monic: &[f64], z0: C64, m: usize) -> C64 {
    let n = monic.len() - 1;
    if m <= 1 || m > n {
        return z0;
    }
    let d: Vec<f64> = (0..=n - (m - 1))
        .map(|k| {
            let f: f64 = (k + 1..k + m).map(|j| j as f64).product();
            monic[k + m - 1] * f
        })
        .collect();
    let mut z = z0;
    for _ in 0..30 {
        let (p, dp) = eval_with_derivative(&d, z);
        if dp.abs() == 0.0 {
            break;
        }
        let step = p.div(dp);
        if !(step.re.is_finite() && step.im.is_finite()) {
            break;
        }
        z = z.sub(step);
        if step.abs() <= 1e-16 * z.abs().max(1e-300) {
            break;
        }
    }
    // Keep the polished value only if it stayed in the cluster.
    if z.sub(z0).abs() <= 1e-3 * z0.abs().max(1e-6) {
        z
    } else {
        z0
    }
}

fn group_roots(groups: &mut Vec<RootGroup>, z: &[C64], scale: f64, monic: &[f64]) {
    // Multiple roots are found to about eps^(1/m): group generously, then average.
    let tol = 1e-6 * scale.max(1e-300);
    let mut used = vec![false; z.len()];
    let mut found: Vec<(C64, usize)> = Vec::new();
    for i in 0..z.len() {
        if used[i] {
            continue;
        }
        let mut members = vec![i];
        used[i] = true;
        for j in i + 1..z.len() {
            if !used[j] && z[j].sub(z[i]).abs() < tol.max(1e-4 * z[i].abs() * 1e-2) {
                used[j] = true;
                members.push(j);
            }
        }
        let mut mean = C64::default();
        for &m in &members {
            mean = mean.add(z[m]);
        }
        let mean = mean.scale(1.0 / members.len() as f64);
        found.push((polish_multiple(monic, mean, members.len()), members.len()));
    }
    // Conjugates: keep the one with im > 0; snap tiny imaginary parts to the real axis.
    let mut taken = vec![false; found.len()];
    for i in 0..found.len() {
        if taken[i] {
            continue;
        }
        taken[i] = true;
        let (r, m) = found[i];
        if r.im.abs() <= tol.max(1e-9 * r.abs()) {
            groups.push(RootGroup {
                re: r.re,
                im: 0.0,
                mult: m,
            });
            continue;
        }
        if let Some(j) = (i + 1..found.len())
            .find(|&j| !taken[j] && found[j].0.sub(conj(r)).abs() < tol.max(1e-6 * r.abs()))
        {
            taken[j] = true;
            let re = 0.5 * (r.re + found[j].0.re);
            let im = 0.5 * (r.im.abs() + found[j].0.im.abs());
            groups.push(RootGroup {
                re,
                im,
                mult: m.max(found[j].1),
            });
        } else {
            // A lone complex root of a real polynomial is a numerical accident: keep its pair.
            groups.push(RootGroup {
                re: r.re,
                im: r.im.abs(),
                mult: m,
            });
        }
    }
    groups.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
}

fn conj(z: C64) -> C64 {
    C64::new(z.re, -z.im)
}

/// Exact rational roots (with multiplicity) of `Σ c_k λ^k`, and the deflated rest.
/// Gives up on coefficients too large to factor quickly (returns no roots).
pub(crate) fn rational_roots(coeffs: &[Rational]) -> (Vec<(Rational, usize)>, Vec<Rational>) {
    let mut c = coeffs.to_vec();
    let mut roots: Vec<(Rational, usize)> = Vec::new();
    let push = |roots: &mut Vec<(Rational, usize)>, r: Rational| {
        if let Some(e) = roots.iter_mut().find(|e| e.0 == r) {
            e.1 += 1;
        } else {
            roots.push((r, 1));
        }
    };
    while c.len() > 1 && c[0].is_zero() {
        c.remove(0);
        push(&mut roots, Rational::ZERO);
    }
    loop {
        if c.len() <= 1 {
            break;
        }
        let Some(ints) = to_integers(&c) else { break };
        let (a0, an) = (ints[0], ints[ints.len() - 1]);
        let (Some(ps), Some(qs)) = (divisors(a0), divisors(an)) else {
            break;
        };
        let mut hit = None;
        'search: for &q in &qs {
            for &p in &ps {
                for s in [1i128, -1] {
                    let Some(r) = Rational::new(s * p, q) else {
                        continue;
                    };
                    if let Some(d) = deflate(&c, &r) {
                        hit = Some((r, d));
                        break 'search;
                    }
                }
            }
        }
        match hit {
            Some((r, d)) => {
                push(&mut roots, r);
                c = d;
            }
            None => break,
        }
    }
    (roots, c)
}

/// Clears denominators: integer coefficients with the same roots (`None` past `i128`: such
/// coefficients are too large to factor quickly anyway).
fn to_integers(c: &[Rational]) -> Option<Vec<i128>> {
    let parts: Vec<(i64, i64)> = c.iter().map(Rational::small).collect::<Option<_>>()?;
    let mut l: i128 = 1;
    for &(_, d) in &parts {
        let d = d as i128;
        l = l.checked_mul(d / gcd(l, d))?;
    }
    parts
        .iter()
        .map(|&(n, d)| (n as i128).checked_mul(l / d as i128))
        .collect()
}

/// gcd, at least 1 (a divisor).
fn gcd(a: i128, b: i128) -> i128 {
    let g = pdyn_expr::number::gcd(a.unsigned_abs(), b.unsigned_abs());
    g.clamp(1, i128::MAX as u128) as i128
}

/// Positive divisors of `n` (`None` when `n` is too large to enumerate quickly).
fn divisors(n: i128) -> Option<Vec<i128>> {
    let n = n.abs();
    if n == 0 || n > 1_000_000_000_000 {
        return None;
    }
    let mut out = Vec::new();
    let mut d = 1i128;
    while d * d <= n {
        if n % d == 0 {
            out.push(d);
            if d * d != n {
                out.push(n / d);
            }
        }
        d += 1;
    }
    out.sort_unstable();
    Some(out)
}

/// `c / (λ - r)` when `r` is an exact root (synthetic division), else `None`.
fn deflate(c: &[Rational], r: &Rational) -> Option<Vec<Rational>> {
    let n = c.len() - 1;
    let mut q = vec![Rational::ZERO; n];
    let mut acc = c[n].clone();
    for k in (0..n).rev() {
        let next = c[k].checked_add(&acc.checked_mul(r)?)?;
        q[k] = acc;
        acc = next;
    }
    acc.is_zero().then_some(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aberth_finds_simple_double_and_complex_roots() {
        // (λ+1)^2 (λ^2 + 4) (λ - 3) = expand
        let poly = |z: f64| (z + 1.0).powi(2) * (z * z + 4.0) * (z - 3.0);
        // coefficients by interpolation-free expansion
        let c = [-12.0, -20.0, -7.0, -1.0, -1.0, 1.0];
        for x in [0.5f64, -2.0, 1.3] {
            let v: f64 = c
                .iter()
                .enumerate()
                .map(|(k, a)| a * x.powi(k as i32))
                .sum();
            assert!((v - poly(x)).abs() < 1e-9);
        }
        let g = numeric_roots(&c);
        assert_eq!(g.len(), 3, "{g:?}");
        assert!((g[0].re + 1.0).abs() < 1e-6 && g[0].mult == 2 && g[0].im == 0.0);
        assert!(g[1].re.abs() < 1e-9 && (g[1].im - 2.0).abs() < 1e-9 && g[1].mult == 1);
        assert!((g[2].re - 3.0).abs() < 1e-9 && g[2].mult == 1);
    }

    #[test]
    fn rational_roots_are_exact_and_deflate() {
        // 2λ^3 - 3λ^2 - 3λ + 2 = (λ-2)(2λ-1)(λ+1)
        let c = [2, -3, -3, 2].map(Rational::int);
        let (r, rest) = rational_roots(&c);
        assert_eq!(rest.len(), 1);
        let mut vals: Vec<f64> = r.iter().map(|x| x.0.to_f64()).collect();
        vals.sort_by(f64::total_cmp);
        assert_eq!(vals, vec![-1.0, 0.5, 2.0]);
    }
}
