//! `potential`: a pair potential `V(dist)` given as an expression in `dist`; the force on the
//! first body is `-V'(dist) e`, `e = (r_A - r_B)/dist`, the opposite on the second.

use super::{vector, Binding, Entry, ForceBuilder, Kind, Loader, ModelError, PotentialTerm, Value};

pub(super) const POTENTIAL: Kind = Kind {
    name: "potential",
    fields: "`between`, `potential` (a function of `dist`)",
    force: "`-V'(dist) e`",
    potential: "`V`",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let ends = b.pair(ld, e)?;
    let vsv = e.need(ld, &e.raw.potential, "potential")?;
    let dist_sym = ld.pool.symbol("dist", true);
    let dist = ld.pool.sym(dist_sym);
    ld.scope
        .local
        .insert("dist".into(), Binding::Value(Value::Scalar(dist)));
    ld.dims.bind("dist", pdyn_expr::Dimension::LENGTH.into());
    let pot = ld.scalar(vsv, "`potential`");
    if pot.is_ok() {
        ld.want(vsv, pdyn_expr::Dimension::ENERGY, "the `potential`");
    }
    ld.dims.unbind("dist");
    ld.scope.local.remove("dist");
    let pot = pot?;
    let rel = vector::sub(&mut ld.pool, ends[0].1, ends[1].1);
    let d = vector::norm(&mut ld.pool, rel);
    let dv = ld.pool.diff(pot, dist);
    let dv = ld.pool.subs1(dv, dist, d);
    let scale = ld.pool.div(dv, d);
    let ns = ld.pool.neg(scale);
    let force = vector::scale(&mut ld.pool, ns, rel);
    let energy = ld.pool.subs1(pot, dist, d);
    b.potentials.push(PotentialTerm {
        label: e.label.clone(),
        energy,
    });
    b.push_pair_labelled(ld, e, &ends, force);
    Ok(())
}
