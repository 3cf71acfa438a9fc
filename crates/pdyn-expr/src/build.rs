//! Canonicalising constructors: the only way nodes enter a [`Pool`].
//!
//! Automatic simplification in the sense of Cohen (*Computer Algebra and Symbolic
//! Computation*, ch. 3): sums and products are flattened, numbers folded exactly, like terms
//! (`2*x + 3*x = 5*x`) and like powers (`x*x^2 = x^3`) collected, children sorted by
//! [`Pool::order`]. A numeric factor is distributed over a single sum (`-(a - b) = b - a`),
//! integer powers over products, and `sqrt` of declared-positive factors is taken out
//! (`sqrt(m^2*g) = m*sqrt(g)` for `m > 0`). Odd/even functions normalise the sign of their
//! argument (`cos(b - a) = cos(a - b)`), and exact values at `0` and multiples of `pi/2` fold.

use crate::number::Number;
use crate::pool::{Constant, Func, Id, Node, NodeRef, Pool};
use rustc_hash::FxHashMap;

impl Pool {
    /// `a + b`.
    pub fn add2(&mut self, a: Id, b: Id) -> Id {
        self.add(&[a, b])
    }

    /// `a - b`.
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        let nb = self.neg(b);
        self.add(&[a, nb])
    }

    /// `-a`.
    pub fn neg(&mut self, a: Id) -> Id {
        self.mul(&[Pool::MINUS_ONE, a])
    }

    /// `a * b`.
    pub fn mul2(&mut self, a: Id, b: Id) -> Id {
        self.mul(&[a, b])
    }

    /// `a / b`.
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        let inv = self.pow(b, Pool::MINUS_ONE);
        self.mul(&[a, inv])
    }

    /// `a^n` for an integer `n`.
    pub fn powi(&mut self, a: Id, n: i64) -> Id {
        let e = self.int(n);
        self.pow(a, e)
    }

    /// `sqrt(a)`, i.e. `a^(1/2)`.
    pub fn sqrt(&mut self, a: Id) -> Id {
        let half = self.num(Number::ratio(1, 2));
        self.pow(a, half)
    }

    /// Splits a term into numeric coefficient and the rest: `3*x*y -> (3, x*y)`.
    pub fn split_coeff(&mut self, t: Id) -> (Number, Id) {
        match self.node(t) {
            Node::Num(n) => (n.clone(), Pool::ONE),
            Node::Mul(fs) => {
                if let Node::Num(c) = self.node(fs[0]) {
                    let c = c.clone();
                    let rest: Vec<Id> = fs[1..].to_vec();
                    let rest = if rest.len() == 1 {
                        rest[0]
                    } else {
                        self.intern_parts(NodeRef::Mul(&rest))
                    };
                    (c, rest)
                } else {
                    (Number::ONE, t)
                }
            }
            _ => (Number::ONE, t),
        }
    }

    /// `c * rest`.
    pub fn scale(&mut self, c: Number, rest: Id) -> Id {
        let cid = self.num(c);
        self.mul(&[cid, rest])
    }

    /// Canonical sum of `terms`.
    pub fn add(&mut self, terms: &[Id]) -> Id {
        if let [t] = terms {
            // A single canonical term other than a sum or a number is its own sum.
            if !matches!(self.node(*t), Node::Add(_) | Node::Num(_)) && !self.rest_is_sum(*t) {
                return *t;
            }
        }
        let mut flat = self.spare.ids.take();
        self.flatten(terms, &mut flat, |n| match n {
            Node::Add(ts) => Some(ts),
            _ => None,
        });
        let mut constant = Number::ZERO;
        // Like terms, keyed by their factors other than the numeric coefficient, in order of
        // first appearance. The keys are read from the terms' own nodes: interning each
        // term's rest (as `split_coeff` does) and then the term again (`scale_term`) was most
        // of the cost of a sum, and only terms that actually combine need either.
        let mut like: Vec<Like> = Vec::with_capacity(flat.len());
        {
            let mut index = KeyIndex::new(flat.len());
            for &t in &flat {
                if let Node::Num(n) = self.node(t) {
                    constant = constant.add(n);
                    continue;
                }
                let (c, key) = self.coeff_key(t);
                match index.find(key, &like, |l| self.coeff_key(l.first).1) {
                    Some(i) => {
                        let l = &mut like[i];
                        l.coeff = l.coeff.add(c.unwrap_or(&Number::ONE));
                        l.count += 1;
                    }
                    None => {
                        index.insert(key, like.len());
                        like.push(Like {
                            first: t,
                            coeff: c.cloned().unwrap_or(Number::ONE),
                            count: 1,
                        });
                    }
                }
            }
        }
        self.spare.ids.put(flat);
        let mut out = self.spare.ids.take();
        for l in like {
            if l.coeff.is_zero() {
                continue;
            }
            if l.count == 1 && !self.rest_is_sum(l.first) {
                // Alone, the term is already `coeff * rest` in canonical form.
                out.push(l.first);
                continue;
            }
            let (_, rest) = self.split_coeff(l.first);
            let term = self.scale_term(l.coeff, rest);
            out.push(term);
        }
        out.sort_by(|a, b| self.order(*a, *b));
        if !constant.is_zero() {
            let c = self.num(constant);
            out.insert(0, c);
        }
        let r = match out.len() {
            0 => Pool::ZERO,
            1 => out[0],
            _ => self.intern_parts(NodeRef::Add(&out)),
        };
        self.spare.ids.put(out);
        r
    }

    /// `items` with every node that `children` opens (a sum's terms, a product's factors)
    /// replaced by its children, recursively, left to right.
    fn flatten(&self, items: &[Id], out: &mut Vec<Id>, children: fn(&Node) -> Option<&[Id]>) {
        for &x in items {
            match children(self.node(x)) {
                Some(kids) => self.flatten(kids, out, children),
                None => out.push(x),
            }
        }
    }

    /// A term's numeric coefficient (none for 1) and the key of its other factors, as
    /// [`Pool::split_coeff`] would split it but without building the rest.
    fn coeff_key(&self, t: Id) -> (Option<&Number>, Key<'_>) {
        match self.node(t) {
            Node::Mul(fs) => {
                let (c, rest) = match self.node(fs[0]) {
                    Node::Num(c) => (Some(c), &fs[1..]),
                    _ => (None, &fs[..]),
                };
                match rest {
                    [one] => (c, Key::One(*one)),
                    _ => (c, Key::Many(rest)),
                }
            }
            _ => (None, Key::One(t)),
        }
    }

    /// Whether the rest of a term after its coefficient is a sum (never, for a canonical
    /// term: a number times a sum is distributed; checked so that such a term is rebuilt
    /// exactly as before).
    fn rest_is_sum(&self, t: Id) -> bool {
        match self.node(t) {
            Node::Mul(fs) if fs.len() == 2 => {
                matches!(self.node(fs[0]), Node::Num(_)) && matches!(self.node(fs[1]), Node::Add(_))
            }
            _ => false,
        }
    }

    /// `c * rest` for a `rest` that came out of [`Pool::split_coeff`] (no coefficient, not a
    /// number), built directly without re-canonicalising the factors.
    fn scale_term(&mut self, c: Number, rest: Id) -> Id {
        if c.is_one() {
            return rest;
        }
        let cid = self.num(c);
        match self.node(rest) {
            Node::Mul(fs) => {
                let mut v = Vec::with_capacity(fs.len() + 1);
                v.push(cid);
                v.extend_from_slice(fs);
                self.intern_parts(NodeRef::Mul(&v))
            }
            // A number times a sum is distributed by `mul`; do the same here for consistency.
            Node::Add(_) => self.mul(&[cid, rest]),
            _ => self.intern_parts(NodeRef::Mul(&[cid, rest])),
        }
    }

    /// Canonical product of `factors`.
    pub fn mul(&mut self, factors: &[Id]) -> Id {
        let mut flat = self.spare.ids.take();
        self.flatten(factors, &mut flat, |n| match n {
            Node::Mul(fs) => Some(fs),
            _ => None,
        });
        let mut coeff = Number::ONE;
        // `(base, exponent)` of every factor in order, and the distinct bases in order of
        // first appearance with the position of their first factor and their count: a
        // product's factors are few, so a scan finds a base faster than a hash map with a
        // vector per base (allocations that were a fifth of `mul`).
        let mut pairs = self.spare.pairs.take();
        let mut bases = self.spare.bases.take();
        let mut index = KeyIndex::new(flat.len());
        for &f in &flat {
            let (b, e) = match self.node(f) {
                Node::Num(n) => {
                    coeff = coeff.mul(n);
                    continue;
                }
                Node::Pow(b, e) => (*b, *e),
                Node::Add(_) => match self.add_content(f) {
                    Some((c, prim)) => {
                        coeff = coeff.mul(&c);
                        (prim, Pool::ONE)
                    }
                    None => (f, Pool::ONE),
                },
                _ => (f, Pool::ONE),
            };
            match index.find(Key::One(b), &bases, |&(base, _, _)| Key::One(base)) {
                Some(i) => bases[i].2 += 1,
                None => {
                    index.insert(Key::One(b), bases.len());
                    bases.push((b, pairs.len(), 1));
                }
            }
            pairs.push((b, e));
        }
        self.spare.ids.put(flat);
        if coeff.is_zero() {
            return Pool::ZERO;
        }
        let mut out = self.spare.ids.take();
        let mut reflatten = false;
        for &(b, first, count) in &bases {
            let p = if count == 1 {
                let e = pairs[first].1;
                if e == Pool::ONE {
                    b
                } else {
                    // Already a canonical Pow node unless the base is a number (2^(1/2)).
                    self.pow(b, e)
                }
            } else {
                let es: Vec<Id> = pairs[first..]
                    .iter()
                    .filter(|&&(x, _)| x == b)
                    .map(|&(_, e)| e)
                    .collect();
                let e = self.add(&es);
                self.pow(b, e)
            };
            match self.node(p) {
                Node::Num(n) => coeff = coeff.mul(n),
                Node::Mul(_) => {
                    reflatten = true;
                    out.push(p)
                }
                Node::Pow(pb, _) if *pb != b => {
                    reflatten = true;
                    out.push(p)
                }
                _ => out.push(p),
            }
        }
        self.spare.pairs.put(pairs);
        self.spare.bases.put(bases);
        if reflatten {
            let c = self.num(coeff);
            out.push(c);
            let r = self.mul(&out);
            self.spare.ids.put(out);
            return r;
        }
        if coeff.is_zero() {
            return Pool::ZERO;
        }
        out.sort_by(|a, b| self.order(*a, *b));
        if out.is_empty() {
            return self.num(coeff);
        }
        if coeff.is_one() && out.len() == 1 {
            return out[0];
        }
        if out.len() == 1 && matches!(self.node(out[0]), Node::Add(_)) {
            // Distribute a number over a sum: 2*(a + b) = 2*a + 2*b.
            if let Node::Add(ts) = self.node(out[0]) {
                let ts = ts.to_vec();
                let terms: Vec<Id> = ts
                    .into_iter()
                    .map(|t| {
                        let (c, rest) = self.split_coeff(t);
                        let nc = c.mul(&coeff);
                        if rest == Pool::ONE {
                            self.num(nc)
                        } else {
                            self.scale_term(nc, rest)
                        }
                    })
                    .collect();
                return self.add(&terms);
            }
        }
        if !coeff.is_one() {
            let c = self.num(coeff);
            out.insert(0, c);
        }
        let r = self.intern_parts(NodeRef::Mul(&out));
        self.spare.ids.put(out);
        r
    }

    /// Canonical power `b^e`.
    pub fn pow(&mut self, b: Id, e: Id) -> Id {
        if e == Pool::ZERO {
            return Pool::ONE;
        }
        if e == Pool::ONE || b == Pool::ONE {
            return b;
        }
        let en = self.as_num(e);
        // The arms below read a sum base's terms from the pool, not from this copy: copying
        // them (a chain's mass sums, 100 terms) at every power was a needless allocation.
        let node = match self.node(b) {
            Node::Add(_) => Node::Add(Box::new([])),
            other => other.clone(),
        };
        match (node, en) {
            (Node::Num(x), Some(y)) => {
                if let Some(r) = x.pow(&y) {
                    return self.num(r);
                }
                // Exact base, fractional exponent without exact root: 2^(3/2) = 2*2^(1/2).
                let exponent = y.as_rational().and_then(|r| r.small());
                if let (Some(xr), Some((p, q))) = (x.as_rational(), exponent) {
                    let whole = p.div_euclid(q);
                    let frac = p.rem_euclid(q);
                    if q != 1 && whole != 0 && xr.signum() > 0 {
                        // `None` when the whole part is over the size budget of exact numbers:
                        // then the power stays as written, exact, never a silent float.
                        if let Some(w) = x.pow(&Number::int(whole)) {
                            let w = self.num(w);
                            let fe = self.num(Number::ratio(frac, q));
                            let fp = self.intern(Node::Pow(b, fe));
                            return self.mul(&[w, fp]);
                        }
                    }
                }
                // An integer power over the size budget (2^1000000) also stays symbolic.
                self.intern(Node::Pow(b, e))
            }
            (Node::Const(Constant::E), _) => self.call(Func::Exp, &[e]),
            (Node::Add(_), Some(y)) => {
                // Canonical sums under powers: (2a + 2b)^k = 2^k (a + b)^k, so that every
                // arrangement of the same product reaches the same node.
                match self.add_content(b) {
                    Some((c, prim)) if y.as_integer().is_some() || c.is_positive() => {
                        let cp = self.num(c);
                        let cpow = self.pow(cp, e);
                        let pp = self.pow(prim, e);
                        self.mul(&[cpow, pp])
                    }
                    _ => self.intern(Node::Pow(b, e)),
                }
            }
            (Node::Pow(b2, e2), Some(y)) => {
                let y_int = y.as_integer().is_some();
                if y_int || self.is_positive(b2) {
                    let ne = self.mul(&[e2, e]);
                    return self.pow(b2, ne);
                }
                if let Some(n) = self.as_num(e2).and_then(|n| n.as_integer()) {
                    let prod = Number::int(n).mul(&y);
                    if n % 2 == 0 && prod.as_integer().is_some() {
                        // sqrt(x^2) = |x| for real x.
                        let a = self.call(Func::Abs, &[b2]);
                        let pe = self.num(prod);
                        return self.pow(a, pe);
                    }
                }
                self.intern(Node::Pow(b, e))
            }
            (Node::Pow(b2, e2), None) if self.is_positive(b2) => {
                let ne = self.mul(&[e2, e]);
                self.pow(b2, ne)
            }
            (Node::Mul(fs), Some(y)) => {
                if y.as_integer().is_some() {
                    let ps: Vec<Id> = fs.iter().map(|&f| self.pow(f, e)).collect();
                    return self.mul(&ps);
                }
                let (pos, rest): (Vec<Id>, Vec<Id>) =
                    fs.iter().partition(|&&f| self.is_positive(f));
                if pos.is_empty() {
                    return self.intern(Node::Pow(b, e));
                }
                let mut ps: Vec<Id> = pos.iter().map(|&f| self.pow(f, e)).collect();
                match rest.len() {
                    0 => {}
                    1 => ps.push(self.pow(rest[0], e)),
                    _ => {
                        let r = self.mul(&rest);
                        ps.push(self.pow(r, e));
                    }
                }
                self.mul(&ps)
            }
            (Node::Call(Func::Exp, args), _) => {
                let u = self.mul(&[args[0], e]);
                self.call(Func::Exp, &[u])
            }
            (Node::Call(Func::Abs, args), Some(y))
                if y.as_integer().is_some_and(|n| n % 2 == 0) =>
            {
                self.pow(args[0], e)
            }
            _ => self.intern(Node::Pow(b, e)),
        }
    }

    /// For a sum with rational coefficients, `(c, p)` with `sum = c * p`, `p` primitive (integer
    /// coefficients with GCD 1) and its first non-constant term positive; `None` when `c = 1`.
    pub fn add_content(&mut self, sum: Id) -> Option<(Number, Id)> {
        let Node::Add(ts) = self.node(sum) else {
            return None;
        };
        if ts.len() < crate::memo::CONTENT_MEMO_TERMS {
            return self.add_content_uncached(sum);
        }
        if let Some(known) = self.memo.content.get(&sum) {
            return known.clone();
        }
        let r = self.add_content_uncached(sum);
        self.memo.content.insert(sum, r.clone());
        r
    }

    fn add_content_uncached(&mut self, sum: Id) -> Option<(Number, Id)> {
        let Node::Add(ts) = self.node(sum) else {
            return None;
        };
        let mut num_gcd: i64 = 0;
        let mut den_lcm: i64 = 1;
        let mut sign_neg = None;
        // The coefficients are read from the terms' nodes: most sums have content 1, and
        // splitting every term (interning its rest) only to find that out was most of the
        // cost of multiplying by a sum.
        for &t in ts.iter() {
            let (c, constant) = match self.node(t) {
                Node::Num(n) => (n, true),
                _ => (self.coeff_key(t).0.unwrap_or(&Number::ONE), false),
            };
            // Sums with big coefficients are left as they are (a normalisation, not needed
            // for correctness; the machine-integer gcd keeps the common case cheap).
            let (n, d) = c.as_rational()?.small()?;
            if !constant && sign_neg.is_none() {
                sign_neg = Some(n < 0);
            }
            num_gcd = gcd_i64(num_gcd, n);
            let g = gcd_i64(den_lcm, d);
            den_lcm = (den_lcm / g).checked_mul(d)?;
        }
        let mut content = crate::number::Rational::new(num_gcd as i128, den_lcm as i128)?;
        if sign_neg == Some(true) {
            content = content.neg();
        }
        if content == crate::number::Rational::ONE || content.is_zero() {
            return None;
        }
        let inv = content.recip()?;
        let ts = ts.to_vec();
        let mut parts = Vec::with_capacity(ts.len());
        for t in ts {
            let (c, rest) = self.split_coeff(t);
            // Rational and small: checked above.
            let r = c.as_rational().cloned()?;
            parts.push((r, rest));
        }
        let mut terms = Vec::with_capacity(parts.len());
        for (r, rest) in parts {
            let c = Number::Rat(r.mul(&inv));
            terms.push(if rest == Pool::ONE {
                self.num(c)
            } else {
                self.scale_term(c, rest)
            });
        }
        let prim = self.add(&terms);
        Some((Number::Rat(content), prim))
    }

    /// True when `id` is known to be strictly positive for all real values of its symbols.
    pub fn is_positive(&self, id: Id) -> bool {
        match self.node(id) {
            Node::Num(n) => n.is_positive(),
            Node::Const(_) => true,
            Node::Sym(s) => self.symbol_info(*s).positive,
            Node::Pow(b, e) => {
                self.is_positive(*b)
                    || (self
                        .as_num(*e)
                        .and_then(|n| n.as_integer())
                        .is_some_and(|n| n % 2 == 0)
                        && self.is_nonzero_square_base(*b))
            }
            Node::Mul(fs) => fs.iter().all(|&f| self.is_positive(f)),
            Node::Add(ts) => ts.iter().all(|&t| self.is_positive(t)),
            Node::Call(Func::Exp | Func::Cosh, _) => true,
            _ => false,
        }
    }

    fn is_nonzero_square_base(&self, b: Id) -> bool {
        // x^2 > 0 needs x != 0; only claim it for bases that cannot vanish.
        match self.node(b) {
            Node::Num(n) => !n.is_zero(),
            _ => self.is_positive(b),
        }
    }

    /// True when the expression "looks negative": a negative number, a product with a negative
    /// coefficient, or a sum whose first term looks negative. Used to normalise signs.
    pub fn looks_negative(&self, id: Id) -> bool {
        match self.node(id) {
            Node::Num(n) => n.is_negative(),
            Node::Mul(fs) => self.as_num(fs[0]).is_some_and(|c| c.is_negative()),
            Node::Add(ts) => self.looks_negative(ts[0]),
            _ => false,
        }
    }

    /// `k` such that `id = k*pi` for a rational `k`.
    fn pi_multiple(&self, id: Id) -> Option<crate::number::Rational> {
        match self.node(id) {
            Node::Const(Constant::Pi) => Some(crate::number::Rational::ONE),
            Node::Mul(fs) if fs.len() == 2 => {
                let c = self.as_num(fs[0])?.as_rational()?.clone();
                matches!(self.node(fs[1]), Node::Const(Constant::Pi)).then_some(c)
            }
            _ => None,
        }
    }

    /// Canonical function call. Arity must match [`Func::arity`] (checked by the parser).
    pub fn call(&mut self, f: Func, args: &[Id]) -> Id {
        debug_assert_eq!(args.len(), f.arity());
        let u = args[0];
        let odd = |p: &mut Pool, f: Func, u: Id| -> Id {
            let nu = p.neg(u);
            let inner = p.call(f, &[nu]);
            p.neg(inner)
        };
        match f {
            Func::Sin | Func::Tan | Func::Asin | Func::Atan | Func::Sinh | Func::Tanh => {
                if u == Pool::ZERO {
                    return Pool::ZERO;
                }
                if self.looks_negative(u) {
                    return odd(self, f, u);
                }
                if let Some(k) = self.pi_multiple(u) {
                    match f {
                        Func::Sin | Func::Tan if k.is_integer() => return Pool::ZERO,
                        Func::Sin if k.small().is_some_and(|(_, d)| d == 2) => {
                            let n = k.small().map_or(1, |(n, _)| n);
                            let s = if n.rem_euclid(4) == 1 { 1 } else { -1 };
                            return self.int(s);
                        }
                        _ => {}
                    }
                }
            }
            Func::Cos | Func::Cosh => {
                if u == Pool::ZERO {
                    return Pool::ONE;
                }
                if self.looks_negative(u) {
                    let nu = self.neg(u);
                    return self.call(f, &[nu]);
                }
                if f == Func::Cos {
                    if let Some(k) = self.pi_multiple(u) {
                        if k.is_integer() {
                            let even = k.mul(&crate::number::Rational::HALF).is_integer();
                            return self.int(if even { 1 } else { -1 });
                        }
                        if k.small().is_some_and(|(_, d)| d == 2) {
                            return Pool::ZERO;
                        }
                    }
                }
            }
            Func::Exp => {
                if u == Pool::ZERO {
                    return Pool::ONE;
                }
                if let Node::Call(Func::Log, a) = self.node(u) {
                    return a[0];
                }
            }
            Func::Log => {
                if u == Pool::ONE {
                    return Pool::ZERO;
                }
                match self.node(u) {
                    Node::Call(Func::Exp, a) => return a[0],
                    Node::Const(Constant::E) => return Pool::ONE,
                    _ => {}
                }
            }
            Func::Abs => {
                if let Some(n) = self.as_num(u) {
                    return self.num(if n.is_negative() { n.neg() } else { n });
                }
                if self.is_positive(u) || matches!(self.node(u), Node::Call(Func::Abs, _)) {
                    return u;
                }
                if self.looks_negative(u) {
                    let nu = self.neg(u);
                    return self.call(Func::Abs, &[nu]);
                }
                if let Node::Mul(fs) = self.node(u) {
                    let (pos, rest): (Vec<Id>, Vec<Id>) =
                        fs.iter().partition(|&&f| self.is_positive(f));
                    if !pos.is_empty() {
                        let r = self.mul(&rest);
                        let a = self.call(Func::Abs, &[r]);
                        let mut v = pos;
                        v.push(a);
                        return self.mul(&v);
                    }
                }
            }
            Func::Sign => {
                if let Some(n) = self.as_num(u) {
                    let s = if n.is_positive() {
                        1
                    } else if n.is_negative() {
                        -1
                    } else {
                        0
                    };
                    return self.int(s);
                }
                if self.is_positive(u) {
                    return Pool::ONE;
                }
                if self.looks_negative(u) {
                    return odd(self, f, u);
                }
            }
            Func::Min | Func::Max => {
                let v = args[1];
                if u == v {
                    return u;
                }
                if let (Some(a), Some(b)) = (self.as_num(u), self.as_num(v)) {
                    let a_smaller = a.total_cmp(&b).is_le();
                    return if (f == Func::Min) == a_smaller { u } else { v };
                }
                // Commutative: order the arguments canonically.
                if self.order(u, v).is_gt() {
                    return self.call(f, &[v, u]);
                }
            }
            Func::Table(_) => {}
            Func::Atan2 => {
                // atan2(y, x) = atan(y/x) when x > 0.
                if self.is_positive(args[1]) {
                    let q = self.div(u, args[1]);
                    return self.call(Func::Atan, &[q]);
                }
            }
            Func::Acos => {}
        }
        self.intern_parts(NodeRef::Call(f, args))
    }
}

/// Working lists of the constructors, kept between calls: each product allocated four
/// (its factors, their bases and exponents, the result) and each sum three, a fifth of the
/// cost of `mul`. A nested call finds the list taken and makes its own.
#[derive(Clone, Debug, Default)]
pub(crate) struct Spare {
    ids: SpareLists<Id>,
    pairs: SpareLists<(Id, Id)>,
    bases: SpareLists<(Id, usize, u32)>,
}

/// Emptied vectors of one kind, ready for reuse.
#[derive(Clone, Debug)]
struct SpareLists<T>(Vec<Vec<T>>);

impl<T> Default for SpareLists<T> {
    fn default() -> Self {
        SpareLists(Vec::new())
    }
}

impl<T> SpareLists<T> {
    /// An empty vector, with the capacity of an earlier one when there is one.
    fn take(&mut self) -> Vec<T> {
        self.0.pop().unwrap_or_default()
    }

    /// Keeps `v` for reuse (a few at most: nesting is shallow).
    fn put(&mut self, mut v: Vec<T>) {
        if self.0.len() < 8 {
            v.clear();
            self.0.push(v);
        }
    }
}

/// A like term of a sum being built: its first occurrence, the sum of the coefficients of
/// every occurrence, and how many there were.
struct Like {
    first: Id,
    coeff: Number,
    count: u32,
}

/// What makes terms alike (their factors but the numeric coefficient), or factors
/// combinable (their base), read from the pool without building a node.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Key<'a> {
    /// A single factor.
    One(Id),
    /// Two factors or more, in canonical order.
    Many(&'a [Id]),
}

/// Finds the entry of a key among entries pushed in order: by scanning while they are few,
/// through a hash map once there are more (a sum of a hundred terms).
struct KeyIndex<'a> {
    map: Option<FxHashMap<Key<'a>, usize>>,
    /// How many entries there may be in all: the map is made that large at once (growing
    /// it key by key rehashed it several times in every long sum).
    most: usize,
}

impl KeyIndex<'_> {
    fn new(most: usize) -> Self {
        KeyIndex { map: None, most }
    }
}

/// Entries up to which a scan is cheaper than hashing.
const SCAN_LIMIT: usize = 16;

impl<'a> KeyIndex<'a> {
    fn find<T>(
        &mut self,
        key: Key<'a>,
        entries: &[T],
        key_of: impl Fn(&T) -> Key<'a>,
    ) -> Option<usize> {
        if let Some(map) = &self.map {
            return map.get(&key).copied();
        }
        let found = entries.iter().position(|e| key_of(e) == key);
        if found.is_none() && entries.len() >= SCAN_LIMIT {
            let mut map = FxHashMap::with_capacity_and_hasher(
                self.most.max(entries.len() + 1),
                Default::default(),
            );
            map.extend(entries.iter().enumerate().map(|(i, e)| (key_of(e), i)));
            self.map = Some(map);
        }
        found
    }

    /// Records that `key` is the entry at `at` (after a [`KeyIndex::find`] that missed).
    fn insert(&mut self, key: Key<'a>, at: usize) {
        if let Some(map) = &mut self.map {
            map.insert(key, at);
        }
    }
}

fn gcd_i64(a: i64, b: i64) -> i64 {
    let g = crate::number::gcd(a.unsigned_abs().into(), b.unsigned_abs().into());
    g.min(i64::MAX as u128) as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn like_terms_and_powers_collect() {
        let mut p = Pool::new();
        let x = p.var("x");
        let y = p.var("y");
        let xx = p.add(&[x, x, x]);
        let three = p.int(3);
        assert_eq!(xx, p.mul(&[three, x]));
        let x2 = p.mul(&[x, x]);
        assert_eq!(x2, p.powi(x, 2));
        let a = p.add(&[x, y]);
        let b = p.add(&[y, x]);
        assert_eq!(a, b, "sums are order independent");
        let d = p.sub(a, y);
        assert_eq!(d, x);
        let q = p.div(x2, x);
        assert_eq!(q, x);
    }

    /// Sums and products long enough to switch from scanning to hashing collect like terms
    /// and bases exactly as sums and products built two at a time do.
    #[test]
    fn long_sums_and_products_collect_like_short_ones() {
        let mut p = Pool::new();
        let xs: Vec<Id> = (0..40).map(|i| p.var(&format!("x{i}"))).collect();
        let c = p.num(Number::Float(0.1));
        // Every symbol twice, the second time with a float coefficient, and a constant.
        let mut terms = Vec::new();
        for &x in &xs {
            terms.push(x);
        }
        for &x in xs.iter().rev() {
            terms.push(p.mul2(c, x));
            terms.push(c);
        }
        let at_once = p.add(&terms);
        let pairwise = terms[1..].iter().fold(terms[0], |acc, &t| p.add2(acc, t));
        assert_eq!(at_once, pairwise);
        let Node::Add(ts) = p.node(at_once) else {
            panic!("a sum")
        };
        assert_eq!(ts.len(), xs.len() + 1);
        // Exact coefficients that cancel leave the constant alone.
        let three = p.int(3);
        let mut all: Vec<Id> = xs.iter().map(|&x| p.mul2(three, x)).collect();
        all.push(three);
        for &x in &xs {
            let minus = p.neg(x);
            all.extend([minus, minus, minus]);
        }
        assert_eq!(p.add(&all), three);

        let mut factors = xs.clone();
        factors.extend(xs.iter().rev());
        let two = p.int(2);
        factors.push(two);
        let at_once = p.mul(&factors);
        let pairwise = factors[1..]
            .iter()
            .fold(factors[0], |acc, &f| p.mul2(acc, f));
        assert_eq!(at_once, pairwise);
        let squares: Vec<Id> = xs.iter().map(|&x| p.powi(x, 2)).collect();
        let mut expected = squares;
        expected.push(two);
        assert_eq!(at_once, p.mul(&expected));
    }

    /// A single term is its own sum; sums with a common factor keep their content out.
    #[test]
    fn single_terms_and_contents() {
        let mut p = Pool::new();
        let t = p.parse_scalar("3*a*sin(b)").unwrap();
        assert_eq!(p.add(&[t]), t);
        let s = p.parse_scalar("2*a + 4*b").unwrap();
        let (c, prim) = p.add_content(s).unwrap();
        assert_eq!(c, Number::int(2));
        assert_eq!(prim, p.parse_scalar("a + 2*b").unwrap());
        let q = p.parse_scalar("a + b").unwrap();
        assert!(p.add_content(q).is_none());
        // Float coefficients are left alone.
        let half = p.num(Number::Float(0.5));
        let (a, b) = (p.var("a"), p.var("b"));
        let ha = p.mul2(half, a);
        let f = p.add2(ha, b);
        assert!(p.add_content(f).is_none());
    }

    #[test]
    fn sqrt_of_square_needs_positivity() {
        let mut p = Pool::new();
        let x = p.var("x");
        let x2 = p.powi(x, 2);
        let s = p.sqrt(x2);
        assert_eq!(s, p.call(Func::Abs, &[x]));
        let ms = p.symbol("m", true);
        let m = p.sym(ms);
        let m2 = p.powi(m, 2);
        let g = p.var("g");
        let prod = p.mul(&[m2, g]);
        let s = p.sqrt(prod);
        let sg = p.sqrt(g);
        assert_eq!(s, p.mul(&[m, sg]));
    }

    #[test]
    fn trig_signs_and_special_values() {
        let mut p = Pool::new();
        let a = p.var("a");
        let b = p.var("b");
        let d1 = p.sub(a, b);
        let d2 = p.sub(b, a);
        assert_eq!(p.call(Func::Cos, &[d1]), p.call(Func::Cos, &[d2]));
        let s1 = p.call(Func::Sin, &[d1]);
        let s2 = p.call(Func::Sin, &[d2]);
        assert_eq!(s1, p.neg(s2));
        let pi = p.constant(Constant::Pi);
        assert_eq!(p.call(Func::Sin, &[pi]), Pool::ZERO);
        assert_eq!(p.call(Func::Cos, &[pi]), Pool::MINUS_ONE);
    }
}
