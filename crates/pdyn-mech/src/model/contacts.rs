//! `[[contacts]]`: a particle against a surface, or two particles, that may touch, separate,
//! stick, slide and collide (the hybrid mechanics of [`crate::hybrid`]).
//!
//! A surface is a function `phi(r)` of a position: the particle is clear of it where
//! `phi > 0` and touches it where `phi = 0` (`surface = "r.y"` is the floor `y = 0`,
//! `surface = "norm(r) - R"` the outside of a sphere). The contact's normal is the unit
//! gradient `∇phi / |∇phi|`, the direction of the normal force on the particle. Two particles
//! `between = ["A", "B"]` use `r = r_A - r_B` (and `distance`, the sum of their radii, for
//! `surface = "norm(r) - distance"`); the force on B is opposite to the force on A.
//!
//! The contact's gap is `phi` at the particle's position. When the coordinates keep it zero
//! whatever their values (a block whose position is `[x, 0, 0]` on the floor `r.y`), the
//! contact is *held*: it cannot open, and its normal force is always an unknown reaction.

use super::raw::{Name, RawContact, RawModel, Sv};
use super::{Loader, ModelError, Particle, Reaction};
use pdyn_expr::error::suggest;
use pdyn_expr::lower::Binding;
use pdyn_expr::{vector, Dimension, Id, Pool, Value};
use rustc_hash::FxHashMap;
use std::ops::Range;
use toml::Spanned;

/// A contact that may open, close, stick, slide and collide.
#[derive(Clone, Debug)]
pub struct Contact {
    /// Name used in reports (`floor`, `ball on dome`).
    pub name: String,
    /// Where it is declared in the model file.
    pub span: Range<usize>,
    /// The particle (the first of a pair).
    pub a: usize,
    /// The second particle of a pair contact.
    pub b: Option<usize>,
    /// `phi` at the contact: positive apart, zero touching (an expression of `q`, `t`).
    pub gap: Id,
    /// Unit normal: the normal force on `a` is `N * normal` (on `b`, the opposite).
    pub normal: [Id; 3],
    /// The coordinates keep the gap at zero: the contact cannot open.
    pub held: bool,
    /// Newton's coefficient of restitution `e` (an expression of the parameters).
    pub restitution: Id,
    /// Static and kinetic friction coefficients; `None` for a smooth contact.
    pub friction: Option<(Id, Id)>,
    /// Velocity of the surface at the contact (a conveyor belt), subtracted from the
    /// particle's to give the slip velocity.
    pub surface_velocity: [Id; 3],
    /// The normal force's name and symbol.
    pub normal_force: (String, Id),
    /// The friction force's name and symbols: along the first tangent, and along the second
    /// (used only where the contact can slip in two directions).
    pub friction_force: (String, [Id; 2]),
    /// Whether the normal force is a reaction of the model itself (a `friction` force's
    /// normal force), not added by the hybrid modes.
    pub normal_in_model: bool,
    /// Loads of the model that the hybrid modes replace (a `friction` force's sliding load).
    pub replaces_loads: Vec<usize>,
}

impl Loader<'_> {
    /// `[[contacts]]`, after the forces and constraints (names of particles and reactions are
    /// known) and before `[[events]]` and `[monitors]` (which may use the contact forces).
    pub(super) fn read_contacts(
        &mut self,
        raw: &RawModel,
        particles: &[Particle],
        reactions: &[Reaction],
    ) -> Result<Vec<Contact>, ModelError> {
        let mut out: Vec<Contact> = Vec::new();
        for (k, c) in raw.contacts.iter().enumerate() {
            let contact = self.contact(c, k, particles, reactions, &out)?;
            out.push(contact);
        }
        Ok(out)
    }

    fn contact(
        &mut self,
        c: &Spanned<RawContact>,
        k: usize,
        particles: &[Particle],
        reactions: &[Reaction],
        earlier: &[Contact],
    ) -> Result<Contact, ModelError> {
        let raw = c.get_ref();
        let name = raw
            .name
            .as_ref()
            .map_or_else(|| format!("contact{}", k + 1), |n| n.get_ref().clone());
        if let Some(prev) = earlier.iter().find(|p| p.name == name) {
            let (line, _) = pdyn_expr::error::line_col(self.source, prev.span.start);
            return Err(self
                .err(
                    raw.name.as_ref().map_or(c.span(), |n| n.span()),
                    format!("duplicate contact name `{name}` (line {line})"),
                )
                .help("give each contact its own name"));
        }
        let find = |ld: &Loader, n: &Name| -> Result<usize, ModelError> {
            particles
                .iter()
                .position(|p| &p.name == n.get_ref())
                .ok_or_else(|| {
                    let names = particles.iter().map(|p| p.name.as_str());
                    let e = ld.err(n.span(), format!("unknown particle `{}`", n.get_ref()));
                    match suggest(n.get_ref(), names) {
                        Some(s) => e.help(format!("did you mean `{s}`?")),
                        None => e.help("a contact acts on particles declared under [particles]"),
                    }
                })
        };
        let (a, b) = match (&raw.on, &raw.between) {
            (Some(on), None) => (find(self, on)?, None),
            (None, Some(bw)) => {
                let names = bw.get_ref();
                if names.len() != 2 {
                    return Err(self.err(
                        bw.span(),
                        format!("`between` lists {} names; it needs two", names.len()),
                    ));
                }
                let (i, j) = (find(self, &names[0])?, find(self, &names[1])?);
                if i == j {
                    return Err(self.err(bw.span(), "a particle cannot touch itself"));
                }
                (i, Some(j))
            }
            (Some(_), Some(bw)) => {
                return Err(self
                    .err(bw.span(), "a contact has `on` or `between`, not both")
                    .help("on = \"P\" for a particle against a surface, between = [\"A\", \"B\"] for two particles"))
            }
            (None, None) => {
                return Err(self
                    .err(c.span(), format!("contact `{name}` needs `on` or `between`"))
                    .help("on = \"P\" for a particle against a surface, between = [\"A\", \"B\"] for two particles"))
            }
        };
        // r: the particle's position, or A's relative to B.
        let r_at = match b {
            None => particles[a].position,
            Some(j) => vector::sub(&mut self.pool, particles[a].position, particles[j].position),
        };
        let phi_of_rho = self.surface(raw, c, &name, b.is_some())?;
        let (phi, rho) = phi_of_rho;
        let grad: [Id; 3] = rho.map(|s| self.pool.diff(phi, s));
        if grad.iter().all(|&g| self.pool.is_zero(g)) {
            let span = raw.surface.as_ref().map_or(c.span(), |s| s.span());
            return Err(self
                .err(span, format!("the surface of contact `{name}` does not depend on the position `r`: it has no normal"))
                .help("write the surface as a function of r that is zero on it and positive on the free side, e.g. \"r.y\" (the floor y = 0) or \"norm(r) - R\" (outside a sphere)"));
        }
        if never_negative(&self.pool, phi) {
            let span = raw.surface.as_ref().map_or(c.span(), |s| s.span());
            return Err(self
                .err(span, format!("the surface of contact `{name}` is never negative: nothing is ever on its other side, so the contact could never close (the particle would pass through)"))
                .help("write phi(r) zero on the surface, positive on the free side and negative beyond it, e.g. \"norm(r) - R\" rather than \"norm(r)\""));
        }
        let map: FxHashMap<Id, Id> = rho.iter().copied().zip(r_at).collect();
        let gap = self.pool.subs(phi, &map);
        let grad_at = grad.map(|g| self.pool.subs(g, &map));
        let normal = vector::unit(&mut self.pool, grad_at);
        let gap_s = self.pool.simplify(gap);
        let held = self.pool.provably_equal(gap_s, Pool::ZERO);

        let restitution = match &raw.e {
            Some(sv) => self.coefficient(sv, "the coefficient of restitution `e`", 1.0)?,
            None => Pool::ZERO,
        };
        let mu = |ld: &mut Loader, sv: &Option<Sv>, what: &str| -> Result<Option<Id>, ModelError> {
            sv.as_ref()
                .map(|sv| ld.coefficient(sv, what, f64::INFINITY))
                .transpose()
        };
        let mu_both = mu(self, &raw.mu, "the friction coefficient `mu`")?;
        let mu_s = mu(self, &raw.mu_s, "the static friction coefficient `mu_s`")?;
        let mu_k = mu(self, &raw.mu_k, "the kinetic friction coefficient `mu_k`")?;
        if let (Some(_), Some(sv)) = (mu_both, raw.mu_s.as_ref().or(raw.mu_k.as_ref())) {
            return Err(self
                .err(
                    sv.span(),
                    "`mu` sets both coefficients: give `mu`, or `mu_s` and `mu_k`",
                )
                .help("mu = 0.3 (static = kinetic), or mu_s = 0.4 and mu_k = 0.3"));
        }
        let friction = match (mu_both, mu_s, mu_k) {
            (Some(m), _, _) => Some((m, m)),
            (None, Some(s), Some(k)) => Some((s, k)),
            (None, Some(s), None) => Some((s, s)),
            (None, None, Some(k)) => Some((k, k)),
            (None, None, None) => None,
        };
        if let (Some(sv), Some((s, k))) = (raw.mu_k.as_ref(), friction) {
            let (vs, vk) = (self.value_of(s), self.value_of(k));
            if vk > vs {
                return Err(self
                    .err(sv.span(), format!("mu_k = {vk} is larger than mu_s = {vs}: kinetic friction cannot exceed static friction"))
                    .help("a body that can slide against mu_k*N could not have been held by mu_s*N: make mu_k <= mu_s"));
            }
        }
        let surface_velocity = match &raw.surface_velocity {
            Some(sv) => {
                let v = self.vector(sv, "`surface_velocity`")?;
                self.want(sv, Dimension::VELOCITY, "the `surface_velocity`");
                v
            }
            None => [Pool::ZERO; 3],
        };
        let n_name = raw
            .normal_force
            .as_ref()
            .map_or_else(|| format!("N_{name}"), |n| n.get_ref().clone());
        let f_name = raw
            .friction_force
            .as_ref()
            .map_or_else(|| format!("F_{name}"), |n| n.get_ref().clone());
        let n_span = raw.normal_force.as_ref().map_or(c.span(), |n| n.span());
        let f_span = raw.friction_force.as_ref().map_or(c.span(), |n| n.span());
        if let Some(r) = reactions.iter().find(|r| r.name == n_name) {
            return Err(self
                .err(n_span, format!("`{}` is already a reaction of [[forces]]: a contact supplies its own normal force, so declaring it again would count it twice", r.name))
                .help("remove the reaction (the contact pushes along its normal), or name the contact's force differently with normal_force = \"...\""));
        }
        let n_id = self.contact_force(&n_name, n_span)?;
        let f1 = self.contact_force(&f_name, f_span.clone())?;
        let f2 = self.contact_force(&format!("{f_name}_2"), f_span)?;
        Ok(Contact {
            name,
            span: c.span(),
            a,
            b,
            gap,
            normal,
            held,
            restitution,
            friction,
            surface_velocity,
            normal_force: (n_name, n_id),
            friction_force: (f_name, [f1, f2]),
            normal_in_model: false,
            replaces_loads: Vec::new(),
        })
    }

    /// `phi(rho)` with `rho` three fresh symbols standing for `r`.
    fn surface(
        &mut self,
        raw: &RawContact,
        c: &Spanned<RawContact>,
        name: &str,
        pair: bool,
    ) -> Result<(Id, [Id; 3]), ModelError> {
        let rho: [Id; 3] = ["x", "y", "z"].map(|a| {
            let s = self
                .pool
                .symbol(&format!("⟨r.{a} of contact {name}⟩"), false);
            self.pool.sym(s)
        });
        let distance = match &raw.distance {
            Some(sv) => {
                let d = self.scalar(sv, "`distance`")?;
                self.want(sv, Dimension::LENGTH, "the contact `distance`");
                if !pair {
                    return Err(self
                        .err(sv.span(), "`distance` applies to a contact between two particles")
                        .help("for a particle against a surface, write the surface: surface = \"r.y\""));
                }
                Some(d)
            }
            None => None,
        };
        let phi = match (&raw.surface, distance) {
            (Some(sv), None) => {
                self.scope
                    .local
                    .insert("r".into(), Binding::Value(Value::Vector(rho)));
                self.dims.bind("r", Dimension::LENGTH.into());
                let v = self.scalar(sv, "`surface`");
                self.dims.unbind("r");
                self.scope.local.remove("r");
                v?
            }
            (None, Some(d)) => {
                let n = vector::norm(&mut self.pool, rho);
                self.pool.sub(n, d)
            }
            (Some(sv), Some(_)) => {
                return Err(self
                    .err(sv.span(), "give `surface` or `distance`, not both")
                    .help("distance = \"R1 + R2\" is surface = \"norm(r) - (R1 + R2)\""))
            }
            (None, None) => {
                let help = if pair {
                    "distance = \"R1 + R2\" (the particles touch when their centres are that far apart)"
                } else {
                    "surface = \"r.y\" (the floor y = 0; positive on the free side), or \"norm(r) - R\" (outside a sphere)"
                };
                return Err(self
                    .err(c.span(), format!("contact `{name}` needs a `surface`"))
                    .help(help));
            }
        };
        Ok((phi, rho))
    }

    /// A coefficient: a scalar of the parameters, a pure number in `[0, max]`.
    fn coefficient(&mut self, sv: &Sv, what: &str, max: f64) -> Result<Id, ModelError> {
        let e = self.scalar(sv, what)?;
        self.want(sv, Dimension::NONE, what);
        let v = self.constant(e, sv.span(), what)?;
        if !(0.0..=max).contains(&v) {
            let range = if max.is_finite() {
                format!("between 0 and {max}")
            } else {
                "at least 0".to_string()
            };
            return Err(self
                .err(sv.span(), format!("{what} is {v}; it must be {range}"))
                .help(if max.is_finite() {
                    "e = 1 is a perfectly elastic impact, e = 0 a perfectly plastic one"
                } else {
                    "friction coefficients are >= 0 (0: a smooth contact)"
                }));
        }
        Ok(e)
    }

    /// The value of an expression of the parameters (NaN if it is not one).
    fn value_of(&mut self, e: Id) -> f64 {
        self.constant(e, 0..0, "").unwrap_or(f64::NAN)
    }

    /// Declares a contact force's name (usable in `[[events]]` and `[monitors]`).
    fn contact_force(&mut self, name: &str, span: Range<usize>) -> Result<Id, ModelError> {
        let s = self.pool.symbol(name, false);
        let id = self.pool.sym(s);
        self.declare(name, span, "reaction", Binding::Value(Value::Scalar(id)))?;
        self.dims.bind(name, Dimension::FORCE.into());
        Ok(id)
    }
}

/// Whether `e` is non-negative whatever its symbols' values, by its form: an even power, a
/// square root, an absolute value, or sums and positive multiples of those (`norm(r)`,
/// `r.y^2`). Such a surface function has no inside.
fn never_negative(p: &Pool, e: Id) -> bool {
    use pdyn_expr::{Func, Node};
    match p.node(e) {
        Node::Num(n) => n.to_f64() >= 0.0,
        Node::Pow(b, x) => match p.node(*x) {
            Node::Num(n) => {
                let v = n.to_f64();
                // x^(1/2), x^(3/2)...: real only where the base is >= 0; x^2, x^4: even.
                (v.fract() != 0.0 && v > 0.0)
                    || (v.fract() == 0.0 && v % 2.0 == 0.0)
                    || never_negative(p, *b)
            }
            _ => false,
        },
        Node::Call(Func::Abs, _) => true,
        Node::Add(ts) | Node::Mul(ts) => ts.iter().all(|&t| never_negative(p, t)),
        _ => false,
    }
}
