//! Force declarations → loads on particles and frames.
//!
//! | kind | force on the first body | potential |
//! |---|---|---|
//! | gravity (top-level `gravity = g`) | `m g` | `-m g·r` |
//! | `applied` | the given vector (may use the particle's `r`, `v`) | — |
//! | `spring` | `-k (l - l0) e`, `e = (r_A - r_B)/l` or `direction`, `l = |r_A - r_B|` or `length` | `k (l - l0)²/2` |
//! | `damper` | `-c (dl/dt) e` | — |
//! | `drag` | `-C |v_rel| v_rel`, `C = coefficient` or `ρ C_D A / 2`, `v_rel = v - wind` | — |
//! | `linear_drag` | `-c v_rel` | — |
//! | `inverse_square` | `-strength (r - r_to)/|r - r_to|³` | `-strength/|r - r_to|` |
//! | `potential` | `-V'(dist) e` for `V(dist)` | `V` |
//! | `reaction` | `N direction` (unknown `N`) or an unknown vector `(N_x, N_y, N_z)` | workless or not: unknown |
//! | `friction` | `N n + T t` (stick, unknown N, T) or `N n - mu N s` (slip, `s` the sliding direction) | — |
//!
//! Two-body forces act equal and opposite on the second body when it is a particle.

use super::raw::{Name, RawForce, Sv};
use super::{Frame, Load, Loader, ModelError, Particle, PotentialTerm, Reaction, Target};
use pdyn_expr::error::suggest;
use pdyn_expr::lower::{Binding, Scope};
use pdyn_expr::vector;
use pdyn_expr::{Id, Number, Pool, Value};
use toml::Spanned;

const KINDS: [&str; 10] = [
    "applied",
    "spring",
    "damper",
    "drag",
    "linear_drag",
    "inverse_square",
    "potential",
    "reaction",
    "friction",
    "gravity",
];

#[derive(Clone, Copy)]
enum Endpoint {
    Particle(usize),
    Point,
}

pub(super) struct Built {
    pub friction_forces: Vec<String>,
    pub loads: Vec<Load>,
    pub reactions: Vec<Reaction>,
    pub potentials: Vec<PotentialTerm>,
    pub conservative: bool,
}

pub(super) struct ForceBuilder<'a> {
    particles: &'a [Particle],
    frames: &'a [Frame],
    points: &'a [(String, [Id; 3])],
    loads: Vec<Load>,
    reactions: Vec<Reaction>,
    potentials: Vec<PotentialTerm>,
    conservative: bool,
    friction_forces: Vec<String>,
}

impl<'a> ForceBuilder<'a> {
    pub fn new(
        particles: &'a [Particle],
        frames: &'a [Frame],
        points: &'a [(String, [Id; 3])],
    ) -> Self {
        ForceBuilder {
            particles,
            frames,
            points,
            loads: Vec::new(),
            reactions: Vec::new(),
            potentials: Vec::new(),
            conservative: true,
            friction_forces: Vec::new(),
        }
    }

    pub fn finish(self) -> Built {
        Built {
            friction_forces: self.friction_forces,
            loads: self.loads,
            reactions: self.reactions,
            potentials: self.potentials,
            conservative: self.conservative,
        }
    }

    pub fn gravity(&mut self, ld: &mut Loader, g: [Id; 3]) {
        for (i, p) in self.particles.iter().enumerate() {
            let force = vector::scale(&mut ld.pool, p.mass, g);
            let gr = vector::dot(&mut ld.pool, g, p.position);
            let pe = ld.pool.mul2(p.mass, gr);
            let energy = ld.pool.neg(pe);
            self.loads.push(Load {
                label: format!("gravity on {}", p.name),
                target: Target::Particle(i),
                force,
            });
            self.potentials.push(PotentialTerm {
                label: format!("gravity on {}", p.name),
                energy,
            });
        }
    }

    fn need<'s>(
        &self,
        ld: &Loader,
        f: &Spanned<RawForce>,
        v: &'s Option<Sv>,
        field: &str,
        kind: &str,
    ) -> Result<&'s Sv, ModelError> {
        v.as_ref().ok_or_else(|| {
            ld.err(f.span(), format!("a `{kind}` force needs `{field}`"))
                .help(format!("add {field} = ... to this [[forces]] entry"))
        })
    }

    fn need_name<'s>(
        &self,
        ld: &Loader,
        f: &Spanned<RawForce>,
        v: &'s Option<Name>,
        field: &str,
        kind: &str,
    ) -> Result<&'s Name, ModelError> {
        v.as_ref().ok_or_else(|| {
            ld.err(f.span(), format!("a `{kind}` force needs `{field}`"))
                .help(format!("add {field} = \"...\" to this [[forces]] entry"))
        })
    }

    fn unknown_body(&self, ld: &Loader, name: &Name, frames_ok: bool) -> ModelError {
        let mut names: Vec<&str> = self.particles.iter().map(|p| p.name.as_str()).collect();
        if frames_ok {
            names.extend(self.frames.iter().map(|f| f.name.as_str()));
        } else {
            names.extend(self.points.iter().map(|p| p.0.as_str()));
        }
        let mut e = ld.err(
            name.span(),
            format!("unknown particle `{}`", name.get_ref()),
        );
        e = match suggest(name.get_ref(), names.iter().copied()) {
            Some(s) => e.help(format!("did you mean `{s}`?")),
            None => e.help(format!("declared: {}", names.join(", "))),
        };
        e
    }

    /// The body a one-body force acts on: a particle, or a frame (then `at` is required).
    fn target(
        &self,
        ld: &mut Loader,
        f: &Spanned<RawForce>,
        kind: &str,
    ) -> Result<(Target, [Id; 3]), ModelError> {
        let on = self.need_name(ld, f, &f.get_ref().on, "on", kind)?;
        if let Some(i) = self.particles.iter().position(|p| &p.name == on.get_ref()) {
            return Ok((Target::Particle(i), self.particles[i].position));
        }
        if let Some(j) = self.frames.iter().position(|fr| &fr.name == on.get_ref()) {
            let at = match &f.get_ref().at {
                Some(sv) => ld.vector(sv, "`at`")?,
                None => {
                    return Err(ld
                        .err(
                            on.span(),
                            format!(
                                "a force on frame `{}` needs `at`, its point of application",
                                on.get_ref()
                            ),
                        )
                        .help("add at = \"[x, y, z]\""))
                }
            };
            return Ok((Target::Frame { frame: j, at }, at));
        }
        Err(self.unknown_body(ld, on, true))
    }

    fn endpoint(&self, ld: &mut Loader, name: &Name) -> Result<(Endpoint, [Id; 3]), ModelError> {
        if let Some(i) = self
            .particles
            .iter()
            .position(|p| &p.name == name.get_ref())
        {
            return Ok((Endpoint::Particle(i), self.particles[i].position));
        }
        if let Some((_, r)) = self.points.iter().find(|(n, _)| n == name.get_ref()) {
            return Ok((Endpoint::Point, *r));
        }
        Err(self
            .unknown_body(ld, name, false)
            .help("an end is a particle or a point declared under [points]"))
    }

    fn pair(
        &self,
        ld: &mut Loader,
        f: &Spanned<RawForce>,
        kind: &str,
    ) -> Result<[(Endpoint, [Id; 3], String); 2], ModelError> {
        let raw = f.get_ref();
        if let Some(b) = &raw.between {
            if b.get_ref().len() != 2 {
                return Err(ld.err(
                    b.span(),
                    format!("`between` lists {} names; it needs two", b.get_ref().len()),
                ));
            }
            let (e0, r0) = self.endpoint(ld, &b.get_ref()[0])?;
            let (e1, r1) = self.endpoint(ld, &b.get_ref()[1])?;
            if matches!((e0, e1), (Endpoint::Point, Endpoint::Point)) {
                return Err(ld.err(
                    b.span(),
                    "both ends are fixed points: this force acts on no particle",
                ));
            }
            return Ok([
                (e0, r0, b.get_ref()[0].get_ref().clone()),
                (e1, r1, b.get_ref()[1].get_ref().clone()),
            ]);
        }
        if let (Some(on), Some(to)) = (&raw.on, &raw.to) {
            let (e0, r0) = self.endpoint(ld, on)?;
            let (e1, r1) = self.endpoint(ld, to)?;
            return Ok([
                (e0, r0, on.get_ref().clone()),
                (e1, r1, to.get_ref().clone()),
            ]);
        }
        Err(ld
            .err(
                f.span(),
                format!("a `{kind}` force needs `between = [\"A\", \"B\"]` (or `on` and `to`)"),
            )
            .help("each end is a particle or a point declared under [points]"))
    }

    /// Pushes `force` on the first end and `-force` on the second (if a particle).
    fn push_pair(
        &mut self,
        ld: &mut Loader,
        ends: &[(Endpoint, [Id; 3], String); 2],
        label: &str,
        force: [Id; 3],
    ) {
        if let Endpoint::Particle(i) = ends[0].0 {
            self.loads.push(Load {
                label: format!("{label} on {}", ends[0].2),
                target: Target::Particle(i),
                force,
            });
        }
        if let Endpoint::Particle(j) = ends[1].0 {
            let neg = force.map(|c| ld.pool.neg(c));
            self.loads.push(Load {
                label: format!("{label} on {}", ends[1].2),
                target: Target::Particle(j),
                force: neg,
            });
        }
    }

    fn reaction(
        &mut self,
        ld: &mut Loader,
        name: &str,
        span: std::ops::Range<usize>,
    ) -> Result<Id, ModelError> {
        if let Some(r) = self.reactions.iter().find(|r| r.name == name) {
            return Ok(r.id);
        }
        if ld.scope.resolve(&mut ld.pool, name).is_some() {
            return Err(ld
                .err(span, format!("reaction `{name}` has the name of an existing parameter, coordinate or definition"))
                .help("give the unknown force its own name"));
        }
        if !name.chars().next().is_some_and(|c| c.is_alphabetic())
            || !name.chars().all(|c| c.is_alphanumeric() || c == '_')
        {
            return Err(ld.err(span, format!("`{name}` is not a valid name")));
        }
        let s = ld.pool.symbol(name, false);
        let id = ld.pool.sym(s);
        self.reactions.push(Reaction {
            name: name.to_string(),
            id,
        });
        Ok(id)
    }

    fn with_local<T>(
        &self,
        ld: &mut Loader,
        r: [Id; 3],
        body: impl FnOnce(&mut Loader) -> Result<T, ModelError>,
    ) -> Result<T, ModelError> {
        let v = r.map(|c| ld.pool.dt(c));
        ld.scope
            .local
            .insert("r".into(), Binding::Value(Value::Vector(r)));
        ld.scope
            .local
            .insert("v".into(), Binding::Value(Value::Vector(v)));
        let out = body(ld);
        ld.scope.local.remove("r");
        ld.scope.local.remove("v");
        out
    }

    pub fn force(&mut self, ld: &mut Loader, f: &Spanned<RawForce>) -> Result<(), ModelError> {
        let raw = f.get_ref();
        let Some(kind_n) = &raw.kind else {
            return Err(ld
                .err(f.span(), "a [[forces]] entry needs `kind`")
                .help(format!("kinds: {}", KINDS.join(", "))));
        };
        let kind = kind_n.get_ref().as_str();
        let label = raw
            .name
            .as_ref()
            .map_or(kind.to_string(), |n| n.get_ref().clone());
        match kind {
            "applied" => {
                let (target, r) = self.target(ld, f, kind)?;
                let fsv = self.need(ld, f, &raw.force, "force", kind)?;
                let force = self.with_local(ld, r, |ld| ld.vector(fsv, "an applied force"))?;
                self.loads.push(Load {
                    label,
                    target,
                    force,
                });
                self.conservative = false;
            }
            "spring" | "damper" => {
                let ends = self.pair(ld, f, kind)?;
                let rel = vector::sub(&mut ld.pool, ends[0].1, ends[1].1);
                let l = match &raw.length {
                    Some(sv) => ld.scalar(sv, "`length`")?,
                    None => vector::norm(&mut ld.pool, rel),
                };
                // Attachments away from the particles' positions: the user gives the unit
                // direction (from the second end to the first) along with the length.
                let e = match &raw.direction {
                    Some(d) => ld.vector(d, "`direction`")?,
                    None => rel.map(|c| ld.pool.div(c, l)),
                };
                let mag = if kind == "spring" {
                    let k = ld.scalar(self.need(ld, f, &raw.k, "k", kind)?, "`k`")?;
                    let l0 = ld.scalar(self.need(ld, f, &raw.l0, "l0", kind)?, "`l0`")?;
                    let stretch = ld.pool.sub(l, l0);
                    let half = ld.pool.num(Number::ratio(1, 2));
                    let s2 = ld.pool.powi(stretch, 2);
                    let energy = ld.pool.mul(&[half, k, s2]);
                    self.potentials.push(PotentialTerm {
                        label: label.clone(),
                        energy,
                    });
                    ld.pool.mul2(k, stretch)
                } else {
                    let c = ld.scalar(self.need(ld, f, &raw.c, "c", kind)?, "`c`")?;
                    self.conservative = false;
                    let dl = ld.pool.dt(l);
                    ld.pool.mul2(c, dl)
                };
                let neg = ld.pool.neg(mag);
                let force = vector::scale(&mut ld.pool, neg, e);
                let lbl = format!("{label} ({}, {})", ends[0].2, ends[1].2);
                self.push_pair(ld, &ends, &lbl, force);
            }
            "drag" | "linear_drag" => {
                let (target, r) = self.target(ld, f, kind)?;
                let v = r.map(|c| ld.pool.dt(c));
                let vrel = match &raw.wind {
                    Some(w) => {
                        let w = ld.vector(w, "`wind`")?;
                        vector::sub(&mut ld.pool, v, w)
                    }
                    None => v,
                };
                let coef = if kind == "linear_drag" {
                    ld.scalar(self.need(ld, f, &raw.c, "c", kind)?, "`c`")?
                } else if let Some(c) = &raw.coefficient {
                    let c = ld.scalar(c, "`coefficient`")?;
                    let speed = vector::norm(&mut ld.pool, vrel);
                    ld.pool.mul2(c, speed)
                } else {
                    let rho = ld.scalar(
                        self.need(ld, f, &raw.rho, "rho (or coefficient)", kind)?,
                        "`rho`",
                    )?;
                    let cd = ld.scalar(self.need(ld, f, &raw.cd, "cd", kind)?, "`cd`")?;
                    let area = ld.scalar(self.need(ld, f, &raw.area, "area", kind)?, "`area`")?;
                    let half = ld.pool.num(Number::ratio(1, 2));
                    let speed = vector::norm(&mut ld.pool, vrel);
                    ld.pool.mul(&[half, rho, cd, area, speed])
                };
                let neg = ld.pool.neg(coef);
                let force = vector::scale(&mut ld.pool, neg, vrel);
                self.loads.push(Load {
                    label,
                    target,
                    force,
                });
                self.conservative = false;
            }
            "inverse_square" => {
                let ends = self.pair(ld, f, kind)?;
                let strength = ld.scalar(
                    self.need(ld, f, &raw.strength, "strength", kind)?,
                    "`strength`",
                )?;
                let rel = vector::sub(&mut ld.pool, ends[0].1, ends[1].1);
                let d = vector::norm(&mut ld.pool, rel);
                let d3 = ld.pool.powi(d, -3);
                let s = ld.pool.mul2(strength, d3);
                let ns = ld.pool.neg(s);
                let force = vector::scale(&mut ld.pool, ns, rel);
                let pe = ld.pool.div(strength, d);
                let energy = ld.pool.neg(pe);
                self.potentials.push(PotentialTerm {
                    label: label.clone(),
                    energy,
                });
                let lbl = format!("{label} ({}, {})", ends[0].2, ends[1].2);
                self.push_pair(ld, &ends, &lbl, force);
            }
            "potential" => {
                let ends = self.pair(ld, f, kind)?;
                let vsv = self.need(ld, f, &raw.potential, "potential", kind)?;
                let dist_sym = ld.pool.symbol("dist", true);
                let dist = ld.pool.sym(dist_sym);
                ld.scope
                    .local
                    .insert("dist".into(), Binding::Value(Value::Scalar(dist)));
                let pot = ld.scalar(vsv, "`potential`");
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
                self.potentials.push(PotentialTerm {
                    label: label.clone(),
                    energy,
                });
                let lbl = format!("{label} ({}, {})", ends[0].2, ends[1].2);
                self.push_pair(ld, &ends, &lbl, force);
            }
            "reaction" => {
                let (target, _) = self.target(ld, f, kind)?;
                let name = self.need_name(ld, f, &raw.name, "name", kind)?;
                let force = match &raw.direction {
                    Some(d) => {
                        let dir = ld.vector(d, "`direction`")?;
                        let n = self.reaction(ld, name.get_ref(), name.span())?;
                        vector::scale(&mut ld.pool, n, dir)
                    }
                    None => {
                        let mut c = [Pool::ZERO; 3];
                        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                            c[k] = self.reaction(
                                ld,
                                &format!("{}_{axis}", name.get_ref()),
                                name.span(),
                            )?;
                        }
                        c
                    }
                };
                self.loads.push(Load {
                    label: format!("reaction {}", name.get_ref()),
                    target,
                    force,
                });
            }
            "friction" => {
                let (target, at) = self.target(ld, f, kind)?;
                let nsv = self.need(ld, f, &raw.normal, "normal", kind)?;
                let normal = ld.vector(nsv, "`normal`")?;
                let n_name = raw
                    .normal_force
                    .as_ref()
                    .map_or("N".to_string(), |n| n.get_ref().clone());
                let t_name = raw
                    .friction_force
                    .as_ref()
                    .map_or("T".to_string(), |n| n.get_ref().clone());
                let span = raw
                    .normal_force
                    .as_ref()
                    .map_or(kind_n.span(), |n| n.span());
                let n_id = self.reaction(ld, &n_name, span)?;
                let nforce = vector::scale(&mut ld.pool, n_id, normal);
                self.loads.push(Load {
                    label: format!("normal force {n_name}"),
                    target: target.clone(),
                    force: nforce,
                });
                let mode = raw.mode.as_ref().map_or("stick", |m| m.get_ref().as_str());
                match mode {
                    "stick" => {
                        let tsv = self.need(
                            ld,
                            f,
                            &raw.tangent,
                            "tangent (the direction of the friction force T)",
                            kind,
                        )?;
                        let tangent = ld.vector(tsv, "`tangent`")?;
                        let span = raw
                            .friction_force
                            .as_ref()
                            .map_or(kind_n.span(), |n| n.span());
                        let t_id = self.reaction(ld, &t_name, span)?;
                        self.friction_forces.push(t_name.clone());
                        let tforce = vector::scale(&mut ld.pool, t_id, tangent);
                        self.loads.push(Load {
                            label: format!("friction force {t_name}"),
                            target,
                            force: tforce,
                        });
                    }
                    "slip" => {
                        let mu = ld.scalar(self.need(ld, f, &raw.mu, "mu", kind)?, "`mu`")?;
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
                                        let s = ld.vector(s, "`surface_velocity`")?;
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
                        self.loads.push(Load {
                            label: format!("sliding friction mu*{n_name}"),
                            target,
                            force: tforce,
                        });
                        self.conservative = false;
                    }
                    other => {
                        let m = raw.mode.as_ref().map_or(kind_n.span(), |m| m.span());
                        return Err(ld
                            .err(m, format!("unknown friction mode `{other}`"))
                            .help("mode is \"stick\" (friction force unknown) or \"slip\" (T = mu*N opposing sliding)"));
                    }
                }
            }
            "gravity" => {
                return Err(ld
                    .err(
                        kind_n.span(),
                        "gravity is declared once for the whole model",
                    )
                    .help("write gravity = \"[0, 0, -g]\" at the top of the file"));
            }
            other => {
                let mut e = ld.err(kind_n.span(), format!("unknown force kind `{other}`"));
                e = match suggest(other, KINDS) {
                    Some(s) => e.help(format!("did you mean `{s}`?")),
                    None => e.help(format!("kinds: {}", KINDS.join(", "))),
                };
                return Err(e);
            }
        }
        Ok(())
    }
}
