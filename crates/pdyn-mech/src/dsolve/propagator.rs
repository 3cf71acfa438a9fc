//! Stable evaluation of a closed-form solution: the exact solution of `Σ_k A_k q^(k) = f(t)`
//! as the exponential of one matrix.
//!
//! # Why not evaluate the formula
//!
//! The closed form is a sum of quasi-polynomials whose coefficients are divided differences of
//! `e^{λt}` over the characteristic roots and the forcing's exponents. Written out, two nearby
//! exponents give `F (sin Ωt − (Ω/ω) sin ωt)/(ω² − Ω²)`: each term is huge and their difference
//! is small, so in floating point every digit goes (2 % off at 2·10⁻⁶ from the building's first
//! resonance, 10⁶ times too large at 10⁻⁸). The product form, `expm1`-style differences and the
//! `t sin ωt` limit are the two-node cases of one identity (Opitz): the divided differences of
//! `e^{zt}` over nodes `z_0 … z_n` are the first row of `exp(Z t)`, `Z` bidiagonal with the
//! nodes on its diagonal. Generalised, the whole solution is `z(t) = exp(𝒜 t) z(0)` for the
//! first-order system `𝒜` of the coordinates, their derivatives and the states that generate
//! the forcing (`t^p/p! e^{at} cos bt`, `t^p/p! e^{at} sin bt`), and the scaling-and-squaring
//! Padé exponential (Higham 2005, nalgebra's `exp`) never forms the cancelling differences: it is
//! accurate to about `ε ‖𝒜‖ t` at every forcing frequency, at resonance included.
//!
//! Between output times a step of the same length reuses `exp(𝒜 h)`, so a run of `N` samples
//! costs one exponential and `N` products with the state.

use super::exact::const_value;
use super::linear::{analyze, forcing_groups};
use super::{no_closed_form, DsolveError};
use nalgebra::{DMatrix, DVector};
use pdyn_expr::{Id, Node, Pool, SymId};

/// Largest first-order state (coordinates' derivatives and forcing generators) evaluated this
/// way: the exponential of an `n × n` matrix takes about `20 · 2n³` operations (0.3 s at 800).
pub const MAX_STATE: usize = 800;

/// The exact solution of a linear constant-coefficient system at numeric coefficients,
/// evaluated as `exp(𝒜 t) z(0)` (see the module documentation).
#[derive(Clone, Debug)]
pub struct Propagator {
    /// `𝒜`: `dz/dt = 𝒜 z`.
    generator: DMatrix<f64>,
    /// `z(0)`.
    initial: DVector<f64>,
    /// Per coordinate, the state index of its value and of its rate (`None` when the rate is
    /// not a state: a first-order equation, whose rate is read from `𝒜 z`).
    outputs: Vec<(usize, Option<usize>)>,
}

/// Builds the [`Propagator`] of `equations` (each `= 0`; numeric coefficients: substitute the
/// parameters' values first) with `initial` giving every coordinate's value and derivatives
/// below its order at `t = 0`.
///
/// Errors when the equations are not linear with constant numeric coefficients, when the
/// forcing is outside the quasi-polynomial family, when an initial condition is missing, when
/// the highest derivatives cannot be solved for (a singular leading matrix), or when the state
/// exceeds [`MAX_STATE`].
pub fn propagator(
    pool: &mut Pool,
    equations: &[Id],
    coords: &[SymId],
    initial: &[(Id, Id)],
) -> Result<Propagator, DsolveError> {
    let ode = analyze(pool, equations, coords)?;
    let n = coords.len();
    let number = |pool: &mut Pool, e: Id, what: &str| {
        const_value(pool, e).ok_or_else(|| {
            no_closed_form(format!(
                "{what} is not a number (give the parameters values)"
            ))
        })
    };
    // State layout: each coordinate's derivatives below its order, then the forcing's.
    let mut offset = Vec::with_capacity(n);
    let mut size = 0usize;
    for (j, &o) in ode.orders.iter().enumerate() {
        if o == 0 {
            return Err(no_closed_form(format!(
                "`{}` appears without derivatives: an algebraic equation, not an equation of motion",
                pool.name(coords[j])
            )));
        }
        offset.push(size);
        size += o;
    }
    let groups = forcing_groups(pool, &ode.forcing)?;
    let mut group_offset = Vec::with_capacity(groups.len());
    let mut total = size;
    for g in &groups {
        group_offset.push(total);
        let per_power = if g.freq == Pool::ZERO { 1 } else { 2 };
        total = total.saturating_add(per_power * (g.degree() + 1));
    }
    if total > MAX_STATE {
        return Err(no_closed_form(format!(
            "a first-order state of {total} (at most {MAX_STATE} evaluated by the matrix exponential)"
        )));
    }
    // The leading matrix H (coefficients of each coordinate's highest derivative) and the
    // lower-order coefficients, as numbers.
    let mut lead = DMatrix::<f64>::zeros(n, n);
    let mut lower = DMatrix::<f64>::zeros(n, size);
    for i in 0..n {
        for j in 0..n {
            let o = ode.orders[j];
            for k in 0..=o {
                let c = ode.coeffs[i][j][k];
                let v = number(
                    pool,
                    c,
                    &format!("the coefficient of a derivative in equation {}", i + 1),
                )?;
                if k == o {
                    lead[(i, j)] = v;
                } else {
                    lower[(i, offset[j] + k)] = v;
                }
            }
        }
    }
    let lu = lead.clone().lu();
    let Some(lead_inv) = lu.try_inverse().filter(|m| m.iter().all(|v| v.is_finite())) else {
        return Err(no_closed_form(
            "the highest derivatives cannot be solved for (singular leading matrix)",
        ));
    };
    let mut generator = DMatrix::<f64>::zeros(total, total);
    // Chains q^(k)' = q^(k+1) below each coordinate's order.
    for j in 0..n {
        for k in 0..ode.orders[j] - 1 {
            generator[(offset[j] + k, offset[j] + k + 1)] = 1.0;
        }
    }
    // Forcing of each equation on the generator states, and the generators' own dynamics.
    let mut forcing = DMatrix::<f64>::zeros(n, total);
    let mut initial_state = DVector::<f64>::zeros(total);
    for (g, &base) in groups.iter().zip(&group_offset) {
        let rate = number(pool, g.rate, "an exponential rate in the forcing")?;
        let freq = number(pool, g.freq, "a frequency in the forcing")?;
        let trig = g.freq != Pool::ZERO;
        let deg = g.degree();
        // States t^p/p! e^{at} (cos, sin)(bt): cos at base + 2p, sin at base + 2p + 1 (or one
        // state per power without a frequency).
        let cos_at = |p: usize| if trig { base + 2 * p } else { base + p };
        let sin_at = |p: usize| base + 2 * p + 1;
        initial_state[cos_at(0)] = 1.0;
        for p in 0..=deg {
            generator[(cos_at(p), cos_at(p))] = rate;
            if p > 0 {
                generator[(cos_at(p), cos_at(p - 1))] = 1.0;
            }
            if trig {
                generator[(cos_at(p), sin_at(p))] = -freq;
                generator[(sin_at(p), sin_at(p))] = rate;
                generator[(sin_at(p), cos_at(p))] = freq;
                if p > 0 {
                    generator[(sin_at(p), sin_at(p - 1))] = 1.0;
                }
            }
        }
        // t^p = p! (t^p/p!).
        let mut factorial = 1.0;
        for p in 0..=deg {
            if p > 0 {
                factorial *= p as f64;
            }
            for i in 0..n {
                for (poly, at) in [(&g.cos[i], cos_at(p)), (&g.sin[i], sin_at(p))] {
                    if let Some(&c) = poly.get(p) {
                        if c != Pool::ZERO {
                            let v = number(pool, c, "a coefficient of the forcing")?;
                            forcing[(i, at)] += factorial * v;
                        }
                    }
                }
            }
        }
    }
    // Highest derivatives: q_top = H⁻¹ (f − Σ lower q^(k)).
    let mut rhs = forcing;
    for i in 0..n {
        for c in 0..size {
            rhs[(i, c)] -= lower[(i, c)];
        }
    }
    let top = &lead_inv * rhs;
    for j in 0..n {
        let row = offset[j] + ode.orders[j] - 1;
        for c in 0..total {
            generator[(row, c)] += top[(j, c)];
        }
    }
    // Initial conditions.
    let mut given = vec![false; size];
    for &(lhs, value) in initial {
        let Node::Coord(s, k) = *pool.node(lhs) else {
            return Err(DsolveError::Invalid(format!(
                "initial condition `{}`: the left side must be a coordinate or one of its rates",
                pool.to_text(lhs)
            )));
        };
        let Some(j) = coords.iter().position(|&c| c == s) else {
            continue;
        };
        let k = k as usize;
        if k >= ode.orders[j] {
            continue;
        }
        let v = number(
            pool,
            value,
            &format!("the initial value of `{}`", pool.name(s)),
        )?;
        initial_state[offset[j] + k] = v;
        given[offset[j] + k] = true;
    }
    if let Some(missing) = given.iter().position(|g| !g) {
        let j = offset.iter().rposition(|&o| o <= missing).unwrap_or(0);
        return Err(DsolveError::Invalid(format!(
            "no initial value for `{}{}`",
            pool.name(coords[j]),
            "'".repeat(missing - offset[j])
        )));
    }
    if generator.iter().any(|v| !v.is_finite()) {
        return Err(no_closed_form("a coefficient is not finite"));
    }
    let outputs = (0..n)
        .map(|j| (offset[j], (ode.orders[j] >= 2).then_some(offset[j] + 1)))
        .collect();
    Ok(Propagator {
        generator,
        initial: initial_state,
        outputs,
    })
}

impl Propagator {
    /// Number of coordinates.
    pub fn coordinates(&self) -> usize {
        self.outputs.len()
    }

    /// Each coordinate and its rate, `[q_1, q_1', q_2, q_2', …]`, at each time of `times`
    /// (ascending or not), row after row.
    ///
    /// The state is carried from one time to the next by `exp(𝒜 (t_k − t_{k−1}))`; a step
    /// equal to the previous one reuses its exponential (a uniform grid costs one exponential
    /// and a product per sample, and the carried round-off grows like the number of samples
    /// times ε).
    pub fn sample(&self, times: &[f64]) -> Vec<f64> {
        let mut out = Vec::with_capacity(times.len() * 2 * self.outputs.len());
        let mut z = self.initial.clone();
        // The time `z` stands for, and the last step's length and exponential.
        let mut at = 0.0f64;
        let mut step: Option<(f64, DMatrix<f64>)> = None;
        for &t in times {
            let h = t - at;
            if h != 0.0 {
                // A grid's steps differ in their last bits (t_k = k·dt rounded): the same
                // exponential serves while the time it reaches stays within a few ulp of `t`.
                let slack = 8.0 * f64::EPSILON * t.abs().max(at.abs());
                match &step {
                    Some((h0, e)) if (h - h0).abs() <= slack => {
                        z = e * z;
                        at += h0;
                    }
                    _ => {
                        let e = exponential(&self.generator, h);
                        z = &e * z;
                        at = t;
                        step = Some((h, e));
                    }
                }
            }
            let rates = self
                .outputs
                .iter()
                .any(|o| o.1.is_none())
                .then(|| &self.generator * &z);
            for &(value, rate) in &self.outputs {
                out.push(z[value]);
                out.push(match (rate, &rates) {
                    (Some(r), _) => z[r],
                    (None, Some(dz)) => dz[value],
                    (None, None) => f64::NAN,
                });
            }
        }
        out
    }
}

/// Largest 1-norm of `𝒜 h` handed to the exponential. Past it the result overflows anyway
/// (`e^{700}` is about the largest double), and nalgebra's scaling count, `⌈log₂ ‖𝒜h‖⌉`
/// squarings, would saturate to 2⁶⁴ on an infinite norm: a hang, not an answer.
const MAX_EXPONENT_NORM: f64 = 1e300;

/// `exp(𝒜 h)`, or a matrix of NaN when `𝒜 h` is too large to exponentiate (the run then
/// reports its values as not finite, with the time).
fn exponential(generator: &DMatrix<f64>, h: f64) -> DMatrix<f64> {
    let scaled = generator * h;
    let norm = (0..scaled.ncols())
        .map(|j| scaled.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    if norm.is_finite() && norm <= MAX_EXPONENT_NORM {
        scaled.exp()
    } else {
        DMatrix::from_element(scaled.nrows(), scaled.ncols(), f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn build(eq: &str, coords: &[&str], initial: &[(&str, &str)]) -> (Pool, Propagator) {
        let mut pool = Pool::new();
        let e = pool.parse_scalar(eq).unwrap();
        let syms: Vec<SymId> = coords
            .iter()
            .map(|c| pool.find_symbol(c).unwrap())
            .collect();
        // `x'` → the leaf of x of order 1.
        let ics: Vec<(Id, Id)> = initial
            .iter()
            .map(|(l, r)| {
                let name = l.trim_end_matches('\'');
                let order = (l.len() - name.len()) as u8;
                let s = pool.find_symbol(name).unwrap();
                (pool.coord(s, order), pool.parse_scalar(r).unwrap())
            })
            .collect();
        let p = propagator(&mut pool, &[e], &syms, &ics).unwrap();
        (pool, p)
    }

    /// x'' + ω² x = sin(Ωt), x(0) = x'(0) = 0 against the formula in product form
    /// (independent of the exponential), at Ω close to ω and at ω itself.
    #[test]
    fn forced_oscillator_near_and_at_resonance() {
        let w = 3.0f64;
        for omega in [3.5, 3.0 * (1.0 + 1e-7), 3.0 * (1.0 - 1e-12), 3.0] {
            let (_, p) = build(
                &format!("x'' + 9*x - sin({omega:e}*t)"),
                &["x"],
                &[("x", "0"), ("x'", "0")],
            );
            let ts: Vec<f64> = (0..=200).map(|k| 0.1 * k as f64).collect();
            let got = p.sample(&ts);
            for (k, &t) in ts.iter().enumerate() {
                // (sin Ωt − (Ω/ω) sin ωt)/(ω² − Ω²)
                //   = [2 cos((Ω+ω)t/2) sin((Ω−ω)t/2) + (1 − Ω/ω) sin ωt]/((ω−Ω)(ω+Ω)),
                // with sin(d t/2)/d → t/2 as d → 0.
                let d = omega - w;
                let half = if d == 0.0 {
                    -t / 2.0
                } else {
                    -(libm::sin(d * t / 2.0)) / d
                };
                let x = (2.0 * libm::cos((omega + w) * t / 2.0) * half + libm::sin(w * t) / w)
                    / (omega + w);
                assert!(
                    (got[2 * k] - x).abs() < 1e-12,
                    "Ω = {omega}, t = {t}: {} vs {x}",
                    got[2 * k]
                );
            }
        }
    }

    /// A first-order equation: x' = -x + e^{-t} (rate at a root), x(0) = 1 → x = (1 + t) e^{-t}.
    #[test]
    fn first_order_with_forcing_at_its_own_rate() {
        let (_, p) = build("x' + x - exp(-t)", &["x"], &[("x", "1")]);
        let ts = [0.5, 1.0, 2.0, 7.0];
        let got = p.sample(&ts);
        for (k, &t) in ts.iter().enumerate() {
            let x = (1.0 + t) * libm::exp(-t);
            let dx = -t * libm::exp(-t);
            assert!((got[2 * k] - x).abs() < 1e-14 && (got[2 * k + 1] - dx).abs() < 1e-14);
        }
    }

    /// Rates of 1e200 over a time of 1e200: the exponent cannot be formed; the values are
    /// NaN (a failure the run reports), not a hang in the squaring loop.
    #[test]
    fn an_exponent_too_large_gives_nan_not_a_hang() {
        let (_, p) = build("x' - 1e200*x", &["x"], &[("x", "1")]);
        let got = p.sample(&[1e200]);
        assert!(got[0].is_nan(), "{got:?}");
        let got = p.sample(&[1e-300]);
        assert!((got[0] - 1.0).abs() < 1e-12, "{got:?}");
    }

    #[test]
    fn missing_initial_values_and_symbols_are_errors() {
        let mut pool = Pool::new();
        let e = pool.parse_scalar("x'' + k*x").unwrap();
        let x = pool.find_symbol("x").unwrap();
        let (x0, v0) = (pool.coord(x, 0), pool.coord(x, 1));
        let r = propagator(&mut pool, &[e], &[x], &[(x0, Pool::ONE), (v0, Pool::ZERO)]);
        assert!(matches!(r, Err(DsolveError::NoClosedForm(ref m)) if m.contains("not a number")));
        let e = pool.parse_scalar("x'' + 4*x").unwrap();
        let r = propagator(&mut pool, &[e], &[x], &[(x0, Pool::ONE)]);
        assert!(
            matches!(r, Err(DsolveError::Invalid(ref m)) if m.contains("x'")),
            "{r:?}"
        );
    }
}
