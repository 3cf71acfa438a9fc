//! Printing: plain text that parses back to the same expression, LaTeX, and Rust source.
//!
//! All three printers share one view of products: sign, numerator factors and denominator
//! factors (numeric negative exponents and the coefficient's denominator go below the line),
//! so `-3*x/(2*y^2)` prints the same way in every format.

use crate::number::Number;
use crate::pool::{Constant, Func, Id, Node, Pool};

/// One factor of a product as printed.
#[derive(Clone, Debug, PartialEq)]
enum Factor {
    Number(Number),
    /// `base^exp` with `exp` a positive number (1 for a bare base).
    Power(Id, Number),
    /// `base^exp` with a symbolic exponent.
    Symbolic(Id, Id),
    /// One square root gathering several positive bases: `sqrt(g*mu/r)` instead of
    /// `sqrt(g)*sqrt(mu)/sqrt(r)` (index ranges into [`Fraction::roots`]).
    Root(usize),
}

struct Fraction {
    negative: bool,
    num: Vec<Factor>,
    den: Vec<Factor>,
    /// Bases under a merged square root: (numerator bases, denominator bases).
    roots: Vec<(Vec<Id>, Vec<Id>)>,
}

fn fraction(p: &Pool, id: Id) -> Fraction {
    let mut f = Fraction {
        negative: false,
        num: Vec::new(),
        den: Vec::new(),
        roots: Vec::new(),
    };
    let factors: Vec<Id> = match p.node(id) {
        Node::Mul(fs) => fs.to_vec(),
        _ => vec![id],
    };
    for x in factors {
        match p.node(x) {
            Node::Num(n) => {
                let n = if n.is_negative() {
                    f.negative = !f.negative;
                    n.neg()
                } else {
                    n.clone()
                };
                match &n {
                    // A big value with a short exact decimal form prints as one number
                    // (`1.3806503e-23`, not thirty zeros under a fraction bar).
                    Number::Rat(r) if r.small().is_none() && n.to_string().contains('e') => {
                        f.num.push(Factor::Number(n))
                    }
                    Number::Rat(r) => {
                        let (num, den) = (r.numer_big(), r.denom_big());
                        if num != 1.into() {
                            let k = crate::number::Rational::from_bigint(num);
                            f.num.push(Factor::Number(Number::Rat(k)));
                        }
                        if den != 1.into() {
                            let k = crate::number::Rational::from_bigint(den);
                            f.den.push(Factor::Number(Number::Rat(k)));
                        }
                    }
                    Number::Float(_) => f.num.push(Factor::Number(n)),
                }
            }
            Node::Pow(b, e) => match p.as_num(*e) {
                Some(en) if en.is_negative() => f.den.push(Factor::Power(*b, en.neg())),
                Some(en) => f.num.push(Factor::Power(*b, en)),
                None => f.num.push(Factor::Symbolic(*b, *e)),
            },
            _ => f.num.push(Factor::Power(x, Number::ONE)),
        }
    }
    // Merge square roots of positive bases (safe: sqrt(a)*sqrt(b) = sqrt(a*b) for a, b > 0, and
    // the parser splits it back the same way).
    let half = Number::ratio(1, 2);
    let is_root = |x: &Factor| matches!(x, Factor::Power(b, e) if *e == half && p.is_positive(*b));
    let count =
        f.num.iter().filter(|x| is_root(x)).count() + f.den.iter().filter(|x| is_root(x)).count();
    if count >= 2 {
        let take = |v: &mut Vec<Factor>| -> Vec<Id> {
            let bases = v
                .iter()
                .filter_map(|x| match x {
                    Factor::Power(b, e) if *e == half && p.is_positive(*b) => Some(*b),
                    _ => None,
                })
                .collect();
            v.retain(|x| !is_root(x));
            bases
        };
        let nb = take(&mut f.num);
        let db = take(&mut f.den);
        f.roots.push((nb, db));
        f.num.push(Factor::Root(0));
    }
    f
}

/// Operator precedence of what a node prints as (higher binds tighter).
fn precedence(p: &Pool, id: Id) -> u8 {
    match p.node(id) {
        Node::Add(_) => 1,
        Node::Mul(_) => 2,
        Node::Num(n) => match n {
            _ if n.is_negative() => 1,
            Number::Rat(r) if !r.is_integer() => 2,
            _ => 5,
        },
        Node::Pow(_, e) => match p.as_num(*e) {
            Some(en) if en.is_negative() => 2,
            Some(en) if en == Number::ratio(1, 2) => 5,
            _ => 3,
        },
        _ => 5,
    }
}

/// Text printer (the format the parser reads).
pub struct TextPrinter<'a> {
    pool: &'a Pool,
    /// Texts of long sums printed before (see [`TextMemo`]).
    memo: Option<&'a TextMemo>,
}

/// The texts of long sums already printed, for printing many expressions that share them:
/// the 100-link chain's `M` and `f` carry a hundred mass sums `m_k + … + m_100` in 15,000
/// places, which formatting anew was most of rendering them.
#[derive(Debug, Default)]
pub struct TextMemo(std::cell::RefCell<rustc_hash::FxHashMap<Id, String>>);

/// Sums of fewer terms are formatted each time (copying is no cheaper).
const MEMO_TERMS: usize = 8;

impl Pool {
    /// Plain text, re-parsable to the same expression: `-g*m*sin(theta) + m*r*omega^2`.
    pub fn to_text(&self, id: Id) -> String {
        TextPrinter {
            pool: self,
            memo: None,
        }
        .expr(id)
    }

    /// [`Pool::to_text`], reusing (and adding to) `memo`'s texts of long sums: the same text.
    pub fn to_text_memo(&self, id: Id, memo: &TextMemo) -> String {
        TextPrinter {
            pool: self,
            memo: Some(memo),
        }
        .expr(id)
    }

    /// LaTeX (math mode, without delimiters): `\frac{g m \cos\left(\theta\right)}{\sin\left(\phi\right)}`.
    pub fn to_latex(&self, id: Id) -> String {
        LatexPrinter { pool: self }.expr(id)
    }

    /// Text (or LaTeX) of `id` when it is at most `limit` characters long, its size otherwise
    /// (without formatting it at all past [`crate::budget::PRINT_NODES`] tree nodes): what
    /// every printout for a person goes through, with `limit` at most
    /// [`crate::budget::PRINT_CHARS`].
    pub fn to_text_within(
        &self,
        id: Id,
        latex: bool,
        limit: usize,
    ) -> Result<String, crate::budget::PrintSize> {
        use crate::budget::{PrintSize, PRINT_NODES};
        if self.tree_size(id, PRINT_NODES + 1) > PRINT_NODES {
            return Err(PrintSize::Nodes);
        }
        let s = if latex {
            self.to_latex(id)
        } else {
            self.to_text(id)
        };
        if s.chars().count() > limit {
            Err(PrintSize::Chars(s.chars().count()))
        } else {
            Ok(s)
        }
    }

    /// A Rust `f64` expression. `leaf` names symbols, coordinates and `t` (e.g. `|n| ...`);
    /// the default [`Pool::rust_leaf_name`] uses the symbol name, `x_d1` for `x'`, and `t`.
    pub fn to_rust(&self, id: Id, leaf: &dyn Fn(&Pool, &Node) -> String) -> String {
        RustPrinter { pool: self, leaf }.expr(id)
    }

    /// Default Rust identifier for a leaf node.
    pub fn rust_leaf_name(&self, node: &Node) -> String {
        match node {
            Node::Sym(s) => rust_identifier(self.name(*s)),
            Node::Coord(s, 0) => rust_identifier(self.name(*s)),
            Node::Coord(s, k) => format!("{}_d{k}", rust_identifier(self.name(*s))),
            Node::Time => "t".to_string(),
            _ => String::new(),
        }
    }
}

impl TextPrinter<'_> {
    fn expr(&self, id: Id) -> String {
        if let (Some(memo), Node::Add(ts)) = (self.memo, self.pool.node(id)) {
            if ts.len() >= MEMO_TERMS {
                if let Some(s) = memo.0.borrow().get(&id) {
                    return s.clone();
                }
                let s = self.expr_uncached(id);
                memo.0.borrow_mut().insert(id, s.clone());
                return s;
            }
        }
        self.expr_uncached(id)
    }

    fn expr_uncached(&self, id: Id) -> String {
        let p = self.pool;
        match p.node(id) {
            Node::Add(ts) => {
                let mut s = String::new();
                for (i, &t) in ts.iter().enumerate() {
                    // A bare symbol (most terms of a chain's mass sums `m2 + … + m100`) is
                    // its name: no product view to build.
                    let (neg, body) = match p.node(t) {
                        Node::Sym(x) => (false, std::borrow::Cow::Borrowed(p.name(*x))),
                        _ => {
                            let (neg, body) = self.term(t);
                            (neg, std::borrow::Cow::Owned(body))
                        }
                    };
                    s += term_separator(i, neg);
                    s += &body;
                }
                s
            }
            Node::Mul(_) | Node::Num(_) | Node::Pow(..) => {
                let (neg, body) = self.term(id);
                if neg {
                    format!("-{body}")
                } else {
                    body
                }
            }
            Node::Const(Constant::Pi) => "pi".into(),
            Node::Const(Constant::E) => "e".into(),
            Node::Time => "t".into(),
            Node::Sym(s) => p.name(*s).to_string(),
            Node::Coord(s, k) => format!("{}{}", p.name(*s), "'".repeat(*k as usize)),
            Node::Call(Func::Table(f), args) => {
                format!("{}({})", p.table_fn_name(*f), self.expr(args[0]))
            }
            Node::Call(f, args) => {
                let a: Vec<String> = args.iter().map(|&x| self.expr(x)).collect();
                format!("{}({})", f.name(), a.join(", "))
            }
        }
    }

    /// A term without its sign: (is negative, text).
    fn term(&self, id: Id) -> (bool, String) {
        let f = fraction(self.pool, id);
        let num = self.factors(&f.num, &f.roots);
        let num = if num.is_empty() { "1".to_string() } else { num };
        if f.den.is_empty() {
            return (f.negative, num);
        }
        let den = self.factors(&f.den, &f.roots);
        let den = if f.den.len() > 1 {
            format!("({den})")
        } else {
            den
        };
        (f.negative, format!("{num}/{den}"))
    }

    fn factors(&self, fs: &[Factor], roots: &[(Vec<Id>, Vec<Id>)]) -> String {
        let parts: Vec<String> = fs
            .iter()
            .map(|f| match f {
                Factor::Root(k) => {
                    let (nb, db) = &roots[*k];
                    let list = |v: &[Id]| -> String {
                        let s: Vec<String> = v.iter().map(|&b| self.wrap(b, 3)).collect();
                        s.join("*")
                    };
                    let n = if nb.is_empty() {
                        "1".to_string()
                    } else {
                        list(nb)
                    };
                    match db.len() {
                        0 => format!("sqrt({n})"),
                        1 => format!("sqrt({n}/{})", list(db)),
                        _ => format!("sqrt({n}/({}))", list(db)),
                    }
                }
                _ => self.factor(f.clone()),
            })
            .collect();
        parts.join("*")
    }

    fn factor(&self, f: Factor) -> String {
        let p = self.pool;
        match f {
            Factor::Number(n) => n.to_string(),
            Factor::Power(b, e) if e.is_one() => self.wrap(b, 3),
            Factor::Power(b, e) if e == Number::ratio(1, 2) => format!("sqrt({})", self.expr(b)),
            Factor::Power(b, e) => {
                let es = match e {
                    Number::Rat(ref r) if r.is_integer() => e.to_string(),
                    _ => format!("({e})"),
                };
                format!("{}^{es}", self.wrap(b, 4))
            }
            Factor::Root(_) => String::new(),
            Factor::Symbolic(b, e) => {
                let es = if precedence(p, e) >= 4 && !p.looks_negative(e) {
                    self.expr(e)
                } else {
                    format!("({})", self.expr(e))
                };
                format!("{}^{es}", self.wrap(b, 4))
            }
        }
    }

    fn wrap(&self, id: Id, min_prec: u8) -> String {
        if precedence(self.pool, id) >= min_prec && !self.pool.looks_negative(id) {
            self.expr(id)
        } else {
            format!("({})", self.expr(id))
        }
    }
}

/// `name` as a Rust identifier: a family member `x[3,-1]` is `x_3_m1`.
fn rust_identifier(name: &str) -> String {
    match name.strip_suffix(']').and_then(|n| n.split_once('[')) {
        Some((base, sub)) => {
            let sub = sub.replace('-', "m").replace([',', ' '], "_");
            format!("{base}_{sub}")
        }
        None => name.to_string(),
    }
}

/// LaTeX name of a symbol: Greek letters, subscripts after `_` (or in brackets, `x[3,4]`),
/// multi-letter names upright.
pub fn latex_name(name: &str) -> String {
    const GREEK: [&str; 34] = [
        "alpha",
        "beta",
        "gamma",
        "delta",
        "epsilon",
        "varepsilon",
        "zeta",
        "eta",
        "theta",
        "vartheta",
        "iota",
        "kappa",
        "lambda",
        "mu",
        "nu",
        "xi",
        "pi",
        "rho",
        "sigma",
        "tau",
        "upsilon",
        "phi",
        "varphi",
        "chi",
        "psi",
        "omega",
        "Gamma",
        "Delta",
        "Theta",
        "Lambda",
        "Xi",
        "Sigma",
        "Phi",
        "Omega",
    ];
    let one = |s: &str| -> String {
        if GREEK.contains(&s) {
            format!("\\{s}")
        } else if s.chars().count() > 1 && !s.chars().all(|c| c.is_ascii_digit()) {
            format!("\\mathrm{{{s}}}")
        } else {
            s.to_string()
        }
    };
    // A member of a family, `x[3,4]`, is the chapter's x_{3,4}.
    if let Some((base, sub)) = name.strip_suffix(']').and_then(|n| n.split_once('[')) {
        return format!("{}_{{{sub}}}", latex_name(base));
    }
    match name.split_once('_') {
        Some((base, sub)) if !base.is_empty() && !sub.is_empty() => {
            format!("{}_{{{}}}", one(base), one(sub))
        }
        _ => {
            // Trailing digits are a subscript, as SymPy prints them: `l1` is `l_{1}`,
            // `theta12` is `\theta_{12}` (not `\mathrm{l1}`).
            let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
            let (base, sub) = name.split_at(name.len() - digits);
            if digits > 0 && !base.is_empty() {
                format!("{}_{{{sub}}}", one(base))
            } else {
                one(name)
            }
        }
    }
}

struct LatexPrinter<'a> {
    pool: &'a Pool,
}

/// What goes before term `i` of a printed sum whose sign is `neg`: `-` or nothing for the
/// first, ` - ` or ` + ` between terms (text and LaTeX alike).
fn term_separator(i: usize, neg: bool) -> &'static str {
    match (i, neg) {
        (0, true) => "-",
        (0, false) => "",
        (_, true) => " - ",
        (_, false) => " + ",
    }
}

impl LatexPrinter<'_> {
    fn expr(&self, id: Id) -> String {
        let p = self.pool;
        match p.node(id) {
            Node::Add(ts) => {
                let mut s = String::new();
                for (i, &t) in ts.iter().enumerate() {
                    let (neg, body) = self.term(t);
                    s += term_separator(i, neg);
                    s += &body;
                }
                s
            }
            Node::Mul(_) | Node::Num(_) | Node::Pow(..) => {
                let (neg, body) = self.term(id);
                if neg {
                    format!("-{body}")
                } else {
                    body
                }
            }
            Node::Const(Constant::Pi) => "\\pi".into(),
            Node::Const(Constant::E) => "e".into(),
            Node::Time => "t".into(),
            Node::Sym(s) => latex_name(p.name(*s)),
            Node::Coord(s, k) => {
                let n = latex_name(p.name(*s));
                match k {
                    0 => n,
                    1 => format!("\\dot{{{n}}}"),
                    2 => format!("\\ddot{{{n}}}"),
                    3 => format!("\\dddot{{{n}}}"),
                    _ => format!("{n}^{{({k})}}"),
                }
            }
            Node::Call(f, args) => {
                let a: Vec<String> = args.iter().map(|&x| self.expr(x)).collect();
                let a = a.join(", ");
                match f {
                    Func::Abs => format!("\\left|{a}\\right|"),
                    Func::Sin
                    | Func::Cos
                    | Func::Tan
                    | Func::Sinh
                    | Func::Cosh
                    | Func::Tanh
                    | Func::Exp
                    | Func::Log
                    | Func::Min
                    | Func::Max => {
                        format!("\\{}\\left({a}\\right)", f.name())
                    }
                    Func::Asin => format!("\\arcsin\\left({a}\\right)"),
                    Func::Acos => format!("\\arccos\\left({a}\\right)"),
                    Func::Atan => format!("\\arctan\\left({a}\\right)"),
                    Func::Atan2 | Func::Sign => {
                        format!("\\operatorname{{{}}}\\left({a}\\right)", f.name())
                    }
                    Func::Table(t) => {
                        let name = self.pool.table(t.table).name.replace('_', "\\_");
                        format!(
                            "\\operatorname{{{name}}}{}\\left({a}\\right)",
                            "'".repeat(t.order as usize)
                        )
                    }
                }
            }
        }
    }

    fn term(&self, id: Id) -> (bool, String) {
        let f = fraction(self.pool, id);
        if f.den.is_empty() {
            let num = self.factors(&f.num, &f.roots);
            return (
                f.negative,
                if num.is_empty() { "1".to_string() } else { num },
            );
        }
        // Inside \frac a lone sum needs no parentheses.
        let side = |fs: &[Factor]| -> String {
            match fs {
                [] => "1".to_string(),
                [Factor::Power(b, e)] if e.is_one() => self.expr(*b),
                _ => self.factors(fs, &f.roots),
            }
        };
        let (n, d) = (side(&f.num), side(&f.den));
        (f.negative, format!("\\frac{{{n}}}{{{d}}}"))
    }

    fn factors(&self, fs: &[Factor], roots: &[(Vec<Id>, Vec<Id>)]) -> String {
        let mut s = String::new();
        for (i, f) in fs.iter().enumerate() {
            let part = match f {
                Factor::Root(k) => {
                    let (nb, db) = &roots[*k];
                    let list = |v: &[Id]| -> String {
                        let parts: Vec<String> = v
                            .iter()
                            .map(|&b| self.factor(Factor::Power(b, Number::ONE)))
                            .collect();
                        parts.join(" ")
                    };
                    let n = if nb.is_empty() {
                        "1".to_string()
                    } else {
                        list(nb)
                    };
                    if db.is_empty() {
                        format!("\\sqrt{{{n}}}")
                    } else {
                        format!("\\sqrt{{\\frac{{{n}}}{{{}}}}}", list(db))
                    }
                }
                _ => self.factor(f.clone()),
            };
            if i > 0 {
                s += if part.starts_with(|c: char| c.is_ascii_digit()) {
                    " \\cdot "
                } else {
                    " "
                };
            }
            s += &part;
        }
        s
    }

    fn factor(&self, f: Factor) -> String {
        let p = self.pool;
        let base = |b: Id| -> String {
            if precedence(p, b) >= 4 && !p.looks_negative(b) {
                self.expr(b)
            } else {
                format!("\\left({}\\right)", self.expr(b))
            }
        };
        match f {
            Factor::Number(n) => {
                let s = n.to_string();
                if s.contains('e') && !s.contains('/') {
                    // A float, or an exact decimal printed in e notation.
                    s.replace('e', " \\times 10^{") + "}"
                } else {
                    s
                }
            }
            Factor::Power(b, e) if e.is_one() => {
                if precedence(p, b) >= 3 && !p.looks_negative(b) {
                    self.expr(b)
                } else {
                    format!("\\left({}\\right)", self.expr(b))
                }
            }
            Factor::Power(b, e) if e == Number::ratio(1, 2) => {
                format!("\\sqrt{{{}}}", self.expr(b))
            }
            Factor::Power(b, e) => {
                let es = match e {
                    Number::Rat(r) if !r.is_integer() => {
                        format!("\\frac{{{}}}{{{}}}", r.numer_big(), r.denom_big())
                    }
                    _ => e.to_string(),
                };
                format!("{}^{{{es}}}", base(b))
            }
            Factor::Symbolic(b, e) => format!("{}^{{{}}}", base(b), self.expr(e)),
            Factor::Root(_) => String::new(),
        }
    }
}

struct RustPrinter<'a> {
    pool: &'a Pool,
    leaf: &'a dyn Fn(&Pool, &Node) -> String,
}

impl RustPrinter<'_> {
    fn num(n: Number) -> String {
        let x = n.to_f64();
        if x.is_nan() {
            "f64::NAN".into()
        } else if x.is_infinite() {
            if x > 0.0 {
                "f64::INFINITY"
            } else {
                "f64::NEG_INFINITY"
            }
            .into()
        } else {
            format!("{x:?}_f64")
        }
    }

    fn expr(&self, id: Id) -> String {
        let p = self.pool;
        match p.node(id) {
            Node::Num(n) => {
                let s = Self::num(n.clone());
                if n.is_negative() {
                    format!("({s})")
                } else {
                    s
                }
            }
            Node::Const(Constant::Pi) => "std::f64::consts::PI".into(),
            Node::Const(Constant::E) => "std::f64::consts::E".into(),
            node @ (Node::Time | Node::Sym(_) | Node::Coord(..)) => (self.leaf)(p, node),
            Node::Add(ts) => {
                let parts: Vec<String> = ts.iter().map(|&t| self.expr(t)).collect();
                format!("({})", parts.join(" + "))
            }
            Node::Mul(fs) => {
                let parts: Vec<String> = fs.iter().map(|&t| self.expr(t)).collect();
                format!("({})", parts.join(" * "))
            }
            Node::Pow(b, e) => {
                let bs = self.expr(*b);
                match p.as_num(*e) {
                    Some(n) if n == Number::ratio(1, 2) => format!("{bs}.sqrt()"),
                    Some(n) if n == Number::ratio(-1, 2) => format!("(1.0_f64 / {bs}.sqrt())"),
                    Some(n) if n.as_integer().is_some_and(|k| k.abs() < i32::MAX as i64) => {
                        format!("{bs}.powi({})", n.as_integer().unwrap_or(1))
                    }
                    _ => format!("{bs}.powf({})", self.expr(*e)),
                }
            }
            Node::Call(f, args) => {
                let a = self.expr(args[0]);
                match f {
                    Func::Atan2 => format!("{a}.atan2({})", self.expr(args[1])),
                    Func::Min => format!("{a}.min({})", self.expr(args[1])),
                    Func::Max => format!("{a}.max({})", self.expr(args[1])),
                    Func::Log => format!("{a}.ln()"),
                    Func::Sign => format!(
                        "{{ let s: f64 = {a}; if s > 0.0 {{ 1.0 }} else if s < 0.0 {{ -1.0 }} else {{ 0.0 }} }}"
                    ),
                    Func::Table(t) => format!(
                        "{}_d{}({a})",
                        self.pool.table(t.table).name,
                        t.order
                    ),
                    _ => format!("{a}.{}()", f.name()),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::pool::Pool;

    fn text(src: &str) -> String {
        let mut p = Pool::new();
        let e = p.parse_scalar(src).unwrap();
        p.to_text(e)
    }

    #[test]
    fn text_reads_naturally() {
        assert_eq!(text("x + x + x"), "3*x");
        assert_eq!(text("-(a - b)"), "-a + b");
        assert_eq!(text("3*x/(2*y^2)"), "3*x/(2*y^2)");
        assert_eq!(text("m*g*cos(theta)"), "g*m*cos(theta)");
        assert_eq!(text("x^(1/2)"), "sqrt(x)");
        assert_eq!(text("1/sqrt(x)"), "1/sqrt(x)");
        assert_eq!(text("x''*R"), "R*x''");
        assert_eq!(text("(a+b)^2"), "(a + b)^2");
        assert_eq!(text("2^(-x)"), "2^(-x)");
    }

    #[test]
    fn family_members_print_as_subscripts() {
        assert_eq!(super::latex_name("x[3,4]"), "x_{3,4}");
        assert_eq!(super::latex_name("theta[2]"), "\\theta_{2}");
        assert_eq!(super::rust_identifier("x[3,-1]"), "x_3_m1");
        assert_eq!(super::rust_identifier("x"), "x");
    }

    #[test]
    fn square_roots_of_positive_factors_merge() {
        let mut p = Pool::new();
        for n in ["g", "mu", "r"] {
            let s = p.symbol(n, true);
            let _ = p.sym(s);
        }
        let e = p.parse_scalar("sqrt(g*mu/r)").unwrap();
        assert_eq!(p.to_text(e), "sqrt(g*mu/r)");
        assert_eq!(p.parse_scalar("sqrt(g*mu/r)").unwrap(), e);
        assert_eq!(p.to_latex(e), "\\sqrt{\\frac{g \\mu}{r}}");
        // Not for symbols of unknown sign: sqrt(a)*sqrt(b) is not sqrt(a*b) for a, b < 0.
        let e = p.parse_scalar("sqrt(a)*sqrt(b)").unwrap();
        assert_eq!(p.to_text(e), "sqrt(a)*sqrt(b)");
    }

    #[test]
    fn latex_names_follow_sympys_subscripts() {
        // SymPy's `latex(Symbol(name))` for these names (split_super_sub: trailing digits and
        // what follows `_` are subscripts; Greek names are letters).
        for (name, sympy) in [
            ("l1", "l_{1}"),
            ("m23", "m_{23}"),
            ("theta1", "\\theta_{1}"),
            ("omega_n", "\\omega_{n}"),
            ("F_T", "F_{T}"),
            ("x", "x"),
            ("alpha", "\\alpha"),
        ] {
            assert_eq!(super::latex_name(name), sympy, "{name}");
        }
        // Multi-letter bases stay upright (SymPy prints them italic, letter by letter).
        assert_eq!(super::latex_name("th2"), "\\mathrm{th}_{2}");
    }

    #[test]
    fn latex_uses_greek_and_fractions() {
        let mut p = Pool::new();
        let e = p.parse_scalar("g*m*cos(theta)/sin(phi) + th''").unwrap();
        assert_eq!(
            p.to_latex(e),
            "\\frac{g m \\cos\\left(\\theta\\right)}{\\sin\\left(\\phi\\right)} + \\ddot{\\mathrm{th}}"
        );
        let e = p.parse_scalar("m_A*omega^2").unwrap();
        assert_eq!(p.to_latex(e), "m_{A} \\omega^{2}");
    }

    #[test]
    fn rust_source_evaluates() {
        let mut p = Pool::new();
        let e = p.parse_scalar("sqrt(x^2 + y^2)*sign(-x)").unwrap();
        let s = p.to_rust(e, &|p, n| p.rust_leaf_name(n));
        assert!(s.contains(".sqrt()"), "{s}");
        assert!(s.contains(".powi(2)"), "{s}");
    }
}
