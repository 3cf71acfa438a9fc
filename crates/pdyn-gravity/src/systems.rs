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

/// Period of [`figure_eight`] (Chenciner & Montgomery 2000), 8 digits as published.
pub const FIGURE_EIGHT_PERIOD: f64 = 6.32591398;

/// The figure-eight choreography of three equal masses, `G = m = 1`: Chenciner &
/// Montgomery (2000), Ann. Math. 152, 881, initial conditions after Simó, 8 digits. After
/// [`FIGURE_EIGHT_PERIOD`] the state returns only to 3.6e-8 (relative), the limit of those
/// digits; [`figure_eight_precise`] is the same orbit to 15 digits.
pub fn figure_eight() -> Simulation {
    let r1 = Vec3::new(0.97000436, -0.24308753, 0.0);
    let v3 = Vec3::new(-0.93240737, -0.86473146, 0.0);
    three_equal_masses([r1, -r1, Vec3::ZERO], [-0.5 * v3, -0.5 * v3, v3])
}

/// Period of [`figure_eight_precise`]: Li & Liao (2017) give 6.3259139829; the further
/// digits are from the shooting described at [`figure_eight_precise`].
pub const FIGURE_EIGHT_PRECISE_PERIOD: f64 = 6.32591398292621;

/// The figure-eight to 15 digits, `G = m = 1`, started at an Euler configuration (bodies at
/// (−1, 0), (1, 0) and the origin; `v₁ = v₂ = (p₁, p₂)`, `v₃ = −2 v₁`): the same orbit as
/// [`figure_eight`] up to a rotation and time reversal, same energy and scale.
///
/// Source: Li & Liao (2017), *More than six hundred new families of Newtonian periodic
/// planar collisionless three-body orbits*, Sci. China Phys. Mech. Astron. 60, 129511
/// (arXiv:1705.00527), in this parametrisation to 10 digits: `p₁ = 0.3471168881`,
/// `p₂ = 0.5327249454`, `T = 6.3259139829`, which return to 1.8e-11 (relative) after one
/// period. No source we could read gives more digits, so they were refined here by
/// Gauss–Newton shooting on the period map `(p₁, p₂, T) ↦ state(T) − state(0)` (least
/// squares over the state's components, Jacobian by central differences, IAS15 at
/// ε = 1e-9 … 1e-12): one iteration takes the residual from 3.7e-11 (absolute) to the
/// integrator's floor, 4e-16 … 2.4e-14, and further iterations wander within ±1.5e-15 in
/// `p` and ±1.5e-14 in `T`: the digits kept below. The shooting confirms the 10 published
/// digits (it rounds to them) and is repeated by `tests/figure_eight.rs`. Values to 18
/// digits circulating in public code (0.347116888118926938, 0.532724945388030229,
/// 6.32591398292621168) agree within those bounds.
pub fn figure_eight_precise() -> Simulation {
    figure_eight_euler(0.347116888118927, 0.532724945388030)
}

/// The figure-eight family's isosceles collinear start: bodies at (−1, 0), (1, 0), the
/// origin, velocities `(p₁, p₂)`, `(p₁, p₂)`, `−2 (p₁, p₂)` (zero momentum and angular
/// momentum for any `p`); used to refine [`figure_eight_precise`].
pub fn figure_eight_euler(p1: f64, p2: f64) -> Simulation {
    let v = Vec3::new(p1, p2, 0.0);
    let x = Vec3::new(1.0, 0.0, 0.0);
    three_equal_masses([-x, x, Vec3::ZERO], [v, v, -2.0 * v])
}

fn three_equal_masses(pos: [Vec3; 3], vel: [Vec3; 3]) -> Simulation {
    let mut sim = Simulation::new(Units::GEqualsOne);
    for (r, v) in pos.into_iter().zip(vel) {
        sim.add(Particle {
            mass: 1.0,
            pos: r,
            vel: v,
        })
        .expect("published initial conditions are valid");
    }
    sim
}
