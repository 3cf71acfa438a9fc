//! `applied`: a given force vector on a particle or a frame. The expression may use the
//! body's position `r` and velocity `v`. Not conservative (no potential).

use super::{Entry, ForceBuilder, Kind, Load, Loader, ModelError};

pub(super) const APPLIED: Kind = Kind {
    name: "applied",
    fields: "`on`, `force` (vector)",
    force: "the given vector",
    potential: "—",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let (target, r) = b.target(ld, e)?;
    let fsv = e.need(ld, &e.raw.force, "force")?;
    let force = b.with_local(ld, r, |ld| ld.vector(fsv, "an applied force"))?;
    ld.want(fsv, pdyn_expr::Dimension::FORCE, "an applied force");
    b.loads.push(Load {
        label: e.label.clone(),
        target,
        force,
    });
    b.conservative = false;
    Ok(())
}
