//! A coordinate family's initial values and rates, evaluated as numbers over its members.
//!
//! `"x[i]" = { initial = "i*L + 0.01*L*sin(pi*i/(n+1))", rate = 0 }` over 10^4 members was
//! lowered to a symbolic expression and compiled once per member (a quarter of loading a
//! chain). Its text is the same for every member: it is lowered once with each index as a
//! symbol, compiled once over the parameters and the indices, and evaluated per member. The
//! members' expressions in the parameters (what `--set` and sweeps recompute the initial
//! state from) are kept as that one expression and each member's index values
//! ([`InitialFamily`]), and written out member by member only for a consumer that asks
//! ([`Model::materialize_initials`]; [`super::load`] does it before returning).
//!
//! Only texts in the parameters, the sizes and the member's own indices take this path; a
//! member whose value is not finite is read again the symbolic way, which reports it as
//! before (same message, same place), as are all other texts (units, unknowns, definitions,
//! table columns, other members). Lowered with a symbol for `i`, `(i - 3)/(i - 3)` is 1,
//! where the member `i = 3` divides by zero: each member's texts are also evaluated as
//! written, in floating point and nothing simplified (`Written`), and a member where
//! that is not finite is read the symbolic way too.

use super::loader::Loader;
use super::raw::Sv;
use super::{Model, ModelError};
use crate::dimensions::Form;
use crate::model::CoordinateKind;
use pdyn_expr::lower::{lower, Binding};
use pdyn_expr::{Id, Program, Value};
use rustc_hash::FxHashMap;

/// The initial values and rates of the members of one coordinate family read from one text.
#[derive(Clone, Debug)]
pub struct InitialFamily {
    /// The symbols standing for the family's indices in [`InitialFamily::initial`] and
    /// [`InitialFamily::rate`], in the order of each member's values.
    pub symbols: Vec<Id>,
    /// The initial value, in the parameters and the index symbols.
    pub initial: Id,
    /// The initial rate, likewise.
    pub rate: Id,
    /// The members: coordinate index in the model.
    pub coordinates: Vec<usize>,
    /// Their index values, `symbols.len()` per member, member after member.
    pub values: Vec<i64>,
}

impl InitialFamily {
    /// The `(coordinate, index values)` of each member.
    pub fn members(&self) -> impl Iterator<Item = (usize, &[i64])> + '_ {
        let k = self.symbols.len();
        self.coordinates
            .iter()
            .enumerate()
            .map(move |(m, &c)| (c, &self.values[m * k..(m + 1) * k]))
    }

    /// `[initial, rate]` over the parameters (`parameters`, in model order) and then the
    /// index symbols, compiled; `None` when it does not compile.
    fn program(&self, pool: &mut pdyn_expr::Pool, parameters: &[Id]) -> Option<Program> {
        let mut inputs = parameters.to_vec();
        inputs.extend(&self.symbols);
        Program::compile(pool, &inputs, &[self.initial, self.rate]).ok()
    }
}

/// A family's text compiled once, while the file is read.
pub(super) struct Compiled {
    /// The index names, in the order of a member's bindings.
    names: Vec<String>,
    program: Program,
    /// The parameters' values, then one slot per index.
    inputs: Vec<f64>,
    workspace: Vec<f64>,
    /// The members' dimension, once the first member's texts were checked.
    form: Option<Form>,
    /// The texts evaluated as written ([`Written`]), their numbers read and names resolved once.
    written: Vec<Written>,
    /// Which of [`Loader::initial_families`] its members go to.
    family: usize,
}

/// Per coordinate table of the file (by its byte offset): its compiled form, or `None` when
/// its texts take the symbolic path.
pub(super) type Cache = FxHashMap<usize, Option<Compiled>>;

impl Loader<'_> {
    /// The initial value and rate of the family member being read, from its family's
    /// compiled texts; `Ok(None)` when they take the symbolic path (not a member, texts that
    /// name more than parameters, sizes and indices, a value that is not finite).
    pub(super) fn family_initial(
        &mut self,
        sv: &Sv,
        t: &toml::Table,
        coordinate: usize,
    ) -> Result<Option<(f64, f64)>, ModelError> {
        if self.member.is_none() {
            return Ok(None);
        }
        let at = sv.span().start;
        if !self.family_initials.contains_key(&at) {
            let compiled = self.compile_family_initial(t);
            self.family_initials.insert(at, compiled);
        }
        let Some(Some(c)) = self.family_initials.get_mut(&at) else {
            return Ok(None);
        };
        let bindings = &self.scope.bindings;
        if bindings.len() != c.names.len() || bindings.iter().zip(&c.names).any(|(b, n)| &b.0 != n)
        {
            return Ok(None);
        }
        let first = c.inputs.len() - c.names.len();
        for (slot, (_, v)) in c.inputs[first..].iter_mut().zip(bindings) {
            *slot = *v as f64;
        }
        let mut out = [0.0; 2];
        c.program.eval(&c.inputs, &mut c.workspace, &mut out);
        let indices = &c.inputs[first..];
        let written = c
            .written
            .iter()
            .all(|w| w.eval(indices).is_some_and(f64::is_finite));
        if !written || !out.iter().all(|x| x.is_finite()) {
            // Read the symbolic way, which says what is wrong where.
            return Ok(None);
        }
        let family = &mut self.initial_families[c.family];
        family.coordinates.push(coordinate);
        family.values.extend(bindings.iter().map(|b| b.1));
        Ok(Some((out[0], out[1])))
    }

    /// The dimension of the members of the family that `sv` (a member's table) declares,
    /// once known.
    pub(super) fn family_form(&self, sv: &Sv) -> Option<Form> {
        let c = self.family_initials.get(&sv.span().start)?.as_ref()?;
        c.form.clone()
    }

    /// Records the dimension of the members of the family that `sv` declares.
    pub(super) fn set_family_form(&mut self, sv: &Sv, form: Form) {
        if let Some(Some(c)) = self.family_initials.get_mut(&sv.span().start) {
            c.form = Some(form);
        }
    }

    /// The family's `initial` and `rate` lowered with its indices as symbols and compiled,
    /// when both are texts in the parameters, the sizes and the indices alone.
    fn compile_family_initial(&mut self, t: &toml::Table) -> Option<Compiled> {
        let names: Vec<String> = self.scope.bindings.iter().map(|b| b.0.clone()).collect();
        let mut asts = Vec::with_capacity(2);
        for key in ["initial", "rate"] {
            let text = match t.get(key)? {
                toml::Value::String(s) => s.clone(),
                toml::Value::Integer(i) => i.to_string(),
                toml::Value::Float(f) => format!("{f:e}"),
                _ => return None,
            };
            if crate::units::looks_like_quantity(&text) {
                return None;
            }
            let ast = pdyn_expr::syntax::parse(&text).ok()?;
            if ast.any_name(&|name| !self.plain_name(name, &names)) {
                return None;
            }
            asts.push(ast);
        }
        let symbols: Vec<Id> = names
            .iter()
            .map(|n| {
                // A name no entry can have (`[` is not in names): the index, not a coordinate.
                let s = self.pool.symbol(&format!("[{n}]"), false);
                self.pool.sym(s)
            })
            .collect();
        let saved = std::mem::take(&mut self.scope.bindings);
        for (n, &s) in names.iter().zip(&symbols) {
            self.scope
                .local
                .insert(n.clone(), Binding::Value(Value::Scalar(s)));
        }
        let lowered: Vec<Option<Id>> = asts
            .iter()
            .map(|ast| match lower(&mut self.pool, ast, &mut self.scope) {
                Ok(Value::Scalar(id)) => Some(id),
                _ => None,
            })
            .collect();
        for n in &names {
            self.scope.local.remove(n);
        }
        self.scope.bindings = saved;
        let (Some(initial), Some(rate)) = (lowered[0], lowered[1]) else {
            return None;
        };
        let mut inputs: Vec<Id> = self.params.iter().map(|p| p.id).collect();
        inputs.extend(&symbols);
        let program = Program::compile(&mut self.pool, &inputs, &[initial, rate]).ok()?;
        let mut values: Vec<f64> = self.params.iter().map(|p| p.value).collect();
        values.resize(values.len() + names.len(), 0.0);
        let mut named: FxHashMap<String, f64> = self
            .params
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect();
        named.extend(
            self.scope
                .indices
                .sizes
                .iter()
                .map(|(n, &v)| (n.clone(), v as f64)),
        );
        self.initial_families.push(InitialFamily {
            symbols,
            initial,
            rate,
            coordinates: Vec::new(),
            values: Vec::new(),
        });
        let value = |name: &str| match names.iter().position(|n| n == name) {
            Some(k) => Some(Written::Index(k)),
            None => named.get(name).map(|&x| Written::Num(x)),
        };
        let written = asts.iter().map(|a| Written::of(a, &value)).collect();
        Some(Compiled {
            names,
            workspace: program.workspace(),
            program,
            inputs: values,
            form: None,
            written,
            family: self.initial_families.len() - 1,
        })
    }

    /// Whether `name` is one the compiled path reads as the symbolic one does: an index of
    /// the member, a parameter, a size, `pi` or a function.
    fn plain_name(&self, name: &str, indices: &[String]) -> bool {
        if indices.iter().any(|n| n == name) || name == "pi" {
            return true;
        }
        if let Some((_, _, kind)) = self.scope.names.get(name) {
            return matches!(*kind, "parameter" | "size");
        }
        pdyn_expr::Func::from_name(name).is_some() || name == "sqrt"
    }
}

/// A text's value as written, in floating point, nothing simplified, prepared once for a
/// family: numbers read, each name an index slot or a number. Evaluated per member: walking
/// the syntax tree, reading each literal and looking up each name for each of 10^4 members
/// was 44 of the 548 million instructions of loading a chain.
#[derive(Debug)]
enum Written {
    Num(f64),
    /// The member's value of index `k`.
    Index(usize),
    Neg(Box<Written>),
    Binary(pdyn_expr::syntax::BinOp, Box<Written>, Box<Written>),
    Call(String, Vec<Written>),
    /// What it does not know (a vector, a derivative, a name without a value, a number it
    /// cannot read): no value for any member.
    Unknown,
}

impl Written {
    /// `ast` prepared, with `value` giving each name's (`pi` is π).
    fn of(ast: &pdyn_expr::syntax::Ast, value: &dyn Fn(&str) -> Option<Written>) -> Written {
        use pdyn_expr::syntax::Ast;
        let of = |a: &Ast| Box::new(Written::of(a, value));
        match ast {
            Ast::Num { text, .. } => pdyn_expr::lower::literal(text)
                .map_or(Written::Unknown, |x| Written::Num(x.to_f64())),
            Ast::Ident { name, .. } if name == "pi" => Written::Num(std::f64::consts::PI),
            Ast::Ident { name, .. } => value(name).unwrap_or(Written::Unknown),
            Ast::Neg { expr, .. } => Written::Neg(of(expr)),
            Ast::Binary { op, lhs, rhs, .. } => Written::Binary(*op, of(lhs), of(rhs)),
            Ast::Call { name, args, .. } => Written::Call(
                name.clone(),
                args.iter().map(|a| Written::of(a, value)).collect(),
            ),
            Ast::Quantity { .. }
            | Ast::Vector { .. }
            | Ast::Prime { .. }
            | Ast::Component { .. } => Written::Unknown,
        }
    }

    /// The value with the member's index values `indices`; `None` for what it does not know
    /// (a function it does not have, or with the wrong number of arguments).
    fn eval(&self, indices: &[f64]) -> Option<f64> {
        use pdyn_expr::syntax::BinOp;
        Some(match self {
            Written::Num(x) => *x,
            Written::Index(k) => *indices.get(*k)?,
            Written::Neg(e) => -e.eval(indices)?,
            Written::Binary(op, lhs, rhs) => {
                let (a, b) = (lhs.eval(indices)?, rhs.eval(indices)?);
                match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    BinOp::Mul => a * b,
                    BinOp::Div => a / b,
                    BinOp::Pow => libm::pow(a, b),
                }
            }
            Written::Call(name, args) => {
                // At most two arguments: no function here takes more.
                let mut x = [0.0; 2];
                if args.len() > 2 {
                    return None;
                }
                for (slot, a) in x.iter_mut().zip(args) {
                    *slot = a.eval(indices)?;
                }
                match (name.as_str(), &x[..args.len()]) {
                    ("sqrt", [a]) => libm::sqrt(*a),
                    ("sin", [a]) => libm::sin(*a),
                    ("cos", [a]) => libm::cos(*a),
                    ("tan", [a]) => libm::tan(*a),
                    ("asin", [a]) => libm::asin(*a),
                    ("acos", [a]) => libm::acos(*a),
                    ("atan", [a]) => libm::atan(*a),
                    ("atan2", [a, b]) => libm::atan2(*a, *b),
                    ("sinh", [a]) => libm::sinh(*a),
                    ("cosh", [a]) => libm::cosh(*a),
                    ("tanh", [a]) => libm::tanh(*a),
                    ("exp", [a]) => libm::exp(*a),
                    ("log", [a]) => libm::log(*a),
                    ("abs", [a]) => a.abs(),
                    ("sign", [a]) => {
                        if *a == 0.0 {
                            0.0
                        } else {
                            a.signum()
                        }
                    }
                    ("min", [a, b]) => a.min(*b),
                    ("max", [a, b]) => a.max(*b),
                    _ => return None,
                }
            }
            Written::Unknown => return None,
        })
    }
}

impl Model {
    /// Writes each member of [`Model::initial_families`] into [`Model::initial_exprs`] as its
    /// own expressions in the parameters (the family's with the member's indices put in), in
    /// coordinate order. Afterwards there are no initial families.
    pub fn materialize_initials(&mut self) {
        if self.initial_families.is_empty() {
            return;
        }
        for family in std::mem::take(&mut self.initial_families) {
            let mut map: FxHashMap<Id, Id> = FxHashMap::default();
            for (c, values) in family.members() {
                map.clear();
                for (&s, &v) in family.symbols.iter().zip(values) {
                    map.insert(s, self.pool.int(v));
                }
                let initial = self.pool.subs(family.initial, &map);
                let rate = self.pool.subs(family.rate, &map);
                self.initial_exprs.push((c, initial, rate));
            }
        }
        self.initial_exprs.sort_by_key(|e| e.0);
    }

    /// Recomputes the numeric initial values and rates of the members of
    /// [`Model::initial_families`] from the current parameter values.
    pub(crate) fn refresh_family_initials(&mut self) {
        let params: Vec<Id> = self.parameters.iter().map(|p| p.id).collect();
        let mut inputs: Vec<f64> = self.parameters.iter().map(|p| p.value).collect();
        let first = inputs.len();
        for family in &self.initial_families {
            let Some(program) = family.program(&mut self.pool, &params) else {
                continue;
            };
            inputs.truncate(first);
            inputs.resize(first + family.symbols.len(), 0.0);
            let mut ws = program.workspace();
            let mut out = [0.0; 2];
            for (c, values) in family.members() {
                for (slot, &v) in inputs[first..].iter_mut().zip(values) {
                    *slot = v as f64;
                }
                program.eval(&inputs, &mut ws, &mut out);
                if let Some(CoordinateKind::Free { initial, rate }) =
                    self.coordinates.get_mut(c).map(|c| &mut c.kind)
                {
                    *initial = out[0];
                    *rate = out[1];
                }
            }
        }
    }
}
