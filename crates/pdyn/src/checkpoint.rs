//! Long runs (issue 29): the options that keep their memory bounded and let them continue
//! after a stop ([`LongRun`]), and the checkpoint file ([`Checkpointer`], [`read`]).
//!
//! A checkpoint is a text file, written whole (a temporary file renamed over the old one, so
//! the previous checkpoint stays intact until the new one is complete):
//!
//! ```text
//! pdyn-checkpoint 1
//! <FNV-1a 64 of the body, 16 hex digits> <the body's length in bytes>
//! <the body: JSON>
//! ```
//!
//! The body holds the kind, a hash of the model file's text, the run's options (each by
//! name, so that a restart with other options says which differ), the time and steps reached,
//! the output files' lengths when it was written (a restart truncates each file to its length
//! before appending: no row twice, none lost) and the engine's state, every floating-point
//! number as its bit pattern (`f64::to_bits`), so that the continuation is bit for bit the
//! uninterrupted run. Kinds: N-body (WHFast, IAS15, leapfrog); MD (`crate::md::checkpoint`);
//! mechanics (smooth models by an explicit adaptive pair: `sim::long_run`).

use crate::model_file::ModelFile;
use crate::{Error, Request};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// The first line of a checkpoint file.
pub const MAGIC: &str = "pdyn-checkpoint 1";

/// The checkpoint's file name in the output directory.
pub const FILE_NAME: &str = "checkpoint.json";

/// Wall time between checkpoints when none is asked for (GROMACS's default).
pub const DEFAULT_SECONDS: f64 = 15.0 * 60.0;

/// When checkpoints are written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Every {
    /// Never (`--checkpoint-every off`).
    Off,
    /// After this much wall time (at the next output).
    Seconds(f64),
    /// After this many steps (at the next output).
    Steps(u64),
}

impl Every {
    /// `15min`, `30s`, `2h`, `500steps` (or `500`), `off`.
    pub fn parse(text: &str) -> Result<Every, String> {
        let t = text.trim();
        if t == "off" || t == "0" {
            return Ok(Every::Off);
        }
        let split = t
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(t.len());
        let (num, unit) = t.split_at(split);
        let bad = || {
            format!(
                "`{text}`: expected a wall time (`15min`, `30s`, `2h`), a number of steps (`500steps`) or `off`"
            )
        };
        let x: f64 = num.parse().map_err(|_| bad())?;
        if !(x.is_finite() && x > 0.0) {
            return Err(bad());
        }
        Ok(match unit.trim() {
            "" | "steps" | "step" => {
                if x.fract() != 0.0 {
                    return Err(bad());
                }
                Every::Steps(x as u64)
            }
            "s" | "sec" => Every::Seconds(x),
            "min" | "m" => Every::Seconds(60.0 * x),
            "h" => Every::Seconds(3600.0 * x),
            _ => return Err(bad()),
        })
    }
}

/// How a long run writes and resumes: the command line's defaults and `--checkpoint-every`,
/// `--restart` (Python's runs keep [`LongRun::default`]: the whole history in memory, no
/// checkpoint).
#[derive(Clone, Debug, Default)]
pub struct LongRun {
    /// With `Request::out`: rows go only to the files as the run goes; the result keeps the
    /// first and last output (bounded memory) instead of every row. Ignored with plots.
    pub stream_only: bool,
    /// When to write `checkpoint.json` into `Request::out` (`None`: [`DEFAULT_SECONDS`] of
    /// wall time for a kind that supports checkpoints, when there is an output directory).
    pub checkpoint_every: Option<Every>,
    /// Continue from this checkpoint.
    pub restart: Option<PathBuf>,
}

/// FNV-1a, 64 bits: the checksum of the body and the hash of the model's text.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Floating-point numbers as their bits (exact through JSON).
pub fn bits(xs: &[f64]) -> Value {
    Value::Array(xs.iter().map(|x| json!(x.to_bits())).collect())
}

/// Back from [`bits`].
pub fn unbits(v: &Value) -> Option<Vec<f64>> {
    v.as_array()?
        .iter()
        .map(|b| b.as_u64().map(f64::from_bits))
        .collect()
}

/// One number from its bits.
pub fn unbit(v: &Value) -> Option<f64> {
    v.as_u64().map(f64::from_bits)
}

/// The options that decide a run's numbers, by name (what a restart must repeat).
pub fn options_of(req: &Request) -> Map<String, Value> {
    let mut m = Map::new();
    let mut put = |k: &str, v: String| {
        m.insert(k.into(), json!(v));
    };
    put("method", format!("{:?}", req.method));
    put("rtol", format!("{:?}", req.rtol));
    put("atol", format!("{:?}", req.atol));
    put("t_end", format!("{:?}", req.t_end));
    put("dt", format!("{:?}", req.dt));
    put("max_step", format!("{:?}", req.max_step));
    put("max_steps", format!("{:?}", req.max_steps));
    put("points", format!("{:?}", req.points));
    put("output_dt", format!("{:?}", req.output_dt));
    put("t_eval", format!("{:?}", req.t_eval));
    put("drift_tolerance", format!("{:?}", req.drift_tolerance));
    put("set", format!("{:?}", req.params));
    put("jit", format!("{:?}", req.jit));
    m
}

/// Writes checkpoints of one run when they are due.
#[derive(Debug)]
pub struct Checkpointer {
    path: PathBuf,
    every: Every,
    kind: &'static str,
    model: String,
    model_hash: String,
    options: Map<String, Value>,
    last_wall: std::time::Instant,
    last_steps: u64,
    /// Checkpoints written.
    pub written: u64,
    /// The time of the last one.
    pub last_time: Option<f64>,
}

impl Checkpointer {
    /// The summary's `checkpoint` field: the file, how many were written, the time of the
    /// last.
    pub fn summary_field(&self) -> Value {
        json!({
            "file": self.path().display().to_string(),
            "written": self.written,
            "last_t": self.last_time,
        })
    }

    /// Checkpoints of the run of `file` with `req` into `dir/checkpoint.json`.
    pub fn new(
        dir: &Path,
        every: Every,
        kind: &'static str,
        file: &ModelFile,
        req: &Request,
    ) -> Checkpointer {
        Checkpointer {
            path: dir.join(FILE_NAME),
            every,
            kind,
            model: file.origin.clone(),
            model_hash: format!("{:016x}", fnv1a(file.source.as_bytes())),
            options: options_of(req),
            last_wall: std::time::Instant::now(),
            last_steps: 0,
            written: 0,
            last_time: None,
        }
    }

    /// Counts steps from `steps` on (a restarted run).
    pub fn starting_at(mut self, steps: u64) -> Checkpointer {
        self.last_steps = steps;
        self
    }

    /// Whether a checkpoint is due after `steps` steps.
    pub fn due(&self, steps: u64) -> bool {
        match self.every {
            Every::Off => false,
            Every::Steps(k) => steps >= self.last_steps.saturating_add(k),
            Every::Seconds(s) => self.last_wall.elapsed().as_secs_f64() >= s,
        }
    }

    /// Writes a checkpoint at time `t` after `steps` steps: `files` the output files' lengths
    /// (flushed and synced by the caller), `state` the engine's.
    pub fn write(&mut self, t: f64, steps: u64, files: Value, state: Value) -> Result<(), Error> {
        let body = json!({
            "kind": self.kind,
            "model": self.model,
            "model_hash": self.model_hash,
            "options": Value::Object(self.options.clone()),
            "t": t,
            "t_bits": t.to_bits(),
            "steps": steps,
            "files": files,
            "state": state,
        });
        let body = body.to_string();
        let text = format!(
            "{MAGIC}\n{:016x} {}\n{body}",
            fnv1a(body.as_bytes()),
            body.len()
        );
        crate::output::write_atomic(&self.path, text.as_bytes())?;
        self.last_wall = std::time::Instant::now();
        self.last_steps = steps;
        self.written += 1;
        self.last_time = Some(t);
        Ok(())
    }

    /// The checkpoint file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// A checkpoint that was read and checked against the run that wants to continue from it.
#[derive(Debug)]
pub struct Restart {
    /// The checkpoint file.
    pub path: PathBuf,
    /// The time reached.
    pub t: f64,
    /// Steps taken.
    pub steps: u64,
    /// The output files' lengths.
    pub files: Value,
    /// The engine's state.
    pub state: Value,
}

impl Restart {
    /// The summary's `restarted_from` field: the checkpoint and its time.
    pub fn summary_field(&self) -> Value {
        json!({ "file": self.path.display().to_string(), "t": self.t })
    }
}

/// Sets the summary's `checkpoint` (the file, how many were written, the time of the last)
/// and `restarted_from` fields for the checkpoints and restart there are.
pub fn add_summary_fields(
    summary: &mut Value,
    checkpoints: Option<&Checkpointer>,
    restart: Option<&Restart>,
) {
    if let Some(cp) = checkpoints {
        summary["checkpoint"] = cp.summary_field();
    }
    if let Some(r) = restart {
        summary["restarted_from"] = r.summary_field();
    }
}

fn refuse(path: &Path, message: String) -> Error {
    Error::argument(
        "--restart",
        format!("cannot restart from {}: {message}", path.display()),
    )
}

/// Reads the checkpoint `path` for the run of `file` with `req` (kind `kind`): a missing,
/// truncated, tampered, foreign (another model, another kind) or mismatched (other options)
/// checkpoint is refused, saying what differs.
pub fn read(path: &Path, kind: &str, file: &ModelFile, req: &Request) -> Result<Restart, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, "read the checkpoint", e))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| refuse(path, "it is not a pdyn checkpoint (not UTF-8 text)".into()))?;
    let mut lines = text.splitn(3, '\n');
    if lines.next() != Some(MAGIC) {
        return Err(refuse(
            path,
            format!("it is not a pdyn checkpoint (the first line is not `{MAGIC}`)"),
        ));
    }
    let head = lines.next().unwrap_or("");
    let body = lines.next().unwrap_or("");
    let (sum, len) = head
        .split_once(' ')
        .and_then(|(s, l)| Some((u64::from_str_radix(s, 16).ok()?, l.parse::<usize>().ok()?)))
        .ok_or_else(|| refuse(path, "its header line is damaged".into()))?;
    if body.len() != len {
        return Err(refuse(
            path,
            format!(
                "it is truncated or extended: its body has {} bytes, the header says {len}",
                body.len()
            ),
        ));
    }
    if fnv1a(body.as_bytes()) != sum {
        return Err(refuse(
            path,
            "its checksum does not match its contents: the file was changed or damaged".into(),
        ));
    }
    let v: Value = serde_json::from_str(body)
        .map_err(|e| refuse(path, format!("its body is not valid JSON ({e})")))?;
    let got_kind = v["kind"].as_str().unwrap_or("");
    if got_kind != kind {
        return Err(refuse(
            path,
            format!("it is a checkpoint of a {got_kind} run; this model is {kind}"),
        ));
    }
    let hash = format!("{:016x}", fnv1a(file.source.as_bytes()));
    if v["model_hash"].as_str() != Some(hash.as_str()) {
        return Err(refuse(
            path,
            format!(
                "it was written for another model text ({} with hash {}; {} has hash {hash}): the model file changed, or it is another model",
                v["model"].as_str().unwrap_or("?"),
                v["model_hash"].as_str().unwrap_or("?"),
                file.origin
            ),
        ));
    }
    let now = options_of(req);
    let then = v["options"].as_object().cloned().unwrap_or_default();
    let differ: Vec<String> = now
        .iter()
        .filter(|(k, val)| then.get(*k) != Some(*val))
        .map(|(k, val)| {
            format!(
                "{k}: {} then, {} now",
                then.get(k).and_then(Value::as_str).unwrap_or("(missing)"),
                val.as_str().unwrap_or("?")
            )
        })
        .collect();
    if !differ.is_empty() {
        return Err(refuse(
            path,
            format!(
                "it was written with other options ({}): restart with the options of the run it continues",
                differ.join("; ")
            ),
        ));
    }
    let t = v["t_bits"]
        .as_u64()
        .map(f64::from_bits)
        .ok_or_else(|| refuse(path, "it has no time".into()))?;
    Ok(Restart {
        path: path.to_path_buf(),
        t,
        steps: v["steps"].as_u64().unwrap_or(0),
        files: v["files"].clone(),
        state: v["state"].clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_reads_wall_times_steps_and_off() {
        assert_eq!(Every::parse("15min"), Ok(Every::Seconds(900.0)));
        assert_eq!(Every::parse("30s"), Ok(Every::Seconds(30.0)));
        assert_eq!(Every::parse("2h"), Ok(Every::Seconds(7200.0)));
        assert_eq!(Every::parse("500steps"), Ok(Every::Steps(500)));
        assert_eq!(Every::parse("500"), Ok(Every::Steps(500)));
        assert_eq!(Every::parse("off"), Ok(Every::Off));
        assert!(Every::parse("1.5steps").is_err());
        assert!(Every::parse("-3s").is_err());
        assert!(Every::parse("soon").is_err());
    }

    #[test]
    fn fnv1a_of_known_strings() {
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
