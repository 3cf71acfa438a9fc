//! `pdyn`: the command-line front end. Thin by design: parse arguments, call the library,
//! print. Every error becomes a message and a non-zero exit code here, and only here.

mod derive_cmd;
mod dsolve_cmd;
mod expr_cmd;
mod forces_cmd;
mod kin_cmd;
mod plots;
mod run_cmd;
mod sweep_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Analyze the motion of systems of particles.
#[derive(Parser, Debug)]
#[command(name = "pdyn", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simplify an expression (Pythagorean identity, common factors, collected terms).
    Simplify(expr_cmd::SimplifyArgs),
    /// Differentiate an expression with respect to a symbol, or in time (`--wrt t`).
    Diff(expr_cmd::DiffArgs),
    /// Solve equations that are linear in the chosen unknowns, exactly.
    Solve(expr_cmd::SolveArgs),
    /// Evaluate an expression numerically.
    Eval(expr_cmd::EvalArgs),
    /// Derive the equations of motion of a model file.
    Derive(derive_cmd::DeriveArgs),
    /// Forces required by a prescribed motion (reactions, thrust, bank angle) and design checks (slip, tip).
    Forces(forces_cmd::ForcesArgs),
    /// Simulate a model file: integrate, check conservation laws, write CSV/JSON/plots.
    Run(run_cmd::RunArgs),
    /// Integrate numerically and compare with the closed-form solution (linear models).
    Check(run_cmd::CheckArgs),
    /// Run a model's [sweep] over parameter values in parallel and tabulate response measures.
    Sweep(sweep_cmd::SweepArgs),
    /// Solve linear constant-coefficient ODEs and systems in closed form, and the 1-D motion rules.
    Dsolve(dsolve_cmd::DsolveArgs),
    /// Kinematics of a particle: velocity, acceleration, normal-tangential and polar components.
    Kin(kin_cmd::KinArgs),
}

/// Ends a command that reports warnings on stderr and may fail after producing output
/// (exit 1: a run whose integration failed; exit 2: nothing could be done).
fn finish(result: Result<(String, String, bool), String>) -> ExitCode {
    match result {
        Ok((out, err, ok)) => {
            print!("{out}");
            eprint!("{err}");
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Err(msg) => {
            eprintln!("{}", msg.trim_end());
            ExitCode::from(2)
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Simplify(a) => expr_cmd::simplify(a),
        Command::Diff(a) => expr_cmd::diff(a),
        Command::Solve(a) => expr_cmd::solve(a),
        Command::Eval(a) => expr_cmd::eval(a),
        Command::Derive(a) => derive_cmd::run(a),
        Command::Forces(a) => forces_cmd::run(a),
        Command::Sweep(a) => return finish(sweep_cmd::run(a)),
        Command::Check(a) => return finish(run_cmd::check(a)),
        Command::Run(a) => return finish(run_cmd::run(a)),
        Command::Dsolve(a) => dsolve_cmd::run(a),
        Command::Kin(a) => kin_cmd::run(a),
    };
    match result {
        Ok(out) => {
            print!("{out}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprint!("{msg}");
            if !msg.ends_with('\n') {
                eprintln!();
            }
            ExitCode::from(2)
        }
    }
}
