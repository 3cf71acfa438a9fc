//! Collecting and factoring sums, for reading: `a*x + b*x = (a + b)*x`.
//!
//! The canonical form of [`crate::build`] keeps sums flat, so a derived mass-matrix entry
//! reads `l1*l2*m2*cos(q1 - q2) + l1*l2*m3*cos(q1 - q2)` where a textbook writes
//! `l1*l2*(m2 + m3)*cos(q1 - q2)`. Both transformations here are exact (the result is the
//! same function, not an approximation), deterministic (the result depends only on the input
//! node, so equal inputs give equal outputs), and one pass over the terms and their factors:
//! they never expand, so their cost is linear in the size of the sum (hash maps keyed by
//! node ids), far inside the budgets of [`crate::budget`].
//!
//! - [`Pool::factor_terms`] takes out of a sum what all its terms share: the rational content
//!   (`2*a + 4*b = 2*(a + 2*b)`, through [`Pool::add_content`]) and the common monomial, each
//!   base with the smallest power it has in every term (`l1^2*m1 + l1^2*m2 = l1^2*(m1 + m2)`).
//! - [`Pool::collect_by`] groups the terms of a sum by the product of their "main" factors
//!   (those a predicate selects: in equations of motion, the factors that depend on the
//!   state), and factors each group's coefficient: `-g*l1*m1*sin(q1) - g*l1*m2*sin(q1) =
//!   -g*l1*(m1 + m2)*sin(q1)`.

use crate::number::Number;
use crate::pool::{Id, Node, Pool};
use rustc_hash::FxHashMap;

/// A term as a numeric coefficient and `(base, integer exponent)` factors.
struct Monomial {
    coeff: Number,
    factors: Vec<(Id, i64)>,
}

impl Pool {
    fn monomial(&self, t: Id) -> Monomial {
        let mut m = Monomial {
            coeff: Number::ONE,
            factors: Vec::new(),
        };
        let fs: &[Id] = match self.node(t) {
            Node::Mul(fs) => fs,
            _ => std::slice::from_ref(&t),
        };
        for &f in fs {
            match self.node(f) {
                Node::Num(n) => m.coeff = m.coeff.mul(n),
                Node::Pow(b, e) => match self.as_num(*e).and_then(|n| n.as_integer()) {
                    Some(k) => m.factors.push((*b, k)),
                    // A symbolic or fractional power is one opaque factor.
                    None => m.factors.push((f, 1)),
                },
                _ => m.factors.push((f, 1)),
            }
        }
        m
    }

    /// `e` with the monomial and rational content common to every term of a sum taken out
    /// (see the module documentation). A product is factored factor by factor; anything else
    /// is returned as it is. The result is equal to `e`.
    pub fn factor_terms(&mut self, e: Id) -> Id {
        if let Some(&r) = self.memo.factor.get(&e) {
            return r;
        }
        let r = self.factor_terms_uncached(e);
        self.memo.factor.insert(e, r);
        r
    }

    fn factor_terms_uncached(&mut self, e: Id) -> Id {
        match self.node(e) {
            Node::Add(ts) => {
                let ts = ts.to_vec();
                self.factor_sum(&ts)
            }
            Node::Mul(fs) => {
                let fs = fs.to_vec();
                if !fs.iter().any(|&f| matches!(self.node(f), Node::Add(_))) {
                    return e;
                }
                let out: Vec<Id> = fs.iter().map(|&f| self.factor_terms(f)).collect();
                self.mul(&out)
            }
            _ => e,
        }
    }

    /// The sum of `terms`, its common monomial and content taken out.
    fn factor_sum(&mut self, terms: &[Id]) -> Id {
        let monos: Vec<Monomial> = terms.iter().map(|&t| self.monomial(t)).collect();
        // Exponent of each base common to all terms: the one nearest zero, when every term
        // has the base with exponents of one sign (`x^2`, `x^3` → `x^2`; `1/m`, `1/m^2` →
        // `1/m`); a base missing from one term, or with mixed signs, is not common.
        let mut common: FxHashMap<Id, i64> = FxHashMap::default();
        let mut first_order: Vec<Id> = Vec::new();
        if let Some(first) = monos.first() {
            for &(b, k) in &first.factors {
                *common.entry(b).or_insert(0) += k;
                first_order.push(b);
            }
        }
        for m in &monos[1..] {
            let mut here: FxHashMap<Id, i64> = FxHashMap::default();
            for &(b, k) in &m.factors {
                *here.entry(b).or_insert(0) += k;
            }
            common.retain(|b, k| match here.get(b) {
                Some(&h) if h.signum() == k.signum() && h != 0 => {
                    *k = if k.abs() <= h.abs() { *k } else { h };
                    true
                }
                _ => false,
            });
            if common.is_empty() {
                break;
            }
        }
        common.retain(|_, k| *k != 0);
        if common.is_empty() {
            // Only the numeric content can be shared: `mul` takes it out of the sum.
            let sum = self.add(terms);
            return match self.add_content(sum) {
                Some((c, prim)) => {
                    let c = self.num(c);
                    self.mul(&[c, prim])
                }
                None => sum,
            };
        }
        let mut inner = Vec::with_capacity(monos.len());
        for m in monos {
            let mut fs: Vec<Id> = Vec::with_capacity(m.factors.len() + 1);
            fs.push(self.num(m.coeff));
            for (b, k) in m.factors {
                let k = k - common.get(&b).copied().unwrap_or(0);
                if k != 0 {
                    fs.push(self.powi(b, k));
                }
            }
            inner.push(self.mul(&fs));
        }
        let mut out: Vec<Id> = Vec::with_capacity(common.len() + 1);
        for b in first_order {
            if let Some(k) = common.remove(&b) {
                out.push(self.powi(b, k));
            }
        }
        // The remaining sum has no common monomial left, only (possibly) content, which
        // `mul` takes out of it.
        out.push(self.add(&inner));
        self.mul(&out)
    }

    /// `e` as groups `coefficient * main` (see [`Collected`]): the terms grouped by the
    /// product of their main factors (those for which `main` holds, e.g. the factors that
    /// depend on the state), each group's coefficient factored by [`Pool::factor_terms`]:
    /// `a*x + b*x + c*y` → `[(a + b, x), (c, y)]`. A term with no main factor belongs to the
    /// group of `1`; an expression that is not a sum is one group.
    pub fn collect_terms(&mut self, e: Id, main: &dyn Fn(&Pool, Id) -> bool) -> Collected {
        let ts: Vec<Id> = match self.node(e) {
            Node::Add(ts) => ts.to_vec(),
            _ => vec![e],
        };
        let mut groups: FxHashMap<Id, Vec<Id>> = FxHashMap::default();
        let mut order: Vec<Id> = Vec::new();
        for t in ts {
            let fs: Vec<Id> = match self.node(t) {
                Node::Mul(fs) => fs.to_vec(),
                _ => vec![t],
            };
            let (mains, rest): (Vec<Id>, Vec<Id>) = fs.into_iter().partition(|&f| main(self, f));
            let key = self.mul(&mains);
            let coeff = self.mul(&rest);
            match groups.get_mut(&key) {
                Some(v) => v.push(coeff),
                None => {
                    groups.insert(key, vec![coeff]);
                    order.push(key);
                }
            }
        }
        // The group of `1` first, then the others in the order of their first term in the
        // (canonical) sum: the result depends only on `e`.
        order.sort_by_key(|&k| k != Pool::ONE);
        let mut out = Vec::with_capacity(order.len());
        for key in order {
            let coeffs = groups.remove(&key).unwrap_or_default();
            let c = if coeffs.len() == 1 {
                self.factor_terms(coeffs[0])
            } else {
                self.factor_sum(&coeffs)
            };
            if c != Pool::ZERO {
                out.push((c, key));
            }
        }
        Collected { groups: out }
    }

    /// [`Pool::collect_terms`] as one expression: `a*x + b*x + c*y = (a + b)*x + c*y`, equal
    /// to `e` (the canonical constructors may order the factors differently from how
    /// [`Collected`] prints them).
    pub fn collect_by(&mut self, e: Id, main: &dyn Fn(&Pool, Id) -> bool) -> Id {
        self.collect_terms(e, main).sum(self)
    }
}

/// A sum as groups `(coefficient, main)`, printed coefficient first the way a textbook
/// writes it: `-g*l1*(m1 + m2)*sin(q1) - l1*l2*(m2 + m3)*q2'^2*sin(q1 - q2)`. (The canonical
/// product would put the sum after the call: `-g*l1*sin(q1)*(m1 + m2)`.) The text parses back
/// to an expression equal to the sum.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Collected {
    /// `(factored coefficient, product of the main factors or 1)`, the group of `1` first.
    pub groups: Vec<(Id, Id)>,
}

impl Collected {
    /// The sum as one expression.
    pub fn sum(&self, p: &mut Pool) -> Id {
        let terms: Vec<Id> = self.groups.iter().map(|&(c, m)| p.mul2(c, m)).collect();
        p.add(&terms)
    }

    /// Plain text (re-parsable). (`&mut`: a negative coefficient's magnitude is a node.)
    pub fn to_text(&self, p: &mut Pool) -> String {
        self.render(p, false, None)
    }

    /// [`Collected::to_text`] sharing `memo`'s texts of long sums with other expressions.
    pub fn to_text_memo(&self, p: &mut Pool, memo: &crate::print::TextMemo) -> String {
        self.render(p, false, Some(memo))
    }

    /// LaTeX.
    pub fn to_latex(&self, p: &mut Pool) -> String {
        self.render(p, true, None)
    }

    fn render(&self, p: &mut Pool, latex: bool, memo: Option<&crate::print::TextMemo>) -> String {
        let text = |p: &Pool, id: Id| match memo {
            Some(memo) => p.to_text_memo(id, memo),
            None => p.to_text(id),
        };
        let show = |p: &Pool, id: Id| {
            let s = if latex { p.to_latex(id) } else { text(p, id) };
            match (p.node(id), latex) {
                (Node::Add(_), true) => format!("\\left({s}\\right)"),
                (Node::Add(_), false) => format!("({s})"),
                _ => s,
            }
        };
        let sep = if latex { " " } else { "*" };
        let mut out = String::new();
        for (i, &(c, m)) in self.groups.iter().enumerate() {
            // The sign goes between the terms: `a - b*x`, not `a + -b*x`. A coefficient that
            // is a sum (nothing in common) keeps its own signs inside its parentheses.
            let negative = p.looks_negative(c) && !matches!(p.node(c), Node::Add(_));
            let c = if negative { p.neg(c) } else { c };
            out += match (i, negative) {
                (0, false) => "",
                (0, true) => "-",
                (_, false) => " + ",
                (_, true) => " - ",
            };
            if m == Pool::ONE {
                out += &if latex { p.to_latex(c) } else { text(p, c) };
            } else if c == Pool::ONE {
                out += &show(p, m);
            } else {
                out += &format!("{}{sep}{}", show(p, c), show(p, m));
            }
        }
        if out.is_empty() {
            out.push('0');
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::pool::{Node, Pool};

    fn state(p: &Pool, f: crate::Id) -> bool {
        p.any_node(f, &|n| matches!(n, Node::Coord(..) | Node::Time))
    }

    #[test]
    fn common_monomial_and_content() {
        let mut p = Pool::new();
        let e = p
            .parse_scalar("l1*l2*m2*cos(q1(t) - q2(t)) + l1*l2*m3*cos(q1(t) - q2(t))")
            .unwrap();
        let f = p.factor_terms(e);
        // Canonical factor order (the pool's): the sum after the call.
        assert_eq!(p.to_text(f), "l1*l2*cos(q1 - q2)*(m2 + m3)");
        let e = p.parse_scalar("6*a*x^2 + 4*b*x^3").unwrap();
        let f = p.factor_terms(e);
        assert_eq!(p.to_text(f), "2*x^2*(3*a + 2*b*x)");
        let e = p.parse_scalar("k/m + c/m^2").unwrap();
        let f = p.factor_terms(e);
        assert_eq!(p.to_text(f), "(c/m + k)/m");
        // Nothing in common: unchanged.
        let e = p.parse_scalar("a*x + b*y").unwrap();
        assert_eq!(p.factor_terms(e), e);
        // Mixed signs of an exponent: not common.
        let e = p.parse_scalar("a*x + b/x").unwrap();
        assert_eq!(p.factor_terms(e), e);
    }

    #[test]
    fn collect_by_state_factors() {
        let mut p = Pool::new();
        let e = p
            .parse_scalar(
                "-g*l1*m1*sin(q1(t)) - g*l1*m2*sin(q1(t)) - l1*l2*m2*q2'^2*sin(q1 - q2) \
                 - l1*l2*m3*q2'^2*sin(q1 - q2) + c",
            )
            .unwrap();
        let c = p.collect_terms(e, &state);
        let text = c.to_text(&mut p);
        assert_eq!(
            text,
            "c - g*l1*(m1 + m2)*sin(q1) - l1*l2*(m2 + m3)*q2'^2*sin(q1 - q2)"
        );
        let latex = c.to_latex(&mut p);
        assert!(latex.contains("\\left(m_{2} + m_{3}\\right)"), "{latex}");
        // The text parses back to an equal expression, and collecting is idempotent.
        let f = c.sum(&mut p);
        let mut scope = crate::FreeScope::with_coordinates(["q1", "q2"]);
        let back = p.parse_in(&text, &mut scope).unwrap().scalar().unwrap();
        assert_eq!(p.collect_by(back, &state), f);
        assert_eq!(p.collect_by(f, &state), f);
        // A single negative group, a pure number and a sum as coefficient.
        let e = p.parse_scalar("-k*x(t) - 2 + (a + b*x)*y").unwrap();
        let c = p.collect_terms(e, &state);
        assert_eq!(c.to_text(&mut p), "-2 - k*x + y*(a + b*x)");
    }

    /// Exactness on random sums of random monomials: the factored and collected forms are
    /// the same function (evaluated at random points).
    #[test]
    fn factored_forms_are_equal_at_random_points() {
        let names = ["a", "b", "x", "y"];
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = |k: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % k
        };
        for _ in 0..300 {
            let mut src = String::new();
            for t in 0..(1 + next(6)) {
                let c = next(7) as i64 - 3;
                src += &format!("{}{}", if t > 0 { " + " } else { "" }, c.max(1) * 2);
                for n in names {
                    let k = next(4) as i64 - 1;
                    src += &format!("*{n}^({k})");
                }
                if next(2) == 0 {
                    src += "*sin(q(t))";
                }
            }
            let mut p = Pool::new();
            let e = p.parse_scalar(&src).unwrap();
            let f = p.factor_terms(e);
            let g = p.collect_by(e, &state);
            let text = p.collect_terms(e, &state).to_text(&mut p);
            let h = p.parse_scalar(&text).unwrap();
            for _ in 0..3 {
                let vals: Vec<f64> = (0..5).map(|_| 0.5 + next(1000) as f64 / 500.0).collect();
                let mut at = |id| {
                    let mut map = rustc_hash::FxHashMap::default();
                    for (i, n) in names.iter().enumerate() {
                        let v = p.var(n);
                        let x = p.num(crate::Number::Float(vals[i]));
                        map.insert(v, x);
                    }
                    let s = p.symbol("q", false);
                    let q = p.coord(s, 0);
                    let x = p.num(crate::Number::Float(vals[4]));
                    map.insert(q, x);
                    // The printed text names `q` without `(t)` or a prime: a symbol there.
                    let qs = p.var("q");
                    map.insert(qs, x);
                    let r = p.subs(id, &map);
                    p.eval_const(r).unwrap()
                };
                let (ve, vf, vg, vh) = (at(e), at(f), at(g), at(h));
                let tol = 1e-12 * ve.abs().max(1.0);
                assert!(
                    (ve - vh).abs() <= tol,
                    "{src}: {ve} vs printed {text}: {vh}"
                );
                assert!((ve - vf).abs() <= tol, "{src}: {ve} vs factored {vf}");
                assert!((ve - vg).abs() <= tol, "{src}: {ve} vs collected {vg}");
            }
        }
    }
}
