//! Drawing 3-D trajectories: plotters' 3-D coordinate system supplies the
//! projection; the box, grid, ticks and labels are drawn here so that their
//! placement is under control.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;

use crate::font::{desc, text_size};
use crate::layout::{padded, title_height, title_lines, Theme};
use crate::output;
use crate::render2d::{
    check_size, draw_legend, err, samples_along, svg_display_size, GRID, INK, MARK, PALETTE,
    SVG_SCALE,
};
use crate::ticks::{ticks, Ticks};
use crate::{clean3, Figure3, PlotError, Style};

/// Rotation about the vertical axis (radians).
const YAW: f64 = 0.6;
/// Tilt towards the viewer (radians): the floor is seen from above.
const PITCH: f64 = 0.35;
/// Fill of the floor and back walls.
const WALL: RGBColor = RGBColor(246, 246, 246);
/// Shadows of the curves on the floor.
const SHADOW: RGBColor = RGBColor(190, 190, 190);

pub(crate) fn svg(fig: &Figure3, size: (u32, u32)) -> Result<String, PlotError> {
    crate::font::ensure()?;
    check_size(size)?;
    clean3(fig)?;
    let dev = (size.0 * SVG_SCALE, size.1 * SVG_SCALE);
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, dev).into_drawing_area();
        draw3(&root, fig, &Theme::new(size, SVG_SCALE as f64))?;
        root.present().map_err(err)?;
    }
    Ok(svg_display_size(s, dev, size))
}

pub(crate) fn png(fig: &Figure3, size: (u32, u32)) -> Result<Vec<u8>, PlotError> {
    crate::font::ensure()?;
    check_size(size)?;
    clean3(fig)?;
    let ss = 3;
    let dev = (size.0 * ss, size.1 * ss);
    let mut buf = vec![255u8; dev.0 as usize * dev.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, dev).into_drawing_area();
        draw3(&root, fig, &Theme::new(size, ss as f64))?;
        root.present().map_err(err)?;
    }
    output::encode_png(&output::downsample(&buf, dev, ss), size)
}

/// A data-space point (x, y, z) with z vertical.
type P3 = (f64, f64, f64);

fn bounds(pts: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = pts.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    padded(lo, hi)
}

fn unit(v: (f64, f64)) -> (f64, f64) {
    let n = (v.0 * v.0 + v.1 * v.1).sqrt();
    if n > 0.0 {
        (v.0 / n, v.1 / n)
    } else {
        (0.0, 1.0)
    }
}

fn draw3<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure3,
    th: &Theme,
) -> Result<(), PlotError> {
    let clean = clean3(fig)?;
    root.fill(&WHITE).map_err(err)?;
    let (w, _) = root.dim_in_pixel();
    let gap = th.gap as f64;
    let (lines, title_px) = title_lines(&fig.title, th.title, w as f64 - 2.0 * gap);
    let title_h = if fig.title.trim().is_empty() {
        th.gap
    } else {
        title_height(&lines, title_px) + 2 * th.gap
    };
    let (title_area, rest) = root.split_vertically(title_h);
    if !fig.title.trim().is_empty() {
        let style = desc(title_px)
            .color(&INK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let line_h = lines
            .iter()
            .map(|l| text_size(l, title_px).1)
            .max()
            .unwrap_or(0) as f64;
        let step = line_h + (0.25 * title_px).floor();
        let block = title_height(&lines, title_px) as f64;
        let top = title_h as f64 / 2.0 + gap / 2.0 - block / 2.0 + line_h / 2.0;
        for (k, line) in lines.iter().enumerate() {
            title_area
                .draw_text(line, &style, (w as i32 / 2, (top + k as f64 * step) as i32))
                .map_err(err)?;
        }
    }

    let all = || clean.iter().flat_map(|s| s.runs.iter().flatten());
    let rx = bounds(all().map(|p| p.0));
    let ry = bounds(all().map(|p| p.1));
    let rz = bounds(all().map(|p| p.2));
    let (cw, ch) = rest.dim_in_pixel();
    let (cw, ch) = (cw as f64, ch as f64);

    // plotters' 3-D axes are (X, Y vertical, Z); ours are (x, y, z vertical).
    let mut chart = ChartBuilder::on(&rest)
        .build_cartesian_3d(rx.clone(), rz.clone(), ry.clone())
        .map_err(err)?;
    // Box proportions follow the data spans, but no side is shorter than
    // 40 % of the longest (flat trajectories stay readable).
    let spans = [rx.end - rx.start, ry.end - ry.start, rz.end - rz.start];
    let longest = spans.iter().cloned().fold(0.0, f64::max);
    let base = cw.min(ch) * 0.8;
    // plotters maps data to integer "3-D pixels" before projecting: work at
    // PRECISION times the size and scale the projection down to match, so
    // curves don't wobble.
    const PRECISION: f64 = 16.0;
    let side = |s: f64| (PRECISION * base * (s / longest).clamp(0.4, 1.0)).round() as i32;
    chart.set_3d_pixel_range((side(spans[0]), side(spans[2]), side(spans[1])));
    // Fit the projected box into the area, leaving room for the labels.
    let corners: Vec<P3> = [rx.start, rx.end]
        .iter()
        .flat_map(|&x| {
            [ry.start, ry.end]
                .into_iter()
                .flat_map(move |y| [rz.start, rz.end].into_iter().map(move |z| (x, y, z)))
        })
        .collect();
    let project_bbox = |chart: &ChartContext<'_, DB, _>| {
        let coord: &plotters::coord::cartesian::Cartesian3d<_, _, _> = chart.as_coord_spec();
        corners.iter().fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |b, &(x, y, z)| {
                let (px, py) = coord.translate(&(x, z, y));
                (
                    b.0.min(px as f64),
                    b.1.max(px as f64),
                    b.2.min(py as f64),
                    b.3.max(py as f64),
                )
            },
        )
    };
    chart.with_projection(|mut p| {
        p.yaw = YAW;
        p.pitch = PITCH;
        p.scale = 1.0 / PRECISION;
        p.into_matrix()
    });
    let bb = project_bbox(&chart);
    let room_x = cw - 2.0 * (th.label + 5.0 * th.tick + 2.0 * gap);
    let room_y = ch - 2.0 * (th.label + 2.0 * th.tick + 3.0 * gap);
    let scale = (room_x.max(50.0) / (bb.1 - bb.0).max(1.0))
        .min(room_y.max(50.0) / (bb.3 - bb.2).max(1.0))
        .clamp(0.1, 10.0);
    chart.with_projection(|mut p| {
        p.yaw = YAW;
        p.pitch = PITCH;
        p.scale = scale / PRECISION;
        p.into_matrix()
    });

    let coord = chart.as_coord_spec().clone();
    let to_px = |(x, y, z): P3| -> (f64, f64) {
        let (px, py) = coord.translate(&(x, z, y));
        (px as f64, py as f64)
    };
    let depth = |(x, y, z): P3| coord.projected_depth(&x, &z, &y);
    let v = |(x, y, z): P3| (x, z, y);

    // Which walls are at the back: larger projected depth is farther away.
    let x_back = if depth((rx.end, ry.start, rz.start)) > depth((rx.start, ry.start, rz.start)) {
        rx.end
    } else {
        rx.start
    };
    let y_back = if depth((rx.start, ry.end, rz.start)) > depth((rx.start, ry.start, rz.start)) {
        ry.end
    } else {
        ry.start
    };
    let x_front = if x_back == rx.end { rx.start } else { rx.end };
    let y_front = if y_back == ry.end { ry.start } else { ry.end };
    let (z0, z1) = (rz.start, rz.end);

    // Walls: floor, x = x_back, y = y_back.
    let walls: [Vec<P3>; 3] = [
        vec![
            (rx.start, ry.start, z0),
            (rx.end, ry.start, z0),
            (rx.end, ry.end, z0),
            (rx.start, ry.end, z0),
        ],
        vec![
            (x_back, ry.start, z0),
            (x_back, ry.end, z0),
            (x_back, ry.end, z1),
            (x_back, ry.start, z1),
        ],
        vec![
            (rx.start, y_back, z0),
            (rx.end, y_back, z0),
            (rx.end, y_back, z1),
            (rx.start, y_back, z1),
        ],
    ];
    let edge_style = RGBColor(150, 150, 150).stroke_width(th.dpr.round() as u32);
    for wall in &walls {
        chart
            .draw_series(std::iter::once(Polygon::new(
                wall.iter().map(|&p| v(p)).collect::<Vec<_>>(),
                WALL.filled(),
            )))
            .map_err(err)?;
    }

    // Ticks: about one per 90 device pixels of projected edge length.
    let n_for = |a: P3, b: P3| {
        let (pa, pb) = (to_px(a), to_px(b));
        let len = ((pa.0 - pb.0).powi(2) + (pa.1 - pb.1).powi(2)).sqrt();
        ((len / (80.0 * th.dpr)) as usize).clamp(4, 8)
    };
    let tx = ticks(&rx, n_for((rx.start, y_front, z0), (rx.end, y_front, z0)));
    let ty = ticks(&ry, n_for((x_front, ry.start, z0), (x_front, ry.end, z0)));
    let tz = ticks(&rz, n_for((x_back, y_front, z0), (x_back, y_front, z1)));

    // Grid lines on the walls.
    let grid = GRID.stroke_width(th.dpr.round() as u32);
    let mut lines: Vec<[P3; 2]> = Vec::new();
    for &x in &tx.values {
        lines.push([(x, ry.start, z0), (x, ry.end, z0)]);
        lines.push([(x, y_back, z0), (x, y_back, z1)]);
    }
    for &y in &ty.values {
        lines.push([(rx.start, y, z0), (rx.end, y, z0)]);
        lines.push([(x_back, y, z0), (x_back, y, z1)]);
    }
    for &z in &tz.values {
        lines.push([(x_back, ry.start, z), (x_back, ry.end, z)]);
        lines.push([(rx.start, y_back, z), (rx.end, y_back, z)]);
    }
    chart
        .draw_series(
            lines
                .iter()
                .map(|l| PathElement::new(vec![v(l[0]), v(l[1])], grid)),
        )
        .map_err(err)?;
    for wall in &walls {
        let mut outline: Vec<_> = wall.iter().map(|&p| v(p)).collect();
        outline.push(outline[0]);
        chart
            .draw_series(std::iter::once(PathElement::new(outline, edge_style)))
            .map_err(err)?;
    }

    // Axes with ticks, tick labels and titles, outside the box.
    let centre = to_px((
        0.5 * (rx.start + rx.end),
        0.5 * (ry.start + ry.end),
        0.5 * (rz.start + rz.end),
    ));
    let axes: [(P3, P3, &Ticks, usize, &String); 3] = [
        (
            (rx.start, y_front, z0),
            (rx.end, y_front, z0),
            &tx,
            0,
            &fig.labels[0],
        ),
        (
            (x_front, ry.start, z0),
            (x_front, ry.end, z0),
            &ty,
            1,
            &fig.labels[1],
        ),
        (
            (x_back, y_front, z0),
            (x_back, y_front, z1),
            &tz,
            2,
            &fig.labels[2],
        ),
    ];
    let axis_style = INK.stroke_width(th.dpr.round() as u32);
    // The x and y axes meet at the front corner: labels of both there would
    // collide, so neither is written close to it.
    let corner = to_px((x_front, y_front, z0));
    for (a, b, t, k, title) in axes {
        let avoid = if k < 2 { Some(corner) } else { None };
        draw_axis(
            root,
            &to_px,
            (a, b),
            t,
            k,
            title,
            centre,
            avoid,
            th,
            axis_style,
        )?;
    }

    // Curves: shadow on the floor, the curve, start (ring) and end (dot).
    let mut samples = Vec::new();
    let line_w = th.line;
    for s in &clean {
        for run in &s.runs {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    run.iter()
                        .map(|&(x, y, _)| v((x, y, z0)))
                        .collect::<Vec<_>>(),
                    SHADOW.stroke_width(line_w),
                )))
                .map_err(err)?;
        }
    }
    let base_px = rest.get_base_pixel();
    for (i, s) in clean.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        for run in &s.runs {
            let mut px = Vec::with_capacity(run.len());
            let mut kept: Vec<(f64, f64, f64)> = Vec::with_capacity(run.len());
            let mut last = (f64::NAN, f64::NAN);
            for (j, &p) in run.iter().enumerate() {
                let q = to_px(p);
                if !((q.0 - last.0).abs() < 0.5 * th.dpr && (q.1 - last.1).abs() < 0.5 * th.dpr)
                    || j + 1 == run.len()
                {
                    kept.push(v(p));
                    px.push((q.0 - base_px.0 as f64, q.1 - base_px.1 as f64));
                    last = q;
                }
            }
            samples_along(&px, 4.0 * th.dpr, &mut samples);
            if kept.len() >= 2 {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        kept.clone(),
                        color.stroke_width(line_w),
                    )))
                    .map_err(err)?;
            }
        }
        let first = s.runs.first().and_then(|r| r.first());
        let last = s.runs.last().and_then(|r| r.last());
        let r = (th.point as f64 * 1.6).round() as i32;
        if let Some(&p) = first {
            // Drop line to the floor to show the height.
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![v(p), v((p.0, p.1, z0))],
                    MARK.mix(0.5).stroke_width(th.dpr.round() as u32),
                )))
                .map_err(err)?;
            chart
                .draw_series(std::iter::once(Circle::new(v(p), r, WHITE.filled())))
                .map_err(err)?;
            chart
                .draw_series(std::iter::once(Circle::new(
                    v(p),
                    r,
                    color.stroke_width(th.line),
                )))
                .map_err(err)?;
        }
        if let Some(&p) = last {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![v(p), v((p.0, p.1, z0))],
                    MARK.mix(0.5).stroke_width(th.dpr.round() as u32),
                )))
                .map_err(err)?;
            chart
                .draw_series(std::iter::once(Circle::new(v(p), r, color.filled())))
                .map_err(err)?;
        }
    }

    if clean.len() > 1 {
        let labels: Vec<&str> = clean.iter().map(|s| s.label.as_str()).collect();
        draw_legend(&rest, &labels, Style::Line, th, (cw, ch), &samples, &[])?;
    }
    Ok(())
}

/// Draws one axis of the 3-D box along the edge `a`–`b` (data space):
/// the edge, tick marks and labels pointing away from the box centre
/// (none near `avoid`), and the axis title beyond them (the vertical axis'
/// title rotated).
#[allow(clippy::too_many_arguments)]
fn draw_axis<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    to_px: &dyn Fn(P3) -> (f64, f64),
    (a, b): (P3, P3),
    t: &Ticks,
    k: usize,
    title: &str,
    centre: (f64, f64),
    avoid: Option<(f64, f64)>,
    th: &Theme,
    style: ShapeStyle,
) -> Result<(), PlotError> {
    let base = root.get_base_pixel();
    let rel = |p: (f64, f64)| {
        (
            (p.0 - base.0 as f64).round() as i32,
            (p.1 - base.1 as f64).round() as i32,
        )
    };
    let (pa, pb) = (to_px(a), to_px(b));
    root.draw(&PathElement::new(vec![rel(pa), rel(pb)], style))
        .map_err(err)?;
    let mid = ((pa.0 + pb.0) / 2.0, (pa.1 + pb.1) / 2.0);
    // Outward: perpendicular to the edge on screen, away from the centre.
    let along = unit((pb.0 - pa.0, pb.1 - pa.1));
    let mut out = (-along.1, along.0);
    if out.0 * (mid.0 - centre.0) + out.1 * (mid.1 - centre.1) < 0.0 {
        out = (-out.0, -out.1);
    }
    let tick = th.tick_len as f64;
    let horizontal_text = out.0.abs() > 0.6;
    let anchor = if horizontal_text {
        Pos::new(
            if out.0 > 0.0 { HPos::Left } else { HPos::Right },
            VPos::Center,
        )
    } else {
        Pos::new(
            HPos::Center,
            if out.1 > 0.0 { VPos::Top } else { VPos::Bottom },
        )
    };
    let font = desc(th.tick).color(&INK).pos(anchor);
    let mut extent: f64 = 0.0;
    for (&val, label) in t.values.iter().zip(&t.labels) {
        let p = match k {
            0 => (val, a.1, a.2),
            1 => (a.0, val, a.2),
            _ => (a.0, a.1, val),
        };
        let q = to_px(p);
        let q1 = (q.0 + out.0 * tick, q.1 + out.1 * tick);
        root.draw(&PathElement::new(vec![rel(q), rel(q1)], style))
            .map_err(err)?;
        if let Some(c) = avoid {
            if ((q.0 - c.0).powi(2) + (q.1 - c.1).powi(2)).sqrt() < 2.5 * th.tick {
                continue;
            }
        }
        let q2 = (q.0 + out.0 * 2.0 * tick, q.1 + out.1 * 2.0 * tick);
        root.draw_text(label, &font, rel(q2)).map_err(err)?;
        let (tw, tht) = text_size(label, th.tick);
        extent = extent.max(if horizontal_text {
            tw as f64
        } else {
            tht as f64
        });
    }
    let title = title.trim();
    if !title.is_empty() {
        let (_, lh) = text_size(title, th.label);
        let d = 2.0 * tick + extent + th.gap as f64 + lh as f64 / 2.0;
        let p = (mid.0 + out.0 * d, mid.1 + out.1 * d);
        let mut font = desc(th.label)
            .color(&INK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        if k == 2 {
            font = font.transform(FontTransform::Rotate270);
        }
        root.draw_text(title, &font, rel(p)).map_err(err)?;
    }
    Ok(())
}
