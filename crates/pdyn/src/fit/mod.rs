//! `pdyn fit` (Python's `Model.fit`): a model's parameters and initial values fitted to
//! measured runs by least squares.
//!
//! The weighted residuals `r = (y_model(t_i; θ) − y_measured,i) / σ_i` of every measured
//! column of every experiment are minimised over the free quantities `θ` by
//! Levenberg–Marquardt within bounds ([`lm`]). The Jacobian `∂r/∂θ` comes from the forward
//! sensitivity equations derived symbolically from the model and compiled with it
//! ([`sensitivity`]), integrated with the state by DOP853 to the sample times — no finite
//! differences. Parameters are shared by the experiments; a free initial value is estimated
//! for each experiment.
//!
//! At the minimum, the covariance is `s² (JᵀJ)⁻¹` with `s² = χ²/(m − n)` (the residual
//! variance: SciPy's `curve_fit` default), or `(JᵀJ)⁻¹` when the σ are absolute; the standard
//! errors are its diagonal's square roots and the correlations its normalised entries. `JᵀJ`
//! is inverted through the SVD of `J` with unit columns ([`svd`]); a singular value below
//! [`RANK_TOLERANCE`] of the largest makes the problem not identifiable, and the quantities
//! that weigh in its singular vector are named.

pub mod experiment;
pub mod lm;
#[cfg(feature = "plots")]
mod plots;
pub mod report;
pub mod sensitivity;
pub mod svd;

pub use experiment::{Experiment, Observed};
pub use report::{summary_json, summary_text};

use crate::Error;
use pdyn_jit::JitMode;
use pdyn_mech::Model;
use pdyn_ode::{solve, Method, Options};
use sensitivity::Sensitivities;

/// A singular value of the scaled Jacobian below this fraction of the largest: the data cannot
/// tell the quantities of its singular vector apart.
pub const RANK_TOLERANCE: f64 = 1e-8;

/// What to fit and how; defaults in one `impl Default`.
#[derive(Clone, Debug)]
pub struct FitRequest {
    /// The free quantities: parameter names, `initial.x` (a coordinate's initial value),
    /// `rate.x` (its initial rate).
    pub free: Vec<String>,
    /// Bounds by name (`lower`, `upper`, each may be infinite). Default: none.
    pub bounds: Vec<(String, f64, f64)>,
    /// The standard deviation of every sample of a column (`x`, `x'`), where the file has no
    /// `sigma_x` column. Default: 1 (unweighted).
    pub sigma: Vec<(String, f64)>,
    /// Whether the σ are absolute (covariance `(JᵀJ)⁻¹`) rather than relative (scaled by
    /// χ²/dof). Default: false.
    pub absolute_sigma: bool,
    /// Relative tolerance of the integrations. Default: 1e-10.
    pub rtol: f64,
    /// Absolute tolerance of the integrations. Default: 1e-12.
    pub atol: f64,
    /// Levenberg–Marquardt's stopping rules.
    pub lm: lm::Settings,
    /// Native code or the interpreter for the sensitivity equations. Default: `Auto`.
    pub jit: JitMode,
}

impl Default for FitRequest {
    fn default() -> FitRequest {
        FitRequest {
            free: Vec::new(),
            bounds: Vec::new(),
            sigma: Vec::new(),
            absolute_sigma: false,
            rtol: 1e-10,
            atol: 1e-12,
            lm: lm::Settings::default(),
            jit: JitMode::Auto,
        }
    }
}

/// One fitted quantity.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// `c`, `initial.x`, `initial.x[run2]` (several experiments).
    pub name: String,
    /// The estimate.
    pub value: f64,
    /// Its standard error (infinite when not identifiable).
    pub stderr: f64,
    /// The starting value.
    pub start: f64,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
}

/// A measured column with the fitted model beside it.
#[derive(Clone, Debug)]
pub struct ColumnFit {
    /// `x`, `x'`.
    pub name: String,
    /// Measured values.
    pub data: Vec<f64>,
    /// The model at the estimates.
    pub model: Vec<f64>,
    /// Each sample's σ (1 when unweighted).
    pub sigma: Vec<f64>,
    /// RMS of `model − data` (the column's units).
    pub rms: f64,
}

/// One experiment's fit.
#[derive(Clone, Debug)]
pub struct ExperimentFit {
    /// The experiment's name.
    pub name: String,
    /// Its file.
    pub origin: String,
    /// The sample times.
    pub t: Vec<f64>,
    /// Its columns.
    pub columns: Vec<ColumnFit>,
}

/// Quantities the data cannot tell apart (a singular value of the scaled Jacobian below
/// [`RANK_TOLERANCE`] of the largest).
#[derive(Clone, Debug)]
pub struct Degeneracy {
    /// The quantities weighing in the singular vector (|component| ≥ 0.1).
    pub names: Vec<String>,
    /// The singular value over the largest.
    pub ratio: f64,
}

/// The result of a fit.
#[derive(Clone, Debug)]
pub struct FitResult {
    /// The model file.
    pub origin: String,
    /// The estimates, in the order of the free quantities (initial values per experiment).
    pub estimates: Vec<Estimate>,
    /// Correlation matrix, row-major (NaN where not identifiable).
    pub corr: Vec<f64>,
    /// Covariance matrix, row-major.
    pub cov: Vec<f64>,
    /// Weighted residuals, experiment by experiment, column by column, sample by sample.
    pub fun: Vec<f64>,
    /// `∂fun/∂θ`, row-major (`fun.len() × estimates.len()`).
    pub jac: Vec<f64>,
    /// `½ Σ fun²`.
    pub cost: f64,
    /// `Σ fun²`.
    pub chi2: f64,
    /// Degrees of freedom: samples − free quantities.
    pub dof: usize,
    /// Why the minimisation stopped.
    pub status: lm::Status,
    /// Evaluations of the residuals and Jacobian (each one integration per experiment).
    pub evaluations: usize,
    /// Accepted steps.
    pub iterations: usize,
    /// Per experiment: data, model, residual statistics.
    pub experiments: Vec<ExperimentFit>,
    /// Quantities the data cannot tell apart.
    pub unidentifiable: Vec<Degeneracy>,
    /// Whether the covariance used absolute σ.
    pub absolute_sigma: bool,
}

impl FitResult {
    /// χ² per degree of freedom.
    pub fn reduced_chi2(&self) -> f64 {
        self.chi2 / self.dof as f64
    }
}

/// What is free, resolved against the model.
struct Free {
    params: Vec<usize>,
    /// State indices of the free initial values.
    initials: Vec<usize>,
    initial_names: Vec<String>,
}

fn resolve_free(model: &Model, state_names: &[String], free: &[String]) -> Result<Free, Error> {
    let n = state_names.len() / 2;
    let mut out = Free {
        params: Vec::new(),
        initials: Vec::new(),
        initial_names: Vec::new(),
    };
    if free.is_empty() {
        return Err(Error::argument(
            "--free",
            "name the quantities to fit: parameters (`c`), initial values (`initial.x`) or \
             initial rates (`rate.x`)",
        ));
    }
    let mut seen: Vec<&str> = Vec::new();
    for name in free {
        let name = name.trim();
        if seen.contains(&name) {
            return Err(Error::argument(
                "--free",
                format!("`{name}` is listed twice"),
            ));
        }
        seen.push(name);
        let coord = |c: &str| state_names[..n].iter().position(|s| s == c);
        if let Some(c) = name.strip_prefix("initial.") {
            let j = coord(c).ok_or_else(|| unknown_coordinate(name, c, &state_names[..n]))?;
            out.initials.push(j);
            out.initial_names.push(name.to_string());
        } else if let Some(c) = name.strip_prefix("rate.") {
            let j = coord(c).ok_or_else(|| unknown_coordinate(name, c, &state_names[..n]))?;
            out.initials.push(n + j);
            out.initial_names.push(name.to_string());
        } else if let Some(i) = model.parameters.iter().position(|p| p.name == name) {
            if model.parameters[i].definition.is_some() {
                return Err(Error::argument(
                    "--free",
                    format!(
                        "`{name}` is computed from other parameters in {}: free those, or give \
                         it a number with --set {name}=VALUE to fit it on its own",
                        model.origin
                    ),
                ));
            }
            out.params.push(i);
        } else {
            let params: Vec<&str> = model.parameters.iter().map(|p| p.name.as_str()).collect();
            return Err(Error::argument(
                "--free",
                format!(
                    "`{name}` is not a parameter of {} (parameters: {}; initial values: {})",
                    model.origin,
                    params.join(", "),
                    state_names[..n]
                        .iter()
                        .map(|s| format!("initial.{s}, rate.{s}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    Ok(out)
}

fn unknown_coordinate(name: &str, c: &str, coords: &[String]) -> Error {
    Error::argument(
        "--free",
        format!(
            "`{name}`: `{c}` is not a coordinate solved for (coordinates: {})",
            coords.join(", ")
        ),
    )
}

/// The residuals of every experiment and their Jacobian by the sensitivity equations.
struct Problem<'a> {
    sens: &'a Sensitivities,
    base: Vec<f64>,
    experiments: &'a [Experiment],
    /// Per experiment, per column: state index and each sample's weight 1/σ.
    columns: Vec<Vec<(usize, Vec<f64>)>>,
    m: usize,
    opts: Options,
    origin: String,
}

impl Problem<'_> {
    fn parameters(&self, x: &[f64]) -> Vec<f64> {
        let mut p = self.base.clone();
        for (c, &i) in self.sens.params.iter().enumerate() {
            p[i] = x[c];
        }
        self.sens.derived.apply(&mut p, &self.sens.params);
        p
    }
}

impl lm::Residuals for Problem<'_> {
    type Error = Error;

    fn n_residuals(&self) -> usize {
        self.m
    }

    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: &mut [f64]) -> Result<(), Error> {
        let s = self.sens;
        let (dim, k, mi) = (s.dim, s.params.len(), s.initials.len());
        let p = self.parameters(x);
        let m = self.m;
        jac.fill(0.0);
        let mut row = 0;
        for (e, exp) in self.experiments.iter().enumerate() {
            let ic = &x[k + e * mi..k + (e + 1) * mi];
            let z0 = s.initial_state(&p, ic);
            let nz = z0.len();
            let t_last = *exp.t.last().unwrap_or(&0.0);
            let zs: Vec<f64> = if t_last > 0.0 {
                let sys = s.system(&p);
                self.opts.t_eval = Some(exp.t.clone());
                let sol =
                    solve(Method::Dop853, &sys, (0.0, t_last), &z0, &self.opts).map_err(|e| {
                        Error::Fit {
                            origin: self.origin.clone(),
                            message: format!(
                            "the integration of experiment `{}` failed at these values ({}): {e}",
                            exp.name,
                            x.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(", ")
                        ),
                        }
                    })?;
                if sol.t.len() != exp.t.len() {
                    return Err(Error::Fit {
                        origin: self.origin.clone(),
                        message: format!(
                            "the integration of experiment `{}` stopped at t = {}",
                            exp.name,
                            sol.t.last().unwrap_or(&0.0)
                        ),
                    });
                }
                sol.y
            } else {
                z0.clone()
            };
            for (obs, (j, w)) in exp.observed.iter().zip(&self.columns[e]) {
                for (i, (&d, &wi)) in obs.values.iter().zip(w).enumerate() {
                    let z = &zs[i * nz..(i + 1) * nz];
                    r[row] = (z[*j] - d) * wi;
                    for c in 0..k {
                        jac[c * m + row] = z[dim * (1 + c) + j] * wi;
                    }
                    for c in 0..mi {
                        jac[(k + e * mi + c) * m + row] = z[dim * (1 + k + c) + j] * wi;
                    }
                    row += 1;
                }
            }
        }
        Ok(())
    }
}

/// Fits `model` (its parameter values are the starting point) to `experiments`.
pub fn fit(
    model: &mut Model,
    experiments: &[Experiment],
    req: &FitRequest,
) -> Result<FitResult, Error> {
    let origin = model.origin.clone();
    if pdyn_mech::hybrid::is_hybrid(model) {
        return Err(Error::argument(
            "--free",
            format!(
                "{origin} has contacts or event actions: fitting a hybrid model is not supported"
            ),
        ));
    }
    if experiments.is_empty() {
        return Err(Error::argument("--data", "give at least one data file"));
    }
    let d =
        pdyn_mech::derive(model, &crate::sim::run_options()).map_err(|error| Error::Derive {
            origin: origin.clone(),
            error,
        })?;
    let free = resolve_free(model, &d.state_names, &req.free)?;
    let sens = Sensitivities::new(model, &d, &free.params, &free.initials, req.jit)?;
    let (k, mi) = (free.params.len(), free.initials.len());
    let n_exp = experiments.len();
    // Names, starts and bounds of θ = (parameters, then each experiment's initial values).
    let mut names: Vec<String> = free
        .params
        .iter()
        .map(|&i| model.parameters[i].name.clone())
        .collect();
    let base: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
    let mut x0: Vec<f64> = free.params.iter().map(|&i| base[i]).collect();
    let start_state = sens.initial_state(&base, &[]);
    for exp in experiments {
        for (c, &j) in free.initials.iter().enumerate() {
            names.push(if n_exp > 1 {
                format!("{}[{}]", free.initial_names[c], exp.name)
            } else {
                free.initial_names[c].clone()
            });
            x0.push(start_state[j]);
        }
    }
    let n_free = k + mi * n_exp;
    let base_name = |c: usize| {
        if c < k {
            names[c].clone()
        } else {
            free.initial_names[(c - k) % mi.max(1)].clone()
        }
    };
    let (mut lo, mut hi) = (vec![f64::NEG_INFINITY; n_free], vec![f64::INFINITY; n_free]);
    for (name, l, h) in &req.bounds {
        if l.is_nan() || h.is_nan() || l >= h {
            return Err(Error::argument(
                "--bounds",
                format!("`{name}`: the lower bound {l} must be below the upper bound {h}"),
            ));
        }
        let mut found = false;
        for c in 0..n_free {
            if base_name(c) == *name {
                lo[c] = *l;
                hi[c] = *h;
                found = true;
            }
        }
        if !found {
            return Err(Error::argument(
                "--bounds",
                format!("`{name}` is not free (free: {})", req.free.join(", ")),
            ));
        }
    }
    for (c, x) in x0.iter_mut().enumerate() {
        if !(*x > lo[c] && *x < hi[c]) {
            // A start on or outside a bound: moved inside (Levenberg–Marquardt needs room).
            *x = if lo[c].is_finite() && hi[c].is_finite() {
                0.5 * (lo[c] + hi[c])
            } else if lo[c].is_finite() {
                lo[c] + 1e-3 * lo[c].abs().max(1.0)
            } else {
                hi[c] - 1e-3 * hi[c].abs().max(1.0)
            };
        }
    }
    // Weights.
    let mut columns = Vec::new();
    let mut m = 0;
    for (name, s) in &req.sigma {
        if !(*s > 0.0 && s.is_finite()) {
            return Err(Error::argument(
                "--sigma",
                format!("`{name}`: σ must be a positive number, not {s}"),
            ));
        }
        if !d.state_names.contains(name) {
            return Err(Error::argument(
                "--sigma",
                format!(
                    "`{name}` is not a coordinate or rate (the state is {})",
                    d.state_names.join(", ")
                ),
            ));
        }
    }
    for exp in experiments {
        let mut cols = Vec::new();
        for obs in &exp.observed {
            let j = d.state_names.iter().position(|s| *s == obs.name).ok_or_else(|| {
                Error::argument(
                    "--data",
                    format!(
                        "{}: the column `{}` is not a coordinate or rate of {origin} (the state is {})",
                        exp.origin,
                        obs.name,
                        d.state_names.join(", ")
                    ),
                )
            })?;
            let given = req.sigma.iter().find(|(n, _)| *n == obs.name).map(|p| p.1);
            let w: Vec<f64> = match &obs.sigma {
                Some(s) => s.iter().map(|v| 1.0 / v).collect(),
                None => vec![1.0 / given.unwrap_or(1.0); obs.values.len()],
            };
            m += w.len();
            cols.push((j, w));
        }
        columns.push(cols);
    }
    if m <= n_free {
        return Err(Error::argument(
            "--data",
            format!(
                "{m} measured value(s) for {n_free} free quantities: a fit needs more samples than unknowns"
            ),
        ));
    }
    let opts = Options {
        rtol: req.rtol.into(),
        atol: req.atol.into(),
        ..Options::default()
    };
    let mut problem = Problem {
        sens: &sens,
        base,
        experiments,
        columns,
        m,
        opts,
        origin: origin.clone(),
    };
    // A quantity whose column of J is zero at the start does not affect what was measured.
    {
        let mut r = vec![0.0; m];
        let mut jac = vec![0.0; m * n_free];
        lm::Residuals::eval(&mut problem, &x0, &mut r, &mut jac)?;
        for c in 0..n_free {
            if jac[c * m..(c + 1) * m].iter().all(|&v| v == 0.0) {
                let measured: Vec<String> = experiments
                    .iter()
                    .flat_map(|e| e.observed.iter().map(|o| format!("`{}`", o.name)))
                    .collect::<std::collections::BTreeSet<_>>()
                    .into_iter()
                    .collect();
                return Err(Error::argument(
                    "--free",
                    format!(
                        "`{}` does not affect the measured columns ({}) at its starting value: \
                         the data cannot determine it",
                        names[c],
                        measured.join(", ")
                    ),
                ));
            }
        }
    }
    let min = lm::minimize(&mut problem, &x0, &lo, &hi, &req.lm)?;
    // Statistics at the minimum.
    let chi2: f64 = min.r.iter().map(|v| v * v).sum();
    let dof = m - n_free;
    let mut scale = vec![0.0; n_free];
    let mut scaled = min.jac.clone();
    for c in 0..n_free {
        let col = &mut scaled[c * m..(c + 1) * m];
        let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
        scale[c] = if norm > 0.0 { norm } else { 1.0 };
        col.iter_mut().for_each(|v| *v /= scale[c]);
    }
    let svd = svd::Svd::new(&scaled, m, n_free);
    let smax = svd.max();
    let mut unidentifiable = Vec::new();
    let mut involved = vec![false; n_free];
    for kk in 0..n_free {
        let ratio = svd.sigma[kk] / smax;
        if ratio < RANK_TOLERANCE {
            let mut group = Vec::new();
            for c in 0..n_free {
                if svd.v[c * n_free + kk].abs() >= 0.1 {
                    group.push(names[c].clone());
                    involved[c] = true;
                }
            }
            unidentifiable.push(Degeneracy {
                names: group,
                ratio,
            });
        }
    }
    let inv = svd.normal_inverse(RANK_TOLERANCE * smax);
    let s2 = if req.absolute_sigma {
        1.0
    } else {
        chi2 / dof as f64
    };
    let mut cov = vec![0.0; n_free * n_free];
    for i in 0..n_free {
        for j in 0..n_free {
            cov[i * n_free + j] = s2 * inv[i * n_free + j] / (scale[i] * scale[j]);
        }
    }
    let stderr: Vec<f64> = (0..n_free)
        .map(|i| {
            if involved[i] {
                f64::INFINITY
            } else {
                cov[i * n_free + i].sqrt()
            }
        })
        .collect();
    let mut corr = vec![0.0; n_free * n_free];
    for i in 0..n_free {
        for j in 0..n_free {
            corr[i * n_free + j] = if involved[i] || involved[j] {
                f64::NAN
            } else if i == j {
                1.0
            } else {
                cov[i * n_free + j] / (stderr[i] * stderr[j])
            };
        }
    }
    let mut jac_rows = vec![0.0; m * n_free];
    for c in 0..n_free {
        for i in 0..m {
            jac_rows[i * n_free + c] = min.jac[c * m + i];
        }
    }
    // The data beside the model (model = data + r σ).
    let mut row = 0;
    let mut fits = Vec::new();
    for (e, exp) in experiments.iter().enumerate() {
        let mut cols = Vec::new();
        for (obs, (_, w)) in exp.observed.iter().zip(&problem.columns[e]) {
            let sigma: Vec<f64> = w.iter().map(|v| 1.0 / v).collect();
            let model_values: Vec<f64> = obs
                .values
                .iter()
                .zip(&sigma)
                .enumerate()
                .map(|(i, (d, s))| d + min.r[row + i] * s)
                .collect();
            row += obs.values.len();
            let rms = (model_values
                .iter()
                .zip(&obs.values)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / obs.values.len() as f64)
                .sqrt();
            cols.push(ColumnFit {
                name: obs.name.clone(),
                data: obs.values.clone(),
                model: model_values,
                sigma,
                rms,
            });
        }
        fits.push(ExperimentFit {
            name: exp.name.clone(),
            origin: exp.origin.clone(),
            t: exp.t.clone(),
            columns: cols,
        });
    }
    let estimates = (0..n_free)
        .map(|c| Estimate {
            name: names[c].clone(),
            value: min.x[c],
            stderr: stderr[c],
            start: x0[c],
            lower: lo[c],
            upper: hi[c],
        })
        .collect();
    Ok(FitResult {
        origin,
        estimates,
        corr,
        cov,
        fun: min.r,
        jac: jac_rows,
        cost: min.cost,
        chi2,
        dof,
        status: min.status,
        evaluations: min.evaluations,
        iterations: min.iterations,
        experiments: fits,
        unidentifiable,
        absolute_sigma: req.absolute_sigma,
    })
}

/// Writes `fit_<experiment>.csv` (t, each column measured, fitted and its residual), the
/// summary (`summary.json`) and, with plots, `fit.{svg,png}` and `residuals.{svg,png}` into
/// `dir`.
pub fn write_outputs(res: &FitResult, dir: &std::path::Path, plots: bool) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create", e))?;
    for exp in &res.experiments {
        let mut table = crate::data::Table::default();
        table.names.push("t".into());
        table.columns.push(exp.t.clone());
        for c in &exp.columns {
            table.names.push(c.name.clone());
            table.columns.push(c.data.clone());
            table.names.push(format!("{}_fit", c.name));
            table.columns.push(c.model.clone());
            table.names.push(format!("{}_residual", c.name));
            table
                .columns
                .push(c.model.iter().zip(&c.data).map(|(a, b)| a - b).collect());
        }
        table.write(&dir.join(format!("fit_{}.csv", exp.name)))?;
    }
    let path = dir.join("summary.json");
    let text = serde_json::to_string_pretty(&summary_json(res)).unwrap_or_default();
    std::fs::write(&path, text + "\n").map_err(|e| Error::io(&path, "write", e))?;
    if plots {
        #[cfg(feature = "plots")]
        plots::write(res, dir)?;
    }
    Ok(())
}
