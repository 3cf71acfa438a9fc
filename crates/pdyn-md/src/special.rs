//! Scaling of the pair interaction between bonded neighbours (LAMMPS `special_bonds lj f₁ f₂
//! f₃`): the pair energy and force between atoms one, two and three bonds apart (1-2, 1-3,
//! 1-4 neighbours) are multiplied by `f₁`, `f₂`, `f₃`. A pair reachable by several paths
//! counts as its closest relation (a 1-2 pair that is also 1-3 in a ring is 1-2), as LAMMPS
//! counts it.
//!
//! The pair kernel computes every pair in full; this module then subtracts `(1 − f)` times
//! the interaction of each special pair within its cutoff (minimum image). That leaves the
//! vectorised kernel untouched and costs `O(special pairs)`; the result equals skipping or
//! scaling the pair in the kernel to round-off. It needs the pair to be in the neighbour list,
//! which the exact displacement check guarantees (`SimParams::neighbor_check`); with a list
//! rebuilt on a fixed schedule a pair missed by the list would be subtracted without having
//! been added.

use crate::potential::PairPotential;
use crate::{Bond, ForceField, MdError, System};

/// The factors of LAMMPS's default for pdyn-md: every pair interacts in full.
pub const NO_SCALING: [f64; 3] = [1.0, 1.0, 1.0];

/// The pairs whose interaction is scaled, and by how much.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpecialPairs {
    /// `(i, j, factor)`, `i < j`, factor ≠ 1, sorted by `(i, j)`.
    pairs: Vec<(u32, u32, f64)>,
}

impl SpecialPairs {
    /// The 1-2, 1-3 and 1-4 neighbours of `n` atoms joined by `bonds`, with `factors` (1-2,
    /// 1-3, 1-4); pairs with factor 1 are left out.
    pub fn from_bonds(n: usize, bonds: &[Bond], factors: [f64; 3]) -> Result<Self, MdError> {
        for (name, f) in ["special 1-2", "special 1-3", "special 1-4"]
            .into_iter()
            .zip(factors)
        {
            if !(f.is_finite() && f >= 0.0) {
                return Err(MdError::InvalidParameter { name, value: f });
            }
        }
        if factors == NO_SCALING || bonds.is_empty() {
            return Ok(SpecialPairs::default());
        }
        let mut adj: Vec<Vec<u32>> = vec![vec![]; n];
        for b in bonds {
            if b.i >= n || b.j >= n {
                return Err(MdError::IndexOutOfRange {
                    what: "bond particle",
                    index: b.i.max(b.j),
                    len: n,
                });
            }
            adj[b.i].push(b.j as u32);
            adj[b.j].push(b.i as u32);
        }
        // (i, j, level), level 0 for 1-2, 1 for 1-3, 2 for 1-4
        let mut found: Vec<(u32, u32, u8)> = vec![];
        let mut push = |a: u32, b: u32, level: u8| {
            if a != b {
                found.push((a.min(b), a.max(b), level));
            }
        };
        for i in 0..n as u32 {
            for &j in &adj[i as usize] {
                push(i, j, 0);
                for &k in &adj[j as usize] {
                    if k == i {
                        continue;
                    }
                    push(i, k, 1);
                    for &l in &adj[k as usize] {
                        if l != j {
                            push(i, l, 2);
                        }
                    }
                }
            }
        }
        found.sort_unstable();
        // the closest relation of each pair: the first of its run after sorting
        found.dedup_by_key(|p| (p.0, p.1));
        let pairs = found
            .into_iter()
            .map(|(i, j, level)| (i, j, factors[level as usize]))
            .filter(|p| p.2 != 1.0)
            .collect();
        Ok(SpecialPairs { pairs })
    }

    /// Number of scaled pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// Whether no pair is scaled.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// Removes `(1 − f)` of each special pair's interaction (within its cutoff) from `out`
    /// (forces, particle order); returns the changes of the energy and the virial.
    pub(crate) fn correct<P: PairPotential>(
        &self,
        s: &System,
        ff: &ForceField<P>,
        out: &mut [[f64; 3]],
    ) -> (f64, f64) {
        let (mut du, mut dw) = (0.0, 0.0);
        let p = &s.particles;
        for &(i, j, f) in &self.pairs {
            let (i, j) = (i as usize, j as usize);
            let pot = ff.get(s.types[i] as usize, s.types[j] as usize);
            let d = s.sim_box.delta(p.pos(i), p.pos(j)).0;
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let rc = pot.cutoff();
            if r2 >= rc * rc {
                continue;
            }
            let (e, fr) = pot.energy_force(r2);
            let g = 1.0 - f;
            for (k, dk) in d.iter().enumerate() {
                out[i][k] -= g * fr * dk;
                out[j][k] += g * fr * dk;
            }
            du -= g * e;
            dw -= g * fr * r2;
        }
        (du, dw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BondKind;

    fn bonds(pairs: &[(usize, usize)]) -> Vec<Bond> {
        let kind = BondKind::Harmonic { k: 1.0, r0: 1.0 };
        pairs.iter().map(|&(i, j)| Bond { i, j, kind }).collect()
    }

    #[test]
    fn chain_and_ring_neighbours_are_classified_by_closest_relation() {
        // chain 0-1-2-3-4: 1-2 (0,1)..; 1-3 (0,2)..; 1-4 (0,3), (1,4)
        let s = SpecialPairs::from_bonds(
            5,
            &bonds(&[(0, 1), (1, 2), (2, 3), (3, 4)]),
            [0.0, 0.5, 0.25],
        )
        .unwrap();
        let want = vec![
            (0, 1, 0.0),
            (0, 2, 0.5),
            (0, 3, 0.25),
            (1, 2, 0.0),
            (1, 3, 0.5),
            (1, 4, 0.25),
            (2, 3, 0.0),
            (2, 4, 0.5),
            (3, 4, 0.0),
        ];
        assert_eq!(s.pairs, want);
        // a 4-ring 0-1-2-3-0: (0,3) is 1-2 although also 1-4; (0,2) is 1-3
        let s = SpecialPairs::from_bonds(
            4,
            &bonds(&[(0, 1), (1, 2), (2, 3), (3, 0)]),
            [0.0, 0.5, 0.25],
        )
        .unwrap();
        assert!(s.pairs.contains(&(0, 3, 0.0)));
        assert!(s.pairs.contains(&(0, 2, 0.5)));
        assert_eq!(s.len(), 6);
        // factors of 1 are left out; a bad factor is refused
        let s = SpecialPairs::from_bonds(5, &bonds(&[(0, 1), (1, 2)]), [0.0, 1.0, 1.0]).unwrap();
        assert_eq!(s.pairs, vec![(0, 1, 0.0), (1, 2, 0.0)]);
        assert!(SpecialPairs::from_bonds(3, &bonds(&[(0, 1)]), [f64::NAN, 1.0, 1.0]).is_err());
    }
}
