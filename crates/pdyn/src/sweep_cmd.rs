//! `pdyn sweep MODEL`: the model's `[sweep]`, in parallel, with a progress bar.

use crate::run_cmd::{settings, RunArgs};
use clap::Args;
use pdyn::sim::{self, sweep};
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

/// `pdyn sweep MODEL`. Returns (stdout, stderr, success).
pub fn run(a: SweepArgs) -> Result<(String, String, bool), String> {
    let mut model = crate::derive_cmd::load(&a.run.model)?;
    crate::forces_cmd::apply_set(&mut model, &a.run.set)?;
    let Some(spec) = model.run.sweep.clone() else {
        return Err(format!(
            "{}: error: the model has no [sweep] table\n  = help: add [sweep] with parameter, values (or from/to/steps) and [sweep.measures]",
            model.origin
        ));
    };
    let set = settings(&model, &a.run)?;
    let prep = sim::prepare(&mut model)?;
    let stats: Vec<_> = model
        .run
        .sweep
        .as_ref()
        .map_or(Vec::new(), |s| s.measures.iter().map(|m| m.stat).collect());
    let progress = std::io::stderr().is_terminal() && !a.run.json;
    let res = match a.threads {
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build()
                .map_err(|e| format!("cannot start {n} threads: {e}"))?;
            let owned = prep.clone();
            pool.install(move || sweep::sweep(&owned, &set, &spec, &stats, progress))
        }
        None => sweep::sweep(&prep, &set, &spec, &stats, progress),
    };
    let mut err = String::new();
    for (v, p) in &res.problems {
        err += &format!("warning: {} = {v}: {p}\n", res.parameter);
    }
    let peaks: Vec<(String, Vec<(f64, f64)>)> = res
        .measures
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let y: Vec<f64> = res.table.iter().map(|r| r[j]).collect();
            (name.clone(), sweep::peaks(&res.values, &y))
        })
        .collect();
    if let Some(dir) = &a.run.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let mut csv = res.parameter.clone();
        for m in &res.measures {
            csv += &format!(",{m}");
        }
        csv.push('\n');
        for (v, row) in res.values.iter().zip(&res.table) {
            csv += &format!("{v:.17e}");
            for x in row {
                csv += &format!(",{x:.17e}");
            }
            csv.push('\n');
        }
        let path = dir.join("sweep.csv");
        std::fs::write(&path, csv).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        if a.run.plot {
            crate::plots::write_sweep_plot(&model, &res, &peaks, dir)?;
        }
    }
    let runs_per_s = res.values.len() as f64 / res.seconds.max(1e-9);
    if a.run.json {
        let v = json!({
            "model": model.name,
            "parameter": res.parameter,
            "runs": res.values.len(),
            "seconds": res.seconds,
            "runs_per_second": runs_per_s,
            "threads": res.threads,
            "values": res.values,
            "measures": res.measures.iter().enumerate().map(|(j, m)| json!({
                "name": m,
                "values": res.table.iter().map(|r| r[j]).collect::<Vec<_>>(),
                "peaks": peaks[j].1.iter().map(|(x, y)| json!({"at": x, "value": y})).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "problems": res.problems.iter().map(|(v, p)| json!({"value": v, "message": p})).collect::<Vec<_>>(),
        });
        return Ok((format!("{v:#}\n"), err, true));
    }
    let mut out = format!(
        "{}\nsweep over {} ({} values) in {:.3} s on {} threads: {:.1} runs/s\n",
        model.name,
        res.parameter,
        res.values.len(),
        res.seconds,
        res.threads,
        runs_per_s
    );
    for (name, pk) in &peaks {
        let list: Vec<String> = pk
            .iter()
            .map(|(x, y)| format!("{} = {x:.4} ({y:.4e})", res.parameter))
            .collect();
        out += &format!(
            "  {name}: peaks at {}\n",
            if list.is_empty() {
                "none".to_string()
            } else {
                list.join(", ")
            }
        );
    }
    if let Some(dir) = &a.run.out {
        out += &format!("wrote {}/sweep.csv\n", dir.display());
    }
    Ok((out, err, true))
}
