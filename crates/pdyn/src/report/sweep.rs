//! `pdyn sweep`'s output: the model's `[sweep]` run in parallel (rayon), the measures' peaks
//! along the first parameter, `sweep.csv` (and a plot) when a directory is given.

use super::Report;
use crate::sim::{self, sweep};
use crate::{Error, Request};
use serde_json::json;

/// Runs `model`'s `[sweep]` (parameters set) with the options of `req` on `threads` threads
/// (rayon's global pool when `None`); `on_run(done, all)` after each run. Text, or JSON when
/// `json`.
pub fn report(
    mut model: pdyn_mech::Model,
    req: &Request,
    threads: Option<usize>,
    json: bool,
    on_run: &(dyn Fn(usize, usize) + Sync),
) -> Result<Report, Error> {
    let Some(spec) = model.run.sweep.clone() else {
        return Err(Error::argument(
            &model.origin,
            format!(
                "{}: error: the model has no [sweep] table\n  = help: add [sweep] with parameter, values (or from/to/steps) and [sweep.measures]",
                model.origin
            ),
        ));
    };
    crate::engine::plots_available(req)?;
    let set = sim::request::settings(&model, req)?;
    let mut prep = sim::request::prepare(&mut model, req.jit)?;
    // Measures and monitors evaluated at every output of every run: native code, as in Python.
    if req.jit != sim::JitMode::Off {
        prep.make_observers_native();
    }
    let stats: Vec<_> = model
        .run
        .sweep
        .as_ref()
        .map_or(Vec::new(), |s| s.measures.iter().map(|m| m.stat).collect());
    let progress = on_run;
    let res = match threads {
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
    .map_err(|e| sim::request::located(&model, "", e))?;
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
    if let Some(dir) = &req.out {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create", e))?;
        // Measures are named by the user (`max(x[0,1])`): the header quotes what needs it.
        let mut names = vec![res.parameter.as_str()];
        if let Some(sl) = res.slices.first() {
            names.extend(sl.fixed.iter().map(|(n, _)| n.as_str()));
        }
        names.extend(res.measures.iter().map(String::as_str));
        let mut csv = crate::output::csv_header(&names);
        for sl in &res.slices {
            for (v, row) in res.values.iter().zip(&sl.table) {
                crate::output::push_number(&mut csv, *v);
                for (_, x) in &sl.fixed {
                    csv.push(',');
                    crate::output::push_number(&mut csv, *x);
                }
                for x in row {
                    csv.push(',');
                    crate::output::push_number(&mut csv, *x);
                }
                csv.push('\n');
            }
        }
        let path = dir.join("sweep.csv");
        std::fs::write(&path, csv).map_err(|e| Error::io(&path, "write", e))?;
        if req.plots {
            #[cfg(feature = "plots")]
            crate::plots::write_sweep_plot(&model, &res, &peaks, dir)?;
        }
    }
    let runs_per_s = res.runs as f64 / res.seconds.max(1e-9);
    let fixed_text = |sl: &sweep::Slice| -> String {
        let f: Vec<String> = sl.fixed.iter().map(|(n, v)| format!("{n} = {v}")).collect();
        f.join(", ")
    };
    if json {
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
        return Ok(Report {
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
    if let Some(dir) = &req.out {
        out += &format!("wrote {}/sweep.csv\n", dir.display());
    }
    Ok(Report {
        stdout: out,
        stderr: err,
        failure: None,
    })
}
