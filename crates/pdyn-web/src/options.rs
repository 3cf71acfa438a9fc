//! The options a page sends, as one JSON object, turned into the library's typed requests.
//! Keys are the CLI's option names in keyword form (`t_end`, `rtol`, `set`); an unknown key or
//! a value of the wrong type is an argument error naming the key and what would be valid,
//! never ignored.

use pdyn::model_file::ModelFile;
use pdyn::report::derive::DeriveRequest;
use pdyn::report::forces::ForcesRequest;
use pdyn::{Error, Request};
use pdyn_mech::derive::Form;
use serde_json::{Map, Value};

/// Every key [`Options::parse`] accepts.
const KEYS: &[&str] = &[
    "method",
    "rtol",
    "atol",
    "t_end",
    "dt",
    "max_step",
    "max_steps",
    "points",
    "output_dt",
    "t_eval",
    "drift_tolerance",
    "set",
    "at",
    "json",
    "latex",
    "form",
    "symbolic_limit",
    "solve",
    "max_frames",
    "frame_every",
];

/// Frames of an animation kept when the page does not say (evenly thinned beyond).
const MAX_FRAMES: usize = 400;

/// A page's options, checked.
#[derive(Debug, Default)]
pub struct Options {
    map: Map<String, Value>,
    /// JSON output instead of text.
    pub json: bool,
    /// Frames kept for the animation.
    pub max_frames: usize,
}

fn bad(key: &str, message: String) -> Error {
    Error::argument(key, format!("option `{key}`: {message}"))
}

impl Options {
    /// Parses `{…}` (an empty string is no options).
    pub fn parse(text: &str) -> Result<Options, Error> {
        let value: Value = if text.trim().is_empty() {
            Value::Object(Map::new())
        } else {
            serde_json::from_str(text)
                .map_err(|e| Error::argument("options", format!("options are not JSON: {e}")))?
        };
        let Value::Object(map) = value else {
            return Err(Error::argument(
                "options",
                "options must be a JSON object, e.g. {\"t_end\": 10}",
            ));
        };
        if let Some(k) = map.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return Err(bad(
                k,
                format!("unknown option; valid: {}", KEYS.join(", ")),
            ));
        }
        let mut o = Options {
            map,
            ..Options::default()
        };
        o.json = o.flag("json")?;
        o.max_frames = o.count("max_frames")?.unwrap_or(MAX_FRAMES);
        Ok(o)
    }

    fn number(&self, key: &str) -> Result<Option<f64>, Error> {
        match self.map.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Number(n)) => Ok(n.as_f64()),
            Some(v) => Err(bad(key, format!("expected a number, got {v}"))),
        }
    }

    fn count(&self, key: &str) -> Result<Option<usize>, Error> {
        match self.map.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Number(n)) if n.as_u64().is_some() => {
                let k = n.as_u64().unwrap_or(0);
                usize::try_from(k)
                    .map(Some)
                    .map_err(|_| bad(key, format!("{k} is too large")))
            }
            Some(v) => Err(bad(key, format!("expected a whole number ≥ 0, got {v}"))),
        }
    }

    fn flag(&self, key: &str) -> Result<bool, Error> {
        match self.map.get(key) {
            None | Some(Value::Null) => Ok(false),
            Some(Value::Bool(b)) => Ok(*b),
            Some(v) => Err(bad(key, format!("expected true or false, got {v}"))),
        }
    }

    fn text(&self, key: &str) -> Result<Option<String>, Error> {
        match self.map.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::String(s)) => Ok(Some(s.clone())),
            Some(v) => Err(bad(key, format!("expected a string, got {v}"))),
        }
    }

    /// `{"name": value, …}` (`set`, `at`), in the order written.
    fn pairs(&self, key: &str) -> Result<Vec<(String, f64)>, Error> {
        match self.map.get(key) {
            None | Some(Value::Null) => Ok(Vec::new()),
            Some(Value::Object(m)) => m
                .iter()
                .map(|(name, v)| match v.as_f64() {
                    Some(x) => Ok((name.clone(), x)),
                    None => Err(bad(key, format!("`{name}` must be a number, got {v}"))),
                })
                .collect(),
            Some(v) => Err(bad(
                key,
                format!("expected an object of numbers such as {{\"m\": 2}}, got {v}"),
            )),
        }
    }

    /// The run options (`pdyn run --no-jit`: this build interprets).
    pub fn request(&self) -> Result<Request, Error> {
        let t_eval = match self.map.get("t_eval") {
            None | Some(Value::Null) => None,
            Some(Value::Array(a)) => Some(
                a.iter()
                    .map(|v| {
                        v.as_f64()
                            .ok_or_else(|| bad("t_eval", format!("{v} is not a number")))
                    })
                    .collect::<Result<Vec<f64>, Error>>()?,
            ),
            Some(v) => Err(bad("t_eval", format!("expected a list of times, got {v}")))?,
        };
        Ok(Request {
            method: self.text("method")?,
            rtol: self.number("rtol")?,
            atol: self.number("atol")?,
            t_end: self.number("t_end")?,
            dt: self.number("dt")?,
            max_step: self.number("max_step")?,
            max_steps: self.count("max_steps")?,
            points: self.count("points")?,
            output_dt: self.number("output_dt")?,
            t_eval,
            drift_tolerance: self.number("drift_tolerance")?,
            params: self.pairs("set")?,
            jit: pdyn::sim::JitMode::Off,
            out: None,
            plots: false,
            interrupt: None,
            frame_every: self.count("frame_every")?.map(|k| k as u64),
        })
    }

    /// The mechanics model of `source` with the parameters of `set`; another kind is the
    /// CLI's located refusal.
    pub fn mechanics(&self, source: &str, origin: &str) -> Result<pdyn_mech::Model, Error> {
        let file = ModelFile::from_source(source.to_string(), origin.to_string());
        let mut model = file.mechanics()?;
        pdyn::params::set_parameter_values(&mut model, &self.pairs("set")?, "--set")?;
        Ok(model)
    }

    /// `pdyn derive`'s options.
    pub fn derive_request(&self) -> Result<DeriveRequest, Error> {
        let form = match self.text("form")?.as_deref() {
            None | Some("auto") => Form::Auto,
            Some("newton") => Form::Newton,
            Some("projected") => Form::Projected,
            Some(other) => {
                return Err(bad(
                    "form",
                    format!("`{other}` is not a form; valid: auto, newton, projected"),
                ))
            }
        };
        let defaults = DeriveRequest::default();
        Ok(DeriveRequest {
            latex: self.flag("latex")?,
            json: self.json,
            form,
            symbolic_limit: self
                .count("symbolic_limit")?
                .unwrap_or(defaults.symbolic_limit),
            solve: self.flag("solve")?,
        })
    }

    /// `pdyn forces`' options.
    pub fn forces_request(&self) -> Result<ForcesRequest, Error> {
        Ok(ForcesRequest {
            at: self.pairs("at")?,
            latex: self.flag("latex")?,
            json: self.json,
        })
    }

    /// A command's printed output: `{"text": …}`, or `{"result": …}` parsed when JSON.
    pub fn text_or_json(&self, text: String) -> Result<Value, Error> {
        if !self.json {
            return Ok(serde_json::json!({ "text": text }));
        }
        let parsed: Value = serde_json::from_str(&text).map_err(|e| Error::Internal {
            message: format!("a command's JSON output does not parse: {e}"),
        })?;
        Ok(serde_json::json!({ "result": parsed }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_become_the_cli_request() {
        let o = Options::parse(r#"{"t_end": 2.5, "rtol": 1e-8, "points": 11, "set": {"m": 2}}"#)
            .unwrap();
        let r = o.request().unwrap();
        assert_eq!(r.t_end, Some(2.5));
        assert_eq!(r.rtol, Some(1e-8));
        assert_eq!(r.points, Some(11));
        assert_eq!(r.params, vec![("m".to_string(), 2.0)]);
        assert_eq!(r.jit, pdyn::sim::JitMode::Off);
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_named() {
        let e = Options::parse(r#"{"tend": 1}"#).unwrap_err().to_string();
        assert!(e.contains("tend") && e.contains("t_end"), "{e}");
        let e = Options::parse(r#"{"points": 2.5}"#)
            .unwrap()
            .request()
            .unwrap_err()
            .to_string();
        assert!(e.contains("points") && e.contains("whole number"), "{e}");
        let e = Options::parse(r#"{"set": {"m": "x"}}"#)
            .unwrap()
            .request()
            .unwrap_err()
            .to_string();
        assert!(e.contains("`m` must be a number"), "{e}");
        let e = Options::parse("[1]").unwrap_err().to_string();
        assert!(e.contains("JSON object"), "{e}");
        let e = Options::parse(r#"{"form": "kane"}"#)
            .unwrap()
            .derive_request()
            .unwrap_err()
            .to_string();
        assert!(e.contains("auto, newton, projected"), "{e}");
    }
}
