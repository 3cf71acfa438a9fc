//! A table of index pairs `(to, from)` kept as runs: stretches where both indices step by one.
//!
//! A net declared as families numbers its particles, coordinates and elements in the same
//! order (`x[i,j]` and `spring[i,j]` both `i` then `j`), so the acceleration an element's
//! output adds to mostly steps by one from one element to the next. Adding a run is one
//! bounds check and a loop the compiler vectorizes (four additions per instruction with AVX),
//! where the same pairs one by one are an index load, a value load, an addition and a store
//! each. A table of scattered pairs (elements read from a CSV in no order) has runs of one or
//! two: it stays a table of indices.

/// Pairs `to + k ← from + k` for `k < len`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    to: u32,
    from: u32,
    len: u32,
}

/// Runs shorter than this on average cost more than the pairs one by one (a run's set-up is
/// about four pairs' worth of indexed loads).
pub(super) const MIN_MEAN_RUN: usize = 4;

/// The runs of a table of pairs, in the table's order.
#[derive(Clone, Debug, Default)]
pub(super) struct Runs {
    runs: Vec<Run>,
    pairs: usize,
    /// One more than the largest `to` and `from`: slices at least this long are read and
    /// written without a failed bounds check.
    to_end: usize,
    from_end: usize,
}

impl Runs {
    /// The runs of `pairs`, in their order: a run goes on while the next pair is
    /// `(to + 1, from + 1)`.
    pub(super) fn new(pairs: impl IntoIterator<Item = (u32, u32)>) -> Runs {
        let mut runs: Vec<Run> = Vec::new();
        let mut count = 0;
        let (mut to_end, mut from_end) = (0usize, 0usize);
        for (to, from) in pairs {
            count += 1;
            to_end = to_end.max(to as usize + 1);
            from_end = from_end.max(from as usize + 1);
            match runs.last_mut() {
                Some(r)
                    if r.to.checked_add(r.len) == Some(to)
                        && r.from.checked_add(r.len) == Some(from) =>
                {
                    r.len += 1
                }
                _ => runs.push(Run { to, from, len: 1 }),
            }
        }
        Runs {
            runs,
            pairs: count,
            to_end,
            from_end,
        }
    }

    /// Whether there are pairs and their runs are long enough, on average, to beat the pairs
    /// one by one.
    pub(super) fn pay(&self) -> bool {
        self.pairs > 0 && self.runs.len() * MIN_MEAN_RUN <= self.pairs
    }

    /// Number of runs.
    pub(super) fn len(&self) -> usize {
        self.runs.len()
    }

    /// Number of pairs.
    #[cfg(test)]
    pub(super) fn pairs(&self) -> usize {
        self.pairs
    }

    /// `to[t] += from[f]` for every pair `(t, f)`, in the table's order: an index `t` that
    /// comes in several pairs adds their values in the order of the pairs.
    ///
    /// # Panics
    /// When `to` or `from` is shorter than an index of the table (the caller sized them).
    pub(super) fn add(&self, from: &[f64], to: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the processor has AVX (checked just above).
            return unsafe { self.add_avx(from, to) };
        }
        self.add_generic(from, to);
    }

    /// [`Runs::add`] compiled for AVX: four additions per instruction instead of two. The
    /// same additions (each its own rounding), so the same bits on every processor.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn add_avx(&self, from: &[f64], to: &mut [f64]) {
        self.add_generic(from, to);
    }

    #[inline(always)]
    fn add_generic(&self, from: &[f64], to: &mut [f64]) {
        let (to, from) = (&mut to[..self.to_end], &from[..self.from_end]);
        for r in &self.runs {
            let (t, f, n) = (r.to as usize, r.from as usize, r.len as usize);
            for (x, &v) in to[t..t + n].iter_mut().zip(&from[f..f + n]) {
                *x += v;
            }
        }
    }

    /// One more than the largest `to` and the largest `from` (0, 0 for no pairs).
    #[cfg(test)]
    fn ends(&self) -> (usize, usize) {
        (self.to_end, self.from_end)
    }
}

#[cfg(test)]
mod tests {
    use super::Runs;

    /// Pairs with runs of every length from 1 up, a repeated `to`, a `from` that steps back.
    fn table() -> Vec<(u32, u32)> {
        vec![
            (0, 10),
            (1, 11),
            (2, 12), // a run of 3
            (7, 3),  // 1: `to` jumps
            (8, 5),  // 1: `from` jumps
            (9, 6),
            (10, 7),
            (11, 8),
            (12, 9), // 5
            (0, 0),  // `to` 0 again: after (0, 10)
            (1, 1),
            (5, 2), // 1
        ]
    }

    #[test]
    fn runs_are_the_stretches_where_both_indices_step_by_one() {
        let runs = Runs::new(table());
        assert_eq!(runs.pairs(), 12);
        assert_eq!(runs.len(), 5, "{runs:?}");
        assert_eq!(runs.ends(), (13, 13));
        assert!(!runs.pay(), "5 runs of 12 pairs: 2.4 on average");
        let long = Runs::new((0..40).map(|k| (k, k + 3)).chain([(0, 0)]));
        assert_eq!(long.len(), 2);
        assert!(long.pay());
        assert_eq!(Runs::new([]).ends(), (0, 0));
    }

    /// Adding by runs is what the pairs one by one give, bit for bit, a repeated `to` adding
    /// its values in the table's order.
    #[test]
    fn sums_are_those_of_the_pairs_one_by_one() {
        let pairs = table();
        let mut from: Vec<f64> = (0..13)
            .map(|k| (1.0 + k as f64 * 0.37).powi(9) * if k % 2 == 0 { -1e-7 } else { 1.0 })
            .collect();
        // `to` 0 adds from[10] then from[0]: 0.3 + 0.2 + 0.1 is 0.6, 0.3 + 0.1 + 0.2 is not.
        (from[10], from[0]) = (0.2, 0.1);
        let runs = Runs::new(pairs.clone());
        let mut by_runs = vec![0.25; 13];
        by_runs[0] = 0.3;
        let mut one_by_one = by_runs.clone();
        runs.add(&from, &mut by_runs);
        for &(t, f) in &pairs {
            one_by_one[t as usize] += from[f as usize];
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&by_runs), bits(&one_by_one));
        // Adding (0, 0) before (0, 10) would give other bits for `to` 0: the order shows.
        let mut reordered = [0.3; 13];
        reordered[0] += from[0];
        reordered[0] += from[10];
        assert_ne!(reordered[0].to_bits(), by_runs[0].to_bits());

        // Runs of every length 1..=11 (the vector loop's body and every tail), apart by gaps
        // that stay NaN: each added whole and nothing beyond it.
        let source: Vec<f64> = (0..200).map(|k| (k as f64 + 0.5) * 1.1).collect();
        let mut pairs = Vec::new();
        let (mut t, mut f) = (0u32, 3u32);
        for len in 1..=11 {
            pairs.extend((0..len).map(|k| (t + k, f + k)));
            (t, f) = (t + len + 1, f + len + 2);
        }
        let runs = Runs::new(pairs.clone());
        assert_eq!(runs.len(), 11);
        let mut by_runs = vec![f64::NAN; t as usize];
        for &(t, _) in &pairs {
            by_runs[t as usize] = 0.7;
        }
        let mut one_by_one = by_runs.clone();
        runs.add(&source, &mut by_runs);
        for &(t, f) in &pairs {
            one_by_one[t as usize] += source[f as usize];
        }
        let nan_or_bits = |v: &[f64]| {
            v.iter()
                .map(|x| (x.is_nan(), x.to_bits()))
                .collect::<Vec<_>>()
        };
        assert_eq!(nan_or_bits(&by_runs), nan_or_bits(&one_by_one));
        assert_eq!(by_runs.iter().filter(|x| x.is_nan()).count(), 11);
    }
}
