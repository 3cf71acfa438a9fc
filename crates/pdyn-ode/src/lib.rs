//! Integrators for ordinary differential equations (work in progress: see issue 3).
#![warn(missing_docs)]
