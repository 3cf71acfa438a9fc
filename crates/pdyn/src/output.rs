//! Output files of a run: the trajectory table as CSV and the summary as JSON.
//!
//! CSV columns: `t`; every free coordinate `q` then every rate `q'` (state order); each
//! particle's position components `NAME.x`, `NAME.y`, `NAME.z` (components that are identically
//! zero are left out); every reaction by name; the conserved quantities pdyn monitors
//! (`energy`, `angular_momentum.z`, `momentum.x`, ...); the model's `[monitors]`.

use crate::sim::RunResult;
use serde_json::json;
use std::io::Write;
use std::path::Path;

/// Writes the trajectory table.
pub fn write_csv(res: &RunResult, path: &Path) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", res.columns.join(","))?;
    for row in &res.rows {
        let mut line = String::with_capacity(row.len() * 24);
        for (i, x) in row.iter().enumerate() {
            if i > 0 {
                line.push(',');
            }
            line += &format!("{x:.17e}");
        }
        writeln!(f, "{line}")?;
    }
    f.flush()
}

/// The JSON summary: final state, events, monitor drifts, solver statistics, warnings.
pub fn summary(res: &RunResult, model_name: &str, state_names: &[String]) -> serde_json::Value {
    let last = res.rows.last();
    let final_state: serde_json::Map<String, serde_json::Value> = match last {
        Some(r) => res
            .columns
            .iter()
            .zip(r)
            .map(|(c, v)| (c.clone(), json_num(*v)))
            .collect(),
        None => Default::default(),
    };
    json!({
        "model": model_name,
        "method": res.method.to_string(),
        "ok": res.failure.is_none(),
        "failure": res.failure.as_ref().map(|f| f.to_string()),
        "final": final_state,
        "events": res.events.iter().map(|e| json!({
            "name": e.name,
            "t": json_num(e.t),
            "direction": if e.rising { "rising" } else { "falling" },
            "state": state_names.iter().zip(&e.state).map(|(n, v)| (n.clone(), json_num(*v))).collect::<serde_json::Map<_, _>>(),
        })).collect::<Vec<_>>(),
        "monitors": res.monitors.iter().map(|m| json!({
            "name": m.name, "initial": json_num(m.initial), "drift": json_num(m.drift),
            "relative": m.relative, "scale": json_num(m.scale), "conserved": m.conserved,
        })).collect::<Vec<_>>(),
        "stats": {
            "steps": res.stats.steps, "accepted": res.stats.accepted, "rejected": res.stats.rejected,
            "fevals": res.stats.fevals, "jacobians": res.stats.jacobians,
            "lu_decompositions": res.stats.lu_decompositions,
        },
        "outputs": res.rows.len(),
        "warnings": res.warnings,
    })
}

/// A number for JSON: finite values as numbers, NaN and infinities as the strings `"NaN"`,
/// `"inf"`, `"-inf"` (JSON has no such numbers; `null` would hide them).
pub fn json_num(x: f64) -> serde_json::Value {
    if x.is_finite() {
        json!(x)
    } else {
        json!(x.to_string())
    }
}
