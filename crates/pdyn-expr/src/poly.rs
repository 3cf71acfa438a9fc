//! Sparse multivariate polynomials with exact rational coefficients over "atoms".
//!
//! An atom is any expression that is not a sum, product or integer power: a symbol, a
//! coordinate, `sin(theta)`, `sqrt(x^2 + y^2)`. [`simplify`](crate::simplify) writes an
//! expression as a ratio of two such polynomials, reduces it modulo `sin^2 + cos^2 - 1`, and
//! cancels their greatest common divisor, computed by the primitive pseudo-remainder sequence
//! (Knuth, TAOCP vol. 2, §4.6.1; Geddes, Czapor & Labahn, *Algorithms for Computer Algebra*,
//! §7.2), recursively in one variable at a time.
//!
//! Every operation takes a [`Budget`]: hostile or merely huge inputs make simplification give up
//! (`None`) instead of running for minutes. Coefficient overflow also gives up.

use crate::number::Rational;
use std::collections::BTreeMap;

/// A monomial: `(atom, exponent)` pairs sorted by atom index, highest first, so that the
/// derived `Ord` is the lexicographic order with the highest atom most significant.
pub type Mono = Vec<(u32, u32)>;

/// A polynomial: monomial → nonzero coefficient.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Poly {
    /// Terms, ordered by monomial (the leading term is the last).
    pub terms: BTreeMap<Mono, Rational>,
}

/// Work limit shared by a chain of polynomial operations.
#[derive(Clone, Copy, Debug)]
pub struct Budget(pub u64);

impl Budget {
    pub(crate) fn spend(&mut self, n: usize) -> Option<()> {
        self.0 = self.0.checked_sub(n as u64 + 1)?;
        Some(())
    }
}

fn mono_mul(a: &Mono, b: &Mono) -> Option<Mono> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        if j == b.len() || (i < a.len() && a[i].0 > b[j].0) {
            out.push(a[i]);
            i += 1;
        } else if i == a.len() || b[j].0 > a[i].0 {
            out.push(b[j]);
            j += 1;
        } else {
            out.push((a[i].0, a[i].1.checked_add(b[j].1)?));
            i += 1;
            j += 1;
        }
    }
    Some(out)
}

/// `a / b` when `b` divides `a`.
fn mono_div(a: &Mono, b: &Mono) -> Option<Mono> {
    let mut out = a.clone();
    for &(v, e) in b {
        let pos = out.iter().position(|&(w, _)| w == v)?;
        let have = out[pos].1;
        if have < e {
            return None;
        }
        if have == e {
            out.remove(pos);
        } else {
            out[pos].1 = have - e;
        }
    }
    Some(out)
}

fn deg_in(m: &Mono, v: u32) -> u32 {
    m.iter().find(|&&(w, _)| w == v).map_or(0, |&(_, e)| e)
}

impl Poly {
    /// The zero polynomial.
    pub fn zero() -> Poly {
        Poly::default()
    }
    /// A constant.
    pub fn constant(c: Rational) -> Poly {
        let mut p = Poly::zero();
        if c != Rational::ZERO {
            p.terms.insert(Vec::new(), c);
        }
        p
    }
    /// The atom `v`.
    pub fn atom(v: u32) -> Poly {
        let mut p = Poly::zero();
        p.terms.insert(vec![(v, 1)], Rational::ONE);
        p
    }
    /// True for 0.
    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }
    /// The value if constant.
    pub fn as_constant(&self) -> Option<Rational> {
        match self.terms.len() {
            0 => Some(Rational::ZERO),
            1 => self.terms.get(&Vec::new()).cloned(),
            _ => None,
        }
    }
    /// Leading (monomial, coefficient) in lex order.
    pub fn leading(&self) -> Option<(&Mono, Rational)> {
        self.terms.iter().next_back().map(|(m, c)| (m, c.clone()))
    }

    pub(crate) fn add_term(&mut self, m: Mono, c: Rational) -> Option<()> {
        if c == Rational::ZERO {
            return Some(());
        }
        match self.terms.get_mut(&m) {
            Some(x) => {
                let s = x.checked_add(&c)?;
                if s == Rational::ZERO {
                    self.terms.remove(&m);
                } else {
                    *x = s;
                }
            }
            None => {
                self.terms.insert(m, c);
            }
        }
        Some(())
    }

    /// `self + k*other`.
    pub fn add_scaled(&self, other: &Poly, k: Rational, b: &mut Budget) -> Option<Poly> {
        b.spend(self.terms.len() + other.terms.len())?;
        let mut out = self.clone();
        for (m, c) in &other.terms {
            out.add_term(m.clone(), c.checked_mul(&k)?)?;
        }
        Some(out)
    }
    /// `self += o`, in place: linear in `o`'s size, where [`Poly::add`] copies `self`
    /// (summing `n` terms one by one with it was quadratic).
    pub fn add_assign(&mut self, o: &Poly, b: &mut Budget) -> Option<()> {
        b.spend(o.terms.len())?;
        for (m, c) in &o.terms {
            self.add_term(m.clone(), c.clone())?;
        }
        Some(())
    }
    /// Sum.
    pub fn add(&self, o: &Poly, b: &mut Budget) -> Option<Poly> {
        self.add_scaled(o, Rational::ONE, b)
    }
    /// Difference.
    pub fn sub(&self, o: &Poly, b: &mut Budget) -> Option<Poly> {
        self.add_scaled(o, Rational::MINUS_ONE, b)
    }
    /// Product.
    pub fn mul(&self, o: &Poly, b: &mut Budget) -> Option<Poly> {
        b.spend(self.terms.len() * o.terms.len())?;
        let mut out = Poly::zero();
        for (m1, c1) in &self.terms {
            for (m2, c2) in &o.terms {
                out.add_term(mono_mul(m1, m2)?, c1.checked_mul(c2)?)?;
            }
        }
        Some(out)
    }
    /// Product with a single term.
    pub fn mul_term(&self, m: &Mono, c: Rational, b: &mut Budget) -> Option<Poly> {
        b.spend(self.terms.len())?;
        let mut out = Poly::zero();
        for (m1, c1) in &self.terms {
            out.add_term(mono_mul(m1, m)?, c1.checked_mul(&c)?)?;
        }
        Some(out)
    }
    /// Power with a non-negative exponent.
    pub fn pow(&self, k: u32, b: &mut Budget) -> Option<Poly> {
        let mut acc = Poly::constant(Rational::ONE);
        for _ in 0..k {
            acc = acc.mul(self, b)?;
        }
        Some(acc)
    }

    /// Exact quotient `self / d`, or `None` if `d` does not divide `self` (or the budget runs out).
    pub fn div_exact(&self, d: &Poly, b: &mut Budget) -> Option<Poly> {
        let (dm, dc) = d.leading()?;
        let (dm, dc) = (dm.clone(), dc);
        let inv = dc.recip()?;
        let mut r = self.clone();
        let mut q = Poly::zero();
        while let Some((rm, rc)) = r.leading() {
            let m = mono_div(rm, &dm)?;
            let c = rc.checked_mul(&inv)?;
            q.add_term(m.clone(), c.clone())?;
            let sub = d.mul_term(&m, c, b)?;
            r = r.sub(&sub, b)?;
        }
        Some(q)
    }

    /// Atoms that occur.
    pub fn vars(&self) -> Vec<u32> {
        let mut v: Vec<u32> = self
            .terms
            .keys()
            .flat_map(|m| m.iter().map(|&(a, _)| a))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Degree in atom `v`.
    pub fn degree(&self, v: u32) -> u32 {
        self.terms.keys().map(|m| deg_in(m, v)).max().unwrap_or(0)
    }

    /// Coefficient of `v^k`, a polynomial in the other atoms.
    pub fn coeff(&self, v: u32, k: u32) -> Poly {
        let mut out = Poly::zero();
        for (m, c) in &self.terms {
            if deg_in(m, v) == k {
                let rest: Mono = m.iter().copied().filter(|&(w, _)| w != v).collect();
                out.terms.insert(rest, c.clone());
            }
        }
        out
    }

    /// Multiplies by `v^k`.
    fn shift(&self, v: u32, k: u32) -> Option<Poly> {
        if k == 0 {
            return Some(self.clone());
        }
        let mut out = Poly::zero();
        for (m, c) in &self.terms {
            out.terms.insert(mono_mul(m, &vec![(v, k)])?, c.clone());
        }
        Some(out)
    }

    /// Divides every coefficient by the leading one (a canonical associate over Q).
    pub fn monic(&self) -> Option<Poly> {
        let (_, lc) = self.leading()?;
        let inv = lc.recip()?;
        let mut out = Poly::zero();
        for (m, c) in &self.terms {
            out.terms.insert(m.clone(), c.checked_mul(&inv)?);
        }
        Some(out)
    }

    /// Pseudo-remainder of `self` by `d` with respect to atom `v`.
    fn prem(&self, d: &Poly, v: u32, b: &mut Budget) -> Option<Poly> {
        let dd = d.degree(v);
        let lc = d.coeff(v, dd);
        let mut r = self.clone();
        while !r.is_zero() && r.degree(v) >= dd {
            let dr = r.degree(v);
            let lr = r.coeff(v, dr);
            let t1 = r.mul(&lc, b)?;
            let t2 = d.mul(&lr, b)?.shift(v, dr - dd)?;
            r = t1.sub(&t2, b)?;
        }
        Some(r)
    }

    /// Content with respect to `v`: the GCD of the coefficients of the powers of `v`.
    fn content(&self, v: u32, b: &mut Budget) -> Option<Poly> {
        let mut g = Poly::zero();
        for k in (0..=self.degree(v)).rev() {
            let c = self.coeff(v, k);
            if c.is_zero() {
                continue;
            }
            g = gcd(&g, &c, b)?;
            if g.as_constant().is_some() {
                return Some(Poly::constant(Rational::ONE));
            }
        }
        Some(g)
    }
}

/// Greatest common divisor, normalised monic (1 for coprime inputs). `gcd(0, p) = monic(p)`.
pub fn gcd(a: &Poly, c: &Poly, b: &mut Budget) -> Option<Poly> {
    b.spend(a.terms.len() + c.terms.len())?;
    if a.is_zero() {
        return if c.is_zero() {
            Some(Poly::zero())
        } else {
            c.monic()
        };
    }
    if c.is_zero() {
        return a.monic();
    }
    if a.as_constant().is_some() || c.as_constant().is_some() {
        return Some(Poly::constant(Rational::ONE));
    }
    let va = a.vars();
    let vc = c.vars();
    // A variable present in only one of them can only enter the GCD through its content.
    if let Some(&v) = va.iter().find(|v| !vc.contains(v)) {
        let ct = a.content(v, b)?;
        return gcd(&ct, c, b);
    }
    if let Some(&v) = vc.iter().find(|v| !va.contains(v)) {
        let ct = c.content(v, b)?;
        return gcd(a, &ct, b);
    }
    let v = *va.last()?;
    let ca = a.content(v, b)?;
    let cc = c.content(v, b)?;
    let g_cont = gcd(&ca, &cc, b)?;
    let mut p = a.div_exact(&ca, b)?;
    let mut q = c.div_exact(&cc, b)?;
    if p.degree(v) < q.degree(v) {
        std::mem::swap(&mut p, &mut q);
    }
    loop {
        let r = p.prem(&q, v, b)?;
        if r.is_zero() {
            break;
        }
        if r.degree(v) == 0 {
            q = Poly::constant(Rational::ONE);
            break;
        }
        let cr = r.content(v, b)?;
        p = q;
        q = r.div_exact(&cr, b)?;
    }
    g_cont.mul(&q, b)?.monic()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(terms: &[(&[(u32, u32)], i64)]) -> Poly {
        let mut out = Poly::zero();
        for (m, c) in terms {
            let mut m: Mono = m.to_vec();
            m.sort_by_key(|&(a, _)| std::cmp::Reverse(a));
            out.add_term(m, Rational::int(*c)).unwrap();
        }
        out
    }

    #[test]
    fn gcd_of_products() {
        let mut b = Budget(1_000_000);
        // (x + y)(x - 2) and (x + y)(y + 3), x = atom 0, y = atom 1
        let xy = p(&[(&[(0, 1)], 1), (&[(1, 1)], 1)]);
        let f1 = p(&[(&[(0, 1)], 1), (&[], -2)]);
        let f2 = p(&[(&[(1, 1)], 1), (&[], 3)]);
        let a = xy.mul(&f1, &mut b).unwrap();
        let c = xy.mul(&f2, &mut b).unwrap();
        let g = gcd(&a, &c, &mut b).unwrap();
        assert_eq!(g, xy.monic().unwrap());
        let q = a.div_exact(&g, &mut b).unwrap();
        assert_eq!(q, f1);
        assert!(a.div_exact(&f2, &mut b).is_none());
    }

    #[test]
    fn coprime_gives_one() {
        let mut b = Budget(1_000_000);
        let x2m1 = p(&[(&[(0, 2)], 1), (&[], -1)]);
        let x1 = p(&[(&[(0, 1)], 1), (&[(1, 1)], 1)]);
        assert_eq!(
            gcd(&x2m1, &x1, &mut b).unwrap(),
            Poly::constant(Rational::ONE)
        );
        let xm1 = p(&[(&[(0, 1)], 1), (&[], -1)]);
        assert_eq!(gcd(&x2m1, &xm1, &mut b).unwrap(), xm1);
    }

    #[test]
    fn budget_stops_work() {
        let mut b = Budget(10);
        let x = p(&[(&[(0, 1)], 1), (&[], 1)]);
        assert!(x.pow(30, &mut b).is_none());
    }
}
