//! `drag` (quadratic, `-C |v_rel| v_rel` with `C = coefficient` or `ρ C_D A / 2`) and
//! `linear_drag` (`-c v_rel`), where `v_rel = v - wind`. Not conservative.

use super::{vector, Entry, ForceBuilder, Id, Kind, Load, Loader, ModelError, Target};
use pdyn_expr::{Dimension, Number};

pub(super) const DRAG: Kind = Kind {
    name: "drag",
    fields: "`on`, `coefficient` (or `rho`, `cd`, `area`), optional `wind`",
    force: "`-C |v_rel| v_rel`, `C = coefficient` or `ρ C_D A/2`",
    potential: "—",
    build: build_quadratic,
};

pub(super) const LINEAR_DRAG: Kind = Kind {
    name: "linear_drag",
    fields: "`on`, `c`, optional `wind`",
    force: "`-c v_rel`",
    potential: "—",
    build: build_linear,
};

fn build_quadratic(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let (target, vrel) = relative_velocity(b, ld, e)?;
    let raw = e.raw;
    let coef = if let Some(c) = &raw.coefficient {
        let csv = c;
        let c = ld.scalar(csv, "`coefficient`")?;
        ld.want(
            csv,
            Dimension::from_ints([-1, 1, 0, 0]),
            "the drag `coefficient` (force/speed^2)",
        );
        let speed = vector::norm(&mut ld.pool, vrel);
        ld.pool.mul2(c, speed)
    } else {
        let rsv = e.need(ld, &raw.rho, "rho (or coefficient)")?;
        let rho = ld.scalar(rsv, "`rho`")?;
        ld.want(
            rsv,
            Dimension::from_ints([-3, 1, 0, 0]),
            "the density `rho`",
        );
        let csv = e.need(ld, &raw.cd, "cd")?;
        let cd = ld.scalar(csv, "`cd`")?;
        ld.want(csv, Dimension::NONE, "the drag coefficient `cd`");
        let asv = e.need(ld, &raw.area, "area")?;
        let area = ld.scalar(asv, "`area`")?;
        ld.want(asv, Dimension::from_ints([2, 0, 0, 0]), "the `area`");
        let half = ld.pool.num(Number::ratio(1, 2));
        let speed = vector::norm(&mut ld.pool, vrel);
        ld.pool.mul(&[half, rho, cd, area, speed])
    };
    push(b, ld, e, target, coef, vrel);
    Ok(())
}

fn build_linear(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let (target, vrel) = relative_velocity(b, ld, e)?;
    let csv = e.need(ld, &e.raw.c, "c")?;
    let coef = ld.scalar(csv, "`c`")?;
    ld.want(
        csv,
        super::damper::damping(),
        "the linear drag coefficient `c`",
    );
    push(b, ld, e, target, coef, vrel);
    Ok(())
}

/// The body and its velocity relative to the air, `v - wind`.
fn relative_velocity(
    b: &ForceBuilder,
    ld: &mut Loader,
    e: &Entry,
) -> Result<(Target, [Id; 3]), ModelError> {
    let (target, r) = b.target(ld, e)?;
    let v = r.map(|c| ld.pool.dt(c));
    let vrel = match &e.raw.wind {
        Some(w) => {
            let wsv = w;
            let w = ld.vector(wsv, "`wind`")?;
            ld.want(wsv, Dimension::VELOCITY, "the `wind`");
            vector::sub(&mut ld.pool, v, w)
        }
        None => v,
    };
    Ok((target, vrel))
}

/// Pushes `-coef v_rel` on the body.
fn push(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry, target: Target, coef: Id, vrel: [Id; 3]) {
    let neg = ld.pool.neg(coef);
    let force = vector::scale(&mut ld.pool, neg, vrel);
    b.loads.push(Load {
        label: e.label.clone(),
        target,
        force,
    });
    b.conservative = false;
}
