//! Sparse direct factorization for the systems of many particles (issue 33), below every
//! crate that solves with it: pdyn-mech's statics (damped Newton's steps on `K + μD`) and
//! pdyn-ode's Radau5 (its iteration matrices `c·I − J`). One ordering and one factorization
//! serve both; this crate knows nothing of models, symbols or integrators.
//!
//! | file | what |
//! |---|---|
//! | `ordering.rs` | nested dissection by breadth-first level structures: the fill-reducing order |
//! | `sparse_lu.rs` | sparse real/complex LU on a known pattern, with a symmetric mode (`SparseLu::factor_symmetric`: half the work, and about half the factors' memory): rows of the shape `q' = v` eliminated first (`sparse_lu/reduce.rs`), the rest supernodal multifrontal with dense kernels (`sparse_lu/{supernodal,multifrontal,scalar}.rs`), no pivoting |

// As in pdyn-ode, where this code came from: index loops over several parallel arrays read
// as the algorithms are written (Davis, George & Liu).
#![allow(clippy::needless_range_loop)]

pub mod ordering;
pub mod sparse_lu;
