//! Kinematics of a particle (Bower, *Dynamics*, 3.1): from a position to velocity,
//! acceleration, normal–tangential and polar components, and radius of curvature.
//!
//! # The mathematics
//!
//! For a position `r(t)` with `v = dr/dt`, `a = dv/dt` and speed `V = |v|`:
//! - unit tangent `t = v/V`; tangential acceleration `a_t = (v·a)/V` (= dV/dt);
//! - normal acceleration `a_n = |v × a|/V` (= V²/R), curvature `κ = |v × a|/V³`, radius of
//!   curvature `R = 1/κ`;
//! - unit normal, toward the centre of curvature, `n = (a - a_t t)/a_n
//!   = (V² a - (v·a) v)/(V |v × a|)` (undefined on straight stretches, where `a_n = 0`).
//!
//! Polar components use `e_r = (cos θ, sin θ, 0)`, `e_θ = (-sin θ, cos θ, 0)`, `k`:
//! `r = r e_r + z k`, `v = r' e_r + r θ' e_θ + z' k`, `a = (r'' - r θ'²) e_r + (r θ'' + 2 r' θ') e_θ
//! + z'' k`. From Cartesian input they are the projections on `e_r = (x, y, 0)/√(x² + y²)`.
//!
//! A planar path given as `(x(p), y(p))` (or `y(x)`, with `p = x`) traversed at speed `V(t)` has,
//! with `' = d/dp` and `g = √(x'² + y'²)`: `t = (x', y')/g`, signed curvature
//! `κ_s = (x' y'' - y' x'')/g³`, `n = sign(κ_s) (-y', x')/g`, `v = V t` and
//! `a = (dV/dt) t + V² κ_s (-y', x')/g`, so `a_t = dV/dt` and `a_n = V² |κ_s|`.
//!
//! [`maximize`] finds the largest value of a quantity over a range numerically (dense sampling
//! and golden-section refinement); [`maximum`] does it for a quantity with symbolic parameters
//! (`extremum.rs`).

use pdyn_expr::vector::{cross, dot};
use pdyn_expr::{Func, Id, Node, Pool, Program};

mod error;
mod extremum;

pub use error::KinError;
pub use extremum::{maximize, maximum, Extremum, Maximum};

/// How the motion is given.
#[derive(Clone, Copy, Debug)]
pub enum Motion {
    /// Cartesian position `r(t) = [x, y, z]` (expressions in `t`, parameters, or coordinates).
    Cartesian([Id; 3]),
    /// Cylindrical-polar `(r(t), θ(t), z(t))`.
    Polar {
        /// Distance from the axis.
        r: Id,
        /// Angle from the x axis.
        theta: Id,
        /// Height.
        z: Id,
    },
    /// A planar path `(x(p), y(p))` traversed at speed `speed` (constant or a function of `t`).
    Path {
        /// `x` as a function of the parameter.
        x: Id,
        /// `y` as a function of the parameter.
        y: Id,
        /// The path parameter (a symbol leaf, e.g. `x` for a graph `y(x)`, or `s`).
        parameter: Id,
        /// The speed `V` (constant, or a function of `t`).
        speed: Id,
    },
}

/// Components in the polar basis `(e_r, e_θ, k)`.
#[derive(Clone, Copy, Debug)]
pub struct PolarComponents {
    /// `e_r` in Cartesian components.
    pub e_r: [Id; 3],
    /// `e_θ` in Cartesian components.
    pub e_theta: [Id; 3],
    /// Position: `(r, 0, z)`.
    pub position: [Id; 3],
    /// Velocity: `(v_r, v_θ, v_z)`.
    pub velocity: [Id; 3],
    /// Acceleration: `(a_r, a_θ, a_z)`.
    pub acceleration: [Id; 3],
    /// Unit tangent: `(t·e_r, t·e_θ, t·k)`.
    pub tangent: [Id; 3],
    /// Unit normal: `(n·e_r, n·e_θ, n·k)`.
    pub normal: [Id; 3],
}

/// Everything [`analyze`] derives, simplified.
#[derive(Clone, Copy, Debug)]
pub struct Kinematics {
    /// The independent variable: `t`, or the path parameter for [`Motion::Path`].
    pub variable: Id,
    /// Position (Cartesian components).
    pub position: [Id; 3],
    /// Velocity.
    pub velocity: [Id; 3],
    /// Acceleration.
    pub acceleration: [Id; 3],
    /// Speed `V = |v|`.
    pub speed: Id,
    /// Unit tangent.
    pub tangent: [Id; 3],
    /// Unit normal toward the centre of curvature.
    pub normal: [Id; 3],
    /// Curvature `κ ≥ 0`.
    pub curvature: Id,
    /// Radius of curvature `R = 1/κ`.
    pub radius: Id,
    /// Tangential acceleration `a_t = dV/dt`.
    pub a_t: Id,
    /// Normal acceleration `a_n = V²/R`.
    pub a_n: Id,
    /// Polar components.
    pub polar: PolarComponents,
    /// True on a straight line (`v × a ≡ 0`, curvature 0): the normal is undefined (given as
    /// the zero vector) and the radius of curvature infinite.
    pub straight: bool,
}

impl Kinematics {
    /// Every quantity by name, vectors as three components: the names `pdyn kin` prints and
    /// that [`maximize`] and instants refer to.
    pub fn named(&self) -> Vec<(&'static str, Quantity)> {
        use Quantity::{Scalar as S, Vector as V};
        vec![
            ("r", V(self.position)),
            ("v", V(self.velocity)),
            ("a", V(self.acceleration)),
            ("speed", S(self.speed)),
            ("tangent", V(self.tangent)),
            ("normal", V(self.normal)),
            ("curvature", S(self.curvature)),
            ("radius", S(self.radius)),
            ("a_t", S(self.a_t)),
            ("a_n", S(self.a_n)),
            ("e_r", V(self.polar.e_r)),
            ("e_theta", V(self.polar.e_theta)),
            ("r_polar", V(self.polar.position)),
            ("v_polar", V(self.polar.velocity)),
            ("a_polar", V(self.polar.acceleration)),
            ("tangent_polar", V(self.polar.tangent)),
            ("normal_polar", V(self.polar.normal)),
        ]
    }
}

/// A scalar or vector quantity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// A scalar.
    Scalar(Id),
    /// A vector (Cartesian or polar components, as named).
    Vector([Id; 3]),
}

/// The unit vector `(x, y, 0)/n` in the plane and its left perpendicular `(-y, x, 0)/n`
/// (`n = |(x, y)|`): a path's tangent and normal side, or polar `e_r` and `e_θ`.
fn planar_frame(pool: &mut Pool, x: Id, y: Id, n: Id) -> ([Id; 3], [Id; 3]) {
    let (a, b) = (pool.div(x, n), pool.div(y, n));
    let unit = simp3(pool, [a, b, Pool::ZERO]);
    let ny = pool.neg(y);
    let (c, d) = (pool.div(ny, n), pool.div(x, n));
    let left = simp3(pool, [c, d, Pool::ZERO]);
    (unit, left)
}

fn simp3(pool: &mut Pool, v: [Id; 3]) -> [Id; 3] {
    v.map(|c| {
        let e = pool.expand(c);
        pool.simplify(e)
    })
}

fn simp(pool: &mut Pool, e: Id) -> Id {
    let x = pool.expand(e);
    let a = pool.simplify(x);
    let b = pool.simplify(e);
    if pool.tree_size(b, usize::MAX) < pool.tree_size(a, usize::MAX) {
        b
    } else {
        a
    }
}

/// Derives the kinematic quantities of `motion`.
pub fn analyze(pool: &mut Pool, motion: Motion) -> Result<Kinematics, KinError> {
    let mut k = analyze_motion(pool, motion)?;
    // Basis conversion (i, j, k) -> (e_r, e_θ, k) of the unit vectors.
    let comps = |pool: &mut Pool, w: [Id; 3], e_r: [Id; 3], e_t: [Id; 3]| -> [Id; 3] {
        let c_r = dot(pool, w, e_r);
        let c_t = dot(pool, w, e_t);
        simp3(pool, [c_r, c_t, w[2]])
    };
    k.polar.tangent = comps(pool, k.tangent, k.polar.e_r, k.polar.e_theta);
    k.polar.normal = comps(pool, k.normal, k.polar.e_r, k.polar.e_theta);
    Ok(k)
}

fn analyze_motion(pool: &mut Pool, motion: Motion) -> Result<Kinematics, KinError> {
    match motion {
        Motion::Cartesian(r) => {
            let t = pool.time();
            for c in r {
                if pool.any_node(c, &|n| matches!(n, Node::Coord(_, k) if *k > 0)) {
                    return Err(KinError::RatesInPosition);
                }
            }
            let v = r.map(|c| pool.dt(c));
            let v = simp3(pool, v);
            let a = v.map(|c| pool.dt(c));
            let a = simp3(pool, a);
            let rho2 = {
                let x2 = pool.powi(r[0], 2);
                let y2 = pool.powi(r[1], 2);
                let s = pool.add2(x2, y2);
                simp(pool, s)
            };
            let rho = pool.sqrt(rho2);
            let e_r = {
                let ex = pool.div(r[0], rho);
                let ey = pool.div(r[1], rho);
                simp3(pool, [ex, ey, Pool::ZERO])
            };
            let e_theta = {
                let ny = pool.neg(r[1]);
                let ex = pool.div(ny, rho);
                let ey = pool.div(r[0], rho);
                simp3(pool, [ex, ey, Pool::ZERO])
            };
            let polar = project(pool, r, v, a, e_r, e_theta);
            nt(pool, t, r, v, a, polar)
        }
        Motion::Polar { r, theta, z } => {
            let t = pool.time();
            let (ct, st) = (
                pool.call(Func::Cos, &[theta]),
                pool.call(Func::Sin, &[theta]),
            );
            let e_r = [ct, st, Pool::ZERO];
            let nst = pool.neg(st);
            let e_theta = [nst, ct, Pool::ZERO];
            let pos = {
                let x = pool.mul2(r, ct);
                let y = pool.mul2(r, st);
                [x, y, z]
            };
            let v = pos.map(|c| pool.dt(c));
            let v = simp3(pool, v);
            let a = v.map(|c| pool.dt(c));
            let a = simp3(pool, a);
            let (r1, r2) = (pool.dt(r), pool.dt_n(r, 2));
            let (th1, th2) = (pool.dt(theta), pool.dt_n(theta, 2));
            let (z1, z2) = (pool.dt(z), pool.dt_n(z, 2));
            let v_theta = pool.mul2(r, th1);
            let th1sq = pool.powi(th1, 2);
            let rth = pool.mul2(r, th1sq);
            let a_r = pool.sub(r2, rth);
            let two = pool.int(2);
            let cor = pool.mul(&[two, r1, th1]);
            let rth2 = pool.mul2(r, th2);
            let a_theta = pool.add2(rth2, cor);
            let polar = PolarComponents {
                e_r,
                e_theta,
                position: simp3(pool, [r, Pool::ZERO, z]),
                velocity: simp3(pool, [r1, v_theta, z1]),
                acceleration: simp3(pool, [a_r, a_theta, z2]),
                tangent: [Pool::ZERO; 3],
                normal: [Pool::ZERO; 3],
            };
            nt(pool, t, pos, v, a, polar)
        }
        Motion::Path {
            x,
            y,
            parameter,
            speed,
        } => {
            if !matches!(pool.node(parameter), Node::Sym(_)) {
                return Err(KinError::PathParameterNotAName {
                    parameter: pool.to_text(parameter),
                });
            }
            let (x1, y1) = (pool.diff(x, parameter), pool.diff(y, parameter));
            let (x2, y2) = (pool.diff(x1, parameter), pool.diff(y1, parameter));
            let g2 = {
                let a = pool.powi(x1, 2);
                let b = pool.powi(y1, 2);
                let s = pool.add2(a, b);
                simp(pool, s)
            };
            if g2 == Pool::ZERO {
                return Err(KinError::PathDoesNotMove);
            }
            let g = pool.sqrt(g2);
            let (tangent, left) = planar_frame(pool, x1, y1, g);
            let kappa_s = {
                let p1 = pool.mul2(x1, y2);
                let p2 = pool.mul2(y1, x2);
                let num = pool.sub(p1, p2);
                let g3 = pool.powi(g, 3);
                let k = pool.div(num, g3);
                simp(pool, k)
            };
            let curvature = {
                let k = pool.call(Func::Abs, &[kappa_s]);
                simp(pool, k)
            };
            let straight = curvature == Pool::ZERO;
            let radius = if straight {
                pool.num(pdyn_expr::Number::Float(f64::INFINITY))
            } else {
                let r = pool.powi(curvature, -1);
                simp(pool, r)
            };
            let sgn = pool.call(Func::Sign, &[kappa_s]);
            let normal = left.map(|c| pool.mul2(sgn, c));
            let a_t = {
                let d = pool.dt(speed);
                simp(pool, d)
            };
            let v2 = pool.powi(speed, 2);
            let a_n = {
                let e = pool.mul2(v2, curvature);
                simp(pool, e)
            };
            let velocity = {
                let v = tangent.map(|c| pool.mul2(speed, c));
                simp3(pool, v)
            };
            let acceleration = {
                let k = pool.mul2(v2, kappa_s);
                let acc: [Id; 3] = [0, 1, 2].map(|i| {
                    let p = pool.mul2(a_t, tangent[i]);
                    let q = pool.mul2(k, left[i]);
                    pool.add2(p, q)
                });
                simp3(pool, acc)
            };
            let position = [x, y, Pool::ZERO];
            let rho2 = {
                let a = pool.powi(x, 2);
                let b = pool.powi(y, 2);
                let s = pool.add2(a, b);
                simp(pool, s)
            };
            let rho = pool.sqrt(rho2);
            let (e_r, e_theta) = planar_frame(pool, x, y, rho);
            let polar = project(pool, position, velocity, acceleration, e_r, e_theta);
            Ok(Kinematics {
                variable: parameter,
                position,
                velocity,
                acceleration,
                speed: simp(pool, speed),
                tangent,
                normal: simp3(pool, normal),
                curvature,
                radius,
                a_t,
                a_n,
                polar,
                straight,
            })
        }
    }
}

fn project(
    pool: &mut Pool,
    r: [Id; 3],
    v: [Id; 3],
    a: [Id; 3],
    e_r: [Id; 3],
    e_theta: [Id; 3],
) -> PolarComponents {
    let comps = |pool: &mut Pool, w: [Id; 3]| -> [Id; 3] {
        let c_r = dot(pool, w, e_r);
        let c_t = dot(pool, w, e_theta);
        simp3(pool, [c_r, c_t, w[2]])
    };
    PolarComponents {
        e_r,
        e_theta,
        position: comps(pool, r),
        velocity: comps(pool, v),
        acceleration: comps(pool, a),
        tangent: [Pool::ZERO; 3],
        normal: [Pool::ZERO; 3],
    }
}

/// `|e|` distributed over products and integer powers (`|R^2 θ'^3| = R^2 |θ'|^3`), so that it
/// cancels against `|θ'|^3` from the speed.
fn abs_of(pool: &mut Pool, e: Id) -> Id {
    match pool.node(e).clone() {
        Node::Mul(fs) => {
            let parts: Vec<Id> = fs.iter().map(|&f| abs_of(pool, f)).collect();
            pool.mul(&parts)
        }
        Node::Pow(b, x) if pool.as_num(x).and_then(|n| n.as_integer()).is_some() => {
            let ab = abs_of(pool, b);
            pool.pow(ab, x)
        }
        _ => pool.call(Func::Abs, &[e]),
    }
}

/// Normal–tangential quantities from `r, v, a` (functions of `t`).
fn nt(
    pool: &mut Pool,
    t: Id,
    r: [Id; 3],
    v: [Id; 3],
    a: [Id; 3],
    polar: PolarComponents,
) -> Result<Kinematics, KinError> {
    let v2 = {
        let d = dot(pool, v, v);
        simp(pool, d)
    };
    if v2 == Pool::ZERO {
        return Err(KinError::NoMotion);
    }
    let speed = crate::dsolve::nice_sqrt(pool, v2);
    let va = {
        let d = dot(pool, v, a);
        simp(pool, d)
    };
    let vxa = cross(pool, v, a);
    let vxa = simp3(pool, vxa);
    let nonzero: Vec<Id> = vxa.iter().copied().filter(|&c| c != Pool::ZERO).collect();
    let vxa_norm = if let [only] = nonzero.as_slice() {
        // Planar motion: |v × a| is |(v × a)_z|, no square root of a square.
        let c = simp(pool, *only);
        abs_of(pool, c)
    } else {
        let d = dot(pool, vxa, vxa);
        let vxa2 = simp(pool, d);
        crate::dsolve::nice_sqrt(pool, vxa2)
    };
    let tangent = {
        let tv = v.map(|c| pool.div(c, speed));
        simp3(pool, tv)
    };
    let a_t = {
        let e = pool.div(va, speed);
        simp(pool, e)
    };
    let a_n = {
        let e = pool.div(vxa_norm, speed);
        simp(pool, e)
    };
    let curvature = {
        let s3 = pool.powi(speed, 3);
        let e = pool.div(vxa_norm, s3);
        simp(pool, e)
    };
    let radius = {
        let s3 = pool.powi(speed, 3);
        let e = pool.div(s3, vxa_norm);
        simp(pool, e)
    };
    if vxa_norm == Pool::ZERO {
        let inf = pool.num(pdyn_expr::Number::Float(f64::INFINITY));
        return Ok(Kinematics {
            variable: t,
            position: r,
            velocity: v,
            acceleration: a,
            speed,
            tangent,
            normal: [Pool::ZERO; 3],
            curvature: Pool::ZERO,
            radius: inf,
            a_t,
            a_n: Pool::ZERO,
            polar,
            straight: true,
        });
    }
    let normal = {
        let den = pool.mul2(speed, vxa_norm);
        let n: [Id; 3] = [0, 1, 2].map(|i| {
            let p = pool.mul2(v2, a[i]);
            let q = pool.mul2(va, v[i]);
            let d = pool.sub(p, q);
            pool.div(d, den)
        });
        simp3(pool, n)
    };
    Ok(Kinematics {
        variable: t,
        position: r,
        velocity: v,
        acceleration: a,
        speed,
        tangent,
        normal,
        curvature,
        radius,
        a_t,
        a_n,
        polar,
        straight: false,
    })
}

/// Tidies a magnitude: square roots in a product lose their positive square factors
/// (`2 sqrt(π² R² T⁴ + 4π⁴ R² T⁴)/T⁴` becomes `2π R sqrt(1 + 4π²)/T²`), then simplifies.
pub fn tidy_magnitude(pool: &mut Pool, e: Id) -> Id {
    let half = pool.num(pdyn_expr::Number::ratio(1, 2));
    let factors: Vec<Id> = match pool.node(e) {
        Node::Mul(fs) => fs.to_vec(),
        _ => vec![e],
    };
    let parts: Vec<Id> = factors
        .into_iter()
        .map(|f| match pool.node(f).clone() {
            Node::Pow(b, x) if x == half => crate::dsolve::nice_sqrt(pool, b),
            _ => f,
        })
        .collect();
    let m = pool.mul(&parts);
    pool.simplify(m)
}

/// The first `t ≥ 0` with `expr(t) = target` (`expr` a function of `t` only, `target` a
/// number): exact when `expr` is linear in `t` or a monomial `c t^n`, else numeric (scan and
/// bisection). Returns the exact instant when found, and its value (NaN when the exact instant
/// still involves parameters without values).
pub fn solve_time(pool: &mut Pool, expr: Id, target: Id) -> Result<(Option<Id>, f64), KinError> {
    let t = pool.time();
    if !pool.contains(expr, t) {
        return Err(KinError::ConstantInTime {
            expr: pool.to_text(expr),
        });
    }
    let eq = pool.sub(expr, target);
    let eq = pool.expand(eq);
    let exact =
        exact_root(pool, eq, expr, target, t).or_else(|| earliest_algebraic_root(pool, eq, t));
    if let Some(e) = exact {
        match value(pool, e) {
            Some(v) if v >= 0.0 => return Ok((Some(e), v)),
            Some(_) => {}
            // Symbolic instant (parameters without values): exact only, value NaN.
            None => return Ok((Some(e), f64::NAN)),
        }
    }
    let prog = Program::compile(pool, &[t], &[eq]).map_err(|e| KinError::NotEvaluable {
        expr: String::new(),
        reason: e.to_string(),
    })?;
    let mut ws = prog.workspace();
    let mut f = |x: f64| {
        let mut o = [0.0];
        prog.eval(&[x], &mut ws, &mut o);
        o[0]
    };
    // Scan outward with a slowly growing step, then bisect the first sign change.
    let (mut lo, mut flo) = (0.0, f(0.0));
    if flo == 0.0 {
        return Ok((None, 0.0));
    }
    let mut h = 1e-3;
    for _ in 0..20_000 {
        let hi = lo + h;
        let fhi = f(hi);
        if fhi == 0.0 {
            return Ok((None, hi));
        }
        if fhi.is_finite() && flo.is_finite() && (fhi < 0.0) != (flo < 0.0) {
            let (mut a, mut b, mut fa) = (lo, hi, flo);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                let fm = f(m);
                if (fm < 0.0) == (fa < 0.0) {
                    a = m;
                    fa = fm;
                } else {
                    b = m;
                }
            }
            return Ok((None, 0.5 * (a + b)));
        }
        lo = hi;
        flo = fhi;
        h *= 1.001;
    }
    Err(KinError::NeverReaches {
        expr: pool.to_text(expr),
        target: pool.to_text(target),
        t_max: lo,
    })
}

/// The earliest root `t ≥ 0` of `eq`, with parameters without values, among those
/// [`crate::algebra::solve`] finds (e.g. both roots of a quadratic): a root is kept when it is
/// `≥ 0` for three sets of positive trial values, and chosen when it is the earliest in all
/// three.
fn earliest_algebraic_root(pool: &mut Pool, eq: Id, t: Id) -> Option<Id> {
    let roots: Vec<Id> = crate::algebra::solve(pool, &[eq], &[t])
        .ok()?
        .into_iter()
        .filter_map(|s| s.first().copied())
        .collect();
    let mut free: Vec<Id> = Vec::new();
    for n in pool.topo_order(&roots) {
        if matches!(pool.node(n), Node::Sym(_)) && !free.contains(&n) {
            free.push(n);
        }
    }
    if free.is_empty() {
        // All numbers: the root-finder below gives the instant to full precision, and an
        // exact form such as `sqrt(43531875 + 3903218*sin(pi/4)^2)/...` informs nobody.
        return None;
    }
    let trials: Vec<Vec<f64>> = extremum::TRIAL_SEEDS
        .iter()
        .map(|&seed| extremum::trial_values(free.len(), seed))
        .collect();
    let mut values = vec![Vec::new(); roots.len()];
    for vals in &trials {
        for (k, &r) in roots.iter().enumerate() {
            let x = free.iter().zip(vals).fold(r, |acc, (&s, &v)| {
                let num = pool.num(pdyn_expr::Number::Float(v));
                pool.subs1(acc, s, num)
            });
            values[k].push(pool.eval_const(x).unwrap_or(f64::NAN));
        }
    }
    let admissible: Vec<usize> = (0..roots.len())
        .filter(|&k| values[k].iter().all(|v| v.is_finite() && *v >= -1e-12))
        .collect();
    let earliest = admissible.iter().copied().find(|&k| {
        admissible
            .iter()
            .all(|&j| (0..trials.len()).all(|i| values[k][i] <= values[j][i]))
    })?;
    Some(roots[earliest])
}

fn exact_root(pool: &mut Pool, eq: Id, expr: Id, target: Id, t: Id) -> Option<Id> {
    let d = pool.diff(eq, t);
    if !pool.contains(d, t) {
        let sys = pool.linear_system(&[eq], &[t]).ok()?;
        return pool.solve_linear(&sys).ok().map(|v| v[0]);
    }
    // expr = c t^n.
    let (c, n) = match pool.node(expr).clone() {
        Node::Pow(b, e) if b == t => (Pool::ONE, pool.as_num(e)?),
        Node::Mul(fs) => {
            let mut c = Vec::new();
            let mut n = None;
            for f in fs.iter() {
                match pool.node(*f) {
                    Node::Pow(b, e) if *b == t => n = Some(pool.as_num(*e)?),
                    Node::Time => n = Some(pdyn_expr::Number::ONE),
                    _ if !pool.contains(*f, t) => c.push(*f),
                    _ => return None,
                }
            }
            (pool.mul(&c), n?)
        }
        _ => return None,
    };
    if !n.is_positive() {
        return None;
    }
    let q = pool.div(target, c);
    let e = pool.num(n.recip());
    let r = pool.pow(q, e);
    Some(pool.simplify(r))
}

fn value(pool: &mut Pool, e: Id) -> Option<f64> {
    pool.eval_const(e).ok().filter(|v| v.is_finite())
}
