//! `friction` at a contact: the normal force `N n` (unknown `N`, named by `normal_force`) and
//! either `T t` (`mode = "stick"`, unknown `T` along `tangent`, named by `friction_force`) or
//! `-mu N s` (`mode = "slip"`, `s` the unit sliding direction: `opposes`, or the velocity of
//! the contact point minus `surface_velocity`, without its normal part). Slip is not
//! conservative.

use super::{vector, Entry, ForceBuilder, Kind, Load, Loader, ModelError};

pub(super) const FRICTION: Kind = Kind {
    name: "friction",
    fields: "`on`, `normal`, `mode`, ...",
    force: "see below",
    potential: "—",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let raw = e.raw;
    let (target, at) = b.target(ld, e)?;
    let nsv = e.need(ld, &raw.normal, "normal")?;
    let normal = ld.vector(nsv, "`normal`")?;
    let n_name = raw
        .normal_force
        .as_ref()
        .map_or("N".to_string(), |n| n.get_ref().clone());
    let t_name = raw
        .friction_force
        .as_ref()
        .map_or("T".to_string(), |n| n.get_ref().clone());
    let n_id = b.reaction(ld, &n_name, e.span_or_kind(&raw.normal_force))?;
    let n_form = ld.dims.of(&n_name).unwrap_or_default();
    ld.want_times(
        nsv,
        &n_form,
        pdyn_expr::Dimension::FORCE,
        &format!("the normal force `{n_name}` times `normal`"),
    );
    let nforce = vector::scale(&mut ld.pool, n_id, normal);
    b.loads.push(Load {
        label: format!("normal force {n_name}"),
        target: target.clone(),
        force: nforce,
    });
    let mode = raw.mode.as_ref().map_or("stick", |m| m.get_ref().as_str());
    match mode {
        "stick" => {
            let tsv = e.need(
                ld,
                &raw.tangent,
                "tangent (the direction of the friction force T)",
            )?;
            let tangent = ld.vector(tsv, "`tangent`")?;
            let t_id = b.reaction(ld, &t_name, e.span_or_kind(&raw.friction_force))?;
            let t_form = ld.dims.of(&t_name).unwrap_or_default();
            ld.want_times(
                tsv,
                &t_form,
                pdyn_expr::Dimension::FORCE,
                &format!("the friction force `{t_name}` times `tangent`"),
            );
            b.friction_forces.push(t_name.clone());
            let tforce = vector::scale(&mut ld.pool, t_id, tangent);
            b.loads.push(Load {
                label: format!("friction force {t_name}"),
                target,
                force: tforce,
            });
        }
        "slip" => {
            let musv = e.need(ld, &raw.mu, "mu")?;
            let mu = ld.scalar(musv, "`mu`")?;
            ld.want(
                musv,
                pdyn_expr::Dimension::NONE,
                "the friction coefficient `mu`",
            );
            let dir = match &raw.opposes {
                Some(s) => {
                    let s = ld.vector(s, "`opposes`")?;
                    vector::unit(&mut ld.pool, s)
                }
                None => {
                    // Sliding velocity: velocity of the contact point relative to the
                    // surface, without its normal part.
                    let v = at.map(|c| ld.pool.dt(c));
                    let v = match &raw.surface_velocity {
                        Some(s) => {
                            let ssv = s;
                            let s = ld.vector(ssv, "`surface_velocity`")?;
                            ld.want(
                                ssv,
                                pdyn_expr::Dimension::VELOCITY,
                                "the `surface_velocity`",
                            );
                            vector::sub(&mut ld.pool, v, s)
                        }
                        None => v,
                    };
                    let nn = vector::dot(&mut ld.pool, normal, normal);
                    let vn = vector::dot(&mut ld.pool, v, normal);
                    let k = ld.pool.div(vn, nn);
                    let along = vector::scale(&mut ld.pool, k, normal);
                    let slide = vector::sub(&mut ld.pool, v, along);
                    vector::unit(&mut ld.pool, slide)
                }
            };
            let mag = ld.pool.mul2(mu, n_id);
            let neg = ld.pool.neg(mag);
            let tforce = vector::scale(&mut ld.pool, neg, dir);
            b.loads.push(Load {
                label: format!("sliding friction mu*{n_name}"),
                target,
                force: tforce,
            });
            b.conservative = false;
        }
        other => {
            let m = e.span_or_kind(&raw.mode);
            return Err(ld
                .err(m, format!("unknown friction mode `{other}`"))
                .help("mode is \"stick\" (friction force unknown) or \"slip\" (T = mu*N opposing sliding)"));
        }
    }
    Ok(())
}
