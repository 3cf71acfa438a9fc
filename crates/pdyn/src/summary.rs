//! The part of `summary.json` every model kind shares (documented in `docs/summary.md`):
//! `kind`, `model`, `ok`, `failure`, `warnings`, `stats.steps` and `monitors`, one entry per
//! quantity the run should conserve, with the same fields whether it is a pendulum's energy,
//! an orbit's angular momentum or an MD run's total energy. Each kind adds its own fields
//! beside these.

use crate::output::json_num;
use serde_json::{json, Map, Value};

/// The model kinds, as `kind` names them.
pub const KINDS: [&str; 3] = ["mechanics", "nbody", "md"];

/// One monitored quantity of a run.
#[derive(Clone, Debug)]
pub struct Conserved<'a> {
    /// `energy`, `angular_momentum`, `momentum.x`, `energy_balance`…
    pub name: &'a str,
    /// Its value at the first output.
    pub initial: f64,
    /// Its value at the last output (`None` when no output was kept).
    pub final_value: Option<f64>,
    /// Largest change from `initial`, divided by `scale` when `relative`.
    pub drift: f64,
    /// Whether `drift` is relative (false only when the scale is zero).
    pub relative: bool,
    /// The scale the change is measured against.
    pub scale: f64,
    /// The drift the run tolerates before it warns.
    pub tolerance: f64,
    /// Whether the model's physics conserves it (a forced system's energy is monitored but
    /// not conserved).
    pub conserved: bool,
}

impl Conserved<'_> {
    /// The verdict: not a conserved quantity, or one that drifted at most `tolerance` (a NaN
    /// drift is not ok).
    pub fn ok(&self) -> bool {
        !self.conserved || self.drift <= self.tolerance
    }

    /// The entry of `monitors`.
    pub fn to_json(&self) -> Value {
        json!({
            "name": self.name,
            "initial": json_num(self.initial),
            "final": self.final_value.map(json_num),
            "drift": json_num(self.drift),
            "relative": self.relative,
            "scale": json_num(self.scale),
            "tolerance": json_num(self.tolerance),
            "conserved": self.conserved,
            "ok": self.ok(),
        })
    }
}

/// The shared fields; `stats` must hold at least `steps`, `extra` holds the kind's own.
pub fn common(
    kind: &str,
    model: &str,
    failure: Option<String>,
    warnings: &[String],
    monitors: &[Conserved<'_>],
    stats: Value,
    extra: Value,
) -> Value {
    debug_assert!(KINDS.contains(&kind) && stats.get("steps").is_some());
    let mut m = Map::new();
    m.insert("kind".into(), json!(kind));
    m.insert("model".into(), json!(model));
    m.insert("ok".into(), json!(failure.is_none()));
    m.insert("failure".into(), json!(failure));
    m.insert("warnings".into(), json!(warnings));
    m.insert(
        "monitors".into(),
        Value::Array(monitors.iter().map(Conserved::to_json).collect()),
    );
    m.insert("stats".into(), stats);
    if let Value::Object(extra) = extra {
        for (k, v) in extra {
            m.entry(k).or_insert(v);
        }
    }
    Value::Object(m)
}

/// The names of the shared fields, and those of a monitor entry (what `docs/summary.md`
/// documents and the schema test checks).
pub const COMMON_FIELDS: [&str; 7] = [
    "kind", "model", "ok", "failure", "warnings", "monitors", "stats",
];
/// See [`COMMON_FIELDS`].
pub const MONITOR_FIELDS: [&str; 9] = [
    "name",
    "initial",
    "final",
    "drift",
    "relative",
    "scale",
    "tolerance",
    "conserved",
    "ok",
];

/// Marks `sum` as the summary of an interrupted run (`status: "interrupted"`, `ok: false`,
/// `t_reached`, the error) and returns the error (exit code 4).
pub fn interrupted(sum: &mut Value, origin: &str, time: f64) -> crate::Error {
    let e = crate::Error::Interrupted {
        origin: origin.to_string(),
        time,
    };
    sum["status"] = json!("interrupted");
    sum["ok"] = json!(false);
    sum["failure"] = json!(e.to_string());
    sum["t_reached"] = json_num(time);
    sum["error"] = e.to_json()["error"].clone();
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_and_fields() {
        let mut c = Conserved {
            name: "energy",
            initial: -1.0,
            final_value: Some(-1.0 + 1e-9),
            drift: 1e-9,
            relative: true,
            scale: 1.0,
            tolerance: 5e-3,
            conserved: true,
        };
        assert!(c.ok());
        c.drift = f64::NAN;
        assert!(!c.ok());
        c.conserved = false;
        assert!(c.ok());
        let v = common(
            "md",
            "m",
            Some("x".into()),
            &[],
            &[c],
            json!({"steps": 3}),
            json!({"dt": 1}),
        );
        for f in COMMON_FIELDS {
            assert!(v.get(f).is_some(), "{f}");
        }
        assert_eq!(v["ok"], false);
        assert_eq!(v["dt"], 1);
        for f in MONITOR_FIELDS {
            assert!(v["monitors"][0].get(f).is_some(), "{f}");
        }
    }
}
