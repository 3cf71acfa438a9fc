//! Plots of an N-body run (`pdyn run --plot`): `orbits` (x–y projection, equal axes),
//! `orbits_3d` (when the motion leaves the plane), `elements` (a, e and inc of each body
//! against time) and `conservation` (the relative energy error and the virial ratio against
//! time). Each as SVG and PNG. Runs without per-body trajectories (large N) get
//! `conservation` and `positions` (the final x–y positions as dots).

use super::run::NbodyResult;
use super::spec::UnitsSpec;
use crate::plots::both;
use crate::Error;
use pdyn_plot::{save, save3, save_grid, Figure, Figure3, Marker, Series, Series3, Style};
use std::path::Path;

/// Most bodies drawn as individual curves (the rest would make an unreadable legend).
const MAX_CURVES: usize = 20;

/// Writes the plots of `res` into `dir`; axes carry the units of `units` (`x [AU]`,
/// `t [days]`).
pub fn write(title: &str, res: &NbodyResult, units: &UnitsSpec, dir: &Path) -> Result<(), Error> {
    let (length, time) = units.length_time();
    let (lx, ly, lz, lt) = (
        format!("x [{length}]"),
        format!("y [{length}]"),
        format!("z [{length}]"),
        format!("t [{time}]"),
    );
    if res.times.len() < 2 {
        return Err(Error::argument(
            crate::options::RunOption::Plot.name(),
            "too few output points to plot",
        ));
    }
    let markers: Vec<Marker> = res
        .events
        .iter()
        .map(|e| Marker::vline(e.t, e.kind))
        .collect();
    if !res.states.is_empty() {
        // One curve per body over the outputs it existed for.
        let n_names = res.names.len().min(MAX_CURVES);
        let mut xyz: Vec<[Vec<f64>; 3]> = vec![[Vec::new(), Vec::new(), Vec::new()]; n_names];
        for states in &res.states {
            for s in states.iter().filter(|s| s.body < n_names) {
                for (c, &x) in xyz[s.body].iter_mut().zip(&s.pos) {
                    c.push(x);
                }
            }
        }
        let planar: Vec<Series> = xyz
            .iter()
            .zip(&res.names)
            .filter(|(c, _)| !c[0].is_empty())
            .map(|(c, n)| Series::new(n.clone(), c[0].clone(), c[1].clone()))
            .collect();
        let fig = Figure {
            title: format!("{title}: orbits (x-y projection)"),
            x_label: lx.clone(),
            y_label: ly.clone(),
            series: planar,
            equal_aspect: true,
            ..Default::default()
        };
        both(dir, "orbits", |p| save(&fig, p))?;
        let extent = |k: usize| {
            xyz.iter()
                .flat_map(|c| c[k].iter())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                })
        };
        let ((xlo, xhi), (ylo, yhi), (zlo, zhi)) = (extent(0), extent(1), extent(2));
        let scale = (xhi - xlo).max(yhi - ylo);
        // A 3-D view only when the z extent is visible next to the x–y extent.
        if zhi - zlo > 1e-3 * scale {
            let fig = Figure3 {
                title: format!("{title}: orbits"),
                labels: [lx.clone(), ly.clone(), lz],
                series: xyz
                    .iter()
                    .zip(&res.names)
                    .filter(|(c, _)| !c[0].is_empty())
                    .map(|(c, n)| Series3::new(n.clone(), c[0].clone(), c[1].clone(), c[2].clone()))
                    .collect(),
            };
            both(dir, "orbits_3d", |p| save3(&fig, p))?;
        }
        let mut panels = Vec::new();
        let a_label = format!("a [{length}]");
        for (label, get) in [
            (
                a_label.as_str(),
                (|o: &pdyn_gravity::Orbit| o.a) as fn(&pdyn_gravity::Orbit) -> f64,
            ),
            ("e", |o| o.e),
            ("inc [rad]", |o| o.inc),
        ] {
            let mut series = Vec::new();
            for (b, name) in res.names.iter().enumerate().take(MAX_CURVES) {
                let (t, y): (Vec<f64>, Vec<f64>) = res
                    .elements
                    .iter()
                    .filter(|r| r.body == b)
                    .map(|r| (r.t, r.orbit.as_ref().map_or(f64::NAN, get)))
                    .unzip();
                if !t.is_empty() {
                    series.push(Series::new(name.clone(), t, y));
                }
            }
            if !series.is_empty() {
                panels.push(Figure {
                    title: format!("{label} against time"),
                    x_label: lt.clone(),
                    y_label: label.into(),
                    series,
                    markers: markers.clone(),
                    ..Default::default()
                });
            }
        }
        if !panels.is_empty() {
            both(dir, "elements", |p| save_grid(&panels, 1, p))?;
        }
    } else {
        let (x, y) = res.final_positions.iter().map(|p| (p[0], p[1])).unzip();
        write_positions(title, x, y, (&lx, &ly), dir)?;
    }
    let t: Vec<f64> = res.conservation.iter().map(|r| r.t).collect();
    let e0 = res.conservation[0].energy;
    let de: Vec<f64> = res
        .conservation
        .iter()
        .map(|r| (r.energy - e0) / e0.abs())
        .collect();
    let virial: Vec<f64> = res
        .conservation
        .iter()
        .map(|r| 2.0 * r.kinetic / r.potential.abs())
        .collect();
    let panels = vec![
        Figure {
            title: "relative energy error".into(),
            x_label: lt.clone(),
            y_label: "(E - E0)/|E0|".into(),
            series: vec![Series::new("energy", t.clone(), de)],
            markers: markers.clone(),
            ..Default::default()
        },
        Figure {
            title: "virial ratio".into(),
            x_label: lt,
            y_label: "2T/|V|".into(),
            series: vec![Series::new("2T/|V|", t, virial)],
            markers,
            ..Default::default()
        },
    ];
    both(dir, "conservation", |p| save_grid(&panels, 1, p))?;
    Ok(())
}

/// The final positions of a large-N run, as dots (x–y projection).
fn write_positions(
    title: &str,
    x: Vec<f64>,
    y: Vec<f64>,
    (lx, ly): (&str, &str),
    dir: &Path,
) -> Result<(), Error> {
    let fig = Figure {
        title: format!("{title}: positions at the end (x-y projection)"),
        x_label: lx.into(),
        y_label: ly.into(),
        series: vec![Series::new("bodies", x, y)],
        style: Style::Points,
        equal_aspect: true,
        ..Default::default()
    };
    both(dir, "positions", |p| save(&fig, p))
}
