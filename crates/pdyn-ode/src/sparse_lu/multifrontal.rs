//! The numeric phase of the supernodal multifrontal LU ([`super::supernodal`]): for each
//! supernode in postorder, its front (a dense `m × m` block, column-major) is assembled from
//! the matrix's entries and its children's update matrices, its `ns` pivots are eliminated
//! with dense kernels (no pivoting), the `L` and `U` blocks are kept and the Schur
//! complement goes on the stack for the parent. Real and complex alike (`T`).

use super::scalar::Scalar;
use super::supernodal::Supernodes;

/// The numeric factors of one matrix on a [`Supernodes`] structure.
#[derive(Debug)]
pub(crate) struct Numeric<T> {
    lu: Vec<T>,
    front: Vec<T>,
    stack: Vec<T>,
    row_max: Vec<f64>,
}

impl<T: Scalar> Numeric<T> {
    pub(crate) fn new(sn: &Supernodes) -> Self {
        Numeric {
            lu: vec![T::ZERO; sn.lu_start[sn.len()]],
            front: vec![T::ZERO; sn.max_front * sn.max_front],
            stack: Vec::with_capacity(sn.max_stack),
            row_max: vec![0.0; sn.n],
        }
    }

    /// Factors the matrix with values `vals` (the analysed pattern's order); `Err(k)` when
    /// pivot `k` (permuted) is zero, not finite, or below `floor` times its row's largest
    /// entry.
    pub(crate) fn factor(&mut self, sn: &Supernodes, vals: &[T], floor: f64) -> Result<(), usize> {
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
            partial_lu(front, m, ns, &self.row_max[f..f + ns], floor).map_err(|k| f + k)?;
            schur(front, m, ns);
            let off = sn.lu_start[s];
            self.lu[off..off + m * ns].copy_from_slice(&front[..m * ns]);
            let u12 = &mut self.lu[off + m * ns..off + m * ns + ns * r];
            for j in 0..r {
                u12[j * ns..j * ns + ns].copy_from_slice(&front[(ns + j) * m..(ns + j) * m + ns]);
            }
            for j in 0..r {
                self.stack
                    .extend_from_slice(&front[(ns + j) * m + ns..(ns + j + 1) * m]);
            }
        }
        Ok(())
    }

    /// Solves `A z = b` in place, `z` in the permuted order.
    pub(crate) fn solve_permuted(&self, sn: &Supernodes, z: &mut [T]) {
        for s in 0..sn.len() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let rows = &sn.rows[sn.row_start[s]..sn.row_start[s + 1]];
            let m = ns + rows.len();
            let l = &self.lu[sn.lu_start[s]..sn.lu_start[s] + m * ns];
            for k in 0..ns {
                let zk = z[f + k];
                let col = &l[k * m..k * m + m];
                for i in k + 1..ns {
                    z[f + i] = z[f + i] - col[i] * zk;
                }
                for (&i, &v) in rows.iter().zip(&col[ns..]) {
                    z[i] = z[i] - v * zk;
                }
            }
        }
        for s in (0..sn.len()).rev() {
            let (f, ns) = (sn.first[s], sn.first[s + 1] - sn.first[s]);
            let rows = &sn.rows[sn.row_start[s]..sn.row_start[s + 1]];
            let m = ns + rows.len();
            let off = sn.lu_start[s];
            let u = &self.lu[off..off + m * ns];
            let u12 = &self.lu[off + m * ns..off + m * ns + ns * rows.len()];
            for (a, &i) in rows.iter().enumerate() {
                let zi = z[i];
                for (k, &v) in u12[a * ns..a * ns + ns].iter().enumerate() {
                    z[f + k] = z[f + k] - v * zi;
                }
            }
            for k in (0..ns).rev() {
                let zk = z[f + k] / u[k + k * m];
                z[f + k] = zk;
                for i in 0..k {
                    z[f + i] = z[f + i] - u[i + k * m] * zk;
                }
            }
        }
    }
}

/// Eliminates the first `ns` pivots of the `m × m` front (column-major): `L11`, `U11` in
/// place of the diagonal block, `L21` below it, `U12 = L11⁻¹ F12` right of it. `Err(k)` for
/// a negligible pivot `k`.
fn partial_lu<T: Scalar>(
    front: &mut [T],
    m: usize,
    ns: usize,
    row_max: &[f64],
    floor: f64,
) -> Result<(), usize> {
    for k in 0..ns {
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
        // Columns of the panel: every row below k; columns right of it: the rows of U12.
        for (jj, col) in right.chunks_exact_mut(m).enumerate() {
            let u = col[k];
            let end = if k + 1 + jj < ns { m } else { ns };
            for (x, &l) in col[k + 1..end].iter_mut().zip(&colk[k + 1..end]) {
                *x = *x - l * u;
            }
        }
    }
    Ok(())
}

/// The Schur complement `F22 −= L21 U12` of the front, four columns at a time (each entry
/// of `L21` loaded once for four multiply–adds).
fn schur<T: Scalar>(front: &mut [T], m: usize, ns: usize) {
    let (left, right) = front.split_at_mut(ns * m);
    let r = m - ns;
    let full = right.len() / (4 * m) * (4 * m);
    let (quads, rest) = right.split_at_mut(full);
    for quad in quads.chunks_exact_mut(4 * m) {
        let (c0, quad) = quad.split_at_mut(m);
        let (c1, quad) = quad.split_at_mut(m);
        let (c2, c3) = quad.split_at_mut(m);
        let (u0, c0) = c0.split_at_mut(ns);
        let (u1, c1) = c1.split_at_mut(ns);
        let (u2, c2) = c2.split_at_mut(ns);
        let (u3, c3) = c3.split_at_mut(ns);
        for k in 0..ns {
            let a = &left[k * m + ns..k * m + ns + r];
            let (b0, b1, b2, b3) = (u0[k], u1[k], u2[k], u3[k]);
            let (c0, c1, c2, c3) = (&mut c0[..r], &mut c1[..r], &mut c2[..r], &mut c3[..r]);
            for i in 0..r {
                let ai = a[i];
                c0[i] = c0[i] - ai * b0;
                c1[i] = c1[i] - ai * b1;
                c2[i] = c2[i] - ai * b2;
                c3[i] = c3[i] - ai * b3;
            }
        }
    }
    for c in rest.chunks_exact_mut(m) {
        let (u, c) = c.split_at_mut(ns);
        for k in 0..ns {
            let a = &left[k * m + ns..(k + 1) * m];
            let b = u[k];
            for (x, &ai) in c.iter_mut().zip(a) {
                *x = *x - ai * b;
            }
        }
    }
}
