//! `pdyn sweep MODEL`: the model's `[sweep]`, in parallel, with a progress bar.

use super::run::{request, RunArgs};
use super::{load_model, set_parameters, Outcome};
use clap::Args;
use pdyn::Error;
use std::io::IsTerminal;

/// `pdyn sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

/// `pdyn sweep MODEL`: the library's sweep report, with a progress bar.
pub fn run(a: SweepArgs) -> Result<Outcome, Error> {
    let mut model = load_model(&a.run.model)?;
    set_parameters(&mut model, &a.run.set)?;
    let bar = if std::io::stderr().is_terminal() && !a.run.json {
        let b = indicatif::ProgressBar::new(0);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{spinner} sweep [{bar:40}] {pos}/{len} runs, {per_sec}, eta {eta}",
        ) {
            b.set_style(style.progress_chars("=> "));
        }
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let progress = |done: usize, all: usize| {
        bar.set_length(all as u64);
        bar.set_position(done as u64);
    };
    let rep =
        pdyn::report::sweep::report(model, &request(&a.run)?, a.threads, a.run.json, &progress);
    bar.finish_and_clear();
    let rep = rep?;
    Ok(Outcome {
        stdout: rep.stdout,
        stderr: rep.stderr,
        failure: rep.failure,
    })
}
