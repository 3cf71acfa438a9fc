//! `pdyn`: the command-line front end. Thin by design: parse arguments, call the library,
//! print. Every failure becomes a message, a `--json` error object and an exit code here, and
//! only here (codes: 0 success, 1 numerical failure after partial output, 2 bad input,
//! 3 internal error, 4 interrupted by a signal, 5 stopped at once by a second one — see
//! `pdyn::error` and `cli::interrupt`).

mod cli;

use clap::{Parser, Subcommand};
use cli::Outcome;
use pdyn::Error;
use std::process::ExitCode;

/// Analyze the motion of systems of particles.
#[derive(Parser, Debug)]
#[command(
    name = "pdyn",
    version,
    about,
    long_about = None,
    after_help = "Exit codes: 0 success; 1 a numerical failure after partial output was written; \
                  2 bad input; 3 an internal error (please report it); 4 `pdyn run` interrupted by \
                  SIGINT/SIGTERM (stopped after a whole step, files whole, summary.json status \
                  \"interrupted\"); 5 stopped at once by a second signal (files hold whole rows)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simplify an expression (Pythagorean identity, common factors, collected terms).
    Simplify(cli::expr::SimplifyArgs),
    /// Differentiate an expression with respect to a symbol, or in time (`--wrt t`).
    Diff(cli::expr::DiffArgs),
    /// Solve equations that are linear in the chosen unknowns, exactly.
    Solve(cli::expr::SolveArgs),
    /// Evaluate an expression numerically.
    Eval(cli::expr::EvalArgs),
    /// Derive the equations of motion of a model file.
    Derive(cli::derive::DeriveArgs),
    /// Forces required by a prescribed motion (reactions, thrust, bank angle) and design checks (slip, tip).
    Forces(cli::forces::ForcesArgs),
    /// Static equilibrium of a model: Newton's method, reactions at the points, mechanisms named.
    Equilibrium(cli::equilibrium::EquilibriumArgs),
    /// Natural frequencies and mode shapes of a model linearized about its equilibrium.
    Modes(cli::modes::ModesArgs),
    /// Simulate a model file: integrate, check conservation laws, write CSV/JSON/plots.
    Run(cli::run::RunArgs),
    /// Integrate numerically and compare with the closed-form solution (linear models).
    Check(cli::run::CheckArgs),
    /// Run a model's [sweep] over parameter values in parallel and tabulate response measures.
    Sweep(cli::sweep::SweepArgs),
    /// Solve linear constant-coefficient ODEs and systems in closed form, and the 1-D motion rules.
    Dsolve(cli::dsolve::DsolveArgs),
    /// Kinematics of a particle: velocity, acceleration, normal-tangential and polar components.
    Kin(cli::kin::KinArgs),
    /// Fuse an accelerometer record with position fixes (Kalman filter + RTS smoother).
    Fuse(cli::fuse::FuseArgs),
    /// Fit a model's parameters and initial values to measured runs (least squares, sensitivities).
    Fit(cli::fit::FitArgs),
    /// The parameter values within bounds that maximise or minimise a measure of the runs.
    Optimize(cli::optimize::OptimizeArgs),
}

/// Stack of the thread that runs a command: 1 GiB of address space.
const WORKER_STACK: usize = 1 << 30;

fn dispatch(command: Command) -> Result<Outcome, Error> {
    let text = |r: Result<String, Error>| r.map(Outcome::text);
    match command {
        Command::Simplify(a) => text(cli::expr::simplify(a)),
        Command::Diff(a) => text(cli::expr::diff(a)),
        Command::Solve(a) => text(cli::expr::solve(a)),
        Command::Eval(a) => cli::expr::eval(a),
        Command::Derive(a) => text(cli::derive::run(a)),
        Command::Forces(a) => text(cli::forces::run(a)),
        Command::Equilibrium(a) => text(cli::equilibrium::run(a)),
        Command::Modes(a) => text(cli::modes::run(a)),
        Command::Run(a) => cli::run::run(a),
        Command::Check(a) => cli::run::check(a),
        Command::Sweep(a) => cli::sweep::run(a),
        Command::Dsolve(a) => text(cli::dsolve::run(a)),
        Command::Kin(a) => text(cli::kin::run(a)),
        Command::Fuse(a) => text(cli::fuse::run(a)),
        Command::Fit(a) => text(cli::fit::run(a)),
        Command::Optimize(a) => cli::optimize::run(a),
    }
}

/// Whether the command line asks for JSON (decided before parsing, so that even a usage error
/// answers in JSON).
fn wants_json() -> bool {
    // `args_os`: an argument that is not UTF-8 must not panic here (clap reports it, exit 2).
    std::env::args_os().skip(1).any(|a| a == "--json")
}

/// The error for a command-line argument that is not UTF-8 (clap refuses it for every
/// option that is text: expressions, names, numbers; file names may be any bytes): which
/// argument it is, shown with the bad bytes replaced by U+FFFD, and at which byte.
fn invalid_utf8_argument() -> Error {
    let bad = std::env::args_os()
        .enumerate()
        .skip(1)
        .find_map(|(i, a)| a.to_str().is_none().then_some((i, a)));
    let Some((index, arg)) = bad else {
        return Error::argument("", "an argument is not valid UTF-8 text");
    };
    let bytes = arg.as_encoded_bytes();
    let at = std::str::from_utf8(bytes)
        .err()
        .map_or(0, |e| e.valid_up_to());
    Error::argument(
        "",
        format!(
            "argument {index} (`{}`) is not valid UTF-8 (byte {} at offset {at}); expressions, \
             names and numbers must be UTF-8 text (file names may be any bytes)",
            arg.to_string_lossy(),
            bytes
                .get(at)
                .map_or(String::new(), |b| format!("0x{b:02X}")),
        ),
    )
}

/// The one place where failures are rendered: the message on stderr, the JSON error object on
/// stdout with `--json`, and the exit code.
fn report(error: &Error, json: bool) -> ExitCode {
    if json {
        println!("{:#}", error.to_json());
    }
    eprintln!("{}", error.to_string().trim_end());
    ExitCode::from(error.exit_code())
}

/// Last resort: a bug must not end in a raw backtrace. Print what was being run, and exit 3.
fn install_panic_hook(json: bool) {
    std::panic::set_hook(Box::new(move |info| {
        let args: Vec<String> = std::env::args_os()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let what = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let error = Error::Internal {
            message: format!("{what}{place} (while running `{}`)", args.join(" ")),
        };
        report(&error, json);
        std::process::exit(error.exit_code().into());
    }));
}

fn main() -> ExitCode {
    // The library's messages name options as this front end does: `--t-end`, not `t_end`.
    pdyn::options::name_options_as(pdyn::options::Naming::Flags);
    let json = wants_json();
    install_panic_hook(json);
    // For the test of the panic hook: a bug on demand.
    if std::env::var_os("PDYN_DEBUG_PANIC").is_some() {
        panic!("PDYN_DEBUG_PANIC is set");
    }
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) if e.kind() == clap::error::ErrorKind::InvalidUtf8 => {
            // Clap says only "invalid UTF-8 was detected in one or more arguments": name it.
            return report(&invalid_utf8_argument(), json);
        }
        Err(e) => {
            if json {
                let error = Error::argument("", e.to_string().trim_end());
                println!("{:#}", error.to_json());
            }
            let _ = e.print();
            return ExitCode::from(2);
        }
    };
    // Expressions are trees and the symbolic algorithms recurse over them: a long sum typed on
    // the command line is a deep tree. The work runs on a thread whose stack is large enough
    // for any input within the size limits (the memory is reserved, not committed).
    let worker = std::thread::Builder::new()
        .name("pdyn".into())
        .stack_size(WORKER_STACK)
        .spawn(move || dispatch(cli.command));
    let result = match worker {
        Ok(handle) => match handle.join() {
            Ok(result) => result,
            // The panic hook has already reported and exited; this is unreachable in practice.
            Err(_) => Err(Error::Internal {
                message: "the worker thread panicked".into(),
            }),
        },
        Err(e) => Err(Error::Internal {
            message: format!("cannot start the worker thread: {e}"),
        }),
    };
    match result {
        Ok(outcome) => {
            print!("{}", outcome.stdout);
            eprint!("{}", outcome.stderr);
            match outcome.failure {
                None => ExitCode::SUCCESS,
                Some(error) => {
                    eprintln!("{}", error.to_string().trim_end());
                    ExitCode::from(error.exit_code())
                }
            }
        }
        Err(error) => report(&error, json),
    }
}
