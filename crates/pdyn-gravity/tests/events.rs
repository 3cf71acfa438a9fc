//! Collisions and escapes end an integration as an `Outcome`, with the bodies involved.

use pdyn_gravity::{
    Anomaly, Elements, EventParams, Ias15Params, Integrator, Outcome, Particle, Primary,
    Simulation, Units, Vec3,
};

/// Two unit masses released at rest 2 apart fall together in t = π/4 · √(d³/(2G·2m))…; with
/// radii 0.1 they touch before that, and IAS15 stops there with the pair named.
#[test]
fn head_on_fall_is_a_collision() {
    let mut sim = Simulation::new(Units::GEqualsOne);
    for x in [-1.0, 1.0] {
        sim.add_with_radius(
            Particle {
                mass: 1.0,
                pos: Vec3::new(x, 0.0, 0.0),
                vel: Vec3::ZERO,
            },
            0.1,
        )
        .unwrap();
    }
    sim.set_integrator(Integrator::Ias15(Ias15Params::default()))
        .unwrap();
    sim.set_dt(1e-3).unwrap();
    let out = sim.integrate(10.0).unwrap();
    let Outcome::Collision { t, i, j } = out else {
        panic!("expected a collision, got {out:?}")
    };
    assert_eq!((i, j), (0, 1));
    // Radial free fall from separation 2 to 0.2 with μ = 2: t = √(r₀³/2μ)(√(x(1−x)) + acos√x),
    // x = r/r₀ = 0.1. The event is reported at the end of the step that finds it.
    let (r0, mu, x) = (2.0f64, 2.0f64, 0.1f64);
    let t_touch =
        (r0.powi(3) / (2.0 * mu)).sqrt() * ((x * (1.0 - x)).sqrt() + libm::acos(x.sqrt()));
    assert!(
        t >= t_touch && t < t_touch + 0.05,
        "t = {t}, analytic {t_touch}"
    );
    assert!((sim.t() - t).abs() < 1e-15);
}

/// A body on a hyperbola leaves a sphere of radius 10.
#[test]
fn hyperbolic_body_escapes() {
    let mut sim = Simulation::new(Units::GEqualsOne);
    sim.add(Particle {
        mass: 1.0,
        pos: Vec3::ZERO,
        vel: Vec3::ZERO,
    })
    .unwrap();
    let hyperbola = Elements {
        a: -1.0,
        e: 1.5,
        anomaly: Anomaly::True(0.0),
        ..Elements::circular(1.0)
    };
    sim.add_orbit(1e-6, &hyperbola, Primary::Interior).unwrap();
    sim.set_events(EventParams {
        escape_distance: Some(10.0),
        ..EventParams::default()
    });
    sim.set_dt(0.01).unwrap();
    let out = sim.integrate(100.0).unwrap();
    let Outcome::Escape {
        index, distance, ..
    } = out
    else {
        panic!("expected an escape, got {out:?}")
    };
    assert_eq!(index, 1);
    assert!((10.0..10.2).contains(&distance));
}
