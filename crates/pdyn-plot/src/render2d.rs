//! Drawing 2-D figures and grids of them with plotters.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::font::{desc, text_size};
use crate::layout::{
    fit_font, layout_with, title_height, title_lines, vline_labels, vline_row_height, Floors,
    Layout, Theme,
};
use crate::output;
use crate::ticks::{map_linear, Axis, Ticks};
use crate::{clean2, Figure, Marker, PlotError, Style};

/// Okabe–Ito colour-blind-safe palette, ordered for contrast on white
/// (blue, vermillion, bluish green, reddish purple, orange, sky blue, black,
/// yellow).
pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];
/// Text and axes.
pub(crate) const INK: RGBColor = RGBColor(34, 34, 34);
/// Grid lines.
pub(crate) const GRID: RGBColor = RGBColor(222, 222, 222);
/// Markers.
pub(crate) const MARK: RGBColor = RGBColor(80, 80, 80);

/// Supersampling factor of PNG output.
const SUPERSAMPLE: u32 = 3;
/// Largest image accepted, in pixels per side.
const MAX_SIDE: u32 = 20_000;
/// Largest image accepted, in pixels (the PNG drawing buffer is at most
/// 3 bytes per pixel times the supersampling factor squared).
const MAX_PIXELS: u64 = 40_000_000;

pub(crate) fn check_size((w, h): (u32, u32)) -> Result<(), PlotError> {
    if w < 200
        || h < 150
        || w > MAX_SIDE
        || h > MAX_SIDE
        || u64::from(w) * u64::from(h) > MAX_PIXELS
    {
        return Err(PlotError::InvalidArgument {
            message: format!(
                "image size {w}×{h} pixels: each panel needs at least 200×150, and the image at most {MAX_SIDE} pixels per side and {MAX_PIXELS} pixels in all"
            ),
        });
    }
    Ok(())
}

/// Columns and rows of a grid of `n` panels with at most `cols` columns.
fn grid_shape(n: usize, cols: usize) -> Result<(u32, u32), PlotError> {
    if n == 0 {
        return Err(PlotError::InvalidArgument {
            message: "no figures to draw in the grid".into(),
        });
    }
    if cols == 0 {
        return Err(PlotError::InvalidArgument {
            message: "a grid needs at least one column".into(),
        });
    }
    let cols = cols.min(n);
    let rows = n.div_ceil(cols);
    let too_many = || PlotError::InvalidArgument {
        message: format!("a grid of {n} panels is too large"),
    };
    Ok((
        u32::try_from(cols).map_err(|_| too_many())?,
        u32::try_from(rows).map_err(|_| too_many())?,
    ))
}

pub(crate) fn image_size(
    figs: &[Figure],
    cols: usize,
    panel: (u32, u32),
) -> Result<(u32, u32, u32), PlotError> {
    let (cols, rows) = grid_shape(figs.len(), cols)?;
    check_size(panel)?;
    let size = (panel.0.saturating_mul(cols), panel.1.saturating_mul(rows));
    check_size(size)?;
    for f in figs {
        clean2(f)?;
    }
    Ok((size.0, size.1, cols))
}

/// SVG of `figs` as a grid of `panel`-sized panels.
pub(crate) fn svg(figs: &[Figure], cols: usize, panel: (u32, u32)) -> Result<String, PlotError> {
    crate::font::ensure()?;
    let (w, h, cols) = image_size(figs, cols, panel)?;
    let dev = (w * SVG_SCALE, h * SVG_SCALE);
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, dev).into_drawing_area();
        draw_grid(&root, figs, cols, &Theme::new(panel, SVG_SCALE as f64))?;
        root.present().map_err(PlotError::render)?;
    }
    Ok(svg_display_size(s, dev, (w, h)))
}

/// SVGs are drawn at this many units per pixel: plotters writes integer
/// coordinates, and a finer grid keeps curves smooth.
pub(crate) const SVG_SCALE: u32 = 4;

/// Finishes an SVG drawn at `dev` units: displayed at `size` pixels (the
/// viewBox keeps the drawing units), and without the control characters
/// XML forbids (they could come from user labels).
pub(crate) fn svg_display_size(mut s: String, dev: (u32, u32), size: (u32, u32)) -> String {
    s.retain(|c| !c.is_control() || matches!(c, '\n' | '\t' | '\r'));
    let from = format!("<svg width=\"{}\" height=\"{}\" ", dev.0, dev.1);
    match s.strip_prefix(&from) {
        Some(rest) => format!("<svg width=\"{}\" height=\"{}\" {rest}", size.0, size.1),
        None => s,
    }
}

/// PNG of `figs` as a grid of `panel`-sized panels, supersampled.
pub(crate) fn png(figs: &[Figure], cols: usize, panel: (u32, u32)) -> Result<Vec<u8>, PlotError> {
    crate::font::ensure()?;
    let (w, h, cols) = image_size(figs, cols, panel)?;
    // Keep the drawing buffer below ~100 MB.
    let ss = (1..=SUPERSAMPLE)
        .rev()
        .find(|s| w as u64 * h as u64 * u64::from(s * s) * 3 <= 100_000_000)
        .unwrap_or(1);
    let dev = (w * ss, h * ss);
    let mut buf = vec![255u8; dev.0 as usize * dev.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, dev).into_drawing_area();
        draw_grid(&root, figs, cols, &Theme::new(panel, ss as f64))?;
        root.present().map_err(PlotError::render)?;
    }
    let small = output::downsample(&buf, dev, ss);
    output::encode_png(&small, (w, h))
}

fn draw_grid<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figs: &[Figure],
    cols: u32,
    th: &Theme,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(PlotError::render)?;
    let rows = (figs.len() as u32).div_ceil(cols);
    let panels = root.split_evenly((rows as usize, cols as usize));
    // Line the panels up: common title height and x label area per row,
    // common y label area and right margin per column.
    let natural = figs
        .iter()
        .zip(panels.iter())
        .map(|(fig, area)| {
            Ok(layout_with(fig, area.dim_in_pixel(), th, &Floors::default())?.floors())
        })
        .collect::<Result<Vec<Floors>, PlotError>>()?;
    let cols = cols as usize;
    for (i, (fig, area)) in figs.iter().zip(panels.iter()).enumerate() {
        let (r, c) = (i / cols, i % cols);
        let mut f = Floors::default();
        for (j, n) in natural.iter().enumerate() {
            if j / cols == r {
                f.title_h = f.title_h.max(n.title_h);
                f.x_area = f.x_area.max(n.x_area);
            }
            if j % cols == c {
                f.y_area = f.y_area.max(n.y_area);
                f.right = f.right.max(n.right);
            }
        }
        draw_figure(area, fig, th, &f)?;
    }
    Ok(())
}

/// The label of the tick nearest to `v`.
fn tick_label(t: &Ticks, v: f64) -> String {
    let mut best = None;
    for (i, &tv) in t.values.iter().enumerate() {
        let d = (tv - v).abs();
        if best.is_none_or(|(_, bd)| d < bd) {
            best = Some((i, d));
        }
    }
    best.and_then(|(i, _)| t.labels.get(i).cloned())
        .unwrap_or_default()
}

/// Pixel position (relative to the plotting area, as f64) of a data point.
fn to_px(lay: &Layout, (x, y): (f64, f64)) -> (f64, f64) {
    let (w, h) = (lay.plot_size.0 as i32, lay.plot_size.1 as i32);
    (
        map_linear(x, lay.x_range.start, lay.x_range.end, (0, w)),
        map_linear(y, lay.y_range.start, lay.y_range.end, (h, 0)),
    )
}

/// Drops points closer than `min_px` pixels to the previously kept one
/// (the last point of the run is always kept). Keeps SVGs of long
/// trajectories small without visible change.
fn thin(run: &[(f64, f64)], lay: &Layout, min_px: f64) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(run.len().min(4096));
    let mut last_px = (f64::NAN, f64::NAN);
    let n = run.len();
    for (i, &p) in run.iter().enumerate() {
        let q = to_px(lay, p);
        let far = !((q.0 - last_px.0).abs() < min_px && (q.1 - last_px.1).abs() < min_px);
        if far || i + 1 == n {
            out.push(p);
            last_px = q;
        }
    }
    out
}

/// Horizontal and vertical anchoring of a text.
type Anchor = (HPos, VPos);

/// A rectangle in plotting-area pixels: x0, y0, x1, y1.
type Rect = (f64, f64, f64, f64);

fn contains(r: &Rect, p: (f64, f64)) -> bool {
    p.0 >= r.0 && p.0 <= r.2 && p.1 >= r.1 && p.1 <= r.3
}

fn overlaps(a: &Rect, b: &Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Index of the candidate box covering the fewest sample points (ties go
/// to the earlier candidate); obstacles count as many points.
pub(crate) fn least_covered(
    candidates: &[Rect],
    samples: &[(f64, f64)],
    obstacles: &[Rect],
) -> usize {
    let mut best = (0, usize::MAX);
    for (i, c) in candidates.iter().enumerate() {
        let n = samples.iter().filter(|&&p| contains(c, p)).count()
            + 10_000 * obstacles.iter().filter(|o| overlaps(c, o)).count();
        if n < best.1 {
            best = (i, n);
        }
    }
    best.0
}

/// Points along the polyline every ~`step` pixels (for legend placement).
pub(crate) fn samples_along(px: &[(f64, f64)], step: f64, out: &mut Vec<(f64, f64)>) {
    if let Some(&first) = px.first() {
        out.push(first);
    }
    for w in px.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let k = (len / step).ceil().clamp(1.0, 10_000.0) as usize;
        for j in 1..=k {
            let t = j as f64 / k as f64;
            out.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
        }
    }
}

pub(crate) fn err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::render(e)
}

/// The chart of a layout on the area below the title (its plotting area
/// is `lay.plot_size`).
fn build_chart<'a, DB: DrawingBackend>(
    rest: &'a DrawingArea<DB, Shift>,
    lay: &Layout,
) -> Result<ChartContext<'a, DB, Cartesian2d<Axis, Axis>>, PlotError> {
    let [mt, mb, ml, mr] = lay.margin;
    ChartBuilder::on(rest)
        .margin_top(mt)
        .margin_bottom(mb)
        .margin_left(ml)
        .margin_right(mr)
        .x_label_area_size(lay.x_area)
        .y_label_area_size(lay.y_area)
        .build_cartesian_2d(
            Axis::new(&lay.x_range, &lay.x_ticks),
            Axis::new(&lay.y_range, &lay.y_ticks),
        )
        .map_err(err)
}

/// Draws one figure into `area`.
fn draw_figure<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    th: &Theme,
    floors: &Floors,
) -> Result<(), PlotError> {
    let clean = clean2(fig)?;
    let (w, _h) = area.dim_in_pixel();
    let lay = layout_with(fig, area.dim_in_pixel(), th, floors)?;
    let dpr = th.dpr;

    let (title_area, rest) = area.split_vertically(lay.title_h);
    if !fig.title.trim().is_empty() {
        let (lines, px) = title_lines(&fig.title, th.title, w as f64 - 2.0 * th.gap as f64);
        let style = desc(px)
            .color(&INK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let line_h = lines.iter().map(|l| text_size(l, px).1).max().unwrap_or(0) as f64;
        let step = line_h + (0.25 * px).floor();
        let block = title_height(&lines, px) as f64;
        let top = lay.title_h as f64 / 2.0 + th.gap as f64 / 2.0 - block / 2.0 + line_h / 2.0;
        for (k, line) in lines.iter().enumerate() {
            // Centred over the plotting area, but kept inside the image.
            let tw = text_size(line, px).0 as f64;
            let cx = (lay.margin[2] + lay.y_area) as f64 + lay.plot_size.0 as f64 / 2.0;
            let half = tw / 2.0 + th.gap as f64;
            let cx = if w as f64 >= 2.0 * half {
                cx.clamp(half, w as f64 - half)
            } else {
                w as f64 / 2.0
            };
            title_area
                .draw_text(line, &style, (cx as i32, (top + k as f64 * step) as i32))
                .map_err(err)?;
        }
    }

    let mut chart = build_chart(&rest, &lay)?;

    let xfmt = |v: &f64| tick_label(&lay.x_ticks, *v);
    let yfmt = |v: &f64| tick_label(&lay.y_ticks, *v);
    let tick_font = desc(th.tick).color(&INK);
    let label_px = fit_font(&fig.x_label, th.label, lay.plot_size.0 as f64).min(fit_font(
        &fig.y_label,
        th.label,
        lay.plot_size.1 as f64,
    ));
    let label_font = desc(label_px).color(&INK);
    {
        let mut mesh = chart.configure_mesh();
        mesh.x_labels(lay.x_ticks.values.len())
            .y_labels(lay.y_ticks.values.len())
            .x_label_formatter(&xfmt)
            .y_label_formatter(&yfmt)
            .label_style(tick_font)
            .axis_desc_style(label_font)
            .bold_line_style(GRID.stroke_width(dpr.round() as u32))
            .light_line_style(TRANSPARENT)
            .axis_style(INK.stroke_width(dpr.round() as u32))
            .set_all_tick_mark_size(th.tick_len);
        if !fig.x_label.trim().is_empty() {
            mesh.x_desc(fig.x_label.trim());
        }
        if !fig.y_label.trim().is_empty() {
            mesh.y_desc(fig.y_label.trim());
        }
        mesh.draw().map_err(err)?;
    }

    let (pw, ph) = (lay.plot_size.0 as f64, lay.plot_size.1 as f64);
    let mut samples: Vec<(f64, f64)> = Vec::new();
    let line = matches!(fig.style, Style::Line | Style::LineAndPoints);
    let dots = matches!(fig.style, Style::Points | Style::LineAndPoints);
    for (i, s) in clean.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let line_style = color.stroke_width(th.line);
        for run in &s.runs {
            let pts = thin(run, &lay, (0.7 * dpr).max(0.5));
            let px: Vec<(f64, f64)> = pts.iter().map(|&p| to_px(&lay, p)).collect();
            samples_along(&px, 4.0 * dpr, &mut samples);
            if line && pts.len() >= 2 {
                chart
                    .draw_series(std::iter::once(PathElement::new(pts.clone(), line_style)))
                    .map_err(err)?;
            }
            if dots || pts.len() == 1 {
                chart
                    .draw_series(
                        pts.iter()
                            .map(|&p| Circle::new(p, th.point, color.filled())),
                    )
                    .map_err(err)?;
            }
        }
    }

    let pa = chart.plotting_area().strip_coord_spec();
    let obstacles = draw_markers(&pa, fig, &lay, th, &mut samples)?;

    if clean.len() > 1 {
        let labels: Vec<&str> = clean.iter().map(|s| s.label.as_str()).collect();
        draw_legend(&pa, &labels, fig.style, th, (pw, ph), &samples, &obstacles)?;
    }

    // Frame around the plotting area.
    let (iw, ih) = (lay.plot_size.0 as i32, lay.plot_size.1 as i32);
    outline(
        &pa,
        (0, 0, iw - 1, ih - 1),
        INK.stroke_width(dpr.round() as u32),
    )?;
    Ok(())
}

/// A rectangle's outline as a closed path (the SVG backend ignores the
/// stroke width of rectangles).
fn outline<DB: DrawingBackend>(
    pa: &DrawingArea<DB, Shift>,
    (x0, y0, x1, y1): (i32, i32, i32, i32),
    style: ShapeStyle,
) -> Result<(), PlotError> {
    pa.draw(&PathElement::new(
        vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
        style,
    ))
    .map_err(err)
}

/// Draws text with a translucent white box behind it; returns the box.
fn note<DB: DrawingBackend>(
    pa: &DrawingArea<DB, Shift>,
    text: &str,
    (x, y): (f64, f64),
    anchor: (HPos, VPos),
    th: &Theme,
) -> Result<Rect, PlotError> {
    let (tw, tht) = text_size(text, th.note);
    let (tw, tht) = (tw as f64, tht as f64);
    let x0 = match anchor.0 {
        HPos::Left => x,
        HPos::Center => x - tw / 2.0,
        HPos::Right => x - tw,
    };
    let y0 = match anchor.1 {
        VPos::Top => y,
        VPos::Center => y - tht / 2.0,
        VPos::Bottom => y - tht,
    };
    let pad = 2.0 * th.dpr;
    let rect = (x0 - pad, y0 - pad, x0 + tw + pad, y0 + tht + pad);
    pa.draw(&Rectangle::new(
        [
            (rect.0 as i32, rect.1 as i32),
            (rect.2 as i32, rect.3 as i32),
        ],
        WHITE.mix(0.9).filled(),
    ))
    .map_err(err)?;
    let style = desc(th.note)
        .color(&MARK)
        .pos(Pos::new(HPos::Left, VPos::Top));
    pa.draw_text(text, &style, (x0 as i32, y0 as i32))
        .map_err(err)?;
    Ok(rect)
}

fn dashed<DB: DrawingBackend>(
    pa: &DrawingArea<DB, Shift>,
    a: (f64, f64),
    b: (f64, f64),
    th: &Theme,
) -> Result<(), PlotError> {
    let (dash, space) = (7.0 * th.dpr, 5.0 * th.dpr);
    let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    if len <= 0.0 {
        return Ok(());
    }
    let (ux, uy) = ((b.0 - a.0) / len, (b.1 - a.1) / len);
    let style = MARK.stroke_width((1.5 * th.dpr).round().max(1.0) as u32);
    let mut t = 0.0;
    while t < len {
        let e = (t + dash).min(len);
        pa.draw(&PathElement::new(
            vec![
                ((a.0 + ux * t).round() as i32, (a.1 + uy * t).round() as i32),
                ((a.0 + ux * e).round() as i32, (a.1 + uy * e).round() as i32),
            ],
            style,
        ))
        .map_err(err)?;
        t += dash + space;
    }
    Ok(())
}

/// Draws the markers; returns the boxes of their labels (for the legend
/// to avoid) and adds marker pixels to `samples`.
fn draw_markers<DB: DrawingBackend>(
    pa: &DrawingArea<DB, Shift>,
    fig: &Figure,
    lay: &Layout,
    th: &Theme,
    samples: &mut Vec<(f64, f64)>,
) -> Result<Vec<Rect>, PlotError> {
    let (pw, ph) = (lay.plot_size.0 as f64, lay.plot_size.1 as f64);
    let gap = th.gap as f64;
    let text_h = text_size("Ag", th.note).1 as f64;
    let mut boxes = Vec::new();
    // Labels are drawn after all lines so that no line crosses a label.
    let mut pending: Vec<(&str, (f64, f64), Anchor)> = Vec::new();
    for l in vline_labels(fig, &lay.x_range, lay.plot_size.0, th) {
        let y = gap + l.row as f64 * vline_row_height(th);
        let (ax, hp) = if l.right {
            (l.px + gap / 2.0, HPos::Left)
        } else {
            (l.px - gap / 2.0, HPos::Right)
        };
        pending.push((l.text, (ax, y), (hp, VPos::Top)));
    }
    for m in &fig.markers {
        match m {
            Marker::VLine { x, .. } if x.is_finite() => {
                let (px, _) = to_px(lay, (*x, lay.y_range.start));
                dashed(pa, (px, 0.0), (px, ph), th)?;
                samples_along(&[(px, 0.0), (px, ph)], 8.0 * th.dpr, samples);
            }
            Marker::HLine { y, label } if y.is_finite() => {
                let (_, py) = to_px(lay, (lay.x_range.start, *y));
                dashed(pa, (0.0, py), (pw, py), th)?;
                samples_along(&[(0.0, py), (pw, py)], 8.0 * th.dpr, samples);
                if !label.trim().is_empty() {
                    let (ay, vp) = if py - text_h - gap > 0.0 {
                        (py - gap / 2.0, VPos::Bottom)
                    } else {
                        (py + gap / 2.0, VPos::Top)
                    };
                    pending.push((label.trim(), (pw - gap, ay), (HPos::Right, vp)));
                }
            }
            Marker::Point { x, y, label } if x.is_finite() && y.is_finite() => {
                let (px, py) = to_px(lay, (*x, *y));
                let r = (th.point as f64 * 2.2).round() as i32;
                let c = (px.round() as i32, py.round() as i32);
                pa.draw(&Circle::new(c, r, WHITE.mix(0.6).filled()))
                    .map_err(err)?;
                pa.draw(&Circle::new(
                    c,
                    r,
                    MARK.stroke_width((1.5 * th.dpr).round().max(1.0) as u32),
                ))
                .map_err(err)?;
                pa.draw(&Circle::new(c, (r / 3).max(1), MARK.filled()))
                    .map_err(err)?;
                if !label.trim().is_empty() {
                    let tw = text_size(label.trim(), th.note).0 as f64;
                    let off = r as f64 + gap / 2.0;
                    let hp = if px + off + tw + gap <= pw {
                        (px + off, HPos::Left)
                    } else {
                        (px - off, HPos::Right)
                    };
                    let vp = if py - off - text_h > 0.0 {
                        (py - off / 2.0, VPos::Bottom)
                    } else {
                        (py + off / 2.0, VPos::Top)
                    };
                    pending.push((label.trim(), (hp.0, vp.0), (hp.1, vp.1)));
                }
            }
            _ => {}
        }
    }
    for (text, at, anchor) in pending {
        boxes.push(note(pa, text, at, anchor, th)?);
    }
    Ok(boxes)
}

/// Draws the legend box in the corner of `pa` (of size `pw`×`ph`) that
/// hides the fewest `samples` and no `obstacles`.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    pa: &DrawingArea<DB, Shift>,
    labels: &[&str],
    style: Style,
    th: &Theme,
    (pw, ph): (f64, f64),
    samples: &[(f64, f64)],
    obstacles: &[Rect],
) -> Result<(), PlotError> {
    let gap = th.gap as f64;
    let text_h = text_size("Ag", th.legend).1 as f64;
    let row_h = text_h * 1.45;
    let sample_w = 2.6 * th.legend;
    let text_w = labels
        .iter()
        .map(|s| text_size(s, th.legend).0)
        .max()
        .unwrap_or(0) as f64;
    let bw = gap + sample_w + gap + text_w + gap * 1.5;
    let bh = labels.len() as f64 * row_h + gap;
    let inset = gap * 1.2;
    let candidates: [Rect; 4] = [
        (pw - inset - bw, inset, pw - inset, inset + bh),
        (inset, inset, inset + bw, inset + bh),
        (pw - inset - bw, ph - inset - bh, pw - inset, ph - inset),
        (inset, ph - inset - bh, inset + bw, ph - inset),
    ];
    let r = candidates[least_covered(&candidates, samples, obstacles)];
    let (x0, y0) = (r.0 as i32, r.1 as i32);
    pa.draw(&Rectangle::new(
        [(x0, y0), (r.2 as i32, r.3 as i32)],
        WHITE.mix(0.88).filled(),
    ))
    .map_err(err)?;
    outline(
        pa,
        (x0, y0, r.2 as i32, r.3 as i32),
        RGBColor(170, 170, 170).stroke_width(th.dpr.round() as u32),
    )?;
    let font = desc(th.legend)
        .color(&INK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (i, s) in labels.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let cy = r.1 + gap / 2.0 + (i as f64 + 0.5) * row_h;
        let sx0 = r.0 + gap;
        let sx1 = sx0 + sample_w;
        let cyi = cy.round() as i32;
        if matches!(style, Style::Line | Style::LineAndPoints) {
            pa.draw(&PathElement::new(
                vec![(sx0 as i32, cyi), (sx1 as i32, cyi)],
                color.stroke_width(th.line),
            ))
            .map_err(err)?;
        }
        if matches!(style, Style::Points | Style::LineAndPoints) {
            let cx = ((sx0 + sx1) / 2.0) as i32;
            pa.draw(&Circle::new((cx, cyi), th.point, color.filled()))
                .map_err(err)?;
        }
        pa.draw_text(s, &font, ((sx1 + gap) as i32, cyi))
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legend_goes_where_there_is_no_data() {
        let c = [
            (80.0, 0.0, 100.0, 20.0),
            (0.0, 0.0, 20.0, 20.0),
            (80.0, 80.0, 100.0, 100.0),
            (0.0, 80.0, 20.0, 100.0),
        ];
        let s = [(90.0, 10.0), (10.0, 10.0), (95.0, 90.0)];
        assert_eq!(least_covered(&c, &s, &[]), 3);
        assert_eq!(least_covered(&c, &[], &[(85.0, 5.0, 90.0, 10.0)]), 1);
    }

    /// The plotting area plotters makes is the one the layout computed
    /// (the ranges, equal aspect included, are chosen for that size).
    #[test]
    fn layout_predicts_the_plotting_area() {
        crate::font::ensure().unwrap();
        let fig = |title: &str, xl: &str, yl: &str, scale: f64| Figure {
            title: title.into(),
            x_label: xl.into(),
            y_label: yl.into(),
            series: vec![crate::Series::new(
                "s",
                vec![0.0, scale],
                vec![-scale, 1e-3],
            )],
            markers: vec![Marker::vline(0.5 * scale, "event")],
            equal_aspect: true,
            ..Default::default()
        };
        let figs = [
            fig("Title", "t [s]", "x [m]", 1.0),
            fig("", "", "", 1e-7),
            fig("A long title that will need shrinking to fit", "x", "", 3e6),
        ];
        for size in [(1000, 700), (200, 150), (640, 440), (2000, 300)] {
            for dpr in [1.0, 3.0] {
                for f in &figs {
                    let dev = ((size.0 as f64 * dpr) as u32, (size.1 as f64 * dpr) as u32);
                    let th = Theme::new(size, dpr);
                    let lay = layout_with(f, dev, &th, &Floors::default()).unwrap();
                    let mut s = String::new();
                    let root = SVGBackend::with_string(&mut s, dev).into_drawing_area();
                    let (_, rest) = root.split_vertically(lay.title_h);
                    let chart = build_chart(&rest, &lay).unwrap();
                    assert_eq!(
                        chart.plotting_area().dim_in_pixel(),
                        lay.plot_size,
                        "{size:?} {dpr}"
                    );
                }
            }
        }
    }

    #[test]
    fn grid_shapes() {
        assert_eq!(grid_shape(4, 2).ok(), Some((2, 2)));
        assert_eq!(grid_shape(3, 5).ok(), Some((3, 1)));
        assert_eq!(grid_shape(5, 2).ok(), Some((2, 3)));
        assert!(grid_shape(0, 2).is_err());
        assert!(grid_shape(2, 0).is_err());
    }
}
