//! The numeric phase of the supernodal multifrontal LU ([`super::supernodal`]): for each
//! supernode in postorder, its front (a dense `m × m` block, column-major) is assembled from
//! the matrix's entries and its children's update matrices, its `ns` pivots are eliminated
//! with dense kernels (no pivoting), the `L` and `U` blocks are kept and the Schur
//! complement goes on the stack for the parent. Real and complex alike (`T`).
//!
//! A symmetric matrix (damped Newton's `K + μD` in the statics) needs only half of the work:
//! its elimination without pivoting has `U = D Lᵀ`, so each row of `U` is its pivot's column
//! of the front as it stands when that pivot is reached (copied, not solved for), and only the
//! lower triangle of each Schur complement is updated (the dominant cost). The upper triangles
//! of the fronts are then never read before the elimination writes them (row `k` of `U` is
//! copied in when pivot `k` is reached; the rest of the upper triangle is never read into the
//! lower one): they are neither zeroed nor assembled, and hold whatever an earlier front left
//! there. The update matrices go on the stack as packed lower triangles. On the 20 × 20
//! hanging net a factorization of `K_s + μD` took 18.0 M instructions with whole fronts
//! zeroed, assembled and stacked, 14.3 M with their lower triangles alone.
//!
//! A symmetric factorization also keeps only half of the factors: the `ns` rows of each
//! supernode's pivots (`U11`, `U12`, unscaled, and `L11` below the diagonal block's
//! diagonal), not `L21`, whose entries are `U12`'s transposed times the pivots' inverses.
//! The solve forms each of them as the elimination did (`x · (1/d)`), so the solutions are
//! the same bits as from the full factors.

use super::scalar::Scalar;
use super::supernodal::Supernodes;

/// The numeric factors of one matrix on a [`Supernodes`] structure.
#[derive(Debug)]
pub(crate) struct Numeric<T> {
    /// The factors: of every supernode its `m × ns` columns and `ns × r` rows of `U` right
    /// of them ([`Supernodes::lu_start`]), or, when `symmetric`, its `ns × m` rows of `U`
    /// ([`Supernodes::sym_start`]). Allocated by the first factorization, for its layout.
    lu: Vec<T>,
    /// The layout of `lu`: the last factorization's.
    symmetric: bool,
    front: Vec<T>,
    stack: Vec<T>,
    row_max: Vec<f64>,
}

#[cfg(test)]
impl Numeric<f64> {
    /// Fills the fronts' scratch with NaN: what an earlier factorization left there must not
    /// reach the next one's lower triangles.
    pub(crate) fn poison_front(&mut self) {
        self.front.fill(f64::NAN);
    }
}

impl<T: Scalar> Numeric<T> {
    pub(crate) fn new(sn: &Supernodes) -> Self {
        Numeric {
            lu: Vec::new(),
            symmetric: false,
            front: vec![T::ZERO; sn.max_front * sn.max_front],
            stack: Vec::with_capacity(sn.max_stack),
            row_max: vec![0.0; sn.n],
        }
    }

    /// Entries the factors hold (as last allocated).
    #[cfg(test)]
    pub(crate) fn stored(&self) -> usize {
        self.lu.len()
    }

    /// Factors the matrix with values `vals` (the analysed pattern's order); `Err(k)` when
    /// pivot `k` (permuted) is zero, not finite, or below `floor` times its row's largest
    /// entry. `symmetric`: the matrix is symmetric (its upper triangle is then not read).
    pub(crate) fn factor(
        &mut self,
        sn: &Supernodes,
        vals: &[T],
        floor: f64,
        symmetric: bool,
    ) -> Result<(), usize> {
        let len = if symmetric {
            sn.sym_start[sn.len()]
        } else {
            sn.lu_start[sn.len()]
        };
        if self.lu.len() != len {
            // The old layout freed before the new one is allocated (the peak is one of them).
            self.lu = Vec::new();
            self.lu = vec![T::ZERO; len];
        }
        self.symmetric = symmetric;
        self.row_max.fill(0.0);
        for (q, v) in vals.iter().enumerate() {
            let r = sn.value_row[q];
            self.row_max[r] = self.row_max[r].max(v.magnitude());
        }
        self.stack.clear();
        for s in 0..sn.len() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let r = sn.row_start[s + 1] - sn.row_start[s];
            let m = ns + r;
            let front = &mut self.front[..m * m];
            if symmetric {
                // The lower triangle alone (the upper one is not read: see the module's
                // comment), and the update matrices below on the stack as packed lower
                // triangles (column `b` of a child's from its diagonal down).
                for j in 0..m {
                    front[j * m + j..(j + 1) * m].fill(T::ZERO);
                }
                for &(at, q) in &sn.assembly[sn.asm_start[s]..sn.asm_lower[s]] {
                    front[at] = front[at] + vals[q];
                }
                for &c in sn.children[sn.child_start[s]..sn.child_start[s + 1]]
                    .iter()
                    .rev()
                {
                    let rel = &sn.rel[sn.row_start[c]..sn.row_start[c + 1]];
                    let rc = rel.len();
                    let base = self.stack.len() - rc * (rc + 1) / 2;
                    let mut src = &self.stack[base..];
                    for (b, &cb) in rel.iter().enumerate() {
                        let col = &mut front[cb * m..cb * m + m];
                        let (here, rest) = src.split_at(rc - b);
                        for (&ra, &v) in rel[b..].iter().zip(here) {
                            col[ra] = col[ra] + v;
                        }
                        src = rest;
                    }
                    self.stack.truncate(base);
                }
            } else {
                front.fill(T::ZERO);
                for &(at, q) in &sn.assembly[sn.asm_start[s]..sn.asm_start[s + 1]] {
                    front[at] = front[at] + vals[q];
                }
                // Extend-add the children's update matrices, last child on top of the stack.
                for &c in sn.children[sn.child_start[s]..sn.child_start[s + 1]]
                    .iter()
                    .rev()
                {
                    let rel = &sn.rel[sn.row_start[c]..sn.row_start[c + 1]];
                    let rc = rel.len();
                    let base = self.stack.len() - rc * rc;
                    let upd = &self.stack[base..];
                    for (b, &cb) in rel.iter().enumerate() {
                        let col = &mut front[cb * m..cb * m + m];
                        let src = &upd[b * rc..b * rc + rc];
                        for (&ra, &v) in rel.iter().zip(src) {
                            col[ra] = col[ra] + v;
                        }
                    }
                    self.stack.truncate(base);
                }
            }
            eliminate(front, m, ns, &self.row_max[f..f + ns], floor, symmetric)
                .map_err(|k| f + k)?;
            if symmetric {
                // The pivots' rows, column by column (leading dimension `ns`).
                let off = sn.sym_start[s];
                let rows = &mut self.lu[off..off + ns * m];
                for (j, dst) in rows.chunks_exact_mut(ns).enumerate() {
                    dst.copy_from_slice(&front[j * m..j * m + ns]);
                }
            } else {
                let off = sn.lu_start[s];
                self.lu[off..off + m * ns].copy_from_slice(&front[..m * ns]);
                let u12 = &mut self.lu[off + m * ns..off + m * ns + ns * r];
                for j in 0..r {
                    u12[j * ns..j * ns + ns]
                        .copy_from_slice(&front[(ns + j) * m..(ns + j) * m + ns]);
                }
            }
            // The Schur complement (its lower triangle when symmetric) for the parent.
            for j in 0..r {
                let top = if symmetric { ns + j } else { ns };
                self.stack
                    .extend_from_slice(&front[(ns + j) * m + top..(ns + j + 1) * m]);
            }
        }
        Ok(())
    }

    /// Solves `A z = b` in place, `z` in the permuted order; `t` is scratch of at least twice
    /// the largest front's side.
    pub(crate) fn solve_permuted(&self, sn: &Supernodes, z: &mut [T], t: &mut [T]) {
        if self.symmetric {
            return self.solve_symmetric(sn, z, t);
        }
        for s in 0..sn.len() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let rows = &sn.rows[sn.row_start[s]..sn.row_start[s + 1]];
            let (r, m) = (rows.len(), ns + rows.len());
            let l = &self.lu[sn.lu_start[s]..sn.lu_start[s] + m * ns];
            let zs = &mut z[f..f + ns];
            let t = &mut t[..r];
            t.fill(T::ZERO);
            for k in 0..ns {
                let zk = zs[k];
                let col = &l[k * m..k * m + m];
                for i in k + 1..ns {
                    zs[i] = zs[i] - col[i] * zk;
                }
                for (x, &v) in t.iter_mut().zip(&col[ns..]) {
                    *x = *x + v * zk;
                }
            }
            for (&i, &v) in rows.iter().zip(t.iter()) {
                z[i] = z[i] - v;
            }
        }
        for s in (0..sn.len()).rev() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let rows = &sn.rows[sn.row_start[s]..sn.row_start[s + 1]];
            let (r, m) = (rows.len(), ns + rows.len());
            let off = sn.lu_start[s];
            let u = &self.lu[off..off + m * ns];
            let u12 = &self.lu[off + m * ns..off + m * ns + ns * r];
            let t = &mut t[..r];
            for (x, &i) in t.iter_mut().zip(rows) {
                *x = z[i];
            }
            let zs = &mut z[f..f + ns];
            for (a, &za) in t.iter().enumerate() {
                for (x, &v) in zs.iter_mut().zip(&u12[a * ns..a * ns + ns]) {
                    *x = *x - v * za;
                }
            }
            for k in (0..ns).rev() {
                let zk = zs[k] / u[k + k * m];
                zs[k] = zk;
                for i in 0..k {
                    zs[i] = zs[i] - u[i + k * m] * zk;
                }
            }
        }
    }

    /// [`Numeric::solve_permuted`] from the pivots' rows of a symmetric factorization: the
    /// same operations in the same order as from the full factors, each entry of `L21`
    /// formed as the elimination formed it (its row of `U` times the pivot's inverse).
    fn solve_symmetric(&self, sn: &Supernodes, z: &mut [T], scratch: &mut [T]) {
        let (t, inv) = scratch.split_at_mut(sn.max_front);
        for s in 0..sn.len() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let rows = &sn.rows[sn.row_start[s]..sn.row_start[s + 1]];
            let (r, m) = (rows.len(), ns + rows.len());
            // Entry (i, j) at `j * ns + i`: `L11` below the diagonal, `U` on and above it.
            let u = &self.lu[sn.sym_start[s]..sn.sym_start[s] + ns * m];
            let zs = &mut z[f..f + ns];
            for k in 0..ns {
                let zk = zs[k];
                let col = &u[k * ns..k * ns + ns];
                for i in k + 1..ns {
                    zs[i] = zs[i] - col[i] * zk;
                }
                inv[k] = T::ONE / col[k];
            }
            let t = &mut t[..r];
            for (x, row) in t.iter_mut().zip(u[ns * ns..].chunks_exact(ns)) {
                let mut sum = T::ZERO;
                for ((&v, &d), &zk) in row.iter().zip(&inv[..ns]).zip(zs.iter()) {
                    sum = sum + v * d * zk;
                }
                *x = sum;
            }
            for (&i, &v) in rows.iter().zip(t.iter()) {
                z[i] = z[i] - v;
            }
        }
        for s in (0..sn.len()).rev() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let rows = &sn.rows[sn.row_start[s]..sn.row_start[s + 1]];
            let (r, m) = (rows.len(), ns + rows.len());
            let u = &self.lu[sn.sym_start[s]..sn.sym_start[s] + ns * m];
            let t = &mut t[..r];
            for (x, &i) in t.iter_mut().zip(rows) {
                *x = z[i];
            }
            let zs = &mut z[f..f + ns];
            for (&za, row) in t.iter().zip(u[ns * ns..].chunks_exact(ns)) {
                for (x, &v) in zs.iter_mut().zip(row) {
                    *x = *x - v * za;
                }
            }
            for k in (0..ns).rev() {
                let zk = zs[k] / u[k + k * ns];
                zs[k] = zk;
                for i in 0..k {
                    zs[i] = zs[i] - u[i + k * ns] * zk;
                }
            }
        }
    }
}

/// Columns eliminated together by [`partial_lu`] before the rest of the front is updated.
const BLOCK: usize = 32;

/// [`partial_lu`], compiled for AVX when the processor has it: four lanes per instruction in
/// the kernels' columns, the same operations in the same order (no fused multiply–add), so
/// the same bits on every processor (as `pdyn_expr::lu`'s Cholesky).
fn eliminate<T: Scalar>(
    front: &mut [T],
    m: usize,
    ns: usize,
    row_max: &[f64],
    floor: f64,
    symmetric: bool,
) -> Result<(), usize> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor has AVX (checked just above).
        return unsafe { partial_lu_avx(front, m, ns, row_max, floor, symmetric) };
    }
    partial_lu(front, m, ns, row_max, floor, symmetric)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn partial_lu_avx<T: Scalar>(
    front: &mut [T],
    m: usize,
    ns: usize,
    row_max: &[f64],
    floor: f64,
    symmetric: bool,
) -> Result<(), usize> {
    partial_lu(front, m, ns, row_max, floor, symmetric)
}

/// Eliminates the first `ns` pivots of the `m × m` front (column-major), `BLOCK` columns at a
/// time (right-looking, blocked): `L11`, `U11` in place of the diagonal block, `L21` below
/// it, `U12 = L11⁻¹ F12` right of it and the Schur complement `F22 − L21 U12` in place of
/// `F22`. `Err(k)` for a negligible pivot `k`. `symmetric`: row `k` of `U` is copied from
/// column `k` when pivot `k` is reached (`U = D Lᵀ`), and only the lower triangle of `F22` is
/// updated. Inlined (always) into [`partial_lu_avx`]: a call to it there would compile it
/// once, for the baseline's two lanes (the release build did so, and the "AVX" kernel ran in
/// SSE2).
#[inline(always)]
fn partial_lu<T: Scalar>(
    front: &mut [T],
    m: usize,
    ns: usize,
    row_max: &[f64],
    floor: f64,
    symmetric: bool,
) -> Result<(), usize> {
    let mut k0 = 0;
    while k0 < ns {
        let k1 = (k0 + BLOCK).min(ns);
        // The block's columns, unblocked, on every row below the diagonal.
        for k in k0..k1 {
            if symmetric {
                // Column k below the pivot is final: it is row k of U right of the pivot.
                for j in k + 1..m {
                    front[k + j * m] = front[j + k * m];
                }
            }
            let (left, right) = front.split_at_mut((k + 1) * m);
            let colk = &mut left[k * m..];
            let d = colk[k];
            let mag = d.magnitude();
            if !(mag.is_finite() && mag > floor * row_max[k]) {
                return Err(k);
            }
            let inv = T::ONE / d;
            for x in &mut colk[k + 1..] {
                *x = *x * inv;
            }
            let colk = &colk[..];
            for col in right.chunks_exact_mut(m).take(k1 - k - 1) {
                let u = col[k];
                for (x, &l) in col[k + 1..].iter_mut().zip(&colk[k + 1..]) {
                    *x = *x - l * u;
                }
            }
        }
        // The block's rows of U right of it: L(k0..k1, k0..k1)⁻¹ F(k0..k1, k1..) (copied
        // already when symmetric).
        let (left, right) = front.split_at_mut(k1 * m);
        for col in right.chunks_exact_mut(m).filter(|_| !symmetric) {
            for k in k0..k1 {
                let u = col[k];
                let l = &left[k * m..];
                for i in k + 1..k1 {
                    col[i] = col[i] - l[i] * u;
                }
            }
        }
        // The rest of the front: F(k1.., k1..) −= L(k1.., k0..k1) U(k0..k1, k1..).
        update(front, m, k0, k1, symmetric);
        k0 = k1;
    }
    Ok(())
}

/// `F(k1.., k1..) −= F(k1.., k0..k1) F(k0..k1, k1..)` on the `m × m` front, four columns at a
/// time (each entry of `L` loaded once for four multiply–adds); `lower`: only the rows from
/// each group's first column down (the lower triangle, and a few entries above it).
#[inline(always)]
fn update<T: Scalar>(front: &mut [T], m: usize, k0: usize, k1: usize, lower: bool) {
    let (left, right) = front.split_at_mut(k1 * m);
    let r = m - k1;
    let full = right.len() / (4 * m) * (4 * m);
    let (quads, rest) = right.split_at_mut(full);
    for (g, quad) in quads.chunks_exact_mut(4 * m).enumerate() {
        // The first row updated (relative to k1).
        let top = if lower { 4 * g } else { 0 };
        let (c0, quad) = quad.split_at_mut(m);
        let (c1, quad) = quad.split_at_mut(m);
        let (c2, c3) = quad.split_at_mut(m);
        let (u0, c0) = c0.split_at_mut(k1);
        let (u1, c1) = c1.split_at_mut(k1);
        let (u2, c2) = c2.split_at_mut(k1);
        let (u3, c3) = c3.split_at_mut(k1);
        for k in k0..k1 {
            let a = &left[k * m + k1..k * m + k1 + r];
            let (b0, b1, b2, b3) = (u0[k], u1[k], u2[k], u3[k]);
            let (c0, c1, c2, c3) = (&mut c0[..r], &mut c1[..r], &mut c2[..r], &mut c3[..r]);
            for i in top..r {
                let ai = a[i];
                c0[i] = c0[i] - ai * b0;
                c1[i] = c1[i] - ai * b1;
                c2[i] = c2[i] - ai * b2;
                c3[i] = c3[i] - ai * b3;
            }
        }
    }
    for (g, c) in rest.chunks_exact_mut(m).enumerate() {
        let top = if lower { full / m + g } else { 0 };
        let (u, c) = c.split_at_mut(k1);
        for k in k0..k1 {
            let a = &left[k * m + k1..(k + 1) * m];
            let b = u[k];
            for (x, &ai) in c[top..].iter_mut().zip(&a[top..]) {
                *x = *x - ai * b;
            }
        }
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_update_subtracts_as_the_plain_loops_to_the_bit() {
        // `F(i, j) −= Σ_k F(i, k) F(k, j)`, k = k0..k1 in order, entry by entry: the same
        // subtractions in the same order give the same bits, whatever the grouping of the
        // columns and the lanes (compiled for AVX or not). Fronts whose remaining side is and
        // is not a multiple of the four columns.
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for (m, k0, k1) in [(5, 0, 1), (20, 0, 3), (41, 4, 9), (77, 0, 32), (90, 32, 45)] {
            let front: Vec<f64> = (0..m * m).map(|_| next()).collect();
            for lower in [false, true] {
                let mut grouped = front.clone();
                update(&mut grouped, m, k0, k1, lower);
                let mut plain = front.clone();
                for j in k1..m {
                    for i in k1..m {
                        for k in k0..k1 {
                            plain[i + j * m] -= plain[i + k * m] * plain[k + j * m];
                        }
                    }
                }
                for j in k1..m {
                    // Lower: the rows from the diagonal down are the ones updated.
                    let from = if lower { j } else { k1 };
                    for i in from..m {
                        let (a, b) = (grouped[i + j * m], plain[i + j * m]);
                        assert_eq!(a.to_bits(), b.to_bits(), "m {m}, ({i}, {j}): {a} vs {b}");
                    }
                }
            }
        }
    }
}
