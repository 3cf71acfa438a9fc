//! `damper`: `-c (dl/dt) e` on the first end (and the opposite on the second), with `l` and
//! `e` as for a spring. Not conservative.

use super::{Entry, ForceBuilder, Kind, Loader, ModelError};

pub(super) const DAMPER: Kind = Kind {
    name: "damper",
    fields: "`between`, `c`, optional `length`, `direction`",
    force: "`-c (dl/dt) e`",
    potential: "—",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let ends = b.pair(ld, e)?;
    let (l, dir) = b.line_of_action(ld, e, &ends)?;
    let c = ld.scalar(e.need(ld, &e.raw.c, "c")?, "`c`")?;
    b.conservative = false;
    let dl = ld.pool.dt(l);
    let mag = ld.pool.mul2(c, dl);
    b.push_axial(ld, e, &ends, mag, dir);
    Ok(())
}
