//! `spring`: `-k (l - l0) e` on the first end (and the opposite on the second), with
//! `l = |r_A - r_B|` (or `length`) and `e = (r_A - r_B)/l` (or `direction`); potential
//! `k (l - l0)²/2`.

use super::{Entry, ForceBuilder, Kind, Loader, ModelError, PotentialTerm};
use pdyn_expr::{Dimension, Number};

/// N/m.
pub(super) fn stiffness() -> Dimension {
    Dimension::from_ints([0, 1, -2, 0])
}

pub(super) const SPRING: Kind = Kind {
    name: "spring",
    fields: "`between`, `k`, `l0`, optional `length`, `direction`",
    force: "`-k (l - l0) e` with `l = |r_A - r_B|`, `e = (r_A - r_B)/l`",
    potential: "`k (l - l0)²/2`",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let ends = b.pair(ld, e)?;
    let (l, dir) = b.line_of_action(ld, e, &ends)?;
    let ksv = e.need(ld, &e.raw.k, "k")?;
    let k = ld.scalar(ksv, "`k`")?;
    ld.want(ksv, stiffness(), "the stiffness `k`");
    let l0sv = e.need(ld, &e.raw.l0, "l0")?;
    let l0 = ld.scalar(l0sv, "`l0`")?;
    ld.want(l0sv, Dimension::LENGTH, "the free length `l0`");
    let stretch = ld.pool.sub(l, l0);
    let half = ld.pool.num(Number::ratio(1, 2));
    let s2 = ld.pool.powi(stretch, 2);
    let energy = ld.pool.mul(&[half, k, s2]);
    b.potentials.push(PotentialTerm {
        label: e.label.clone(),
        energy,
    });
    let mag = ld.pool.mul2(k, stretch);
    b.push_axial(ld, e, &ends, mag, dir);
    Ok(())
}
