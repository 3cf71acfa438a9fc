//! Each acceleration summed from the kernels' outputs: the terms of a coordinate's
//! acceleration are the outputs of the elements pushing its particle along its axis.
//!
//! The terms of each acceleration, in their order (kernel by kernel, output by output, element
//! by element), are the rows of a sparse matrix. Summed row by row, each sum is a chain of
//! dependent additions, one load of an index and one of a value per term. But the three
//! components of a particle's acceleration mostly have parallel rows: its next term along `y`
//! is the output after its next term along `x` in the same kernel (one output column,
//! `elements` values, further on), and its next along `z` as far again. Such a step is kept
//! once, as `(index of x's term, stride)`, and the three sums advance together: one index load
//! for three terms, three independent chains of additions. A term without partners in the
//! other rows (gravity's, along `z` alone) is a step of its own row. Every sum adds the same
//! terms in the same order, from the same starting value, as summing its row alone with
//! `Iterator::sum`: the same bits.
//!
//! When the outputs and the rows they add to step together (a net declared as families,
//! [`super::runs`]), the sums go instead output by output in the outputs' order, each
//! output added into its row in memory, run by run: each row still adds its terms in its
//! order (the outputs' order) from the same starting value, so the bits are again the same.

use super::runs::Runs;

/// One step of a particle's three sums.
#[derive(Clone, Copy, Debug)]
enum Step {
    /// Outputs `i`, `i + s`, `i + 2s` added to the x, y and z sums.
    Together { i: u32, s: u32 },
    /// Output `i` added to the sum of `axis` alone.
    Alone { axis: u8, i: u32 },
}

/// The x, y, z accelerations of one particle, summed by `steps[start..end]`.
#[derive(Clone, Debug)]
struct Triple {
    rows: [u32; 3],
    start: u32,
    end: u32,
}

/// How every acceleration is summed from the outputs.
#[derive(Clone, Debug)]
pub(super) struct Sums {
    order: Order,
    rows: usize,
    /// Terms in all.
    total: usize,
    /// The value `Iterator::sum` of `f64` starts from (−0.0 in current Rust), so that a sum is
    /// bit for bit that of its terms summed alone.
    zero: f64,
}

/// The order the terms are added in.
#[derive(Clone, Debug)]
enum Order {
    /// Output by output: every term as `(row, output)` in the outputs' order, in runs (when
    /// they pay).
    ByOutput(Runs),
    /// Particle by particle, row by row.
    ByParticle(ByParticle),
}

/// The sums particle by particle: the triples, then the rows of no triple.
#[derive(Clone, Debug)]
struct ByParticle {
    triples: Vec<Triple>,
    steps: Vec<Step>,
    /// Rows of no triple (a particle with an axis that is not a coordinate) and their terms:
    /// those of `singles[k]` are `terms[single_start[k]..single_start[k + 1]]`.
    singles: Vec<u32>,
    single_start: Vec<u32>,
    terms: Vec<u32>,
}

/// Whether outputs `a`, `b`, `c` are one step apart each (`b - a == c - b > 0`).
fn parallel(a: u32, b: u32, c: u32) -> bool {
    b > a && c > b && b - a == c - b
}

impl Sums {
    /// The sums of the rows whose terms are `terms[start[r]..start[r + 1]]` (indices of
    /// outputs, `< outputs`), rows grouped by `particles` (per particle, the row of each axis
    /// that is a coordinate). `None` when a term indexes no output or the table is malformed
    /// (cannot happen: the kernels built it).
    pub(super) fn new(
        start: &[u32],
        terms: &[u32],
        particles: &[[Option<u32>; 3]],
        outputs: usize,
    ) -> Option<Sums> {
        let rows = start.len().checked_sub(1)?;
        if terms.len() != *start.last()? as usize || terms.iter().any(|&t| t as usize >= outputs) {
            return None;
        }
        let by_output = in_output_order(start, terms, outputs);
        if by_output.pay() {
            return Some(Sums {
                order: Order::ByOutput(by_output),
                rows,
                total: terms.len(),
                zero: std::iter::empty::<f64>().sum(),
            });
        }
        let row = |r: u32| -> Option<&[u32]> {
            let r = r as usize;
            terms.get(*start.get(r)? as usize..*start.get(r + 1)? as usize)
        };
        let mut in_triple = vec![false; rows];
        let mut triples = Vec::new();
        let mut steps = Vec::new();
        for axes in particles {
            let [Some(x), Some(y), Some(z)] = *axes else {
                continue;
            };
            let begin = steps.len() as u32;
            align([row(x)?, row(y)?, row(z)?], &mut steps);
            for r in [x, y, z] {
                *in_triple.get_mut(r as usize)? = true;
            }
            triples.push(Triple {
                rows: [x, y, z],
                start: begin,
                end: steps.len() as u32,
            });
        }
        let singles: Vec<u32> = (0..rows as u32)
            .filter(|&r| !in_triple[r as usize])
            .collect();
        let mut single_start = vec![0];
        let mut single_terms = Vec::new();
        for &r in &singles {
            single_terms.extend_from_slice(row(r)?);
            single_start.push(single_terms.len() as u32);
        }
        Some(Sums {
            order: Order::ByParticle(ByParticle {
                triples,
                steps,
                singles,
                single_start,
                terms: single_terms,
            }),
            rows,
            total: terms.len(),
            zero: std::iter::empty::<f64>().sum(),
        })
    }

    /// Terms added per evaluation three at a time (a deterministic count).
    pub(super) fn together(&self) -> usize {
        match &self.order {
            Order::ByOutput(_) => 0,
            Order::ByParticle(p) => {
                let together = p
                    .steps
                    .iter()
                    .filter(|s| matches!(s, Step::Together { .. }));
                3 * together.count()
            }
        }
    }

    /// Terms added per evaluation, in all.
    pub(super) fn terms(&self) -> usize {
        self.total
    }

    /// The runs the sums go by, output by output, if they do (a deterministic count).
    pub(super) fn runs(&self) -> Option<usize> {
        match &self.order {
            Order::ByOutput(runs) => Some(runs.len()),
            Order::ByParticle(_) => None,
        }
    }

    /// `acc[r]` = the sum of row `r`'s terms in `outputs`, for every row.
    pub(super) fn sum_into(&self, outputs: &[f64], acc: &mut [f64]) {
        let p = match &self.order {
            Order::ByOutput(runs) => {
                let acc = &mut acc[..self.rows];
                acc.fill(self.zero);
                runs.add(outputs, acc);
                return;
            }
            Order::ByParticle(p) => p,
        };
        // SAFETY (every `get_unchecked` below): `new` checked that every term indexes
        // `outputs`, whose length the kernels never change; a step's indices are such terms.
        let at = |i: u32| unsafe { *outputs.get_unchecked(i as usize) };
        for t in &p.triples {
            // Three locals, not an array indexed by the axis: they stay in registers.
            let (mut x, mut y, mut z) = (self.zero, self.zero, self.zero);
            for step in &p.steps[t.start as usize..t.end as usize] {
                match *step {
                    Step::Together { i, s } => {
                        x += at(i);
                        y += at(i + s);
                        z += at(i + 2 * s);
                    }
                    Step::Alone { axis: 0, i } => x += at(i),
                    Step::Alone { axis: 1, i } => y += at(i),
                    Step::Alone { i, .. } => z += at(i),
                }
            }
            let [rx, ry, rz] = t.rows;
            acc[rx as usize] = x;
            acc[ry as usize] = y;
            acc[rz as usize] = z;
        }
        for (&r, w) in p.singles.iter().zip(p.single_start.windows(2)) {
            let mut s = self.zero;
            for &i in &p.terms[w[0] as usize..w[1] as usize] {
                s += at(i);
            }
            acc[r as usize] = s;
        }
    }
}

/// Every term `(row, output)` in the order of the outputs (`start`, `terms` as for
/// [`Sums::new`], which checked them; each output is a term of one row at most). A row's terms
/// are in the order of their outputs, so that adding them in this order adds each row's in
/// its order.
fn in_output_order(start: &[u32], terms: &[u32], outputs: usize) -> Runs {
    const NONE: u32 = u32::MAX;
    let mut row_of = vec![NONE; outputs];
    let mut ordered = true;
    for (r, w) in start.windows(2).enumerate() {
        let Some(row) = terms.get(w[0] as usize..w[1] as usize) else {
            return Runs::default();
        };
        ordered &= row.windows(2).all(|p| p[0] < p[1]);
        for &i in row {
            ordered &= row_of[i as usize] == NONE;
            row_of[i as usize] = r as u32;
        }
    }
    if !ordered {
        // Not a table the kernels build: no runs (the steps keep each row's order).
        return Runs::default();
    }
    Runs::new(
        row_of
            .iter()
            .enumerate()
            .filter(|(_, &r)| r != NONE)
            .map(|(i, &r)| (r, i as u32)),
    )
}

/// The steps summing three rows, each row's terms in its order: together while the next
/// terms are parallel; otherwise the one row whose next term alone keeps the others from
/// being parallel (gravity's along `z`), or else every row one term alone.
fn align(rows: [&[u32]; 3], steps: &mut Vec<Step>) {
    let mut next = [0usize; 3];
    let term = |c: usize, k: usize| rows[c].get(k).copied();
    loop {
        let here = [0, 1, 2].map(|c| term(c, next[c]));
        if here.iter().all(Option::is_none) {
            return;
        }
        if let [Some(a), Some(b), Some(c)] = here {
            if parallel(a, b, c) {
                steps.push(Step::Together { i: a, s: b - a });
                next.iter_mut().for_each(|k| *k += 1);
                continue;
            }
        }
        // A row whose next term, skipped, leaves the three parallel.
        let skip = (0..3).find(|&c| {
            let mut after = next;
            after[c] += 1;
            match [0, 1, 2].map(|d| term(d, after[d])) {
                [Some(a), Some(b), Some(c)] => parallel(a, b, c),
                _ => false,
            }
        });
        for c in 0..3 {
            if skip.is_none_or(|s| s == c) {
                if let Some(i) = here[c] {
                    steps.push(Step::Alone { axis: c as u8, i });
                    next[c] += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Sums;

    /// Each row summed alone, as the kernels summed before there were triples.
    fn alone(start: &[u32], terms: &[u32], outputs: &[f64]) -> Vec<f64> {
        start
            .windows(2)
            .map(|w| {
                terms[w[0] as usize..w[1] as usize]
                    .iter()
                    .map(|&i| outputs[i as usize])
                    .sum()
            })
            .collect()
    }

    /// Rows of four particles: one whose rows are parallel and then go on along z alone
    /// (gravity), one whose rows part after one term, one with a constant axis (no triple),
    /// one whose z row starts alone; values chosen so that the order of the additions shows in
    /// the last bits.
    #[test]
    fn sums_are_those_of_each_row_alone_bit_for_bit() {
        // Kernel A: 4 elements, outputs x, y, z at 0..4, 4..8, 8..12; kernel B: 2 elements at
        // 12..14, 14..16, 16..18; gravity's z at 18..20.
        let rows: Vec<Vec<u32>> = vec![
            vec![0, 2, 12],      // particle 0, x
            vec![4, 6, 14],      //             y
            vec![8, 10, 16, 18], //            z: parallel for three terms, then gravity
            vec![1, 3],          // particle 1, x
            vec![5, 13],         //             y: parts after one term
            vec![9, 11],         //             z
            vec![0, 1],          // particle 2: x a coordinate, y constant, z a coordinate
            vec![8, 19],
            vec![0, 12], // particle 3: z's first term alone (gravity first), then
            vec![4, 14], //             parallel
            vec![19, 8, 16],
        ];
        let particles = [
            [Some(0), Some(1), Some(2)],
            [Some(3), Some(4), Some(5)],
            [Some(6), None, Some(7)],
            [Some(8), Some(9), Some(10)],
        ];
        let mut start = vec![0u32];
        let mut terms = Vec::new();
        for r in &rows {
            terms.extend_from_slice(r);
            start.push(terms.len() as u32);
        }
        let outputs: Vec<f64> = (0..20)
            .map(|k| (1.0 + k as f64 * 0.1).powi(7) * if k % 3 == 0 { -1e-9 } else { 1.0 })
            .collect();
        let sums = Sums::new(&start, &terms, &particles, outputs.len()).unwrap();
        assert_eq!(
            sums.together(),
            3 * (3 + 1 + 2),
            "together: 3, 1 and 2 steps"
        );
        assert_eq!(sums.terms(), terms.len());
        assert_eq!(sums.runs(), None, "scattered terms: no runs");
        let mut acc = vec![f64::NAN; rows.len()];
        sums.sum_into(&outputs, &mut acc);
        for (r, (a, b)) in acc.iter().zip(alone(&start, &terms, &outputs)).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "row {r}: {a:e} against {b:e}");
        }
        // A term outside the outputs is refused, not read.
        assert!(Sums::new(&start, &terms, &particles, 19).is_none());
    }

    /// A family of 8 springs along a line of 9 particles (x, y, z of particle `p` the rows
    /// `p`, `9 + p`, `18 + p`; spring `e` from particle `e` to `e + 1`) and gravity on each:
    /// the outputs and their rows step together, so the sums go by runs, one per output column,
    /// and give each row's sum alone bit for bit (the middle particles add two springs' terms
    /// and gravity's, in that order).
    #[test]
    fn sums_by_runs_are_those_of_each_row_alone_bit_for_bit() {
        let (particles, springs) = (9u32, 8u32);
        let mut rows: Vec<Vec<u32>> = vec![Vec::new(); 3 * particles as usize];
        for o in 0..6 {
            let (slot, axis) = (o / 3, o % 3);
            for e in 0..springs {
                rows[(axis * particles + e + slot) as usize].push(o * springs + e);
            }
        }
        for p in 0..particles {
            rows[(2 * particles + p) as usize].push(6 * springs + p);
        }
        let mut start = vec![0u32];
        let mut terms = Vec::new();
        for r in &mut rows {
            r.sort_unstable();
            terms.extend_from_slice(r);
            start.push(terms.len() as u32);
        }
        let outputs: Vec<f64> = (0..6 * springs + particles)
            .map(|k| (1.0 + k as f64 * 0.1).powi(7) * if k % 3 == 0 { -1e-9 } else { 1.0 })
            .collect();
        let axes: Vec<[Option<u32>; 3]> = (0..particles)
            .map(|p| [Some(p), Some(particles + p), Some(2 * particles + p)])
            .collect();
        let sums = Sums::new(&start, &terms, &axes, outputs.len()).unwrap();
        assert_eq!(sums.runs(), Some(7), "six spring columns and gravity's");
        assert_eq!(sums.terms(), terms.len());
        let mut acc = vec![f64::NAN; rows.len()];
        sums.sum_into(&outputs, &mut acc);
        for (r, (a, b)) in acc.iter().zip(alone(&start, &terms, &outputs)).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "row {r}: {a:e} against {b:e}");
        }
    }
}
