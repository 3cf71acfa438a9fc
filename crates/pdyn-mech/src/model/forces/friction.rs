//! `friction` at a contact: the normal force `N n` (unknown `N`, named by `normal_force`) and
//! either `T t` (`mode = "stick"`, unknown `T` along `tangent`, named by `friction_force`) or
//! `-mu N s` (`mode = "slip"`, `s` the unit sliding direction: `opposes`, or the velocity of
//! the contact point minus `surface_velocity`, without its normal part). Slip is not
//! conservative.
//!
//! `mode = "coulomb"` (the default when `mu_s` or `mu_k` is given), and `"slip"` without
//! `opposes`, are Coulomb friction that sticks and slips: the sliding load is what `pdyn
//! derive` and `pdyn forces` show, and the entry is also a held contact
//! ([`crate::model::Contact`]) whose modes `pdyn run` switches between
//! ([`crate::hybrid`]): stuck while the force needed to stick is within `mu_s N`, sliding
//! against the slip with `mu_k N` otherwise.

use super::{vector, Entry, ForceBuilder, Kind, Load, Loader, ModelError, Target};
use crate::model::Contact;
use pdyn_expr::Id;

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
    let n_span = e.span_or_kind(&raw.normal_force);
    b.directed(ld, &n_name, &target, normal, n_span, "friction")?;
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
    let coulomb_default = raw.mu_s.is_some() || raw.mu_k.is_some();
    let mode = raw
        .mode
        .as_ref()
        .map_or(if coulomb_default { "coulomb" } else { "stick" }, |m| {
            m.get_ref().as_str()
        });
    if mode != "coulomb" {
        if let Some(sv) = raw.mu_s.as_ref().or(raw.mu_k.as_ref()) {
            return Err(ld
                .err(
                    sv.span(),
                    format!(
                        "`mu_s` and `mu_k` belong to Coulomb friction, not to mode = \"{mode}\""
                    ),
                )
                .help(
                    "use mode = \"coulomb\" (sticks and slips), or mu = ... with mode = \"slip\"",
                ));
        }
    }
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
        "slip" | "coulomb" => {
            let (mu, mu_s) = coefficients(ld, e, mode)?;
            // Sliding velocity: velocity of the contact point relative to the surface,
            // without its normal part.
            let v = at.map(|c| ld.pool.dt(c));
            let v = match &raw.surface_velocity {
                Some(ssv) => {
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
            let dir = match &raw.opposes {
                Some(s) => {
                    let s = ld.vector(s, "`opposes`")?;
                    vector::unit(&mut ld.pool, s)
                }
                None => vector::unit(&mut ld.pool, slide),
            };
            let mag = ld.pool.mul2(mu, n_id);
            let neg = ld.pool.neg(mag);
            let tforce = vector::scale(&mut ld.pool, neg, dir);
            if raw.opposes.is_some() {
                // A direction drawn by hand can be wrong: the run checks that this friction's
                // power on the slip, F·v_slip, never turns positive.
                let power = vector::dot(&mut ld.pool, tforce, slide);
                let fm = vector::norm(&mut ld.pool, tforce);
                let vm = vector::norm(&mut ld.pool, slide);
                let size = ld.pool.mul2(fm, vm);
                b.friction_power.push((e.label.clone(), power, size));
                b.conservative = false;
            }
            let slip_load = b.loads.len();
            b.loads.push(Load {
                label: format!("sliding friction mu*{n_name}"),
                target: target.clone(),
                force: tforce,
            });
            if raw.opposes.is_none() {
                let Target::Particle(a) = target else {
                    return Err(ld
                        .err(e.kind_span.clone(), "friction that sticks and slips acts on a particle, not on a frame")
                        .help("put `on` on the particle at the contact, or give the sliding direction with `opposes` and mode = \"slip\""));
                };
                let surface_velocity = match &raw.surface_velocity {
                    Some(s) => ld.vector(s, "`surface_velocity`")?,
                    None => [pdyn_expr::Pool::ZERO; 3],
                };
                let unit_normal = vector::unit(&mut ld.pool, normal);
                let f1 = ld.pool.symbol(&t_name, false);
                let f2 = ld.pool.symbol(&format!("{t_name}_2"), false);
                let fs = [ld.pool.sym(f1), ld.pool.sym(f2)];
                b.contacts.push(Contact {
                    name: e.label.clone(),
                    span: e.f.span(),
                    a,
                    b: None,
                    gap: pdyn_expr::Pool::ZERO,
                    normal: unit_normal,
                    held: true,
                    restitution: pdyn_expr::Pool::ZERO,
                    friction: Some((mu_s, mu)),
                    surface_velocity,
                    normal_force: (n_name.clone(), n_id),
                    friction_force: (t_name.clone(), fs),
                    normal_in_model: true,
                    replaces_loads: vec![slip_load],
                });
            }
        }
        other => {
            let m = e.span_or_kind(&raw.mode);
            return Err(ld
                .err(m, format!("unknown friction mode `{other}`"))
                .help("mode is \"stick\" (friction force unknown), \"slip\" (T = mu*N opposing sliding) or \"coulomb\" (sticks and slips: mu_s, mu_k)"));
        }
    }
    Ok(())
}

/// `(mu_k, mu_s)`: `mu` for both, or `mu_s` and `mu_k` (Coulomb mode), each a pure number of
/// the parameters, `>= 0`, with `mu_k <= mu_s`.
fn coefficients(ld: &mut Loader, e: &Entry, mode: &str) -> Result<(Id, Id), ModelError> {
    let raw = e.raw;
    let read = |ld: &mut Loader, sv: &super::Sv, what: &str| -> Result<(Id, f64), ModelError> {
        let x = ld.scalar(sv, what)?;
        ld.want(sv, pdyn_expr::Dimension::NONE, what);
        let v = ld.constant(x, sv.span(), what)?;
        if v < 0.0 {
            return Err(ld
                .err(sv.span(), format!("{what} is {v}; it must be at least 0"))
                .help("friction coefficients are >= 0 (0: a smooth contact)"));
        }
        Ok((x, v))
    };
    match (&raw.mu, &raw.mu_s, &raw.mu_k) {
        (Some(m), None, None) => {
            let (x, _) = read(ld, m, "the friction coefficient `mu`")?;
            Ok((x, x))
        }
        (Some(_), Some(sv), _) | (Some(_), _, Some(sv)) => Err(ld
            .err(
                sv.span(),
                "`mu` sets both coefficients: give `mu`, or `mu_s` and `mu_k`",
            )
            .help("mu = 0.3 (static = kinetic), or mu_s = 0.4 and mu_k = 0.3")),
        (None, s, k) if mode == "coulomb" && (s.is_some() || k.is_some()) => {
            let s = s
                .as_ref()
                .map(|sv| read(ld, sv, "the static friction coefficient `mu_s`"))
                .transpose()?;
            let k = k
                .as_ref()
                .map(|sv| read(ld, sv, "the kinetic friction coefficient `mu_k`"))
                .transpose()?;
            let zero = (pdyn_expr::Pool::ZERO, 0.0);
            let (s, k) = (s.or(k).unwrap_or(zero), k.or(s).unwrap_or(zero));
            if k.1 > s.1 {
                let span = raw.mu_k.as_ref().map_or(e.f.span(), |sv| sv.span());
                return Err(ld
                    .err(span, format!("mu_k = {} is larger than mu_s = {}: kinetic friction cannot exceed static friction", k.1, s.1))
                    .help("a body that can slide against mu_k*N could not have been held by mu_s*N: make mu_k <= mu_s"));
            }
            Ok((k.0, s.0))
        }
        _ => Err(ld
            .err(
                e.f.span(),
                format!("a `friction` force in mode \"{mode}\" needs `mu`"),
            )
            .help("add mu = ... (or mu_s and mu_k for mode = \"coulomb\")")),
    }
}
