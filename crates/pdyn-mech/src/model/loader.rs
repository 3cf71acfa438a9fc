//! The state of reading one model file: the expression pool, the names declared so far and
//! the parameters' values, with the helpers every table uses to turn a TOML value into an
//! expression (located errors, unit literals, shape checks, constant evaluation).

use super::families::{in_member, Indices, Member, Members, Table};
use super::member_template::MemberTemplate;
use super::raw::Sv;
use super::{ModelError, Parameter};
use crate::dimensions::{Form, Inference, Source};
use crate::units::{looks_like_quantity, parse_quantity_with_dimension};
use pdyn_expr::lower::{lower, Binding, Scope};
use pdyn_expr::syntax::Ast;
use pdyn_expr::{ExprError, Id, Number, Pool, Program, Value};
use rustc_hash::FxHashMap;
use std::borrow::Cow;
use std::ops::Range;
use std::rc::Rc;

/// Name resolution for expressions in a model file.
#[derive(Default)]
pub(crate) struct ModelScope {
    /// Every name declared, with where and as what. Its text is shared with `order` (one
    /// allocation per name: a family declares 10^4).
    pub(super) names: FxHashMap<Rc<str>, (Binding, Range<usize>, &'static str)>,
    pub(super) order: Vec<Rc<str>>,
    pub(super) local: FxHashMap<String, Binding>,
    /// Sizes, index ranges and family shapes ([`super::families`]).
    pub(super) indices: Indices,
    /// The indices of the family member being read (`i = 3, j = 4`), empty elsewhere.
    pub(super) bindings: Vec<(String, i64)>,
    /// The table rows that member stands for (`[tables.NAME]`), empty elsewhere.
    pub(super) rows: Vec<(usize, usize)>,
    /// The names `[indices]` declares as indices: no other entry may take them.
    pub(super) index_names: Vec<String>,
    /// Where a member's name is written to be looked up ([`Scope::resolve`]).
    scratch: String,
}

impl ModelScope {
    /// Room for `names` more declared names and `local` more local ones.
    pub(super) fn reserve(&mut self, names: usize, local: usize) {
        self.names.reserve(names);
        self.order.reserve(names);
        self.local.reserve(local);
    }

    fn lookup(&self, name: &str) -> Option<Binding> {
        if let Some((b, _, _)) = self.names.get(name) {
            return Some(*b);
        }
        self.local.get(name).copied()
    }
}

impl Scope for ModelScope {
    fn resolve(&mut self, pool: &mut Pool, name: &str) -> Option<Binding> {
        if let Some((_, v)) = self.bindings.iter().find(|(n, _)| n == name) {
            return Some(Binding::Value(Value::Scalar(pool.int(*v))));
        }
        // A table's column: the value in the member's row (`nodes_x`) or in the row named
        // (`nodes_x[bars_a]`); a column without a row is no value (`undefined` says why).
        if self.indices.columns.contains_key(name) {
            let cell = self.indices.cell(name, &self.rows).ok()??;
            return Some(Binding::Value(Value::Scalar(cell_number(
                pool,
                cell.value(),
            ))));
        }
        if name.ends_with(']') {
            if let Some(cell) = self
                .indices
                .subscripted_cell(name, &self.bindings, &self.rows)
                .ok()?
            {
                return Some(Binding::Value(Value::Scalar(cell_number(
                    pool,
                    cell.value(),
                ))));
            }
            // `x[i+1, j]`: the member the subscript names with the current indices, its
            // name written into a buffer kept for this (nothing allocated per member).
            let mut buf = std::mem::take(&mut self.scratch);
            let found =
                match self
                    .indices
                    .member_name_into(name, &self.bindings, &self.rows, &mut buf)
                {
                    Ok(true) => self.lookup(&buf),
                    Ok(false) | Err(_) => None,
                };
            self.scratch = buf;
            return found;
        }
        self.lookup(name)
    }
    fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.order.iter().map(|n| n.to_string()).collect();
        v.extend(self.local.keys().cloned());
        v
    }
    fn undefined(&self, name: &str) -> Option<(String, Option<String>)> {
        if let Err(message) = self.indices.cell(name, &self.rows) {
            return Some((message, None));
        }
        if let Err(e) = self
            .indices
            .subscripted_cell(name, &self.bindings, &self.rows)
        {
            return Some((e.message, None));
        }
        if let Some(m) = self.missing_column(name) {
            return Some(m);
        }
        if !name.ends_with(']') {
            return None;
        }
        let help = "a member is written NAME[i] or NAME[i,j] with indices in its family's ranges";
        match self.indices.member_name(name, &self.bindings, &self.rows) {
            Err(e) => Some((e.message, Some(help.to_string()))),
            Ok(Some(member)) => {
                let base = member.split('[').next().unwrap_or_default();
                let message = match self.indices.shapes.get(base) {
                    Some(shape) => format!(
                        "{member} is not declared: it is inside {} but its `where` leaves it out",
                        super::families::shape_text(base, shape)
                    ),
                    None => format!("undefined name `{member}`"),
                };
                Some((message, Some(help.to_string())))
            }
            Ok(None) => None,
        }
    }
}

impl ModelScope {
    /// `bars_EA` when table `bars` has no column `EA`: the message and the columns it has.
    fn missing_column(&self, name: &str) -> Option<(String, Option<String>)> {
        let base = name.split('[').next().unwrap_or(name);
        if self.indices.columns.contains_key(base) {
            return None;
        }
        let table = self.indices.tables.iter().find(|t| {
            base.strip_prefix(t.name.as_str())
                .and_then(|rest| rest.strip_prefix('_'))
                .is_some_and(|c| !c.is_empty())
        })?;
        let column = &base[table.name.len() + 1..];
        Some((
            format!(
                "table `{}` ({}) has no column `{column}`",
                table.name, table.file
            ),
            Some(format!(
                "its columns are {} (written {}_COLUMN)",
                super::row_tables::quoted_list(table.column_names()),
                table.name
            )),
        ))
    }
}

/// A table's value in an expression: an integer as an integer (so `nodes_i*a` is the same
/// expression as `i*a` over an index), anything else as the number it is.
fn cell_number(pool: &mut Pool, x: f64) -> Id {
    if x.fract() == 0.0 && x.abs() < 9_007_199_254_740_992.0 {
        pool.int(x as i64)
    } else {
        pool.num(Number::Float(x))
    }
}

const RESERVED: [&str; 2] = ["t", "pi"];

pub(crate) struct Loader<'a> {
    pub origin: &'a str,
    pub source: &'a str,
    pub pool: Pool,
    pub scope: ModelScope,
    pub params: Vec<Parameter>,
    /// The dimensions of names and expressions ([`crate::dimensions`]).
    pub dims: Inference,
    /// The dimension of the last value [`Loader::value`] read.
    pub last: Form,
    /// Whether that value was a bare number (`mass = 2`), which takes the dimension its field
    /// needs.
    pub last_bare: bool,
    /// The coordinates read so far: name and whether it is free (not prescribed).
    pub coordinate_names: Vec<(String, bool)>,
    /// The names `[definitions]` will declare (read after the coordinates, which they may
    /// use): an initial value that names one is read once they are declared.
    pub definition_names: Vec<String>,
    /// `(coordinate index, name, its table's span and value, "initial" or "rate")` of the
    /// initial conditions waiting for the definitions.
    pub deferred_initials: Vec<(usize, String, Sv, toml::Table, &'static str)>,
    /// The `[unknowns]`: name and symbol (an initial condition may name them).
    pub unknown_ids: Vec<(String, Id)>,
    /// The initial conditions read so far that name an unknown.
    pub unknown_initials: Vec<super::UnknownInitial>,
    /// Which family member each expanded entry is ([`super::families`]).
    pub members: Members,
    /// The family of the member being read (with [`ModelScope::bindings`], its label
    /// `spring[i=3, j=19]`, prefixed to its errors).
    pub member: Option<Rc<str>>,
    /// Whether force families may be left unexpanded ([`super::load_deferring`]).
    pub defer: bool,
    /// The force families left unexpanded.
    pub deferred: Vec<super::deferred::DeferredForces>,
    /// The values [`Loader::constant`] found, by expression: a family's members repeat a
    /// few (`initial = "i*a"` over 10^4 members has 100), each evaluated once.
    constants: FxHashMap<Id, f64>,
    /// The members of a family read one text at one place in the file, each with its own
    /// index values: its syntax tree, parsed once, by offset (with the text).
    parsed: FxHashMap<usize, (String, Rc<Ast>)>,
    /// And its dimension, inferred once: the same text in the same names gives the same
    /// equations between dimensions (and the same errors, at the same place), member after
    /// member. Inferring them again for each of 10^4 members was a sixth of loading a chain.
    inferred: FxHashMap<usize, (String, Form)>,
    /// And its template ([`super::member_template`]), when it has one, by offset (with the
    /// text).
    templates: FxHashMap<usize, (String, Option<Rc<MemberTemplate>>)>,
    /// And its expression, when it names nothing of the member's own
    /// ([`Loader::same_for_every_member`]): lowered once, by offset (with the text).
    lowered: FxHashMap<usize, (String, Value)>,
    /// Coordinate families whose initial values are read as numbers
    /// ([`super::family_initials`]): each table's texts compiled once, by its offset.
    pub(super) family_initials: super::family_initials::Cache,
    /// Their members, with the family's expressions.
    pub initial_families: Vec<super::InitialFamily>,
    /// The last forms [`Loader::want`] required equal at each place of the file, for the
    /// members of families.
    wanted: FxHashMap<usize, (Form, Form)>,
}

impl<'a> Loader<'a> {
    /// A loader for the file `origin` with text `source`, nothing declared yet.
    pub fn new(origin: &'a str, source: &'a str) -> Loader<'a> {
        Loader {
            origin,
            source,
            pool: Pool::new(),
            scope: ModelScope::default(),
            params: Vec::new(),
            dims: Inference::default(),
            last: Form::default(),
            last_bare: false,
            coordinate_names: Vec::new(),
            definition_names: Vec::new(),
            deferred_initials: Vec::new(),
            unknown_ids: Vec::new(),
            unknown_initials: Vec::new(),
            members: Members::default(),
            member: None,
            defer: false,
            deferred: Vec::new(),
            constants: FxHashMap::default(),
            parsed: FxHashMap::default(),
            inferred: FxHashMap::default(),
            lowered: FxHashMap::default(),
            templates: FxHashMap::default(),
            family_initials: FxHashMap::default(),
            initial_families: Vec::new(),
            wanted: FxHashMap::default(),
        }
    }

    /// The syntax tree of `text` (at byte `at` of the file): parsed once for all the members
    /// of a family.
    pub(crate) fn parse(&mut self, text: &str, at: usize) -> Result<Rc<Ast>, ExprError> {
        if self.member.is_none() {
            return pdyn_expr::syntax::parse(text).map(Rc::new);
        }
        // Looked up by place, the text compared: no key string made per member.
        if let Some((t, ast)) = self.parsed.get(&at) {
            if t == text {
                return Ok(Rc::clone(ast));
            }
        }
        let ast = Rc::new(pdyn_expr::syntax::parse(text)?);
        self.parsed.insert(at, (text.to_string(), Rc::clone(&ast)));
        Ok(ast)
    }

    /// The dimension of `ast` ([`Inference::infer`]), inferred once for all the members of a
    /// family that read it at the same place.
    pub(crate) fn infer(&mut self, ast: &Ast, src: Source) -> Form {
        if self.member.is_none() {
            return self.dims.infer(ast, src);
        }
        if let Some((t, form)) = self.inferred.get(&src.offset) {
            if t == src.text {
                return form.clone();
            }
        }
        let form = self.dims.infer(ast, src);
        self.inferred
            .insert(src.offset, (src.text.to_string(), form.clone()));
        form
    }

    /// Starts reading entry `k` of `table`: binds its indices if it is a family member.
    pub(super) fn enter(&mut self, table: Table, k: usize) {
        let list = match table {
            Table::Coordinates => &self.members.coordinates,
            Table::Definitions => &self.members.definitions,
            Table::Points => &self.members.points,
            Table::Particles => &self.members.particles,
            Table::Forces => &self.members.forces,
        };
        match list.get(k).and_then(Option::as_ref) {
            Some(Member {
                base,
                names,
                values,
                rows,
            }) => {
                // The family's names are already bound when the last entry was a member of
                // it (members come in a row): only the values change.
                let bound = &mut self.scope.bindings;
                if bound.len() != names.len()
                    || bound.iter().zip(names.iter()).any(|(b, n)| b.0 != *n)
                {
                    *bound = names.iter().map(|n| (n.clone(), 0)).collect();
                }
                for (b, &v) in bound.iter_mut().zip(values.iter()) {
                    b.1 = v;
                }
                self.scope.rows.clone_from(rows);
                self.member = Some(Rc::clone(base));
            }
            None => self.leave(),
        }
    }

    /// Done with the entries of families.
    pub(super) fn leave(&mut self) {
        self.scope.bindings.clear();
        self.scope.rows.clear();
        self.member = None;
    }

    /// `err` with the label of the member being read, if any.
    pub(super) fn in_member(&self, err: ModelError) -> ModelError {
        match &self.member {
            Some(base) => in_member(
                err,
                &self
                    .scope
                    .indices
                    .label(base, &self.scope.bindings, &self.scope.rows),
            ),
            None => err,
        }
    }

    /// Keeps `name` for an index of `[indices]`.
    pub(super) fn reserve_index_name(
        &mut self,
        name: &str,
        span: Range<usize>,
    ) -> Result<(), ModelError> {
        if !is_identifier(name) || RESERVED.contains(&name) {
            return Err(self
                .err(span, format!("`{name}` cannot be used as an index name"))
                .help("index names are letters, digits and `_`, not starting with a digit, and not t or pi"));
        }
        if self.scope.names.contains_key(name) {
            return Err(self.err(span, format!("`{name}` is already declared")));
        }
        self.scope.index_names.push(name.to_string());
        Ok(())
    }

    /// The index of coordinate `name` in the model and whether it is free.
    pub fn coordinate_index(&self, name: &str) -> Option<(usize, bool)> {
        self.coordinate_names
            .iter()
            .position(|(n, _)| n == name)
            .map(|k| (k, self.coordinate_names[k].1))
    }

    /// The names of the free coordinates, and of their rates.
    pub fn free_coordinate_names(&self) -> Vec<String> {
        let free = self.coordinate_names.iter().filter(|c| c.1);
        free.clone()
            .map(|c| c.0.clone())
            .chain(free.map(|c| format!("{}'", c.0)))
            .collect()
    }

    pub fn err(&self, span: Range<usize>, msg: impl Into<String>) -> ModelError {
        ModelError::new(self.origin, span, msg)
    }

    pub(crate) fn declare(
        &mut self,
        name: &str,
        span: Range<usize>,
        what: &'static str,
        b: Binding,
    ) -> Result<(), ModelError> {
        if let Some((_, prev, kind)) = self.scope.names.get(name) {
            let (line, _) = pdyn_expr::error::line_col(self.source, prev.start);
            return Err(self
                .err(span, format!("duplicate name `{name}`: already a {kind} (line {line})"))
                .help("every parameter, coordinate, definition, point, particle and reaction needs its own name"));
        }
        if self.scope.index_names.iter().any(|n| n == name) {
            return Err(self
                .err(span, format!("`{name}` is an index (declared under [indices]): it cannot also be a {what}"))
                .help("rename the index or this entry"));
        }
        if self.pool.table_named(name).is_some() {
            return Err(self
                .err(
                    span,
                    format!("duplicate name `{name}`: already a column of a [data] table"),
                )
                .help(
                    "a [data.NAME] table's column `c` is the function `NAME_c`: rename one of them",
                ));
        }
        let reserved = (RESERVED.contains(&name) && what != "reaction")
            || pdyn_expr::Func::from_name(name).is_some()
            || ["sqrt", "dot", "cross", "norm", "unit"].contains(&name);
        if reserved || !(is_identifier(name) || is_member_name(name)) {
            return Err(self
                .err(span, format!("`{name}` cannot be used as a {what} name"))
                .help("names are letters, digits and `_`, not starting with a digit, and not t, pi or a function name"));
        }
        let name: Rc<str> = Rc::from(name);
        self.scope.names.insert(Rc::clone(&name), (b, span, what));
        self.scope.order.push(name);
        Ok(())
    }

    /// Text of an expression-valued field and the byte offset of that text in the file.
    pub fn expr_text(&self, sv: &Sv) -> Result<(String, usize), ModelError> {
        self.expr_str(sv).map(|(t, at)| (t.into_owned(), at))
    }

    /// [`Loader::expr_text`], a string value borrowed (not copied for each member).
    fn expr_str<'s>(&self, sv: &'s Sv) -> Result<(Cow<'s, str>, usize), ModelError> {
        let span = sv.span();
        match sv.get_ref() {
            toml::Value::String(s) => {
                let raw = &self.source[span.start..];
                let quote = if raw.starts_with("\"\"\"") || raw.starts_with("'''") {
                    3
                } else {
                    1
                };
                Ok((Cow::Borrowed(s.as_str()), span.start + quote))
            }
            toml::Value::Integer(_) | toml::Value::Float(_) => {
                let text = self.source[span.clone()].replace('_', "");
                let text = if pdyn_expr::lower::literal(&text).is_some() {
                    text
                } else {
                    match sv.get_ref() {
                        toml::Value::Float(f) => format!("{f:e}"),
                        other => other.to_string(),
                    }
                };
                Ok((Cow::Owned(text), span.start))
            }
            other => Err(self
                .err(span, format!("expected a number or an expression in quotes, found a {}", other.type_str()))
                .help("write numbers plainly (9.81) and expressions in quotes (\"m*g\", \"[x, y, 0]\", \"25 mph\")")),
        }
    }

    pub(crate) fn located(&self, e: ExprError, offset: usize) -> ModelError {
        let e = e.offset(offset);
        ModelError {
            origin: self.origin.to_string(),
            span: e.span,
            message: e.message,
            help: e.help,
        }
    }

    /// Parses an expression-valued field; its dimension is left in [`Loader::last`].
    pub fn value(&mut self, sv: &Sv) -> Result<Value, ModelError> {
        let (owned, off) = self.expr_str(sv)?;
        let text: &str = &owned;
        if looks_like_quantity(text) {
            let (x, dim) = parse_quantity_with_dimension(text).map_err(|e| {
                let mut me = self.err(e.span.start + off..e.span.end + off, e.message);
                me.help = e.help;
                me
            })?;
            // An angle alone (`"30 deg"`) does not make the model strict.
            self.dims.has_units |= dim != pdyn_expr::Dimension::NONE;
            self.last = dim.into();
            self.last_bare = false;
            return Ok(Value::Scalar(self.pool.num(Number::Float(x))));
        }
        let ast = self.parse(text, off).map_err(|e| self.located(e, off))?;
        let same = match self.lowered.get(&off) {
            Some((t, v)) if self.member.is_some() && t == text => Some(*v),
            _ => None,
        };
        let v = match same.or_else(|| self.templated_value(text, off, &ast)) {
            Some(v) => v,
            None => {
                let v = lower(&mut self.pool, &ast, &mut self.scope)
                    .map_err(|e| self.located(e, off))?;
                if self.member.is_some() && self.same_for_every_member(&ast) {
                    self.lowered.insert(off, (text.to_string(), v));
                }
                v
            }
        };
        self.last_bare = is_bare_number(&ast);
        self.last = if self.last_bare {
            self.dims.fresh(text)
        } else {
            self.infer(&ast, Source { text, offset: off })
        };
        Ok(v)
    }

    /// The value of a family member's field from its family's template
    /// ([`super::member_template`]), made at the first member that reads `text` at `off`.
    /// `None` outside families, for a text of another shape, or for a member whose names do
    /// not resolve as the template needs (it is then lowered in full, with its error).
    fn templated_value(&mut self, text: &str, off: usize, ast: &Ast) -> Option<Value> {
        self.member.as_ref()?;
        let template = match self.templates.get(&off) {
            Some((t, template)) if t == text => template.clone()?,
            _ => {
                // What differs from member to member, named once (the scope is lowered
                // through while the template is made).
                let own: Vec<String> = (self.scope.bindings.iter().map(|(b, _)| b))
                    .chain(self.scope.indices.ranges.keys())
                    .chain(self.scope.indices.columns.keys())
                    .cloned()
                    .collect();
                let varies = |a: &Ast| {
                    a.any_name(&|name| name.contains('[') || own.iter().any(|o| o == name))
                };
                let template =
                    MemberTemplate::of(&mut self.pool, ast, &mut self.scope, &varies).map(Rc::new);
                self.templates
                    .insert(off, (text.to_string(), template.clone()));
                template?
            }
        };
        template.member(&mut self.pool, &mut self.scope)
    }

    /// Whether `ast` names nothing that differs from member to member of a family: no index,
    /// no subscripted name (`x[i]`, `r_P[i,j]`), no table column. Its expression is then
    /// the same for every member (the pool interns it), lowered once (a chain's `mass = "m"`
    /// for each of 10^4 particles).
    fn same_for_every_member(&self, ast: &Ast) -> bool {
        !ast.any_name(&|name| {
            name.contains('[')
                || self.scope.bindings.iter().any(|(b, _)| b == name)
                || self.scope.indices.ranges.contains_key(name)
                || self.scope.indices.columns.contains_key(name)
        })
    }

    /// Requires the value just read from `sv` to have the dimension `want` (checked at the end
    /// of loading, and reported only in a model that uses units).
    pub fn want(&mut self, sv: &Sv, want: impl Into<Form>, what: &str) {
        if let Some((got, want)) = self.still_wanted(sv, want.into()) {
            self.require(sv, &got, &want, what);
        }
    }

    /// [`Loader::want`] with the description made only when the forms are compared: a
    /// family's members repeat one requirement, checked once (formatting `the position of
    /// P[3]` for each of 10^4 members was 25 of the 188 million instructions of reading them).
    pub fn want_with(&mut self, sv: &Sv, want: impl Into<Form>, what: impl FnOnce() -> String) {
        if let Some((got, want)) = self.still_wanted(sv, want.into()) {
            self.require(sv, &got, &want, &what());
        }
    }

    /// The forms to require equal, or `None` when this member's family already required
    /// them at this place.
    fn still_wanted(&mut self, sv: &Sv, want: Form) -> Option<(Form, Form)> {
        if self.member.is_some() {
            // The members of a family read one text at one place: the same two forms
            // required equal again change nothing (they are equal once unified; a failure
            // was recorded by the first member, and only the first error is reported).
            // Compared before anything is copied: this is once per member and field.
            let key = sv.span().start;
            if let Some((g, w)) = self.wanted.get(&key) {
                if *g == self.last && *w == want {
                    return None;
                }
            }
            self.wanted.insert(key, (self.last.clone(), want.clone()));
        }
        Some((self.last.clone(), want))
    }

    fn require(&mut self, sv: &Sv, got: &Form, want: &Form, what: &str) {
        self.dims.require(
            got,
            want,
            sv.span(),
            what,
            "write the quantity with its units (\"2 kg\", \"0.5 m\", \"100 N/m\"), or check \
             the units of the parameters it uses",
        );
    }

    /// Requires the value just read from `sv`, times `other`, to have the dimension `want`
    /// (`N · normal` is a force).
    pub fn want_times(&mut self, sv: &Sv, other: &Form, want: impl Into<Form>, what: &str) {
        if let Some(product) = self.last.mul(other) {
            self.last = product;
            self.want(sv, want, what);
        }
    }

    /// The dimension to give a name defined by the value just read: its own unknown when that
    /// was a bare number (`g = 9.81`), else the value's.
    pub fn last_for(&mut self, name: &str) -> Form {
        if self.last_bare {
            self.dims.fresh(name)
        } else {
            self.last.clone()
        }
    }

    /// The first dimension error, in a model that writes units anywhere.
    pub fn dimension_error(&self) -> Option<ModelError> {
        if !self.dims.has_units {
            return None;
        }
        let e = self.dims.errors.first()?;
        Some(self.err(e.span.clone(), &e.message).help(&e.help))
    }

    /// Parses a field that must be a scalar.
    pub fn scalar(&mut self, sv: &Sv, what: &str) -> Result<Id, ModelError> {
        match self.value(sv)? {
            Value::Scalar(s) => Ok(s),
            Value::Vector(_) => Err(self.err(
                sv.span(),
                format!("{what} must be a scalar, but this is a vector"),
            )),
        }
    }

    /// Parses a field that must be a vector.
    pub fn vector(&mut self, sv: &Sv, what: &str) -> Result<[Id; 3], ModelError> {
        self.vector_with(sv, || what.to_string())
    }

    /// [`Loader::vector`] with the description made only for an error.
    pub fn vector_with(
        &mut self,
        sv: &Sv,
        what: impl FnOnce() -> String,
    ) -> Result<[Id; 3], ModelError> {
        match self.value(sv)? {
            Value::Vector(v) => Ok(v),
            Value::Scalar(_) => Err(self
                .err(
                    sv.span(),
                    format!("{} must be a vector, but this is a scalar", what()),
                )
                .help("write vectors as \"[x, y, z]\" (or \"[x, y]\" in the plane)")),
        }
    }

    /// The `[unknowns]` that `e` names, in declaration order.
    pub fn unknowns_in(&self, e: Id) -> Vec<String> {
        self.unknown_ids
            .iter()
            .filter(|(_, u)| self.pool.contains(e, *u))
            .map(|(n, _)| n.clone())
            .collect()
    }

    /// Checks that `e` involves only parameters and `[unknowns]` (what `pdyn forces` can
    /// substitute at the instant), with the error [`Loader::constant`] gives otherwise.
    pub fn constant_in_unknowns(
        &mut self,
        e: Id,
        span: Range<usize>,
        what: &str,
    ) -> Result<(), ModelError> {
        let mut inputs: Vec<Id> = self.params.iter().map(|p| p.id).collect();
        inputs.extend(self.unknown_ids.iter().map(|u| u.1));
        Program::compile(&mut self.pool, &inputs, &[e])
            .map(|_| ())
            .map_err(|err| {
                self.err(span, format!("{what} must be a number here: {err}"))
                    .help("only parameters, [unknowns] (for `pdyn forces`), numbers, pi and units may appear here")
            })
    }

    /// Evaluates an expression that may only involve parameters.
    pub fn constant(&mut self, e: Id, span: Range<usize>, what: &str) -> Result<f64, ModelError> {
        // Parameters' values do not change while a file is read.
        if let Some(&v) = self.constants.get(&e) {
            return Ok(v);
        }
        let inputs: Vec<Id> = self.params.iter().map(|p| p.id).collect();
        let values: Vec<f64> = self.params.iter().map(|p| p.value).collect();
        let prog = Program::compile(&mut self.pool, &inputs, &[e]).map_err(|err| {
            self.err(span.clone(), format!("{what} must be a number here: {err}"))
                .help("only parameters (and numbers, pi, units) may appear here")
        })?;
        let mut ws = prog.workspace();
        let mut out = [0.0];
        prog.eval(&values, &mut ws, &mut out);
        if !out[0].is_finite() {
            return Err(self.err(span, format!("{what} evaluates to {}", out[0])));
        }
        self.constants.insert(e, out[0]);
        Ok(out[0])
    }
}

/// `2`, `-1.5e3`: a number without units.
fn is_bare_number(ast: &Ast) -> bool {
    match ast {
        Ast::Num { .. } => true,
        Ast::Neg { expr, .. } => is_bare_number(expr),
        _ => false,
    }
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_alphabetic() || c == '_')
        && chars.all(|c| c.is_alphanumeric() || c == '_')
}

/// `P[3,4]`: a member of a family, as the expansion names it.
fn is_member_name(name: &str) -> bool {
    // Scanned byte by byte, once (every member of a family is declared by name: splitting
    // and trimming its parts was a quarter of declaring one).
    let Some(open) = name.find('[') else {
        return false;
    };
    let Some(inner) = name[open + 1..].strip_suffix(']') else {
        return false;
    };
    if !is_identifier(&name[..open]) {
        return false;
    }
    // Each part is not empty: `-`s, then digits (as `trim_start_matches('-')` then all
    // digits read it).
    let mut length = 0usize;
    let mut in_digits = false;
    for b in inner.bytes() {
        match b {
            b',' => {
                if length == 0 {
                    return false;
                }
                length = 0;
                in_digits = false;
            }
            b'-' if !in_digits => length += 1,
            b'0'..=b'9' => {
                length += 1;
                in_digits = true;
            }
            _ => return false,
        }
    }
    length > 0
}

#[cfg(test)]
mod tests {
    /// The byte scan accepts what splitting at `,` and trimming leading `-`s accepted.
    #[test]
    fn member_names_as_the_parts_read_them() {
        let by_parts = |name: &str| {
            let Some(open) = name.find('[') else {
                return false;
            };
            let Some(inner) = name[open + 1..].strip_suffix(']') else {
                return false;
            };
            super::is_identifier(&name[..open])
                && inner.split(',').all(|p| {
                    !p.is_empty()
                        && p.trim_start_matches('-')
                            .bytes()
                            .all(|b| b.is_ascii_digit())
                })
        };
        let names = [
            "P[3]",
            "P[3,4]",
            "P[-3,4]",
            "P[--3]",
            "P[-]",
            "P[]",
            "P[,]",
            "P[3,]",
            "P[,3]",
            "P[3-]",
            "P[3-4]",
            "P[ 3]",
            "P[3",
            "P3]",
            "[3]",
            "1P[3]",
            "P[a]",
            "P[3,4,5]",
            "P[-,-]",
            "x_2[10000]",
            "P[3]]",
            "P[[3]",
        ];
        for n in names {
            assert_eq!(super::is_member_name(n), by_parts(n), "{n}");
        }
        assert!(super::is_member_name("P[10000]"));
        assert!(!super::is_member_name("P[3-4]"));
    }
}
