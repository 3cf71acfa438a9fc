//! Plots of runs and sweeps (pdyn-plot): written by `pdyn run --plot` and `pdyn sweep --plot`.
//!
//! A run gives `trajectory` (each particle's path: in the plane of motion with equal axes, or in
//! 3-D), `coordinates` (each coordinate against time, one panel each, events marked) and, when
//! pdyn monitors conserved quantities, `conservation` (their relative drift against time); a
//! hybrid run's mode switches and impacts are marked on the time plots and the trajectory. A
//! sweep gives `sweep` (each response measure against the parameter, peaks marked). Each is
//! written as SVG and PNG.

use crate::sim::sweep::SweepResult;
use crate::sim::{Prepared, RunResult};
use crate::Error;
use pdyn_plot::{save, save3, save_grid, Figure, Figure3, Marker, Series, Series3};
use std::path::Path;

pub(crate) fn both(
    dir: &Path,
    stem: &str,
    f: impl Fn(&Path) -> Result<(), pdyn_plot::PlotError>,
) -> Result<(), Error> {
    for ext in ["svg", "png"] {
        let path = dir.join(format!("{stem}.{ext}"));
        f(&path).map_err(|e| Error::Plot {
            path: path.clone(),
            error: e.to_string(),
        })?;
    }
    Ok(())
}

fn column(res: &RunResult, name: &str) -> Option<Vec<f64>> {
    let j = res.columns.iter().position(|c| c == name)?;
    Some(res.rows.iter().map(|r| r[j]).collect())
}

/// Writes the plots of a run into `dir`.
pub fn write_run_plots(
    model: &pdyn_mech::Model,
    prep: &Prepared,
    res: &RunResult,
    dir: &Path,
) -> Result<(), Error> {
    if res.rows.len() < 2 {
        return Err(Error::argument(
            crate::options::RunOption::Plot.name(),
            "too few output points to plot",
        ));
    }
    let t = column(res, "t").unwrap_or_default();
    let mut markers: Vec<Marker> = res
        .events
        .iter()
        .map(|e| Marker::vline(e.t, e.name.clone()))
        .collect();
    // A hybrid run's switches (labelled with the new mode) and impacts (the first labelled:
    // a bouncing ball has dozens), at their times; on the trajectory, where they happen.
    let mut switch_times = Vec::new();
    if let Some(h) = &res.hybrid {
        for sw in &h.switches {
            markers.push(Marker::vline(sw.t, format!("{} {}", sw.contact, sw.to)));
            switch_times.push((sw.t, format!("{} {}", sw.contact, sw.to)));
        }
        for (k, im) in h.impacts.iter().enumerate() {
            let label = if k == 0 {
                "impact".to_string()
            } else {
                String::new()
            };
            markers.push(Marker::vline(im.t, label.clone()));
            // An impact that ends in contact is marked once, by its switch.
            if !h.switches.iter().any(|sw| sw.t == im.t) {
                switch_times.push((im.t, label));
            }
        }
    }

    // Trajectory: the components that vary.
    let mut planar = Vec::new();
    let mut spatial = Vec::new();
    let mut axes_used = [false; 3];
    for (i, p) in model.particles.iter().enumerate() {
        // A net's position that is a coordinate is that coordinate's column.
        let comps: Vec<Option<Vec<f64>>> = ["x", "y", "z"]
            .iter()
            .enumerate()
            .map(|(k, a)| {
                column(res, &format!("{}.{a}", p.name)).or_else(|| {
                    crate::sim::net::position_column(model, i, k).and_then(|c| column(res, &c))
                })
            })
            .collect();
        let varies = |c: &Option<Vec<f64>>| {
            c.as_ref().is_some_and(|v| {
                let (lo, hi) = v
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                        (a.min(x), b.max(x))
                    });
                hi - lo > 1e-12 * (1.0 + hi.abs().max(lo.abs()))
            })
        };
        for (k, c) in comps.iter().enumerate() {
            axes_used[k] |= varies(c);
        }
        let get = |k: usize| comps[k].clone().unwrap_or_else(|| vec![0.0; t.len()]);
        spatial.push(Series3::new(p.name.clone(), get(0), get(1), get(2)));
        planar.push((p.name.clone(), [get(0), get(1), get(2)]));
    }
    let used: Vec<usize> = (0..3).filter(|&k| axes_used[k]).collect();
    let names = ["x [m]", "y [m]", "z [m]"];
    if used.len() == 3 {
        let fig = Figure3 {
            title: format!("{}: trajectory", model.name),
            labels: names.map(String::from),
            series: spatial,
        };
        both(dir, "trajectory", |p| save3(&fig, p))?;
    } else if used.len() == 2 {
        let (a, b) = (used[0], used[1]);
        // The particles' positions at each switch, interpolated between the output rows
        // around it (the positions are continuous through every switch).
        let mut at_switches = Vec::new();
        for (ts, label) in &switch_times {
            let k = t.partition_point(|x| x <= ts);
            if k == 0 || k > t.len() {
                continue;
            }
            let (k0, k1) = (k - 1, k.min(t.len() - 1));
            let w = if t[k1] > t[k0] {
                (ts - t[k0]) / (t[k1] - t[k0])
            } else {
                0.0
            };
            let at = |v: &[f64]| v[k0] + w * (v[k1] - v[k0]);
            for (name, c) in &planar {
                let label = if planar.len() > 1 && !label.is_empty() {
                    format!("{name}: {label}")
                } else {
                    label.clone()
                };
                at_switches.push(Marker::point(at(&c[a]), at(&c[b]), label));
            }
        }
        let fig = Figure {
            title: format!("{}: trajectory", model.name),
            x_label: names[a].into(),
            y_label: names[b].into(),
            series: planar
                .iter()
                .map(|(n, c)| Series::new(n.clone(), c[a].clone(), c[b].clone()))
                .collect(),
            equal_aspect: true,
            markers: at_switches,
            ..Default::default()
        };
        both(dir, "trajectory", |p| save(&fig, p))?;
    }

    // Coordinates against time.
    let n = prep.system.n;
    let panels: Vec<Figure> = prep.state_names[..n]
        .iter()
        .filter_map(|name| {
            let y = column(res, name)?;
            Some(Figure {
                title: name.clone(),
                x_label: "t [s]".into(),
                y_label: name.clone(),
                series: vec![Series::new(name.clone(), t.clone(), y)],
                markers: markers.clone(),
                ..Default::default()
            })
        })
        .collect();
    if !panels.is_empty() {
        let cols = if panels.len() == 1 { 1 } else { 2 };
        both(dir, "coordinates", |p| save_grid(&panels, cols, p))?;
    }

    // Drift of the conserved quantities.
    let mut series = Vec::new();
    for m in &res.monitors {
        if let Some(v) = column(res, &m.name) {
            let scale = if m.relative { m.scale } else { 1.0 };
            let d: Vec<f64> = v.iter().map(|x| (x - m.initial) / scale).collect();
            let label = if m.relative {
                format!("({0} - {0}(0))/{1:.3e}", m.name, m.scale)
            } else {
                format!("{0} - {0}(0)", m.name)
            };
            series.push(Series::new(label, t.clone(), d));
        }
    }
    if !series.is_empty() {
        let fig = Figure {
            title: format!("Conserved quantities ({}): drift", res.method),
            x_label: "t [s]".into(),
            y_label: "drift".into(),
            series,
            markers: vec![Marker::hline(0.0, "")],
            ..Default::default()
        };
        both(dir, "conservation", |p| save(&fig, p))?;
    }
    Ok(())
}

/// Writes the sweep's response curves with their peaks into `dir`: one curve per measure and
/// per combination of the other swept parameters.
pub fn write_sweep_plot(
    model: &pdyn_mech::Model,
    res: &SweepResult,
    peaks: &[crate::sim::sweep::Peaks],
    dir: &Path,
) -> Result<(), Error> {
    let mut series = Vec::new();
    let mut markers = Vec::new();
    for (sl, pk) in res.slices.iter().zip(peaks) {
        let suffix = if sl.fixed.is_empty() {
            String::new()
        } else {
            let f: Vec<String> = sl.fixed.iter().map(|(n, v)| format!("{n} = {v}")).collect();
            format!(" ({})", f.join(", "))
        };
        for (j, name) in res.measures.iter().enumerate() {
            let y: Vec<f64> = sl.table.iter().map(|r| r[j]).collect();
            series.push(Series::new(
                format!("{name}{suffix}"),
                res.values.clone(),
                y,
            ));
            if let Some((_, list)) = pk.iter().find(|(n, _)| n == name) {
                for (x, v) in list {
                    markers.push(Marker::point(*x, *v, format!("{} = {x:.2}", res.parameter)));
                }
            }
        }
    }
    if series.is_empty() {
        return Err(Error::argument(
            crate::options::RunOption::Plot.name(),
            "the sweep has no measures to plot: add [sweep.measures]",
        ));
    }
    let fig = Figure {
        title: format!("{}: response vs {}", model.name, res.parameter),
        x_label: res.parameter.clone(),
        y_label: if res.measures.len() == 1 {
            res.measures[0].clone()
        } else {
            "response".into()
        },
        series,
        markers,
        ..Default::default()
    };
    both(dir, "sweep", |p| save(&fig, p))
}
