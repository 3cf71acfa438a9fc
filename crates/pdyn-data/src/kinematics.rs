//! Kinematics from sampled positions: each coordinate is smoothed by a cubic smoothing spline
//! ([`crate::spline`], λ by GCV unless given), whose first and second derivatives at the
//! sample times are the velocity and acceleration. From them, as in the chapter's section 3.1:
//! speed `|v|`, unit tangent `T = v/|v|`, tangential acceleration `a_t = a·T`, normal
//! acceleration `a_n = |a − a_t T|` (≥ 0) and principal normal `N = (a − a_t T)/a_n`,
//! curvature `κ = a_n/|v|²`, and polar (cylindrical) components in the x–y plane: `r`, `θ`
//! (continuous, unwrapped), `v_r`, `v_θ`, `a_r`, `a_θ`.
//!
//! **Uncertainty.** Every coordinate gets interior standard errors of its value, velocity and
//! acceleration ([`crate::spline::standard_errors`]); the errors of the coordinates are
//! independent, and at one instant the spline's velocity and acceleration errors are
//! uncorrelated (the equivalent kernel's first and second derivatives are odd and even), so
//! the standard errors of speed, a_t, a_n and curvature follow by first-order propagation:
//! `se(|v|)² = Σ T_i² se(v_i)²`, `se(a_t)² = Σ T_i² se(a_i)² + Σ (a_n N_i/|v|)² se(v_i)²`,
//! `se(a_n)² = Σ N_i² se(a_i)² + Σ (a_t N_i/|v|)² se(v_i)²`,
//! `se(κ)² = Σ (N_i/|v|²)² se(a_i)² + Σ ((a_t N_i + 2 a_n T_i)/|v|³)² se(v_i)²`.
//! They hold away from the ends: within [`KinData::boundary`] of the first or last sample the
//! natural end condition (`f'' = 0`) biases the fit.

use crate::csv::Series;
use crate::error::DataError;
use crate::spline::{fit, Smoothing, SmoothingSpline};

/// The smoothing of one coordinate.
#[derive(Clone, Debug)]
pub struct ComponentFit {
    /// The column's name.
    pub name: String,
    /// The smoothing parameter λ.
    pub lambda: f64,
    /// Whether λ came from GCV.
    pub from_gcv: bool,
    /// The residual standard deviation (the estimated measurement noise).
    pub sigma: f64,
    /// Effective degrees of freedom of the fit.
    pub edf: f64,
    /// Standard errors of the position, velocity and acceleration component (interior).
    pub se: [f64; 3],
    /// Within this time of either end this coordinate's end bias may exceed its standard
    /// errors: four decay lengths `√2 (λ h)^{1/4}` of the smoothing kernel. A coordinate
    /// fitted as (nearly) a straight line has a huge λ and a boundary spanning the record;
    /// its errors are then a line fit's, small beside a curved coordinate's.
    pub boundary: f64,
}

/// Kinematics at every sample time.
#[derive(Clone, Debug, Default)]
pub struct KinData {
    /// Sample times.
    pub t: Vec<f64>,
    /// Smoothed position, one vector per coordinate (2 or 3).
    pub position: Vec<Vec<f64>>,
    /// Velocity components.
    pub velocity: Vec<Vec<f64>>,
    /// Acceleration components.
    pub acceleration: Vec<Vec<f64>>,
    /// Speed |v|.
    pub speed: Vec<f64>,
    /// Unit tangent components (zero where the speed is zero).
    pub tangent: Vec<Vec<f64>>,
    /// Principal normal components (zero where a_n is zero).
    pub normal: Vec<Vec<f64>>,
    /// Curvature a_n/|v|².
    pub curvature: Vec<f64>,
    /// Tangential acceleration.
    pub a_t: Vec<f64>,
    /// Normal acceleration (≥ 0).
    pub a_n: Vec<f64>,
    /// Polar radius in the x–y plane.
    pub r: Vec<f64>,
    /// Polar angle, unwrapped to be continuous.
    pub theta: Vec<f64>,
    /// Radial velocity.
    pub v_r: Vec<f64>,
    /// Transverse velocity r θ'.
    pub v_theta: Vec<f64>,
    /// Radial acceleration r'' − r θ'².
    pub a_r: Vec<f64>,
    /// Transverse acceleration r θ'' + 2 r' θ'.
    pub a_theta: Vec<f64>,
    /// Standard error of the speed.
    pub se_speed: Vec<f64>,
    /// Standard error of a_t.
    pub se_a_t: Vec<f64>,
    /// Standard error of a_n.
    pub se_a_n: Vec<f64>,
    /// Standard error of the curvature.
    pub se_curvature: Vec<f64>,
    /// The fit of each coordinate.
    pub fits: Vec<ComponentFit>,
    /// Within this time of either end the standard errors do not hold (end bias): four decay
    /// lengths `√2 (λ h)^{1/4}` of the smoothing kernel, the largest over the coordinates.
    pub boundary: f64,
}

/// Which of the derived columns [`kinematics_with`] computes. Speed, a_t and a_n are always
/// computed; a table that shows only some of the others spares their memory (8 bytes per
/// sample each) and time. Columns not wanted are left empty in [`KinData`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Wanted {
    /// The unit tangent and principal normal (`tangent`, `normal`).
    pub frame: bool,
    /// The curvature `a_n/|v|²`.
    pub curvature: bool,
    /// The standard errors (`se_speed`, `se_a_t`, `se_a_n`, `se_curvature`).
    pub se: bool,
    /// The polar components (`r`, `theta`, `v_r`, `v_theta`, `a_r`, `a_theta`).
    pub polar: bool,
}

impl Wanted {
    /// Every column.
    pub const ALL: Wanted = Wanted {
        frame: true,
        curvature: true,
        se: true,
        polar: true,
    };
}

/// Kinematics of the positions in `series` (2 or 3 value columns: x, y[, z]).
pub fn kinematics(series: &Series, smoothing: Smoothing) -> Result<KinData, DataError> {
    kinematics_with(series, smoothing, Wanted::ALL)
}

/// [`kinematics`], computing only the derived columns `wanted` (the others are left empty):
/// `pdyn kin --data --quantities speed,a_t` spares the frame, curvature, error and polar
/// columns, their memory and the polar components' two transcendental calls per sample.
pub fn kinematics_with(
    series: &Series,
    smoothing: Smoothing,
    wanted: Wanted,
) -> Result<KinData, DataError> {
    let dim = series.values.len();
    if !(2..=3).contains(&dim) {
        return Err(DataError::new(
            "",
            format!("kinematics needs 2 or 3 position columns (x, y[, z]); {dim} given"),
        )
        .help("choose the columns with --columns t,x,y[,z]"));
    }
    let t = &series.t;
    // The coordinates are independent fits: one thread each.
    let columns: Vec<(&Vec<f64>, &String)> = series.values.iter().zip(&series.names).collect();
    let fits = crate::parallel::map(&columns, "smoothing", |&(y, name)| {
        fit(t, y, smoothing, name)
    });
    let fits: Vec<SmoothingSpline> = fits.into_iter().collect::<Result<_, _>>()?;
    let mut k = KinData {
        t: t.clone(),
        ..KinData::default()
    };
    k.boundary = fits
        .iter()
        .map(|f| 4.0 * std::f64::consts::SQRT_2 * libm::pow(f.lambda * f.h, 0.25))
        .fold(0.0, f64::max);
    k.fits = fits
        .iter()
        .zip(&series.names)
        .map(|(f, name)| ComponentFit {
            name: name.clone(),
            lambda: f.lambda,
            from_gcv: f.from_gcv,
            sigma: f.sigma2.sqrt(),
            edf: f.edf,
            se: f.se,
            boundary: 4.0 * std::f64::consts::SQRT_2 * libm::pow(f.lambda * f.h, 0.25),
        })
        .collect();
    let se_v: Vec<f64> = fits.iter().map(|f| f.se[1]).collect();
    let se_a: Vec<f64> = fits.iter().map(|f| f.se[2]).collect();
    let mut fits = fits;
    for f in fits.iter_mut() {
        k.position.push(std::mem::take(&mut f.value));
        k.velocity.push(std::mem::take(&mut f.d1));
        k.acceleration.push(std::mem::take(&mut f.d2));
    }
    // The Frenet quantities are independent from sample to sample: two halves on two
    // threads, with the polar components (a recurrence: θ is unwrapped from the sample
    // before) on a third when they are wanted.
    let KinData {
        position,
        velocity,
        acceleration,
        ..
    } = &k;
    let n = series.t.len();
    let mut frenet = Frenet::zeros(n, velocity.len(), wanted);
    let polar = std::thread::scope(|s| {
        let polar = wanted
            .polar
            .then(|| s.spawn(|| polar_columns(position, velocity, acceleration)));
        let (se_v, se_a) = (&se_v[..], &se_a[..]);
        let (first, second) = frenet.split_at_mut(n / 2);
        let other = s.spawn(move || first.fill(velocity, acceleration, se_v, se_a, 0));
        second.fill(velocity, acceleration, se_v, se_a, n / 2);
        let joined = other.join();
        (polar.map(|p| p.join()), joined)
    });
    let polar = match polar {
        (polar, Ok(())) => polar.transpose(),
        (_, Err(e)) => Err(e),
    }
    .map_err(|_| DataError::new("", "internal error: a thread of the kinematics panicked"))?;
    (k.speed, k.tangent, k.a_t, k.a_n, k.normal, k.curvature) = (
        frenet.speed,
        frenet.tangent,
        frenet.a_t,
        frenet.a_n,
        frenet.normal,
        frenet.curvature,
    );
    (k.se_speed, k.se_a_t, k.se_a_n, k.se_curvature) = (
        frenet.se_speed,
        frenet.se_a_t,
        frenet.se_a_n,
        frenet.se_curvature,
    );
    if let Some(p) = polar {
        [k.r, k.theta, k.v_r, k.v_theta, k.a_r, k.a_theta] = p;
    }
    Ok(k)
}

/// Speed, tangent, a_t, a_n, normal, curvature and their standard errors at every sample
/// (the columns not [`Wanted`] empty).
struct Frenet {
    speed: Vec<f64>,
    tangent: Vec<Vec<f64>>,
    a_t: Vec<f64>,
    a_n: Vec<f64>,
    normal: Vec<Vec<f64>>,
    curvature: Vec<f64>,
    se_speed: Vec<f64>,
    se_a_t: Vec<f64>,
    se_a_n: Vec<f64>,
    se_curvature: Vec<f64>,
}

/// The rows of a [`Frenet`] from some sample on, to be filled (an empty column stays empty).
struct FrenetRows<'a> {
    speed: &'a mut [f64],
    tangent: Vec<&'a mut [f64]>,
    a_t: &'a mut [f64],
    a_n: &'a mut [f64],
    normal: Vec<&'a mut [f64]>,
    curvature: &'a mut [f64],
    se_speed: &'a mut [f64],
    se_a_t: &'a mut [f64],
    se_a_n: &'a mut [f64],
    se_curvature: &'a mut [f64],
}

impl Frenet {
    /// Zeroed columns of `n` samples in `dim` dimensions, empty where not `wanted`.
    fn zeros(n: usize, dim: usize, wanted: Wanted) -> Frenet {
        let col = |on: bool| if on { vec![0.0; n] } else { Vec::new() };
        let cols = |on: bool| {
            if on {
                vec![vec![0.0; n]; dim]
            } else {
                Vec::new()
            }
        };
        Frenet {
            speed: col(true),
            tangent: cols(wanted.frame),
            a_t: col(true),
            a_n: col(true),
            normal: cols(wanted.frame),
            curvature: col(wanted.curvature),
            se_speed: col(wanted.se),
            se_a_t: col(wanted.se),
            se_a_n: col(wanted.se),
            se_curvature: col(wanted.se),
        }
    }

    /// The rows before sample `at` and those from it on.
    fn split_at_mut(&mut self, at: usize) -> (FrenetRows<'_>, FrenetRows<'_>) {
        fn split(c: &mut [f64], at: usize) -> (&mut [f64], &mut [f64]) {
            c.split_at_mut(at.min(c.len()))
        }
        fn splits(cs: &mut [Vec<f64>], at: usize) -> (Vec<&mut [f64]>, Vec<&mut [f64]>) {
            cs.iter_mut().map(|c| split(c, at)).unzip()
        }
        let (speed0, speed1) = split(&mut self.speed, at);
        let (tangent0, tangent1) = splits(&mut self.tangent, at);
        let (a_t0, a_t1) = split(&mut self.a_t, at);
        let (a_n0, a_n1) = split(&mut self.a_n, at);
        let (normal0, normal1) = splits(&mut self.normal, at);
        let (curvature0, curvature1) = split(&mut self.curvature, at);
        let (se_speed0, se_speed1) = split(&mut self.se_speed, at);
        let (se_a_t0, se_a_t1) = split(&mut self.se_a_t, at);
        let (se_a_n0, se_a_n1) = split(&mut self.se_a_n, at);
        let (se_curvature0, se_curvature1) = split(&mut self.se_curvature, at);
        (
            FrenetRows {
                speed: speed0,
                tangent: tangent0,
                a_t: a_t0,
                a_n: a_n0,
                normal: normal0,
                curvature: curvature0,
                se_speed: se_speed0,
                se_a_t: se_a_t0,
                se_a_n: se_a_n0,
                se_curvature: se_curvature0,
            },
            FrenetRows {
                speed: speed1,
                tangent: tangent1,
                a_t: a_t1,
                a_n: a_n1,
                normal: normal1,
                curvature: curvature1,
                se_speed: se_speed1,
                se_a_t: se_a_t1,
                se_a_n: se_a_n1,
                se_curvature: se_curvature1,
            },
        )
    }
}

impl FrenetRows<'_> {
    /// Fills the rows from the velocity and acceleration columns (2 or 3; these rows are
    /// samples `first..`) and each coordinate's standard errors of velocity and acceleration
    /// (module documentation).
    fn fill(
        self,
        velocity: &[Vec<f64>],
        acceleration: &[Vec<f64>],
        se_v: &[f64],
        se_a: &[f64],
        first: usize,
    ) {
        let dim = velocity.len();
        let (frame, curvature, se) = (
            !self.tangent.is_empty(),
            !self.curvature.is_empty(),
            !self.se_speed.is_empty(),
        );
        let FrenetRows {
            speed,
            mut tangent,
            a_t,
            a_n,
            mut normal,
            curvature: curvature_col,
            se_speed,
            se_a_t,
            se_a_n,
            se_curvature,
        } = self;
        for r in 0..speed.len() {
            let i = first + r;
            // Fixed-size vectors (a third component of 0 in the plane): no allocation per
            // sample.
            let mut v = [0.0; 3];
            let mut a = [0.0; 3];
            for c in 0..dim {
                v[c] = velocity[c][i];
                a[c] = acceleration[c][i];
            }
            let s = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let tan = if s > 0.0 { v.map(|x| x / s) } else { [0.0; 3] };
            let at = a[0] * tan[0] + a[1] * tan[1] + a[2] * tan[2];
            let perp = [a[0] - at * tan[0], a[1] - at * tan[1], a[2] - at * tan[2]];
            let an = (perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]).sqrt();
            let nor = if an > 0.0 {
                perp.map(|x| x / an)
            } else {
                [0.0; 3]
            };
            speed[r] = s;
            a_t[r] = at;
            a_n[r] = an;
            if curvature {
                curvature_col[r] = if s > 0.0 { an / (s * s) } else { f64::INFINITY };
            }
            if frame {
                for c in 0..dim {
                    tangent[c][r] = tan[c];
                    normal[c][r] = nor[c];
                }
            }
            if se {
                let (mut vs, mut vat, mut van, mut vk) = (0.0, 0.0, 0.0, 0.0);
                for c in 0..dim {
                    let (sv, sa) = (se_v[c] * se_v[c], se_a[c] * se_a[c]);
                    vs += tan[c] * tan[c] * sv;
                    if s > 0.0 {
                        vat += tan[c] * tan[c] * sa + (an * nor[c] / s).powi(2) * sv;
                        van += nor[c] * nor[c] * sa + (at * nor[c] / s).powi(2) * sv;
                        vk += (nor[c] / (s * s)).powi(2) * sa
                            + ((at * nor[c] + 2.0 * an * tan[c]) / (s * s * s)).powi(2) * sv;
                    }
                }
                se_speed[r] = vs.sqrt();
                se_a_t[r] = if s > 0.0 { vat.sqrt() } else { f64::INFINITY };
                se_a_n[r] = if s > 0.0 { van.sqrt() } else { f64::INFINITY };
                se_curvature[r] = if s > 0.0 { vk.sqrt() } else { f64::INFINITY };
            }
        }
    }
}

/// Polar components in the x–y plane: `[r, θ, v_r, v_θ, a_r, a_θ]`, θ continuous (unwrapped).
fn polar_columns(
    position: &[Vec<f64>],
    velocity: &[Vec<f64>],
    acceleration: &[Vec<f64>],
) -> [Vec<f64>; 6] {
    let n = position[0].len();
    let mut out: [Vec<f64>; 6] = std::array::from_fn(|_| vec![0.0; n]);
    let [r_col, theta, v_r, v_theta, a_r, a_theta] = &mut out;
    let mut prev_theta = f64::NAN;
    for i in 0..n {
        let (x, y) = (position[0][i], position[1][i]);
        let (v, a) = (
            [velocity[0][i], velocity[1][i]],
            [acceleration[0][i], acceleration[1][i]],
        );
        let r = libm::hypot(x, y);
        let mut th = libm::atan2(y, x);
        if prev_theta.is_finite() {
            // Unwrap: the branch nearest the previous sample's angle.
            let tau = std::f64::consts::TAU;
            th += tau * ((prev_theta - th) / tau).round();
        }
        prev_theta = th;
        r_col[i] = r;
        theta[i] = th;
        if r > 0.0 {
            let (c, sn) = (x / r, y / r);
            v_r[i] = c * v[0] + sn * v[1];
            v_theta[i] = c * v[1] - sn * v[0];
            a_r[i] = c * a[0] + sn * a[1];
            a_theta[i] = c * a[1] - sn * a[0];
        }
    }
    out
}
