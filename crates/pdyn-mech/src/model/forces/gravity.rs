//! Gravity: declared once at the top of the model (`gravity = g`), it puts `m g` on every
//! particle with potential `-m g·r`. A `[[forces]]` entry of kind `gravity` is an error that
//! says so.

use super::Target;
use super::{vector, Entry, ForceBuilder, Id, Kind, Load, Loader, ModelError, PotentialTerm};

pub(super) const GRAVITY: Kind = Kind {
    name: "gravity",
    fields: "top-level `gravity = g`",
    force: "`m g`",
    potential: "`-m g·r`",
    build,
};

fn build(_: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    Err(ld
        .err(
            e.kind_span.clone(),
            "gravity is declared once for the whole model",
        )
        .help("write gravity = \"[0, 0, -g]\" at the top of the file"))
}

impl ForceBuilder<'_> {
    /// Uniform gravity `g` on every particle: the load `m g` and the potential `-m g·r`.
    pub fn gravity(&mut self, ld: &mut Loader, g: [Id; 3]) {
        for (i, p) in self.particles.iter().enumerate() {
            let force = vector::scale(&mut ld.pool, p.mass, g);
            let gr = vector::dot(&mut ld.pool, g, p.position);
            let pe = ld.pool.mul2(p.mass, gr);
            let energy = ld.pool.neg(pe);
            self.loads.push(Load {
                label: format!("gravity on {}", p.name),
                target: Target::Particle(i),
                force,
            });
            self.potentials.push(PotentialTerm {
                label: format!("gravity on {}", p.name),
                energy,
            });
        }
    }
}
