//! 3-vector algebra on expression components (fixed basis i, j, k).

use crate::pool::{Id, Pool};

/// `a · b`.
pub fn dot(p: &mut Pool, a: [Id; 3], b: [Id; 3]) -> Id {
    let terms = [0, 1, 2].map(|i| p.mul2(a[i], b[i]));
    p.add(&terms)
}

/// `a × b`.
pub fn cross(p: &mut Pool, a: [Id; 3], b: [Id; 3]) -> [Id; 3] {
    [0, 1, 2].map(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let l = p.mul2(a[j], b[k]);
        let r = p.mul2(a[k], b[j]);
        p.sub(l, r)
    })
}

/// `|a|`.
pub fn norm(p: &mut Pool, a: [Id; 3]) -> Id {
    let d = dot(p, a, a);
    p.sqrt(d)
}

/// `a / |a|`.
pub fn unit(p: &mut Pool, a: [Id; 3]) -> [Id; 3] {
    let n = norm(p, a);
    a.map(|c| p.div(c, n))
}

/// `s * a`.
pub fn scale(p: &mut Pool, s: Id, a: [Id; 3]) -> [Id; 3] {
    a.map(|c| p.mul2(s, c))
}

/// `a + b`.
pub fn add(p: &mut Pool, a: [Id; 3], b: [Id; 3]) -> [Id; 3] {
    [0, 1, 2].map(|i| p.add2(a[i], b[i]))
}

/// `a - b`.
pub fn sub(p: &mut Pool, a: [Id; 3], b: [Id; 3]) -> [Id; 3] {
    [0, 1, 2].map(|i| p.sub(a[i], b[i]))
}
