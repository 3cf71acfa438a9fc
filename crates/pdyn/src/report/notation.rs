//! How expressions are written in a report: plain text that pdyn parses back, LaTeX, or a Rust
//! `f64` expression; and the `{"text", "latex"}` pair every JSON report carries.

use pdyn_expr::{Id, Pool, Value};

/// Output notation for expressions (`--format` in the CLI).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Notation {
    /// Plain text that pdyn parses back.
    #[default]
    Text,
    /// LaTeX (math mode).
    Latex,
    /// A Rust f64 expression.
    Rust,
}

impl Notation {
    /// `id` in this notation.
    pub fn show(self, pool: &Pool, id: Id) -> String {
        match self {
            Notation::Text => pool.to_text(id),
            Notation::Latex => pool.to_latex(id),
            Notation::Rust => pool.to_rust(id, &|p, n| p.rust_leaf_name(n)),
        }
    }

    /// A 3-vector in this notation (a LaTeX column matrix, or `[x, y, z]`).
    pub fn show_vector(self, pool: &Pool, v: [Id; 3]) -> String {
        let parts: Vec<String> = v.iter().map(|&c| self.show(pool, c)).collect();
        match self {
            Notation::Latex => format!(
                "\\begin{{bmatrix}} {} \\end{{bmatrix}}",
                parts.join(" \\\\ ")
            ),
            _ => format!("[{}]", parts.join(", ")),
        }
    }

    /// A scalar or a vector in this notation.
    pub fn show_value(self, pool: &Pool, v: Value) -> String {
        match v {
            Value::Scalar(s) => self.show(pool, s),
            Value::Vector(c) => self.show_vector(pool, c),
        }
    }
}

/// A scalar as `{"text", "latex"}`, a vector as a list of three of them.
pub fn value_json(pool: &Pool, v: Value) -> serde_json::Value {
    match v {
        Value::Scalar(s) => both(pool, s),
        Value::Vector(c) => serde_json::json!(c.iter().map(|&x| both(pool, x)).collect::<Vec<_>>()),
    }
}

/// `{"text": ..., "latex": ...}` for JSON output.
pub fn both(pool: &Pool, id: Id) -> serde_json::Value {
    serde_json::json!({"text": pool.to_text(id), "latex": pool.to_latex(id)})
}
