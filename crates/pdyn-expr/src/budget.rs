//! Limits on symbolic work, and the typed error when one is reached.
//!
//! Symbolic algorithms can blow up on small inputs: `(a+b+c+d)^40` has 12,341 terms, the
//! hundredth derivative of `exp(x^2)` thousands of nodes, `x^100000` differentiated 100,000
//! times coefficients of half a million digits. Each such algorithm counts its work and stops
//! with a [`BudgetError`] that says what ran out and what to do instead, so that no input
//! makes pdyn hang. The limits are constants here, one place to read and tune them.

use std::fmt;

/// Most terms in one sum produced by [`Pool::try_expand`](crate::Pool::try_expand).
pub const MAX_EXPAND_TERMS: usize = 5_000;
/// Most products of two terms formed by one expansion (the work, counted before collecting
/// like terms).
pub const MAX_EXPAND_PRODUCTS: usize = 200_000;
/// Most new expression nodes created by
/// [`Pool::try_derivative_n`](crate::Pool::try_derivative_n).
pub const MAX_DERIVATIVE_NODES: usize = 100_000;
/// Most term views built plus pairs of views compared by one
/// [`Pool::contract_trig`](crate::Pool::contract_trig).
pub const MAX_CONTRACT_WORK: usize = 1_000_000;

/// A symbolic operation would exceed its limit.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum BudgetError {
    /// Expanding would produce a sum of more than `limit` terms, or form more than
    /// [`MAX_EXPAND_PRODUCTS`] products of terms.
    ExpandTerms {
        /// The limit that was reached.
        limit: usize,
    },
    /// The derivatives up to `order` needed more than `limit` new expression nodes.
    DerivativeSize {
        /// The derivative being computed when the limit was reached (1 = first).
        order: usize,
        /// The limit on new nodes.
        limit: usize,
    },
    /// Contracting products of sines and cosines into angle sums needed more than `limit`
    /// comparisons.
    Contract {
        /// The limit on views and comparisons.
        limit: usize,
    },
    /// A coefficient of the `order`-th derivative exceeded the size of exact numbers.
    DerivativeNumbers {
        /// The derivative being computed when the limit was reached.
        order: usize,
    },
    /// A time derivative would give a coordinate of order above [`MAX_COORD_ORDER`]
    /// (`x` with 256 primes).
    CoordinateOrder {
        /// The order the derivative would need.
        order: usize,
    },
}

/// Highest order of a coordinate's time derivative an expression can hold (`x` followed by
/// 255 primes): the order is stored in a byte. Past it is an error, never a saturated order.
pub const MAX_COORD_ORDER: usize = u8::MAX as usize;

impl fmt::Display for BudgetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BudgetError::ExpandTerms { limit } => write!(
                f,
                "expanding would produce more than {limit} terms: keep the expression \
                 factored (simplify without --expand), or evaluate it numerically"
            ),
            BudgetError::DerivativeSize { order, limit } => write!(
                f,
                "the derivatives up to order {order} need more than {limit} expression \
                 nodes: differentiate fewer times, or evaluate the derivative numerically (finite differences, \
                 or integrate the equations numerically with `pdyn run`)"
            ),
            BudgetError::Contract { limit } => write!(
                f,
                "contracting sines and cosines into angle sums needed more than {limit} \
                 comparisons: the expression is left expanded (it is equal); simplify a \
                 smaller part, or evaluate numerically"
            ),
            BudgetError::DerivativeNumbers { order } => write!(
                f,
                "derivative {order} has coefficients over the limit of {} digits for exact \
                 numbers: differentiate fewer times, or evaluate numerically",
                crate::number::MAX_DIGITS
            ),
            BudgetError::CoordinateOrder { order } => write!(
                f,
                "this needs a coordinate's time derivative of order {order}, over the limit of \
                 {MAX_COORD_ORDER}: differentiate fewer times"
            ),
        }
    }
}

impl std::error::Error for BudgetError {}

/// Longest expression, in characters, that pdyn prints for a person to read (`pdyn derive`'s
/// lines, messages that quote an expression): past it the text names what is omitted and its
/// size instead ([`Pool::to_text_within`](crate::Pool::to_text_within)); `--json` output has
/// every expression whole.
pub const PRINT_CHARS: usize = 2_000;
/// Longest expression a message quotes inline (`its coefficient `cos(x)` depends on …`):
/// past it the message names the expression and gives its size (`its coefficient, 1012
/// characters, …`), which is what a reader can use in a sentence; a 1,000-character
/// coefficient quoted whole buries the reason it was given for.
pub const QUOTE_CHARS: usize = 120;
/// Expressions of more tree nodes than this are not even formatted: formatting the 4-link
/// chain's explicit accelerations took seconds, and any expression that prints within
/// [`PRINT_CHARS`] has far fewer nodes.
pub const PRINT_NODES: usize = 4_000;

/// How large an expression too large to print is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrintSize {
    /// More than [`PRINT_NODES`] tree nodes (not formatted).
    Nodes,
    /// This many characters once formatted.
    Chars(usize),
}

impl fmt::Display for PrintSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PrintSize::Nodes => write!(f, "over {PRINT_NODES} expression nodes"),
            PrintSize::Chars(n) => write!(f, "{n} characters"),
        }
    }
}
