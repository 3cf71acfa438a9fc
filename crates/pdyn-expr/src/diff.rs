//! Differentiation: partial derivatives with respect to any leaf, and the total time
//! derivative by the chain rule.
//!
//! The total derivative is `d/dt f = ∂f/∂t + Σ_q Σ_k q^(k+1) ∂f/∂q^(k)`, computed in one pass:
//! each leaf maps to its own time derivative (`t → 1`, `x^(k) → x^(k+1)`, parameters → 0)
//! and the usual rules combine them. Results are memoised per pool, so differentiating a
//! shared subexpression twice costs nothing.

use crate::budget::{BudgetError, MAX_DERIVATIVE_NODES};
use crate::number::{Number, MAX_BITS};
use crate::pool::{Func, Id, Node, Pool};
use rustc_hash::FxHashMap;

impl Pool {
    /// Total time derivative `d/dt`.
    pub fn dt(&mut self, e: Id) -> Id {
        self.derive(e, Pool::ZERO, true)
    }

    /// `k`-th total time derivative.
    pub fn dt_n(&mut self, e: Id, k: usize) -> Id {
        (0..k).fold(e, |acc, _| self.dt(acc))
    }

    /// The `n`-th derivative of `e`, in time (`var = None`) or with respect to the leaf `var`,
    /// under a budget: at most [`MAX_DERIVATIVE_NODES`] new nodes in all, and coefficients
    /// within the size of exact numbers. Repetition is detected, so `sin(x)` or `exp(t)`
    /// differentiated 100,000 times costs a few steps.
    pub fn try_derivative_n(
        &mut self,
        e: Id,
        var: Option<Id>,
        n: usize,
    ) -> Result<Id, BudgetError> {
        // In time, each derivative raises the order of the coordinates (`t^2` has none: its
        // derivatives may go on).
        if var.is_none() && self.has_coord(e) {
            let order = self.max_coord_order(e).saturating_add(n);
            if order > crate::budget::MAX_COORD_ORDER {
                return Err(BudgetError::CoordinateOrder { order });
            }
        }
        let start = self.len();
        // Each derivative seen, with its order: a repeat means the sequence is periodic from
        // there on (sin → cos → -sin → -cos → sin; exp → exp; 0 → 0).
        let mut seen: FxHashMap<Id, usize> = FxHashMap::default();
        let mut history = vec![e];
        seen.insert(e, 0);
        let mut cur = e;
        for k in 1..=n {
            let before = self.len();
            cur = match var {
                None => self.dt(cur),
                Some(v) => self.diff(cur, v),
            };
            if self.len() - start > MAX_DERIVATIVE_NODES {
                return Err(BudgetError::DerivativeSize {
                    order: k,
                    limit: MAX_DERIVATIVE_NODES,
                });
            }
            // Only nodes created by this step can hold new coefficients.
            let too_big = (before..self.len()).any(|i| {
                matches!(self.node(Id(i as u32)), Node::Num(Number::Rat(r)) if r.bits() > MAX_BITS)
            });
            if too_big {
                return Err(BudgetError::DerivativeNumbers { order: k });
            }
            if let Some(&j) = seen.get(&cur) {
                let period = k - j;
                return Ok(history[j + (n - j) % period]);
            }
            seen.insert(cur, k);
            history.push(cur);
        }
        Ok(cur)
    }

    /// `∂e/∂v` for every `v` in `vars` (leaves), read off the terms of `e` in one pass when `e`
    /// is, as built, linear in them: a sum of terms each free of `vars` or the product of one
    /// of them (to the first power) with factors free of `vars`; velocities are linear in the
    /// rates this way. `None` otherwise (then use [`Pool::diff`] per variable). The results
    /// are the canonical expressions `diff` builds for such terms, at O(size of `e`) for all
    /// variables together instead of O(size) per variable: the partial velocities of the
    /// 100-link chain took a fifth of `pdyn run`'s preparation by `diff`.
    pub fn linear_coefficients(&mut self, e: Id, vars: &[Id]) -> Option<Vec<Id>> {
        let index: FxHashMap<Id, usize> = vars.iter().enumerate().map(|(i, &v)| (v, i)).collect();
        let order = self.topo_order(&[e]);
        let mut mentions: FxHashMap<Id, bool> = FxHashMap::default();
        for &x in &order {
            let mut m = index.contains_key(&x);
            self.for_each_child(x, |c| m = m || mentions[&c]);
            mentions.insert(x, m);
        }
        let terms: Vec<Id> = match self.node(e) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![e],
        };
        let mut parts: Vec<Vec<Id>> = vec![Vec::new(); vars.len()];
        for t in terms {
            if !mentions[&t] {
                continue;
            }
            if let Some(&i) = index.get(&t) {
                parts[i].push(Pool::ONE);
                continue;
            }
            let Node::Mul(fs) = self.node(t) else {
                return None;
            };
            let fs = fs.to_vec();
            let mut var = None;
            for (k, f) in fs.iter().enumerate() {
                if mentions[f] {
                    match (var, index.get(f)) {
                        (None, Some(&i)) => var = Some((k, i)),
                        _ => return None,
                    }
                }
            }
            let (k, i) = var?;
            let rest: Vec<Id> = fs
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != k)
                .map(|(_, &f)| f)
                .collect();
            let c = self.mul(&rest);
            parts[i].push(c);
        }
        Some(parts.iter().map(|ps| self.add(ps)).collect())
    }

    /// Partial derivative with respect to the leaf `var` (a symbol, a coordinate or one of its
    /// derivatives, or `t`). Every other leaf is held constant.
    ///
    /// # Panics
    /// Never; a `var` that is not a leaf simply gives 0 unless it occurs as a whole node, in
    /// which case that node is treated as the variable.
    pub fn diff(&mut self, e: Id, var: Id) -> Id {
        self.derive(e, var, false)
    }

    /// Derivatives of nodes formed on this pool so far (each remembered): a deterministic
    /// measure of differentiation work, for regression tests.
    pub fn derivative_work(&self) -> usize {
        self.memo.diff.len()
    }

    fn derive(&mut self, e: Id, var: Id, total: bool) -> Id {
        if let Some(&d) = self.memo.diff.get(&(e, var, total)) {
            return d;
        }
        // Iterative post-order over the DAG so that deep expressions cannot overflow the stack.
        // What is memoised was derived with everything below it: walking it again made the
        // velocities and accelerations of a chain's particles, which share all but their last
        // link, quadratic in its length.
        let memo = &self.memo.diff;
        let order = self.topo_order_pruned(&[e], |n| memo.contains_key(&(n, var, total)));
        for &n in &order {
            let d = self.derive_node(n, var, total);
            self.memo.diff.insert((n, var, total), d);
        }
        self.memo.diff[&(e, var, total)]
    }

    fn d(&self, n: Id, var: Id, total: bool) -> Id {
        self.memo.diff[&(n, var, total)]
    }

    fn derive_node(&mut self, n: Id, var: Id, total: bool) -> Id {
        if !total && n == var {
            return Pool::ONE;
        }
        match self.node(n).clone() {
            Node::Num(_) | Node::Const(_) | Node::Sym(_) => Pool::ZERO,
            Node::Time => {
                if total {
                    Pool::ONE
                } else {
                    Pool::ZERO
                }
            }
            Node::Coord(s, k) => {
                if total {
                    self.coord(s, k.saturating_add(1))
                } else {
                    Pool::ZERO
                }
            }
            Node::Add(ts) => {
                let ds: Vec<Id> = ts.iter().map(|&t| self.d(t, var, total)).collect();
                self.add(&ds)
            }
            Node::Mul(fs) => {
                let mut terms = Vec::with_capacity(fs.len());
                for i in 0..fs.len() {
                    let di = self.d(fs[i], var, total);
                    if di == Pool::ZERO {
                        continue;
                    }
                    let mut prod: Vec<Id> = fs.to_vec();
                    prod[i] = di;
                    terms.push(self.mul(&prod));
                }
                self.add(&terms)
            }
            Node::Pow(b, e) => {
                let db = self.d(b, var, total);
                let de = self.d(e, var, total);
                let mut terms = Vec::new();
                if db != Pool::ZERO {
                    // e * b^(e-1) * b'
                    let em1 = self.add2(e, Pool::MINUS_ONE);
                    let p = self.pow(b, em1);
                    terms.push(self.mul(&[e, p, db]));
                }
                if de != Pool::ZERO {
                    // b^e * log(b) * e'
                    let lb = self.call(Func::Log, &[b]);
                    terms.push(self.mul(&[n, lb, de]));
                }
                self.add(&terms)
            }
            Node::Call(f, args) => {
                let u = args[0];
                let du = self.d(u, var, total);
                if f.arity() == 1 && du == Pool::ZERO {
                    return Pool::ZERO;
                }
                let outer = match f {
                    // A measured column's derivative is its interpolant's (piecewise
                    // constant for linear interpolation); zero past its degree.
                    Func::Table(t) => self.tabulated(t.table, t.order + 1, u),
                    Func::Sin => self.call(Func::Cos, &[u]),
                    Func::Cos => {
                        let s = self.call(Func::Sin, &[u]);
                        self.neg(s)
                    }
                    Func::Tan => {
                        let c = self.call(Func::Cos, &[u]);
                        self.powi(c, -2)
                    }
                    Func::Asin | Func::Acos => {
                        let u2 = self.powi(u, 2);
                        let one_minus = self.sub(Pool::ONE, u2);
                        let mh = self.num(Number::ratio(-1, 2));
                        let r = self.pow(one_minus, mh);
                        if f == Func::Acos {
                            self.neg(r)
                        } else {
                            r
                        }
                    }
                    Func::Atan => {
                        let u2 = self.powi(u, 2);
                        let s = self.add2(Pool::ONE, u2);
                        self.powi(s, -1)
                    }
                    Func::Sinh => self.call(Func::Cosh, &[u]),
                    Func::Cosh => self.call(Func::Sinh, &[u]),
                    Func::Tanh => {
                        let c = self.call(Func::Cosh, &[u]);
                        self.powi(c, -2)
                    }
                    Func::Exp => n,
                    Func::Log => self.powi(u, -1),
                    Func::Abs => self.call(Func::Sign, &[u]),
                    Func::Sign => Pool::ZERO,
                    Func::Atan2 => {
                        // atan2(y, x)' = (x y' - y x') / (x^2 + y^2)
                        let x = args[1];
                        let dx = self.d(x, var, total);
                        let a = self.mul2(x, du);
                        let b = self.mul2(u, dx);
                        let num = self.sub(a, b);
                        let x2 = self.powi(x, 2);
                        let y2 = self.powi(u, 2);
                        let den = self.add2(x2, y2);
                        return self.div(num, den);
                    }
                    Func::Min | Func::Max => {
                        // min(a,b) = (a+b)/2 - |a-b|/2, max(a,b) = (a+b)/2 + |a-b|/2
                        let v = args[1];
                        let dv = self.d(v, var, total);
                        let half = self.num(Number::ratio(1, 2));
                        let sum = self.add2(du, dv);
                        let avg = self.mul2(half, sum);
                        let diff = self.sub(u, v);
                        let sg = self.call(Func::Sign, &[diff]);
                        let ddiff = self.sub(du, dv);
                        let mut corr = self.mul(&[half, sg, ddiff]);
                        if f == Func::Min {
                            corr = self.neg(corr);
                        }
                        return self.add2(avg, corr);
                    }
                };
                self.mul2(outer, du)
            }
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn linear_coefficients_are_the_partial_derivatives() {
        use crate::pool::{Id, Pool};
        let mut p = Pool::new();
        let vars: Vec<Id> = ["u", "v", "w"].iter().map(|n| p.var(n)).collect();
        for src in [
            "l1*u*cos(q1) + l2*v*cos(q2) - 3*u*sin(q1)/m + 7",
            "-u",
            "u",
            "2*a*(b + c)*w + u*v^0",
            "sin(q) + k",
        ] {
            let e = p.parse_scalar(src).unwrap();
            let cs = p.linear_coefficients(e, &vars).expect(src);
            for (i, &v) in vars.iter().enumerate() {
                assert_eq!(cs[i], p.diff(e, v), "{src}: d/d{}", p.to_text(v));
            }
        }
        // Not linear as built: a product of two variables, a power, a variable inside a
        // function or a sum factor.
        for src in ["u*v", "u^2", "sin(u)", "(u + 1)*a", "a/(u + 1)"] {
            let e = p.parse_scalar(src).unwrap();
            assert_eq!(p.linear_coefficients(e, &vars), None, "{src}");
        }
    }

    #[test]
    fn high_order_derivatives_are_bounded() {
        use crate::budget::BudgetError;
        use crate::pool::Pool;
        let mut p = Pool::new();
        let x = p.var("x");
        // Periodic and fixed-point sequences: found in a few steps, exactly.
        let s = p.parse_scalar("sin(x)").unwrap();
        let d = p.try_derivative_n(s, Some(x), 100_000).unwrap();
        assert_eq!(
            d, s,
            "the 100000th derivative of sin is sin (100000 = 0 mod 4)"
        );
        let d = p.try_derivative_n(s, Some(x), 100_001).unwrap();
        assert_eq!(d, p.parse_scalar("cos(x)").unwrap());
        let c = p.parse_scalar("x^3").unwrap();
        assert_eq!(p.try_derivative_n(c, Some(x), 100_000), Ok(Pool::ZERO));
        // Growing coefficients: (10^40)^k passes 100,000 digits at k = 2,500.
        let big = p.parse_scalar("x^(10^40)").unwrap();
        assert_eq!(
            p.try_derivative_n(big, Some(x), 100_000),
            Err(BudgetError::DerivativeNumbers { order: 2_500 })
        );
        // Growing expressions: the k-th derivative of exp(x^2) has about k terms.
        let g = p.parse_scalar("exp(x^2)*sin(x^3)").unwrap();
        assert!(matches!(
            p.try_derivative_n(g, Some(x), 100_000),
            Err(BudgetError::DerivativeSize { .. })
        ));
        // Within the budget, the same as repeated differentiation.
        let f = p.parse_scalar("x^2*sin(x)").unwrap();
        let mut r = f;
        for _ in 0..5 {
            r = p.diff(r, x);
        }
        assert_eq!(p.try_derivative_n(f, Some(x), 5), Ok(r));
    }

    use crate::pool::Pool;

    #[test]
    fn chain_rule_in_time() {
        let mut p = Pool::new();
        let e = p.parse_scalar("R*cos(th')").unwrap();
        let d = p.dt(e);
        assert_eq!(d, p.parse_scalar("-R*th''*sin(th')").unwrap());
        let e = p.parse_scalar("x(t)^2 + t^3").unwrap();
        let d = p.parse_scalar("2*x*x' + 3*t^2").unwrap();
        assert_eq!(p.dt(e), d);
        let s = p.parse_scalar("x^2").unwrap();
        assert_eq!(
            p.dt(s),
            Pool::ZERO,
            "a name never written as x' or x(t) is a constant"
        );
    }

    #[test]
    fn partials_hold_other_leaves_fixed() {
        let mut p = Pool::new();
        let e = p.parse_scalar("a*x'^2 + x*t").unwrap();
        let xd = p.parse_scalar("x'").unwrap();
        let d = p.diff(e, xd);
        assert_eq!(d, p.parse_scalar("2*a*x'").unwrap());
        let t = p.time();
        let d = p.diff(e, t);
        assert_eq!(d, p.parse_scalar("x(t)").unwrap());
    }
}
