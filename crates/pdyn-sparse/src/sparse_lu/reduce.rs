//! Kinematic rows eliminated before the sparse factorization: the Schur complement of the
//! rows that say `y_i' = a · y_p` and nothing else.
//!
//! A mechanical system in first-order form, `y = (q, v)`, has `q' = v`: its Jacobian is
//! `[[0, I], [K, C]]`, and its iteration matrix `c·I − J` has, in each row of `q`, the
//! diagonal `c` and one entry `−1` in the column of the matching `v`. Eliminating those rows
//! first costs nothing (each pivot row has one entry beside its diagonal) and leaves the
//! Schur complement on `v` alone, `c·I − C − K/c` with `K`'s pattern: half the dimension, an
//! eighth of the dense blocks' work. This is recognised from the pattern, for any system:
//! row `i` is *kinematic* when it has exactly one entry besides its diagonal, in a column `p`
//! whose own row is not of that shape (so that `y_p` stays an unknown of the reduced system).
//!
//! With `E(i, i) y_i + E(i, p) y_p = b_i` for each kinematic `i`:
//! `y_i = (b_i − E(i, p) y_p) / E(i, i)`, and every other row `r` becomes
//! `Σ_s S(r, s) y_s = b_r − Σ_i E(r, i) b_i / E(i, i)` with
//! `S(r, s) = E(r, s) − Σ_{i: p(i) = s} E(r, i) E(i, p) / E(i, i)`.

use super::scalar::Scalar;
use super::Pattern;

/// The kinematic rows of a pattern and the pattern of the reduced matrix `S`.
#[derive(Debug)]
pub(crate) struct Reduction {
    /// The kinematic rows: `(i, value index of E(i, i), value index of E(i, p), p as an
    /// unknown of S)`.
    pub kin: Vec<(usize, usize, usize, usize)>,
    /// The original index of each unknown of `S`.
    pub orig: Vec<usize>,
    /// The pattern of `S` (indices of `S`'s unknowns), with every diagonal.
    pub s: Pattern,
    /// `S`'s entries taken from `E`: `(entry of S, value index in E)`.
    direct: Vec<(usize, usize)>,
    /// `S`'s entries made through a kinematic row: `(entry of S, value index of E(r, i),
    /// kinematic number of i, r as an unknown of S)`.
    through: Vec<(usize, usize, usize, usize)>,
}

impl Reduction {
    /// Finds the kinematic rows of `pattern`, whose row `i` has its diagonal at `diag[i]`.
    pub(crate) fn new(pattern: &Pattern, diag: &[usize]) -> Reduction {
        let n = pattern.dim();
        // The one entry beside the diagonal of each row that has exactly one.
        let single: Vec<Option<usize>> = (0..n)
            .map(|i| {
                let row = pattern.start[i]..pattern.start[i + 1];
                let mut off = row.filter(|&q| pattern.cols[q] != i);
                match (off.next(), off.next()) {
                    (Some(q), None) => Some(q),
                    _ => None,
                }
            })
            .collect();
        let mut kin_of = vec![usize::MAX; n];
        let mut kin = Vec::new();
        for i in 0..n {
            if let Some(q) = single[i] {
                let p = pattern.cols[q];
                if single[p].is_none() {
                    kin_of[i] = kin.len();
                    kin.push((i, diag[i], q, p));
                }
            }
        }
        let mut red = vec![usize::MAX; n];
        let mut orig = Vec::with_capacity(n - kin.len());
        for i in 0..n {
            if kin_of[i] == usize::MAX {
                red[i] = orig.len();
                orig.push(i);
            }
        }
        for k in &mut kin {
            k.3 = red[k.3];
        }
        let m = orig.len();
        let (mut start, mut cols) = (vec![0usize], Vec::new());
        let (mut direct, mut through) = (Vec::new(), Vec::new());
        let mut mark = vec![usize::MAX; m];
        let mut slot = vec![0usize; m];
        let mut row_cols = Vec::new();
        for (r, &ro) in orig.iter().enumerate() {
            // The columns of S's row r: E's own and those reached through kinematic rows.
            let target = |c: usize| -> usize {
                match kin_of[c] {
                    usize::MAX => red[c],
                    k => kin[k].3,
                }
            };
            row_cols.clear();
            for &c in &pattern.cols[pattern.start[ro]..pattern.start[ro + 1]] {
                let s = target(c);
                if mark[s] != r {
                    mark[s] = r;
                    row_cols.push(s);
                }
            }
            row_cols.sort_unstable();
            let base = cols.len();
            for (k, &s) in row_cols.iter().enumerate() {
                slot[s] = base + k;
            }
            cols.extend_from_slice(&row_cols);
            for q in pattern.start[ro]..pattern.start[ro + 1] {
                let c = pattern.cols[q];
                match kin_of[c] {
                    usize::MAX => direct.push((slot[red[c]], q)),
                    k => through.push((slot[kin[k].3], q, k, r)),
                }
            }
            start.push(cols.len());
        }
        Reduction {
            kin,
            orig,
            s: Pattern { start, cols },
            direct,
            through,
        }
    }

    /// The pivots `E(i, i)` and entries `E(i, p)` of the kinematic rows, and `S`'s values;
    /// `Err(i)` when the pivot of kinematic row `i` is negligible against its row.
    pub(crate) fn values<T: Scalar>(
        &self,
        value: &impl Fn(usize) -> T,
        floor: f64,
        piv: &mut [T],
        off: &mut [T],
        through: &mut [T],
        s: &mut [T],
    ) -> Result<(), usize> {
        for (k, &(i, d, q, _)) in self.kin.iter().enumerate() {
            let (a, b) = (value(d), value(q));
            let m = a.magnitude();
            if !(m.is_finite() && m > floor * b.magnitude()) {
                return Err(i);
            }
            piv[k] = a;
            off[k] = b;
        }
        s.fill(T::ZERO);
        for &(e, q) in &self.direct {
            s[e] = s[e] + value(q);
        }
        for (t, &(e, q, k, _)) in self.through.iter().enumerate() {
            let v = value(q);
            through[t] = v;
            s[e] = s[e] - v * (off[k] / piv[k]);
        }
        Ok(())
    }

    /// `b_S = b_r − Σ E(r, i) b_i / E(i, i)` for the unknowns of `S`, into `out`.
    pub(crate) fn reduce_rhs<T: Scalar>(&self, piv: &[T], through: &[T], b: &[T], out: &mut [T]) {
        for (r, &o) in self.orig.iter().enumerate() {
            out[r] = b[o];
        }
        for (t, &(_, _, k, r)) in self.through.iter().enumerate() {
            let i = self.kin[k].0;
            out[r] = out[r] - through[t] * (b[i] / piv[k]);
        }
    }

    /// Given `S`'s solution `ys`, the whole solution: `x_i = (b_i − E(i, p) x_p) / E(i, i)`
    /// for the kinematic rows (`b` is overwritten with `x`).
    pub(crate) fn expand<T: Scalar>(&self, piv: &[T], off: &[T], ys: &[T], b: &mut [T]) {
        for (k, &(i, _, _, p)) in self.kin.iter().enumerate() {
            b[i] = (b[i] - off[k] * ys[p]) / piv[k];
        }
        for (r, &o) in self.orig.iter().enumerate() {
            b[o] = ys[r];
        }
    }

    /// Entries of `S` made through kinematic rows (for sizing the numeric arrays).
    pub(crate) fn through_len(&self) -> usize {
        self.through.len()
    }
}
