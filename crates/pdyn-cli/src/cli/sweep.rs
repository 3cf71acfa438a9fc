//! `pdyn sweep MODEL`: the model's `[sweep]`, in parallel, with a progress bar.

use super::run::{settings, sim_error, RunArgs};
use super::{load_model, set_parameters, Outcome};
use clap::Args;
use pdyn::sim::sweep;
use pdyn::Error;
use serde_json::json;
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

/// `pdyn sweep MODEL`.
pub fn run(a: SweepArgs) -> Result<Outcome, Error> {
    let mut model = load_model(&a.run.model)?;
    set_parameters(&mut model, &a.run.set)?;
    let Some(spec) = model.run.sweep.clone() else {
        return Err(Error::argument(
            &model.origin,
            format!(
                "{}: error: the model has no [sweep] table\n  = help: add [sweep] with parameter, values (or from/to/steps) and [sweep.measures]",
                model.origin
            ),
        ));
    };
    let set = settings(&model, &a.run)?;
    let mut prep = super::run::prepare(&mut model, &a.run)?;
    // Measures and monitors evaluated at every output of every run: native code, as in Python.
    if !a.run.no_jit {
        prep.make_observers_native();
    }
    let stats: Vec<_> = model
        .run
        .sweep
        .as_ref()
        .map_or(Vec::new(), |s| s.measures.iter().map(|m| m.stat).collect());
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
    let res = match a.threads {
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build()
                .map_err(|e| {
                    Error::argument("--threads", format!("cannot start {n} threads: {e}"))
                })?;
            let owned = prep.clone();
            let on_run = &progress;
            pool.install(move || sweep::sweep(&owned, &set, &spec, &stats, on_run))
        }
        None => sweep::sweep(&prep, &set, &spec, &stats, &progress),
    }
    .map_err(|e| sim_error(&model, "", e))?;
    bar.finish_and_clear();
    let mut err = String::new();
    for (at, p) in &res.problems {
        let at: Vec<String> = at.iter().map(|(n, v)| format!("{n} = {v}")).collect();
        err += &format!("warning: {}: {p}\n", at.join(", "));
    }
    // Peaks along the first parameter, per slice and measure.
    let peaks: Vec<sweep::Peaks> = res
        .slices
        .iter()
        .map(|sl| {
            res.measures
                .iter()
                .enumerate()
                .map(|(j, name)| {
                    let y: Vec<f64> = sl.table.iter().map(|r| r[j]).collect();
                    (name.clone(), sweep::peaks(&res.values, &y))
                })
                .collect()
        })
        .collect();
    if let Some(dir) = &a.run.out {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create", e))?;
        let mut csv = res.parameter.clone();
        if let Some(sl) = res.slices.first() {
            for (n, _) in &sl.fixed {
                csv += &format!(",{n}");
            }
        }
        for m in &res.measures {
            csv += &format!(",{m}");
        }
        csv.push('\n');
        for sl in &res.slices {
            for (v, row) in res.values.iter().zip(&sl.table) {
                pdyn::output::push_number(&mut csv, *v);
                for (_, x) in &sl.fixed {
                    csv.push(',');
                    pdyn::output::push_number(&mut csv, *x);
                }
                for x in row {
                    csv.push(',');
                    pdyn::output::push_number(&mut csv, *x);
                }
                csv.push('\n');
            }
        }
        let path = dir.join("sweep.csv");
        std::fs::write(&path, csv).map_err(|e| Error::io(&path, "write", e))?;
        if a.run.plot {
            pdyn::plots::write_sweep_plot(&model, &res, &peaks, dir)?;
        }
    }
    let runs_per_s = res.runs as f64 / res.seconds.max(1e-9);
    let fixed_text = |sl: &sweep::Slice| -> String {
        let f: Vec<String> = sl.fixed.iter().map(|(n, v)| format!("{n} = {v}")).collect();
        f.join(", ")
    };
    if a.run.json {
        let v = json!({
            "model": model.name,
            "parameter": res.parameter,
            "runs": res.runs,
            "seconds": res.seconds,
            "runs_per_second": runs_per_s,
            "threads": res.threads,
            "values": res.values,
            "slices": res.slices.iter().zip(&peaks).map(|(sl, pk)| json!({
                "fixed": sl.fixed.iter().map(|(n, v)| (n.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                "measures": res.measures.iter().enumerate().map(|(j, m)| json!({
                    "name": m,
                    "values": sl.table.iter().map(|r| r[j]).collect::<Vec<_>>(),
                    "peaks": pk[j].1.iter().map(|(x, y)| json!({"at": x, "value": y})).collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "problems": res.problems.iter().map(|(at, p)| json!({
                "at": at.iter().map(|(n, v)| (n.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                "message": p.to_string(),
            })).collect::<Vec<_>>(),
        });
        return Ok(Outcome {
            stdout: format!("{v:#}\n"),
            stderr: err,
            failure: None,
        });
    }
    let mut out = format!(
        "{}\nsweep over {} ({} runs) in {:.3} s on {} threads: {:.1} runs/s\n",
        model.name,
        if res.slices.len() > 1 {
            format!(
                "{} x {} combinations of the others",
                res.parameter,
                res.slices.len()
            )
        } else {
            res.parameter.clone()
        },
        res.runs,
        res.seconds,
        res.threads,
        runs_per_s
    );
    for (sl, pk) in res.slices.iter().zip(&peaks) {
        let prefix = if sl.fixed.is_empty() {
            String::new()
        } else {
            format!("[{}] ", fixed_text(sl))
        };
        for (name, p) in pk {
            let list: Vec<String> = p
                .iter()
                .map(|(x, y)| format!("{} = {x:.4} ({y:.4e})", res.parameter))
                .collect();
            out += &format!(
                "  {prefix}{name}: peaks at {}\n",
                if list.is_empty() {
                    "none".to_string()
                } else {
                    list.join(", ")
                }
            );
        }
    }
    if let Some(dir) = &a.run.out {
        out += &format!("wrote {}/sweep.csv\n", dir.display());
    }
    Ok(Outcome {
        stdout: out,
        stderr: err,
        failure: None,
    })
}
