//! Block averaging of correlated samples (Flyvbjerg & Petersen, J. Chem. Phys. 91, 461
//! (1989)): the standard error of a time series is estimated from the means of contiguous
//! blocks, which are nearly independent when the blocks are longer than the correlation time.

/// The mean of `blocks` contiguous block means of `xs` (a tail shorter than a block is left
/// out) and its standard error; `None` when `xs` has fewer values than twice `blocks` (or
/// `blocks` < 2).
pub fn block_means(xs: &[f64], blocks: usize) -> Option<(f64, f64)> {
    if blocks < 2 || xs.len() < 2 * blocks {
        return None;
    }
    let len = xs.len() / blocks;
    let bm: Vec<f64> = (0..blocks)
        .map(|b| xs[b * len..(b + 1) * len].iter().sum::<f64>() / len as f64)
        .collect();
    let m = bm.iter().sum::<f64>() / blocks as f64;
    let var = bm.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (blocks * (blocks - 1)) as f64;
    Some((m, var.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blocks of 1, 2, 3, 4 (the tail 9 left out): means 1.5, 3.5, ..., by hand.
    #[test]
    fn block_means_by_hand() {
        let xs = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        let (m, e) = block_means(&xs, 4).unwrap();
        // Block means 1.5, 3.5, 5.5, 7.5: mean 4.5, sample variance 20/3, error sqrt(20/3/4).
        assert_eq!(m, 4.5);
        assert!((e - (20.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert_eq!(block_means(&xs[..7], 4), None);
        assert_eq!(block_means(&xs, 1), None);
    }
}
