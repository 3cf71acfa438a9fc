//! `pdyn dsolve`: closed-form solution of linear constant-coefficient ODEs and systems, and the
//! 1-D rules of straight-line motion (`--rule "a(v) = -c*v^2"`). Computed by
//! [`pdyn::dsolve`], printed by [`pdyn::report::dsolve`].

use super::Format;
use clap::Args;
use pdyn::dsolve::{dsolve, DsolveInput};
use pdyn::Error;

/// `pdyn dsolve`.
#[derive(Args, Debug)]
#[command(after_help = "Examples:
  pdyn dsolve \"x'' + 2*zeta*wn*x' + wn^2*x = 0\" --ic \"x(0)=x0, x'(0)=v0\"
  pdyn dsolve \"m*x'' = -k*(x - L0) - m*g\" --ic \"x(0)=L, x'(0)=0\"
  pdyn dsolve \"x'' = 0\" \"y'' = -g\" --ic \"x(0)=0, x'(0)=V*cos(a), y(0)=h, y'(0)=V*sin(a)\"
  pdyn dsolve --rule \"a(v) = -g - c*v^2\" --ic \"x(0)=0, v(0)=v0\"")]
pub struct DsolveArgs {
    /// Equations `lhs = rhs` in coordinates written `x'`, `x''` or `x(t)`, one per argument.
    /// An equation starting with `-` goes after `--`.
    equations: Vec<String>,
    /// Initial conditions, comma separated: `x(0)=x0, x'(0)=v0` (all at the same time).
    #[arg(long, allow_hyphen_values = true)]
    ic: Option<String>,
    /// A 1-D rule of straight-line motion instead of equations: `a(t) = ...`, `v(t) = ...`,
    /// `a(v) = ...` or `a(x) = ...` (initial conditions `x(0)=..., v(0)=...`).
    #[arg(long, allow_hyphen_values = true)]
    rule: Option<String>,
    /// Parameter values substituted before solving, e.g. `--set m=2,k=50` (a numeric damping
    /// ratio picks the under-, critically or over-damped form).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    set: Vec<String>,
    /// Evaluate the solution at these times (or at these values of the independent variable
    /// of a rule), e.g. `--at 0,0.5,1`.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    at: Vec<String>,
    /// Find the first instant t ≥ 0 where a condition holds, e.g. `--when "y = 0"` (landing)
    /// or `--when "y' = 0"` (highest point), and print the state there (exactly when the
    /// instant solves exactly).
    #[arg(long, allow_hyphen_values = true)]
    when: Option<String>,
    /// Parameters that may be negative or zero. Every other parameter of the equations is
    /// assumed positive (masses, stiffnesses, lengths), which decides signs of discriminants.
    #[arg(long, value_delimiter = ',')]
    signed: Vec<String>,
    /// Output notation.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

/// `pdyn dsolve EQUATIONS --ic ...` or `pdyn dsolve --rule ...`.
pub fn run(a: DsolveArgs) -> Result<String, Error> {
    let input = DsolveInput {
        equations: a.equations,
        ic: a.ic,
        rule: a.rule,
        set: a.set,
        at: a.at,
        when: a.when,
        signed: a.signed,
    };
    let r = dsolve(&input)?;
    Ok(pdyn::report::dsolve::report(&r, a.format.into(), a.json))
}
