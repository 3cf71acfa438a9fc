//! Butcher tableaus as constant data, and a checker of the order conditions.
//!
//! A Runge–Kutta method with `s` stages advances `y_{n+1} = y_n + h Σ_i b_i k_i`,
//! `k_i = f(t_n + c_i h, y_n + h Σ_j a_ij k_j)`; an embedded solution uses `b̂` instead of `b`.
//! The method has order `p` when `Σ_i b_i Φ_i(τ) = 1/γ(τ)` for every rooted tree `τ` with at
//! most `p` vertices (Butcher 1963; Hairer, Nørsett & Wanner I, §II.2), where the elementary
//! weights satisfy `Φ(•) = 1` and `Φ_i([τ_1,…,τ_m]) = Π_k (A Φ(τ_k))_i`, and
//! `γ([τ_1,…,τ_m]) = |τ| Π_k γ(τ_k)`. [`order_residual`] enumerates the trees and returns the
//! largest residual, so each method's test checks its tableau against its claimed order.

/// An explicit or implicit Runge–Kutta tableau with `S` stages.
#[derive(Debug, Clone, Copy)]
pub struct Tableau<const S: usize> {
    /// Runge–Kutta matrix `a_ij` (row `i` = stage `i`).
    pub a: [[f64; S]; S],
    /// Weights of the propagated solution.
    pub b: [f64; S],
    /// Weights of the embedded solution (error estimate `h Σ (b_i − b̂_i) k_i`), if any.
    pub b_hat: Option<[f64; S]>,
    /// Nodes `c_i`.
    pub c: [f64; S],
    /// Order of `b`.
    pub order: u32,
    /// Order of `b̂` (0 when there is none).
    pub embedded_order: u32,
    /// First same as last: the last stage is `f(t + h, y_{n+1})`, reused as the next first stage.
    pub fsal: bool,
}

impl<const S: usize> Tableau<S> {
    /// Largest `|Σ_j a_ij − c_i|`.
    pub fn row_sum_residual(&self) -> f64 {
        (0..S)
            .map(|i| (self.a[i].iter().sum::<f64>() - self.c[i]).abs())
            .fold(0.0, f64::max)
    }

    /// The matrix as a vector of rows (for [`order_residual`]).
    pub fn a_rows(&self) -> Vec<Vec<f64>> {
        self.a.iter().map(|r| r.to_vec()).collect()
    }
}

/// Largest residual `|Σ b_i Φ_i(τ) − 1/γ(τ)|` over all rooted trees with at most `order`
/// vertices, for the weights `b` and matrix `a` (any size).
pub fn order_residual(a: &[Vec<f64>], b: &[f64], order: usize) -> f64 {
    let s = b.len();
    // trees[k] = (children indices (nondecreasing), order, gamma, Φ vector)
    let mut orders: Vec<usize> = Vec::new();
    let mut gammas: Vec<f64> = Vec::new();
    let mut phis: Vec<Vec<f64>> = Vec::new(); // Φ_i(τ)
    let mut worst: f64 = 0.0;
    for p in 1..=order {
        // all multisets of existing trees whose orders sum to p - 1
        let mut new_trees: Vec<Vec<usize>> = Vec::new();
        let mut cur = Vec::new();
        multisets(&orders, p - 1, 0, &mut cur, &mut new_trees);
        for children in new_trees {
            let mut phi = vec![1.0; s];
            let mut gamma = p as f64;
            for &ch in &children {
                gamma *= gammas[ch];
                for (i, ph) in phi.iter_mut().enumerate() {
                    let aphi: f64 = (0..s).map(|j| a[i][j] * phis[ch][j]).sum();
                    *ph *= aphi;
                }
            }
            let lhs: f64 = (0..s).map(|i| b[i] * phi[i]).sum();
            worst = worst.max((lhs - 1.0 / gamma).abs());
            orders.push(p);
            gammas.push(gamma);
            phis.push(phi);
        }
    }
    worst
}

/// Number of rooted trees with at most `order` vertices (1, 2, 4, 8, 17, 37, 85, 200, …).
pub fn tree_count(order: usize) -> usize {
    let mut orders: Vec<usize> = Vec::new();
    for p in 1..=order {
        let mut out = Vec::new();
        multisets(&orders, p - 1, 0, &mut Vec::new(), &mut out);
        orders.extend(std::iter::repeat_n(p, out.len()));
    }
    orders.len()
}

fn multisets(
    orders: &[usize],
    remaining: usize,
    start: usize,
    cur: &mut Vec<usize>,
    out: &mut Vec<Vec<usize>>,
) {
    if remaining == 0 {
        out.push(cur.clone());
        return;
    }
    for k in start..orders.len() {
        if orders[k] <= remaining {
            cur.push(k);
            multisets(orders, remaining - orders[k], k, cur, out);
            cur.pop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_counts_match_oeis_a000081_partial_sums() {
        let expected = [1, 2, 4, 8, 17, 37, 85, 200];
        for (p, &e) in expected.iter().enumerate() {
            assert_eq!(tree_count(p + 1), e);
        }
    }

    #[test]
    fn classical_rk4_has_order_four_not_five() {
        let a = vec![
            vec![0.0, 0.0, 0.0, 0.0],
            vec![0.5, 0.0, 0.0, 0.0],
            vec![0.0, 0.5, 0.0, 0.0],
            vec![0.0, 0.0, 1.0, 0.0],
        ];
        let b = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
        assert!(order_residual(&a, &b, 4) < 1e-15);
        assert!(order_residual(&a, &b, 5) > 1e-3);
    }
}
