//! Sizes, margins, ranges and ticks of a 2-D figure: everything decided
//! before drawing, as pure functions.

use std::ops::Range;

use crate::font::text_size;
use crate::ticks::{ticks, Ticks};
use crate::{clean2, Figure, Marker, PlotError};

/// Fraction of the data span added on each side of an axis.
pub(crate) const PAD: f64 = 0.04;

/// Font sizes, line widths and spacings for an image (or panel) of a given
/// size, in device pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Theme {
    pub title: f64,
    pub label: f64,
    pub tick: f64,
    pub legend: f64,
    pub note: f64,
    pub line: u32,
    pub point: u32,
    pub tick_len: i32,
    pub gap: u32,
    /// Device pixels per logical pixel (3 for PNG, 4 for SVG).
    pub dpr: f64,
}

impl Theme {
    /// The theme of a `w`×`h` (logical pixels) image drawn at `dpr` device
    /// pixels per logical pixel.
    pub fn new((w, h): (u32, u32), dpr: f64) -> Theme {
        let fit = (w as f64 / 1000.0).min(h as f64 / 700.0);
        let f = (0.55 + 0.45 * fit).clamp(0.7, 1.6);
        let s = f * dpr;
        Theme {
            title: 24.0 * s,
            label: 19.0 * s,
            tick: 16.0 * s,
            legend: 16.0 * s,
            note: 15.0 * s,
            line: (2.0 * dpr).round().max(1.0) as u32,
            point: (3.0 * s).round().max(1.0) as u32,
            tick_len: (5.0 * s).round() as i32,
            gap: (8.0 * s).round() as u32,
            dpr,
        }
    }
}

/// Where everything goes on a 2-D figure drawn at a given pixel size.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Horizontal data range spanned by the plotting area.
    pub x_range: Range<f64>,
    /// Vertical data range spanned by the plotting area.
    pub y_range: Range<f64>,
    /// Width and height in pixels of the plotting area (inside the axes).
    pub plot_size: (u32, u32),
    pub(crate) x_ticks: Ticks,
    pub(crate) y_ticks: Ticks,
    /// Height of the title strip.
    pub(crate) title_h: u32,
    /// Height of the label area below the plot, width of the one left of it.
    pub(crate) x_area: u32,
    pub(crate) y_area: u32,
    /// Margins around the chart: top, bottom, left, right.
    pub(crate) margin: [u32; 4],
}

/// Widens `lo..hi` by [`PAD`] of its span on each side; a degenerate range
/// (a constant) gets ±10 % of its value (±1 around zero).
pub(crate) fn padded(lo: f64, hi: f64) -> Range<f64> {
    let span = hi - lo;
    let scale = lo.abs().max(hi.abs());
    if span <= scale * 1e-12 || span <= f64::MIN_POSITIVE {
        let d = if scale > 0.0 { 0.1 * scale } else { 1.0 };
        return (lo - d)..(hi + d);
    }
    (lo - PAD * span)..(hi + PAD * span)
}

/// The data ranges of `fig` before any aspect correction: the bounds of
/// all finite points and finite markers, widened by 4 % of the span on
/// each side (a constant gets ±10 %).
pub fn data_ranges(fig: &Figure) -> Result<(Range<f64>, Range<f64>), PlotError> {
    let clean = clean2(fig)?;
    let mut bx = (f64::INFINITY, f64::NEG_INFINITY);
    let mut by = (f64::INFINITY, f64::NEG_INFINITY);
    let add = |b: &mut (f64, f64), v: f64| {
        if v.is_finite() {
            b.0 = b.0.min(v);
            b.1 = b.1.max(v);
        }
    };
    for s in &clean {
        for &(x, y) in s.runs.iter().flatten() {
            add(&mut bx, x);
            add(&mut by, y);
        }
    }
    for m in &fig.markers {
        match *m {
            Marker::VLine { x, .. } => add(&mut bx, x),
            Marker::HLine { y, .. } => add(&mut by, y),
            Marker::Point { x, y, .. } if x.is_finite() && y.is_finite() => {
                add(&mut bx, x);
                add(&mut by, y);
            }
            Marker::Point { .. } => {}
        }
    }
    Ok((padded(bx.0, bx.1), padded(by.0, by.1)))
}

/// Widens one of the ranges, about its centre, so that both axes have the
/// same data units per pixel on a plotting area of `plot_px` = (width,
/// height) pixels:
/// `(x.end - x.start) / width == (y.end - y.start) / height`.
pub fn equal_aspect_ranges(
    x: Range<f64>,
    y: Range<f64>,
    plot_px: (u32, u32),
) -> (Range<f64>, Range<f64>) {
    let (w, h) = (plot_px.0.max(1) as f64, plot_px.1.max(1) as f64);
    let (sx, sy) = (x.end - x.start, y.end - y.start);
    let (ux, uy) = (sx / w, sy / h);
    if ux > uy {
        let c = 0.5 * (y.start + y.end);
        let half = 0.5 * ux * h;
        (x, (c - half)..(c + half))
    } else {
        let c = 0.5 * (x.start + x.end);
        let half = 0.5 * uy * w;
        ((c - half)..(c + half), y)
    }
}

/// Placement of the label of a vertical-line marker: row 0 is at the top
/// of the plot, `right` tells on which side of the line the text goes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct VLabel<'a> {
    pub text: &'a str,
    pub px: f64,
    pub right: bool,
    pub row: usize,
}

/// Height of one row of vertical-line labels.
pub(crate) fn vline_row_height(th: &Theme) -> f64 {
    text_size("Ag", th.note).1 as f64 + 1.5 * th.gap as f64
}

/// Places the labels of the vertical-line markers of `fig` in rows at the
/// top of a plotting area `plot_w` pixels wide showing `x_range`: to the
/// right of its line unless that leaves the plot or crosses another marker
/// line and the left side does not; in the first row where it overlaps no
/// other label.
pub(crate) fn vline_labels<'a>(
    fig: &'a Figure,
    x_range: &Range<f64>,
    plot_w: u32,
    th: &Theme,
) -> Vec<VLabel<'a>> {
    let pw = plot_w as f64;
    let gap = th.gap as f64;
    let to_px =
        |x: f64| crate::ticks::map_linear(x, x_range.start, x_range.end, (0, plot_w as i32));
    let lines: Vec<f64> = fig
        .markers
        .iter()
        .filter_map(|m| match m {
            Marker::VLine { x, .. } if x.is_finite() => Some(to_px(*x)),
            _ => None,
        })
        .collect();
    let mut rows: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut out = Vec::new();
    for m in &fig.markers {
        let Marker::VLine { x, label } = m else {
            continue;
        };
        let text = label.trim();
        if !x.is_finite() || text.is_empty() {
            continue;
        }
        let px = to_px(*x);
        let tw = text_size(text, th.note).0 as f64;
        let span = |right: bool| {
            if right {
                (px, px + gap / 2.0 + tw)
            } else {
                (px - gap / 2.0 - tw, px)
            }
        };
        let clear = |(a, b): (f64, f64)| {
            a >= 0.0
                && b + gap <= pw
                && !lines
                    .iter()
                    .any(|&o| (o - px).abs() > 0.5 && o > a - gap && o < b + gap)
        };
        let right = clear(span(true)) || (!clear(span(false)) && px + gap / 2.0 + tw + gap <= pw);
        let (x0, x1) = span(right);
        let row = rows
            .iter()
            .position(|r| r.iter().all(|&(a, b)| x1 + gap < a || x0 > b + gap))
            .unwrap_or(rows.len());
        if row == rows.len() {
            rows.push(Vec::new());
        }
        rows[row].push((x0, x1));
        out.push(VLabel {
            text,
            px,
            right,
            row,
        });
    }
    out
}

/// `px`, or a smaller size (down to 55 %) at which `text` fits in `max_w`
/// pixels.
pub(crate) fn fit_font(text: &str, px: f64, max_w: f64) -> f64 {
    let tw = text_size(text.trim(), px).0 as f64;
    if tw > max_w && tw > 0.0 {
        (px * max_w / tw).max(0.55 * px)
    } else {
        px
    }
}

/// Most lines a title is wrapped into; the rest is cut with `…`.
pub(crate) const MAX_TITLE_LINES: usize = 3;

/// A title laid out to fit `max_w` pixels: on one line at `px` when it fits, or shrunk down to
/// 3/4 of `px`; otherwise wrapped at spaces into at most [`MAX_TITLE_LINES`] lines at 3/4 of
/// `px` (a word longer than a line is broken; text beyond the last line is cut with `…`).
/// Never wider than `max_w`: a long title was shrunk to at most 0.55·px and then clipped at the
/// image's edge. Returns the lines and the font size.
pub(crate) fn title_lines(text: &str, px: f64, max_w: f64) -> (Vec<String>, f64) {
    let text = text.trim();
    let fits = |t: &str, px: f64| (text_size(t, px).0 as f64) <= max_w;
    let one = fit_font(text, px, max_w).max(0.75 * px);
    if fits(text, one) || max_w <= 0.0 {
        return (vec![text.to_string()], one);
    }
    let px = 0.75 * px;
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let candidate = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if fits(&candidate, px) {
            line = candidate;
            continue;
        }
        if !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        // A word wider than a line: broken by characters.
        let mut rest = word.to_string();
        while !fits(&rest, px) {
            let mut cut = rest.chars().count() - 1;
            while cut > 1 && !fits(&rest.chars().take(cut).collect::<String>(), px) {
                cut -= 1;
            }
            lines.push(rest.chars().take(cut).collect());
            rest = rest.chars().skip(cut).collect();
        }
        line = rest;
    }
    if !line.is_empty() {
        lines.push(line);
    }
    if lines.len() > MAX_TITLE_LINES {
        lines.truncate(MAX_TITLE_LINES);
        let last = &mut lines[MAX_TITLE_LINES - 1];
        loop {
            let with = format!("{last}…");
            if fits(&with, px) || last.is_empty() {
                *last = with;
                break;
            }
            last.pop();
        }
    }
    (lines, px)
}

/// Height of a title's lines at `px`, with the line spacing the renderers use.
pub(crate) fn title_height(lines: &[String], px: f64) -> u32 {
    let line = lines.iter().map(|l| text_size(l, px).1).max().unwrap_or(0);
    line * lines.len() as u32 + (0.25 * px) as u32 * lines.len().saturating_sub(1) as u32
}

fn max_width(labels: &[String], px: f64) -> u32 {
    labels.iter().map(|l| text_size(l, px).0).max().unwrap_or(0)
}

/// The layout of `fig` drawn at `size` pixels (as [`crate::save`] does at
/// [`crate::DEFAULT_SIZE`]): ranges, ticks and the size of the plotting
/// area. The ranges are [`data_ranges`], raised at the top when labels of
/// markers need room there, then (with `equal_aspect`) widened by
/// [`equal_aspect_ranges`] so that
/// `x_range span / plot width == y_range span / plot height`.
pub fn layout(fig: &Figure, size: (u32, u32)) -> Result<Layout, PlotError> {
    crate::font::ensure()?;
    layout_with(fig, size, &Theme::new(size, 1.0), &Floors::default())
}

/// Lower bounds for the sizes of a layout, so that the panels of a grid
/// line up: title height and x label area per row, y label area and right
/// margin per column.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Floors {
    pub title_h: u32,
    pub x_area: u32,
    pub y_area: u32,
    pub right: u32,
}

impl Layout {
    /// The sizes of this layout, as floors.
    pub(crate) fn floors(&self) -> Floors {
        Floors {
            title_h: self.title_h,
            x_area: self.x_area,
            y_area: self.y_area,
            right: self.margin[3],
        }
    }
}

/// [`layout`] for a device size `size` (device pixels) and theme, with
/// lower bounds for the sizes of its parts.
pub(crate) fn layout_with(
    fig: &Figure,
    size: (u32, u32),
    th: &Theme,
    floors: &Floors,
) -> Result<Layout, PlotError> {
    let (xr0, yr0) = data_ranges(fig)?;
    let (w, h) = size;
    let gap = th.gap;
    let title_h = if fig.title.trim().is_empty() {
        gap
    } else {
        let (lines, px) = title_lines(&fig.title, th.title, w as f64 - 2.0 * gap as f64);
        title_height(&lines, px) + 2 * gap
    }
    .max(floors.title_h);
    let tick_h = text_size("0123456789", th.tick).1.max(1);
    let label_h = |s: &str| {
        if s.trim().is_empty() {
            0
        } else {
            text_size(s, th.label).1 + gap
        }
    };
    // plotters puts tick labels 2 × tick length away from the axis.
    let label_dist = 2 * th.tick_len.max(0) as u32;
    let x_area = (label_dist + tick_h + label_h(&fig.x_label) + gap).max(floors.x_area);
    let top = (tick_h / 2 + gap / 2).max(gap);
    let bottom = gap;
    let left = gap;
    let mut right = (3 * gap).max(floors.right);
    let plot_h = h.saturating_sub(title_h + top + bottom + x_area).max(1);

    let n_y = ((plot_h as f64 / (tick_h as f64 * 3.2)) as usize).clamp(2, 10);
    let mut y_area =
        (label_dist + text_size("\u{2212}0.00", th.tick).0 + label_h(&fig.y_label) + gap)
            .max(floors.y_area);
    for iter in 0..8 {
        let plot_w = w.saturating_sub(left + right + y_area).max(1);
        // Room at the top for the labels of vertical-line markers.
        let n_rows = vline_labels(fig, &xr0, plot_w, th)
            .iter()
            .map(|l| l.row + 1)
            .max()
            .unwrap_or(0);
        let yr1 = if n_rows > 0 {
            let room =
                ((n_rows as f64 * vline_row_height(th) + gap as f64) / plot_h as f64).min(0.5);
            let top = yr0.start + (yr0.end - yr0.start) / (1.0 - room);
            yr0.start..top
        } else {
            yr0.clone()
        };
        // Room above labelled points for their labels.
        let off = (th.point as f64 * 2.2).round() + gap as f64 / 2.0;
        let need = (off + text_size("Ag", th.note).1 as f64 + gap as f64 / 2.0) / plot_h as f64;
        let mut y_top = yr1.end;
        if need < 0.5 {
            for m in &fig.markers {
                if let Marker::Point { x, y, label } = m {
                    if x.is_finite() && y.is_finite() && !label.trim().is_empty() {
                        y_top = y_top.max((y - need * yr1.start) / (1.0 - need));
                    }
                }
            }
        }
        let yr1 = yr1.start..y_top;
        let (xr, yr) = if fig.equal_aspect {
            equal_aspect_ranges(xr0.clone(), yr1, (plot_w, plot_h))
        } else {
            (xr0.clone(), yr1)
        };
        let y_ticks = ticks(&yr, n_y);
        // As many x ticks as fit with generous gaps between labels.
        let mut n_x = 10usize;
        let mut x_ticks = ticks(&xr, n_x);
        for _ in 0..8 {
            let lw = max_width(&x_ticks.labels, th.tick) as f64 + 2.5 * tick_h as f64;
            let fit = ((plot_w as f64 / lw) as usize).clamp(2, 10);
            if x_ticks.values.len() <= fit || n_x <= 2 {
                break;
            }
            n_x = fit.min(n_x - 1);
            x_ticks = ticks(&xr, n_x);
        }
        let new_y_area =
            (label_dist + max_width(&y_ticks.labels, th.tick) + label_h(&fig.y_label) + gap)
                .max(floors.y_area);
        let last_w = x_ticks.labels.last().map_or(0, |l| text_size(l, th.tick).0);
        let new_right = (last_w / 2 + gap).max(3 * gap).max(floors.right);
        if (new_y_area == y_area && new_right == right) || iter == 7 {
            return Ok(Layout {
                x_range: xr,
                y_range: yr,
                plot_size: (plot_w, plot_h),
                x_ticks,
                y_ticks,
                title_h,
                x_area,
                y_area,
                margin: [top, bottom, left, right],
            });
        }
        // Grow only after the first rounds so that the loop terminates.
        if iter < 2 {
            y_area = new_y_area;
            right = new_right;
        } else {
            y_area = y_area.max(new_y_area);
            right = right.max(new_right);
        }
    }
    Err(PlotError::render("layout did not converge"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padding() {
        let r = padded(0.0, 10.0);
        assert!((r.start + 0.4).abs() < 1e-12 && (r.end - 10.4).abs() < 1e-12);
        assert_eq!(padded(0.0, 0.0), -1.0..1.0);
        let r = padded(5.0, 5.0);
        assert!((r.start - 4.5).abs() < 1e-12 && (r.end - 5.5).abs() < 1e-12);
    }

    #[test]
    fn vline_labels_avoid_lines_and_each_other() {
        crate::font::ensure().unwrap();
        let th = Theme::new((1000, 700), 1.0);
        let fig = Figure {
            markers: vec![
                Marker::vline(3.0, "kick"),
                Marker::vline(3.3, "contact"),
                Marker::vline(3.5, "second contact"),
                Marker::vline(9.9, "end"),
                Marker::vline(f64::NAN, "skipped"),
                Marker::vline(5.0, ""),
            ],
            ..Default::default()
        };
        let l = vline_labels(&fig, &(0.0..10.0), 800, &th);
        let names: Vec<_> = l.iter().map(|l| l.text).collect();
        assert_eq!(names, ["kick", "contact", "second contact", "end"]);
        // "kick" goes left: to its right is the "contact" line.
        assert!(!l[0].right && l[0].row == 0);
        // "end" would leave the plot on the right.
        assert!(!l[3].right);
        // Labels in one row don't overlap.
        let span = |v: &VLabel| {
            let w = text_size(v.text, th.note).0 as f64 + th.gap as f64 / 2.0;
            if v.right {
                (v.px, v.px + w)
            } else {
                (v.px - w, v.px)
            }
        };
        for a in &l {
            for b in &l {
                if a != b && a.row == b.row {
                    let (sa, sb) = (span(a), span(b));
                    assert!(sa.1 < sb.0 || sb.1 < sa.0, "{a:?} overlaps {b:?}");
                }
            }
        }
    }

    /// A title too long for one line, even shrunk, is wrapped into lines that each fit the
    /// width, keeping every word (up to the line limit), never clipped.
    #[test]
    fn long_titles_wrap_within_the_width() {
        crate::font::ensure().unwrap();
        let words = "Lennard-Jones liquid at the triple point, heated from 40 K to 240 K by a \
                     Langevin ramp: energy per atom";
        for (width, px) in [(500.0, 24.0), (300.0, 24.0), (800.0, 30.0)] {
            let (lines, size) = title_lines(words, px, width);
            for l in &lines {
                assert!(
                    text_size(l, size).0 as f64 <= width,
                    "{l:?} at {size} > {width}"
                );
            }
            assert!(lines.len() > 1, "{lines:?}");
            if lines.len() < MAX_TITLE_LINES {
                assert_eq!(lines.join(" "), words);
            }
        }
        // Short titles are untouched; a word longer than a line is broken; too many lines end
        // with an ellipsis.
        assert_eq!(
            title_lines("energy", 24.0, 500.0),
            (vec!["energy".to_string()], 24.0)
        );
        let (lines, size) = title_lines(&"x".repeat(400), 24.0, 300.0);
        assert!(lines.iter().all(|l| text_size(l, size).0 as f64 <= 300.0));
        let (lines, _) = title_lines(&"word ".repeat(200), 24.0, 300.0);
        assert_eq!(lines.len(), MAX_TITLE_LINES);
        assert!(lines.last().unwrap().ends_with('…'));
    }

    #[test]
    fn long_titles_shrink() {
        crate::font::ensure().unwrap();
        let long = "a very long title ".repeat(10);
        let px = fit_font(&long, 24.0, 500.0);
        assert!((0.55 * 24.0..24.0).contains(&px));
        assert_eq!(fit_font("short", 24.0, 500.0), 24.0);
    }

    #[test]
    fn equal_aspect_widens_the_short_side() {
        let (x, y) = equal_aspect_ranges(-1.0..1.0, -1.0..1.0, (800, 400));
        assert_eq!(y, -1.0..1.0);
        assert!((x.start + 2.0).abs() < 1e-12 && (x.end - 2.0).abs() < 1e-12);
        let (x, y) = equal_aspect_ranges(0.0..10.0, 0.0..1.0, (500, 500));
        assert_eq!(x, 0.0..10.0);
        assert!((y.start + 4.5).abs() < 1e-12 && (y.end - 5.5).abs() < 1e-12);
    }
}
