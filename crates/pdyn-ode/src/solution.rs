//! The result of a solve: output times and states, statistics, events.

use crate::Method;

/// Work statistics, counted as Hairer's codes count them (see each method's docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Step attempts (Hairer's NSTEP: accepted, rejected, and for Radau5 also the attempts
    /// abandoned because Newton failed).
    pub steps: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Steps rejected by the error test, counted as Hairer's codes count them (NREJCT):
    /// rejections before the first accepted step are not included (they are in `steps`).
    pub rejected: usize,
    /// Evaluations of `f` (including those for finite-difference Jacobians, which Hairer's
    /// RADAU5 does *not* count in NFCN: see [`Stats::jac_fevals`]).
    pub fevals: usize,
    /// Evaluations of `f` spent on finite-difference Jacobians (included in `fevals`).
    pub jac_fevals: usize,
    /// Jacobian evaluations (analytic or finite-difference).
    pub jacobians: usize,
    /// LU factorizations (Radau5 counts one per real+complex pair, as RADAU5 does).
    pub lu_decompositions: usize,
    /// Linear solves (Radau5 counts one per real+complex pair, as RADAU5 does).
    pub linear_solves: usize,
    /// Accepted step at which the explicit method's stiffness detector fired, if it did.
    pub stiffness_detected_at: Option<f64>,
    /// Whether the implicit method factored its iteration matrices as sparse matrices
    /// ([`crate::LinearSolver`]).
    pub sparse_lu: bool,
}

impl Stats {
    /// Adds the counts of another solve (a method switch, a restart after an event); the
    /// first stiffness detection is kept.
    pub fn add(&mut self, other: &Stats) {
        self.steps += other.steps;
        self.accepted += other.accepted;
        self.rejected += other.rejected;
        self.fevals += other.fevals;
        self.jac_fevals += other.jac_fevals;
        self.jacobians += other.jacobians;
        self.lu_decompositions += other.lu_decompositions;
        self.linear_solves += other.linear_solves;
        self.sparse_lu |= other.sparse_lu;
        if self.stiffness_detected_at.is_none() {
            self.stiffness_detected_at = other.stiffness_detected_at;
        }
    }
}

/// Direction of a zero crossing of an event function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// `g` goes from negative to positive.
    Rising,
    /// `g` goes from positive to negative.
    Falling,
    /// Either.
    Both,
}

/// One located zero of an event function.
#[derive(Debug, Clone, PartialEq)]
pub struct EventHit {
    /// Index of the event in the slice passed to the solver.
    pub index: usize,
    /// Time of the zero.
    pub t: f64,
    /// State at `t` (from the method's dense output).
    pub y: Vec<f64>,
    /// Whether `g` was rising or falling through zero.
    pub direction: Direction,
}

/// Why the integration stopped (successfully).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Reached `tf`.
    Finished,
    /// A terminal event stopped the integration; its index.
    TerminalEvent(usize),
}

/// An interval in which event `index` may have crossed zero twice unseen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PossibleMiss {
    /// Index of the event function.
    pub index: usize,
    /// Start of the interval.
    pub t_from: f64,
    /// End of the interval.
    pub t_to: f64,
}

/// Output of a solve. States are stored flat: `y[k*n..(k+1)*n]` belongs to `t[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Method that produced the solution (for `Auto`, the last one used).
    pub method: Method,
    /// System dimension.
    pub n: usize,
    /// Output times.
    pub t: Vec<f64>,
    /// Output states, flat (`n` values per output time).
    pub y: Vec<f64>,
    /// Located events in time order.
    pub events: Vec<EventHit>,
    /// Intervals where an event function came back from (nearly) crossing zero between two
    /// evaluations, and sampling did not settle it: a pair of crossings may have been missed.
    pub possible_misses: Vec<PossibleMiss>,
    /// Work statistics.
    pub stats: Stats,
    /// How the integration ended.
    pub status: Status,
    /// Every accepted step's interpolant, when [`crate::Options::dense_output`] is set.
    pub dense: Option<crate::DenseSolution>,
}

impl Solution {
    pub(crate) fn new(method: Method, n: usize) -> Self {
        Solution {
            method,
            n,
            t: Vec::new(),
            y: Vec::new(),
            events: Vec::new(),
            possible_misses: Vec::new(),
            stats: Stats::default(),
            status: Status::Finished,
            dense: None,
        }
    }

    pub(crate) fn push(&mut self, t: f64, y: &[f64]) {
        self.t.push(t);
        self.y.extend_from_slice(y);
    }

    /// Number of output points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// `true` when there is no output point.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// State at output `k` (panics if `k >= self.len()`, like slice indexing).
    pub fn y_at(&self, k: usize) -> &[f64] {
        &self.y[k * self.n..(k + 1) * self.n]
    }

    /// Last output time and state, if any.
    pub fn last(&self) -> Option<(f64, &[f64])> {
        let k = self.t.len().checked_sub(1)?;
        Some((self.t[k], self.y_at(k)))
    }
}
