//! An [`NbodySpec`] turned into a `pdyn_gravity::Simulation`: bodies added in file order
//! (elements converted about their primary, as REBOUND's `sim.add(primary=...)`), the Plummer
//! sphere generated, the frame moved to the centre of mass, integrator, forces and events
//! set. The engine's refusals (a body on another, elements that describe no orbit) come back
//! located at the body that caused them.

use super::spec::{BodySpec, InitialState, IntegratorKind, NbodySpec, Origin};
use pdyn_gravity::{
    EventParams, Gravity, GravityError, Ias15Params, Integrator, Particle, Primary, Simulation,
    Vec3, WhFastParams,
};
use pdyn_mech::ModelError;

/// Most bodies a model may ask for (checked before anything is allocated).
pub const MAX_BODIES: usize = 2_000_000;

/// How the simulation integrates, kept so that it can be rebuilt after a merger or a removal
/// (the engine has no removal; a new simulation with the same settings is equivalent).
#[derive(Debug, Clone, Copy)]
pub struct Config {
    /// Units.
    pub units: pdyn_gravity::Units,
    /// Integrator and its parameters.
    pub integrator: Integrator,
    /// Step (initial step for IAS15).
    pub dt: f64,
    /// Forces.
    pub gravity: Gravity,
    /// Softening length.
    pub softening: f64,
    /// Events.
    pub events: EventParams,
}

impl Config {
    /// The settings of `spec` (with its `dt` or the default for the integrator).
    pub fn of(spec: &NbodySpec) -> Result<Config, ModelError> {
        let integrator = match spec.integrator {
            IntegratorKind::WhFast => Integrator::WhFast(WhFastParams {
                corrector: spec.corrector,
                ..WhFastParams::default()
            }),
            IntegratorKind::Ias15 => Integrator::Ias15(Ias15Params {
                epsilon: spec.epsilon.unwrap_or(Ias15Params::default().epsilon),
                ..Ias15Params::default()
            }),
            IntegratorKind::Leapfrog => Integrator::Leapfrog,
        };
        let dt = match (&spec.dt, spec.integrator) {
            (Some((dt, _)), _) => *dt,
            // IAS15 adapts its step from the first trial (which may shrink or grow 4× a step).
            (None, IntegratorKind::Ias15) => 1e-3 * spec.t_end.unwrap_or(1.0),
            (None, kind) => {
                return Err(ModelError::new(
                    &spec.origin,
                    spec.integrator_span.clone(),
                    format!("integrator `{}` has a fixed step: give dt", kind.name()),
                )
                .help(format!(
                    "for WHFast a twentieth of the shortest orbital period is usual; or {}",
                    crate::options::RunOption::Dt
                )))
            }
        };
        Ok(Config {
            units: spec.units.units,
            integrator,
            dt,
            gravity: spec.tree.map_or(Gravity::Direct, Gravity::Tree),
            softening: spec.softening,
            events: EventParams {
                collisions: true,
                escape_distance: spec.escape.map(|(r, _)| r),
            },
        })
    }

    /// A simulation with these settings and the given bodies (state, radius).
    pub fn simulation(&self, bodies: &[(Particle, f64)]) -> Result<Simulation, GravityError> {
        let mut sim = Simulation::new(self.units);
        for &(p, r) in bodies {
            sim.add_with_radius(p, r)?;
        }
        self.apply(&mut sim)?;
        Ok(sim)
    }

    fn apply(&self, sim: &mut Simulation) -> Result<(), GravityError> {
        sim.set_integrator(self.integrator)?;
        sim.set_dt(self.dt)?;
        sim.set_gravity(self.gravity)?;
        sim.set_softening(self.softening)?;
        sim.set_events(self.events);
        Ok(())
    }
}

/// A located build error: where, what.
#[derive(Debug, Clone)]
pub struct BuildError {
    /// The file and the span of the body (or table) at fault.
    pub origin: Origin,
    /// What is wrong.
    pub message: String,
    /// What would be valid.
    pub help: Option<String>,
}

impl BuildError {
    fn at(origin: &Origin, message: impl Into<String>) -> BuildError {
        BuildError {
            origin: origin.clone(),
            message: message.into(),
            help: None,
        }
    }
    fn help(mut self, h: impl Into<String>) -> BuildError {
        self.help = Some(h.into());
        self
    }
    /// As a [`ModelError`].
    pub fn model_error(&self) -> ModelError {
        let e = ModelError::new(&self.origin.file, self.origin.span.clone(), &self.message);
        match &self.help {
            Some(h) => e.help(h),
            None => e,
        }
    }
}

/// The simulation and what it was built from.
pub struct Built {
    /// The simulation, ready to integrate.
    pub sim: Simulation,
    /// Its settings (to rebuild after a merger).
    pub config: Config,
    /// Body names, in index order (Plummer stars are `star0`, `star1`...).
    pub names: Vec<String>,
    /// Each body's primary for its orbital elements: the declared one, or `None` (Jacobi:
    /// the interior bodies' centre of mass).
    pub primaries: Vec<Option<usize>>,
}

/// Builds the simulation of `spec`.
pub fn build(spec: &NbodySpec) -> Result<Built, BuildError> {
    let table = Origin {
        file: spec.origin.clone(),
        span: spec.table_span.clone(),
    };
    let config = Config::of(spec).map_err(|e| BuildError {
        origin: Origin {
            file: e.origin.clone(),
            span: e.span.clone(),
        },
        message: e.message.clone(),
        help: e.help.clone(),
    })?;
    let total = spec.bodies.len() + spec.plummer.as_ref().map_or(0, |p| p.n);
    if total > MAX_BODIES {
        return Err(BuildError::at(
            &table,
            format!("{total} bodies: more than the limit of {MAX_BODIES}"),
        ));
    }
    let mut sim = Simulation::new(config.units);
    let mut names = Vec::with_capacity(total);
    let mut primaries = Vec::with_capacity(total);
    for (index, b) in spec.bodies.iter().enumerate() {
        add_body(&mut sim, b, index).map_err(|e| located(e, b, spec))?;
        names.push(b.name.clone());
        primaries.push(match b.state {
            InitialState::Orbit { primary, .. } => primary,
            InitialState::Cartesian { .. } => None,
        });
    }
    if let Some(p) = &spec.plummer {
        use pdyn_gravity::plummer::{plummer_scaled, Scaling};
        let scaling = if p.rescale {
            Scaling::Henon
        } else {
            Scaling::Natural
        };
        let stars = plummer_scaled(p.n, p.seed, MAX_BODIES, scaling)
            .map_err(|e| BuildError::at(&p.origin, e.to_string()))?;
        let g = config.units.g();
        let vscale = (g * p.mass / p.scale).sqrt();
        for (k, s) in stars.into_iter().enumerate() {
            let star = Particle {
                mass: s.mass * p.mass,
                pos: p.scale * s.pos,
                vel: vscale * s.vel,
            };
            sim.add(star).map_err(|e| {
                BuildError::at(&p.origin, format!("star {k} of the Plummer sphere: {e}"))
            })?;
            names.push(format!("star{k}"));
            primaries.push(None);
        }
    }
    check_overlaps(&sim, spec)?;
    if spec.center_of_mass {
        sim.move_to_center_of_mass()
            .map_err(|e| BuildError::at(&table, e.to_string()))?;
    }
    config
        .apply(&mut sim)
        .map_err(|e| BuildError::at(&table, e.to_string()))?;
    Ok(Built {
        sim,
        config,
        names,
        primaries,
    })
}

fn add_body(sim: &mut Simulation, b: &BodySpec, index: usize) -> Result<usize, GravityError> {
    debug_assert_eq!(sim.len(), index);
    match &b.state {
        InitialState::Cartesian { position, velocity } => sim.add_with_radius(
            Particle {
                mass: b.mass,
                pos: Vec3(*position),
                vel: Vec3(*velocity),
            },
            b.radius,
        ),
        InitialState::Orbit { elements, primary } => sim.add_orbit_with_radius(
            b.mass,
            elements,
            primary.map_or(Primary::Interior, Primary::Body),
            b.radius,
        ),
    }
}

fn located(e: GravityError, b: &BodySpec, spec: &NbodySpec) -> BuildError {
    let name = |i: usize| {
        spec.bodies
            .get(i)
            .map_or(format!("body {i}"), |b| format!("`{}`", b.name))
    };
    match e {
        GravityError::Coincident { other, .. } => BuildError::at(
            &b.origin,
            format!(
                "body `{}` is placed exactly on body {}",
                b.name,
                name(other)
            ),
        )
        .help("their mutual force would be infinite: give distinct positions"),
        GravityError::InvalidPrimary { .. } => BuildError::at(
            &b.origin,
            format!("body `{}`: its primary has no mass to orbit", b.name),
        ),
        other => BuildError::at(&b.origin, format!("body `{}`: {other}", b.name)),
    }
}

/// Bodies with radii that already touch at the start would be reported as a collision at
/// the first step; that is bad input, said where it is.
fn check_overlaps(sim: &Simulation, spec: &NbodySpec) -> Result<(), BuildError> {
    let r = sim.radii();
    let with: Vec<usize> = (0..r.len()).filter(|&i| r[i] > 0.0).collect();
    let p = sim.particles();
    for (k, &i) in with.iter().enumerate() {
        for &j in &with[k + 1..] {
            let d = (p.pos(i) - p.pos(j)).norm();
            if d < r[i] + r[j] {
                let origin = spec.bodies.get(j).map_or_else(
                    || Origin {
                        file: spec.origin.clone(),
                        span: spec.table_span.clone(),
                    },
                    |b| b.origin.clone(),
                );
                let name = |i: usize| {
                    spec.bodies
                        .get(i)
                        .map_or(format!("{i}"), |b| b.name.clone())
                };
                return Err(BuildError::at(
                    &origin,
                    format!(
                        "bodies `{}` and `{}` overlap at t = 0 (distance {d:.6e} < sum of radii {:.6e})",
                        name(i),
                        name(j),
                        r[i] + r[j]
                    ),
                ));
            }
        }
    }
    Ok(())
}
