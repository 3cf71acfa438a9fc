//! What `pdyn fit` prints: the estimates with standard errors, the correlation matrix, the
//! residual statistics and the warnings, as text or JSON.

use super::FitResult;
use crate::output::json_num;
use serde_json::json;
use std::fmt::Write;

/// The fit as JSON (`pdyn fit --json`, `summary.json`).
pub fn summary_json(res: &FitResult) -> serde_json::Value {
    let n = res.estimates.len();
    let corr: Vec<Vec<serde_json::Value>> = (0..n)
        .map(|i| (0..n).map(|j| json_num(res.corr[i * n + j])).collect())
        .collect();
    let experiments: Vec<serde_json::Value> = res
        .experiments
        .iter()
        .map(|e| {
            json!({
                "name": e.name,
                "file": e.origin,
                "samples": e.t.len(),
                "rms": e.columns.iter().map(|c| (c.name.clone(), json_num(c.rms))).collect::<serde_json::Map<_, _>>(),
            })
        })
        .collect();
    json!({
        "model": res.origin,
        "estimates": res.estimates.iter().map(|e| json!({
            "name": e.name,
            "value": json_num(e.value),
            "stderr": json_num(e.stderr),
            "start": json_num(e.start),
            "lower": json_num(e.lower),
            "upper": json_num(e.upper),
        })).collect::<Vec<_>>(),
        "correlation": corr,
        "cost": json_num(res.cost),
        "chi2": json_num(res.chi2),
        "dof": res.dof,
        "reduced_chi2": json_num(res.reduced_chi2()),
        "absolute_sigma": res.absolute_sigma,
        "status": res.status.code(),
        "message": res.status.message(),
        "success": res.status.converged(),
        "evaluations": res.evaluations,
        "iterations": res.iterations,
        "experiments": experiments,
        "unidentifiable": res.unidentifiable.iter().map(|d| json!({
            "quantities": d.names,
            "singular_value_ratio": json_num(d.ratio),
        })).collect::<Vec<_>>(),
        "warnings": warnings(res),
    })
}

/// The warnings of a fit: not identifiable, not converged.
pub fn warnings(res: &FitResult) -> Vec<String> {
    let mut w = Vec::new();
    for d in &res.unidentifiable {
        w.push(format!(
            "not identifiable: the data cannot tell {} apart (a singular value of the scaled \
             Jacobian is {:.1e} of the largest); fix one of them (--set) or measure more",
            d.names
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", "),
            d.ratio
        ));
    }
    if !res.status.converged() {
        w.push(format!(
            "the fit did not converge: {} (raise the budget, or start nearer with --set)",
            res.status.message()
        ));
    }
    for e in &res.estimates {
        if e.value <= e.lower || e.value >= e.upper {
            w.push(format!(
                "`{}` is at its bound ({}): its standard error assumes it is not",
                e.name, e.value
            ));
        }
    }
    w
}

/// The fit as text.
pub fn summary_text(res: &FitResult) -> String {
    let mut s = String::new();
    let n = res.estimates.len();
    let width = res
        .estimates
        .iter()
        .map(|e| e.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(9);
    let _ = writeln!(s, "Fit of {} ({})", res.origin, res.status.message());
    let _ = writeln!(
        s,
        "  {:<width$}  {:>16}  {:>12}  {:>9}  {:>16}",
        "quantity", "estimate", "std. error", "rel.", "start"
    );
    for e in &res.estimates {
        let rel = (e.stderr / e.value.abs()) * 100.0;
        let _ = writeln!(
            s,
            "  {:<width$}  {:>16.10e}  {:>12.4e}  {:>8.3}%  {:>16.6e}",
            e.name, e.value, e.stderr, rel, e.start
        );
    }
    if n > 1 {
        let _ = writeln!(s, "Correlation:");
        for i in 0..n {
            let _ = write!(s, "  {:<width$}", res.estimates[i].name);
            for j in 0..=i {
                let _ = write!(s, " {:>7.4}", res.corr[i * n + j]);
            }
            let _ = writeln!(s);
        }
    }
    let samples: usize = res.experiments.iter().map(|e| e.t.len()).sum();
    let _ = writeln!(
        s,
        "Residuals: χ² = {:.6e}, dof = {}, χ²/dof = {:.4e}{}",
        res.chi2,
        res.dof,
        res.reduced_chi2(),
        if res.absolute_sigma {
            " (σ absolute)"
        } else {
            " (standard errors scaled by χ²/dof)"
        }
    );
    for e in &res.experiments {
        let rms: Vec<String> = e
            .columns
            .iter()
            .map(|c| format!("{} {:.4e}", c.name, c.rms))
            .collect();
        let _ = writeln!(
            s,
            "  {} ({} samples): RMS {}",
            e.origin,
            e.t.len(),
            rms.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "{} evaluations (residuals and sensitivities), {} steps, {} samples",
        res.evaluations, res.iterations, samples
    );
    for w in warnings(res) {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}
