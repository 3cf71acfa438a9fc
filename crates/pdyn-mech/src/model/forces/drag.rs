//! `drag` (quadratic, `-C |v_rel| v_rel` with `C = coefficient` or `ρ C_D A / 2`) and
//! `linear_drag` (`-c v_rel`), where `v_rel = v - wind`. Not conservative.

use super::{vector, Entry, ForceBuilder, Id, Kind, Load, Loader, ModelError, Target};
use pdyn_expr::Number;

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
        let c = ld.scalar(c, "`coefficient`")?;
        let speed = vector::norm(&mut ld.pool, vrel);
        ld.pool.mul2(c, speed)
    } else {
        let rho = ld.scalar(e.need(ld, &raw.rho, "rho (or coefficient)")?, "`rho`")?;
        let cd = ld.scalar(e.need(ld, &raw.cd, "cd")?, "`cd`")?;
        let area = ld.scalar(e.need(ld, &raw.area, "area")?, "`area`")?;
        let half = ld.pool.num(Number::ratio(1, 2));
        let speed = vector::norm(&mut ld.pool, vrel);
        ld.pool.mul(&[half, rho, cd, area, speed])
    };
    push(b, ld, e, target, coef, vrel);
    Ok(())
}

fn build_linear(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let (target, vrel) = relative_velocity(b, ld, e)?;
    let coef = ld.scalar(e.need(ld, &e.raw.c, "c")?, "`c`")?;
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
            let w = ld.vector(w, "`wind`")?;
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
