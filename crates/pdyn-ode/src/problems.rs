//! Reference problems with published data (Hairer–Nørsett–Wanner, *Solving Ordinary
//! Differential Equations* I and II, and the Bari test set; see each item): the test suite
//! checks pdyn-ode against them, the benchmarks time them, and users can try a method on
//! them. Each problem is a function returning an [`OdeSystem`], with its initial state,
//! time span and reference values as constants.
#![allow(clippy::excessive_precision)]

use crate::{FnSystem, FnSystemWithJacobian, OdeSystem};

/// Arenstorf orbit (HNW I, §II.0): state (y1, y2, y1', y2').
pub const AREN_MU: f64 = 0.012277471;
/// Initial state.
pub const AREN_Y0: [f64; 4] = [0.994, 0.0, 0.0, -2.00158510637908252240537862224];
/// Period.
pub const AREN_T: f64 = 17.0652165601579625588917206249;
/// DOPRI5 end state at rtol = atol = 1e-7, h0 = 1e-4 (dopri5.f).
pub const AREN_DOPRI5_YT: [f64; 4] = [
    0.9940021704037415,
    9.040893396741956e-6,
    1.4597586885445324e-3,
    -2.0012455157289244,
];

/// The Arenstorf right-hand side, `f = y'(y)`, for codes that take a plain function.
pub fn arenstorf_rhs(y: &[f64], f: &mut [f64]) {
    let mu = AREN_MU;
    let mup = 1.0 - mu;
    let d1 = libm::pow((y[0] + mu).powi(2) + y[1] * y[1], 1.5);
    let d2 = libm::pow((y[0] - mup).powi(2) + y[1] * y[1], 1.5);
    f[0] = y[2];
    f[1] = y[3];
    f[2] = y[0] + 2.0 * y[3] - mup * (y[0] + mu) / d1 - mu * (y[0] - mup) / d2;
    f[3] = y[1] - 2.0 * y[2] - mup * y[1] / d1 - mu * y[1] / d2;
}

/// The Arenstorf orbit as an [`OdeSystem`].
pub fn arenstorf() -> impl OdeSystem {
    FnSystem::new(4, |_t, y: &[f64], f: &mut [f64]| arenstorf_rhs(y, f))
}

/// Van der Pol, scaled form y1' = y2, y2' = ((1 − y1²) y2 − y1)/ε, with Jacobian.
pub fn van_der_pol(eps: f64) -> impl OdeSystem {
    FnSystemWithJacobian::new(
        2,
        move |_t, y: &[f64], f: &mut [f64]| {
            f[0] = y[1];
            f[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / eps;
        },
        move |_t, y: &[f64], j: &mut [f64]| {
            j[0] = 0.0;
            j[1] = 1.0;
            j[2] = (-2.0 * y[0] * y[1] - 1.0) / eps;
            j[3] = (1.0 - y[0] * y[0]) / eps;
        },
    )
}
/// Non-stiff VdP (ε = 1e-3) end state, DOP853 at tol 1e-9 (dop853.f).
pub const VDP_NONSTIFF_Y2: [f64; 2] = [1.763234540172087, -0.8356886819301910];
/// Stiff VdP (ε = 1e-6) reference y(2) (Bari test set, RADAU5 at tol 1.1e-18).
pub const VDP_STIFF_Y2: [f64; 2] = [1.706167732170483, -0.8928097010247975];

/// Robertson chemical kinetics, with Jacobian.
pub fn robertson() -> impl OdeSystem {
    FnSystemWithJacobian::new(
        3,
        |_t, y: &[f64], f: &mut [f64]| {
            f[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
            f[2] = 3e7 * y[1] * y[1];
            f[1] = -f[0] - f[2];
        },
        |_t, y: &[f64], j: &mut [f64]| {
            j[0] = -0.04;
            j[1] = 1e4 * y[2];
            j[2] = 1e4 * y[1];
            j[6] = 0.0;
            j[7] = 6e7 * y[1];
            j[8] = 0.0;
            j[3] = 0.04;
            j[4] = -1e4 * y[2] - 6e7 * y[1];
            j[5] = -1e4 * y[1];
        },
    )
}
/// RADAU5 at t = 0.3 (atol 1e-8, rtol 1e-2, h0 1e-6).
pub const ROBER_Y03: [f64; 3] = [
    0.9886740138499884,
    3.447720471782070e-5,
    1.129150894529390e-2,
];
/// Bari reference at t = 1e11.
pub const ROBER_Y1E11: [f64; 3] = [
    0.2083340149701255e-7,
    0.8333360770334713e-13,
    0.9999999791665050,
];

/// The Pleiades right-hand side (7 bodies, G = 1, m_j = j; state x1..7, y1..7, x'1..7,
/// y'1..7), for codes that take a plain function.
pub fn pleiades_rhs(s: &[f64], f: &mut [f64]) {
    let (x, rest) = s.split_at(7);
    let (y, v) = rest.split_at(7);
    f[..14].copy_from_slice(v);
    for i in 0..7 {
        let (mut ax, mut ay) = (0.0, 0.0);
        for j in 0..7 {
            if i != j {
                let dx = x[j] - x[i];
                let dy = y[j] - y[i];
                let r2 = dx * dx + dy * dy;
                let r3 = r2 * r2.sqrt();
                ax += (j + 1) as f64 * dx / r3;
                ay += (j + 1) as f64 * dy / r3;
            }
        }
        f[14 + i] = ax;
        f[21 + i] = ay;
    }
}

/// Pleiades (HNW I, §II.10) as an [`OdeSystem`].
pub fn pleiades() -> impl OdeSystem {
    FnSystem::new(28, |_t, s: &[f64], f: &mut [f64]| pleiades_rhs(s, f))
}

/// Pleiades initial state at t = 0.
pub const PLEI_Y0: [f64; 28] = [
    3.0, 3.0, -1.0, -3.0, 2.0, -2.0, 2.0, //
    3.0, -3.0, 2.0, 0.0, 0.0, -4.0, 4.0, //
    0.0, 0.0, 0.0, 0.0, 0.0, 1.75, -1.5, //
    0.0, 0.0, 0.0, -1.25, 1.0, 0.0, 0.0,
];
/// Pleiades reference state at t = 3 (HNW I, §II.10).
pub const PLEI_Y3: [f64; 28] = [
    0.3706139143970502,
    3.237284092057233,
    -3.222559032418324,
    0.6597091455775310,
    0.3425581707156584,
    1.562172101400631,
    -0.7003092922212495, //
    -3.943437585517392,
    -3.271380973972550,
    5.225081843456543,
    -2.590612434977470,
    1.198213693392275,
    -0.2429682344935824,
    1.091449240428980, //
    3.417003806314313,
    1.354584501625501,
    -2.590065597810775,
    2.025053734714242,
    -1.155815100160448,
    -0.8072988170223021,
    0.5952396354208710, //
    -3.741244961234010,
    0.3773459685750630,
    0.9386858869551073,
    0.3667922227200571,
    -0.3474046353808490,
    2.344915448180937,
    -1.947020434263292,
];

/// Brusselator (ODE form).
pub fn brusselator() -> impl OdeSystem {
    FnSystem::new(2, |_t, y: &[f64], f: &mut [f64]| {
        f[0] = 1.0 - 4.0 * y[0] + y[0] * y[0] * y[1];
        f[1] = 3.0 * y[0] - y[0] * y[0] * y[1];
    })
}
/// Brusselator reference state at t = 20 from y(0) = (1.5, 3).
pub const BRUSS_Y20: [f64; 2] = [0.4986370712683478291, 4.596780349452011025];
