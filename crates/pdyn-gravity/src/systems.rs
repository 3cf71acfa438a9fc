//! Published initial conditions, ready to integrate (tests, examples and benchmarks use them).

use pdyn_particles::{Particle, Vec3};

use crate::{Simulation, Units};

/// Outer Solar System (Sun carrying the inner planets' mass, Jupiter, Saturn, Uranus,
/// Neptune) in AU, days and solar masses, `G = k²` (Gauss's constant): the epoch state of
/// Applegate et al. (1986), AJ 92, 176, as used by REBOUND's
/// `examples/outer_solar_system/problem.c` (Pluto omitted). Moved to the centre-of-mass
/// frame.
pub fn outer_solar_system() -> Simulation {
    const POS: [[f64; 3]; 5] = [
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
    const VEL: [[f64; 3]; 5] = [
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
    const MASS: [f64; 5] = [
        1.00000597682,
        1.0 / 1047.355,
        1.0 / 3501.6,
        1.0 / 22869.0,
        1.0 / 19314.0,
    ];
    let mut sim = Simulation::new(Units::AuDaySolarMass);
    for i in 0..5 {
        sim.add(Particle {
            mass: MASS[i],
            pos: Vec3(POS[i]),
            vel: Vec3(VEL[i]),
        })
        .expect("published initial conditions are valid");
    }
    sim.move_to_center_of_mass()
        .expect("no integrator state yet");
    sim
}

/// Period of [`figure_eight`] (Chenciner & Montgomery 2000).
pub const FIGURE_EIGHT_PERIOD: f64 = 6.32591398;

/// The figure-eight choreography of three equal masses, `G = m = 1`: Chenciner &
/// Montgomery (2000), Ann. Math. 152, 881, initial conditions after Simó, 8 digits.
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
        .expect("published initial conditions are valid");
    }
    sim
}
