//! Differentiation: partial derivatives with respect to any leaf, and the total time
//! derivative by the chain rule.
//!
//! The total derivative is `d/dt f = ∂f/∂t + Σ_q Σ_k q^(k+1) ∂f/∂q^(k)`, computed in one pass:
//! each leaf maps to its own time derivative (`t → 1`, `x^(k) → x^(k+1)`, parameters → 0)
//! and the usual rules combine them. Results are memoised per pool, so differentiating a
//! shared subexpression twice costs nothing.

use crate::number::Number;
use crate::pool::{Func, Id, Node, Pool};

impl Pool {
    /// Total time derivative `d/dt`.
    pub fn dt(&mut self, e: Id) -> Id {
        self.derive(e, Pool::ZERO, true)
    }

    /// `k`-th total time derivative.
    pub fn dt_n(&mut self, e: Id, k: usize) -> Id {
        (0..k).fold(e, |acc, _| self.dt(acc))
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

    fn derive(&mut self, e: Id, var: Id, total: bool) -> Id {
        if let Some(&d) = self.memo.diff.get(&(e, var, total)) {
            return d;
        }
        // Iterative post-order over the DAG so that deep expressions cannot overflow the stack.
        let order = self.topo_order(&[e]);
        for &n in &order {
            if self.memo.diff.contains_key(&(n, var, total)) {
                continue;
            }
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
