//! The fit's plots: `fit` (each measured column, data as dots and the fitted model as a line,
//! one panel per experiment and column) and `residuals` (model − data against time).

use super::FitResult;
use crate::plots::both;
use crate::Error;
use pdyn_plot::{save_grid, Figure, Marker, Series, Style};
use std::path::Path;

/// Writes `fit.{svg,png}` and `residuals.{svg,png}` into `dir`.
pub fn write(res: &FitResult, dir: &Path) -> Result<(), Error> {
    let mut fits = Vec::new();
    let mut residuals = Vec::new();
    let several = res.experiments.len() > 1;
    for e in &res.experiments {
        for c in &e.columns {
            let title = if several {
                format!("{} ({})", c.name, e.name)
            } else {
                c.name.clone()
            };
            fits.push(Figure {
                title: format!("{title}: data (dots) and fit"),
                x_label: "t [s]".into(),
                y_label: c.name.clone(),
                series: vec![Series::new("fit", e.t.clone(), c.model.clone())],
                markers: e
                    .t
                    .iter()
                    .zip(&c.data)
                    .map(|(&t, &y)| Marker::point(t, y, ""))
                    .collect(),
                ..Default::default()
            });
            residuals.push(Figure {
                title: format!("{title}: residual (RMS {:.3e})", c.rms),
                x_label: "t [s]".into(),
                y_label: format!("{} fit − data", c.name),
                series: vec![Series::new(
                    "residual",
                    e.t.clone(),
                    c.model.iter().zip(&c.data).map(|(a, b)| a - b).collect(),
                )],
                style: Style::Points,
                markers: vec![Marker::hline(0.0, "")],
                ..Default::default()
            });
        }
    }
    let cols = if fits.len() == 1 { 1 } else { 2 };
    both(dir, "fit", |p| save_grid(&fits, cols, p))?;
    both(dir, "residuals", |p| save_grid(&residuals, cols, p))?;
    Ok(())
}
