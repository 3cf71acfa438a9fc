//! Constant values in tables that other crates read from a model file (the `[nbody]` table of
//! `pdyn`): the same numbers, expressions of `[parameters]`, `pi` and unit literals as the
//! mechanics tables, evaluated by the same loader, so every error is located and worded the
//! same way (`file:line:col`, the offending text, "did you mean").

use super::{Loader, ModelError, Parameter};
use pdyn_expr::lower::Binding;
use pdyn_expr::Value;
use toml::Spanned;

/// A TOML value with its byte span in the file.
pub type SpannedValue = Spanned<toml::Value>;

/// Evaluates constant fields of one file in the scope of its parameters.
pub struct Constants<'a> {
    ld: Loader<'a>,
}

impl<'a> Constants<'a> {
    /// An empty scope (only `pi`) for the file `origin` with text `source`.
    pub fn new(source: &'a str, origin: &'a str) -> Self {
        Constants {
            ld: Loader::new(origin, source),
        }
    }

    /// An error at `span` of this file.
    pub fn err(&self, span: std::ops::Range<usize>, message: impl Into<String>) -> ModelError {
        self.ld.err(span, message)
    }

    /// Evaluates the parameter `name = sv` (or takes `value` when given, e.g. from `--set`)
    /// and declares it for the fields that follow; returns its value.
    pub fn parameter(
        &mut self,
        name: &Spanned<String>,
        sv: &SpannedValue,
        value: Option<f64>,
    ) -> Result<f64, ModelError> {
        let value = match value {
            Some(v) => v,
            None => self.scalar(sv, "a parameter")?,
        };
        let sym = self.ld.pool.symbol(name.get_ref(), value > 0.0);
        let id = self.ld.pool.sym(sym);
        self.ld.declare(
            name.get_ref(),
            name.span(),
            "parameter",
            Binding::Value(Value::Scalar(id)),
        )?;
        self.ld.params.push(Parameter {
            name: name.get_ref().clone(),
            id,
            value,
            definition: None,
        });
        Ok(value)
    }

    /// The text of a string field, when it is a unit literal such as `"1.3 deg"` (converted
    /// to SI by [`Constants::scalar`]); callers whose units are not SI refuse those.
    pub fn unit_literal<'s>(&self, sv: &'s SpannedValue) -> Option<&'s str> {
        match sv.get_ref() {
            toml::Value::String(s) if crate::units::looks_like_quantity(s) => Some(s),
            _ => None,
        }
    }

    /// A scalar field: a number, or a string holding a constant expression or a quantity.
    pub fn scalar(&mut self, sv: &SpannedValue, what: &str) -> Result<f64, ModelError> {
        let id = self.ld.scalar(sv, what)?;
        self.ld.constant(id, sv.span(), what)
    }

    /// A vector field: `"[x, y, z]"` (or `"[x, y]"`), or a TOML array of two or three numbers
    /// or constant expressions.
    pub fn vector(&mut self, sv: &SpannedValue, what: &str) -> Result<[f64; 3], ModelError> {
        let span = sv.span();
        if let toml::Value::Array(items) = sv.get_ref() {
            if !(2..=3).contains(&items.len()) {
                return Err(self
                    .err(
                        span,
                        format!("{what} must have 2 or 3 components, found {}", items.len()),
                    )
                    .help("write [x, y, z]"));
            }
            let mut out = [0.0; 3];
            for (k, item) in items.iter().enumerate() {
                out[k] = match item {
                    toml::Value::Float(f) => *f,
                    toml::Value::Integer(i) => *i as f64,
                    toml::Value::String(s) => {
                        // The element's own place in the file, so an error points into it.
                        let text = &self.ld.source[span.clone()];
                        let quoted = format!("\"{s}\"");
                        let at = text
                            .find(&quoted)
                            .map_or(span.start, |p| span.start + p + 1);
                        let ast =
                            pdyn_expr::syntax::parse(s).map_err(|e| self.ld.located(e, at))?;
                        let v =
                            pdyn_expr::lower::lower(&mut self.ld.pool, &ast, &mut self.ld.scope)
                                .map_err(|e| self.ld.located(e, at))?;
                        let Value::Scalar(id) = v else {
                            return Err(self.err(
                                at..at + s.len(),
                                format!("a component of {what} must be a scalar"),
                            ));
                        };
                        self.ld.constant(id, at..at + s.len(), what)?
                    }
                    other => {
                        return Err(self.err(
                            span,
                            format!("{what}: expected numbers, found a {}", other.type_str()),
                        ))
                    }
                };
                if !out[k].is_finite() {
                    return Err(self.err(span, format!("{what} is not finite")));
                }
            }
            return Ok(out);
        }
        let v = self.ld.vector(sv, what)?;
        let mut out = [0.0; 3];
        for k in 0..3 {
            out[k] = self.ld.constant(v[k], span.clone(), what)?;
        }
        Ok(out)
    }

    /// Names and values of the parameters declared so far, in order.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        self.ld
            .params
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Deserialize)]
    struct T {
        p: indexmap::IndexMap<Spanned<String>, SpannedValue>,
        x: SpannedValue,
        v: SpannedValue,
    }

    #[test]
    fn parameters_expressions_units_and_located_errors() {
        let src = "x = \"2*a\"\nv = [1, \"a + 1\", \"pi\"]\n[p]\na = \"3 km\"\n";
        let t: T = toml::from_str(src).unwrap();
        let mut c = Constants::new(src, "f.toml");
        for (n, sv) in &t.p {
            c.parameter(n, sv, None).unwrap();
        }
        assert_eq!(c.scalar(&t.x, "x").unwrap(), 6000.0);
        assert_eq!(
            c.vector(&t.v, "v").unwrap(),
            [1.0, 3001.0, std::f64::consts::PI]
        );
        let bad = "x = \"2*b\"\nv = [1, \"c\", 0]\n[p]\na = 1\n";
        let t: T = toml::from_str(bad).unwrap();
        let mut c = Constants::new(bad, "f.toml");
        for (n, sv) in &t.p {
            c.parameter(n, sv, None).unwrap();
        }
        let e = c.scalar(&t.x, "x").unwrap_err();
        assert_eq!(&bad[e.span.clone()], "b");
        let e = c.vector(&t.v, "v").unwrap_err();
        assert_eq!(&bad[e.span.clone()], "c");
    }
}
