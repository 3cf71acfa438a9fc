//! Dimension inference: every expression of a model gets a dimension, names without units get
//! theirs from how they are used, and a sum of a force and a velocity is refused with both
//! terms named.
//!
//! A dimension here is affine in unknowns: `kg·m/s^2 · [c]^1 · [x]^-1`, where `[c]` is the
//! dimension of a name nobody gave units to. Each base dimension (length, mass, time,
//! temperature) is one linear equation in the same unknowns, so "these two terms have the same
//! dimension" is solved by Gaussian elimination, one unknown per equation, as Hindley–Milner
//! does for types (Kennedy, "Dimension types", ESOP 1994). Checking every input this way —
//! each term of each sum homogeneous, positions lengths, masses masses, forces forces, the
//! arguments of `sin` and `exp` pure numbers — makes every term of the derived F = m a a force.
//!
//! Literal zeros take any dimension (`[x, 0, 0]`); other plain numbers take the dimension their
//! context needs when they stand as a whole term (`[2, y, 0]`, `y - 2`) and are pure numbers
//! when they multiply or divide (`2*x`).

use num_traits::{CheckedAdd, CheckedMul};
use pdyn_expr::dimension::{Dimension, Exponent};
use pdyn_expr::syntax::{Ast, BinOp};
use rustc_hash::FxHashMap;
use std::collections::BTreeMap;
use std::ops::Range;

/// A dimension with unknown factors: `known · Π [var]^power`.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Form {
    known: Dimension,
    vars: BTreeMap<usize, Exponent>,
}

impl From<Dimension> for Form {
    fn from(known: Dimension) -> Form {
        Form {
            known,
            vars: BTreeMap::new(),
        }
    }
}

impl Form {
    /// `self · other`; `None` on exponent overflow.
    pub fn mul(&self, other: &Form) -> Option<Form> {
        let mut out = Form {
            known: self.known.mul(&other.known)?,
            vars: self.vars.clone(),
        };
        for (v, p) in &other.vars {
            let e = out.vars.entry(*v).or_default();
            *e = e.checked_add(p)?;
            if *e == Exponent::default() {
                out.vars.remove(v);
            }
        }
        Some(out)
    }

    /// `self^p`; `None` on overflow.
    pub fn pow(&self, p: Exponent) -> Option<Form> {
        let mut vars = BTreeMap::new();
        if p != Exponent::default() {
            for (v, e) in &self.vars {
                vars.insert(*v, e.checked_mul(&p)?);
            }
        }
        Some(Form {
            known: self.known.pow(p)?,
            vars,
        })
    }

    /// `self / other`; `None` on overflow.
    pub fn div(&self, other: &Form) -> Option<Form> {
        self.mul(&other.pow((-1).into())?)
    }
}

/// A dimension error at a span of the model file.
#[derive(Clone, Debug, PartialEq)]
pub struct DimensionError {
    /// Byte range in the file.
    pub span: Range<usize>,
    /// What is wrong, naming both sides and their dimensions.
    pub message: String,
    /// What would be valid.
    pub help: String,
}

/// The dimensions of a model's names and the equations among them.
#[derive(Default)]
pub struct Inference {
    names: FxHashMap<String, Form>,
    /// Solved unknowns, each written without other solved ones.
    solved: BTreeMap<usize, Form>,
    /// For each unknown, the solved ones whose solution may mention it (a superset: entries
    /// are not removed when a solution is rewritten). Solving an unknown rewrites only
    /// these, where scanning every solution made loading a 100-link chain quadratic.
    mentioned_in: FxHashMap<usize, Vec<usize>>,
    labels: Vec<String>,
    /// Every inconsistency found, in the order met.
    pub errors: Vec<DimensionError>,
    /// Whether any unit was written (only then are errors reported: a model in plain numbers
    /// is dimensionless by convention and may add `1` to a length).
    pub has_units: bool,
}

/// Where the text of an expression is: its source and its offset in the file.
#[derive(Clone, Copy)]
pub struct Source<'a> {
    /// The expression's text.
    pub text: &'a str,
    /// Byte offset of `text` in the file.
    pub offset: usize,
}

impl Source<'_> {
    fn snippet(&self, span: &Range<usize>) -> String {
        let s = self.text.get(span.clone()).unwrap_or("?").trim();
        if s.chars().count() > 60 {
            let short: String = s.chars().take(57).collect();
            format!("{short}...")
        } else {
            s.to_string()
        }
    }
    fn at(&self, span: &Range<usize>) -> Range<usize> {
        span.start + self.offset..span.end + self.offset
    }
}

impl Inference {
    /// A new unknown dimension, called `label` in messages.
    pub fn fresh(&mut self, label: &str) -> Form {
        let v = self.labels.len();
        self.labels.push(label.to_string());
        Form {
            known: Dimension::NONE,
            vars: BTreeMap::from([(v, 1.into())]),
        }
    }

    /// Gives `name` a dimension.
    pub fn bind(&mut self, name: &str, form: Form) {
        self.names.insert(family_key(name).into_owned(), form);
    }

    /// Forgets `name` (a local such as `dist` in a potential).
    pub fn unbind(&mut self, name: &str) {
        self.names.remove(name);
    }

    /// Gives `name` an unknown dimension of its own.
    pub fn bind_unknown(&mut self, name: &str) {
        let f = self.fresh(name);
        self.bind(name, f);
    }

    /// The dimension of `name`, if declared.
    pub fn of(&self, name: &str) -> Option<Form> {
        self.names
            .get(family_key(name).as_ref())
            .map(|f| self.normalize(f))
    }

    /// `form` with every solved unknown replaced by its solution.
    pub fn normalize(&self, form: &Form) -> Form {
        let mut out = Form::from(form.known);
        for (v, p) in &form.vars {
            let part = match self.solved.get(v) {
                Some(sol) => sol.pow(*p),
                None => Some(Form {
                    known: Dimension::NONE,
                    vars: BTreeMap::from([(*v, *p)]),
                }),
            };
            match part.and_then(|x| out.mul(&x)) {
                Some(o) => out = o,
                None => return form.clone(),
            }
        }
        out
    }

    /// Makes `a` and `b` the same dimension. `Err` with both, normalised, when they cannot be;
    /// `Ok` also when exponents overflow (nothing can be concluded then).
    pub fn unify(&mut self, a: &Form, b: &Form) -> Result<(), Box<(Form, Form)>> {
        if a == b {
            // Equal before normalising, equal after: nothing to solve. Most terms of a sum
            // and the components of a vector are alike; normalising both sides of each pair
            // was a third of inferring a 100-link chain's positions.
            return Ok(());
        }
        let (a, b) = (self.normalize(a), self.normalize(b));
        let Some(h) = a.div(&b) else { return Ok(()) };
        let Some((&v, &c)) = h.vars.iter().next_back() else {
            return if h.known.is_none() {
                Ok(())
            } else {
                Err(Box::new((a, b)))
            };
        };
        // [v]^c · rest = 1  ⇒  [v] = rest^(-1/c).
        let mut rest = h.clone();
        rest.vars.remove(&v);
        let Some(sol) = rest.pow(-c.recip()) else {
            return Ok(());
        };
        // Earlier solutions that mention v are rewritten with its solution.
        let mut updated = Vec::new();
        for k in self.mentioned_in.remove(&v).unwrap_or_default() {
            let Some(f) = self.solved.get(&k) else {
                continue;
            };
            if let Some(p) = f.vars.get(&v) {
                let mut g = f.clone();
                g.vars.remove(&v);
                if let Some(g) = sol.pow(*p).and_then(|s| g.mul(&s)) {
                    updated.push((k, g));
                }
            }
        }
        for (k, g) in updated {
            for &u in g.vars.keys() {
                self.mentioned_in.entry(u).or_default().push(k);
            }
            self.solved.insert(k, g);
        }
        for &u in sol.vars.keys() {
            self.mentioned_in.entry(u).or_default().push(v);
        }
        self.solved.insert(v, sol);
        Ok(())
    }

    /// How `form` reads in a message: `kg·m/s^2 (force)`, or `m/s · [c]` while `c` is unknown.
    pub fn describe(&self, form: &Form) -> String {
        let f = self.normalize(form);
        if f.vars.is_empty() {
            return f.known.describe();
        }
        let vars: Vec<String> = f
            .vars
            .iter()
            .map(|(v, p)| {
                let name = &self.labels[*v];
                if *p == 1.into() {
                    format!("[{name}]")
                } else {
                    format!("[{name}]^{p}")
                }
            })
            .collect();
        let vars = vars.join("·");
        if f.known.is_none() {
            format!("the dimension {vars}")
        } else {
            format!("{} · {vars}", f.known)
        }
    }

    /// Requires `form` (of the text at `span`) to be `want`, called `what` in the message.
    pub fn require(
        &mut self,
        form: &Form,
        want: &Form,
        span: Range<usize>,
        what: &str,
        help: &str,
    ) {
        if let Err(pair) = self.unify(form, want) {
            let (got, want) = *pair;
            let message = format!(
                "{what} has the dimension {}, but it must be {}",
                self.describe(&got),
                self.describe(&want)
            );
            self.errors.push(DimensionError {
                span,
                message,
                help: help.to_string(),
            });
        }
    }

    /// Requires the two expressions `a` and `b` to have one dimension; `why` completes
    /// "dimension mismatch" in the message (" between the two sides of a constraint").
    pub fn mismatch(&mut self, src: Source, a: (&Ast, &Form), b: (&Ast, &Form), why: &str) {
        if let Err(pair) = self.unify(a.1, b.1) {
            let (fa, fb) = *pair;
            let span = a.0.span().start.min(b.0.span().start)..a.0.span().end.max(b.0.span().end);
            let message = format!(
                "dimension mismatch{why}: `{}` is {} but `{}` is {}",
                src.snippet(&a.0.span()),
                self.describe(&fa),
                src.snippet(&b.0.span()),
                self.describe(&fb)
            );
            self.errors.push(DimensionError {
                span: src.at(&span),
                message,
                help: "give both terms the same units, or give the parameters their units \
                       (k = \"100 N/m\") so that pdyn can tell which one is wrong"
                    .into(),
            });
        }
    }

    fn must_be_number(&mut self, src: Source, ast: &Ast, form: &Form, what: &str) {
        if let Err(pair) = self.unify(form, &Form::from(Dimension::NONE)) {
            let got = pair.0;
            let message = format!(
                "{what} must be a pure number, but `{}` is {}",
                src.snippet(&ast.span()),
                self.describe(&got)
            );
            self.errors.push(DimensionError {
                span: src.at(&ast.span()),
                message,
                help: "divide by a quantity of the same dimension (sin(omega*t), exp(-t/tau))"
                    .into(),
            });
        }
    }

    /// The dimension of an expression; [`Inference::has_units`] is set when it contains a unit.
    pub fn infer(&mut self, ast: &Ast, src: Source) -> Form {
        self.infer_as(ast, src, true)
    }

    /// [`Inference::infer`] of an expression standing as a whole term (`term`: a summand, a
    /// vector component, a whole field) or as a factor.
    fn infer_as(&mut self, ast: &Ast, src: Source, term: bool) -> Form {
        match self.walk(ast, src, term) {
            Some(f) => f,
            None => self.fresh("?"),
        }
    }

    fn walk(&mut self, ast: &Ast, src: Source, term: bool) -> Option<Form> {
        Some(match ast {
            // A number without a unit that stands as a whole term (`[2, y, 0]`, `y - 2`,
            // `x + 0.5`) has an unknown unit and takes the dimension its context needs, as
            // in Modelica's unit checking: engineers write SI values bare. A number that
            // multiplies or divides (`2*x`, `x/3`) is a pure scale factor. Zero is anything.
            Ast::Num { text, .. } => {
                if term || pdyn_expr::lower::literal(text).is_some_and(|n| n.is_zero()) {
                    self.fresh(text)
                } else {
                    Form::from(Dimension::NONE)
                }
            }
            Ast::Quantity { unit, .. } => {
                let d = unit.dimension()?;
                // An angle alone (`30 deg`) is a pure number: it does not make a model
                // written in plain numbers strict.
                self.has_units |= d != Dimension::NONE;
                Form::from(d)
            }
            Ast::Ident { name, .. } => match name.as_str() {
                "t" => Form::from(Dimension::TIME),
                _ => match self.names.get(family_key(name).as_ref()) {
                    Some(f) => f.clone(),
                    None if name == "pi" || name == "e" => Form::from(Dimension::NONE),
                    None => self.fresh(name),
                },
            },
            Ast::Neg { expr, .. } => self.walk(expr, src, term)?,
            Ast::Binary { op, lhs, rhs, .. } => {
                let additive = matches!(op, BinOp::Add | BinOp::Sub);
                let a = self.infer_as(lhs, src, additive);
                match op {
                    BinOp::Add | BinOp::Sub => {
                        let b = self.infer_as(rhs, src, true);
                        self.mismatch(src, (lhs, &a), (rhs, &b), "");
                        a
                    }
                    BinOp::Mul => a.mul(&self.infer_as(rhs, src, false))?,
                    BinOp::Div => a.div(&self.infer_as(rhs, src, false))?,
                    BinOp::Pow => match constant_exponent(rhs) {
                        Some(p) => a.pow(p)?,
                        None => {
                            let b = self.infer_as(rhs, src, false);
                            self.must_be_number(src, rhs, &b, "an exponent");
                            self.must_be_number(src, lhs, &a, "the base of a symbolic power");
                            Form::from(Dimension::NONE)
                        }
                    },
                }
            }
            Ast::Call { name, args, .. } => self.call(name, args, src)?,
            Ast::Vector { items, .. } => {
                let forms: Vec<Form> = items.iter().map(|i| self.infer_as(i, src, true)).collect();
                for k in 1..items.len() {
                    self.mismatch(
                        src,
                        (&items[0], &forms[0]),
                        (&items[k], &forms[k]),
                        " between the components of a vector",
                    );
                }
                forms.into_iter().next()?
            }
            Ast::Prime { expr, count, .. } => {
                let f = self.walk(expr, src, false)?;
                let t = Form::from(Dimension::TIME).pow((*count as i64).into())?;
                f.div(&t)?
            }
            Ast::Component { expr, .. } => self.walk(expr, src, false)?,
        })
    }

    fn call(&mut self, name: &str, args: &[Ast], src: Source) -> Option<Form> {
        // `min(x, 0.5)`, `abs(2)`: the arguments of the functions that keep a dimension are
        // terms; those of `sin`, `sqrt`... are factors (a pure number there stays one).
        let keeps = matches!(name, "abs" | "min" | "max" | "atan2" | "norm");
        let forms: Vec<Form> = args.iter().map(|a| self.infer_as(a, src, keeps)).collect();
        let first = || forms.first().cloned();
        Some(match name {
            "sqrt" => first()?.pow(Exponent::new(1, 2))?,
            "abs" => first()?,
            "sign" | "unit" => Form::from(Dimension::NONE),
            "norm" => first()?,
            "dot" | "cross" if forms.len() == 2 => forms[0].mul(&forms[1])?,
            "min" | "max" | "atan2" if args.len() == 2 => {
                let why = format!(" between the arguments of `{name}`");
                self.mismatch(src, (&args[0], &forms[0]), (&args[1], &forms[1]), &why);
                if name == "atan2" {
                    Form::from(Dimension::NONE)
                } else {
                    first()?
                }
            }
            _ if pdyn_expr::Func::from_name(name).is_some() => {
                for (a, f) in args.iter().zip(&forms) {
                    self.must_be_number(src, a, f, &format!("the argument of `{name}`"));
                }
                Form::from(Dimension::NONE)
            }
            // `x(t)`: a coordinate written as a function of time.
            _ => match self.names.get(name) {
                Some(f) => f.clone(),
                None => self.fresh(name),
            },
        })
    }
}

/// The value of an exponent made only of numbers (`2`, `-1/2`, `1.5`), as a small rational.
fn constant_exponent(ast: &Ast) -> Option<Exponent> {
    match ast {
        Ast::Num { text, .. } => {
            let (p, q) = pdyn_expr::lower::literal(text)?.as_rational()?.small()?;
            Some(Exponent::new(p, q))
        }
        Ast::Neg { expr, .. } => constant_exponent(expr).map(|e| -e),
        Ast::Binary { op, lhs, rhs, .. } => {
            let (a, b) = (constant_exponent(lhs)?, constant_exponent(rhs)?);
            use num_traits::{CheckedDiv, CheckedSub};
            match op {
                BinOp::Add => a.checked_add(&b),
                BinOp::Sub => a.checked_sub(&b),
                BinOp::Mul => a.checked_mul(&b),
                BinOp::Div if b != 0.into() => a.checked_div(&b),
                _ => None,
            }
        }
        _ => None,
    }
}

/// The key under which a name's dimension is kept: the members of a family (`x[3,4]`, and
/// `x[i+1, j]` as written in a member's expression) share their family's, `x[]`.
fn family_key(name: &str) -> std::borrow::Cow<'_, str> {
    match name.find('[') {
        Some(open) if name.ends_with(']') => format!("{}[]", &name[..open]).into(),
        _ => name.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn infer(inf: &mut Inference, text: &str) -> Form {
        let ast = pdyn_expr::syntax::parse(text).unwrap();
        inf.infer(&ast, Source { text, offset: 0 })
    }

    #[test]
    fn unknowns_are_solved_from_use() {
        let mut inf = Inference::default();
        inf.bind(
            "k",
            Form::from(Dimension::FORCE.div(&Dimension::LENGTH).unwrap()),
        );
        inf.bind_unknown("x");
        inf.bind_unknown("c");
        inf.bind_unknown("m");
        let pos = infer(&mut inf, "[x, 0, 0]");
        inf.require(&pos, &Dimension::LENGTH.into(), 0..0, "a position", "");
        let f = infer(&mut inf, "-k*x - c*x'");
        inf.require(&f, &Dimension::FORCE.into(), 0..0, "a force", "");
        assert!(inf.errors.is_empty(), "{:?}", inf.errors);
        assert_eq!(
            inf.describe(&inf.of("c").unwrap()),
            "kg/s (damping coefficient)"
        );
        let w = infer(&mut inf, "sqrt(k/m)*t");
        inf.unify(&w, &Dimension::NONE.into()).unwrap();
        assert_eq!(inf.describe(&inf.of("m").unwrap()), "kg (mass)");
    }

    #[test]
    fn a_solution_is_rewritten_when_an_unknown_it_mentions_is_solved() {
        let mut inf = Inference::default();
        let a = inf.fresh("a");
        let b = inf.fresh("b");
        let c = inf.fresh("c");
        // b = a·m, then c = b·s (both mention unknowns solved later), then a = kg.
        inf.unify(&b, &a.mul(&Dimension::LENGTH.into()).unwrap())
            .unwrap();
        inf.unify(&c, &b.mul(&Dimension::TIME.into()).unwrap())
            .unwrap();
        inf.unify(&a, &Dimension::MASS.into()).unwrap();
        let mass_length = Dimension::MASS.mul(&Dimension::LENGTH).unwrap();
        assert_eq!(inf.normalize(&b), Form::from(mass_length));
        let mass_length_time = mass_length.mul(&Dimension::TIME).unwrap();
        assert_eq!(inf.normalize(&c), Form::from(mass_length_time));
    }

    #[test]
    fn a_spring_force_added_to_a_velocity_names_both_terms() {
        let mut inf = Inference::default();
        inf.bind(
            "k",
            Form::from(Dimension::FORCE.div(&Dimension::LENGTH).unwrap()),
        );
        inf.bind("x", Dimension::LENGTH.into());
        let text = "-k*x + x'";
        infer(&mut inf, text);
        let e = &inf.errors[0];
        assert_eq!(e.span, 0..9);
        assert!(
            e.message.contains("`-k*x` is kg·m/s^2 (force)"),
            "{}",
            e.message
        );
        assert!(
            e.message.contains("`x'` is m/s (velocity)"),
            "{}",
            e.message
        );
    }

    #[test]
    fn functions_want_pure_numbers_and_zero_is_anything() {
        let mut inf = Inference::default();
        inf.bind("L", Dimension::LENGTH.into());
        infer(&mut inf, "[L*sin(t), 0, 0]");
        assert_eq!(inf.errors.len(), 1);
        assert!(
            inf.errors[0].message.contains("the argument of `sin`"),
            "{:?}",
            inf.errors
        );
        let mut inf = Inference::default();
        inf.bind("L", Dimension::LENGTH.into());
        infer(&mut inf, "2*pi/(120 s)*t + L^2/L^(4/2) - 3");
        assert!(inf.errors.is_empty(), "{:?}", inf.errors);
        assert!(inf.has_units);
    }
}
