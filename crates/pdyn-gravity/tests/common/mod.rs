//! Initial conditions shared by the integration tests.
#![allow(dead_code)]

use pdyn_gravity::{Particle, Simulation, Units, Vec3};

/// Outer Solar System (Sun with the inner planets' mass, Jupiter, Saturn, Uranus, Neptune)
/// in AU, days and solar masses, `G = k²`. Heliocentric-ish barycentric positions and
/// velocities from Applegate et al. (1986), AJ 92, 176 — the set REBOUND's
/// `examples/outer_solar_system/problem.c` uses (Pluto omitted).
pub fn outer_solar_system() -> Simulation {
    let pos = [
        [
            -4.06428567034226e-3,
            -6.08813756435987e-3,
            -1.66162304225834e-6,
        ],
        [
            3.40546614227466e+0,
            3.62978190075864e+0,
            3.42386261766577e-2,
        ],
        [
            6.60801554403466e+0,
            6.38084674585064e+0,
            -1.36145963724542e-1,
        ],
        [
            1.11636331405597e+1,
            1.60373479057256e+1,
            3.61783279369958e-1,
        ],
        [
            -3.01777243405203e+1,
            1.91155314998064e+0,
            -1.53887595621042e-1,
        ],
    ];
    let vel = [
        [
            6.69048890636161e-6,
            -6.33922479583593e-6,
            -3.13202145590767e-9,
        ],
        [
            -5.59797969310664e-3,
            5.51815399480116e-3,
            -2.66711392865591e-6,
        ],
        [
            -4.17354020307064e-3,
            3.99723751748116e-3,
            1.67206320571441e-5,
        ],
        [
            -3.25884806151064e-3,
            2.06438412905916e-3,
            -2.17699042180559e-5,
        ],
        [
            -2.17471785045538e-4,
            -3.11361111025884e-3,
            3.58344705491441e-5,
        ],
    ];
    let mass = [
        1.00000597682,
        1.0 / 1047.355,
        1.0 / 3501.6,
        1.0 / 22869.0,
        1.0 / 19314.0,
    ];
    let mut sim = Simulation::new(Units::AuDaySolarMass);
    for i in 0..5 {
        sim.add(Particle {
            mass: mass[i],
            pos: Vec3(pos[i]),
            vel: Vec3(vel[i]),
        })
        .unwrap();
    }
    sim.move_to_center_of_mass().unwrap();
    sim
}

/// Figure-eight choreography of Chenciner & Montgomery (2000), initial conditions from
/// their paper (after Simó), `G = m = 1`; period ≈ 6.32591398.
pub fn figure_eight() -> Simulation {
    let mut sim = Simulation::new(Units::GEqualsOne);
    let r1 = Vec3::new(0.97000436, -0.24308753, 0.0);
    let v3 = Vec3::new(-0.93240737, -0.86473146, 0.0);
    for (r, v) in [(r1, -0.5 * v3), (-r1, -0.5 * v3), (Vec3::ZERO, v3)] {
        sim.add(Particle {
            mass: 1.0,
            pos: r,
            vel: v,
        })
        .unwrap();
    }
    sim
}

pub const FIGURE_EIGHT_PERIOD: f64 = 6.32591398;
