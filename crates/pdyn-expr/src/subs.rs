//! Substitution: replace subexpressions (usually leaves: symbols, coordinates, `t`) by other
//! expressions, rebuilding through the canonical constructors so the result is simplified as
//! it is rebuilt (`x*y` with `y -> 1/x` becomes `1`).

use crate::pool::{Id, Node, Pool};
use rustc_hash::FxHashMap;

impl Pool {
    /// Replaces every occurrence of each key of `map` in `e` by its value.
    pub fn subs(&mut self, e: Id, map: &FxHashMap<Id, Id>) -> Id {
        if map.is_empty() {
            return e;
        }
        self.rewrite(e, |_, n| map.get(&n).copied(), |_, r| r)
    }

    /// Bottom-up rewriting shared by the transformations that rebuild an expression: for each
    /// node (children first), `replace` may give its replacement outright; otherwise the node is
    /// rebuilt from its rewritten children through the canonical constructors and passed to
    /// `finish`.
    pub(crate) fn rewrite(
        &mut self,
        e: Id,
        replace: impl Fn(&Pool, Id) -> Option<Id>,
        mut finish: impl FnMut(&mut Pool, Id) -> Id,
    ) -> Id {
        let mut done: FxHashMap<Id, Id> = FxHashMap::default();
        for n in self.topo_order(&[e]) {
            let r = match replace(self, n) {
                Some(v) => v,
                None => {
                    let get = |x: &Id| done[x];
                    // A node whose children are all unchanged is itself: it was built by the
                    // same canonical constructors (most of a tree that a contraction or a
                    // substitution touches in a few places; rebuilding it anyway was most of
                    // `contract_trig` on a 100-link chain's entries).
                    let same = |xs: &[Id]| xs.iter().all(|x| done[x] == *x);
                    let rebuilt = match self.node(n) {
                        Node::Add(ts) | Node::Mul(ts) | Node::Call(_, ts) if same(ts) => n,
                        Node::Pow(b, x) if done[b] == *b && done[x] == *x => n,
                        node => match node.clone() {
                            Node::Add(ts) => {
                                let ts: Vec<Id> = ts.iter().map(get).collect();
                                self.add(&ts)
                            }
                            Node::Mul(fs) => {
                                let fs: Vec<Id> = fs.iter().map(get).collect();
                                self.mul(&fs)
                            }
                            Node::Pow(b, x) => {
                                let (b, x) = (get(&b), get(&x));
                                self.pow(b, x)
                            }
                            Node::Call(f, args) => {
                                let args: Vec<Id> = args.iter().map(get).collect();
                                self.call(f, &args)
                            }
                            _ => n,
                        },
                    };
                    finish(self, rebuilt)
                }
            };
            done.insert(n, r);
        }
        done[&e]
    }

    /// Substitutes a single pair.
    pub fn subs1(&mut self, e: Id, from: Id, to: Id) -> Id {
        let mut m = FxHashMap::default();
        m.insert(from, to);
        self.subs(e, &m)
    }
}

#[cfg(test)]
mod tests {
    use crate::pool::Pool;

    #[test]
    fn substitution_rebuilds_canonically() {
        let mut p = Pool::new();
        let e = p.parse_scalar("x*y + sin(x)").unwrap();
        let x = p.var("x");
        let y = p.var("y");
        let inv = p.powi(x, -1);
        let r = p.subs1(e, y, inv);
        assert_eq!(r, p.parse_scalar("1 + sin(x)").unwrap());
        let z = p.subs1(e, x, Pool::ZERO);
        assert_eq!(z, Pool::ZERO);
    }
}
