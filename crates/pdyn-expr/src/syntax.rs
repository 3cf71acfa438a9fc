//! The expression language: tokens and a recursive-descent parser producing a spanned AST.
//!
//! ```text
//! equation := expr ('=' | '==') expr
//! expr     := term (('+' | '-') term)*
//! term     := unary (('*' | '/') unary)*
//! unary    := ('-' | '+') unary | power
//! power    := postfix (('^' | '**') unary)?          right associative: 2^-x, -x^2 = -(x^2)
//! postfix  := primary ("'" | '.' ('x'|'y'|'z'))*     x'' is the second time derivative
//! primary  := number unit? | ident | ident '(' args ')' | '(' expr ')' | '[' expr, expr (, expr)? ']'
//! ```
//! Numbers: `12`, `1.5`, `.5`, `1.5e-3`, optionally followed by a unit (`120 s`, `9.81 m/s^2`,
//! `45 deg`: see [`crate::units`]); a name after a number that is not a unit is an error
//! (multiplication is written with `*`). Identifiers: letters (Unicode allowed, e.g. `θ`),
//! digits and `_`, not starting with a digit. A name followed at once by a subscript,
//! `x[i+1, j]`, is one identifier (a member of an indexed family in a model file): the
//! subscript is kept as written for the scope to resolve.

use crate::error::ExprError;
use std::ops::Range;

/// Binary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

/// A parsed expression with source spans.
#[derive(Clone, Debug, PartialEq)]
#[allow(missing_docs)]
pub enum Ast {
    /// A numeric literal, kept as text so that it converts exactly.
    Num { text: String, span: Range<usize> },
    /// A number with a unit: `120 s`, `9.81 m/s^2`.
    Quantity {
        text: String,
        unit: crate::units::UnitExpr,
        span: Range<usize>,
    },
    /// A name.
    Ident { name: String, span: Range<usize> },
    /// `-expr`.
    Neg { expr: Box<Ast>, span: Range<usize> },
    /// `lhs op rhs`.
    Binary {
        op: BinOp,
        lhs: Box<Ast>,
        rhs: Box<Ast>,
        span: Range<usize>,
    },
    /// `name(args)`.
    Call {
        name: String,
        name_span: Range<usize>,
        args: Vec<Ast>,
        span: Range<usize>,
    },
    /// `[a, b, c]` (or `[a, b]` for a planar vector).
    Vector { items: Vec<Ast>, span: Range<usize> },
    /// `expr'` repeated `count` times: time derivative.
    Prime {
        expr: Box<Ast>,
        count: u8,
        span: Range<usize>,
    },
    /// `expr.x` (component 0), `.y` (1), `.z` (2).
    Component {
        expr: Box<Ast>,
        index: usize,
        span: Range<usize>,
    },
}

impl Ast {
    fn set_span(&mut self, to: Range<usize>) {
        match self {
            Ast::Num { span, .. }
            | Ast::Quantity { span, .. }
            | Ast::Ident { span, .. }
            | Ast::Neg { span, .. }
            | Ast::Binary { span, .. }
            | Ast::Call { span, .. }
            | Ast::Vector { span, .. }
            | Ast::Prime { span, .. }
            | Ast::Component { span, .. } => *span = to,
        }
    }

    /// Whether `pred` holds for the name of some identifier in the tree (a variable, or a
    /// function called by name).
    pub fn any_name(&self, pred: &dyn Fn(&str) -> bool) -> bool {
        match self {
            Ast::Num { .. } | Ast::Quantity { .. } => false,
            Ast::Ident { name, .. } => pred(name),
            Ast::Neg { expr, .. } | Ast::Prime { expr, .. } | Ast::Component { expr, .. } => {
                expr.any_name(pred)
            }
            Ast::Binary { lhs, rhs, .. } => lhs.any_name(pred) || rhs.any_name(pred),
            Ast::Call { name, args, .. } => pred(name) || args.iter().any(|a| a.any_name(pred)),
            Ast::Vector { items, .. } => items.iter().any(|a| a.any_name(pred)),
        }
    }

    /// Byte span covered by this node.
    pub fn span(&self) -> Range<usize> {
        match self {
            Ast::Num { span, .. }
            | Ast::Quantity { span, .. }
            | Ast::Ident { span, .. }
            | Ast::Neg { span, .. }
            | Ast::Binary { span, .. }
            | Ast::Call { span, .. }
            | Ast::Vector { span, .. }
            | Ast::Prime { span, .. }
            | Ast::Component { span, .. } => span.clone(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(String),
    Quantity(String, crate::units::UnitExpr),
    Ident(String),
    Op(char),
    Pow,
    Prime,
    Eq,
    End,
}

struct Lexer<'a> {
    src: &'a str,
    pos: usize,
}

impl<'a> Lexer<'a> {
    fn next(&mut self) -> Result<(Tok, Range<usize>), ExprError> {
        let bytes = self.src.as_bytes();
        while self.pos < bytes.len() && (bytes[self.pos] as char).is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        let Some(c) = self.src[self.pos..].chars().next() else {
            return Ok((Tok::End, start..start));
        };
        if c.is_ascii_digit()
            || (c == '.' && self.src[self.pos + 1..].starts_with(|d: char| d.is_ascii_digit()))
        {
            return self.number(start);
        }
        if c.is_alphabetic() || c == '_' {
            let mut end = start;
            for (i, ch) in self.src[start..].char_indices() {
                if ch.is_alphanumeric() || ch == '_' {
                    end = start + i + ch.len_utf8();
                } else {
                    break;
                }
            }
            // `x[i+1, j]`, written without a space: one member of an indexed family, whose
            // name the scope resolves (the indices are its business, not the parser's).
            if let Some(close) = member_subscript_end(&self.src[end..]) {
                end += close;
            }
            self.pos = end;
            return Ok((Tok::Ident(self.src[start..end].to_string()), start..end));
        }
        self.pos += c.len_utf8();
        let tok = match c {
            '+' | '-' | '/' | '(' | ')' | '[' | ']' | ',' | '.' => Tok::Op(c),
            '*' => {
                if self.src[self.pos..].starts_with('*') {
                    self.pos += 1;
                    Tok::Pow
                } else {
                    Tok::Op('*')
                }
            }
            '^' => Tok::Pow,
            '\'' => Tok::Prime,
            '=' => {
                if self.src[self.pos..].starts_with('=') {
                    self.pos += 1;
                }
                Tok::Eq
            }
            other => {
                return Err(ExprError::new(
                    start..self.pos,
                    format!("unexpected character `{other}`"),
                )
                .with_help(
                    "expressions use numbers, names, + - * / ^, ( ), [a, b, c], x' and f(x)",
                ))
            }
        };
        Ok((tok, start..self.pos))
    }

    fn number(&mut self, start: usize) -> Result<(Tok, Range<usize>), ExprError> {
        let b = self.src.as_bytes();
        let mut i = start;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i < b.len() && b[i] == b'.' {
            i += 1;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
        }
        if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
            let mut j = i + 1;
            if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                j += 1;
            }
            if j < b.len() && b[j].is_ascii_digit() {
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
                i = j;
            }
        }
        self.pos = i;
        let text = self.src[start..i].to_string();
        // A unit right after the number (`120 s`, `9.81m/s^2`).
        let mut j = i;
        while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
            j += 1;
        }
        if let Ok(Some((len, unit))) = crate::units::scan_unit(&self.src[j..], false) {
            self.pos = j + len;
            return Ok((Tok::Quantity(text, unit), start..j + len));
        }
        Ok((Tok::Num(text), start..i))
    }
}

/// Deepest nesting accepted, so that hostile input cannot overflow the stack.
const MAX_DEPTH: usize = 200;

struct Parser<'a> {
    lex: Lexer<'a>,
    tok: Tok,
    span: Range<usize>,
    depth: usize,
}

impl<'a> Parser<'a> {
    fn new(src: &'a str) -> Result<Parser<'a>, ExprError> {
        let mut lex = Lexer { src, pos: 0 };
        let (tok, span) = lex.next()?;
        Ok(Parser {
            lex,
            tok,
            span,
            depth: 0,
        })
    }

    fn bump(&mut self) -> Result<(), ExprError> {
        let (t, s) = self.lex.next()?;
        self.tok = t;
        self.span = s;
        Ok(())
    }

    fn describe(&self) -> String {
        match &self.tok {
            Tok::End => "end of input".to_string(),
            Tok::Num(n) => format!("number `{n}`"),
            Tok::Quantity(n, u) => format!("quantity `{n} {u}`"),
            Tok::Ident(n) => format!("name `{n}`"),
            Tok::Op(c) => format!("`{c}`"),
            Tok::Pow => "`^`".to_string(),
            Tok::Prime => "`'`".to_string(),
            Tok::Eq => "`=`".to_string(),
        }
    }

    fn expect_token(&mut self, c: char, what: &str) -> Result<Range<usize>, ExprError> {
        if self.tok == Tok::Op(c) {
            let s = self.span.clone();
            self.bump()?;
            Ok(s)
        } else {
            Err(ExprError::new(
                self.span.clone(),
                format!("expected `{c}` {what}, found {}", self.describe()),
            ))
        }
    }

    fn enter(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ExprError::new(
                self.span.clone(),
                format!("expression nested more than {MAX_DEPTH} levels deep"),
            ));
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<Ast, ExprError> {
        self.enter()?;
        let first = self.term()?;
        let mut rest = Vec::new();
        loop {
            let op = match self.tok {
                Tok::Op('+') => BinOp::Add,
                Tok::Op('-') => BinOp::Sub,
                _ => break,
            };
            self.bump()?;
            rest.push((op, self.term()?));
        }
        self.depth -= 1;
        Ok(chain(first, rest, BinOp::Add))
    }

    fn term(&mut self) -> Result<Ast, ExprError> {
        let first = self.unary()?;
        let mut rest = Vec::new();
        loop {
            let op = match self.tok {
                Tok::Op('*') => BinOp::Mul,
                Tok::Op('/') => BinOp::Div,
                _ => break,
            };
            self.bump()?;
            rest.push((op, self.unary()?));
        }
        Ok(chain(first, rest, BinOp::Mul))
    }

    fn unary(&mut self) -> Result<Ast, ExprError> {
        self.enter()?;
        let out = match self.tok {
            Tok::Op('-') => {
                let start = self.span.start;
                self.bump()?;
                let e = self.unary()?;
                let span = start..e.span().end;
                Ast::Neg {
                    expr: Box::new(e),
                    span,
                }
            }
            Tok::Op('+') => {
                self.bump()?;
                self.unary()?
            }
            _ => self.power()?,
        };
        self.depth -= 1;
        Ok(out)
    }

    fn power(&mut self) -> Result<Ast, ExprError> {
        let base = self.postfix()?;
        if self.tok == Tok::Pow {
            self.bump()?;
            let exp = self.unary()?;
            return Ok(binary(BinOp::Pow, base, exp));
        }
        Ok(base)
    }

    fn postfix(&mut self) -> Result<Ast, ExprError> {
        let mut e = self.primary()?;
        loop {
            match &self.tok {
                Tok::Prime => {
                    let start = e.span().start;
                    let mut count = 0usize;
                    let mut end = self.span.end;
                    while self.tok == Tok::Prime {
                        count += 1;
                        end = self.span.end;
                        self.bump()?;
                    }
                    let Ok(count) = u8::try_from(count) else {
                        return Err(ExprError::new(
                            start..end,
                            format!(
                                "{count} primes: a time derivative of order at most {} can be \
                                 written",
                                crate::budget::MAX_COORD_ORDER
                            ),
                        ));
                    };
                    e = Ast::Prime {
                        expr: Box::new(e),
                        count,
                        span: start..end,
                    };
                }
                Tok::Op('.') => {
                    self.bump()?;
                    let index = match &self.tok {
                        Tok::Ident(n) if n == "x" => 0,
                        Tok::Ident(n) if n == "y" => 1,
                        Tok::Ident(n) if n == "z" => 2,
                        _ => {
                            return Err(ExprError::new(
                                self.span.clone(),
                                format!(
                                    "expected a component after `.`, found {}",
                                    self.describe()
                                ),
                            )
                            .with_help("components are `.x`, `.y` and `.z`"))
                        }
                    };
                    let span = e.span().start..self.span.end;
                    self.bump()?;
                    e = Ast::Component {
                        expr: Box::new(e),
                        index,
                        span,
                    };
                }
                _ => return Ok(e),
            }
        }
    }

    fn primary(&mut self) -> Result<Ast, ExprError> {
        let span = self.span.clone();
        match self.tok.clone() {
            Tok::Num(text) => {
                self.bump()?;
                Ok(Ast::Num { text, span })
            }
            Tok::Quantity(text, unit) => {
                self.bump()?;
                Ok(Ast::Quantity { text, unit, span })
            }
            Tok::Ident(name) => {
                self.bump()?;
                if self.tok == Tok::Op('(') {
                    self.bump()?;
                    let mut args = Vec::new();
                    if self.tok != Tok::Op(')') {
                        args.push(self.expr()?);
                        while self.tok == Tok::Op(',') {
                            self.bump()?;
                            args.push(self.expr()?);
                        }
                    }
                    // The message is written only when it is needed (a chain's positions
                    // have ten thousand calls).
                    let close = if self.tok == Tok::Op(')') {
                        self.expect_token(')', "")?
                    } else {
                        self.expect_token(')', &format!("to close the call of `{name}`"))?
                    };
                    Ok(Ast::Call {
                        name,
                        name_span: span.clone(),
                        args,
                        span: span.start..close.end,
                    })
                } else {
                    Ok(Ast::Ident { name, span })
                }
            }
            Tok::Op('(') => {
                self.bump()?;
                let mut e = self.expr()?;
                let close = self.expect_token(')', "to close `(`")?;
                // The parentheses belong to the term: `2*pi/(120 s)` ends at `)`.
                e.set_span(span.start..close.end);
                Ok(e)
            }
            Tok::Op('[') => {
                self.bump()?;
                let mut items = vec![self.expr()?];
                while self.tok == Tok::Op(',') {
                    self.bump()?;
                    items.push(self.expr()?);
                }
                let close = self.expect_token(']', "to close the vector")?;
                Ok(Ast::Vector {
                    items,
                    span: span.start..close.end,
                })
            }
            _ => Err(ExprError::new(
                span,
                format!(
                    "expected a number, name, `(` or `[`, found {}",
                    self.describe()
                ),
            )),
        }
    }

    fn finish(&mut self) -> Result<(), ExprError> {
        if self.tok != Tok::End {
            let msg = format!(
                "unexpected {} after the end of the expression",
                self.describe()
            );
            let mut e = ExprError::new(self.span.clone(), msg);
            if matches!(
                self.tok,
                Tok::Ident(_) | Tok::Num(_) | Tok::Quantity(..) | Tok::Op('(')
            ) {
                e = e.with_help("write multiplication explicitly with `*`");
            }
            return Err(e);
        }
        Ok(())
    }
}

/// Chains of one precedence level longer than this are built as balanced trees.
const MAX_CHAIN: usize = 32;

/// `first op1 x1 op2 x2 ...` for the operators of one level (`+ -` with `plus = Add`, or
/// `* /` with `plus = Mul`). Short chains are left-associative as written. Long ones (a sum
/// of 20,000 terms) become a balanced tree, of depth log2(n) instead of n, so that no tree
/// walk can overflow the stack: `a - b + c ...` is the sum of `a`, `-b`, `c`...;
/// `a / b * c ...` is the product of the numerators over the product of the denominators
/// (equal in exact arithmetic, which is what the pool does).
fn chain(first: Ast, rest: Vec<(BinOp, Ast)>, plus: BinOp) -> Ast {
    if rest.len() < MAX_CHAIN {
        return rest
            .into_iter()
            .fold(first, |lhs, (op, rhs)| binary(op, lhs, rhs));
    }
    let mut pos = vec![first];
    let mut neg = Vec::new();
    for (op, x) in rest {
        if op == plus {
            pos.push(x);
        } else if plus == BinOp::Add {
            let span = x.span();
            pos.push(Ast::Neg {
                expr: Box::new(x),
                span,
            });
        } else {
            neg.push(x);
        }
    }
    let top = balanced(pos, plus);
    if neg.is_empty() {
        top
    } else {
        binary(BinOp::Div, top, balanced(neg, BinOp::Mul))
    }
}

/// `items` combined with `op` as a balanced binary tree (`items` is not empty).
fn balanced(mut items: Vec<Ast>, op: BinOp) -> Ast {
    while items.len() > 1 {
        let mut next = Vec::with_capacity(items.len().div_ceil(2));
        let mut it = items.into_iter();
        while let Some(a) = it.next() {
            next.push(match it.next() {
                Some(b) => binary(op, a, b),
                None => a,
            });
        }
        items = next;
    }
    items.pop().unwrap_or(Ast::Num {
        text: "0".into(),
        span: 0..0,
    })
}

fn binary(op: BinOp, lhs: Ast, rhs: Ast) -> Ast {
    let span = lhs.span().start..rhs.span().end;
    Ast::Binary {
        op,
        lhs: Box::new(lhs),
        rhs: Box::new(rhs),
        span,
    }
}

/// Parses one expression.
pub fn parse(src: &str) -> Result<Ast, ExprError> {
    let mut p = Parser::new(src)?;
    let e = p.expr()?;
    if p.tok == Tok::Eq {
        return Err(
            ExprError::new(p.span.clone(), "unexpected `=` in an expression")
                .with_help("an equation is only accepted where one is expected"),
        );
    }
    p.finish()?;
    Ok(e)
}

/// Parses `lhs = rhs` (or `lhs == rhs`). An expression without `=` means `expr = 0`.
pub fn parse_equation(src: &str) -> Result<(Ast, Option<Ast>), ExprError> {
    let mut p = Parser::new(src)?;
    let lhs = p.expr()?;
    if p.tok == Tok::Eq {
        p.bump()?;
        let rhs = p.expr()?;
        p.finish()?;
        return Ok((lhs, Some(rhs)));
    }
    p.finish()?;
    Ok((lhs, None))
}

/// The length of the subscript `[...]` that `rest` starts with, when it is one: a bracket
/// right after a name, holding no bracket, closed on the same line. Before families this was
/// always a syntax error (a name followed by a vector), so no valid expression changes
/// meaning.
fn member_subscript_end(rest: &str) -> Option<usize> {
    let inner = rest.strip_prefix('[')?;
    let close = inner.find([']', '[', '\n'])?;
    (inner.as_bytes()[close] == b']' && !inner[..close].trim().is_empty()).then_some(close + 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_and_spans() {
        let e = parse("a + b*c^2").unwrap();
        match e {
            Ast::Binary {
                op: BinOp::Add,
                rhs,
                span,
                ..
            } => {
                assert_eq!(span, 0..9);
                assert!(matches!(*rhs, Ast::Binary { op: BinOp::Mul, .. }));
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(parse("-x^2").unwrap(), Ast::Neg { .. }));
        assert!(matches!(parse("x''").unwrap(), Ast::Prime { count: 2, .. }));
        assert!(matches!(
            parse("r.z").unwrap(),
            Ast::Component { index: 2, .. }
        ));
    }

    #[test]
    fn errors_are_located() {
        let e = parse("2*(x + 1").unwrap_err();
        assert_eq!(e.span, 8..8);
        assert!(e.message.contains("expected `)`"));
        let e = parse("2 x").unwrap_err();
        assert_eq!(e.span, 2..3);
        assert!(e.help.unwrap().contains('*'));
        let e = parse("x # y").unwrap_err();
        assert_eq!(e.span, 2..3);
        let deep = "(".repeat(10_000) + "x" + &")".repeat(10_000);
        assert!(parse(&deep).unwrap_err().message.contains("nested"));
    }

    #[test]
    fn a_subscript_right_after_a_name_is_part_of_it() {
        let Ast::Binary { lhs, rhs, .. } = parse("x[i+1, j]'' + r_P[3,4].z").unwrap() else {
            panic!()
        };
        let Ast::Prime { expr, .. } = *lhs else {
            panic!()
        };
        assert!(
            matches!(*expr, Ast::Ident { ref name, span: ref s } if name == "x[i+1, j]" && *s == (0..9))
        );
        let Ast::Component { expr, .. } = *rhs else {
            panic!()
        };
        assert!(matches!(*expr, Ast::Ident { ref name, .. } if name == "r_P[3,4]"));
        // With a space it is a name followed by a vector, still an error; so is an empty or
        // unclosed subscript.
        assert!(parse("x [1, 2]").is_err());
        assert!(parse("x[]").is_err());
        assert!(parse("x[1").is_err());
        // A vector literal is not a subscript.
        assert!(matches!(parse("2*[1, 0, 0]").unwrap(), Ast::Binary { .. }));
    }
}
