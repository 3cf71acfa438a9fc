//! Expansion: products distributed over sums and positive integer powers of sums multiplied
//! out, everywhere in the expression (function arguments included). Denominators keep their
//! sums but have their insides expanded.

use crate::pool::{Id, Node, Pool};

/// Largest power of a sum that is multiplied out (`(a+b)^40` stays as it is).
const MAX_EXPAND_POWER: i64 = 24;

impl Pool {
    /// Expands products and integer powers of sums.
    pub fn expand(&mut self, e: Id) -> Id {
        if let Some(&r) = self.memo.expand.get(&e) {
            return r;
        }
        for n in self.topo_order(&[e]) {
            if self.memo.expand.contains_key(&n) {
                continue;
            }
            let r = self.expand_node(n);
            self.memo.expand.insert(n, r);
        }
        self.memo.expand[&e]
    }

    fn expanded(&self, n: Id) -> Id {
        self.memo.expand[&n]
    }

    fn expand_node(&mut self, n: Id) -> Id {
        match self.node(n).clone() {
            Node::Num(_) | Node::Const(_) | Node::Time | Node::Sym(_) | Node::Coord(..) => n,
            Node::Add(ts) => {
                let ts: Vec<Id> = ts.iter().map(|&t| self.expanded(t)).collect();
                self.add(&ts)
            }
            Node::Mul(fs) => {
                let fs: Vec<Id> = fs.iter().map(|&f| self.expanded(f)).collect();
                let mut acc = Pool::ONE;
                for f in fs {
                    acc = self.distribute(acc, f);
                }
                acc
            }
            Node::Pow(b, e) => {
                let b = self.expanded(b);
                let e = self.expanded(e);
                match self.as_num(e).and_then(|x| x.as_integer()) {
                    Some(k)
                        if k > 1
                            && k <= MAX_EXPAND_POWER
                            && matches!(self.node(b), Node::Add(_)) =>
                    {
                        let mut acc = b;
                        for _ in 1..k {
                            acc = self.distribute(acc, b);
                        }
                        acc
                    }
                    _ => self.pow(b, e),
                }
            }
            Node::Call(f, args) => {
                let args: Vec<Id> = args.iter().map(|&a| self.expanded(a)).collect();
                self.call(f, &args)
            }
        }
    }

    /// `a * b` with both sides already expanded, distributed term by term.
    fn distribute(&mut self, a: Id, b: Id) -> Id {
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
                Node::Pow(base, _) if matches!(self.node(*base), Node::Add(_)) => self.expand(m),
                _ => m,
            };
        }
        let mut terms = Vec::with_capacity(ta.len() * tb.len());
        for &x in &ta {
            for &y in &tb {
                terms.push(self.distribute(x, y));
            }
        }
        self.add(&terms)
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
}
