//! Publication-quality plots of simulation results: data in, SVG or PNG file
//! out.
//!
//! * [`Figure`] — 2-D line/point plot of one or more [`Series`], optionally
//!   with equal aspect (orbits look round) and labelled [`Marker`]s (event
//!   times, resonance peaks, …). Saved with [`save`], or rendered to a string
//!   with [`to_svg`] / to PNG bytes with [`to_png`].
//! * [`Figure3`] — 3-D trajectories ([`Series3`]) in a fixed oblique
//!   projection with the third coordinate (`z`) drawn vertical; [`save3`].
//! * [`save_grid`] — several [`Figure`]s as panels of one image ("small
//!   multiples", e.g. each coordinate against time).
//!
//! The output format is chosen from the file extension (`.svg` or `.png`,
//! case-insensitive). Text is rendered with an embedded copy of DejaVu Sans,
//! so nothing depends on system fonts or libraries. PNGs are drawn at three
//! times their size and downsampled (anti-aliased lines); SVGs are drawn
//! on a 4× finer grid and displayed at their size. Long series are thinned
//! to sub-pixel resolution, so files stay small.
//!
//! A legend appears when a figure has more than one series, in the corner
//! that hides the least data. Colours follow the Okabe–Ito palette (8
//! colours, then repeated). Rendering is thread-safe.
//!
//! Non-finite points (NaN, ±∞) are skipped; a line is broken where they
//! were. Invalid input gives a [`PlotError`], never a panic.
//!
//! ```no_run
//! use pdyn_plot::{save, Figure, Series};
//! let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.05).collect();
//! let fig = Figure {
//!     title: "Damped oscillator".into(),
//!     x_label: "t [s]".into(),
//!     y_label: "q [m]".into(),
//!     series: vec![Series::new("q", t.clone(), t.iter().map(|t| (-0.3 * t).exp() * t.cos()).collect())],
//!     ..Default::default()
//! };
//! save(&fig, std::path::Path::new("q.png"))?;
//! # Ok::<(), pdyn_plot::PlotError>(())
//! ```
#![warn(missing_docs)]

mod font;
mod layout;
mod output;
mod render2d;
mod render3d;
mod ticks;

use std::fmt;
use std::path::{Path, PathBuf};

pub use layout::{data_ranges, equal_aspect_ranges, layout, Layout};

/// Default image size in pixels (width, height) of [`save`], [`save3`],
/// [`to_svg`] and [`to_png`].
pub const DEFAULT_SIZE: (u32, u32) = (1000, 700);

/// Size in pixels of one panel of [`save_grid`].
pub const PANEL_SIZE: (u32, u32) = (640, 440);

/// One 2-D data series: `y` against `x`, drawn in the next palette colour.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Name shown in the legend (the legend appears when a figure has more
    /// than one series; an empty label is shown as "series N").
    pub label: String,
    /// Abscissae. Must have the same length as `y`.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
}

impl Series {
    /// A series from its label and coordinates.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
        }
    }
}

/// One 3-D trajectory: points `(x[i], y[i], z[i])`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series3 {
    /// Name shown in the legend (when there is more than one series).
    pub label: String,
    /// First coordinate (horizontal).
    pub x: Vec<f64>,
    /// Second coordinate (horizontal, depth).
    pub y: Vec<f64>,
    /// Third coordinate, drawn vertical (height).
    pub z: Vec<f64>,
}

impl Series3 {
    /// A 3-D series from its label and coordinates.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, z: Vec<f64>) -> Self {
        Series3 {
            label: label.into(),
            x,
            y,
            z,
        }
    }
}

/// How the series of a [`Figure`] are drawn.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Style {
    /// Connected lines (broken at non-finite points).
    #[default]
    Line,
    /// Dots at the data points.
    Points,
    /// Lines with dots at the data points.
    LineAndPoints,
}

/// A labelled annotation of a [`Figure`], drawn in dark grey over the data.
#[derive(Debug, Clone, PartialEq)]
pub enum Marker {
    /// Dashed vertical line at abscissa `x` (e.g. an event time), label at
    /// the top of the plot.
    VLine {
        /// Abscissa of the line.
        x: f64,
        /// Text next to the line (may be empty).
        label: String,
    },
    /// Dashed horizontal line at ordinate `y` (e.g. a reference level),
    /// label at its right end.
    HLine {
        /// Ordinate of the line.
        y: f64,
        /// Text above the line (may be empty).
        label: String,
    },
    /// A highlighted point (e.g. a resonance peak) with its label.
    Point {
        /// Abscissa of the point.
        x: f64,
        /// Ordinate of the point.
        y: f64,
        /// Text next to the point (may be empty).
        label: String,
    },
}

impl Marker {
    /// A vertical line marker at `x`.
    pub fn vline(x: f64, label: impl Into<String>) -> Self {
        Marker::VLine {
            x,
            label: label.into(),
        }
    }
    /// A horizontal line marker at `y`.
    pub fn hline(y: f64, label: impl Into<String>) -> Self {
        Marker::HLine {
            y,
            label: label.into(),
        }
    }
    /// A point marker at `(x, y)`.
    pub fn point(x: f64, y: f64, label: impl Into<String>) -> Self {
        Marker::Point {
            x,
            y,
            label: label.into(),
        }
    }
}

/// A 2-D plot. Build it as a struct literal, with `..Default::default()` for
/// the fields you don't need.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Figure {
    /// Title above the plot (may be empty).
    pub title: String,
    /// Label of the horizontal axis, with units, e.g. `"t [s]"`.
    pub x_label: String,
    /// Label of the vertical axis, with units.
    pub y_label: String,
    /// The data, drawn in order, one palette colour each.
    pub series: Vec<Series>,
    /// Lines, points or both.
    pub style: Style,
    /// Same data units per pixel on both axes (a circular orbit looks like a
    /// circle): the shorter range is widened, centred.
    pub equal_aspect: bool,
    /// Labelled vertical/horizontal lines or points drawn over the data.
    /// Non-finite markers are skipped.
    pub markers: Vec<Marker>,
}

/// A 3-D trajectory plot (oblique projection, `z` vertical, a grey shadow
/// of each curve on the floor, start and end points marked).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Figure3 {
    /// Title above the plot (may be empty).
    pub title: String,
    /// Axis labels with units, for x, y and z.
    pub labels: [String; 3],
    /// The trajectories.
    pub series: Vec<Series3>,
}

/// Why a plot could not be made.
#[derive(Debug)]
#[non_exhaustive]
pub enum PlotError {
    /// The figure has no series at all.
    NoSeries {
        /// Title of the offending figure.
        title: String,
    },
    /// A series has no points.
    EmptySeries {
        /// Label of the series.
        label: String,
    },
    /// The coordinate vectors of a series have different lengths.
    LengthMismatch {
        /// Label of the series.
        label: String,
        /// Lengths of x, y (and z for 3-D series).
        lengths: Vec<usize>,
    },
    /// Every point of a series has a NaN or infinite coordinate.
    NoFiniteData {
        /// Label of the series.
        label: String,
    },
    /// The path's extension is not `.svg` or `.png`.
    UnsupportedFormat {
        /// The path given.
        path: PathBuf,
    },
    /// The file could not be written.
    Io {
        /// The path given.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Invalid argument: zero columns, no panels, a too small image size…
    InvalidArgument {
        /// What is wrong.
        message: String,
    },
    /// The drawing library or the PNG encoder failed (should not happen).
    Render {
        /// The underlying message.
        message: String,
    },
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlotError::NoSeries { title } => {
                write!(f, "figure {title:?} has no data series to plot")
            }
            PlotError::EmptySeries { label } => write!(f, "series {label:?} has no points"),
            PlotError::LengthMismatch { label, lengths } => write!(
                f,
                "series {label:?}: coordinate vectors have different lengths {lengths:?}"
            ),
            PlotError::NoFiniteData { label } => write!(
                f,
                "series {label:?} has no finite point (all NaN or infinite)"
            ),
            PlotError::UnsupportedFormat { path } => write!(
                f,
                "cannot tell the image format of {}: use a .svg or .png extension",
                path.display()
            ),
            PlotError::Io { path, source } => {
                write!(f, "cannot write {}: {source}", path.display())
            }
            PlotError::InvalidArgument { message } => write!(f, "invalid argument: {message}"),
            PlotError::Render { message } => write!(f, "rendering failed: {message}"),
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PlotError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl PlotError {
    pub(crate) fn render(e: impl fmt::Display) -> Self {
        PlotError::Render {
            message: e.to_string(),
        }
    }
}

/// Image file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics (text stays text).
    Svg,
    /// Portable network graphics (RGB, anti-aliased).
    Png,
}

impl Format {
    /// The format given by the extension of `path` (`.svg` or `.png`, any
    /// case).
    pub fn from_path(path: &Path) -> Result<Format, PlotError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(PlotError::UnsupportedFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// Saves `fig` to `path` at [`DEFAULT_SIZE`]; the format comes from the
/// extension (`.svg` or `.png`).
pub fn save(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    save_with_size(fig, path, DEFAULT_SIZE)
}

/// Like [`save`] with an explicit image size in pixels (at least 200×150).
pub fn save_with_size(fig: &Figure, path: &Path, size: (u32, u32)) -> Result<(), PlotError> {
    let format = Format::from_path(path)?;
    let bytes = match format {
        Format::Svg => render2d::svg(std::slice::from_ref(fig), 1, size)?.into_bytes(),
        Format::Png => render2d::png(std::slice::from_ref(fig), 1, size)?,
    };
    output::write(path, &bytes)
}

/// The SVG document of `fig` at [`DEFAULT_SIZE`].
pub fn to_svg(fig: &Figure) -> Result<String, PlotError> {
    render2d::svg(std::slice::from_ref(fig), 1, DEFAULT_SIZE)
}

/// The PNG file contents of `fig` at [`DEFAULT_SIZE`].
pub fn to_png(fig: &Figure) -> Result<Vec<u8>, PlotError> {
    render2d::png(std::slice::from_ref(fig), 1, DEFAULT_SIZE)
}

/// Saves several figures as panels of one image ("small multiples"), `cols`
/// panels per row, each panel [`PANEL_SIZE`]; the format comes from the
/// extension. Each panel has its own ranges, title, labels and legend.
pub fn save_grid(figs: &[Figure], cols: usize, path: &Path) -> Result<(), PlotError> {
    let format = Format::from_path(path)?;
    let bytes = match format {
        Format::Svg => render2d::svg(figs, cols, PANEL_SIZE)?.into_bytes(),
        Format::Png => render2d::png(figs, cols, PANEL_SIZE)?,
    };
    output::write(path, &bytes)
}

/// The SVG document of a grid of panels (see [`save_grid`]).
pub fn grid_to_svg(figs: &[Figure], cols: usize) -> Result<String, PlotError> {
    render2d::svg(figs, cols, PANEL_SIZE)
}

/// The PNG file contents of a grid of panels (see [`save_grid`]).
pub fn grid_to_png(figs: &[Figure], cols: usize) -> Result<Vec<u8>, PlotError> {
    render2d::png(figs, cols, PANEL_SIZE)
}

/// Saves a 3-D figure to `path` at [`DEFAULT_SIZE`]; the format comes from
/// the extension (`.svg` or `.png`).
pub fn save3(fig: &Figure3, path: &Path) -> Result<(), PlotError> {
    let format = Format::from_path(path)?;
    let bytes = match format {
        Format::Svg => render3d::svg(fig, DEFAULT_SIZE)?.into_bytes(),
        Format::Png => render3d::png(fig, DEFAULT_SIZE)?,
    };
    output::write(path, &bytes)
}

/// The SVG document of a 3-D figure at [`DEFAULT_SIZE`].
pub fn to_svg3(fig: &Figure3) -> Result<String, PlotError> {
    render3d::svg(fig, DEFAULT_SIZE)
}

/// The PNG file contents of a 3-D figure at [`DEFAULT_SIZE`].
pub fn to_png3(fig: &Figure3) -> Result<Vec<u8>, PlotError> {
    render3d::png(fig, DEFAULT_SIZE)
}

/// A series after validation: its label for the legend and its finite
/// points, split into runs where non-finite points were.
#[derive(Debug, Clone)]
pub(crate) struct Clean<P> {
    pub label: String,
    pub runs: Vec<Vec<P>>,
}

fn series_name(label: &str, i: usize) -> String {
    if label.trim().is_empty() {
        format!("series {}", i + 1)
    } else {
        label.to_string()
    }
}

/// Splits points into runs of finite points.
fn runs<P>(points: impl Iterator<Item = Option<P>>) -> Vec<Vec<P>> {
    let mut out: Vec<Vec<P>> = Vec::new();
    let mut cur = Vec::new();
    for p in points {
        match p {
            Some(p) => cur.push(p),
            None => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Validates the series of a 2-D figure.
pub(crate) fn clean2(fig: &Figure) -> Result<Vec<Clean<(f64, f64)>>, PlotError> {
    if fig.series.is_empty() {
        return Err(PlotError::NoSeries {
            title: fig.title.clone(),
        });
    }
    fig.series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let label = series_name(&s.label, i);
            if s.x.len() != s.y.len() {
                return Err(PlotError::LengthMismatch {
                    label,
                    lengths: vec![s.x.len(), s.y.len()],
                });
            }
            if s.x.is_empty() {
                return Err(PlotError::EmptySeries { label });
            }
            let runs = runs(s.x.iter().zip(&s.y).map(|(&x, &y)| {
                if x.is_finite() && y.is_finite() {
                    Some((x, y))
                } else {
                    None
                }
            }));
            if runs.is_empty() {
                return Err(PlotError::NoFiniteData { label });
            }
            Ok(Clean { label, runs })
        })
        .collect()
}

/// A 3-D data point.
pub(crate) type Point3 = (f64, f64, f64);

/// Validates the series of a 3-D figure.
pub(crate) fn clean3(fig: &Figure3) -> Result<Vec<Clean<Point3>>, PlotError> {
    if fig.series.is_empty() {
        return Err(PlotError::NoSeries {
            title: fig.title.clone(),
        });
    }
    fig.series
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let label = series_name(&s.label, i);
            if s.x.len() != s.y.len() || s.x.len() != s.z.len() {
                return Err(PlotError::LengthMismatch {
                    label,
                    lengths: vec![s.x.len(), s.y.len(), s.z.len()],
                });
            }
            if s.x.is_empty() {
                return Err(PlotError::EmptySeries { label });
            }
            let runs = runs(s.x.iter().zip(&s.y).zip(&s.z).map(|((&x, &y), &z)| {
                if x.is_finite() && y.is_finite() && z.is_finite() {
                    Some((x, y, z))
                } else {
                    None
                }
            }));
            if runs.is_empty() {
                return Err(PlotError::NoFiniteData { label });
            }
            Ok(Clean { label, runs })
        })
        .collect()
}
