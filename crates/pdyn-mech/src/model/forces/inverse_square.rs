//! `inverse_square`: `-strength (r_A - r_B)/|r_A - r_B|³` on the first body (gravitation,
//! Coulomb), the opposite on the second; potential `-strength/|r_A - r_B|`.

use super::{vector, Entry, ForceBuilder, Kind, Loader, ModelError, PotentialTerm};

pub(super) const INVERSE_SQUARE: Kind = Kind {
    name: "inverse_square",
    fields: "`on` + `to`, or `between`; `strength`",
    force: "`-strength (r_A - r_B)/|r_A - r_B|³`",
    potential: "`-strength/|r_A - r_B|`",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let ends = b.pair(ld, e)?;
    let ssv = e.need(ld, &e.raw.strength, "strength")?;
    let strength = ld.scalar(ssv, "`strength`")?;
    let want = pdyn_expr::Dimension::FORCE.mul(&pdyn_expr::Dimension::from_ints([2, 0, 0, 0]));
    if let Some(want) = want {
        ld.want(
            ssv,
            want,
            "the `strength` (force times distance^2, as G m1 m2)",
        );
    }
    let rel = vector::sub(&mut ld.pool, ends[0].1, ends[1].1);
    let d = vector::norm(&mut ld.pool, rel);
    let d3 = ld.pool.powi(d, -3);
    let s = ld.pool.mul2(strength, d3);
    let ns = ld.pool.neg(s);
    let force = vector::scale(&mut ld.pool, ns, rel);
    let pe = ld.pool.div(strength, d);
    let energy = ld.pool.neg(pe);
    b.potentials.push(PotentialTerm {
        label: e.label.clone(),
        energy,
    });
    b.push_pair_labelled(ld, e, &ends, force);
    Ok(())
}
