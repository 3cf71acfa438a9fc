//! The small language of indices in a model file's families: integer arithmetic on index
//! names and sizes (`i+1`, `n-1`, `2*k`, `j % 2`), conditions (`j == 0 and (i == 0 or i ==
//! n-1)`), ranges (`0..n-1`, both ends included as in "i = 0, …, n−1") and the `for` list of
//! a force family (`i in 0..n-2, j`, or `e in bars` over the rows of a table). It is separate from the expression language because
//! indices are exact integers known while the file loads, never symbols.
//!
//! Errors carry a byte range in the text they were parsed from; the caller places it in the
//! file.

use std::ops::Range;

/// A located problem in an index expression (span relative to its text).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IndexError {
    /// Byte range in the text.
    pub span: Range<usize>,
    /// What is wrong.
    pub message: String,
}

fn fail<T>(span: Range<usize>, message: impl Into<String>) -> Result<T, IndexError> {
    Err(IndexError {
        span,
        message: message.into(),
    })
}

/// A parsed index expression.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IndexExpr {
    /// An integer literal.
    Int(i64),
    /// An index or size name.
    Name(String, Range<usize>),
    /// `-a`.
    Neg(Box<IndexExpr>),
    /// `not a`.
    Not(Box<IndexExpr>),
    /// `a op b`.
    Binary(Op, Box<IndexExpr>, Box<IndexExpr>, Range<usize>),
}

/// Binary operators, lowest precedence first in the grammar: `or`, `and`, comparisons, `+ -`,
/// `* / %`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Op {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
}

/// An evaluated index expression: a number or a truth value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexValue {
    /// An integer.
    Int(i64),
    /// A condition's value.
    Bool(bool),
}

/// A range `lo..hi`, both ends included.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RangeExpr {
    /// First value.
    pub lo: IndexExpr,
    /// Last value.
    pub hi: IndexExpr,
}

/// One clause of a `for` list: an index name and, unless it takes its `[indices]` range, a
/// range of its own or the table whose rows it runs over.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ForClause {
    /// The index name.
    pub name: String,
    /// Where the name is written.
    pub span: Range<usize>,
    /// `in lo..hi`, if written.
    pub range: Option<RangeExpr>,
    /// `in TABLE` (a `[tables.TABLE]`), if written: the table's name and where it is written.
    pub table: Option<(String, Range<usize>)>,
}

/// What a name stands for while an index expression is evaluated: its value, nothing
/// (`Ok(None)`: an unknown name), or why it has no integer value (a table's cell that is not
/// an integer).
pub type Lookup<'a> = dyn Fn(&str) -> Result<Option<i64>, String> + 'a;

#[derive(Clone, Debug, PartialEq, Eq)]
enum Tok {
    Int(i64),
    Name(String),
    Sym(&'static str),
    End,
}

const SYMBOLS: [&str; 16] = [
    "..", "==", "!=", "<=", ">=", "&&", "||", "<", ">", "+", "-", "*", "/", "%", "(", ")",
];

fn lex(text: &str) -> Result<Vec<(Tok, Range<usize>)>, IndexError> {
    let mut out = Vec::new();
    let mut pos = 0;
    while pos < text.len() {
        let rest = &text[pos..];
        let c = rest.chars().next().unwrap_or(' ');
        if c.is_whitespace() {
            pos += c.len_utf8();
            continue;
        }
        if c == ',' {
            out.push((Tok::Sym(","), pos..pos + 1));
            pos += 1;
            continue;
        }
        if c.is_ascii_digit() {
            let len = rest
                .find(|d: char| !d.is_ascii_digit())
                .unwrap_or(rest.len());
            let Ok(n) = rest[..len].parse::<i64>() else {
                return fail(pos..pos + len, "this index is too large");
            };
            out.push((Tok::Int(n), pos..pos + len));
            pos += len;
            continue;
        }
        if c.is_alphabetic() || c == '_' {
            let len = rest
                .find(|d: char| !(d.is_alphanumeric() || d == '_'))
                .unwrap_or(rest.len());
            out.push((Tok::Name(rest[..len].to_string()), pos..pos + len));
            pos += len;
            continue;
        }
        let Some(sym) = SYMBOLS.iter().find(|s| rest.starts_with(**s)) else {
            return fail(
                pos..pos + c.len_utf8(),
                format!("`{c}` has no meaning in an index expression"),
            );
        };
        out.push((Tok::Sym(sym), pos..pos + sym.len()));
        pos += sym.len();
    }
    out.push((Tok::End, text.len()..text.len()));
    Ok(out)
}

/// Deepest nesting of parentheses accepted (a hostile file cannot overflow the stack).
const MAX_DEPTH: usize = 64;

struct Parser {
    toks: Vec<(Tok, Range<usize>)>,
    at: usize,
    depth: usize,
}

impl Parser {
    fn new(text: &str) -> Result<Parser, IndexError> {
        Ok(Parser {
            toks: lex(text)?,
            at: 0,
            depth: 0,
        })
    }
    fn peek(&self) -> &Tok {
        &self.toks[self.at].0
    }
    fn span(&self) -> Range<usize> {
        self.toks[self.at].1.clone()
    }
    fn bump(&mut self) {
        if self.at + 1 < self.toks.len() {
            self.at += 1;
        }
    }
    fn is_sym(&self, s: &str) -> bool {
        matches!(self.peek(), Tok::Sym(t) if *t == s)
    }
    fn is_word(&self, w: &str) -> bool {
        matches!(self.peek(), Tok::Name(n) if n == w)
    }
    fn describe(&self) -> String {
        match self.peek() {
            Tok::Int(n) => format!("`{n}`"),
            Tok::Name(n) => format!("`{n}`"),
            Tok::Sym(s) => format!("`{s}`"),
            Tok::End => "the end".to_string(),
        }
    }
    fn expect_end(&self, what: &str) -> Result<(), IndexError> {
        if *self.peek() == Tok::End {
            return Ok(());
        }
        fail(
            self.span(),
            format!("unexpected {} after {what}", self.describe()),
        )
    }

    fn expr(&mut self) -> Result<IndexExpr, IndexError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return fail(self.span(), "index expression nested too deeply");
        }
        let e = self.or();
        self.depth -= 1;
        e
    }
    fn or(&mut self) -> Result<IndexExpr, IndexError> {
        let mut e = self.and()?;
        while self.is_word("or") || self.is_sym("||") {
            let span = self.span();
            self.bump();
            let r = self.and()?;
            e = IndexExpr::Binary(Op::Or, Box::new(e), Box::new(r), span);
        }
        Ok(e)
    }
    fn and(&mut self) -> Result<IndexExpr, IndexError> {
        let mut e = self.not()?;
        while self.is_word("and") || self.is_sym("&&") {
            let span = self.span();
            self.bump();
            let r = self.not()?;
            e = IndexExpr::Binary(Op::And, Box::new(e), Box::new(r), span);
        }
        Ok(e)
    }
    fn not(&mut self) -> Result<IndexExpr, IndexError> {
        if self.is_word("not") {
            self.bump();
            return Ok(IndexExpr::Not(Box::new(self.not()?)));
        }
        self.comparison()
    }
    fn comparison(&mut self) -> Result<IndexExpr, IndexError> {
        let e = self.sum()?;
        let op = match self.peek() {
            Tok::Sym("==") => Op::Eq,
            Tok::Sym("!=") => Op::Ne,
            Tok::Sym("<") => Op::Lt,
            Tok::Sym("<=") => Op::Le,
            Tok::Sym(">") => Op::Gt,
            Tok::Sym(">=") => Op::Ge,
            _ => return Ok(e),
        };
        let span = self.span();
        self.bump();
        let r = self.sum()?;
        Ok(IndexExpr::Binary(op, Box::new(e), Box::new(r), span))
    }
    fn sum(&mut self) -> Result<IndexExpr, IndexError> {
        let mut e = self.product()?;
        loop {
            let op = match self.peek() {
                Tok::Sym("+") => Op::Add,
                Tok::Sym("-") => Op::Sub,
                _ => return Ok(e),
            };
            let span = self.span();
            self.bump();
            let r = self.product()?;
            e = IndexExpr::Binary(op, Box::new(e), Box::new(r), span);
        }
    }
    fn product(&mut self) -> Result<IndexExpr, IndexError> {
        let mut e = self.unary()?;
        loop {
            let op = match self.peek() {
                Tok::Sym("*") => Op::Mul,
                Tok::Sym("/") => Op::Div,
                Tok::Sym("%") => Op::Rem,
                _ => return Ok(e),
            };
            let span = self.span();
            self.bump();
            let r = self.unary()?;
            e = IndexExpr::Binary(op, Box::new(e), Box::new(r), span);
        }
    }
    fn unary(&mut self) -> Result<IndexExpr, IndexError> {
        if self.is_sym("-") {
            self.bump();
            return Ok(IndexExpr::Neg(Box::new(self.unary()?)));
        }
        if self.is_sym("+") {
            self.bump();
            return self.unary();
        }
        self.primary()
    }
    fn primary(&mut self) -> Result<IndexExpr, IndexError> {
        let span = self.span();
        match self.peek().clone() {
            Tok::Int(n) => {
                self.bump();
                Ok(IndexExpr::Int(n))
            }
            Tok::Name(n) if !["and", "or", "not", "in"].contains(&n.as_str()) => {
                self.bump();
                Ok(IndexExpr::Name(n, span))
            }
            Tok::Sym("(") => {
                self.bump();
                let e = self.expr()?;
                if !self.is_sym(")") {
                    return fail(
                        self.span(),
                        format!("expected `)`, found {}", self.describe()),
                    );
                }
                self.bump();
                Ok(e)
            }
            _ => fail(
                span,
                format!(
                    "expected an index, a number or `(`, found {}",
                    self.describe()
                ),
            ),
        }
    }
    fn range(&mut self) -> Result<RangeExpr, IndexError> {
        let lo = self.sum()?;
        if !self.is_sym("..") {
            return fail(
                self.span(),
                format!(
                    "expected `..` (a range is `first..last`), found {}",
                    self.describe()
                ),
            );
        }
        self.bump();
        let hi = self.sum()?;
        Ok(RangeExpr { lo, hi })
    }
}

/// Parses an integer expression or condition.
pub fn parse(text: &str) -> Result<IndexExpr, IndexError> {
    let mut p = Parser::new(text)?;
    let e = p.expr()?;
    p.expect_end("the expression")?;
    Ok(e)
}

/// Parses a range `first..last`.
pub fn parse_range(text: &str) -> Result<RangeExpr, IndexError> {
    let mut p = Parser::new(text)?;
    let r = p.range()?;
    p.expect_end("the range")?;
    Ok(r)
}

/// Parses a `for` list: `i in 0..n-2, j` (a clause without `in` takes the range `[indices]`
/// gives the name).
pub fn parse_for(text: &str) -> Result<Vec<ForClause>, IndexError> {
    let mut p = Parser::new(text)?;
    let mut out = Vec::new();
    loop {
        let span = p.span();
        let Tok::Name(name) = p.peek().clone() else {
            return fail(
                span,
                format!("expected an index name, found {}", p.describe()),
            );
        };
        p.bump();
        let (range, table) = if p.is_word("in") {
            p.bump();
            // `e in bars`: a name alone (up to `,` or the end) is a table, not a range.
            let alone = matches!(
                p.toks.get(p.at + 1).map(|t| &t.0),
                Some(Tok::End) | Some(Tok::Sym(","))
            );
            match p.peek().clone() {
                Tok::Name(t) if alone => {
                    let at = p.span();
                    p.bump();
                    (None, Some((t, at)))
                }
                _ => (Some(p.range()?), None),
            }
        } else {
            (None, None)
        };
        if out.iter().any(|c: &ForClause| c.name == name) {
            return fail(span, format!("index `{name}` is listed twice"));
        }
        out.push(ForClause {
            name,
            span,
            range,
            table,
        });
        if p.is_sym(",") {
            p.bump();
            continue;
        }
        p.expect_end("the `for` list")?;
        return Ok(out);
    }
}

/// Splits `P[i+1, j]` into `P` and the texts of its indices with their offsets in `name`;
/// `None` when `name` has no subscript.
pub fn split_subscript(name: &str) -> Option<(&str, Vec<(&str, usize)>)> {
    let open = name.find('[')?;
    let inner = name[open + 1..].strip_suffix(']')?;
    let mut parts = Vec::new();
    let mut start = open + 1;
    for piece in inner.split(',') {
        parts.push((piece, start));
        start += piece.len() + 1;
    }
    Some((&name[..open], parts))
}

impl IndexExpr {
    /// The value, with `lookup` giving the value of a name.
    pub fn eval(&self, lookup: &Lookup) -> Result<IndexValue, IndexError> {
        match self {
            IndexExpr::Int(n) => Ok(IndexValue::Int(*n)),
            IndexExpr::Name(n, span) => match lookup(n) {
                Ok(Some(v)) => Ok(IndexValue::Int(v)),
                Ok(None) => fail(
                    span.clone(),
                    format!("`{n}` is not an index here, nor a size declared in [indices]"),
                ),
                Err(message) => fail(span.clone(), message),
            },
            IndexExpr::Neg(e) => match e.eval(lookup)? {
                IndexValue::Int(v) => v
                    .checked_neg()
                    .map(IndexValue::Int)
                    .ok_or_else(|| overflow(0..0)),
                IndexValue::Bool(_) => fail(0..0, "`-` applies to a number, not a condition"),
            },
            IndexExpr::Not(e) => match e.eval(lookup)? {
                IndexValue::Bool(b) => Ok(IndexValue::Bool(!b)),
                IndexValue::Int(_) => fail(0..0, "`not` applies to a condition, not a number"),
            },
            IndexExpr::Binary(op, a, b, span) => {
                let x = a.eval(lookup)?;
                let y = b.eval(lookup)?;
                binary(*op, x, y, span.clone())
            }
        }
    }

    /// The names the expression uses, in order (with repeats).
    pub fn names(&self) -> Vec<&str> {
        let mut out = Vec::new();
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            match e {
                IndexExpr::Int(_) => {}
                IndexExpr::Name(n, _) => out.push(n.as_str()),
                IndexExpr::Neg(a) | IndexExpr::Not(a) => stack.push(a),
                IndexExpr::Binary(_, a, b, _) => {
                    stack.push(b);
                    stack.push(a);
                }
            }
        }
        out
    }

    /// The value as an integer.
    pub fn int(&self, lookup: &Lookup) -> Result<i64, IndexError> {
        match self.eval(lookup)? {
            IndexValue::Int(v) => Ok(v),
            IndexValue::Bool(_) => fail(0..0, "expected a number, found a condition"),
        }
    }

    /// The value as a condition.
    pub fn condition(&self, lookup: &Lookup) -> Result<bool, IndexError> {
        match self.eval(lookup)? {
            IndexValue::Bool(b) => Ok(b),
            IndexValue::Int(_) => fail(
                0..0,
                "expected a condition (`i == 0`, `j < n-1`, `... and ...`), found a number",
            ),
        }
    }
}

fn overflow(span: Range<usize>) -> IndexError {
    IndexError {
        span,
        message: "index arithmetic overflows".to_string(),
    }
}

fn binary(
    op: Op,
    x: IndexValue,
    y: IndexValue,
    span: Range<usize>,
) -> Result<IndexValue, IndexError> {
    use IndexValue::{Bool, Int};
    match (op, x, y) {
        (Op::Or, Bool(a), Bool(b)) => Ok(Bool(a || b)),
        (Op::And, Bool(a), Bool(b)) => Ok(Bool(a && b)),
        (Op::Or | Op::And, _, _) => fail(span, "`and` and `or` join conditions, not numbers"),
        (_, Int(a), Int(b)) => {
            let v = match op {
                Op::Eq => return Ok(Bool(a == b)),
                Op::Ne => return Ok(Bool(a != b)),
                Op::Lt => return Ok(Bool(a < b)),
                Op::Le => return Ok(Bool(a <= b)),
                Op::Gt => return Ok(Bool(a > b)),
                Op::Ge => return Ok(Bool(a >= b)),
                Op::Add => a.checked_add(b),
                Op::Sub => a.checked_sub(b),
                Op::Mul => a.checked_mul(b),
                Op::Div | Op::Rem if b == 0 => return fail(span, "division by zero"),
                // Floor division and a non-negative remainder: `(i-1) % n` wraps around a ring.
                Op::Div => a.checked_div_euclid(b),
                Op::Rem => a.checked_rem_euclid(b),
                Op::Or | Op::And => unreachable!("handled above"),
            };
            v.map(Int).ok_or_else(|| overflow(span))
        }
        _ => fail(span, "this operator takes two numbers, not conditions"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lookup(name: &str) -> Result<Option<i64>, String> {
        Ok(match name {
            "i" => Some(3),
            "j" => Some(0),
            "n" => Some(5),
            _ => None,
        })
    }

    #[test]
    fn arithmetic_and_conditions() {
        let int = |t: &str| parse(t).unwrap().int(&lookup).unwrap();
        assert_eq!(int("i+1"), 4);
        assert_eq!(int("2*n - (i + 1)"), 6);
        assert_eq!(int("-1 % n"), 4);
        assert_eq!(int("-7 / 2"), -4);
        let cond = |t: &str| parse(t).unwrap().condition(&lookup).unwrap();
        assert!(cond("j == 0 and (i == 0 or i == n-2)"));
        assert!(!cond("not (i < n)"));
        assert!(cond("i != 2 && j <= 0"));
    }

    #[test]
    fn ranges_and_for_lists() {
        let r = parse_range("0..n-1").unwrap();
        assert_eq!(r.lo.int(&lookup).unwrap(), 0);
        assert_eq!(r.hi.int(&lookup).unwrap(), 4);
        let f = parse_for("i in 0..n-2, j").unwrap();
        assert_eq!(f.len(), 2);
        assert!(f[0].range.is_some() && f[1].range.is_none());
        assert!(parse_for("i, i").unwrap_err().message.contains("twice"));
        // A name alone after `in` is a table; a range may still start with a size.
        let f = parse_for("e in bars, j in n..n+1").unwrap();
        assert_eq!(f[0].table, Some(("bars".to_string(), 5..9)));
        assert!(f[0].range.is_none() && f[1].table.is_none() && f[1].range.is_some());
        assert!(parse_for("e in bars j").is_err());
    }

    #[test]
    fn errors_are_located_in_the_text() {
        let e = parse("i + m").unwrap().int(&lookup).unwrap_err();
        assert_eq!(e.span, 4..5);
        let e = parse("i $ 1").unwrap_err();
        assert_eq!(e.span, 2..3);
        let e = parse("n / (i - 3)").unwrap().int(&lookup).unwrap_err();
        assert!(e.message.contains("division by zero"));
        let e = parse("9223372036854775807 + 1")
            .unwrap()
            .int(&lookup)
            .unwrap_err();
        assert!(e.message.contains("overflow"));
        assert!(parse(&("(".repeat(100) + "1" + &")".repeat(100))).is_err());
        assert!(parse_range("0, 4").is_err());
    }

    #[test]
    fn subscripts_split_with_offsets() {
        let (base, parts) = split_subscript("P[i+1, j]").unwrap();
        assert_eq!(base, "P");
        assert_eq!(parts, vec![("i+1", 2), (" j", 6)]);
        assert!(split_subscript("P").is_none());
    }
}
