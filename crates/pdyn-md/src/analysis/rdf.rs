//! Radial distribution function `g(r) = n(r) / (ρ 4π r² Δr)` averaged over particles and
//! frames, where `n(r)` is the mean number of neighbours in the shell `[r, r + Δr)` (minimum
//! image, so `r_max ≤ L_min/2`). Uses the exact shell volume `(4π/3)(r₂³ − r₁³)`.

use crate::{MdError, System};
use std::f64::consts::PI;

/// Histogram accumulator for `g(r)`.
#[derive(Debug, Clone)]
pub struct Rdf {
    r_max: f64,
    counts: Vec<u64>,
    frames: u64,
    norm: f64,
}

impl Rdf {
    /// `bins` bins on `[0, r_max)`.
    pub fn new(r_max: f64, bins: usize) -> Result<Self, MdError> {
        if !(r_max.is_finite() && r_max > 0.0) {
            return Err(MdError::InvalidParameter {
                name: "r_max",
                value: r_max,
            });
        }
        if bins == 0 || bins > 1 << 24 {
            return Err(MdError::InvalidParameter {
                name: "bins",
                value: bins as f64,
            });
        }
        Ok(Rdf {
            r_max,
            counts: vec![0; bins],
            frames: 0,
            norm: 0.0,
        })
    }

    /// Adds one frame (all pairs, `O(N²)`).
    pub fn add(&mut self, s: &System) -> Result<(), MdError> {
        let half = 0.5 * s.sim_box.min_edge();
        if self.r_max > half {
            return Err(MdError::InvalidParameter {
                name: "r_max (> L/2)",
                value: self.r_max,
            });
        }
        let p = &s.particles;
        let n = p.len();
        let nb = self.counts.len();
        let scale = nb as f64 / self.r_max;
        for i in 0..n {
            for j in i + 1..n {
                let r = s.sim_box.delta(p.pos(i), p.pos(j)).norm();
                let b = (r * scale) as usize;
                if b < nb {
                    self.counts[b] += 2;
                }
            }
        }
        self.frames += 1;
        // Σ over frames of N·ρ
        self.norm += n as f64 * s.density();
        Ok(())
    }

    /// Frames added so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// The accumulated histogram (pair counts per bin), frames and `Σ N·ρ` over the frames:
    /// what a checkpoint saves to continue the average ([`Rdf::restore`]).
    pub fn accumulated(&self) -> (&[u64], u64, f64) {
        (&self.counts, self.frames, self.norm)
    }

    /// Sets the accumulations [`Rdf::accumulated`] returned (the counts must have this
    /// histogram's number of bins).
    pub fn restore(&mut self, counts: &[u64], frames: u64, norm: f64) -> Result<(), MdError> {
        if counts.len() != self.counts.len() {
            return Err(MdError::SnapshotMismatch {
                what: "RDF bins",
                expected: self.counts.len(),
                found: counts.len(),
            });
        }
        self.counts.copy_from_slice(counts);
        self.frames = frames;
        self.norm = norm;
        Ok(())
    }

    /// Adds the frames of `other` (same range and bins, else an error).
    pub fn merge(&mut self, other: &Rdf) -> Result<(), MdError> {
        if other.r_max != self.r_max || other.counts.len() != self.counts.len() {
            return Err(MdError::InvalidParameter {
                name: "rdf to merge (other range or bins)",
                value: other.r_max,
            });
        }
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.frames += other.frames;
        self.norm += other.norm;
        Ok(())
    }

    /// `g(r)` of the frames of all `blocks` together, and its standard error per bin from the
    /// spread of the blocks' own `g(r)` (`√(Σ (g_b − ḡ)²/(B(B − 1)))` over the `B` blocks with
    /// frames; Flyvbjerg & Petersen 1989: blocks of consecutive frames longer than the
    /// correlation time are nearly independent). `None` for the error with fewer than two
    /// blocks with frames.
    pub fn block_result(blocks: &[Rdf]) -> Result<BlockRdf, MdError> {
        let first = blocks.first().ok_or(MdError::InvalidParameter {
            name: "rdf blocks",
            value: 0.0,
        })?;
        let mut all = Rdf::new(first.r_max, first.counts.len())?;
        for b in blocks {
            all.merge(b)?;
        }
        let (r, g) = all.result();
        let used: Vec<Vec<f64>> = blocks
            .iter()
            .filter(|b| b.frames > 0)
            .map(|b| b.result().1)
            .collect();
        let nb = used.len();
        let error = (nb >= 2).then(|| {
            (0..g.len())
                .map(|k| {
                    let m = used.iter().map(|gb| gb[k]).sum::<f64>() / nb as f64;
                    let var = used.iter().map(|gb| (gb[k] - m).powi(2)).sum::<f64>();
                    (var / (nb * (nb - 1)) as f64).sqrt()
                })
                .collect()
        });
        Ok(BlockRdf {
            r,
            g,
            error,
            blocks: nb,
            frames: all.frames,
        })
    }

    /// Bin centres and `g(r)`.
    pub fn result(&self) -> (Vec<f64>, Vec<f64>) {
        let nb = self.counts.len();
        let dr = self.r_max / nb as f64;
        let mut r = Vec::with_capacity(nb);
        let mut g = Vec::with_capacity(nb);
        for (b, &c) in self.counts.iter().enumerate() {
            let (r1, r2) = (b as f64 * dr, (b + 1) as f64 * dr);
            let shell = 4.0 / 3.0 * PI * (r2.powi(3) - r1.powi(3));
            r.push(0.5 * (r1 + r2));
            g.push(if self.norm > 0.0 {
                c as f64 / (self.norm * shell)
            } else {
                0.0
            });
        }
        (r, g)
    }
}

/// `g(r)` with block error bars ([`Rdf::block_result`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BlockRdf {
    /// Bin centres.
    pub r: Vec<f64>,
    /// `g(r)` over all frames.
    pub g: Vec<f64>,
    /// Standard error of `g` per bin (None with fewer than two blocks).
    pub error: Option<Vec<f64>>,
    /// Blocks with frames.
    pub blocks: usize,
    /// Frames in all.
    pub frames: u64,
}
