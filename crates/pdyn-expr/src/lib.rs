//! Symbolic expression engine (work in progress: see issue 2).
#![warn(missing_docs)]
