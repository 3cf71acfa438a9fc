//! Renders every figure type to SVG and PNG in a temporary directory and
//! checks the files; checks that bad input gives errors, not panics.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use pdyn_plot::{
    equal_aspect_ranges, grid_to_png, grid_to_svg, layout, save, save3, save_grid, save_with_size,
    to_png, to_png3, to_svg, to_svg3, Figure, Figure3, Marker, PlotError, Series, Series3, Style,
    DEFAULT_SIZE,
};

/// A fresh directory under the system temp dir, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("pdyn-plot-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

fn orbit() -> Figure {
    let th = linspace(0.0, 2.0 * PI, 300);
    Figure {
        title: "Orbit".into(),
        x_label: "x [m]".into(),
        y_label: "y [m]".into(),
        series: vec![
            Series::new(
                "circle",
                th.iter().map(|t| libm::cos(*t)).collect(),
                th.iter().map(|t| libm::sin(*t)).collect(),
            ),
            Series::new(
                "ellipse",
                th.iter().map(|t| 2.0 * libm::cos(*t)).collect(),
                th.iter().map(|t| 0.5 * libm::sin(*t)).collect(),
            ),
        ],
        equal_aspect: true,
        markers: vec![Marker::point(0.0, 0.0, "centre")],
        ..Default::default()
    }
}

fn history() -> Figure {
    let t = linspace(0.0, 10.0, 500);
    Figure {
        title: "History".into(),
        x_label: "t [s]".into(),
        y_label: "q [rad]".into(),
        series: vec![
            Series::new("q1", t.clone(), t.iter().map(|t| libm::sin(*t)).collect()),
            Series::new("q2", t.clone(), t.iter().map(|t| libm::cos(*t)).collect()),
            Series::new("q3", t.clone(), t.iter().map(|t| 0.1 * t).collect()),
        ],
        style: Style::LineAndPoints,
        markers: vec![Marker::vline(2.0, "impact"), Marker::hline(0.5, "limit")],
        ..Default::default()
    }
}

fn trajectory() -> Figure3 {
    let t = linspace(0.0, 2.0, 100);
    Figure3 {
        title: "Projectile".into(),
        labels: ["x [m]".into(), "y [m]".into(), "z [m]".into()],
        series: vec![
            Series3::new(
                "ball",
                t.iter().map(|t| 10.0 * t).collect(),
                t.iter().map(|t| 2.0 * t).collect(),
                t.iter().map(|t| 10.0 * t - 4.9 * t * t).collect(),
            ),
            Series3::new(
                "ref",
                t.iter().map(|t| 8.0 * t).collect(),
                t.iter().map(|_| 0.0).collect(),
                t.iter().map(|t| 9.0 * t - 4.9 * t * t).collect(),
            ),
        ],
    }
}

/// Checks the PNG signature and returns (width, height) from IHDR.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(
        bytes.len() > 5_000,
        "PNG suspiciously small: {} bytes",
        bytes.len()
    );
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[12..16], b"IHDR");
    let w = u32::from_be_bytes([bytes[16], bytes[17], bytes[18], bytes[19]]);
    let h = u32::from_be_bytes([bytes[20], bytes[21], bytes[22], bytes[23]]);
    (w, h)
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

fn assert_svg(svg: &str, texts: &[&str]) {
    assert!(svg.starts_with("<svg"), "not an SVG document");
    // Displayed at the image size, drawn on a finer grid.
    assert!(
        svg.starts_with("<svg width=\"1000\" height=\"700\" viewBox=\"0 0 4000 2800\"")
            || !svg.starts_with("<svg width=\"1000\""),
        "{}",
        &svg[..100]
    );
    assert!(svg.trim_end().ends_with("</svg>"));
    for t in texts {
        assert!(svg.contains(t), "SVG lacks {t:?}");
    }
}

#[test]
fn figure_svg_and_png() {
    let dir = TempDir::new("fig");
    for fig in [orbit(), history()] {
        let svg_path = dir.path("f.svg");
        let png_path = dir.path("f.PNG");
        save(&fig, &svg_path).unwrap();
        save(&fig, &png_path).unwrap();
        let svg = String::from_utf8(read(&svg_path)).unwrap();
        let mut texts = vec![
            fig.title.as_str(),
            fig.x_label.as_str(),
            fig.y_label.as_str(),
        ];
        texts.extend(fig.series.iter().map(|s| s.label.as_str()));
        assert_svg(&svg, &texts);
        assert_eq!(png_size(&read(&png_path)), DEFAULT_SIZE);
    }
    // Markers' labels are drawn.
    let svg = to_svg(&history()).unwrap();
    assert_svg(&svg, &["impact", "limit"]);
    assert_eq!(png_size(&to_png(&orbit()).unwrap()), DEFAULT_SIZE);
}

#[test]
fn single_series_has_no_legend() {
    let mut fig = history();
    fig.series.truncate(1);
    fig.series[0].label = "unique-label".into();
    let svg = to_svg(&fig).unwrap();
    assert!(!svg.contains("unique-label"));
    let mut two = fig.clone();
    two.series
        .push(Series::new("", vec![0.0, 1.0], vec![1.0, 0.0]));
    let svg = to_svg(&two).unwrap();
    assert!(svg.contains("unique-label") && svg.contains("series 2"));
}

#[test]
fn figure3_svg_and_png() {
    let dir = TempDir::new("fig3");
    let fig = trajectory();
    save3(&fig, &dir.path("t.svg")).unwrap();
    save3(&fig, &dir.path("t.png")).unwrap();
    let svg = String::from_utf8(read(&dir.path("t.svg"))).unwrap();
    assert_svg(
        &svg,
        &["Projectile", "x [m]", "y [m]", "z [m]", "ball", "ref"],
    );
    assert_eq!(png_size(&read(&dir.path("t.png"))), DEFAULT_SIZE);
    assert_svg(&to_svg3(&fig).unwrap(), &["Projectile"]);
    assert_eq!(png_size(&to_png3(&fig).unwrap()), DEFAULT_SIZE);
    // A single series: no legend.
    let mut one = fig.clone();
    one.series.truncate(1);
    assert!(!to_svg3(&one).unwrap().contains(">\nball\n<"));
}

#[test]
fn grid_svg_and_png() {
    let dir = TempDir::new("grid");
    let figs: Vec<Figure> = ["a", "b", "c", "d", "e"]
        .iter()
        .map(|n| {
            let mut f = history();
            f.title = format!("panel {n}");
            f.series.truncate(1);
            f
        })
        .collect();
    save_grid(&figs, 2, &dir.path("g.svg")).unwrap();
    save_grid(&figs, 2, &dir.path("g.png")).unwrap();
    let svg = String::from_utf8(read(&dir.path("g.svg"))).unwrap();
    assert_svg(
        &svg,
        &["panel a", "panel b", "panel c", "panel d", "panel e"],
    );
    let (w, h) = png_size(&read(&dir.path("g.png")));
    assert_eq!(
        (w, h),
        (2 * pdyn_plot::PANEL_SIZE.0, 3 * pdyn_plot::PANEL_SIZE.1)
    );
    assert!(grid_to_svg(&figs[..1], 3).unwrap().contains("panel a"));
    assert_eq!(
        png_size(&grid_to_png(&figs[..3], 3).unwrap()),
        (3 * pdyn_plot::PANEL_SIZE.0, pdyn_plot::PANEL_SIZE.1)
    );
}

/// The pixel bounding box of the first polyline of the given colour.
fn polyline_bbox(svg: &str, stroke: &str) -> (f64, f64, f64, f64) {
    let start = svg
        .find(&format!("stroke=\"{stroke}\""))
        .expect("series colour not found");
    let rest = &svg[start..];
    let pts_start = rest.find("points=\"").unwrap() + 8;
    let pts = &rest[pts_start..];
    let pts = &pts[..pts.find('"').unwrap()];
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in pts.split_whitespace() {
        let (x, y) = p.split_once(',').unwrap();
        let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
        b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
    }
    b
}

#[test]
fn equal_aspect_gives_equal_units_per_pixel() {
    // Pure range computation.
    let (x, y) = equal_aspect_ranges(-1.0..3.0, 0.0..1.0, (600, 400));
    let (ux, uy) = ((x.end - x.start) / 600.0, (y.end - y.start) / 400.0);
    assert!((ux - uy).abs() < 1e-12 * ux, "{ux} vs {uy}");
    assert_eq!(x, -1.0..3.0, "the wider range is kept");
    assert!(
        (y.start + y.end - 1.0).abs() < 1e-12,
        "the other is centred"
    );

    // The ranges the renderer actually uses, for several image sizes.
    for size in [DEFAULT_SIZE, (400, 900), (1600, 500)] {
        let lay = layout(&orbit(), size).unwrap();
        let (w, h) = lay.plot_size;
        let ux = (lay.x_range.end - lay.x_range.start) / w as f64;
        let uy = (lay.y_range.end - lay.y_range.start) / h as f64;
        assert!((ux - uy).abs() < 1e-9 * ux, "{size:?}: {ux} vs {uy}");
        // All data is inside.
        assert!(lay.x_range.start <= -2.0 && lay.x_range.end >= 2.0);
        assert!(lay.y_range.start <= -1.0 && lay.y_range.end >= 1.0);
    }

    // And the circle drawn in the SVG is as wide as it is tall.
    let mut fig = orbit();
    fig.series.truncate(1);
    fig.series[0].x.iter_mut().for_each(|x| *x *= 5.0);
    fig.series[0].y.iter_mut().for_each(|y| *y *= 5.0);
    let svg = to_svg(&fig).unwrap();
    let (x0, x1, y0, y1) = polyline_bbox(&svg, "#0072B2");
    let (bw, bh) = (x1 - x0, y1 - y0);
    assert!((bw - bh).abs() <= 0.005 * bw, "circle drawn {bw} × {bh}");
}

#[test]
fn non_finite_points_are_skipped_and_break_the_line() {
    let mut y: Vec<f64> = linspace(0.0, 1.0, 50);
    y[20] = f64::NAN;
    y[30] = f64::INFINITY;
    let fig = Figure {
        series: vec![Series::new("gappy", linspace(0.0, 1.0, 50), y)],
        markers: vec![
            Marker::vline(f64::NAN, "never"),
            Marker::point(0.5, f64::INFINITY, "no"),
        ],
        ..Default::default()
    };
    let svg = to_svg(&fig).unwrap();
    let runs = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke=\"#0072B2\""))
        .count();
    assert_eq!(runs, 3, "three runs of finite points");
    assert!(!svg.contains("never"));
    let lay = layout(&fig, DEFAULT_SIZE).unwrap();
    assert!(lay.y_range.end.is_finite() && lay.y_range.end < 1.1);
}

#[test]
fn degenerate_data_renders() {
    let dir = TempDir::new("degenerate");
    let cases = [
        Series::new("constant", vec![0.0, 1.0, 2.0], vec![3.0; 3]),
        Series::new("single point", vec![1.0], vec![1.0]),
        Series::new("zeros", vec![0.0; 4], vec![0.0; 4]),
        Series::new("tiny", vec![0.0, 1e-12], vec![1e-15, 2e-15]),
        Series::new("huge", vec![-1e200, 1e200], vec![1e300, -1e300]),
        Series::new("offset", vec![1e9, 1e9 + 1.0], vec![5.0, 6.0]),
    ];
    for s in cases {
        let fig = Figure {
            title: s.label.clone(),
            series: vec![s],
            style: Style::Points,
            ..Default::default()
        };
        save(&fig, &dir.path("d.png")).unwrap();
        save(&fig, &dir.path("d.svg")).unwrap();
        let mut eq = fig.clone();
        eq.equal_aspect = true;
        to_svg(&eq).unwrap();
    }
}

#[test]
fn degenerate_3d_data_renders() {
    let flat = Series3::new(
        "planar",
        vec![0.0, 1.0, 0.0],
        vec![0.0, 0.0, 1.0],
        vec![0.0; 3],
    );
    let point = Series3::new("point", vec![2.0], vec![2.0], vec![2.0]);
    let gappy = Series3::new(
        "gappy",
        vec![0.0, f64::NAN, 1.0, 2.0],
        vec![1e12, 1e12, f64::INFINITY, 2e12],
        vec![-1e-9, 0.0, 1e-9, 2e-9],
    );
    for s in [flat, point, gappy] {
        let fig = Figure3 {
            title: s.label.clone(),
            series: vec![s],
            ..Default::default()
        };
        to_svg3(&fig).unwrap();
        png_size(&to_png3(&fig).unwrap());
    }
}

#[test]
fn renders_from_many_threads() {
    std::thread::scope(|sc| {
        let handles: Vec<_> = (0..4)
            .map(|i| {
                sc.spawn(move || {
                    let mut fig = history();
                    fig.title = format!("thread {i}");
                    (to_svg(&fig).unwrap(), to_png(&fig).unwrap())
                })
            })
            .collect();
        for (i, h) in handles.into_iter().enumerate() {
            let (svg, png) = h.join().unwrap();
            assert!(svg.contains(&format!("thread {i}")));
            png_size(&png);
        }
    });
}

#[test]
fn long_series_give_small_svg() {
    let n = 200_000;
    let t = linspace(0.0, 100.0, n);
    let y: Vec<f64> = t.iter().map(|t| libm::sin(*t)).collect();
    let fig = Figure {
        series: vec![Series::new("long", t, y)],
        ..Default::default()
    };
    let svg = to_svg(&fig).unwrap();
    assert!(svg.len() < 400_000, "SVG is {} bytes", svg.len());
}

#[test]
fn long_texts_still_render() {
    let mut fig = history();
    fig.title = "A title that is much too long for the figure ".repeat(4);
    fig.y_label = "a y label that is longer than the axis is high ".repeat(3);
    save_with_size(&fig, &TempDir::new("long").path("l.png"), (300, 200)).unwrap();
    assert!(to_svg(&fig).unwrap().contains("much too long"));
}

#[test]
fn glyphs_missing_from_the_font_do_not_fail() {
    let mut fig = history();
    fig.title = "軌道 🚀 ∮ E·dA".into();
    fig.series[0].label = "\u{0}\t\u{200b}".into();
    png_size(&to_png(&fig).unwrap());
    let svg = to_svg(&fig).unwrap();
    assert!(svg.contains("軌道") && !svg.contains('\u{0}'));
}

#[test]
fn text_is_escaped_in_svg() {
    let mut fig = history();
    fig.title = "a < b & c".into();
    let svg = to_svg(&fig).unwrap();
    assert!(svg.contains("a &lt; b &amp; c"));
}

#[test]
fn errors_not_panics() {
    let dir = TempDir::new("errors");
    let png = dir.path("x.png");
    let fig = |series: Vec<Series>| Figure {
        title: "T".into(),
        series,
        ..Default::default()
    };
    assert!(matches!(
        save(&fig(vec![]), &png),
        Err(PlotError::NoSeries { .. })
    ));
    assert!(matches!(
        save(&fig(vec![Series::new("e", vec![], vec![])]), &png),
        Err(PlotError::EmptySeries { .. })
    ));
    let nan = fig(vec![
        Series::new("ok", vec![0.0, 1.0], vec![0.0, 1.0]),
        Series::new("nan", vec![f64::NAN; 3], vec![1.0, 2.0, 3.0]),
    ]);
    match save(&nan, &png) {
        Err(e @ PlotError::NoFiniteData { .. }) => assert!(e.to_string().contains("\"nan\"")),
        other => panic!("{other:?}"),
    }
    assert!(matches!(to_svg(&nan), Err(PlotError::NoFiniteData { .. })));
    assert!(matches!(
        save(
            &fig(vec![Series::new("m", vec![0.0, 1.0], vec![0.0])]),
            &png
        ),
        Err(PlotError::LengthMismatch { .. })
    ));
    let good = history();
    for bad in ["x.jpg", "x", "x.svg.gz", ".png.txt"] {
        match save(&good, &dir.path(bad)) {
            Err(e @ PlotError::UnsupportedFormat { .. }) => {
                assert!(e.to_string().contains(".svg or .png"))
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    // Unwritable: a directory that does not exist, and a path through a file.
    let missing = dir.path("no/such/dir/x.png");
    match save(&good, &missing) {
        Err(e @ PlotError::Io { .. }) => assert!(e.to_string().contains("no/such/dir")),
        other => panic!("{other:?}"),
    }
    std::fs::write(dir.path("file"), b"").unwrap();
    assert!(matches!(
        save(&good, &dir.path("file/x.svg")),
        Err(PlotError::Io { .. })
    ));
    assert!(matches!(
        save3(&trajectory(), &missing),
        Err(PlotError::Io { .. })
    ));
    assert!(matches!(
        save_grid(std::slice::from_ref(&good), 1, &missing),
        Err(PlotError::Io { .. })
    ));
    // Nothing was written by failed calls.
    assert!(!png.exists());

    // Grids and sizes.
    assert!(matches!(
        save_grid(&[], 2, &png),
        Err(PlotError::InvalidArgument { .. })
    ));
    assert!(matches!(
        save_grid(std::slice::from_ref(&good), 0, &png),
        Err(PlotError::InvalidArgument { .. })
    ));
    assert!(matches!(
        save_grid(&[good.clone(), fig(vec![])], 2, &png),
        Err(PlotError::NoSeries { .. })
    ));
    for size in [(10, 10), (0, 500), (20_000, 20_000), (100_000, 300)] {
        assert!(matches!(
            save_with_size(&good, &png, size),
            Err(PlotError::InvalidArgument { .. })
        ));
    }

    // 3-D.
    let mut t3 = trajectory();
    t3.series[1].z.pop();
    assert!(matches!(
        save3(&t3, &png),
        Err(PlotError::LengthMismatch { .. })
    ));
    let mut t3 = trajectory();
    t3.series[0].x.iter_mut().for_each(|x| *x = f64::NAN);
    assert!(matches!(
        save3(&t3, &png),
        Err(PlotError::NoFiniteData { .. })
    ));
    let empty3 = Figure3::default();
    assert!(matches!(to_svg3(&empty3), Err(PlotError::NoSeries { .. })));
    assert!(matches!(
        save3(&trajectory(), &dir.path("t.bmp")),
        Err(PlotError::UnsupportedFormat { .. })
    ));
}
