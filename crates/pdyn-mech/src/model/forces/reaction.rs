//! `reaction`: an unknown force on a body, `name * direction` (one unknown `name`) or, without
//! `direction`, an unknown vector `(name_x, name_y, name_z)`. Reactions with the same name are
//! the same unknown. Workless or not: unknown. `one_sided = true`: it can only push along
//! `direction` (a normal force); a run warns when it pulls.

use super::{vector, Entry, ForceBuilder, Kind, Load, Loader, ModelError, Pool};

pub(super) const REACTION: Kind = Kind {
    name: "reaction",
    fields: "`on`, `name`, optional `direction`, `one_sided`",
    force: "`name * direction` (one unknown), or an unknown vector `name_x, name_y, name_z`",
    potential: "—",
    build,
};

fn build(b: &mut ForceBuilder, ld: &mut Loader, e: &Entry) -> Result<(), ModelError> {
    let (target, _) = b.target(ld, e)?;
    let name = e.need_name(ld, &e.raw.name, "name")?;
    if let (Some(os), None) = (&e.raw.one_sided, &e.raw.direction) {
        if *os.get_ref() {
            return Err(ld
                .err(
                    os.span(),
                    "a one-sided reaction needs the `direction` it pushes along",
                )
                .help("direction = \"[0, 1, 0]\": the reaction may push along it, never pull"));
        }
    }
    if e.raw.one_sided.as_ref().is_some_and(|o| *o.get_ref()) {
        b.one_sided.push(name.get_ref().clone());
    }
    let force = match &e.raw.direction {
        Some(d) => {
            let dir = ld.vector(d, "`direction`")?;
            let n = b.reaction(ld, name.get_ref(), name.span())?;
            b.directed(ld, name.get_ref(), &target, dir, name.span(), "reaction")?;
            let n_form = ld.dims.of(name.get_ref()).unwrap_or_default();
            let what = format!("the reaction `{}` times its `direction`", name.get_ref());
            ld.want_times(d, &n_form, pdyn_expr::Dimension::FORCE, &what);
            vector::scale(&mut ld.pool, n, dir)
        }
        None => {
            let mut c = [Pool::ZERO; 3];
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                c[k] = b.reaction(ld, &format!("{}_{axis}", name.get_ref()), name.span())?;
            }
            c
        }
    };
    b.loads.push(Load {
        label: format!("reaction {}", name.get_ref()),
        target,
        force,
    });
    Ok(())
}
