//! Simplification, in the spirit of MATLAB's and SymPy's `simplify`: try a few normal forms and
//! keep the shortest.
//!
//! The main normal form is a ratio of two polynomials over atoms ([`crate::poly`]):
//! 1. atoms are simplified first (function arguments, bases of fractional powers), and
//!    `b^(p/q)` becomes the atom `b^(1/q)` raised to `p`, so `x^(3/2)/sqrt(x) = x`;
//! 2. optionally, `sin`/`cos`/`tan` of sums and integer multiples are expanded
//!    (`cos(a - b) = cos a cos b + sin a sin b`), exposing cancellations between angles;
//! 3. for every angle `u`, the numerator and denominator are reduced modulo
//!    `sin(u)^2 + cos(u)^2 - 1` by eliminating `sin^2` or `cos^2`, whichever leaves fewer terms;
//! 4. the GCD of numerator and denominator is cancelled.
//!
//! The candidates (the input, and the rational form with and without trig expansion) are
//! compared by [`Pool::tree_size`]; ties keep the earlier candidate.

use crate::budget::{BudgetError, MAX_CONTRACT_WORK};
use crate::number::{Number, Rational};
use crate::poly::{gcd, Budget, Mono, Poly};
use crate::pool::{Func, Id, Node, Pool};
use rustc_hash::FxHashMap;

/// Work allowed per rational-form attempt (polynomial term operations). Each unit is a
/// monomial product and a map insertion (about 1 µs), so an attempt that gives up costs tens
/// of milliseconds; 400,000 let one fuzzed `pdyn kin` input spend 1.5 s in powers of sums.
const BUDGET: u64 = 60_000;
/// Most terms a power of a sum may expand to before it is kept as an atom: `(a + b + ... )^k`
/// with many terms is rarely simplified by expanding, and expanding it dominated the work.
const MAX_POWER_TERMS: u64 = 400;
/// Most terms of an angle whose `sin`/`cos` is expanded into products (`a - b + c` is the
/// largest that chapter models use).
const MAX_TRIG_TERMS: usize = 3;
/// Largest tree handed to the rational normal form.
const MAX_TREE: usize = 20_000;

impl Pool {
    /// Polynomial work units (monomial products and insertions) spent by [`Pool::simplify`]
    /// on this pool so far: a deterministic cost measure for regression tests.
    pub fn simplify_work(&self) -> u64 {
        self.memo.simplify_work
    }

    /// Simplifies `e` (see the module documentation). Memoised.
    pub fn simplify(&mut self, e: Id) -> Id {
        if let Some(&r) = self.memo.simplify.get(&e) {
            return r;
        }
        if let Some(ceiling) = self.memo.simplify_ceiling {
            let mut left = ceiling.saturating_sub(self.memo.simplify_work);
            return self.simplify_within(e, &mut left).unwrap_or_else(|| {
                self.memo.simplify_exceeded = true;
                e
            });
        }
        let r = self.simplify_uncached_unlimited(e);
        self.memo.simplify.insert(e, r);
        self.memo.simplify.insert(r, r);
        r
    }

    /// [`Pool::simplify`] spending at most `*budget` polynomial work units (taken from it) on
    /// rational normal forms, or `None` (and the budget spent) when that is not enough: a
    /// caller that only may print the result (an exact solution that `pdyn derive` writes by
    /// reference unless it is short) stops where its own work budget ends. Whenever it
    /// returns, the result is [`Pool::simplify`]'s (memoised ones cost nothing).
    pub fn simplify_within(&mut self, e: Id, budget: &mut u64) -> Option<Id> {
        if let Some(&r) = self.memo.simplify.get(&e) {
            return Some(r);
        }
        let r = self.simplify_uncached(e, Some(budget))?;
        self.memo.simplify.insert(e, r);
        self.memo.simplify.insert(r, r);
        Some(r)
    }

    /// Runs `f` with at most `work` polynomial work units for every [`Pool::simplify`] inside
    /// it together (on top of any enclosing budget), and says whether that was enough. Past
    /// the budget, `simplify` returns its argument as it is (and remembers nothing), so `f`
    /// finishes quickly with a valid but unsimplified result that the caller should discard
    /// when the budget ran out: an algorithm whose intermediate expressions swell (the
    /// closed form of two coupled oscillators with four symbolic parameters: 1.75 M units,
    /// 0.5–2 s) gives up instead of making its caller wait; it can stop early by checking
    /// [`Pool::simplify_budget_exhausted`].
    pub fn with_simplify_budget<R>(
        &mut self,
        work: u64,
        f: impl FnOnce(&mut Pool) -> R,
    ) -> (R, bool) {
        let (outer_ceiling, outer_exceeded) =
            (self.memo.simplify_ceiling, self.memo.simplify_exceeded);
        let mine = self.memo.simplify_work.saturating_add(work);
        let ceiling = outer_ceiling.map_or(mine, |c| c.min(mine));
        self.memo.simplify_ceiling = Some(ceiling);
        self.memo.simplify_exceeded = false;
        let r = f(self);
        let exceeded = self.memo.simplify_exceeded;
        self.memo.simplify_ceiling = outer_ceiling;
        // The enclosing budget ran out too when it was the tighter one.
        self.memo.simplify_exceeded =
            outer_exceeded || (exceeded && outer_ceiling.is_some_and(|c| c <= mine));
        (r, !exceeded)
    }

    /// Whether the innermost [`Pool::with_simplify_budget`] has run out: a long computation
    /// inside one checks it between steps and stops, its result being discarded anyway.
    pub fn simplify_budget_exhausted(&self) -> bool {
        self.memo.simplify_exceeded
    }

    /// [`Pool::simplify`] without its memo.
    fn simplify_uncached_unlimited(&mut self, e: Id) -> Id {
        // Without a limit nothing fails: `e` is only a fallback the types ask for.
        self.simplify_uncached(e, None).unwrap_or(e)
    }

    /// `limit`: the caller's work budget ([`Pool::simplify_within`]), `None` for none (then
    /// the result is never `None`).
    fn simplify_uncached(&mut self, e: Id, mut limit: Option<&mut u64>) -> Option<Id> {
        if matches!(
            self.node(e),
            Node::Num(_) | Node::Const(_) | Node::Time | Node::Sym(_) | Node::Coord(..)
        ) {
            return Some(e);
        }
        let base = self.simplify_args(e);
        let mut best = base;
        let mut best_cost = self.tree_size(base, usize::MAX);
        if best_cost > MAX_TREE {
            return Some(best);
        }
        if self.plain_polynomial(base) {
            // Its rational form is itself (see `plain_polynomial`): only the contraction of
            // sines and cosines can shorten it. A 100-link chain's particle velocities and
            // accelerations spent 0.3 s being converted to polynomials and back.
            let c = self.contract_trig(base);
            return Some(if self.tree_size(c, best_cost) < best_cost {
                c
            } else {
                base
            });
        }
        for expand_trig in [false, true] {
            // Each attempt has its own budget; under a caller's limit, an attempt that gets
            // less than that and fails might have succeeded: give up rather than return
            // something `simplify` would not.
            let allowed = match &limit {
                Some(left) => BUDGET.min(**left),
                None => BUDGET,
            };
            let (form, spent) = self.rational_form(base, expand_trig, allowed);
            if let Some(left) = limit.as_deref_mut() {
                if form.is_none() && allowed < BUDGET {
                    *left = 0;
                    return None;
                }
                *left -= spent.min(*left);
            }
            if let Some(c) = form {
                for cand in [c, self.contract_trig(c)] {
                    let cost = self.tree_size(cand, best_cost + 1);
                    if cost < best_cost {
                        best = cand;
                        best_cost = cost;
                    }
                }
            }
        }
        Some(best)
    }

    /// Contracts products of sines and cosines back into angle sums, in every sum of `e`:
    /// `R cos a cos b ± R sin a sin b = R cos(a ∓ b)`, `R sin a cos b ± R cos a sin b =
    /// R sin(a ± b)` (the inverse of the expansion used to find cancellations, so that results
    /// read like `cos(theta - phi)` rather than four products).
    ///
    /// The search is bounded ([`MAX_CONTRACT_WORK`] term views and view pairs per call): when
    /// the bound is reached the remaining sums are left as they are (equal, not contracted).
    pub fn contract_trig(&mut self, e: Id) -> Id {
        self.contract_trig_counted(e).0
    }

    /// [`Pool::contract_trig`], or [`BudgetError::Contract`] when the bound was reached.
    pub fn try_contract_trig(&mut self, e: Id) -> Result<Id, BudgetError> {
        match self.contract_trig_counted(e) {
            (r, false) => Ok(r),
            (_, true) => Err(BudgetError::Contract {
                limit: MAX_CONTRACT_WORK,
            }),
        }
    }

    /// The contraction and whether the work bound was reached.
    fn contract_trig_counted(&mut self, e: Id) -> (Id, bool) {
        let mut work = 0usize;
        // A sum with no other sum below it (a dot product of two partial velocities, the x
        // and y parts of a forcing term: 15,000 of them in a 100-link chain) is contracted
        // as the rewrite below would, without walking and indexing its tree first.
        if matches!(self.node(e), Node::Add(_)) && self.no_sum_below(e) {
            let r = self.contract_sum(e, &mut work);
            return (r, work > MAX_CONTRACT_WORK);
        }
        let r = self.rewrite(
            e,
            |_, _| None,
            |p, r| {
                if matches!(p.node(r), Node::Add(_)) && work <= MAX_CONTRACT_WORK {
                    p.contract_sum(r, &mut work)
                } else {
                    r
                }
            },
        );
        (r, work > MAX_CONTRACT_WORK)
    }

    /// Whether the sum `e` is small (at most 64 nodes below it, counted as a tree) and has no
    /// other sum below it: then the rewrite of `contract_trig_counted` changes nothing but
    /// `e` itself.
    fn no_sum_below(&self, e: Id) -> bool {
        let Node::Add(ts) = self.node(e) else {
            return false;
        };
        let mut stack: Vec<Id> = ts.to_vec();
        let mut visited = 0;
        while let Some(x) = stack.pop() {
            visited += 1;
            if visited > 64 {
                return false;
            }
            match self.node(x) {
                Node::Add(_) => return false,
                Node::Mul(cs) | Node::Call(_, cs) => stack.extend(cs.iter().copied()),
                Node::Pow(b, x) => stack.extend([*b, *x]),
                _ => {}
            }
        }
        true
    }

    /// One sum: repeatedly merges a matching pair of terms, counting the views built and the
    /// pairs of views compared in `work` (quadratic in the trig factors per term: a few terms
    /// with many sines and cosines once stalled here for over 30 s).
    fn contract_sum(&mut self, s: Id, work: &mut usize) -> Id {
        let mut cur = s;
        for _ in 0..32 {
            if *work > MAX_CONTRACT_WORK {
                return cur;
            }
            let Node::Add(ts) = self.node(cur).clone() else {
                return cur;
            };
            if ts.len() > 64 {
                return cur;
            }
            // (term index, coefficient, rest, kind: (first fn, second fn), a, b)
            let mut views = Vec::new();
            for (i, &t) in ts.iter().enumerate() {
                let (c, rest) = self.split_coeff(t);
                let fs: Vec<Id> = match self.node(rest) {
                    Node::Mul(fs) => fs.to_vec(),
                    _ => vec![rest],
                };
                let trig: Vec<usize> = (0..fs.len())
                    .filter(|&k| matches!(self.node(fs[k]), Node::Call(Func::Sin | Func::Cos, _)))
                    .collect();
                // Bounded before building: each view costs a product node.
                *work += trig.len() * trig.len().saturating_sub(1) / 2;
                if *work > MAX_CONTRACT_WORK {
                    return cur;
                }
                for x in 0..trig.len() {
                    for y in x + 1..trig.len() {
                        let (f1, f2) = (fs[trig[x]], fs[trig[y]]);
                        let (Node::Call(k1, a1), Node::Call(k2, a2)) =
                            (self.node(f1).clone(), self.node(f2).clone())
                        else {
                            continue;
                        };
                        if a1[0] == a2[0] {
                            continue;
                        }
                        let others: Vec<Id> = fs
                            .iter()
                            .enumerate()
                            .filter(|(k, _)| *k != trig[x] && *k != trig[y])
                            .map(|(_, &f)| f)
                            .collect();
                        let r = self.mul(&others);
                        views.push((i, c.clone(), r, k1, a1[0], k2, a2[0]));
                    }
                }
            }
            *work += views.len() + views.len() * views.len() / 2;
            if *work > MAX_CONTRACT_WORK {
                return cur;
            }
            let mut merged = None;
            'search: for (x, v) in views.iter().enumerate() {
                for w in &views[x + 1..] {
                    if v.0 == w.0 || v.2 != w.2 {
                        continue;
                    }
                    // Normalise each view to (fn of a, fn of b) with a < b by id.
                    let norm = |v: &(usize, Number, Id, Func, Id, Func, Id)| {
                        if v.4 < v.6 {
                            (v.3, v.4, v.5, v.6)
                        } else {
                            (v.5, v.6, v.3, v.4)
                        }
                    };
                    let (p1, a, p2, b) = norm(v);
                    let (q1, a2, q2, b2) = norm(w);
                    if (a, b) != (a2, b2) {
                        continue;
                    }
                    use Func::{Cos, Sin};
                    // The anchor carries the result's coefficient: cos a cos b for a cosine,
                    // sin a cos b for a sine; `sign` is the other term's coefficient over it.
                    let (anchor, other, f) = match ((p1, p2), (q1, q2)) {
                        ((Cos, Cos), (Sin, Sin)) => (v, w, Cos),
                        ((Sin, Sin), (Cos, Cos)) => (w, v, Cos),
                        ((Sin, Cos), (Cos, Sin)) => (v, w, Sin),
                        ((Cos, Sin), (Sin, Cos)) => (w, v, Sin),
                        _ => continue,
                    };
                    let plus = if other.1 == anchor.1 {
                        true
                    } else if other.1 == anchor.1.neg() {
                        false
                    } else {
                        continue;
                    };
                    // cos a cos b ± sin a sin b = cos(a ∓ b); sin a cos b ± cos a sin b = sin(a ± b)
                    let sum = if f == Cos { !plus } else { plus };
                    let (v, w) = (anchor, other);
                    let arg = if sum { self.add2(a, b) } else { self.sub(a, b) };
                    let call = self.call(f, &[arg]);
                    let coef = self.num(v.1.clone());
                    let term = self.mul(&[coef, v.2, call]);
                    merged = Some((v.0, w.0, term));
                    break 'search;
                }
            }
            let Some((i, j, term)) = merged else {
                return cur;
            };
            let mut rest: Vec<Id> = ts
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != i && *k != j)
                .map(|(_, &t)| t)
                .collect();
            rest.push(term);
            cur = self.add(&rest);
        }
        cur
    }

    /// Rebuilds `e` with simplified function arguments and power bases/exponents.
    /// Whether `e` (canonical, its arguments simplified) is already its own rational normal
    /// form: a sum of products of atoms with positive integer powers, with no sine, cosine
    /// or tangent that the trigonometric expansion or the Pythagorean reduction would
    /// rewrite (an argument that is a sum or a multiple, a power of two or more, a tangent).
    /// Canonical sums have their like terms combined already, the denominator is 1, so
    /// `rational_form` would give `e` back.
    fn plain_polynomial(&self, e: Id) -> bool {
        let atom = |p: &Pool, a: Id, power: i64| match p.node(a) {
            Node::Sym(_) | Node::Coord(..) | Node::Const(_) | Node::Time => true,
            Node::Call(Func::Sin | Func::Cos, args) => {
                power < 2 && matches!(p.node(args[0]), Node::Sym(_) | Node::Coord(..) | Node::Time)
            }
            _ => false,
        };
        let factor = |p: &Pool, f: Id| match p.node(f) {
            Node::Num(Number::Rat(_)) => true,
            Node::Pow(b, x) => match p.as_num(*x).and_then(|n| n.as_integer()) {
                Some(k) if k >= 2 => atom(p, *b, k),
                _ => false,
            },
            _ => atom(p, f, 1),
        };
        let term = |p: &Pool, t: Id| match p.node(t) {
            Node::Mul(fs) => fs.iter().all(|&f| factor(p, f)),
            _ => factor(p, t),
        };
        match self.node(e) {
            Node::Add(ts) => ts.iter().all(|&t| term(self, t)),
            _ => term(self, e),
        }
    }

    fn simplify_args(&mut self, e: Id) -> Id {
        match self.node(e).clone() {
            Node::Add(ts) => {
                let ts: Vec<Id> = ts.iter().map(|&t| self.simplify_args(t)).collect();
                self.add(&ts)
            }
            Node::Mul(fs) => {
                let fs: Vec<Id> = fs.iter().map(|&f| self.simplify_args(f)).collect();
                self.mul(&fs)
            }
            Node::Pow(b, x) => {
                // Under a fractional or symbolic power the base becomes an atom of the rational
                // form, so it must be simplified on its own (sqrt(sin^2 + cos^2) = 1).
                let integer = self.as_num(x).and_then(|n| n.as_integer()).is_some();
                let b = if integer {
                    self.simplify_args(b)
                } else {
                    self.simplify(b)
                };
                let x = self.simplify(x);
                self.pow(b, x)
            }
            Node::Call(f, args) => {
                let args: Vec<Id> = args.iter().map(|&a| self.simplify(a)).collect();
                self.call(f, &args)
            }
            _ => e,
        }
    }

    /// `e` as a reduced ratio of polynomials, converted back to an expression; `None` when it
    /// does not apply (floating-point coefficients) or exceeds `budget` work units. Also
    /// returns the work spent.
    fn rational_form(&mut self, e: Id, expand_trig: bool, budget: u64) -> (Option<Id>, u64) {
        let mut cx = RationalForm::new(budget, expand_trig);
        let r = cx.convert(self, e).and_then(|(num, den)| {
            let (num, den) = cx.reduce_pythagorean(self, num, den)?;
            cx.cancel(num, den)
        });
        let spent = budget - cx.budget.0;
        self.memo.simplify_work += spent;
        let Some((num, den)) = r else {
            return (None, spent);
        };
        let n = cx.to_expr(self, &num);
        let d = cx.to_expr(self, &den);
        (Some(self.div(n, d)), spent)
    }

    /// Simplifies both sides' difference and reports whether it is zero: a sound but
    /// incomplete equality test (false can mean "could not prove").
    pub fn provably_equal(&mut self, a: Id, b: Id) -> bool {
        let d = self.sub(a, b);
        let d = self.expand(d);
        self.simplify(d) == Pool::ZERO
    }
}

/// Conversion between expressions and polynomials over a shared table of atoms.
pub(crate) struct RationalForm {
    atoms: Vec<Id>,
    index: FxHashMap<Id, u32>,
    pub(crate) budget: Budget,
    expand_trig: bool,
}

pub(crate) type Frac = (Poly, Poly);

fn one() -> Poly {
    Poly::constant(Rational::ONE)
}

impl RationalForm {
    pub(crate) fn new(budget: u64, expand_trig: bool) -> RationalForm {
        RationalForm {
            atoms: Vec::new(),
            index: FxHashMap::default(),
            budget: Budget(budget),
            expand_trig,
        }
    }

    fn atom(&mut self, id: Id) -> Poly {
        let k = match self.index.get(&id) {
            Some(&k) => k,
            None => {
                let k = self.atoms.len() as u32;
                self.atoms.push(id);
                self.index.insert(id, k);
                k
            }
        };
        Poly::atom(k)
    }

    pub(crate) fn convert(&mut self, p: &mut Pool, e: Id) -> Option<Frac> {
        match p.node(e).clone() {
            Node::Num(Number::Rat(r)) => Some((Poly::constant(r), one())),
            Node::Num(Number::Float(_)) => None,
            Node::Add(ts) => {
                let mut acc: Frac = (Poly::zero(), one());
                for t in ts.iter() {
                    let f = self.convert(p, *t)?;
                    if f.1 == acc.1 {
                        // The common case (polynomial terms): summed in place.
                        acc.0.add_assign(&f.0, &mut self.budget)?;
                    } else {
                        acc = self.add(acc, f)?;
                    }
                }
                Some(acc)
            }
            Node::Mul(fs) => {
                let mut acc: Frac = (one(), one());
                for f in fs.iter() {
                    let x = self.convert(p, *f)?;
                    let b = &mut self.budget;
                    acc = (acc.0.mul(&x.0, b)?, acc.1.mul(&x.1, b)?);
                }
                Some(acc)
            }
            Node::Pow(b, x) => {
                // Exponents past i64 are treated like symbolic ones: an atom.
                let r = p
                    .as_num(x)
                    .and_then(|n| n.as_rational().and_then(|r| r.small()));
                match r {
                    Some((num, 1)) => {
                        let base = self.convert(p, b)?;
                        if power_too_big(&base.0, &base.1, num) {
                            // Kept whole: an atom is exact, it only hides cancellations
                            // inside the power.
                            return Some((self.atom(e), one()));
                        }
                        self.power(base, num)
                    }
                    Some((num, den)) => {
                        // b^(p/q) = (b^(1/q))^p with b^(1/q) an atom.
                        let inv_q = p.num(Number::ratio(1, den));
                        let root = p.pow(b, inv_q);
                        if matches!(p.node(root), Node::Pow(rb, _) if *rb == b) {
                            let a = self.atom(root);
                            self.power((a, one()), num)
                        } else {
                            // The root simplified (sqrt(m^2) = m for m > 0): use root^p.
                            let pe = p.int(num);
                            let v = p.pow(root, pe);
                            if v == e {
                                return Some((self.atom(e), one()));
                            }
                            self.convert(p, v)
                        }
                    }
                    None => Some((self.atom(e), one())),
                }
            }
            Node::Call(f @ (Func::Sin | Func::Cos | Func::Tan), args) if self.expand_trig => {
                match expand_trig_call(p, f, args[0]) {
                    Some(x) => self.convert(p, x),
                    None => Some((self.atom(e), one())),
                }
            }
            _ => Some((self.atom(e), one())),
        }
    }

    fn power(&mut self, (n, d): Frac, k: i64) -> Option<Frac> {
        if power_too_big(&n, &d, k) {
            return None;
        }
        let b = &mut self.budget;
        let m = u32::try_from(k.unsigned_abs()).ok()?;
        if m > 64 {
            return None;
        }
        let (n, d) = (n.pow(m, b)?, d.pow(m, b)?);
        if k < 0 {
            if n.is_zero() {
                return None; // division by zero: leave it to evaluation (inf)
            }
            Some((d, n))
        } else {
            Some((n, d))
        }
    }

    fn add(&mut self, (n1, d1): Frac, (n2, d2): Frac) -> Option<Frac> {
        let b = &mut self.budget;
        if d1 == d2 {
            return Some((n1.add(&n2, b)?, d1));
        }
        if d1.as_constant().is_some() || d2.as_constant().is_some() {
            return Some((n1.mul(&d2, b)?.add(&n2.mul(&d1, b)?, b)?, d1.mul(&d2, b)?));
        }
        let g = gcd(&d1, &d2, b)?;
        let c1 = d1.div_exact(&g, b)?;
        let c2 = d2.div_exact(&g, b)?;
        let n = n1.mul(&c2, b)?.add(&n2.mul(&c1, b)?, b)?;
        Some((n, d1.mul(&c2, b)?))
    }

    /// Eliminates sin^2 or cos^2 of each angle, whichever leaves fewer terms.
    fn reduce_pythagorean(&mut self, p: &Pool, mut num: Poly, mut den: Poly) -> Option<Frac> {
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (i, &a) in self.atoms.iter().enumerate() {
            if let Node::Call(Func::Sin, args) = p.node(a) {
                let cos = self.atoms.iter().position(
                    |&c| matches!(p.node(c), Node::Call(Func::Cos, cargs) if cargs[0] == args[0]),
                );
                if let Some(j) = cos {
                    pairs.push((i as u32, j as u32));
                }
            }
        }
        let squared = |poly: &Poly, x: u32| {
            poly.terms
                .keys()
                .any(|m| m.iter().any(|&(a, e)| a == x && e >= 2))
        };
        for (s, c) in pairs {
            // No square of either to rewrite (a chain's sums are linear in each sine and
            // cosine): nothing to compare, and nothing copied.
            if ![&num, &den].iter().any(|p| squared(p, s) || squared(p, c)) {
                continue;
            }
            let b = &mut self.budget;
            let ns = eliminate_square(&num, s, c, b)?;
            let ds = eliminate_square(&den, s, c, b)?;
            let nc = eliminate_square(&num, c, s, b)?;
            let dc = eliminate_square(&den, c, s, b)?;
            // Fewer terms first, then lower total degree.
            let size = |a: &Poly, b: &Poly| {
                let deg = |p: &Poly| -> u32 {
                    p.terms
                        .keys()
                        .map(|m| m.iter().map(|&(_, e)| e).sum::<u32>())
                        .sum()
                };
                (a.terms.len() + b.terms.len(), deg(a) + deg(b))
            };
            let (s0, s1, s2) = (size(&num, &den), size(&ns, &ds), size(&nc, &dc));
            if s1 < s0 && s1 <= s2 {
                num = ns;
                den = ds;
            } else if s2 < s0 {
                num = nc;
                den = dc;
            }
        }
        Some((num, den))
    }

    fn cancel(&mut self, num: Poly, den: Poly) -> Option<Frac> {
        let b = &mut self.budget;
        if num.is_zero() {
            return Some((Poly::zero(), one()));
        }
        let (num, den) = if den.as_constant().is_some() {
            (num, den)
        } else {
            let g = gcd(&num, &den, b)?;
            (num.div_exact(&g, b)?, den.div_exact(&g, b)?)
        };
        // Normalise: denominator with leading coefficient 1.
        let (_, lc) = den.leading()?;
        let inv = lc.recip()?;
        let k = Poly::constant(inv);
        Some((num.mul(&k, b)?, den.mul(&k, b)?))
    }

    pub(crate) fn to_expr(&self, p: &mut Pool, poly: &Poly) -> Id {
        let mut terms = Vec::with_capacity(poly.terms.len());
        for (m, c) in &poly.terms {
            let mut fs = Vec::with_capacity(m.len() + 1);
            fs.push(p.num(Number::Rat(c.clone())));
            for &(a, e) in m {
                let base = self.atoms[a as usize];
                fs.push(p.powi(base, e as i64));
            }
            terms.push(p.mul(&fs));
        }
        p.add(&terms)
    }
}

/// Whether `(n/d)^k` could have more than [`MAX_POWER_TERMS`] terms in its numerator or
/// denominator: a sum of `t` terms to the power `k` has at most `C(t + k - 1, k)` (the
/// monomials of degree `k` in `t` variables), and at most `t^k`.
fn power_too_big(n: &Poly, d: &Poly, k: i64) -> bool {
    let k = k.unsigned_abs();
    let bound = |t: usize| -> u64 {
        let t = t as u64;
        if t <= 1 {
            return 1;
        }
        // C(t + k - 1, k) = C(t + k - 1, t - 1), computed incrementally, capped.
        let (mut c, mut pw) = (1u64, 1u64);
        for i in 1..=k.min(64) {
            c = c.saturating_mul(t - 1 + i) / i;
            pw = pw.saturating_mul(t);
            if c.min(pw) > MAX_POWER_TERMS {
                return u64::MAX;
            }
        }
        c.min(pw)
    };
    k > 64 || bound(n.terms.len()) > MAX_POWER_TERMS || bound(d.terms.len()) > MAX_POWER_TERMS
}

/// Replaces `x^k` (k ≥ 2) by `x^(k mod 2) * (1 - y^2)^(k div 2)`, i.e. uses `x^2 = 1 - y^2`.
fn eliminate_square(poly: &Poly, x: u32, y: u32, b: &mut Budget) -> Option<Poly> {
    let power_of_x = |m: &Mono| m.iter().find(|&&(a, _)| a == x).map_or(0, |&(_, e)| e);
    // Nothing to rewrite (most sums: a chain's velocities are linear in each sine): the
    // polynomial itself, without rebuilding it term by term.
    if poly.terms.keys().all(|m| power_of_x(m) < 2) {
        return Some(poly.clone());
    }
    b.spend(poly.terms.len())?;
    let mut one_minus_y2 = Poly::constant(Rational::ONE);
    one_minus_y2 = one_minus_y2.sub(&Poly::atom(y).pow(2, b)?, b)?;
    let mut out = Poly::zero();
    for (m, c) in &poly.terms {
        let k = power_of_x(m);
        if k < 2 {
            out.add_term(m.clone(), c.clone())?;
            continue;
        }
        let mut rest: Mono = m.iter().copied().filter(|&(a, _)| a != x).collect();
        if k % 2 == 1 {
            rest.push((x, 1));
            rest.sort_by_key(|&(a, _)| std::cmp::Reverse(a));
        }
        let f = one_minus_y2.pow(k / 2, b)?;
        for (fm, fc) in f.mul_term(&rest, c.clone(), b)?.terms {
            out.add_term(fm, fc)?;
        }
    }
    Some(out)
}

/// `sin`, `cos`, `tan` of a sum or of an integer multiple, written in terms of simpler angles.
fn expand_trig_call(p: &mut Pool, f: Func, u: Id) -> Option<Id> {
    if f == Func::Tan {
        let s = p.call(Func::Sin, &[u]);
        let c = p.call(Func::Cos, &[u]);
        return Some(p.div(s, c));
    }
    let (a, b) = match p.node(u).clone() {
        // An angle of more than MAX_TRIG_TERMS terms would expand into 2^(terms - 1) products
        // that seldom cancel (a fuzzed 7-term angle cost a second per simplify): kept whole.
        Node::Add(ts) if ts.len() > MAX_TRIG_TERMS => return None,
        Node::Add(ts) => {
            let a = ts[0];
            let b = p.add(&ts[1..]);
            (a, b)
        }
        Node::Mul(fs) => {
            let k = p.as_num(fs[0])?.as_integer()?;
            if !(2..=8).contains(&k) {
                return None;
            }
            let rest = p.mul(&fs[1..]);
            let km1 = p.int(k - 1);
            (p.mul2(km1, rest), rest)
        }
        _ => return None,
    };
    let (sa, ca) = (p.call(Func::Sin, &[a]), p.call(Func::Cos, &[a]));
    let (sb, cb) = (p.call(Func::Sin, &[b]), p.call(Func::Cos, &[b]));
    Some(match f {
        Func::Sin => {
            let x = p.mul2(sa, cb);
            let y = p.mul2(ca, sb);
            p.add2(x, y)
        }
        _ => {
            let x = p.mul2(ca, cb);
            let y = p.mul2(sa, sb);
            p.sub(x, y)
        }
    })
}

#[cfg(test)]
mod tests {
    use crate::pool::Pool;

    fn simp(src: &str) -> String {
        let mut p = Pool::new();
        let e = p.parse_scalar(src).unwrap();
        let s = p.simplify(e);
        p.to_text(s)
    }

    /// Within a budget: `simplify`'s result when it fits (same node), `None` when it does not,
    /// the budget spent either way; the memoised result is free.
    #[test]
    fn simplify_within_a_budget_gives_simplify_or_nothing() {
        let src = "(a^2*sin(x)^2 + a^2*cos(x)^2 + a*b)/(a*b + a^2)";
        let mut p = Pool::new();
        let e = p.parse_scalar(src).unwrap();
        let mut tiny = 3;
        assert_eq!(p.simplify_within(e, &mut tiny), None);
        assert_eq!(tiny, 0);
        let mut q = Pool::new();
        let f = q.parse_scalar(src).unwrap();
        let want = q.simplify(f);
        let mut ample = 1_000_000;
        let got = p.simplify_within(e, &mut ample).unwrap();
        assert_eq!(p.to_text(got), q.to_text(want));
        assert_eq!(p.to_text(got), "1");
        assert!(ample < 1_000_000);
        let mut none = 0;
        assert_eq!(p.simplify_within(e, &mut none), Some(got));
    }

    #[test]
    fn a_scoped_budget_stops_simplify_and_says_so() {
        let src = "(a^2*sin(x)^2 + a^2*cos(x)^2 + a*b)/(a*b + a^2)";
        let mut p = Pool::new();
        let e = p.parse_scalar(src).unwrap();
        // Too little: the expression comes back as it is, not remembered as simplified.
        let (r, enough) = p.with_simplify_budget(3, |p| p.simplify(e));
        assert!(!enough);
        assert_eq!(r, e);
        // Nested inside a tight outer budget, the outer one also runs out.
        let ((_, inner_enough), outer_enough) =
            p.with_simplify_budget(3, |p| p.with_simplify_budget(1_000_000, |p| p.simplify(e)));
        assert!(!inner_enough && !outer_enough);
        // Enough: the same answer as without a budget, and the budget is gone afterwards.
        let (r, enough) = p.with_simplify_budget(1_000_000, |p| p.simplify(e));
        assert!(enough);
        assert_eq!(p.to_text(r), "1");
        let f = p.parse_scalar("(x^2 - 1)/(x - 1)").unwrap();
        let g = p.simplify(f);
        assert_eq!(p.to_text(g), "1 + x");
    }

    #[test]
    fn pythagorean_identity() {
        assert_eq!(simp("sin(x)^2 + cos(x)^2"), "1");
        assert_eq!(simp("3*sin(x)^2 + 3*cos(x)^2 + y"), "3 + y");
        assert_eq!(simp("a*sin(x)^2 + a*cos(x)^2"), "a");
        assert_eq!(simp("sin(x)^4 - cos(x)^4"), "1 - 2*cos(x)^2");
    }

    #[test]
    fn rational_cancellation() {
        assert_eq!(simp("(x^2 - 1)/(x - 1)"), "1 + x");
        assert_eq!(simp("(a*b + a*c)/(b + c)"), "a");
        assert_eq!(simp("x^(3/2)/sqrt(x)"), "x");
        assert_eq!(simp("1/x + 1/y - (x + y)/(x*y)"), "0");
    }

    #[test]
    fn trig_products_contract_to_angle_sums() {
        let mut p = Pool::new();
        for (src, expected) in [
            ("cos(a)*cos(b) + sin(a)*sin(b)", "cos(a - b)"),
            ("cos(a)*cos(b) - sin(a)*sin(b)", "cos(a + b)"),
            ("m*g*sin(a)*cos(b) - m*g*cos(a)*sin(b)", "g*m*sin(a - b)"),
            ("x + 2*sin(a)*cos(b) + 2*cos(a)*sin(b)", "x + 2*sin(a + b)"),
        ] {
            let e = p.parse_scalar(src).unwrap();
            let c = p.contract_trig(e);
            assert_eq!(
                c,
                p.parse_scalar(expected).unwrap(),
                "{src} -> {}",
                p.to_text(c)
            );
        }
    }

    #[test]
    fn trig_contraction_is_bounded() {
        let mut p = Pool::new();
        // 64 terms of 12 trig factors each: 66 pairs per term, 4,224 views, 8.9 million pairs
        // of views per pass, over the bound: a typed error, and the lenient form returns an
        // equal expression.
        let trig: Vec<String> = (0..12)
            .map(|i| format!("{}(a{i})", if i % 2 == 0 { "cos" } else { "sin" }))
            .collect();
        let terms: Vec<String> = (0..64)
            .map(|k| format!("b{k}*{}", trig.join("*")))
            .collect();
        let e = p.parse_scalar(&terms.join(" + ")).unwrap();
        assert_eq!(
            p.try_contract_trig(e),
            Err(crate::BudgetError::Contract {
                limit: crate::budget::MAX_CONTRACT_WORK
            })
        );
        assert_eq!(p.contract_trig(e), e);
        // Small sums are contracted as before.
        let e = p.parse_scalar("cos(a)*cos(b) - sin(a)*sin(b)").unwrap();
        assert_eq!(
            p.try_contract_trig(e),
            Ok(p.parse_scalar("cos(a + b)").unwrap())
        );
    }

    #[test]
    fn trig_of_sums() {
        assert_eq!(simp("cos(p - q)*sin(q) + cos(q)*sin(p - q)"), "sin(p)");
        assert_eq!(simp("sin(2*x) - 2*sin(x)*cos(x)"), "0");
    }
}
