//! The computation of `pdyn kin` (and of Python's `pdyn.kin`): kinematics of a particle from
//! its position (Cartesian or polar) or its path and speed — velocity, acceleration,
//! normal–tangential and polar components, curvature, values at instants and the maximum of a
//! quantity over a range. The command prints a [`KinResult`]; Python converts it.

use crate::args::{assignments, idents, positive_parameters, split_top, subs_all};
use crate::Error;
use pdyn_expr::{Binding, FreeScope, Id, Number, Pool, Scope, Value};
use pdyn_mech::kinematics::{analyze, maximum, solve_time, Kinematics, Maximum, Motion, Quantity};

/// What to analyse, as the text of the command's arguments.
#[derive(Clone, Debug, Default)]
pub struct KinInput {
    /// Cartesian position `[x, y, z]` as functions of `t` (or of coordinates written `x(t)`).
    pub position: Option<String>,
    /// Cylindrical-polar position: `r = ..., theta = ..., z = ...` (z optional).
    pub polar: Option<String>,
    /// A planar path: `y = f(x)`, or `x = ..., y = ...` in the parameter `param`.
    pub path: Option<String>,
    /// The parameter of a parametric path (the command's default: `s`).
    pub param: String,
    /// Speed along the path (the command's default: `V`).
    pub speed: String,
    /// Instants: `t=2`, `theta=pi` (solves for t), `x=L/4`; several assignments per instant
    /// separated by commas.
    pub at: Vec<String>,
    /// Parameter values, `name=value` (each item may hold several, comma separated).
    pub set: Vec<String>,
    /// A scalar to maximise over `over`, in the names of the quantities.
    pub max: Option<String>,
    /// The range for `max`: `x=0..L` or `t=0..10`.
    pub over: Option<String>,
    /// Parameters that may be negative; every other parameter is assumed positive.
    pub signed: Vec<String>,
}

impl KinInput {
    /// An input with the command's defaults (`param = "s"`, `speed = "V"`).
    pub fn new() -> KinInput {
        KinInput {
            param: "s".into(),
            speed: "V".into(),
            ..KinInput::default()
        }
    }
}

/// One evaluated instant.
#[derive(Clone, Debug)]
pub struct KinInstant {
    /// The instant as given (`t=2`).
    pub spec: String,
    /// The instant as resolved (`theta = pi (t = sqrt(pi))`).
    pub resolved: String,
    /// Every quantity there that is defined: name, exact value, numeric value when it has no
    /// free symbol.
    pub values: Vec<(&'static str, Quantity, Option<Vec<f64>>)>,
    /// The quantities that are undefined there and why (the tangent where the point is at
    /// rest, the polar unit vectors at the origin); they are not in `values`.
    pub undefined: Vec<(&'static str, &'static str)>,
    /// Where `dr/d(variable)` is zero: the limit of the tangent, when it exists.
    pub at_rest: Option<AtRest>,
}

/// The tangent where the point is at rest (`dr/d(variable) = 0`): its limit as the variable
/// increases to the instant is the direction of the first derivative of `r` that is not
/// zero there, `r⁽ᵏ⁾` (Taylor: `r' ≈ r⁽ᵏ⁾ hᵏ⁻¹/(k−1)!`); from below it is the same for odd
/// `k` and reversed for even `k` (a cusp: the point stops and turns back).
#[derive(Clone, Debug)]
pub struct AtRest {
    /// `k`, the order of the first derivative of `r` that is not zero; `None` when every
    /// derivative up to [`AT_REST_ORDERS`] is zero (or cannot be decided).
    pub order: Option<usize>,
    /// The limiting tangent `r⁽ᵏ⁾/|r⁽ᵏ⁾|` (exact) and its value, when `order` is known.
    pub tangent: Option<([Id; 3], Option<[f64; 3]>)>,
    /// Whether the tangent reverses through the instant (even `k`).
    pub reverses: bool,
    /// The limits of `a_t = a·T` and `a_n = |a − (a·T)T|` as the variable increases to the
    /// instant, when the acceleration there and the limiting tangent are numbers.
    pub a_t: Option<f64>,
    /// See `a_t`.
    pub a_n: Option<f64>,
}

/// How many derivatives of `r` are tried for the limiting tangent at rest.
pub const AT_REST_ORDERS: usize = 8;

/// The quantities built on the unit tangent: undefined where the point is at rest.
const ON_THE_TANGENT: [&str; 8] = [
    "tangent",
    "normal",
    "curvature",
    "radius",
    "a_t",
    "a_n",
    "tangent_polar",
    "normal_polar",
];

/// The quantities built on the polar unit vectors: undefined at the origin.
const ON_POLAR_AXES: [&str; 7] = [
    "e_r",
    "e_theta",
    "r_polar",
    "v_polar",
    "a_polar",
    "tangent_polar",
    "normal_polar",
];

/// The maximum asked for with `max`/`over`.
#[derive(Clone, Debug)]
pub struct KinMax {
    /// The expression maximised, as given.
    pub expr: String,
    /// The range, as given.
    pub over: String,
    /// The name of the range's variable.
    pub variable: String,
    /// The maximum found.
    pub found: Maximum,
}

/// Everything `pdyn kin` computes; expressions are ids in `pool`.
#[derive(Debug)]
pub struct KinResult {
    /// The pool the expressions live in.
    pub pool: Pool,
    /// The independent variable's name (`t`, or the path's parameter).
    pub variable: String,
    /// A straight line: the normal is undefined (given as 0) and the radius infinite.
    pub straight: bool,
    /// Every quantity by name (`r`, `v`, `a`, `speed`, ...), in the command's order.
    pub quantities: Vec<(&'static str, Quantity)>,
    /// The instants asked for, in order.
    pub instants: Vec<KinInstant>,
    /// The maximum asked for.
    pub max: Option<KinMax>,
    /// The parameters assumed positive (those without a value).
    pub assumed_positive: Vec<String>,
}

/// A kinematic quantity as an expression value.
pub fn value(q: Quantity) -> Value {
    match q {
        Quantity::Scalar(s) => Value::Scalar(s),
        Quantity::Vector(v) => Value::Vector(v),
    }
}

/// Parses `src` as a scalar with `scope`; errors carry the location.
fn scalar(pool: &mut Pool, src: &str, scope: &mut dyn Scope, origin: &str) -> Result<Id, Error> {
    match pool
        .parse_in(src, scope)
        .map_err(|e| Error::expr(origin, src, e))?
    {
        Value::Scalar(s) => Ok(s),
        Value::Vector(_) => Err(Error::argument(
            "",
            format!("{origin}: `{src}` is a vector, expected a scalar"),
        )),
    }
}

/// Names bound to the kinematic quantities, other names free (parameters).
struct KinScope {
    named: Vec<(String, Value)>,
    free: FreeScope,
}

impl Scope for KinScope {
    fn resolve(&mut self, pool: &mut Pool, name: &str) -> Option<Binding> {
        if let Some((_, v)) = self.named.iter().find(|(n, _)| n == name) {
            return Some(Binding::Value(*v));
        }
        self.free.resolve(pool, name)
    }
    fn names(&self) -> Vec<String> {
        self.named.iter().map(|(n, _)| n.clone()).collect()
    }
}

/// The motion, its input names (for `--at theta=pi`), and the independent variable's name.
struct Input {
    motion: Motion,
    inputs: Vec<(String, Id)>,
    variable: String,
}

fn read_input(a: &KinInput, pool: &mut Pool, scope: &mut FreeScope) -> Result<Input, Error> {
    let given = [a.position.is_some(), a.polar.is_some(), a.path.is_some()]
        .iter()
        .filter(|&&b| b)
        .count();
    if given != 1 {
        return Err(Error::argument("", "give exactly one of: a position \"[x, y, z]\", --polar \"r = ..., theta = ...\", or --path \"y = f(x)\""));
    }
    if let Some(src) = &a.position {
        let v = pool
            .parse_in(src, scope)
            .map_err(|e| Error::expr("<position>", src, e))?;
        let Value::Vector(r) = v else {
            return Err(Error::argument(
                "<position>",
                format!(
                    "<position>: `{src}` is a scalar; write the position as a vector [x, y, z]"
                ),
            ));
        };
        return Ok(Input {
            motion: Motion::Cartesian(r),
            inputs: vec![("x".into(), r[0]), ("y".into(), r[1]), ("z".into(), r[2])],
            variable: "t".into(),
        });
    }
    if let Some(src) = &a.polar {
        let (mut r, mut th, mut z) = (None, None, Pool::ZERO);
        for (k, v) in assignments(src, "--polar")? {
            let e = scalar(pool, &v, scope, "--polar")?;
            match k.as_str() {
                "r" => r = Some(e),
                "theta" | "th" => th = Some(e),
                "z" => z = e,
                other => {
                    return Err(Error::argument(
                        "--polar",
                        format!("--polar: unknown component `{other}` (use r, theta, z)"),
                    ))
                }
            }
        }
        let (Some(r), Some(th)) = (r, th) else {
            return Err(Error::argument(
                "--polar",
                "--polar: give both r = ... and theta = ...",
            ));
        };
        return Ok(Input {
            motion: Motion::Polar { r, theta: th, z },
            inputs: vec![("r".into(), r), ("theta".into(), th), ("z".into(), z)],
            variable: "t".into(),
        });
    }
    let src = a.path.as_deref().unwrap_or_default();
    let items = assignments(src, "--path")?;
    let speed = scalar(pool, &a.speed, scope, "--speed")?;
    match items.as_slice() {
        [(k, v)] if k == "y" => {
            let y = scalar(pool, v, scope, "--path")?;
            let x = pool.var("x");
            Ok(Input {
                motion: Motion::Path {
                    x,
                    y,
                    parameter: x,
                    speed,
                },
                inputs: vec![("y".into(), y)],
                variable: "x".into(),
            })
        }
        [(k1, v1), (k2, v2)] if k1 == "x" && k2 == "y" => {
            let x = scalar(pool, v1, scope, "--path")?;
            let y = scalar(pool, v2, scope, "--path")?;
            let p = pool.var(&a.param);
            if !pool.contains(x, p) && !pool.contains(y, p) {
                return Err(Error::argument(
                    "--path",
                    format!(
                    "--path: neither x nor y depends on the parameter `{}` (set it with --param)",
                    a.param
                ),
                ));
            }
            Ok(Input {
                motion: Motion::Path {
                    x,
                    y,
                    parameter: p,
                    speed,
                },
                inputs: vec![("x".into(), x), ("y".into(), y)],
                variable: a.param.clone(),
            })
        }
        _ => Err(Error::argument(
            "--path",
            "--path: write `y = f(x)` or `x = f(s), y = g(s)`",
        )),
    }
}

fn numeric(pool: &mut Pool, e: Id) -> Option<f64> {
    pool.eval_const(e).ok()
}

fn tidy(pool: &mut Pool, e: Id) -> Id {
    let x = pool.expand(e);
    pool.simplify(x)
}

/// Analyses the motion given by `a`: what `pdyn kin` prints.
pub fn kin(a: &KinInput) -> Result<KinResult, Error> {
    let mut pool = Pool::new();
    // Parameters: every plain name except t, the path variable and the quantity names.
    let mut names = Vec::new();
    for src in [&a.position, &a.polar, &a.path]
        .into_iter()
        .flatten()
        .chain(a.path.is_some().then_some(&a.speed))
    {
        for item in split_top(src) {
            let rhs = item
                .split_once('=')
                .map_or(item.as_str(), |(_, r)| r)
                .trim();
            if let Ok(ast) = pdyn_expr::syntax::parse(rhs) {
                idents(&ast, &mut names);
            }
        }
    }
    let mut scope = FreeScope::default();
    for src in [&a.position, &a.polar, &a.path].into_iter().flatten() {
        for item in split_top(src) {
            let rhs = item
                .split_once('=')
                .map_or(item.as_str(), |(_, r)| r)
                .trim();
            if let Ok(ast) = pdyn_expr::syntax::parse(rhs) {
                scope.learn(&ast);
            }
        }
    }
    let path_var = if a
        .path
        .as_deref()
        .is_some_and(|p| p.trim_start().starts_with('y'))
    {
        "x".to_string()
    } else {
        a.param.clone()
    };
    let skip = |n: &str| (a.path.is_some() && n == path_var) || scope.coordinates.contains(n);
    let params = positive_parameters(names, skip, &a.signed, &a.set);
    scope.positive = params.iter().cloned().collect();
    let input = read_input(a, &mut pool, &mut scope)?;
    let k = analyze(&mut pool, input.motion).map_err(|error| Error::Kin {
        context: String::new(),
        error,
    })?;
    // Parameter values.
    let mut set = Vec::new();
    for (name, v) in a
        .set
        .iter()
        .map(|kv| assignments(kv, "--set"))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
    {
        let val = scalar(&mut pool, &v, &mut scope, "--set")?;
        let sym = pool.var(&name);
        set.push((sym, val));
    }
    let named: Vec<(&'static str, Quantity)> = k.named();
    let mut instants = Vec::new();
    for spec in &a.at {
        let (resolved, values, map) =
            instant(&mut pool, &k, &input, &named, &set, spec, &mut scope)?;
        let (values, undefined, at_rest) = undefined_there(&mut pool, &k, &map, values);
        instants.push(KinInstant {
            spec: spec.clone(),
            resolved,
            values,
            undefined,
            at_rest,
        });
    }
    let max = if let Some(expr) = &a.max {
        let over = a.over.as_deref().ok_or_else(|| {
            Error::argument("--max", "--max needs a range: --over x=0..L (or t=0..T)")
        })?;
        Some(max_over(
            &mut pool, &k, &input, &named, &set, expr, over, &mut scope,
        )?)
    } else if a.over.is_some() {
        return Err(Error::argument(
            "--over",
            "--over is the range of --max; give --max too",
        ));
    } else {
        None
    };
    let assumed_positive: Vec<String> = params
        .iter()
        .filter(|p| !set.iter().any(|&(s, _)| pool.to_text(s) == **p))
        .cloned()
        .collect();
    Ok(KinResult {
        pool,
        variable: input.variable,
        straight: k.straight,
        quantities: named,
        instants,
        max,
        assumed_positive,
    })
}

type InstantValues = Vec<(&'static str, Quantity, Option<Vec<f64>>)>;

/// An instant resolved: its header, the values there, and the substitutions that make it.
type Instant = (String, InstantValues, Vec<(Id, Id)>);

/// Whether `e`, at the instant, is zero: exactly, or numerically zero to the last bits.
fn zero_there(pool: &mut Pool, e: [Id; 3], map: &[(Id, Id)]) -> ([Id; 3], bool) {
    let x = e.map(|c| {
        let s = subs_all(pool, c, map);
        tidy(pool, s)
    });
    let zero = x.iter().all(|&c| c == Pool::ZERO)
        || x.iter()
            .all(|&c| numeric(pool, c).is_some_and(|v| v.abs() < 1e-300));
    (x, zero)
}

/// Splits the values of an instant into the defined ones and those undefined there: the
/// tangent and what is built on it where `dr/d(variable) = 0` (with its limit, see
/// [`AtRest`]), the polar components at the origin. They were printed as `0` or NaN.
fn undefined_there(
    pool: &mut Pool,
    k: &Kinematics,
    map: &[(Id, Id)],
    values: InstantValues,
) -> (
    InstantValues,
    Vec<(&'static str, &'static str)>,
    Option<AtRest>,
) {
    let var = k.variable;
    let mut undefined: Vec<(&'static str, &'static str)> = Vec::new();
    let mut d = k.position.map(|c| pool.diff(c, var));
    let (_, at_rest) = zero_there(pool, d, map);
    let at_rest = at_rest.then(|| {
        for name in ON_THE_TANGENT {
            undefined.push((
                name,
                "the point is at rest here (dr/dt = 0): no direction of motion",
            ));
        }
        let mut found = None;
        for order in 2..=AT_REST_ORDERS {
            d = d.map(|c| pool.diff(c, var));
            let (x, zero) = zero_there(pool, d, map);
            if !zero {
                found = Some((order, x));
                break;
            }
        }
        let Some((order, x)) = found else {
            return AtRest {
                order: None,
                tangent: None,
                reverses: false,
                a_t: None,
                a_n: None,
            };
        };
        let sq: Vec<Id> = x.iter().map(|&c| pool.powi(c, 2)).collect();
        let n2 = pool.add(&sq);
        let n = pool.sqrt(n2);
        let dir = x.map(|c| {
            let q = pool.div(c, n);
            tidy(pool, q)
        });
        let value = {
            let v: Option<Vec<f64>> = dir.iter().map(|&c| numeric(pool, c)).collect();
            v.map(|v| [v[0], v[1], v[2]])
        };
        let (a, _) = zero_there(pool, k.acceleration, map);
        let a: Option<Vec<f64>> = a.iter().map(|&c| numeric(pool, c)).collect();
        let (a_t, a_n) = match (&a, value) {
            (Some(a), Some(t)) => {
                let at = a[0] * t[0] + a[1] * t[1] + a[2] * t[2];
                let an = (0..3)
                    .map(|i| (a[i] - at * t[i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                (Some(at), Some(an))
            }
            _ => (None, None),
        };
        AtRest {
            order: Some(order),
            tangent: Some((dir, value)),
            reverses: order % 2 == 0,
            a_t,
            a_n,
        }
    });
    // The polar unit vectors need the point off the origin (in the plane of motion).
    let planar = [k.position[0], k.position[1], Pool::ZERO];
    if zero_there(pool, planar, map).1 {
        for name in ON_POLAR_AXES {
            if !undefined.iter().any(|(n, _)| *n == name) {
                undefined.push((name, "the point is at the origin here: no radial direction"));
            }
        }
    }
    let values = values
        .into_iter()
        .filter(|(n, _, _)| !undefined.iter().any(|(u, _)| u == n))
        .collect();
    (values, undefined, at_rest)
}

/// Resolves one `--at` spec and evaluates every quantity there.
fn instant(
    pool: &mut Pool,
    k: &Kinematics,
    input: &Input,
    named: &[(&'static str, Quantity)],
    set: &[(Id, Id)],
    spec: &str,
    scope: &mut FreeScope,
) -> Result<Instant, Error> {
    let t = pool.time();
    let mut map: Vec<(Id, Id)> = set.to_vec();
    let mut header = Vec::new();
    for (name, v) in assignments(spec, "--at")? {
        let val = scalar(pool, &v, scope, "--at")?;
        let val = subs_all(pool, val, set);
        if name == "t" {
            map.push((t, val));
            header.push(format!("t = {}", pool.to_text(val)));
        } else if name == input.variable {
            let var = k.variable;
            map.push((var, val));
            header.push(format!("{name} = {}", pool.to_text(val)));
        } else if let Some(&(_, e)) = input.inputs.iter().find(|(n, _)| *n == name) {
            if k.variable != t {
                return Err(Error::argument("--at", format!(
                    "--at: for a path, give the position along it (`{} = ...`) and, if the speed varies, `t = ...`",
                    input.variable
                )));
            }
            let e = subs_all(pool, e, set);
            let (exact, tv) = solve_time(pool, e, val).map_err(|error| Error::Kin {
                context: format!("--at {spec}"),
                error,
            })?;
            let tt = match exact {
                Some(x) => x,
                None => pool.num(Number::Float(tv)),
            };
            header.push(format!(
                "{name} = {} (t = {}{})",
                pool.to_text(val),
                pool.to_text(tt),
                if exact.is_some() && tv.is_finite() && pool.as_num(tt).is_none() {
                    format!(" ≈ {tv}")
                } else {
                    String::new()
                }
            ));
            map.push((t, tt));
        } else {
            return Err(Error::argument(
                "--at",
                format!(
                    "--at: `{name}` is not t, {} or a component of the input ({})",
                    input.variable,
                    input
                        .inputs
                        .iter()
                        .map(|(n, _)| n.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    let mut values = Vec::new();
    for (n, q) in named {
        let ev = |pool: &mut Pool, e: Id| {
            let s = subs_all(pool, e, &map);
            tidy(pool, s)
        };
        let (q2, nums) = match *q {
            Quantity::Scalar(s) => {
                let x = ev(pool, s);
                let v = numeric(pool, x).map(|v| vec![v]);
                (Quantity::Scalar(x), v)
            }
            Quantity::Vector(v) => {
                let x = v.map(|c| ev(pool, c));
                let nums: Option<Vec<f64>> = x.iter().map(|&c| numeric(pool, c)).collect();
                (Quantity::Vector(x), nums)
            }
        };
        values.push((*n, q2, nums));
    }
    Ok((header.join(", "), values, map))
}

/// `--max EXPR --over VAR=LO..HI`: the expression in the names of the quantities, the range
/// parsed, and the maximum found by [`pdyn_mech::kinematics::maximum`].
#[allow(clippy::too_many_arguments)] // the command's parsed state, passed once
fn max_over(
    pool: &mut Pool,
    k: &Kinematics,
    input: &Input,
    named: &[(&'static str, Quantity)],
    set: &[(Id, Id)],
    expr: &str,
    over: &str,
    scope: &mut FreeScope,
) -> Result<KinMax, Error> {
    let mut ks = KinScope {
        named: named
            .iter()
            .map(|(n, q)| (n.to_string(), value(*q)))
            .collect(),
        free: scope.clone(),
    };
    let f = scalar(pool, expr, &mut ks, "--max")?;
    let (var_name, range) = over.split_once('=').ok_or_else(|| {
        Error::argument("--over", format!("--over: expected `x=0..L`, got `{over}`"))
    })?;
    let var_name = var_name.trim();
    let (lo_s, hi_s) = range.split_once("..").ok_or_else(|| {
        Error::argument(
            "--over",
            format!("--over: expected `lo..hi`, got `{range}`"),
        )
    })?;
    let var = if var_name == "t" {
        pool.time()
    } else if var_name == input.variable {
        k.variable
    } else {
        return Err(Error::argument(
            "--over",
            format!(
                "--over: the range must be in t or {} (got `{var_name}`)",
                input.variable
            ),
        ));
    };
    let lo = scalar(pool, lo_s.trim(), scope, "--over")?;
    let hi = scalar(pool, hi_s.trim(), scope, "--over")?;
    let f = subs_all(pool, f, set);
    let f = tidy(pool, f);
    let (lo, hi) = (subs_all(pool, lo, set), subs_all(pool, hi, set));
    let found = maximum(pool, f, var, lo, hi).map_err(|error| {
        use pdyn_mech::kinematics::KinError;
        let context = match error {
            KinError::DependsOnTime { .. } | KinError::LocationDependsOn { .. } => "--max",
            _ => "",
        };
        Error::Kin {
            context: context.into(),
            error,
        }
    })?;
    Ok(KinMax {
        expr: expr.to_string(),
        over: over.to_string(),
        variable: var_name.to_string(),
        found,
    })
}
