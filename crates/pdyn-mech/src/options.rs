//! The options of a run, named neutrally in the libraries and by each front end in its own way:
//! `--t-end` on the command line, `t_end=` in Python. Library messages that name an option
//! (here, in `pdyn`, and the parameter values of `kin`/`dsolve`) format a [`RunOption`]; the front end says once, at start-up, which names it uses
//! ([`name_options_as`]), so a Python user never reads a command-line flag and the command
//! line keeps its own.

use std::fmt;
use std::sync::atomic::{AtomicU8, Ordering};

/// How options are named in messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Naming {
    /// As keywords (`t_end`, `rtol`): Python and library users (the default).
    Keywords,
    /// As command-line flags (`--t-end`, `--rtol`): the `pdyn` binary.
    Flags,
}

static NAMING: AtomicU8 = AtomicU8::new(0);

/// Sets how this process's messages name options. A front end calls it once, before any work
/// (a process is one front end: the binary, or the Python extension).
pub fn name_options_as(naming: Naming) {
    NAMING.store(
        match naming {
            Naming::Keywords => 0,
            Naming::Flags => 1,
        },
        Ordering::Relaxed,
    );
}

/// How this process's messages name options.
pub fn naming() -> Naming {
    match NAMING.load(Ordering::Relaxed) {
        1 => Naming::Flags,
        _ => Naming::Keywords,
    }
}

/// One option of a run (of every model kind), whichever front end gave it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RunOption {
    /// Integration method.
    Method,
    /// Relative tolerance.
    Rtol,
    /// Absolute tolerance.
    Atol,
    /// End time.
    TEnd,
    /// Fixed or first step.
    Dt,
    /// Largest step.
    MaxStep,
    /// Step limit.
    MaxSteps,
    /// Equally spaced outputs.
    Points,
    /// Output interval.
    OutputDt,
    /// Output times.
    TEval,
    /// Reported drift of conserved quantities.
    DriftTolerance,
    /// Parameter values.
    Set,
    /// Output directory.
    Out,
    /// Plots.
    Plot,
    /// Initial values of state components.
    Initial,
}

impl RunOption {
    /// The command-line flag.
    pub fn flag(self) -> &'static str {
        match self {
            RunOption::Method => "--method",
            RunOption::Rtol => "--rtol",
            RunOption::Atol => "--atol",
            RunOption::TEnd => "--t-end",
            RunOption::Dt => "--dt",
            RunOption::MaxStep => "--max-step",
            RunOption::MaxSteps => "--max-steps",
            RunOption::Points => "--points",
            RunOption::OutputDt => "--output-dt",
            RunOption::TEval => "--t-eval",
            RunOption::DriftTolerance => "--drift-tolerance",
            RunOption::Set => "--set",
            RunOption::Out => "--out",
            RunOption::Plot => "--plot",
            RunOption::Initial => "--initial",
        }
    }

    /// The keyword (Python's argument name; for the settings also the `[simulate]` key).
    pub fn keyword(self) -> &'static str {
        match self {
            RunOption::Method => "method",
            RunOption::Rtol => "rtol",
            RunOption::Atol => "atol",
            RunOption::TEnd => "t_end",
            RunOption::Dt => "dt",
            RunOption::MaxStep => "max_step",
            RunOption::MaxSteps => "max_steps",
            RunOption::Points => "points",
            RunOption::OutputDt => "output_dt",
            RunOption::TEval => "t_eval",
            RunOption::DriftTolerance => "drift_tolerance",
            RunOption::Set => "params",
            RunOption::Out => "out",
            RunOption::Plot => "plots",
            RunOption::Initial => "initial",
        }
    }

    /// The option as this process names it.
    pub fn name(self) -> &'static str {
        match naming() {
            Naming::Flags => self.flag(),
            Naming::Keywords => self.keyword(),
        }
    }

    /// The option given a value, as a user would type it: `--rtol 1e-9` or `rtol=1e-9`.
    pub fn with(self, value: impl fmt::Display) -> String {
        match naming() {
            Naming::Flags => format!("{} {value}", self.flag()),
            Naming::Keywords => format!("{}={value}", self.keyword()),
        }
    }
}

/// Where this front end lists the integration methods.
pub fn methods_list() -> &'static str {
    match naming() {
        Naming::Flags => "`pdyn run --method help`",
        Naming::Keywords => "`pdyn.methods()`",
    }
}

impl fmt::Display for RunOption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_option_has_a_flag_and_a_keyword_that_match() {
        for o in [
            RunOption::Method,
            RunOption::Rtol,
            RunOption::Atol,
            RunOption::TEnd,
            RunOption::Dt,
            RunOption::MaxStep,
            RunOption::MaxSteps,
            RunOption::Points,
            RunOption::OutputDt,
            RunOption::TEval,
            RunOption::DriftTolerance,
        ] {
            // The settings' keyword is the flag without dashes, in snake case (and the
            // `[simulate]` key).
            assert_eq!(
                o.flag().trim_start_matches("--").replace('-', "_"),
                o.keyword()
            );
        }
    }
}
