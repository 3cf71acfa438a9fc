//! Output lines for a person to read, none longer than [`PRINT_CHARS`]: an expression that does
//! not fit is replaced by what it is and its size (`⟨f[1]: 5312 characters …⟩`), a long list
//! of names by its ends, a vector by one line per component. Used by `pdyn derive`, whose
//! equations grow without bound with the model (`--json` has every expression whole).

use pdyn_expr::budget::{PrintSize, PRINT_CHARS};
use pdyn_expr::{Id, Pool};

/// What marks a line of prose clipped at the budget (followed by its length).
pub const CLIPPED: &str = "⟨line clipped";

/// Text being assembled line by line within the budget.
pub struct Lines<'a> {
    /// The pool the expressions live in.
    pub pool: &'a Pool,
    /// LaTeX rather than plain text.
    pub latex: bool,
    /// What was written so far.
    pub out: String,
}

/// `s`'s length in characters (what the budget counts: `⟨`, `…` and `θ` are one each).
pub fn chars(s: &str) -> usize {
    s.chars().count()
}

/// The note that replaces an expression over the budget: what it is and how large.
pub fn omitted(what: &str, size: PrintSize) -> String {
    format!(
        "⟨{what}: {size}, over the printing budget of {PRINT_CHARS} characters; `pdyn derive --json` gives it whole⟩"
    )
}

impl<'a> Lines<'a> {
    /// An empty text.
    pub fn new(pool: &'a Pool, latex: bool) -> Lines<'a> {
        Lines {
            pool,
            latex,
            out: String::new(),
        }
    }

    /// A line of prose (no expression): clipped at the budget as a last resort, so that no
    /// line is ever longer. The messages this prints are short by construction; a clipped
    /// line says so ([`CLIPPED`]), and the tests fail on it.
    pub fn line(&mut self, s: &str) {
        if chars(s) <= PRINT_CHARS {
            self.out += s;
        } else {
            let keep: String = s.chars().take(PRINT_CHARS - 60).collect();
            self.out += &format!("{keep} {CLIPPED} ({} characters)⟩", chars(s));
        }
        self.out.push('\n');
    }

    /// `prefix` followed by `id`, or by [`omitted`] naming it `what` when the line would be
    /// over the budget.
    pub fn expr(&mut self, prefix: &str, what: &str, id: Id) {
        self.expr_in(prefix, what, id, "");
    }

    /// `prefix`, `id` (or [`omitted`]), `suffix`.
    pub fn expr_in(&mut self, prefix: &str, what: &str, id: Id, suffix: &str) {
        let room = PRINT_CHARS.saturating_sub(chars(prefix) + chars(suffix));
        let body = match self.pool.to_text_within(id, self.latex, room) {
            Ok(s) => s,
            Err(size) => omitted(what, size),
        };
        self.line(&format!("{prefix}{body}{suffix}"));
    }

    /// `prefix` followed by already rendered text `s` (a collected sum), or by [`omitted`].
    pub fn rendered(&mut self, prefix: &str, what: &str, s: &str) {
        if chars(prefix) + chars(s) <= PRINT_CHARS {
            self.line(&format!("{prefix}{s}"));
        } else {
            let size = PrintSize::Chars(chars(s));
            self.line(&format!("{prefix}{}", omitted(what, size)));
        }
    }

    /// `{indent}{name} = [x, y, z]` on one line when it fits, else one line per component
    /// (`{name}.x = …`), each within the budget.
    pub fn vector(&mut self, indent: &str, name: &str, v: [Id; 3]) {
        // Each component formatted once: the per-component lines reuse it (formatting the
        // 100-link chain's accelerations twice, to find them too long, was a tenth of `pdyn
        // derive`).
        let parts: Vec<Result<String, PrintSize>> = v
            .iter()
            .map(|&c| self.pool.to_text_within(c, self.latex, PRINT_CHARS))
            .collect();
        if parts.iter().all(|p| p.is_ok()) {
            let texts: Vec<&str> = parts.iter().flatten().map(String::as_str).collect();
            let joined = if self.latex {
                format!(
                    "\\begin{{bmatrix}} {} \\end{{bmatrix}}",
                    texts.join(" \\\\ ")
                )
            } else {
                format!("[{}]", texts.join(", "))
            };
            let line = format!("{indent}{name} = {joined}");
            if chars(&line) <= PRINT_CHARS {
                self.line(&line);
                return;
            }
        }
        for (part, axis) in parts.into_iter().zip(["x", "y", "z"]) {
            let prefix = format!("{indent}{name}.{axis} = ");
            let what = format!("{name}.{axis}");
            // As `expr` would print it: the text when the line fits, else its size.
            let body = match part {
                Ok(text) if chars(&prefix) + chars(&text) <= PRINT_CHARS => text,
                Ok(text) => omitted(&what, PrintSize::Chars(chars(&text))),
                Err(size) => omitted(&what, size),
            };
            self.line(&format!("{prefix}{body}"));
        }
    }

    /// `prefix` followed by `names` joined by `sep`, or by its first and last few names when
    /// that would be over the budget.
    pub fn names(&mut self, prefix: &str, names: &[String], sep: &str, suffix: &str) {
        let all = names.join(sep);
        if chars(prefix) + chars(&all) + chars(suffix) <= PRINT_CHARS {
            self.line(&format!("{prefix}{all}{suffix}"));
            return;
        }
        let k = 3.min(names.len());
        let head = names[..k].join(sep);
        let tail = names[names.len() - k..].join(sep);
        self.line(&format!(
            "{prefix}{head}{sep}… ({} in all){sep}{tail}{suffix}",
            names.len()
        ));
    }
}
