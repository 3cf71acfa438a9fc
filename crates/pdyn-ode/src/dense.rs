//! The dense output of a whole solve ([`DenseSolution`]): every accepted step's own
//! interpolant, recorded when [`crate::Options::dense_output`] is set.
//!
//! Each method's continuous extension is kept at the method's order (the same code evaluates
//! it during the solve, for `t_eval` and events, so that `sol.eval(t)` at an output time gives
//! the output's bits):
//!
//! | method | interpolant | order |
//! |---|---|---|
//! | DOPRI5 | Shampine's (dopri5.f `CONTD5`) | 4 |
//! | Tsit5 | Tsitouras's `b_i(θ)` | 4 |
//! | DOP853 | Hairer's (dop853.f `CONTD8`, three extra stages) | 7 |
//! | RK23 | Bogacki–Shampine's free interpolant (cubic Hermite) | 3 |
//! | Radau5 | the collocation polynomial (radau5.f `CONTR5`) | 3 |
//! | BDF | the interpolating polynomial through the last `k + 1` points (SciPy's `BdfDenseOutput`) | the step's order `k` (1–5) |
//! | Vern9, fixed-step methods | cubic Hermite through the step's ends | 3 |
//!
//! Storage: one block of coefficients per step (`5n` doubles for DOPRI5, `8n` for DOP853, `8n`
//! for Tsit5, `(k + 1)n` for BDF of order `k`, `4n` otherwise), plus the step's bounds.

/// The interpolant of one recorded step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Interpolant {
    /// DOPRI5's 4th-order continuous extension (5 coefficient vectors).
    Dopri5,
    /// Tsit5's: `y0` then the 7 stages.
    Tsit5,
    /// DOP853's 7th-order continuous extension (8 coefficient vectors).
    Dop853,
    /// Cubic Hermite: `y0, f0, y1, f1` (Vern9, RK23, fixed-step methods).
    Hermite,
    /// Radau5's collocation polynomial (4 vectors), `s = (t − t_ref)/h` with `t_ref` the end
    /// of the step; its constants `c1 − 1`, `c2 − 1`.
    Radau5 {
        /// `c1 − 1`.
        c1m1: f64,
        /// `c2 − 1`.
        c2m1: f64,
    },
    /// BDF's interpolating polynomial of the step's order (`order + 1` backward differences),
    /// `s = (t − t_ref)/h` with `t_ref` the end of the step.
    Bdf {
        /// The order (1–5).
        order: u8,
    },
}

#[derive(Debug, Clone, PartialEq)]
struct Piece {
    kind: Interpolant,
    t_ref: f64,
    h: f64,
    offset: usize,
}

/// The dense output of a solve: the interpolant of every accepted step, evaluated by
/// [`DenseSolution::eval`] anywhere in the integration interval (clamped to the first or last
/// step outside it, as SciPy's `OdeSolution` extrapolates).
#[derive(Debug, Clone, PartialEq)]
pub struct DenseSolution {
    n: usize,
    /// Step boundaries: step `k` covers `[bounds[k], bounds[k + 1]]`.
    bounds: Vec<f64>,
    pieces: Vec<Piece>,
    data: Vec<f64>,
}

impl DenseSolution {
    /// An empty record for a system of dimension `n`.
    pub fn new(n: usize) -> Self {
        DenseSolution {
            n,
            bounds: Vec::new(),
            pieces: Vec::new(),
            data: Vec::new(),
        }
    }

    /// Records the step `[t_from, t_to]` whose interpolant is `kind` with reference time
    /// `t_ref` and step `h`, its coefficient vectors `parts` (concatenated).
    pub(crate) fn push(
        &mut self,
        t_from: f64,
        t_to: f64,
        kind: Interpolant,
        t_ref: f64,
        h: f64,
        parts: &[&[f64]],
    ) {
        if self.bounds.is_empty() {
            self.bounds.push(t_from);
        }
        self.bounds.push(t_to);
        let offset = self.data.len();
        for p in parts {
            self.data.extend_from_slice(p);
        }
        self.pieces.push(Piece {
            kind,
            t_ref,
            h,
            offset,
        });
    }

    /// Appends the steps of `other` (a solve that continued this one).
    pub(crate) fn append(&mut self, other: &DenseSolution) {
        if other.pieces.is_empty() {
            return;
        }
        if self.bounds.is_empty() {
            self.bounds.push(other.bounds[0]);
        }
        let shift = self.data.len();
        self.bounds.extend_from_slice(&other.bounds[1..]);
        self.pieces.extend(other.pieces.iter().map(|p| Piece {
            offset: p.offset + shift,
            ..p.clone()
        }));
        self.data.extend_from_slice(&other.data);
    }

    /// Number of recorded steps.
    pub fn len(&self) -> usize {
        self.pieces.len()
    }

    /// `true` when no step was recorded.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// The step boundaries (`len() + 1` times, in the direction of integration).
    pub fn steps(&self) -> &[f64] {
        &self.bounds
    }

    /// The interpolant of step `k`.
    pub fn interpolant(&self, k: usize) -> Interpolant {
        self.pieces[k].kind
    }

    /// Doubles of coefficients stored per step for `kind` and dimension `n`.
    pub fn doubles_per_step(kind: Interpolant, n: usize) -> usize {
        match kind {
            Interpolant::Dopri5 => 5 * n,
            Interpolant::Tsit5 | Interpolant::Dop853 => 8 * n,
            Interpolant::Hermite | Interpolant::Radau5 { .. } => 4 * n,
            Interpolant::Bdf { order } => (usize::from(order) + 1) * n,
        }
    }

    /// The step holding `t`: the last step whose start is not past `t` (the first step
    /// before the interval, the last one after it).
    fn find(&self, t: f64) -> usize {
        let m = self.pieces.len();
        let b = &self.bounds;
        let forward = b[m] >= b[0];
        // Index of the first boundary strictly past t (in the direction of integration).
        let k = if forward {
            b.partition_point(|&x| x <= t)
        } else {
            b.partition_point(|&x| x >= t)
        };
        k.saturating_sub(1).min(m - 1)
    }

    /// Writes the state at `t` into `out` (length `n`). Panics when nothing was recorded.
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        assert!(!self.pieces.is_empty(), "no step recorded");
        let p = &self.pieces[self.find(t)];
        let n = self.n;
        let c = &self.data[p.offset..p.offset + Self::doubles_per_step(p.kind, n)];
        let s = (t - p.t_ref) / p.h;
        match p.kind {
            Interpolant::Dopri5 => crate::methods::dopri5::eval_cont(c, n, s, out),
            Interpolant::Tsit5 => crate::methods::tsit5::eval_cont(c, n, s, p.h, out),
            Interpolant::Dop853 => crate::methods::dop853::eval_cont::<0>(c, n, s, out),
            Interpolant::Hermite => hermite(c, n, s, p.h, out),
            Interpolant::Radau5 { c1m1, c2m1 } => {
                crate::methods::radau5::eval_cont(c, n, s, c1m1, c2m1, out)
            }
            Interpolant::Bdf { order } => {
                crate::methods::bdf::eval_cont(c, n, usize::from(order), s, out)
            }
        }
    }
}

/// The cubic Hermite interpolant through `(y0, f0)` and `(y1, f1)` (`b = [y0, f0, y1, f1]`) at
/// `s = (t − t0)/h`.
#[inline]
pub(crate) fn hermite(b: &[f64], n: usize, s: f64, h: f64, out: &mut [f64]) {
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = (s3 - 2.0 * s2 + s) * h;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = (s3 - s2) * h;
    for i in 0..n {
        out[i] = h00 * b[i] + h10 * b[n + i] + h01 * b[2 * n + i] + h11 * b[3 * n + i];
    }
}
