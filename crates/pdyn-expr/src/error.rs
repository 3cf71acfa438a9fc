//! Errors located in source text, rendered with an excerpt and a caret, plus "did you mean"
//! suggestions.

use std::fmt;
use std::ops::Range;

/// An error in an expression, located by a byte span of the source it was parsed from.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ExprError {
    /// Byte range of the offending text.
    pub span: Range<usize>,
    /// What is wrong.
    pub message: String,
    /// What would be valid, when we can tell.
    pub help: Option<String>,
}

impl ExprError {
    /// An error at `span`.
    pub fn new(span: Range<usize>, message: impl Into<String>) -> ExprError {
        ExprError {
            span,
            message: message.into(),
            help: None,
        }
    }

    /// Adds a help line.
    pub fn with_help(mut self, help: impl Into<String>) -> ExprError {
        self.help = Some(help.into());
        self
    }

    /// Shifts the span, for an expression embedded at `offset` in a larger file.
    pub fn offset(mut self, offset: usize) -> ExprError {
        self.span = self.span.start + offset..self.span.end + offset;
        self
    }

    /// Renders `origin:line:col: error: message`, the source line, a caret under the span, and
    /// the help. `source` is the whole text the span refers to.
    pub fn render(&self, source: &str, origin: &str) -> String {
        render_diagnostic(
            source,
            origin,
            &self.span,
            &self.message,
            self.help.as_deref(),
        )
    }
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} (at bytes {}..{})",
            self.message, self.span.start, self.span.end
        )?;
        if let Some(h) = &self.help {
            write!(f, "; {h}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ExprError {}

/// 1-based line and column (in characters) of byte `pos` in `source`.
pub fn line_col(source: &str, pos: usize) -> (usize, usize) {
    let pos = floor_char_boundary(source, pos.min(source.len()));
    let before = &source[..pos];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = source[line_start..pos].chars().count() + 1;
    (line, col)
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Renders a located diagnostic in the style of rustc: shared by every pdyn crate.
pub fn render_diagnostic(
    source: &str,
    origin: &str,
    span: &Range<usize>,
    message: &str,
    help: Option<&str>,
) -> String {
    let start = floor_char_boundary(source, span.start.min(source.len()));
    let end = floor_char_boundary(source, span.end.clamp(start, source.len()));
    let (line, col) = line_col(source, start);
    let line_start = source[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = source[start..]
        .find('\n')
        .map_or(source.len(), |i| start + i);
    let text = &source[line_start..line_end];
    let width = source[start..end.min(line_end)].chars().count().max(1);
    let gutter = line.to_string().len();
    let pad = " ".repeat(gutter);
    let mut out = format!("{origin}:{line}:{col}: error: {message}\n");
    out += &format!("{pad} |\n{line} | {text}\n{pad} | ");
    out += &" ".repeat(col - 1);
    out += &"^".repeat(width);
    out.push('\n');
    if let Some(h) = help {
        out += &format!("{pad} = help: {h}\n");
    }
    out
}

/// Edit distance between two short strings (optimal string alignment: insertions,
/// deletions, substitutions and transpositions of adjacent characters cost 1).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    let mut prev2 = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                cur[j] = cur[j].min(prev2[j - 2] + 1);
            }
        }
        std::mem::swap(&mut prev2, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// The candidate closest to `name`, if it is close enough to be a plausible typo.
pub fn suggest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| (edit_distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min()
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggestions_find_typos() {
        assert_eq!(suggest("sn", ["sin", "cos", "sinh"]), Some("sin"));
        assert_eq!(suggest("omgea", ["omega", "m"]), Some("omega"));
        assert_eq!(suggest("zzz", ["sin", "cos"]), None);
    }

    #[test]
    fn render_points_at_span() {
        let src = "a + b\n2*sn(x)";
        let e = ExprError::new(8..10, "unknown function `sn`").with_help("did you mean `sin`?");
        let r = e.render(src, "model.toml");
        assert!(
            r.starts_with("model.toml:2:3: error: unknown function `sn`"),
            "{r}"
        );
        assert!(r.contains("2 | 2*sn(x)\n  |   ^^\n"), "{r}");
        assert!(r.contains("help: did you mean `sin`?"), "{r}");
    }
}
