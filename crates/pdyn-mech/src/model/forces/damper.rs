//! `damper`: `-c (dl/dt) e` on the first end (and the opposite on the second), with `l` and
//! `e` as for a spring. Not conservative.

use super::{Entry, ForceBuilder, Kind, Loader, ModelError};
use pdyn_expr::Dimension;

/// N·s/m.
pub(super) fn damping() -> Dimension {
    Dimension::from_ints([0, 1, -1, 0])
}

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
    let csv = e.need(ld, &e.raw.c, "c")?;
    let c = ld.scalar(csv, "`c`")?;
    ld.want(csv, damping(), "the damping coefficient `c`");
    b.conservative = false;
    let dl = ld.pool.dt(l);
    let mag = ld.pool.mul2(c, dl);
    b.push_axial(ld, e, &ends, mag, dir);
    Ok(())
}
