//! Indexed families: one declaration standing for many coordinates, points, particles,
//! definitions or forces, the way the chapter writes "P_ij, i = 0, …, n−1".
//!
//! ```toml
//! [indices]
//! n = 5                    # a size (an integer that ranges and conditions may use)
//! i = "0..n-1"             # an index and its range, both ends included
//! j = "0..n-1"
//!
//! [particles."P[i,j]"]     # P[0,0] ... P[4,4], except where `where` is false
//! where = "not (j == 0 and (i == 0 or i == n-1))"
//! position = "[x[i,j], y[i,j], z[i,j]]"
//!
//! [[forces]]
//! kind = "spring"
//! for = "i in 0..n-2, j"   # a range of its own for i, the [indices] range for j
//! between = ["P[i,j]", "P[i+1,j]"]
//! ```
//!
//! Expansion happens before anything is resolved: each family becomes its members, ordinary
//! entries named `P[3,4]` whose values are the family's own (same text, same place in the
//! file), read with the member's indices bound. Name fields (`on`, `between`...) are resolved
//! here to the members they name. A reference outside a family's declared ranges is a located
//! error naming the family and the member being read (`spring[i=3, j=19]: P[4,20] is outside
//! P[0..19, 0..19]`). Sizes are checked before anything is allocated.

use super::index_expr::{self, ForClause, IndexError, IndexExpr};
use super::index_program::{IndexProgram, Operand};
use super::loader::Loader;
use super::raw::{Keyed, Name, RawForce, RawModel, RawParticle, Sv};
use super::row_tables::RowTable;
use super::ModelError;
use indexmap::IndexMap;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cell::RefCell;
use std::ops::Range;
use std::rc::Rc;
use toml::Spanned;

/// Most members all families of one model may have together: expansion allocates an entry per
/// member (and loading a symbolic expression per field), so a family of 10^12 is refused
/// before anything is made.
pub const MAX_MEMBERS: u64 = 2_000_000;

/// A family's declared shape, for messages about references outside it: `P[0..19, 0..19]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Shape {
    /// Inclusive range of each index.
    pub ranges: Vec<(i64, i64)>,
    /// For a family declared over the rows of tables only: the subscripts its rows give
    /// (node ids need not fill their range). `None` when a declaration covers whole ranges.
    pub rows: Option<FxHashSet<Vec<i64>>>,
}

/// The rows of tables a member stands for: `(table, row)`, indices into [`Indices::tables`]
/// and the table's rows.
pub(crate) type Rows = Vec<(usize, usize)>;

/// Which member of which family an expanded entry is.
#[derive(Clone, Debug)]
pub(crate) struct Member {
    /// The family's name (`P`, `spring`): with the bindings, the label `spring[i=3, j=19]`
    /// prefixed to errors while the member is read (formed only then).
    pub base: Rc<str>,
    /// The names of its indices, shared by the family's members.
    pub names: Rc<[String]>,
    /// Their values for this member.
    pub values: IndexValues,
    /// The table rows it stands for (empty outside families over tables).
    pub rows: Rows,
}

impl Member {
    /// The member of family `base` over the indices `names` at `bindings` (the same names,
    /// with values) and table rows `rows`.
    fn of(
        base: &Rc<str>,
        names: &Rc<[String]>,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Member {
        Member {
            base: Rc::clone(base),
            names: Rc::clone(names),
            values: IndexValues::of(bindings),
            rows: rows.to_vec(),
        }
    }
}

/// A member's index values: one or two kept inline (nothing allocated, nor freed, for each
/// of 10^4 members), more on the heap.
#[derive(Clone, Debug)]
pub(crate) enum IndexValues {
    Inline([i64; 2], u8),
    Heap(Vec<i64>),
}

impl IndexValues {
    fn of(bindings: &[(String, i64)]) -> IndexValues {
        match bindings {
            [a] => IndexValues::Inline([a.1, 0], 1),
            [a, b] => IndexValues::Inline([a.1, b.1], 2),
            more => IndexValues::Heap(more.iter().map(|b| b.1).collect()),
        }
    }
}

impl std::ops::Deref for IndexValues {
    type Target = [i64];
    fn deref(&self) -> &[i64] {
        match self {
            IndexValues::Inline(v, n) => &v[..*n as usize],
            IndexValues::Heap(v) => v,
        }
    }
}

/// For each entry of each expanded table, the member it is (`None` for an ordinary entry).
#[derive(Clone, Debug, Default)]
pub(crate) struct Members {
    pub coordinates: Vec<Option<Member>>,
    pub definitions: Vec<Option<Member>>,
    pub points: Vec<Option<Member>>,
    pub particles: Vec<Option<Member>>,
    pub forces: Vec<Option<Member>>,
    /// The `[[forces]]` entries after expansion (`raw.forces` keeps the file's).
    pub force_entries: Vec<ForceEntry>,
}

/// An expanded table and, entry by entry, the member each is.
type Expanded<T> = (T, Vec<Option<Member>>);

/// The values the members of a keyed table's families share: each family's value once, and
/// for each entry of the expanded table the index of its family's value. A member's own
/// value in the table is then a placeholder (copying a coordinate's `{ initial, rate }` table
/// or a particle's fields for each of 10^4 members, and freeing them, was a third of
/// expanding a chain); readers take the value through [`Shared::get`].
#[derive(Debug)]
pub(crate) struct Shared<V> {
    values: Vec<V>,
    of_entry: Vec<Option<u32>>,
}

impl<V> Default for Shared<V> {
    fn default() -> Self {
        Shared {
            values: Vec::new(),
            of_entry: Vec::new(),
        }
    }
}

impl<V> Shared<V> {
    /// The value of entry `k` of the expanded table, whose value in the table is `own`.
    pub fn get<'a>(&'a self, k: usize, own: &'a V) -> &'a V {
        match self.of_entry.get(k).copied().flatten() {
            Some(v) => &self.values[v as usize],
            None => own,
        }
    }
}

/// [`Shared`] for each keyed table.
#[derive(Debug, Default)]
pub(crate) struct SharedValues {
    pub coordinates: Shared<Sv>,
    pub points: Shared<Sv>,
    pub definitions: Shared<Sv>,
    pub particles: Shared<Spanned<RawParticle>>,
}

/// A value that stands in the expanded table for a member's (its family's is in [`Shared`]):
/// nothing allocated.
fn placeholder_value(v: &Sv) -> Sv {
    Spanned::new(v.span(), toml::Value::Boolean(false))
}

fn placeholder_particle(p: &Spanned<RawParticle>) -> Spanned<RawParticle> {
    Spanned::new(
        p.span(),
        RawParticle {
            mass: None,
            position: None,
            for_list: None,
            condition: None,
        },
    )
}

/// Which table an entry is in.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Table {
    Coordinates,
    Definitions,
    Points,
    Particles,
    Forces,
}

/// `[indices]` read: sizes and index ranges, and the shapes of the families declared so far.
#[derive(Clone, Debug, Default)]
pub(crate) struct Indices {
    /// Named integers.
    pub sizes: FxHashMap<String, i64>,
    /// Each index's default range.
    pub ranges: IndexMap<String, (i64, i64)>,
    /// The shape of each family, by its base name.
    pub shapes: FxHashMap<String, Shape>,
    /// Subscripted names parsed so far (`P[i+1, j]`): a family's members name the same
    /// texts with other indices, parsed once.
    parsed: RefCell<FxHashMap<String, Rc<Subscript>>>,
    /// `[tables.NAME]`, in file order.
    pub tables: Vec<Rc<RowTable>>,
    /// `NAME_c`: the table and column it names.
    pub columns: FxHashMap<String, (usize, usize)>,
    /// Each particle family's members by their indices (`None`: the family is declared more
    /// than once, or over tables' rows; its members are then found by name).
    pub particles: FxHashMap<String, Option<EntriesByIndex>>,
}

/// The entries of an expanded table that one declaration's members are, by their indices:
/// row-major over the declared ranges (a force's `between = ["P[i+1]", "P[i]"]` finds its
/// particles by arithmetic, not by making and hashing `P[4]`).
#[derive(Clone, Debug)]
pub(crate) struct EntriesByIndex {
    ranges: Vec<(i64, i64)>,
    entries: Vec<u32>,
}

impl EntriesByIndex {
    const NONE: u32 = u32::MAX;

    /// No entry yet over `ranges` (their product at most [`MAX_MEMBERS`]: checked before the
    /// first member is made).
    fn new(ranges: &[(i64, i64)]) -> EntriesByIndex {
        let len = ranges
            .iter()
            .map(|(lo, hi)| (hi - lo + 1) as usize)
            .product::<usize>()
            .min(MAX_MEMBERS as usize);
        EntriesByIndex {
            ranges: ranges.to_vec(),
            entries: vec![Self::NONE; len],
        }
    }

    /// Where the member at `values` is kept, `None` outside the ranges.
    fn slot(&self, values: &[i64]) -> Option<usize> {
        if values.len() != self.ranges.len() {
            return None;
        }
        let mut at = 0usize;
        for (&v, &(lo, hi)) in values.iter().zip(&self.ranges) {
            if v < lo || v > hi {
                return None;
            }
            at = at * (hi - lo + 1) as usize + (v - lo) as usize;
        }
        (at < self.entries.len()).then_some(at)
    }

    fn set(&mut self, values: &[i64], entry: usize) {
        if let (Some(at), Ok(entry)) = (self.slot(values), u32::try_from(entry)) {
            self.entries[at] = entry;
        }
    }

    /// The entry of the member at `values`, if it is one.
    pub fn get(&self, values: &[i64]) -> Option<usize> {
        let e = self.entries[self.slot(values)?];
        (e != Self::NONE).then_some(e as usize)
    }
}

/// A subscripted name parsed: its base and each index expression with its place in the name.
#[derive(Debug)]
struct Subscript {
    base: Rc<str>,
    parts: Vec<(IndexExpr, usize, usize)>,
    /// Its parts as [`IndexProgram`]s, for the index names they were compiled with (`None`
    /// inside: a part names something a program cannot hold).
    programs: RefCell<Option<ProgramsFor>>,
}

/// Index names and the programs compiled for them.
type ProgramsFor = (Vec<String>, Option<Vec<IndexProgram>>);

/// A table's cell that a name (`bars_a`) stands for in a member.
pub(crate) struct Cell<'a> {
    pub table: &'a RowTable,
    pub row: usize,
    pub column: usize,
}

impl Cell<'_> {
    pub fn value(&self) -> f64 {
        self.table.value(self.row, self.column)
    }
}

impl Indices {
    /// The value of a size, a bound index, or a table's cell in the bound row.
    fn lookup<'a>(
        &'a self,
        bindings: &'a [(String, i64)],
        rows: &'a [(usize, usize)],
    ) -> impl Fn(&str) -> Result<Option<i64>, String> + 'a {
        move |name| {
            if let Some(b) = bindings.iter().find(|(n, _)| n == name) {
                return Ok(Some(b.1));
            }
            if let Some(&v) = self.sizes.get(name) {
                return Ok(Some(v));
            }
            match self.cell(name, rows)? {
                Some(c) => c.table.integer(c.row, c.column, name).map(Some),
                None => Ok(None),
            }
        }
    }

    /// `e` with its names resolved once: `names[k]` (a member's indices, in the order its
    /// values are given) before the sizes, as [`Indices::lookup`] finds them. `None` when `e`
    /// names anything else (a table's column, an unknown name).
    pub(crate) fn program(&self, e: &IndexExpr, names: &[String]) -> Option<IndexProgram> {
        IndexProgram::compile(e, &|n: &str| match names.iter().position(|m| m == n) {
            Some(k) => Some(Operand::Index(k)),
            None => self.sizes.get(n).map(|&v| Operand::Constant(v)),
        })
    }

    /// The cell that column `name` (`bars_a`) stands for in the row of its table in `rows`:
    /// `Ok(None)` when `name` is no column, an error when no row of its table is bound.
    pub fn cell(&self, name: &str, rows: &[(usize, usize)]) -> Result<Option<Cell<'_>>, String> {
        let Some(&(t, column)) = self.columns.get(name) else {
            return Ok(None);
        };
        let table = &self.tables[t];
        match rows.iter().find(|(rt, _)| *rt == t) {
            Some(&(_, row)) => Ok(Some(Cell { table, row, column })),
            None => Err(format!(
                "`{name}` is a column of table `{}`: it has a value in a family over its rows (for = \"r in {}\"), or with the row named: {name}[k]",
                table.name, table.name
            )),
        }
    }

    /// The cell that `name` names when it is a column with a subscript, `nodes_x[bars_a]`: the
    /// row whose key (or number) the subscript gives. `Ok(None)` when `name` is not that.
    pub fn subscripted_cell(
        &self,
        name: &str,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<Option<Cell<'_>>, IndexError> {
        if self.columns.is_empty() {
            // No table: no column, with or without a subscript (a family's members name
            // their neighbours 10^4 times: nothing is split for them).
            return Ok(None);
        }
        let Some((base, parts)) = index_expr::split_subscript(name) else {
            return Ok(None);
        };
        let Some(&(t, column)) = self.columns.get(base) else {
            return Ok(None);
        };
        let table = &self.tables[t];
        let [(text, offset)] = parts.as_slice() else {
            return Err(IndexError {
                span: 0..name.len(),
                message: format!("`{base}` is a column: it takes one subscript, the row's key"),
            });
        };
        let at = |e: IndexError| IndexError {
            span: e.span.start + offset..e.span.end + offset,
            message: e.message,
        };
        let e = index_expr::parse(text).map_err(at)?;
        let key = e.int(&self.lookup(bindings, rows)).map_err(|e| {
            let span = if e.span == (0..0) {
                0..text.len()
            } else {
                e.span
            };
            at(IndexError {
                span,
                message: e.message,
            })
        })?;
        match table.row_of(key) {
            Some(row) => Ok(Some(Cell { table, row, column })),
            None => Err(IndexError {
                span: 0..name.len(),
                message: format!(
                    "`{name}`: table `{}` has no row {key} (its rows are named by {}){}",
                    table.name,
                    table.naming(),
                    self.cells_text(&e, rows)
                ),
            }),
        }
    }

    /// `spring[i=3, j=19]`, with the table rows the member stands for.
    pub fn label(&self, base: &str, bindings: &[(String, i64)], rows: &[(usize, usize)]) -> String {
        let mut out = label(base, bindings);
        for &(t, row) in rows {
            let table = &self.tables[t];
            out.push_str(&format!(
                " (table `{}`, {} line {})",
                table.name,
                table.file,
                table.line(row)
            ));
        }
        out
    }

    /// ` (`bars_b` = 9 at bars.csv:4:5)`: where the table cells an index expression uses
    /// come from, for a message about the member they name.
    fn cells_text(&self, e: &IndexExpr, rows: &[(usize, usize)]) -> String {
        let mut parts = Vec::new();
        for name in e.names() {
            if let Ok(Some(c)) = self.cell(name, rows) {
                let text = c
                    .table
                    .cell_message(c.row, c.column, "")
                    .split(": ")
                    .next()
                    .unwrap_or_default()
                    .to_string();
                let part = format!("`{name}` = {} at {text}", c.value());
                if !parts.contains(&part) {
                    parts.push(part);
                }
            }
        }
        if parts.is_empty() {
            String::new()
        } else {
            format!(" ({})", parts.join(", "))
        }
    }

    /// The member that `name` (`P[i+1, j]`, `P[3,4]`, `P`) names with `bindings`: its canonical
    /// name `P[4,3]`. `Ok(None)` when `name` has no subscript. An error when an index cannot
    /// be evaluated, or the member is outside its family's shape; spans are in `name`.
    pub fn member_name(
        &self,
        name: &str,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<Option<String>, IndexError> {
        let mut out = String::new();
        Ok(self
            .member_name_into(name, bindings, rows, &mut out)?
            .then_some(out))
    }

    /// [`Indices::member_name`] written into `buf` (cleared first) instead of a new string:
    /// `Ok(false)` when `name` has no subscript. For a lookup by name that keeps nothing (a
    /// family's template names `x[i]` for each of 10^4 members).
    pub fn member_name_into(
        &self,
        name: &str,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
        buf: &mut String,
    ) -> Result<bool, IndexError> {
        let Some(subscript) = self.subscript(name)? else {
            return Ok(false);
        };
        // One or two indices in practice: kept on the stack (this is once per reference per
        // member).
        let n = subscript.parts.len();
        let mut inline = [0i64; 4];
        let mut spilled = Vec::new();
        let values: &[i64] = if n <= inline.len() {
            self.subscript_values(&subscript, bindings, rows, &mut inline[..n])?;
            &inline[..n]
        } else {
            spilled.resize(n, 0);
            self.subscript_values(&subscript, bindings, rows, &mut spilled)?;
            &spilled
        };
        self.check_member(&subscript, values, name, rows)?;
        buf.clear();
        push_member(buf, &subscript.base, values);
        Ok(true)
    }

    /// [`Indices::member_name`] without the name: the member's family and indices, checked
    /// as that checks them. `Ok(None)` when `name` has no subscript or more than two (the
    /// name then says what it is).
    pub fn member_ref(
        &self,
        name: &str,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<Option<MemberRef>, IndexError> {
        let Some(subscript) = self.subscript(name)? else {
            return Ok(None);
        };
        let n = subscript.parts.len();
        if n > 2 {
            return Ok(None);
        }
        let mut values = [0i64; 2];
        self.subscript_values(&subscript, bindings, rows, &mut values[..n])?;
        self.check_member(&subscript, &values[..n], name, rows)?;
        Ok(Some(MemberRef {
            base: Rc::clone(&subscript.base),
            values,
            len: n as u8,
        }))
    }

    /// The entry of `[particles]` (after expansion: the particle's index) that `r` names, when
    /// its family's members are known by index; `None` otherwise (found by name then).
    pub fn particle_of(&self, r: &MemberRef) -> Option<usize> {
        self.particles.get(&*r.base)?.as_ref()?.get(r.values())
    }

    /// The subscripted name `name` parsed (once per text), or `None` when it has no subscript.
    fn subscript(&self, name: &str) -> Result<Option<Rc<Subscript>>, IndexError> {
        if let Some(s) = self.parsed.borrow().get(name) {
            return Ok(Some(Rc::clone(s)));
        }
        let Some((base, parts)) = index_expr::split_subscript(name) else {
            return Ok(None);
        };
        let mut parsed = Vec::with_capacity(parts.len());
        for (text, offset) in &parts {
            let e = index_expr::parse(text).map_err(|e| IndexError {
                span: e.span.start + offset..e.span.end + offset,
                message: e.message,
            })?;
            parsed.push((e, *offset, text.len()));
        }
        let s = Rc::new(Subscript {
            base: Rc::from(base),
            parts: parsed,
            programs: RefCell::new(None),
        });
        self.parsed
            .borrow_mut()
            .insert(name.to_string(), Rc::clone(&s));
        Ok(Some(s))
    }

    /// The values of `subscript`'s indices with `bindings`, into `out` (one per part): by its
    /// programs when they compute them, else (and for the error) by the general evaluation.
    fn subscript_values(
        &self,
        subscript: &Subscript,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
        out: &mut [i64],
    ) -> Result<(), IndexError> {
        {
            let mut programs = subscript.programs.borrow_mut();
            // Compiled for the names of the indices bound: a family's members bind the same
            // names, so this is once per text and family.
            let same_names = programs.as_ref().is_some_and(|(names, _)| {
                names.len() == bindings.len() && names.iter().zip(bindings).all(|(n, b)| *n == b.0)
            });
            if !same_names {
                let names: Vec<String> = bindings.iter().map(|b| b.0.clone()).collect();
                let compiled: Option<Vec<IndexProgram>> = subscript
                    .parts
                    .iter()
                    .map(|(e, _, _)| self.program(e, &names))
                    .collect();
                *programs = Some((names, compiled));
            }
            if let Some((_, Some(compiled))) = programs.as_ref() {
                let mut bound = [0i64; 4];
                if bindings.len() <= bound.len() {
                    for (slot, b) in bound.iter_mut().zip(bindings) {
                        *slot = b.1;
                    }
                    let bound = &bound[..bindings.len()];
                    let mut all = true;
                    for (o, p) in out.iter_mut().zip(compiled) {
                        match p.int(bound) {
                            Some(v) => *o = v,
                            None => {
                                all = false;
                                break;
                            }
                        }
                    }
                    if all {
                        return Ok(());
                    }
                }
            }
        }
        let lookup = self.lookup(bindings, rows);
        for (o, (e, offset, len)) in out.iter_mut().zip(&subscript.parts) {
            *o = e.int(&lookup).map_err(|e| {
                let span = if e.span == (0..0) { 0..*len } else { e.span };
                IndexError {
                    span: span.start + offset..span.end + offset,
                    message: e.message,
                }
            })?;
        }
        Ok(())
    }

    /// Whether the member of `subscript`'s family at `values` is inside its family's shape
    /// (and among the rows of a family over tables); the error names it (`name` is the text
    /// referring to it, for the span).
    fn check_member(
        &self,
        subscript: &Subscript,
        values: &[i64],
        name: &str,
        rows: &[(usize, usize)],
    ) -> Result<(), IndexError> {
        let base: &str = &subscript.base;
        if let Some(shape) = self.shapes.get(base) {
            let inside = shape.ranges.len() == values.len()
                && shape
                    .ranges
                    .iter()
                    .zip(values)
                    .all(|((lo, hi), v)| lo <= v && v <= hi);
            if !inside {
                return Err(IndexError {
                    span: 0..name.len(),
                    message: format!(
                        "{} is outside {}{}",
                        member(base, values),
                        shape_text(base, shape),
                        self.subscript_cells(subscript, rows)
                    ),
                });
            }
            if let Some(declared) = &shape.rows {
                if !declared.contains(values) {
                    let canonical = member(base, values);
                    return Err(IndexError {
                        span: 0..name.len(),
                        message: format!(
                            "{canonical} is not declared: `{base}` is declared over the rows of tables, and no row names {canonical}{}",
                            self.subscript_cells(subscript, rows)
                        ),
                    });
                }
            }
        }
        Ok(())
    }
}

/// A member of a family named by its indices (`P[i+1]` read for `i = 3`: `P` at `[4]`), its
/// name `P[4]` made only when something needs it.
#[derive(Clone, Debug)]
pub(crate) struct MemberRef {
    /// The family.
    pub base: Rc<str>,
    values: [i64; 2],
    len: u8,
}

impl MemberRef {
    /// The member's indices.
    pub fn values(&self) -> &[i64] {
        &self.values[..self.len as usize]
    }

    /// Its canonical name, `P[4]`.
    pub fn name(&self) -> String {
        member(&self.base, self.values())
    }
}

impl Indices {
    fn subscript_cells(&self, s: &Subscript, rows: &[(usize, usize)]) -> String {
        let mut out = String::new();
        for (e, _, _) in &s.parts {
            out.push_str(&self.cells_text(e, rows));
        }
        out
    }
}

thread_local! {
    /// How many members' names this thread has made ([`names_made`]).
    static NAMES_MADE: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// How many members' names (`P[3,4]`) this thread has made so far: a test counts those a
/// load makes (a reference found by index makes none). One increment per name.
#[doc(hidden)]
pub fn names_made() -> u64 {
    NAMES_MADE.with(|c| c.get())
}

/// `P[3,4]`.
pub(crate) fn member(base: &str, values: &[i64]) -> String {
    // Written into one string: a net's 10^5 names were a Vec of strings each.
    let mut out = String::with_capacity(base.len() + 2 + 6 * values.len());
    push_member(&mut out, base, values);
    out
}

/// `P[3,4]` appended to `out`.
fn push_member(out: &mut String, base: &str, values: &[i64]) {
    NAMES_MADE.with(|c| c.set(c.get() + 1));
    out.push_str(base);
    out.push('[');
    for (k, &v) in values.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        push_int(out, v);
    }
    out.push(']');
}

/// `v` in decimal appended to `out`, as `{v}` writes it: a family's names are made per
/// member and per reference (`P[i+1]` of each spring), and the formatting machinery was most
/// of making them.
fn push_int(out: &mut String, v: i64) {
    let mut digits = [0u8; 20];
    let mut k = digits.len();
    let mut m = v.unsigned_abs();
    loop {
        k -= 1;
        digits[k] = b'0' + (m % 10) as u8;
        m /= 10;
        if m == 0 {
            break;
        }
    }
    if v < 0 {
        out.push('-');
    }
    // ASCII digits pushed one by one: checking them as UTF-8 (`from_utf8`) cost more than
    // pushing a name's few digits.
    out.reserve(digits.len() - k);
    for &d in &digits[k..] {
        out.push(char::from(d));
    }
}

/// `P[0..19, 0..19]`.
pub(crate) fn shape_text(base: &str, shape: &Shape) -> String {
    let r: Vec<String> = shape
        .ranges
        .iter()
        .map(|(lo, hi)| format!("{lo}..{hi}"))
        .collect();
    format!("{base}[{}]", r.join(", "))
}

/// `spring[i=3, j=19]`.
fn label(base: &str, bindings: &[(String, i64)]) -> String {
    let mut out = String::with_capacity(base.len() + 2 + 8 * bindings.len());
    out.push_str(base);
    out.push('[');
    for (k, (n, v)) in bindings.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        out.push_str(n);
        out.push('=');
        push_int(&mut out, *v);
    }
    out.push(']');
    out
}

/// A family declaration's head: `P[i,j]` is `P` over `i`, `j`; `P[3,4]` (all numbers) is an
/// ordinary name, `P` too. A family over the rows of tables may be named by its columns,
/// `P[nodes_i, nodes_j]`: each part is kept with its offset in the name.
enum Head<'a> {
    Plain,
    Family(&'a str, Vec<(String, usize)>),
}

/// Whether `p` is a plain index name.
fn is_index_name(p: &str) -> bool {
    p.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && p.chars().all(|c| c.is_alphanumeric() || c == '_')
}

/// The byte offset at which the text of a string value or key starts (after its quote).
fn text_start(ld: &Loader, span: &Range<usize>) -> usize {
    match ld.source.as_bytes().get(span.start) {
        Some(b'"') | Some(b'\'') => span.start + 1,
        _ => span.start,
    }
}

fn located(ld: &Loader, span: &Range<usize>, e: IndexError) -> ModelError {
    let start = text_start(ld, span);
    let end = (start + e.span.end).min(span.end.max(start));
    ld.err(start + e.span.start.min(end - start)..end, e.message)
}

/// What one family iterates over: its index names and their ranges, and its condition.
struct Domain {
    names: Vec<String>,
    ranges: Vec<(i64, i64)>,
    /// Per name, the table whose rows it runs over (its range is then the rows' numbers and
    /// its value each row's key).
    tables: Vec<Option<usize>>,
    condition: Option<(IndexExpr, Sv)>,
}

impl Domain {
    fn count(&self) -> u64 {
        self.ranges
            .iter()
            // In i128: a range from i64::MIN to i64::MAX must not overflow while it is refused.
            .map(|(lo, hi)| u64::try_from(*hi as i128 - *lo as i128 + 1).unwrap_or(u64::MAX))
            .fold(1u64, |a, b| a.saturating_mul(b))
    }
}

struct Expander<'l, 'a> {
    ld: &'l mut Loader<'a>,
    indices: Indices,
    members: u64,
}

impl<'l, 'a> Expander<'l, 'a> {
    fn head<'n>(&self, name: &'n Name) -> Result<Head<'n>, ModelError> {
        let text = name.get_ref();
        let Some((base, parts)) = index_expr::split_subscript(text) else {
            if text.contains('[') || text.contains(']') {
                return Err(self.ld.err(
                    name.span(),
                    format!("`{text}` is not a name: a family is written NAME[i] or NAME[i,j]"),
                ));
            }
            return Ok(Head::Plain);
        };
        let trimmed: Vec<&str> = parts.iter().map(|(p, _)| p.trim()).collect();
        if trimmed.iter().all(|p| p.parse::<i64>().is_ok()) {
            return Ok(Head::Plain);
        }
        let mut names: Vec<(String, usize)> = Vec::new();
        for (p, (raw, off)) in trimmed.iter().zip(&parts) {
            if is_index_name(p) && names.iter().any(|(n, _)| n == p) {
                return Err(self.ld.err(
                    name.span(),
                    format!("index `{p}` appears twice in `{text}`"),
                ));
            }
            let lead = raw.len() - raw.trim_start().len();
            names.push((p.to_string(), off + lead));
        }
        if names.len() > 2 {
            return Err(self.ld.err(
                name.span(),
                format!(
                    "`{text}` has {} indices: families have one or two",
                    names.len()
                ),
            ));
        }
        Ok(Head::Family(base, names))
    }

    /// The ranges of `names` (from `for` when given, else from `[indices]`) and the `where`.
    fn domain(
        &self,
        at: &Range<usize>,
        names: &[String],
        for_list: Option<&Sv>,
        condition: Option<&Sv>,
    ) -> Result<Domain, ModelError> {
        let clauses: Vec<ForClause> = match for_list {
            Some(sv) => {
                let toml::Value::String(text) = sv.get_ref() else {
                    return Err(self
                        .ld
                        .err(sv.span(), "`for` is a string: \"i in 0..n-2, j\""));
                };
                index_expr::parse_for(text).map_err(|e| located(self.ld, &sv.span(), e))?
            }
            None => names
                .iter()
                .map(|n| ForClause {
                    name: n.clone(),
                    span: 0..0,
                    range: None,
                    table: None,
                })
                .collect(),
        };
        let mut out = Domain {
            names: Vec::new(),
            ranges: Vec::new(),
            tables: Vec::new(),
            condition: None,
        };
        let lookup = self.indices.lookup(&[], &[]);
        for c in &clauses {
            let mut table = None;
            let range = match &c.range {
                _ if c.table.is_some() => {
                    let (t, at) = c.table.clone().unwrap_or_default();
                    let Some(k) = self.indices.tables.iter().position(|x| x.name == t) else {
                        let span = match for_list {
                            Some(sv) => {
                                let s = text_start(self.ld, &sv.span());
                                s + at.start..s + at.end
                            }
                            None => at.clone(),
                        };
                        let declared: Vec<String> =
                            self.indices.tables.iter().map(|x| x.name.clone()).collect();
                        let help = if declared.is_empty() {
                            "declare it as [tables.NAME] with file = \"NAME.csv\", or give a range: i in 0..n-1".to_string()
                        } else {
                            format!(
                                "the tables are {}; a range is written i in 0..n-1",
                                super::row_tables::quoted_list(&declared)
                            )
                        };
                        return Err(self
                            .ld
                            .err(span, format!("`{t}` is not a table: `{} in {t}` runs over the rows of a [tables.{t}]", c.name))
                            .help(help));
                    };
                    table = Some(k);
                    (0, self.indices.tables[k].len() as i64 - 1)
                }
                Some(r) => {
                    // A range is written in a `for` list; its clause's own span otherwise.
                    let span = for_list.map_or(c.span.clone(), |sv| sv.span());
                    let lo = r.lo.int(&lookup).map_err(|e| located(self.ld, &span, e))?;
                    let hi = r.hi.int(&lookup).map_err(|e| located(self.ld, &span, e))?;
                    (lo, hi)
                }
                None => match self.indices.ranges.get(&c.name) {
                    Some(r) => *r,
                    None => {
                        let span = match for_list {
                            Some(sv) => {
                                let s = text_start(self.ld, &sv.span());
                                s + c.span.start..s + c.span.end
                            }
                            None => at.clone(),
                        };
                        return Err(self
                            .ld
                            .err(span, format!("index `{}` has no range", c.name))
                            .help(format!("declare it under [indices] (`{} = \"0..n-1\"`) or give it one here: for = \"{} in 0..n-1\"", c.name, c.name)));
                    }
                },
            };
            if range.1 < range.0 {
                let span = for_list.map_or(at.clone(), |sv| sv.span());
                return Err(self
                    .ld
                    .err(
                        span,
                        format!(
                            "index `{}` has an empty range {}..{}",
                            c.name, range.0, range.1
                        ),
                    )
                    .help("a range first..last includes both ends and needs first <= last"));
            }
            out.names.push(c.name.clone());
            out.ranges.push(range);
            out.tables.push(table);
        }
        for n in names {
            if !out.names.contains(n) {
                let span = for_list.map_or(at.clone(), |sv| sv.span());
                return Err(self
                    .ld
                    .err(span, format!("`for` gives no range to index `{n}`")));
            }
        }
        if let Some(sv) = condition {
            let toml::Value::String(text) = sv.get_ref() else {
                return Err(self.ld.err(
                    sv.span(),
                    "`where` is a condition in quotes: \"j > 0 or i != 0\"",
                ));
            };
            let e = index_expr::parse(text).map_err(|e| located(self.ld, &sv.span(), e))?;
            out.condition = Some((e, sv.clone()));
        }
        Ok(out)
    }

    /// Every member of `domain` (row-major: the last index fastest), with `make` building each
    /// entry.
    fn each(
        &mut self,
        at: &Range<usize>,
        base: &str,
        domain: &Domain,
        mut make: impl FnMut(&mut Self, &[(String, i64)], &[(usize, usize)]) -> Result<(), ModelError>,
    ) -> Result<(), ModelError> {
        let count = domain.count();
        self.members = self.members.saturating_add(count);
        if self.members > MAX_MEMBERS {
            return Err(self
                .ld
                .err(
                    at.clone(),
                    format!(
                        "the family `{base}` has {count} members, which would make the model's families more than {MAX_MEMBERS} entries"
                    ),
                )
                .help("a model of this size cannot be loaded; use smaller ranges"));
        }
        let mut any = false;
        let mut values: Vec<i64> = domain.ranges.iter().map(|r| r.0).collect();
        // The names once, the values set for each member (not a string per index per member).
        let mut bindings: Vec<(String, i64)> =
            domain.names.iter().map(|n| (n.clone(), 0)).collect();
        let mut rows: Rows = Vec::new();
        // The `where` with its names resolved once (`None`: it names a table's column, or
        // something that is an error; the general path then evaluates it, and says so).
        let program = domain
            .condition
            .as_ref()
            .and_then(|(e, _)| self.indices.program(e, &domain.names));
        let mut bound: Vec<i64> = vec![0; bindings.len()];
        'all: loop {
            // A table's index takes each row's key; the row itself is kept for its cells.
            rows.clear();
            for (((b, slot), &v), t) in bindings
                .iter_mut()
                .zip(bound.iter_mut())
                .zip(&values)
                .zip(&domain.tables)
            {
                b.1 = match t {
                    Some(t) => {
                        rows.push((*t, v as usize));
                        self.indices.tables[*t].keys[v as usize]
                    }
                    None => v,
                };
                *slot = b.1;
            }
            let fast = program.as_ref().and_then(|p| p.condition(&bound));
            let keep = match (&domain.condition, fast) {
                (None, _) => true,
                (Some(_), Some(keep)) => keep,
                (Some((e, sv)), None) => e
                    .condition(&self.indices.lookup(&bindings, &rows))
                    .map_err(|e| {
                        let e = if e.span == (0..0) {
                            IndexError {
                                span: 0..self.ld.source[sv.span()].len().saturating_sub(2),
                                message: e.message,
                            }
                        } else {
                            e
                        };
                        let err = located(self.ld, &sv.span(), e);
                        in_member(err, &self.indices.label(base, &bindings, &rows))
                    })?,
            };
            if keep {
                any = true;
                make(self, &bindings, &rows)?;
            }
            for k in (0..values.len()).rev() {
                if values[k] < domain.ranges[k].1 {
                    values[k] += 1;
                    continue 'all;
                }
                values[k] = domain.ranges[k].0;
            }
            break;
        }
        if !any {
            return Err(self
                .ld
                .err(
                    at.clone(),
                    format!("the family `{base}` has no members: its `where` excludes every index"),
                )
                .help("check the condition, or remove the family"));
        }
        Ok(())
    }

    /// Records a declared family's shape (the union of its declarations' ranges: `P` may be
    /// points where pinned and particles elsewhere).
    fn record_shape(
        &mut self,
        name: &Name,
        base: &str,
        ranges: &[(i64, i64)],
        rows: Option<FxHashSet<Vec<i64>>>,
    ) -> Result<(), ModelError> {
        match self.indices.shapes.get_mut(base) {
            None => {
                self.indices.shapes.insert(
                    base.to_string(),
                    Shape {
                        ranges: ranges.to_vec(),
                        rows,
                    },
                );
            }
            Some(shape) if shape.ranges.len() == ranges.len() => {
                for (s, r) in shape.ranges.iter_mut().zip(ranges) {
                    *s = (s.0.min(r.0), s.1.max(r.1));
                }
                match (&mut shape.rows, rows) {
                    (Some(a), Some(b)) => a.extend(b),
                    // A declaration over whole ranges: every member inside them may exist.
                    (a, _) => *a = None,
                }
            }
            Some(shape) => {
                return Err(self.ld.err(
                    name.span(),
                    format!(
                        "`{}` has {} indices but `{base}` was declared with {}",
                        name.get_ref(),
                        ranges.len(),
                        shape.ranges.len()
                    ),
                ))
            }
        }
        Ok(())
    }

    /// Expands one keyed table (`[coordinates]`, `[points]`, `[definitions]`, `[particles]`).
    /// `split` takes the `for` and `where` out of an entry's value and returns the value left.
    fn keyed<V: Clone>(
        &mut self,
        table: Keyed<V>,
        shared: &mut Shared<V>,
        span_of: impl Fn(&V) -> Range<usize>,
        split: impl Fn(&Self, &V) -> Result<(V, Option<Sv>, Option<Sv>), ModelError>,
        placeholder: impl Fn(&V) -> V,
        by_index: &mut FxHashMap<String, Option<EntriesByIndex>>,
    ) -> Result<Expanded<Keyed<V>>, ModelError> {
        let mut out = Keyed::with_capacity_and_hasher(table.len(), Default::default());
        let mut members = Vec::with_capacity(table.len());
        for (name, value) in table {
            match self.head(&name)? {
                Head::Plain => {
                    let (value, for_list, condition) = split(self, &value)?;
                    if let Some(sv) = for_list.or(condition) {
                        return Err(self
                            .ld
                            .err(
                                sv.span(),
                                format!(
                                    "`for` and `where` belong to families; `{}` is one entry",
                                    name.get_ref()
                                ),
                            )
                            .help(format!(
                                "declare a family with its indices: `{}[i]`",
                                name.get_ref()
                            )));
                    }
                    let key = match index_expr::split_subscript(name.get_ref()) {
                        Some(_) => Spanned::new(
                            name.span(),
                            self.indices
                                .member_name(name.get_ref(), &[], &[])
                                .map_err(|e| located(self.ld, &name.span(), e))?
                                .unwrap_or_else(|| name.get_ref().clone()),
                        ),
                        None => name,
                    };
                    self.insert(&mut out, key, value)?;
                    members.push(None);
                    shared.of_entry.push(None);
                }
                Head::Family(base, parts) => {
                    let base = base.to_string();
                    let (value, for_list, condition) = split(self, &value)?;
                    let index_names: Vec<String> = parts
                        .iter()
                        .filter(|(p, _)| is_index_name(p))
                        .map(|(p, _)| p.clone())
                        .collect();
                    // Without `for`, the head's names take their [indices] ranges; with it, the
                    // names are checked below (a family over table rows has none to check).
                    let implied: &[String] = if for_list.is_some() {
                        &[]
                    } else {
                        &index_names
                    };
                    let domain = self.domain(
                        &span_of(&value),
                        implied,
                        for_list.as_ref(),
                        condition.as_ref(),
                    )?;
                    if domain.tables.iter().any(Option::is_some) {
                        // Over table rows: each part of the name an index expression of the
                        // row (`N[r]`, `P[nodes_i, nodes_j]`).
                        self.table_family(
                            &name,
                            &base,
                            &parts,
                            &domain,
                            &value,
                            &mut out,
                            &mut members,
                        )?;
                        shared.of_entry.resize(members.len(), None);
                        by_index.insert(base, None);
                        continue;
                    }
                    for (p, off) in &parts {
                        if !is_index_name(p) {
                            let e = IndexError {
                                span: *off..off + p.len().max(1),
                                message: format!("a family is declared over index names (`{base}[i,j]`), not `{p}`: index arithmetic belongs where members are used"),
                            };
                            return Err(located(self.ld, &name.span(), e));
                        }
                    }
                    let names = index_names;
                    for n in &names {
                        if !domain.names.contains(n) {
                            let span = for_list.as_ref().map_or(span_of(&value), |sv| sv.span());
                            return Err(self
                                .ld
                                .err(span, format!("`for` gives no range to index `{n}`")));
                        }
                    }
                    // The shape is the ranges declared, whatever `where` leaves out.
                    let ranges: Vec<(i64, i64)> = names
                        .iter()
                        .map(|n| {
                            domain.ranges[domain.names.iter().position(|d| d == n).unwrap_or(0)]
                        })
                        .collect();
                    self.record_shape(&name, &base, &ranges, None)?;
                    let family: Rc<str> = Rc::from(base.as_str());
                    let index_names: Rc<[String]> = domain.names.clone().into();
                    let stand_in = placeholder(&value);
                    let which = Some(shared.values.len() as u32);
                    shared.values.push(value);
                    let count = usize::try_from(domain.count()).unwrap_or(0);
                    let count = count.min(MAX_MEMBERS as usize);
                    out.reserve(count);
                    members.reserve(count);
                    shared.of_entry.reserve(count);
                    // Where each head name's value is among the bindings, found once.
                    let slots: Vec<usize> = names
                        .iter()
                        .map(|n| domain.names.iter().position(|d| d == n).unwrap_or(0))
                        .collect();
                    let mut entries: Option<EntriesByIndex> = None;
                    self.each(&name.span(), &base, &domain, |ex, bindings, rows| {
                        let mut inline = [0i64; 2];
                        let mut spilled = Vec::new();
                        let values: &mut [i64] = if slots.len() <= inline.len() {
                            &mut inline[..slots.len()]
                        } else {
                            spilled.resize(slots.len(), 0);
                            &mut spilled
                        };
                        for (v, &k) in values.iter_mut().zip(&slots) {
                            *v = bindings.get(k).map_or(0, |b| b.1);
                        }
                        // Made at the first member: `each` has checked the family's size.
                        entries
                            .get_or_insert_with(|| EntriesByIndex::new(&ranges))
                            .set(values, out.len());
                        let key = Spanned::new(name.span(), member(&base, values));
                        ex.insert(&mut out, key, stand_in.clone())?;
                        members.push(Some(Member::of(&family, &index_names, bindings, rows)));
                        shared.of_entry.push(which);
                        Ok(())
                    })?;
                    // A second declaration of the same family in this table: found by name.
                    let known = by_index.contains_key(&base);
                    by_index.insert(base, if known { None } else { entries });
                }
            }
        }
        Ok((out, members))
    }

    /// The members of a family over table rows, named by index expressions of each row
    /// (`N[r]`, `P[nodes_i, nodes_j]`); its shape is the names its rows give.
    #[allow(clippy::too_many_arguments)]
    fn table_family<V: Clone>(
        &mut self,
        name: &Name,
        base: &str,
        parts: &[(String, usize)],
        domain: &Domain,
        value: &V,
        out: &mut Keyed<V>,
        members: &mut Vec<Option<Member>>,
    ) -> Result<(), ModelError> {
        let mut exprs = Vec::with_capacity(parts.len());
        for (p, off) in parts {
            let e = index_expr::parse(p).map_err(|e| {
                let e = IndexError {
                    span: e.span.start + off..e.span.end + off,
                    message: e.message,
                };
                located(self.ld, &name.span(), e)
            })?;
            exprs.push((e, *off, p.len()));
        }
        let family: Rc<str> = Rc::from(base);
        let index_names: Rc<[String]> = domain.names.clone().into();
        let mut declared: FxHashSet<Vec<i64>> = FxHashSet::default();
        let mut ranges = vec![(i64::MAX, i64::MIN); parts.len()];
        self.each(&name.span(), base, domain, |ex, bindings, rows| {
            let label = || ex.indices.label(base, bindings, rows);
            let mut values = Vec::with_capacity(exprs.len());
            {
                let lookup = ex.indices.lookup(bindings, rows);
                for (e, off, len) in &exprs {
                    let v = e.int(&lookup).map_err(|e| {
                        let span = if e.span == (0..0) { 0..*len } else { e.span };
                        let e = IndexError {
                            span: span.start + off..span.end + off,
                            message: e.message,
                        };
                        in_member(located(ex.ld, &name.span(), e), &label())
                    })?;
                    values.push(v);
                }
            }
            for (r, &v) in ranges.iter_mut().zip(&values) {
                *r = (r.0.min(v), r.1.max(v));
            }
            let key = Spanned::new(name.span(), member(base, &values));
            ex.insert(out, key, value.clone())
                .map_err(|e| in_member(e, &label()))?;
            declared.insert(values);
            members.push(Some(Member::of(&family, &index_names, bindings, rows)));
            Ok(())
        })?;
        self.record_shape(name, base, &ranges, Some(declared))
    }

    fn insert<V>(&self, out: &mut Keyed<V>, key: Name, value: V) -> Result<(), ModelError> {
        // Hashed once: inserted, and refused if it was there (the table is then dropped).
        let span = key.span();
        let (at, previous) = out.insert_full(key, value);
        if previous.is_some() {
            let name = out.get_index(at).map_or("", |(k, _)| k.get_ref().as_str());
            return Err(self
                .ld
                .err(span, format!("`{name}` is declared twice in this table"))
                .help("a family's members and the table's other entries need distinct names"));
        }
        Ok(())
    }

    /// A name field of a force member: `P[i+1, j]` → `P[4,3]`.
    fn resolve_name(
        &self,
        name: &Name,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<Name, ModelError> {
        match self
            .indices
            .member_name(name.get_ref(), bindings, rows)
            .map_err(|e| located(self.ld, &name.span(), e))?
        {
            Some(n) => Ok(Spanned::new(name.span(), n)),
            None => Ok(name.clone()),
        }
    }

    /// A force's name fields resolved to members: `P[i+1, j]` → `P[4,3]` with `bindings`
    /// (`P[0, 9]` → `P[0,9]`, checked against its family, in an ordinary force).
    fn resolve_names(
        &self,
        raw: &RawForce,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<Names, ModelError> {
        let names = |field: &Option<Name>| -> Result<Option<Name>, ModelError> {
            field
                .as_ref()
                .map(|n| self.resolve_name(n, bindings, rows))
                .transpose()
        };
        let between = match &raw.between {
            Some(b) => {
                let ends = b
                    .get_ref()
                    .iter()
                    .map(|n| self.resolve_name(n, bindings, rows))
                    .collect::<Result<Vec<_>, _>>()?;
                Some(Spanned::new(b.span(), ends))
            }
            None => None,
        };
        Ok(Names {
            name: raw.name.clone(),
            on: names(&raw.on)?,
            to: names(&raw.to)?,
            normal_force: names(&raw.normal_force)?,
            friction_force: names(&raw.friction_force)?,
            between,
        })
    }

    /// A force member's `between` (two names) or `on` as members by index, when that is
    /// all it names and each is a subscripted name: no name made (`Ok(None)` otherwise: its
    /// names are then resolved as text). The errors are [`Expander::resolve_name`]'s.
    fn member_ends(
        &self,
        raw: &RawForce,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<Option<MemberEnds>, ModelError> {
        if raw.to.is_some() || raw.normal_force.is_some() || raw.friction_force.is_some() {
            return Ok(None);
        }
        let end = |name: &Name| -> Result<Option<(MemberRef, Range<usize>)>, ModelError> {
            let r = self
                .indices
                .member_ref(name.get_ref(), bindings, rows)
                .map_err(|e| located(self.ld, &name.span(), e))?;
            Ok(r.map(|r| (r, name.span())))
        };
        match (&raw.between, &raw.on) {
            (Some(b), None) => {
                let [first, second] = b.get_ref().as_slice() else {
                    return Ok(None);
                };
                let (Some(first), Some(second)) = (end(first)?, end(second)?) else {
                    return Ok(None);
                };
                Ok(Some(MemberEnds::Between(b.span(), [first, second])))
            }
            (None, Some(on)) => Ok(end(on)?.map(|(r, span)| MemberEnds::On(r, span))),
            _ => Ok(None),
        }
    }

    /// A member of the force family `f` whose name (without `name`: its kind) is `base`, read
    /// with `bindings`: its name fields resolved, `between` or `on` by index when they can be
    /// ([`Expander::member_ends`]), its own name made when it is built ([`ForceEntry::raw`]).
    fn force_member(
        &self,
        entry: usize,
        f: &Spanned<RawForce>,
        base: &Rc<str>,
        bindings: &[(String, i64)],
        rows: &[(usize, usize)],
    ) -> Result<ForceEntry, ModelError> {
        let raw = f.get_ref();
        let (mut names, ends) = match self.member_ends(raw, bindings, rows)? {
            Some(ends) => (Names::default(), Some(ends)),
            None => (self.resolve_names(raw, bindings, rows)?, None),
        };
        let mut label_of = None;
        match &raw.name {
            Some(n) if n.get_ref().contains('[') => {
                names.name = Some(self.resolve_name(n, bindings, rows)?)
            }
            // `spring[i=3]`: made from the bindings when the member is built.
            Some(n) => label_of = Some((Rc::clone(base), n.span())),
            None => label_of = Some((Rc::clone(base), f.span())),
        }
        Ok(ForceEntry {
            entry,
            names,
            ends,
            label_of,
        })
    }

    fn forces(
        &mut self,
        forces: &[Spanned<RawForce>],
    ) -> Result<Expanded<Vec<ForceEntry>>, ModelError> {
        let mut out = Vec::with_capacity(forces.len());
        let mut members = Vec::with_capacity(forces.len());
        for (entry, f) in forces.iter().enumerate() {
            let raw = f.get_ref();
            let Some(for_list) = raw.for_list.clone() else {
                if let Some(c) = &raw.condition {
                    return Err(self
                        .ld
                        .err(
                            c.span(),
                            "`where` needs `for`: it selects members of a family",
                        )
                        .help(
                            "add for = \"i in 0..n-2\" (or the indices declared under [indices])",
                        ));
                }
                let names = self.resolve_names(raw, &[], &[])?;
                out.push(ForceEntry::written(entry, names));
                members.push(None);
                continue;
            };
            let base = match (&raw.name, &raw.kind) {
                (Some(n), _) => n.get_ref().split('[').next().unwrap_or("").to_string(),
                (None, Some(k)) => k.get_ref().clone(),
                (None, None) => "force".to_string(),
            };
            let domain = self.domain(&f.span(), &[], Some(&for_list), raw.condition.as_ref())?;
            let family: Rc<str> = Rc::from(base.as_str());
            let index_names: Rc<[String]> = domain.names.clone().into();
            let count = usize::try_from(domain.count())
                .unwrap_or(0)
                .min(MAX_MEMBERS as usize);
            out.reserve(count);
            members.reserve(count);
            self.each(&for_list.span(), &base, &domain, |ex, bindings, rows| {
                let member = ex
                    .force_member(entry, f, &family, bindings, rows)
                    .map_err(|e| in_member(e, &ex.indices.label(&base, bindings, rows)))?;
                out.push(member);
                members.push(Some(Member::of(&family, &index_names, bindings, rows)));
                Ok(())
            })?;
        }
        Ok((out, members))
    }
}

/// The name fields of a `[[forces]]` entry, resolved to the members they name.
#[derive(Clone, Debug, Default)]
pub(crate) struct Names {
    pub name: Option<Name>,
    pub on: Option<Name>,
    pub to: Option<Name>,
    pub normal_force: Option<Name>,
    pub friction_force: Option<Name>,
    pub between: Option<Spanned<Vec<Name>>>,
}

/// One `[[forces]]` entry after expansion: the entry of the file it comes from (a family's
/// members share it: its other fields are not copied per member) and its name fields.
#[derive(Clone, Debug)]
pub(crate) struct ForceEntry {
    /// Index into the file's `[[forces]]`.
    pub entry: usize,
    /// Its name fields, resolved (without what `ends` and `label_of` hold).
    names: Names,
    /// A family member's `between` or `on` by index ([`Expander::member_ends`]): the names
    /// `P[4]` are made only for a member that is built (a deferred member needs its
    /// particles, found by index: [`Indices::particle_of`]).
    ends: Option<MemberEnds>,
    /// A family member named by its family and indices, `spring[i=3]`: the family and the
    /// span of the name (or of the entry), the label made when the member is built.
    label_of: Option<(Rc<str>, Range<usize>)>,
}

/// A force member's ends by index, with the spans of the names that name them.
#[derive(Clone, Debug)]
pub(crate) enum MemberEnds {
    /// `between = ["P[i+1]", "P[i]"]`: the list's span and each end.
    Between(Range<usize>, [(MemberRef, Range<usize>); 2]),
    /// `on = "P[i]"`.
    On(MemberRef, Range<usize>),
}

/// One end of a force as its entry names it: by name, or a member by index.
#[derive(Clone, Copy, Debug)]
pub(crate) enum End<'a> {
    Name(&'a str),
    Member(&'a MemberRef),
}

impl ForceEntry {
    /// An entry whose name fields are all resolved to text.
    fn written(entry: usize, names: Names) -> ForceEntry {
        ForceEntry {
            entry,
            names,
            ends: None,
            label_of: None,
        }
    }

    /// The name fields resolved to text: a member's with its `bindings` (the indices it was
    /// expanded with, in its family's order).
    pub fn names(&self, bindings: &[(String, i64)]) -> Names {
        let mut n = self.names.clone();
        if let Some((base, span)) = &self.label_of {
            n.name = Some(Spanned::new(span.clone(), label(base, bindings)));
        }
        match &self.ends {
            None => {}
            Some(MemberEnds::Between(span, ends)) => {
                let names = ends
                    .iter()
                    .map(|(r, s)| Spanned::new(s.clone(), r.name()))
                    .collect();
                n.between = Some(Spanned::new(span.clone(), names));
            }
            Some(MemberEnds::On(r, s)) => n.on = Some(Spanned::new(s.clone(), r.name())),
        }
        n
    }

    /// The ends its `between` (when it has no `on`) or its `on` (when it has no `between`)
    /// names, at most two; `None` for any other entry. Nothing is made for a member's ends.
    pub fn ends(&self) -> Option<([End<'_>; 2], usize)> {
        let none = End::Name("");
        match &self.ends {
            Some(MemberEnds::Between(_, [a, b])) => {
                Some(([End::Member(&a.0), End::Member(&b.0)], 2))
            }
            Some(MemberEnds::On(r, _)) => Some(([End::Member(r), none], 1)),
            None => match (&self.names.between, &self.names.on) {
                (Some(b), None) => match b.get_ref().as_slice() {
                    [a] => Some(([End::Name(a.get_ref()), none], 1)),
                    [a, c] => Some(([End::Name(a.get_ref()), End::Name(c.get_ref())], 2)),
                    _ => None,
                },
                (None, Some(on)) => Some(([End::Name(on.get_ref()), none], 1)),
                _ => None,
            },
        }
    }

    /// The entry as an ordinary `[[forces]]` entry (`forces`: the file's; `bindings`: the
    /// member's indices, as for [`ForceEntry::names`]).
    pub fn raw(
        &self,
        forces: &[Spanned<RawForce>],
        bindings: &[(String, i64)],
    ) -> Spanned<RawForce> {
        let f = &forces[self.entry];
        let mut m = f.get_ref().clone();
        m.for_list = None;
        m.condition = None;
        let n = self.names(bindings);
        m.name = n.name;
        m.on = n.on;
        m.to = n.to;
        m.normal_force = n.normal_force;
        m.friction_force = n.friction_force;
        m.between = n.between;
        Spanned::new(f.span(), m)
    }
}

/// `err` as met while reading member `label`.
pub(crate) fn in_member(mut err: ModelError, label: &str) -> ModelError {
    if !err.message.starts_with(label) {
        err.message = format!("{label}: {}", err.message);
    }
    err
}

/// Splits `for` and `where` out of a table value (`{ initial = ..., where = ... }`), with
/// `main` naming the field that holds a point's or definition's value in table form.
fn split_table(
    ld: &Loader,
    v: &Sv,
    main: Option<&str>,
) -> Result<(Sv, Option<Sv>, Option<Sv>), ModelError> {
    let toml::Value::Table(t) = v.get_ref() else {
        return Ok((v.clone(), None, None));
    };
    let mut t = t.clone();
    // The values inside an inline table carry no spans: errors point at the whole table.
    let take = |t: &mut toml::Table, key: &str| t.remove(key).map(|x| Spanned::new(v.span(), x));
    let for_list = take(&mut t, "for");
    let condition = take(&mut t, "where");
    let value = match main {
        Some(key) if t.len() == 1 && t.contains_key(key) => Spanned::new(
            v.span(),
            t.remove(key).unwrap_or(toml::Value::Boolean(false)),
        ),
        Some(key) => {
            return Err(ld
                .err(
                    v.span(),
                    format!("a table here holds `{key}` and optionally `for` and `where`"),
                )
                .help(format!("{{ {key} = \"...\", where = \"i > 0\" }}")))
        }
        None => Spanned::new(v.span(), toml::Value::Table(t)),
    };
    Ok((value, for_list, condition))
}

/// Reads `[indices]` into the loader's scope and replaces every family in `raw` by its
/// members.
pub(crate) fn expand(
    ld: &mut Loader,
    mut raw: RawModel,
) -> Result<(RawModel, Members), ModelError> {
    let tables = ld.read_row_tables(&raw)?;
    let mut indices = read_indices(ld, &raw)?;
    for (k, t) in tables.into_iter().enumerate() {
        for (c, column) in t.column_names().iter().enumerate() {
            indices
                .columns
                .insert(format!("{}_{column}", t.name), (k, c));
        }
        indices.sizes.insert(t.name.clone(), t.len() as i64);
        indices.tables.push(Rc::new(t));
    }
    if indices.ranges.is_empty() && indices.sizes.is_empty() && !mentions_families(&raw) {
        let members = Members {
            coordinates: vec![None; raw.coordinates.len()],
            definitions: vec![None; raw.definitions.len()],
            points: vec![None; raw.points.len()],
            particles: vec![None; raw.particles.len()],
            forces: vec![None; raw.forces.len()],
            force_entries: raw
                .forces
                .iter()
                .enumerate()
                .map(|(entry, f)| {
                    let r = f.get_ref();
                    ForceEntry::written(
                        entry,
                        Names {
                            name: r.name.clone(),
                            on: r.on.clone(),
                            to: r.to.clone(),
                            normal_force: r.normal_force.clone(),
                            friction_force: r.friction_force.clone(),
                            between: r.between.clone(),
                        },
                    )
                })
                .collect(),
        };
        return Ok((raw, members));
    }
    let mut ex = Expander {
        ld,
        indices,
        members: 0,
    };
    let sv_span = |v: &Sv| v.span();
    let mut shared = SharedValues::default();
    let mut particles_by_index = FxHashMap::default();
    let (coordinates, mc) = ex.keyed(
        std::mem::take(&mut raw.coordinates),
        &mut shared.coordinates,
        sv_span,
        |ex, v| split_table(ex.ld, v, None),
        placeholder_value,
        &mut FxHashMap::default(),
    )?;
    let (points, mp) = ex.keyed(
        std::mem::take(&mut raw.points),
        &mut shared.points,
        sv_span,
        |ex, v| split_table(ex.ld, v, Some("position")),
        placeholder_value,
        &mut FxHashMap::default(),
    )?;
    let (definitions, md) = ex.keyed(
        std::mem::take(&mut raw.definitions),
        &mut shared.definitions,
        sv_span,
        |ex, v| split_table(ex.ld, v, Some("value")),
        placeholder_value,
        &mut FxHashMap::default(),
    )?;
    let (particles, mq) = ex.keyed(
        std::mem::take(&mut raw.particles),
        &mut shared.particles,
        |p: &Spanned<RawParticle>| p.span(),
        |_, p| {
            let mut q = p.get_ref().clone();
            let for_list = q.for_list.take();
            let condition = q.condition.take();
            Ok((Spanned::new(p.span(), q), for_list, condition))
        },
        placeholder_particle,
        &mut particles_by_index,
    )?;
    ex.indices.particles = particles_by_index;
    raw.shared = shared;
    let (force_entries, mf) = ex.forces(&raw.forces)?;
    raw.coordinates = coordinates;
    raw.points = points;
    raw.definitions = definitions;
    raw.particles = particles;
    let indices = ex.indices;
    ld.scope.indices = indices;
    Ok((
        raw,
        Members {
            coordinates: mc,
            definitions: md,
            points: mp,
            particles: mq,
            forces: mf,
            force_entries,
        },
    ))
}

/// Whether any entry is written with a subscript or `for`/`where` (a file without
/// `[indices]` is then still expanded, to report what is missing).
fn mentions_families(raw: &RawModel) -> bool {
    let keyed = |k: &Name| k.get_ref().contains('[');
    raw.coordinates.keys().any(keyed)
        || raw.points.keys().any(keyed)
        || raw.definitions.keys().any(keyed)
        || raw.particles.keys().any(keyed)
        || raw
            .forces
            .iter()
            .any(|f| f.get_ref().for_list.is_some() || f.get_ref().condition.is_some())
        || raw
            .particles
            .values()
            .any(|p| p.get_ref().for_list.is_some() || p.get_ref().condition.is_some())
}

/// `[indices]`: sizes (integers) and index ranges (`"0..n-1"`), in order, each range using
/// the sizes above it.
fn read_indices(ld: &mut Loader, raw: &RawModel) -> Result<Indices, ModelError> {
    let mut indices = Indices::default();
    for (name, sv) in &raw.indices {
        let n = name.get_ref();
        match sv.get_ref() {
            toml::Value::Integer(v) => {
                let value = pdyn_expr::Value::Scalar(ld.pool.int(*v));
                ld.declare(n, name.span(), "size", pdyn_expr::lower::Binding::Value(value))?;
                ld.dims.bind(n, pdyn_expr::Dimension::NONE.into());
                indices.sizes.insert(n.clone(), *v);
            }
            toml::Value::String(text) => {
                let r = index_expr::parse_range(text).map_err(|e| located(ld, &sv.span(), e))?;
                let (lo, hi) = {
                    let lookup = indices.lookup(&[], &[]);
                    let lo = r.lo.int(&lookup).map_err(|e| located(ld, &sv.span(), e))?;
                    let hi = r.hi.int(&lookup).map_err(|e| located(ld, &sv.span(), e))?;
                    (lo, hi)
                };
                if hi < lo {
                    return Err(ld
                        .err(sv.span(), format!("index `{n}` has an empty range {lo}..{hi}"))
                        .help("a range first..last includes both ends and needs first <= last"));
                }
                if indices.sizes.contains_key(n) || indices.ranges.contains_key(n) {
                    return Err(ld.err(name.span(), format!("`{n}` is declared twice in [indices]")));
                }
                ld.reserve_index_name(n, name.span())?;
                indices.ranges.insert(n.clone(), (lo, hi));
            }
            other => {
                return Err(ld
                    .err(sv.span(), format!("an entry of [indices] is a size (an integer) or a range (\"0..n-1\"), not a {}", other.type_str()))
                    .help("n = 20 declares a size; i = \"0..n-1\" an index running from 0 to n-1"))
            }
        }
    }
    Ok(indices)
}

#[cfg(test)]
mod tests {
    #[test]
    fn names_print_their_indices_as_format_does() {
        for v in [0, 7, -7, 10, 99, -100, 123_456, i64::MAX, i64::MIN] {
            assert_eq!(super::member("P", &[v, 3]), format!("P[{v},3]"));
        }
        assert_eq!(
            super::label("spring", &[("i".into(), -3), ("j".into(), 19)]),
            "spring[i=-3, j=19]"
        );
    }
}
