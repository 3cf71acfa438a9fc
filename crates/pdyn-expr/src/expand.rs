//! Expansion: products distributed over sums and positive integer powers of sums multiplied
//! out, everywhere in the expression (function arguments included). Denominators keep their
//! sums but have their insides expanded.
//!
//! The work is bounded ([`crate::budget`]): no sum produced may exceed
//! [`MAX_EXPAND_TERMS`] terms and one expansion forms at most [`MAX_EXPAND_PRODUCTS`] products
//! of terms. [`Pool::try_expand`] reports reaching a limit as a [`BudgetError`];
//! [`Pool::expand`], used inside derivations where expanding is only a normalisation, keeps
//! the parts over the limit factored instead (equal, just not expanded).

use crate::budget::{BudgetError, MAX_EXPAND_PRODUCTS, MAX_EXPAND_TERMS};
use crate::pool::{Id, Node, Pool};
use rustc_hash::FxHashMap;

/// Work counter of one expansion.
struct Work {
    products: usize,
}

impl Work {
    fn new() -> Work {
        Work { products: 0 }
    }
    fn spend(&mut self, products: usize) -> Result<(), BudgetError> {
        self.products = self.products.saturating_add(products);
        if self.products > MAX_EXPAND_PRODUCTS || products > MAX_EXPAND_TERMS * 4 {
            return Err(BudgetError::ExpandTerms {
                limit: MAX_EXPAND_TERMS,
            });
        }
        Ok(())
    }
}

impl Pool {
    /// Expands products and integer powers of sums, or says which limit it reached.
    pub fn try_expand(&mut self, e: Id) -> Result<Id, BudgetError> {
        let mut work = Work::new();
        self.expand_in(e, &mut work)
    }

    /// Expands products and integer powers of sums; a part whose expansion would exceed the
    /// limits of [`Pool::try_expand`] is kept factored (the result is equal either way).
    pub fn expand(&mut self, e: Id) -> Id {
        if let Ok(r) = self.try_expand(e) {
            return r;
        }
        // Node by node, each with its own budget: everything that can be expanded is.
        let mut local: FxHashMap<Id, Id> = FxHashMap::default();
        for n in self.topo_order(&[e]) {
            if let Some(&r) = self.memo.expand.get(&n) {
                local.insert(n, r);
                continue;
            }
            let mut work = Work::new();
            let r = match self.expand_node(n, &|x| local[&x], &mut work) {
                Ok(r) => r,
                Err(_) => self.rebuild(n, &|x| local[&x]),
            };
            local.insert(n, r);
        }
        local[&e]
    }

    /// Strict expansion with a shared work counter; complete results are memoised.
    fn expand_in(&mut self, e: Id, work: &mut Work) -> Result<Id, BudgetError> {
        if let Some(&r) = self.memo.expand.get(&e) {
            return Ok(r);
        }
        for n in self.topo_order(&[e]) {
            if self.memo.expand.contains_key(&n) {
                continue;
            }
            let memo = std::mem::take(&mut self.memo.expand);
            let r = self.expand_node(n, &|x| memo[&x], work);
            self.memo.expand = memo;
            self.memo.expand.insert(n, r?);
        }
        Ok(self.memo.expand[&e])
    }

    /// `n` rebuilt from the given images of its children, without expanding it.
    fn rebuild(&mut self, n: Id, image: &dyn Fn(Id) -> Id) -> Id {
        match self.node(n).clone() {
            Node::Add(ts) => {
                let ts: Vec<Id> = ts.iter().map(|&t| image(t)).collect();
                self.add(&ts)
            }
            Node::Mul(fs) => {
                let fs: Vec<Id> = fs.iter().map(|&f| image(f)).collect();
                self.mul(&fs)
            }
            Node::Pow(b, e) => {
                let (b, e) = (image(b), image(e));
                self.pow(b, e)
            }
            Node::Call(f, args) => {
                let args: Vec<Id> = args.iter().map(|&a| image(a)).collect();
                self.call(f, &args)
            }
            _ => n,
        }
    }

    fn expand_node(
        &mut self,
        n: Id,
        expanded: &dyn Fn(Id) -> Id,
        work: &mut Work,
    ) -> Result<Id, BudgetError> {
        Ok(match self.node(n).clone() {
            Node::Num(_) | Node::Const(_) | Node::Time | Node::Sym(_) | Node::Coord(..) => n,
            Node::Add(ts) => {
                let ts: Vec<Id> = ts.iter().map(|&t| expanded(t)).collect();
                self.add(&ts)
            }
            Node::Mul(fs) => {
                let fs: Vec<Id> = fs.iter().map(|&f| expanded(f)).collect();
                let mut acc = Pool::ONE;
                for f in fs {
                    acc = self.distribute(acc, f, work)?;
                }
                acc
            }
            Node::Pow(b, e) => {
                let b = expanded(b);
                let e = expanded(e);
                match self.as_num(e).and_then(|x| x.as_integer()) {
                    // Negative powers are denominators: kept as they are.
                    Some(k) if k > 1 && matches!(self.node(b), Node::Add(_)) => {
                        let mut acc = b;
                        for _ in 1..k {
                            acc = self.distribute(acc, b, work)?;
                        }
                        acc
                    }
                    _ => self.pow(b, e),
                }
            }
            Node::Call(f, args) => {
                let args: Vec<Id> = args.iter().map(|&a| expanded(a)).collect();
                self.call(f, &args)
            }
        })
    }

    /// `a * b` with both sides already expanded, distributed term by term.
    fn distribute(&mut self, a: Id, b: Id, work: &mut Work) -> Result<Id, BudgetError> {
        let ta: Vec<Id> = match self.node(a) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![a],
        };
        let tb: Vec<Id> = match self.node(b) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![b],
        };
        if ta.len() == 1 && tb.len() == 1 {
            let m = self.mul2(a, b);
            // A numeric coefficient times a sum is distributed by `mul` itself; a product can
            // still produce a power of a sum, e.g. (a+b)*(a+b) = (a+b)^2.
            return match self.node(m) {
                Node::Pow(base, _) if matches!(self.node(*base), Node::Add(_)) => {
                    self.expand_in(m, work)
                }
                _ => Ok(m),
            };
        }
        work.spend(ta.len() * tb.len())?;
        let mut terms = Vec::with_capacity(ta.len() * tb.len());
        for &x in &ta {
            for &y in &tb {
                terms.push(self.distribute(x, y, work)?);
            }
        }
        let sum = self.add(&terms);
        if matches!(self.node(sum), Node::Add(ts) if ts.len() > MAX_EXPAND_TERMS) {
            return Err(BudgetError::ExpandTerms {
                limit: MAX_EXPAND_TERMS,
            });
        }
        Ok(sum)
    }
}

#[cfg(test)]
mod tests {
    use crate::pool::Pool;

    #[test]
    fn expands_products_and_powers() {
        let mut p = Pool::new();
        let e = p.parse_scalar("(a + b)^2 - a*(a + 2*b)").unwrap();
        assert_eq!(p.expand(e), p.parse_scalar("b^2").unwrap());
        let e = p.parse_scalar("sin(x*(y + 1))").unwrap();
        assert_eq!(p.expand(e), p.parse_scalar("sin(x*y + x)").unwrap());
        let e = p.parse_scalar("(x + 1)^2/(x + 1)").unwrap();
        let ex = p.expand(e);
        // (x+1)^2/(x+1) is already x + 1 by collecting powers.
        assert_eq!(ex, p.parse_scalar("x + 1").unwrap());
    }

    #[test]
    fn high_powers_expand_within_the_budget() {
        let mut p = Pool::new();
        // Once left unexpanded (a fixed limit of power 24): 26 terms, binomial coefficients.
        let e = p.parse_scalar("(x + y)^25").unwrap();
        let ex = p.try_expand(e).unwrap();
        match p.node(ex) {
            crate::Node::Add(ts) => assert_eq!(ts.len(), 26),
            other => panic!("not expanded: {other:?}"),
        }
        let c = p.parse_scalar("5200300*x^12*y^13").unwrap();
        assert!(matches!(p.node(ex), crate::Node::Add(ts) if ts.contains(&c)));
    }

    #[test]
    fn products_of_sums_stop_at_the_budget() {
        let mut p = Pool::new();
        // (a+b+c+d)^40 has 12,341 terms: over the limit of 5,000, a typed error.
        let e = p.parse_scalar("(a + b + c + d)^40").unwrap();
        assert_eq!(
            p.try_expand(e),
            Err(crate::BudgetError::ExpandTerms {
                limit: crate::budget::MAX_EXPAND_TERMS
            })
        );
        // The lenient form keeps that power factored and expands the rest.
        let e = p.parse_scalar("(a + b + c + d)^40 + x*(y + 1)").unwrap();
        let ex = p.expand(e);
        assert_eq!(ex, p.parse_scalar("(a + b + c + d)^40 + x*y + x").unwrap());
    }
}
