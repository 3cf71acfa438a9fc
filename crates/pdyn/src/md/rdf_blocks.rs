//! The RDF of a run with block error bars: the planned frames are split into
//! [`RDF_BLOCKS`] consecutive blocks, each a histogram of its own, so that the spread of the
//! blocks' `g(r)` gives a standard error per bin (`pdyn_md::analysis::Rdf::block_result`).

use pdyn_md::analysis::{BlockRdf, Rdf};
use pdyn_md::{MdError, System};

/// Blocks of an RDF's frames.
pub const RDF_BLOCKS: usize = 5;

/// One block's pair counts per bin, frames and `Σ N·ρ`.
pub type BlockAccumulation<'a> = (&'a [u64], u64, f64);

/// Frames of the RDF, gathered into consecutive blocks.
#[derive(Debug, Clone)]
pub struct RdfBlocks {
    blocks: Vec<Rdf>,
    planned: u64,
    taken: u64,
}

impl RdfBlocks {
    /// `planned` frames (at least 1 is assumed) on `[0, r_max)` in `bins` bins.
    pub fn new(r_max: f64, bins: usize, planned: u64) -> Result<Self, MdError> {
        let blocks = (0..RDF_BLOCKS)
            .map(|_| Rdf::new(r_max, bins))
            .collect::<Result<_, _>>()?;
        Ok(RdfBlocks {
            blocks,
            planned: planned.max(1),
            taken: 0,
        })
    }

    /// Adds a frame to the block its position in the plan falls in (frames beyond the plan
    /// go to the last block).
    pub fn add(&mut self, s: &System) -> Result<(), MdError> {
        let b = ((self.taken * RDF_BLOCKS as u64 / self.planned) as usize).min(RDF_BLOCKS - 1);
        self.blocks[b].add(s)?;
        self.taken += 1;
        Ok(())
    }

    /// Frames added.
    pub fn frames(&self) -> u64 {
        self.taken
    }

    /// Each block's accumulations (`pdyn_md::analysis::Rdf::accumulated`) and the frames
    /// taken: what a checkpoint saves.
    pub fn accumulated(&self) -> (Vec<BlockAccumulation<'_>>, u64) {
        (
            self.blocks.iter().map(Rdf::accumulated).collect(),
            self.taken,
        )
    }

    /// Sets the accumulations [`RdfBlocks::accumulated`] returned (as many blocks, as many
    /// bins, else an error).
    pub fn restore(&mut self, blocks: &[(Vec<u64>, u64, f64)], taken: u64) -> Result<(), MdError> {
        if blocks.len() != self.blocks.len() {
            return Err(MdError::SnapshotMismatch {
                what: "RDF blocks",
                expected: self.blocks.len(),
                found: blocks.len(),
            });
        }
        for (b, (counts, frames, norm)) in self.blocks.iter_mut().zip(blocks) {
            b.restore(counts, *frames, *norm)?;
        }
        self.taken = taken;
        Ok(())
    }

    /// `g(r)` and its block errors.
    pub fn result(&self) -> Result<BlockRdf, MdError> {
        Rdf::block_result(&self.blocks)
    }
}
