//! # pdyn-expr — the symbolic expression engine of pdyn
//!
//! Everything pdyn derives (velocities, accelerations, equations of motion, reactions,
//! Jacobians) is built here, in a [`Pool`] of hash-consed expression nodes:
//!
//! - [`syntax`] parses the expression language (`R*cos(th)`, `x''`, `[x, y, 0]`,
//!   `dot(a, b)`) into a spanned AST; [`lower`] resolves names and checks shapes;
//! - [`build`] holds the canonicalising constructors (automatic simplification);
//! - [`diff`] differentiates (partial, and total in time by the chain rule);
//! - [`expand`] distributes products and integer powers; [`factor`] collects and factors
//!   sums for reading (`a*x + b*x = (a + b)*x`);
//! - [`poly`] and [`simplify`] work on rational functions over "atoms" (the Pythagorean
//!   identity, trigonometric expansion, polynomial GCD cancellation);
//! - [`linsolve`] extracts `A x = b` from equations linear in chosen unknowns and solves it,
//!   symbolically (fraction-free elimination) or numerically via [`lu`];
//! - [`units`] reads unit literals (`25 mph`, `2*pi/(120 s)`) with their [`dimension`]s;
//! - [`print`] writes text (re-parsable), LaTeX and Rust;
//! - [`compile`] turns a set of expressions into one flat, allocation-free program.
//!
//! ```
//! use pdyn_expr::Pool;
//! let mut p = Pool::new();
//! let x = p.parse_scalar("R*cos(th(t))").unwrap();
//! let a = p.dt_n(x, 2);
//! assert_eq!(p.to_text(a), "-R*th'^2*cos(th) - R*th''*sin(th)");
//! ```
#![warn(missing_docs)]

pub mod budget;
pub mod build;
pub mod compile;
mod constant;
pub mod diff;
pub mod dimension;
pub mod error;
pub mod expand;
pub mod factor;
pub mod hoist;
pub mod linsolve;
pub mod lower;
pub mod lu;
mod memo;
pub mod number;
pub mod poly;
pub mod pool;
pub mod print;
pub mod simplify;
mod sincos;
pub mod sincos_many;
pub mod subs;
pub mod syntax;
pub mod tabulated;
pub mod units;
pub mod vector;

pub use budget::BudgetError;
pub use compile::Program;
pub use dimension::Dimension;
pub use error::ExprError;
pub use lower::{Binding, FreeScope, Scope, Value};
pub use number::{Number, Rational};
pub use pool::{Constant, Func, Id, Node, Pool, SymId};
pub use sincos_many::sincos_many;
pub use tabulated::{TableFn, Tabulated};
