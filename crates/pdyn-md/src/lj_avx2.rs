//! The cluster-pair kernel for Lennard-Jones (plain or energy-shifted cutoff) written with
//! AVX2 intrinsics, for CPUs that have them (chosen at run time in `forces.rs`).
//!
//! It performs the operations of the portable kernel (`forces::kernel` with
//! `Truncated<LennardJones>`), in the same order and without fused multiply-add: per row,
//! `d = xᵢ − xⱼ`, `r² = (dx² + dy²) + dz²`, `1/r²`, `s = σ²/r²`, `s⁶ = (s·s)·s`,
//! `f/r = ((24ε·s⁶)(2s⁶ − 1))/r²` and, when energies are asked for, `u = (4ε·s⁶)(s⁶ − 1) − u_c`
//! and the virial, both cleared bit by bit outside the cutoff and below the diagonal, then the
//! same sums. (The portable kernel evaluates the lanes outside the cutoff at `r_c` before
//! clearing them; here they are evaluated where they are, which changes nothing that is kept.)
//! Each operation is exactly rounded IEEE arithmetic, so the two give the same bits (test
//! `avx2_and_portable_kernels_agree_bit_for_bit`).

use crate::forces::ListView;
use crate::neighbor::{ClusterVec, Segment, CL};
use crate::potential::LjConstants;
use std::arch::x86_64::*;

/// The entries of one segment into `buf` (zeroed by the caller); returns the segment's
/// energy and virial (zero without `ENERGY`, which leaves their sums out).
#[target_feature(enable = "avx2")]
pub(crate) fn kernel<const ENERGY: bool>(
    v: ListView,
    seg: &Segment,
    buf: &mut [ClusterVec],
    c: LjConstants,
) -> (f64, f64) {
    let rc2 = _mm256_set1_pd(c.rc * c.rc);
    let one = _mm256_set1_pd(1.0);
    let two = _mm256_set1_pd(2.0);
    let sigma2 = _mm256_set1_pd(c.sigma2);
    let eps4 = _mm256_set1_pd(c.eps4);
    let eps24 = _mm256_set1_pd(c.eps24);
    let u_c = _mm256_set1_pd(c.u_c);
    // lanes l > a of row a (the diagonal cluster pair counts a < b only)
    let upper = |a: i64| {
        let m = |l: i64| if l > a { -1 } else { 0 };
        _mm256_castsi256_pd(_mm256_set_epi64x(m(3), m(2), m(1), m(0)))
    };
    let diag_mask = [upper(0), upper(1), upper(2), upper(3)];
    let mut e = _mm256_setzero_pd();
    let mut w = _mm256_setzero_pd();
    let load = |x: &[f64; CL]| {
        // SAFETY: `x` is four f64 in a row
        unsafe { _mm256_loadu_pd(x.as_ptr()) }
    };
    for ent in &v.entries[seg.entries.clone()] {
        let ci = ent.ci as usize;
        let mut xi = v.xc[ci];
        for (k, row) in xi.iter_mut().enumerate() {
            for x in row.iter_mut() {
                *x += ent.shift[k];
            }
        }
        let mut fi = [[_mm256_setzero_pd(); 3]; CL];
        let (j0, j1) = (ent.js.0 as usize, ent.js.1 as usize);
        for jj in j0..j1 {
            let xj = &v.xc[v.jglobal[jj] as usize];
            let xj = [load(&xj[0]), load(&xj[1]), load(&xj[2])];
            let diag = ent.diag && jj == j0;
            let mut fj = [_mm256_setzero_pd(); 3];
            macro_rules! row {
                ($a:literal) => {{
                    let dx = _mm256_sub_pd(_mm256_set1_pd(xi[0][$a]), xj[0]);
                    let dy = _mm256_sub_pd(_mm256_set1_pd(xi[1][$a]), xj[1]);
                    let dz = _mm256_sub_pd(_mm256_set1_pd(xi[2][$a]), xj[2]);
                    let r2 = _mm256_add_pd(
                        _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                        _mm256_mul_pd(dz, dz),
                    );
                    let mut inside = _mm256_cmp_pd::<_CMP_LT_OQ>(r2, rc2);
                    if diag {
                        inside = _mm256_and_pd(inside, diag_mask[$a]);
                    }
                    // lanes outside are cleared bit by bit below (an infinity or NaN of a
                    // particle paired with itself included), so they need no clamping
                    let inv = _mm256_div_pd(one, r2);
                    let s2 = _mm256_mul_pd(sigma2, inv);
                    let s6 = _mm256_mul_pd(_mm256_mul_pd(s2, s2), s2);
                    let fr = _mm256_mul_pd(
                        _mm256_mul_pd(
                            _mm256_mul_pd(eps24, s6),
                            _mm256_sub_pd(_mm256_mul_pd(two, s6), one),
                        ),
                        inv,
                    );
                    let fr = _mm256_and_pd(fr, inside);
                    let fx = _mm256_mul_pd(fr, dx);
                    let fy = _mm256_mul_pd(fr, dy);
                    let fz = _mm256_mul_pd(fr, dz);
                    fi[$a][0] = _mm256_add_pd(fi[$a][0], fx);
                    fi[$a][1] = _mm256_add_pd(fi[$a][1], fy);
                    fi[$a][2] = _mm256_add_pd(fi[$a][2], fz);
                    fj[0] = _mm256_add_pd(fj[0], fx);
                    fj[1] = _mm256_add_pd(fj[1], fy);
                    fj[2] = _mm256_add_pd(fj[2], fz);
                    if ENERGY {
                        let u = _mm256_mul_pd(_mm256_mul_pd(eps4, s6), _mm256_sub_pd(s6, one));
                        let u = _mm256_and_pd(_mm256_sub_pd(u, u_c), inside);
                        e = _mm256_add_pd(e, u);
                        w = _mm256_add_pd(w, _mm256_mul_pd(fr, r2));
                    }
                }};
            }
            const _: () = assert!(CL == 4);
            row!(0);
            row!(1);
            row!(2);
            row!(3);
            let b = &mut buf[v.jlocal[jj] as usize];
            for k in 0..3 {
                let p = b[k].as_mut_ptr();
                // SAFETY: `p` points to four f64 of `b[k]`
                unsafe { _mm256_storeu_pd(p, _mm256_sub_pd(_mm256_loadu_pd(p), fj[k])) };
            }
        }
        let b = &mut buf[ci - seg.lo];
        for (a, f) in fi.iter().enumerate() {
            for k in 0..3 {
                let l = lanes(f[k]);
                b[k][a] += (l[0] + l[1]) + (l[2] + l[3]);
            }
        }
    }
    let (e, w) = (lanes(e), lanes(w));
    ((e[0] + e[1]) + (e[2] + e[3]), (w[0] + w[1]) + (w[2] + w[3]))
}

#[inline(always)]
fn lanes(x: __m256d) -> [f64; 4] {
    let mut a = [0.0; 4];
    // SAFETY: `a` holds four f64
    unsafe { _mm256_storeu_pd(a.as_mut_ptr(), x) };
    a
}
