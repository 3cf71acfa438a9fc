//! Dense linear solves, in place and allocation-free, for the linear systems `A x = b` that
//! equations of motion leave when they are not eliminated symbolically (mass matrices,
//! reactions, constraints). Solved once per right-hand-side evaluation, so the caller owns
//! every buffer.
//!
//! - LU with partial pivoting, Doolittle elimination `P A = L U` (Golub & Van Loan, *Matrix
//!   Computations*, alg. 3.4.1), for any nonsingular `A`;
//! - Cholesky `A = Uᵀ U` (Golub & Van Loan alg. 4.2.2, outer-product form) for the symmetric matrices
//!   that mass matrices are: half the operations of LU and no pivoting, since a mass matrix is
//!   positive definite. [`DenseSolver`] tries it first on a symmetric system and falls back to
//!   LU when `A` turns out not to be positive definite.

/// `A` was singular (or nearly): no pivot larger than `tolerance * max|A|` in column `pivot`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingularMatrix {
    /// Column (0-based) where elimination found no usable pivot.
    pub pivot: usize,
}

impl std::fmt::Display for SingularMatrix {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "singular matrix (no pivot in column {})", self.pivot)
    }
}

impl std::error::Error for SingularMatrix {}

/// Factorises the row-major `n×n` matrix `a` in place into `L U` (unit lower `L`), recording
/// row swaps in `perm` (length `n`).
pub fn lu_factor_in_place(
    a: &mut [f64],
    n: usize,
    perm: &mut [usize],
) -> Result<(), SingularMatrix> {
    debug_assert_eq!(a.len(), n * n);
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let tiny = scale * 1e-14;
    for (i, p) in perm.iter_mut().enumerate().take(n) {
        *p = i;
    }
    for k in 0..n {
        let mut piv = k;
        let mut best = a[k * n + k].abs();
        for i in k + 1..n {
            let v = a[i * n + k].abs();
            if v > best {
                best = v;
                piv = i;
            }
        }
        if best.is_nan() || best <= tiny {
            return Err(SingularMatrix { pivot: k });
        }
        if piv != k {
            let (upper, lower) = a.split_at_mut(piv * n);
            upper[k * n..(k + 1) * n].swap_with_slice(&mut lower[..n]);
            perm.swap(k, piv);
        }
        // Row slices rather than indices: no bounds checks in the inner loop, which the
        // compiler then vectorises (the same operations in the same order as before).
        let (top, bottom) = a.split_at_mut((k + 1) * n);
        let row_k = &top[k * n..];
        let inv = 1.0 / row_k[k];
        for row_i in bottom.chunks_exact_mut(n) {
            let l = row_i[k] * inv;
            row_i[k] = l;
            if l != 0.0 {
                for (x, y) in row_i[k + 1..].iter_mut().zip(&row_k[k + 1..]) {
                    *x -= l * y;
                }
            }
        }
    }
    Ok(())
}

/// Solves `A x = b` given the factors from [`lu_factor_in_place`]; `b` is overwritten by `x`.
/// `work` must have length `n`.
pub fn lu_solve_in_place(lu: &[f64], n: usize, perm: &[usize], b: &mut [f64], work: &mut [f64]) {
    for i in 0..n {
        work[i] = b[perm[i]];
    }
    for i in 0..n {
        let mut s = work[i];
        for j in 0..i {
            s -= lu[i * n + j] * work[j];
        }
        work[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = work[i];
        for j in i + 1..n {
            s -= lu[i * n + j] * work[j];
        }
        work[i] = s / lu[i * n + i];
    }
    b[..n].copy_from_slice(&work[..n]);
}

/// `x·y` over `x.len()` terms, in four interleaved partial sums (independent additions the
/// processor overlaps; a single running sum waits on each addition).
#[inline(always)]
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let y = &y[..x.len()];
    let mut s = [0.0f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for k in 0..4 {
            s[k] += a[k] * b[k];
        }
    }
    let mut tail = 0.0;
    for (a, b) in xr.iter().zip(yr) {
        tail += a * b;
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// Factorises the symmetric row-major `n×n` matrix `a` as `Uᵀ U` (`U = Lᵀ`, upper
/// triangular), reading and overwriting only its upper triangle and diagonal (the lower
/// triangle is left as it was). Fails at the first pivot that is not positive (beyond
/// `1e-14 · max|a|`): `a` is not positive definite, or is singular.
///
/// Every element of the factor has the bits of the plainest right-looking form, on every
/// processor: once row `k` of `U` is known, every later element `(i, j)` loses `u_ki * u_kj`
/// (a multiplication then a subtraction, no fused multiply-add), for k = 0, 1, 2, … in that
/// order, and row `k` is finished as `sqrt` of its pivot and multiples of `1 / u_kk`. What
/// the implementations change is only where partial results live: with AVX, blocks of four
/// rows held in registers (module `avx`); otherwise panels of four rows
/// (`cholesky_factor_generic`). The dot-product form that came first waited on one running
/// sum per element, and took 2–3× as long as the panels at `n = 100` (a 100-link chain's
/// mass matrix, factorised at every evaluation); the AVX blocks take about half the
/// panels' time there.
pub fn cholesky_factor_in_place(a: &mut [f64], n: usize) -> Result<(), SingularMatrix> {
    debug_assert_eq!(a.len(), n * n);
    #[cfg(target_arch = "x86_64")]
    if n >= 4 && a.len() == n * n && std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor has AVX, `a` holds `n²` elements and `n >= 4` (checked just
        // above).
        return unsafe { avx::cholesky_factor(a, n) };
    }
    cholesky_factor_generic(a, n)
}

fn cholesky_factor_generic(a: &mut [f64], n: usize) -> Result<(), SingularMatrix> {
    let tiny = max_abs(a) * 1e-14;
    // Rows in panels of four: each later row is read and written once per four rows of `U`
    // rather than once per row (the 100-link chain's 80 KB matrix does not stay in L1, and
    // one row at a time the update waited on memory). Each element still loses `u_ki * u_kj`
    // for k = 0, 1, 2, ... in that order, a multiplication then a subtraction: the same bits
    // as one row at a time.
    let mut k = 0;
    while k < n {
        let b = PANEL.min(n - k);
        let (done, rest) = a.split_at_mut((k + b) * n);
        // The panel's own rows, then the rows below it.
        factor_block(&mut done[k * n..], n, k, n, tiny)?;
        let panel = &done[k * n..];
        if b == PANEL {
            let (r0, r1, r2, r3) = (
                &panel[..n],
                &panel[n..2 * n],
                &panel[2 * n..3 * n],
                &panel[3 * n..4 * n],
            );
            for (i, row_i) in (k + PANEL..n).zip(rest.chunks_exact_mut(n)) {
                let (u0, u1, u2, u3) = (r0[i], r1[i], r2[i], r3[i]);
                let ys = r0[i..].iter().zip(&r1[i..]).zip(&r2[i..]).zip(&r3[i..]);
                for (x, (((&y0, &y1), &y2), &y3)) in row_i[i..].iter_mut().zip(ys) {
                    *x = (((*x - u0 * y0) - u1 * y1) - u2 * y2) - u3 * y3;
                }
            }
        } else {
            for (i, row_i) in (k + b..n).zip(rest.chunks_exact_mut(n)) {
                for row_j in panel.chunks_exact(n) {
                    let u = row_j[i];
                    for (x, &y) in row_i[i..].iter_mut().zip(&row_j[i..]) {
                        *x -= u * y;
                    }
                }
            }
        }
        k += b;
    }
    Ok(())
}

/// Rows of `U` finished before the rows below them are updated (see
/// [`cholesky_factor_in_place`]).
const PANEL: usize = 4;

/// Row `k` of `U` from what the earlier rows left of row `k` of `A` (`row_k` is that whole
/// row): fails when the pivot is not above `tiny` (or is NaN).
fn finish_row(row_k: &mut [f64], k: usize, tiny: f64) -> Result<(), SingularMatrix> {
    let d = row_k[k];
    if d.is_nan() || d <= tiny {
        return Err(SingularMatrix { pivot: k });
    }
    let ukk = d.sqrt();
    row_k[k] = ukk;
    let inv = 1.0 / ukk;
    for x in &mut row_k[k + 1..] {
        *x *= inv;
    }
    Ok(())
}

/// Rows `i0..i0 + b` of `U` (`b = rows.len() / n`, `rows` those rows of `a`) in columns
/// `..end`, once every earlier row of `U` has been subtracted from them: row `i0 + r` loses
/// the block's rows above it, one at a time, then is finished.
fn factor_block(
    rows: &mut [f64],
    n: usize,
    i0: usize,
    end: usize,
    tiny: f64,
) -> Result<(), SingularMatrix> {
    for r in 0..rows.len() / n {
        let (above, row_r) = rows.split_at_mut(r * n);
        let row_r = &mut row_r[..end];
        let col = i0 + r;
        for row_j in above.chunks_exact(n) {
            let u = row_j[col];
            for (x, &y) in row_r[col..].iter_mut().zip(&row_j[col..end]) {
                *x -= u * y;
            }
        }
        finish_row(row_r, col, tiny)?;
    }
    Ok(())
}

/// The largest `|x|` in `a`, NaNs ignored (as `f64::max` does), in eight running maxima:
/// the maximum does not depend on the order, and one running maximum waits on each
/// comparison. `if |x| > m` rather than `f64::max`: the same value (a NaN compares false and
/// is skipped, `m` is never NaN) in one instruction (`f64::max` adds a NaN test and a blend
/// to every step, and took a tenth of the factor's time at `n = 100`).
#[inline(always)]
fn max_abs(a: &[f64]) -> f64 {
    let mut m = [0.0f64; 8];
    let chunks = a.chunks_exact(8);
    let rest = chunks.remainder();
    for c in chunks {
        for (m, x) in m.iter_mut().zip(c) {
            let x = x.abs();
            if x > *m {
                *m = x;
            }
        }
    }
    let m = m.iter().fold(0.0f64, |m, &x| m.max(x));
    rest.iter().fold(m, |m, x| m.max(x.abs()))
}

/// The factor in blocks of four rows held in AVX registers.
///
/// Left-looking by blocks: rows `i0..i0 + 4` of `A` lose every earlier row of `U` at once,
/// `u_pi * u_pj` for p = 0, 1, …, i0 − 1 in that order, then the block's own rows one after
/// the other. Every element thus loses `u_ki * u_kj` for k = 0, 1, 2, … in order, a
/// multiplication then a subtraction (no fused multiply-add), and is then multiplied by
/// `1 / u_ii`: the same bits as the generic factor. What changes is where the partial results
/// live: a tile of four rows by eight columns stays in eight registers while p runs over all
/// the rows above it and the block's own rows are applied, so each element of `A` is loaded
/// and stored once, and each step of p costs two loads and four broadcasts for eight
/// four-lane multiplications and eight subtractions, 32 element updates (the panel form
/// loaded and stored every element once per four rows of `U`, and loaded four elements of
/// `U` per element).
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{max_abs, SingularMatrix};
    use std::arch::x86_64::*;

    /// `MASKS[m]` selects lanes `m..4` (all bits set in a selected lane, for `blendv`).
    static MASKS: [[u64; 4]; 4] = [
        [!0, !0, !0, !0],
        [0, !0, !0, !0],
        [0, 0, !0, !0],
        [0, 0, 0, !0],
    ];

    /// # Safety
    /// The processor must have AVX; `a.len() == n * n` and `n >= 4`.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn cholesky_factor(a: &mut [f64], n: usize) -> Result<(), SingularMatrix> {
        let tiny = max_abs(a) * 1e-14;
        let mut i0 = 0;
        while i0 < n {
            let b = (n - i0).min(4);
            // SAFETY: AVX is present, `a` holds `n²` elements, `n >= 4` and `i0 + b <= n`
            // (this function's contract and the loop bounds).
            unsafe {
                match b {
                    4 => factor_rows::<4>(a, n, i0, tiny)?,
                    3 => factor_rows::<3>(a, n, i0, tiny)?,
                    2 => factor_rows::<2>(a, n, i0, tiny)?,
                    _ => factor_rows::<1>(a, n, i0, tiny)?,
                }
            }
            i0 += b;
        }
        Ok(())
    }

    /// Rows `i0..i0 + R` of `U`, on and right of their diagonal, given rows `..i0`. Columns
    /// come in windows of four or eight; the first window holds the block's diagonal
    /// triangle, finished in scalar code (square roots, pivot checks), and the later windows
    /// apply the block's rows in registers. Lanes left of the diagonal, or done by an earlier
    /// window, are computed and then their old bits are stored back: the lower triangle keeps
    /// its values.
    ///
    /// # Safety
    /// AVX; `a.len() == n * n`; `n >= 4`; `1 <= R <= 4` and `i0 + R <= n`.
    #[target_feature(enable = "avx")]
    unsafe fn factor_rows<const R: usize>(
        a: &mut [f64],
        n: usize,
        i0: usize,
        tiny: f64,
    ) -> Result<(), SingularMatrix> {
        // The diagonal window: its first four columns, or the last four when fewer are left
        // (then R = n - i0); row t starts at lane t + i0 - cd.
        let cd = if i0 + 4 <= n { i0 } else { n - 4 };
        let off = i0 - cd;
        let p = a.as_mut_ptr();
        let mut w = [[0.0; 4]; R];
        // SAFETY: rows `..i0 + R` and columns `cd..cd + 4` lie within the `n * n` elements.
        unsafe {
            let acc = tile::<R, 1>(p, n, i0, cd);
            for (w, acc) in w.iter_mut().zip(&acc) {
                _mm256_storeu_pd(w.as_mut_ptr(), acc[0]);
            }
        }
        // `off` is 0 but in the last block: a constant there lets the triangle's loops unroll.
        let inv = if off == 0 {
            finish_triangle(&mut w, 0, i0, tiny)?
        } else {
            finish_triangle(&mut w, off, i0, tiny)?
        };
        // SAFETY: as above.
        unsafe {
            for (t, w) in w.iter().enumerate() {
                let row = _mm256_loadu_pd(w.as_ptr());
                store_from_lane(p.add((i0 + t) * n + cd), row, t + off);
            }
        }
        if cd + 4 == n {
            return Ok(());
        }
        // Here off = 0: `w[q][r] = u_(i0+q, i0+r)`, the block's multipliers.
        let u = w;
        let p = a.as_mut_ptr();
        // SAFETY (for every window below): columns `c..c + 4V` lie in `cd + 4..n` and rows
        // in `..i0 + R`, so every access is inside the `n * n` elements.
        unsafe {
            let mut c = i0 + 4;
            while c + 8 <= n {
                let mut acc = tile::<R, 2>(p, n, i0, c);
                apply_block(&mut acc, &u, &inv);
                store_tile(p, n, i0, c, acc);
                c += 8;
            }
            if c + 4 <= n {
                let mut acc = tile::<R, 1>(p, n, i0, c);
                apply_block(&mut acc, &u, &inv);
                store_tile(p, n, i0, c, acc);
                c += 4;
            }
            if c < n {
                // One to three columns left: the window of the last four, whose first lanes
                // were done above.
                let first = 4 - (n - c);
                let mut acc = tile::<R, 1>(p, n, i0, n - 4);
                apply_block(&mut acc, &u, &inv);
                for (t, acc) in acc.iter().enumerate() {
                    store_from_lane(p.add((i0 + t) * n + n - 4), acc[0], first);
                }
            }
        }
        Ok(())
    }

    /// The block's diagonal triangle, rows `i0..i0 + R` in a window of four columns where
    /// row r starts at lane `r + off`, once every earlier row has been subtracted: row r
    /// loses the block's rows above it, one at a time, then is finished (the pivot checked,
    /// its square root taken, the rest multiplied by its inverse), as [`factor_block`](super::factor_block) does
    /// along a whole row. In scalar code on a copy in registers: this is the factor's
    /// critical path (a square root and a division per row), so it has no loop or bounds
    /// overhead. Returns the inverses `1 / u_rr`.
    #[inline(always)]
    fn finish_triangle<const R: usize>(
        w: &mut [[f64; 4]; R],
        off: usize,
        i0: usize,
        tiny: f64,
    ) -> Result<[f64; R], SingularMatrix> {
        let mut inv = [0.0; R];
        for (r, inv_r) in inv.iter_mut().enumerate() {
            let (above, row_r) = w.split_at_mut(r);
            let row_r = &mut row_r[0];
            let d = r + off;
            for row_q in above.iter() {
                let m = row_q[d];
                for (x, &y) in row_r[d..].iter_mut().zip(&row_q[d..]) {
                    *x -= m * y;
                }
            }
            let pivot = row_r[d];
            if pivot.is_nan() || pivot <= tiny {
                return Err(SingularMatrix { pivot: i0 + r });
            }
            let ukk = pivot.sqrt();
            row_r[d] = ukk;
            *inv_r = 1.0 / ukk;
            for x in &mut row_r[d + 1..] {
                *x *= *inv_r;
            }
        }
        Ok(inv)
    }

    /// Rows `i0..i0 + R`, columns `c..c + 4V` of `a`, less `u_pi * u_pj` for p = 0, …,
    /// i0 − 1 in order (a multiplication then a subtraction per term).
    ///
    /// # Safety
    /// AVX; rows `0..i0 + R` and columns `c..c + 4V` lie within the `n * n` elements at `a`.
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn tile<const R: usize, const V: usize>(
        a: *const f64,
        n: usize,
        i0: usize,
        c: usize,
    ) -> [[__m256d; V]; R] {
        // SAFETY: every pointer is to row < i0 + R, column < c + 4V (the contract).
        unsafe {
            let mut acc = [[_mm256_setzero_pd(); V]; R];
            for (t, acc) in acc.iter_mut().enumerate() {
                for (v, acc) in acc.iter_mut().enumerate() {
                    *acc = _mm256_loadu_pd(a.add((i0 + t) * n + c + 4 * v));
                }
            }
            let mut row_p = a;
            for _ in 0..i0 {
                let mut y = [_mm256_setzero_pd(); V];
                for (v, y) in y.iter_mut().enumerate() {
                    *y = _mm256_loadu_pd(row_p.add(c + 4 * v));
                }
                for (t, acc) in acc.iter_mut().enumerate() {
                    let u = _mm256_broadcast_sd(&*row_p.add(i0 + t));
                    for (acc, &y) in acc.iter_mut().zip(&y) {
                        *acc = _mm256_sub_pd(*acc, _mm256_mul_pd(u, y));
                    }
                }
                row_p = row_p.add(n);
            }
            acc
        }
    }

    /// The block's own rows on a tile that has lost every earlier row: row r loses
    /// `u[q][r]` times (finished) row q for q = 0, …, r − 1 in order, then is multiplied by
    /// `inv[r] = 1 / u_rr`, as [`factor_block`](super::factor_block) does.
    ///
    /// # Safety
    /// AVX.
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn apply_block<const R: usize, const V: usize>(
        acc: &mut [[__m256d; V]; R],
        u: &[[f64; 4]; R],
        inv: &[f64; R],
    ) {
        for r in 0..R {
            let (above, row_r) = acc.split_at_mut(r);
            let row_r = &mut row_r[0];
            for (q, row_q) in above.iter().enumerate() {
                let m = _mm256_set1_pd(u[q][r]);
                for (x, &y) in row_r.iter_mut().zip(row_q) {
                    *x = _mm256_sub_pd(*x, _mm256_mul_pd(m, y));
                }
            }
            let s = _mm256_set1_pd(inv[r]);
            for x in row_r {
                *x = _mm256_mul_pd(*x, s);
            }
        }
    }

    /// Stores a tile computed by [`tile`] back where it came from.
    ///
    /// # Safety
    /// AVX; as for [`tile`].
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn store_tile<const R: usize, const V: usize>(
        a: *mut f64,
        n: usize,
        i0: usize,
        c: usize,
        acc: [[__m256d; V]; R],
    ) {
        for (t, acc) in acc.iter().enumerate() {
            for (v, &acc) in acc.iter().enumerate() {
                // SAFETY: the element range the tile was loaded from (the contract).
                unsafe { _mm256_storeu_pd(a.add((i0 + t) * n + c + 4 * v), acc) };
            }
        }
    }

    /// Stores lanes `first..4` of `acc` at `dst`, storing back the old bits of the lanes
    /// before them.
    ///
    /// # Safety
    /// AVX; `dst..dst + 4` are valid elements; `first < 4`.
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn store_from_lane(dst: *mut f64, acc: __m256d, first: usize) {
        // SAFETY: `dst..dst + 4` are valid (the contract); `MASKS[first]` is four `u64`s,
        // read as four `f64` bit patterns.
        unsafe {
            let mask = _mm256_loadu_pd(MASKS[first].as_ptr().cast());
            let old = _mm256_loadu_pd(dst);
            _mm256_storeu_pd(dst, _mm256_blendv_pd(old, acc, mask));
        }
    }
}

/// Solves `A x = b` given the factor from [`cholesky_factor_in_place`]; `b` is overwritten by
/// `x`.
pub fn cholesky_solve_in_place(u: &[f64], n: usize, b: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor has AVX (checked just above).
        return unsafe { cholesky_solve_avx(u, n, b) };
    }
    cholesky_solve_generic(u, n, b);
}

/// [`cholesky_solve_generic`] compiled for AVX: four lanes per instruction in the
/// subtractions along a row and in the dot product's four partial sums. The same operations
/// in the same order (no fused multiply-add), so the same bits on every processor.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn cholesky_solve_avx(u: &[f64], n: usize, b: &mut [f64]) {
    cholesky_solve_generic(u, n, b);
}

#[inline(always)]
fn cholesky_solve_generic(u: &[f64], n: usize, b: &mut [f64]) {
    // Uᵀ y = b: column k of Uᵀ is row k of U, subtracted from the rest of b once y_k is known.
    for k in 0..n {
        let row = &u[k * n..(k + 1) * n];
        let yk = b[k] / row[k];
        b[k] = yk;
        for (bi, uki) in b[k + 1..].iter_mut().zip(&row[k + 1..]) {
            *bi -= uki * yk;
        }
    }
    // U x = y, row by row from the bottom.
    for i in (0..n).rev() {
        let row = &u[i * n..(i + 1) * n];
        b[i] = (b[i] - dot(&row[i + 1..], &b[i + 1..])) / row[i];
    }
}

/// Solves `A x = b` for one size `n`, owning its buffers: Cholesky when the caller knows `A`
/// is symmetric (a mass matrix), LU with partial pivoting otherwise or when `A` is not
/// positive definite after all.
#[derive(Clone, Debug)]
pub struct DenseSolver {
    n: usize,
    symmetric: bool,
    perm: Vec<usize>,
    work: Vec<f64>,
}

impl DenseSolver {
    /// A solver for `n×n` systems; `symmetric` when every `A` it will see is symmetric.
    pub fn new(n: usize, symmetric: bool) -> DenseSolver {
        DenseSolver {
            n,
            symmetric,
            perm: vec![0; n],
            work: vec![0.0; n],
        }
    }

    /// Whether Cholesky is tried first.
    pub fn is_symmetric(&self) -> bool {
        self.symmetric
    }

    /// Solves `A x = b` where `ab` holds `A` (row-major, `n²`) then `b` (`n`); `ab` is
    /// overwritten, the solution written to `x[..n]`.
    pub fn solve(&mut self, ab: &mut [f64], x: &mut [f64]) -> Result<(), SingularMatrix> {
        let n = self.n;
        let (a, b) = ab.split_at_mut(n * n);
        if self.symmetric {
            for (d, i) in self.work.iter_mut().zip(0..n) {
                *d = a[i * n + i];
            }
            if cholesky_factor_in_place(a, n).is_ok() {
                cholesky_solve_in_place(a, n, b);
                x[..n].copy_from_slice(&b[..n]);
                return Ok(());
            }
            // Not positive definite: A is its untouched lower triangle and the saved
            // diagonal; let pivoting decide whether it is singular.
            for i in 0..n {
                a[i * n + i] = self.work[i];
                for j in i + 1..n {
                    a[i * n + j] = a[j * n + i];
                }
            }
        }
        lu_factor_in_place(a, n, &mut self.perm)?;
        lu_solve_in_place(a, n, &self.perm, b, &mut self.work);
        x[..n].copy_from_slice(&b[..n]);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_random_systems_against_residual() {
        // Deterministic pseudo-random matrices; check the residual of the solution.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for n in 1..8 {
            let a: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
            let b: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let mut lu = a.clone();
            let mut perm = vec![0; n];
            lu_factor_in_place(&mut lu, n, &mut perm).unwrap();
            let mut x = b.clone();
            let mut w = vec![0.0; n];
            lu_solve_in_place(&lu, n, &perm, &mut x, &mut w);
            for i in 0..n {
                let r: f64 = (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - b[i];
                assert!(r.abs() < 1e-10, "n={n} residual {r}");
            }
        }
    }

    #[test]
    fn singular_is_reported() {
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        let mut perm = vec![0; 2];
        assert_eq!(
            lu_factor_in_place(&mut a, 2, &mut perm),
            Err(SingularMatrix { pivot: 1 })
        );
    }

    fn random_matrix(n: usize, seed: &mut u64) -> Vec<f64> {
        (0..n * n)
            .map(|_| {
                *seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    /// `Bᵀ B + shift·I` for a random `B`: symmetric positive definite.
    fn spd_matrix(n: usize, seed: &mut u64, shift: f64) -> Vec<f64> {
        let bm = random_matrix(n, seed);
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| bm[k * n + i] * bm[k * n + j]).sum::<f64>()
                    + if i == j { shift } else { 0.0 };
            }
        }
        a
    }

    fn residual(a: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let n = b.len();
        (0..n)
            .map(|i| ((0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - b[i]).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn cholesky_solves_symmetric_positive_definite_systems() {
        // A = Bᵀ B + I is symmetric positive definite; sizes across the 4-wide dot's tails.
        let mut seed = 7;
        for n in [1, 2, 3, 4, 5, 8, 13, 40] {
            let a = spd_matrix(n, &mut seed, 1.0);
            let b: Vec<f64> = random_matrix(n, &mut seed)[..n].to_vec();
            let mut ab = a.clone();
            ab.extend_from_slice(&b);
            let mut x = vec![0.0; n];
            let mut solver = DenseSolver::new(n, true);
            solver.solve(&mut ab, &mut x).unwrap();
            assert!(residual(&a, &x, &b) < 1e-12, "n={n}");
            // And the lower triangle was left as it was.
            for i in 0..n {
                for j in 0..i {
                    assert_eq!(ab[i * n + j], a[i * n + j]);
                }
            }
        }
    }

    /// The plainest right-looking factor, one row of `U` at a time: the reference for the
    /// bits. Returns the first pivot that is not above `tiny` (or NaN), as the factor does.
    fn one_row_at_a_time(a: &mut [f64], n: usize, tiny: f64) -> Result<(), SingularMatrix> {
        for k in 0..n {
            let d = a[k * n + k];
            if d.is_nan() || d <= tiny {
                return Err(SingularMatrix { pivot: k });
            }
            let ukk = d.sqrt();
            a[k * n + k] = ukk;
            for j in k + 1..n {
                a[k * n + j] *= 1.0 / ukk;
            }
            for i in k + 1..n {
                let u = a[k * n + i];
                for j in i..n {
                    a[i * n + j] -= u * a[k * n + j];
                }
            }
        }
        Ok(())
    }

    /// `spd_matrix` with its strict lower triangle replaced by NaNs of distinct payloads:
    /// a factor that read it, or wrote it, shows in the bits.
    fn spd_with_poisoned_lower(n: usize, seed: &mut u64) -> Vec<f64> {
        let mut a = spd_matrix(n, seed, 0.1);
        for i in 0..n {
            for j in 0..i {
                a[i * n + j] = f64::from_bits(0x7ff8_0000_0000_0000 | (i * n + j) as u64);
            }
        }
        a
    }

    fn assert_same_bits(x: &[f64], y: &[f64], what: &str) {
        for (k, (a, b)) in x.iter().zip(y).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "{what}: element {k}: {a} vs {b}");
        }
    }

    /// Sizes across every remainder of the blocks of four and the windows of eight columns,
    /// and the 100-link chain's.
    const SIZES: [usize; 40] = {
        let mut s = [0; 40];
        let mut i = 0;
        while i < 37 {
            s[i] = i + 1;
            i += 1;
        }
        s[37] = 100;
        s[38] = 101;
        s[39] = 103;
        s
    };

    /// Every implementation (the dispatched one, and the AVX one called directly when the
    /// processor has AVX) gives the bits of one row at a time in the whole matrix: the
    /// factor in the upper triangle, and the lower triangle (NaNs) untouched.
    #[test]
    fn blocked_factor_has_the_bits_of_one_row_at_a_time_at_every_size() {
        let mut seed = 21;
        for n in SIZES {
            let a = spd_with_poisoned_lower(n, &mut seed);
            let mut plain = a.clone();
            one_row_at_a_time(&mut plain, n, 0.0).unwrap();
            let mut dispatched = a.clone();
            cholesky_factor_in_place(&mut dispatched, n).unwrap();
            assert_same_bits(&dispatched, &plain, &format!("dispatched, n={n}"));
            let mut generic = a.clone();
            cholesky_factor_generic(&mut generic, n).unwrap();
            assert_same_bits(&generic, &plain, &format!("generic, n={n}"));
            #[cfg(target_arch = "x86_64")]
            if n >= 4 && std::arch::is_x86_feature_detected!("avx") {
                let mut blocked = a.clone();
                // SAFETY: AVX is present, `blocked` holds `n²` elements and `n >= 4`.
                unsafe { avx::cholesky_factor(&mut blocked, n) }.unwrap();
                assert_same_bits(&blocked, &plain, &format!("avx, n={n}"));
            }
        }
    }

    /// A matrix that is not positive definite at pivot `k` (its diagonal there set to zero,
    /// so the pivot is minus a sum of squares): every implementation stops at `k`, leaves
    /// the lower triangle as it was, and `DenseSolver` still solves the system by LU.
    #[test]
    fn a_pivot_that_is_not_positive_is_found_at_every_position() {
        let mut seed = 33;
        for n in [1, 2, 3, 4, 5, 7, 8, 9, 13, 16, 17, 37, 100] {
            let a0 = spd_matrix(n, &mut seed, 0.1);
            let b: Vec<f64> = random_matrix(n, &mut seed)[..n].to_vec();
            for k in (0..n).filter(|k| n < 20 || k % 7 < 5 || *k >= n - 5) {
                let mut a = a0.clone();
                a[k * n + k] = 0.0;
                let tiny = 1e-14 * a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let mut plain = a.clone();
                let expected = Err(SingularMatrix { pivot: k });
                assert_eq!(one_row_at_a_time(&mut plain, n, tiny), expected, "n={n}");
                let mut dispatched = a.clone();
                assert_eq!(
                    cholesky_factor_in_place(&mut dispatched, n),
                    expected,
                    "n={n}"
                );
                let mut generic = a.clone();
                assert_eq!(cholesky_factor_generic(&mut generic, n), expected, "n={n}");
                for v in [&dispatched, &generic] {
                    for i in 0..n {
                        for j in 0..i {
                            assert_eq!(v[i * n + j].to_bits(), a[i * n + j].to_bits());
                        }
                    }
                }
                // Symmetric and (almost surely) nonsingular: LU solves it.
                let mut ab = a.clone();
                ab.extend_from_slice(&b);
                let mut x = vec![0.0; n];
                if n == 1 {
                    // [0] is singular: LU says so.
                    assert_eq!(
                        DenseSolver::new(n, true).solve(&mut ab, &mut x),
                        Err(SingularMatrix { pivot: 0 })
                    );
                    continue;
                }
                DenseSolver::new(n, true).solve(&mut ab, &mut x).unwrap();
                let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                assert!(residual(&a, &x, &b) < 1e-10 * scale, "n={n} k={k}");
            }
        }
    }

    /// A NaN on the diagonal, or above it, stops the factor at the first pivot it reaches,
    /// in every implementation, as in one row at a time.
    #[test]
    fn a_nan_stops_the_factor_at_the_pivot_it_reaches() {
        let mut seed = 44;
        for n in [1, 3, 4, 6, 9, 16, 37, 100] {
            let a0 = spd_matrix(n, &mut seed, 0.1);
            let places = [(n / 2, n / 2), (0, n - 1), (n / 3, n / 2), (n - 1, n - 1)];
            for (i, j) in places {
                let mut a = a0.clone();
                a[i * n + j] = f64::NAN;
                let tiny = 1e-14 * a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let mut plain = a.clone();
                let expected = one_row_at_a_time(&mut plain, n, tiny);
                assert_eq!(
                    expected,
                    Err(SingularMatrix { pivot: j }),
                    "n={n} ({i},{j})"
                );
                let mut dispatched = a.clone();
                assert_eq!(cholesky_factor_in_place(&mut dispatched, n), expected);
                let mut generic = a.clone();
                assert_eq!(cholesky_factor_generic(&mut generic, n), expected);
            }
        }
    }

    /// The eight running maxima give `f64::max`'s fold: NaNs skipped, every length.
    #[test]
    fn max_abs_is_the_largest_magnitude_ignoring_nans() {
        for len in 0..40 {
            let mut v: Vec<f64> = (0..len)
                .map(|k| (k as f64 - 17.5) * (k % 3) as f64)
                .collect();
            if len > 5 {
                v[len / 2] = f64::NAN;
                v[len - 1] = -f64::NAN;
            }
            let expected = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert_eq!(max_abs(&v).to_bits(), expected.to_bits(), "len={len}");
        }
    }

    /// The panel factor has the bits of the plainest right-looking factor, one row of `U` at
    /// a time, at every size (panels of four and every remainder).
    #[test]
    fn panels_give_the_bits_of_one_row_at_a_time() {
        let mut seed = 5;
        for n in (1..=13).chain([31, 100]) {
            let a = spd_matrix(n, &mut seed, 0.1);
            let (mut panel, mut plain) = (a.clone(), a);
            cholesky_factor_in_place(&mut panel, n).unwrap();
            one_row_at_a_time(&mut plain, n, 0.0).unwrap();
            for i in 0..n {
                for j in i..n {
                    let (x, y) = (panel[i * n + j], plain[i * n + j]);
                    assert_eq!(x.to_bits(), y.to_bits(), "n={n} ({i},{j}): {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn the_dispatched_factor_has_the_generic_factors_bits() {
        // On a processor with AVX the dispatched factor runs the AVX build: same bits.
        let mut seed = 11;
        for n in [1, 2, 3, 6, 7, 31, 64] {
            let mut a = spd_matrix(n, &mut seed, 0.1);
            let mut dispatched = a.clone();
            cholesky_factor_in_place(&mut dispatched, n).unwrap();
            cholesky_factor_generic(&mut a, n).unwrap();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&dispatched), bits(&a), "n={n}");
        }
    }

    /// The dispatched solve (AVX where the processor has it) has the generic solve's bits,
    /// at every size across the dot product's four partial sums and their remainder.
    #[test]
    fn the_dispatched_solve_has_the_generic_solves_bits() {
        let mut seed = 66;
        for n in SIZES {
            let mut u = spd_matrix(n, &mut seed, 0.1);
            cholesky_factor_in_place(&mut u, n).unwrap();
            let b = random_matrix(n, &mut seed)[..n].to_vec();
            let (mut dispatched, mut generic) = (b.clone(), b);
            cholesky_solve_in_place(&u, n, &mut dispatched);
            cholesky_solve_generic(&u, n, &mut generic);
            assert_same_bits(&dispatched, &generic, &format!("n={n}"));
        }
    }

    #[test]
    fn symmetric_indefinite_and_singular_fall_back_to_lu() {
        // Symmetric but indefinite: Cholesky fails at the second pivot, LU solves it.
        let a = [1.0, 2.0, 2.0, 1.0];
        let mut ab = vec![1.0, 2.0, 2.0, 1.0, 3.0, 3.0];
        let mut x = [0.0; 2];
        DenseSolver::new(2, true).solve(&mut ab, &mut x).unwrap();
        assert!(residual(&a, &x, &[3.0, 3.0]) < 1e-14);
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        // A zero first pivot with a usable off-diagonal: needs pivoting.
        let mut ab = vec![0.0, 1.0, 1.0, 0.0, 2.0, 5.0];
        DenseSolver::new(2, true).solve(&mut ab, &mut x).unwrap();
        assert_eq!(x, [5.0, 2.0]);
        // Singular: reported by LU, with its pivot column.
        let mut ab = vec![1.0, 2.0, 2.0, 4.0, 1.0, 1.0];
        assert_eq!(
            DenseSolver::new(2, true).solve(&mut ab, &mut x),
            Err(SingularMatrix { pivot: 1 })
        );
    }

    #[test]
    fn lu_agrees_with_cholesky_on_spd_systems() {
        let mut seed = 99;
        let n = 17;
        let a = spd_matrix(n, &mut seed, 0.5);
        let mut ab = a.clone();
        ab.extend((0..n).map(|i| i as f64 - 3.0));
        let mut ab2 = ab.clone();
        let (mut x1, mut x2) = (vec![0.0; n], vec![0.0; n]);
        DenseSolver::new(n, true).solve(&mut ab, &mut x1).unwrap();
        DenseSolver::new(n, false).solve(&mut ab2, &mut x2).unwrap();
        for i in 0..n {
            assert!((x1[i] - x2[i]).abs() < 1e-9 * (1.0 + x2[i].abs()), "{i}");
        }
    }
}
