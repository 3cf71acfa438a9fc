//! Tabulated functions: a measured column (a model's `[data.NAME]` table) as a function of
//! one argument inside expressions.
//!
//! The pool knows a tabulated function by name and holds it as a [`Tabulated`] object (the
//! interpolant lives in the crate that reads the data: pdyn-expr only calls it). In an
//! expression it is the call `Func::Table(TableFn { table, order })`: the interpolant's
//! derivative of order `order` at its argument, so that differentiation is the chain rule
//! (`d/dx f(u) = f'(u) u'`) and compiled programs call the object
//! ([`crate::compile::Op::Table`]).
//!
//! Evaluation outside the data's range is the [`Tabulated`] object's business: it returns
//! NaN there and remembers the argument, for the caller to report (a run leaving the data).

use crate::pool::{Func, Id, Pool};
use std::sync::Arc;

/// A function of one real argument known from samples.
pub trait Tabulated: Send + Sync + std::fmt::Debug {
    /// The derivative of order `order` (0: the value) at `x`; NaN outside the range.
    fn eval(&self, order: u8, x: f64) -> f64;
    /// The highest derivative order that is not identically zero between the samples (1 for
    /// linear interpolation: its derivative is piecewise constant, the second is zero; 3 for
    /// cubic pieces).
    fn degree(&self) -> u8;
    /// The object itself, for callers that know its concrete type (a model's data columns
    /// report a run that left their range).
    fn as_any(&self) -> &dyn std::any::Any;
}

/// Which tabulated function and which of its derivatives: the function of a
/// [`Func::Table`] call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TableFn {
    /// The function's index in its pool ([`Pool::table`]).
    pub table: u32,
    /// The derivative order: 0 for the value.
    pub order: u8,
}

/// A tabulated function registered in a pool.
#[derive(Clone, Debug)]
pub struct TableEntry {
    /// The name it is called by in expressions.
    pub name: String,
    /// Its samples and interpolant.
    pub function: Arc<dyn Tabulated>,
}

/// A tabulated function's name is already taken in this pool.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TableNameTaken(pub String);

impl std::fmt::Display for TableNameTaken {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "a function named `{}` exists already", self.0)
    }
}

impl std::error::Error for TableNameTaken {}

impl Pool {
    /// Registers `function` under `name`, callable in expressions parsed afterwards as
    /// `name(x)`. A built-in function's name or a name registered before is refused.
    pub fn add_table(
        &mut self,
        name: &str,
        function: Arc<dyn Tabulated>,
    ) -> Result<u32, TableNameTaken> {
        if Func::from_name(name).is_some()
            || crate::lower::VECTOR_FUNCS.contains(&name)
            || name == "sqrt"
            || self.table_named(name).is_some()
        {
            return Err(TableNameTaken(name.to_string()));
        }
        self.tables.push(TableEntry {
            name: name.to_string(),
            function,
        });
        Ok((self.tables.len() - 1) as u32)
    }

    /// The tabulated function called `name`, if one is registered.
    pub fn table_named(&self, name: &str) -> Option<u32> {
        self.tables
            .iter()
            .position(|t| t.name == name)
            .map(|i| i as u32)
    }

    /// The tabulated function `table` (an index [`Pool::add_table`] returned).
    ///
    /// # Panics
    /// If `table` was not returned by this pool's [`Pool::add_table`].
    pub fn table(&self, table: u32) -> &TableEntry {
        &self.tables[table as usize]
    }

    /// Every registered tabulated function, in registration order.
    pub fn tables(&self) -> &[TableEntry] {
        &self.tables
    }

    /// `f^(order)(x)` for the tabulated function `table`; zero past its degree.
    pub fn tabulated(&mut self, table: u32, order: u8, x: Id) -> Id {
        if order > self.table(table).function.degree() {
            return Pool::ZERO;
        }
        self.call(Func::Table(TableFn { table, order }), &[x])
    }

    /// The name a [`Func::Table`] call prints with: the function's name with a prime per
    /// derivative (`ground_a'`).
    pub fn table_fn_name(&self, f: TableFn) -> String {
        format!(
            "{}{}",
            self.table(f.table).name,
            "'".repeat(f.order as usize)
        )
    }
}
