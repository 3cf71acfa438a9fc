//! [`KinError`]: why kinematic quantities could not be derived, located or maximised.

use std::fmt;

/// Why the kinematics could not be derived or evaluated.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum KinError {
    /// A position was written with rates (`x'`): it must be the position itself.
    RatesInPosition,
    /// A path's parameter is an expression, not a plain name.
    PathParameterNotAName {
        /// The parameter as written.
        parameter: String,
    },
    /// The path's coordinates do not change with its parameter.
    PathDoesNotMove,
    /// `v = 0`: no tangent, normal or curvature.
    NoMotion,
    /// An instant was asked for by a quantity that does not change with `t`.
    ConstantInTime {
        /// The quantity.
        expr: String,
    },
    /// A quantity cannot be evaluated numerically (symbols without values).
    NotEvaluable {
        /// The quantity.
        expr: String,
        /// What the compiler said.
        reason: String,
    },
    /// The quantity never reaches the target value for `t` in `[0, t_max]`.
    NeverReaches {
        /// The quantity.
        expr: String,
        /// The target.
        target: String,
        /// How far the search went.
        t_max: f64,
    },
    /// A range that is empty or not finite.
    InvalidRange {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// The quantity is NaN or infinite everywhere in the range.
    NotFinite {
        /// The quantity.
        expr: String,
    },
    /// The quantity to maximise depends on `t` while the range is over another variable.
    DependsOnTime {
        /// The quantity.
        expr: String,
    },
    /// With symbolic parameters, the maximum does not sit at one fixed fraction of the range:
    /// its location depends on the parameters' values.
    LocationDependsOn {
        /// The parameters without values.
        parameters: Vec<String>,
    },
}

impl fmt::Display for KinError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KinError::RatesInPosition => {
                f.write_str("give the position itself, without rates (x', y'...)")
            }
            KinError::PathParameterNotAName { parameter } => {
                write!(f, "the path parameter `{parameter}` must be a plain name")
            }
            KinError::PathDoesNotMove => {
                f.write_str("the path does not move with its parameter (x' = y' = 0)")
            }
            KinError::NoMotion => f.write_str(
                "the particle does not move (v = 0): there is no tangent, normal or curvature",
            ),
            KinError::ConstantInTime { expr } => write!(f, "`{expr}` does not change with t"),
            KinError::NotEvaluable { expr, reason } if expr.is_empty() => write!(
                f,
                "cannot locate the instant: {reason}; give the parameters values with {}",
                crate::options::RunOption::Set
            ),
            KinError::NotEvaluable { expr, reason } => write!(
                f,
                "cannot evaluate `{expr}`: {reason}; give the parameters values with {}",
                crate::options::RunOption::Set
            ),
            KinError::NeverReaches { expr, target, t_max } => write!(
                f,
                "`{expr}` never reaches {target} for t between 0 and {t_max:.3e}"
            ),
            KinError::InvalidRange { lo, hi } => write!(f, "empty or invalid range {lo}..{hi}"),
            KinError::NotFinite { expr } => {
                write!(f, "`{expr}` is not finite anywhere in the range")
            }
            KinError::DependsOnTime { expr } => write!(
                f,
                "`{expr}` also depends on t; give t a value ({} is for parameters) or maximise over t",
                crate::options::RunOption::Set
            ),
            KinError::LocationDependsOn { parameters } => write!(
                f,
                "the location of the maximum depends on {}; give values with {}",
                parameters.join(", "),
                crate::options::RunOption::Set
            ),
        }
    }
}

impl std::error::Error for KinError {}
