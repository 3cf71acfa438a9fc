//! Renders the sample figures used to judge the look of pdyn-plot:
//! `cargo run -p pdyn-plot --example gallery -- OUT_DIR` writes orbit,
//! history, trajectory3d and grid, each as .png and .svg.

use std::f64::consts::PI;
use std::path::PathBuf;

use pdyn_plot::{save, save3, save_grid, Figure, Figure3, Marker, Series, Series3, Style};

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Two orbits: a circle of radius 1 and an ellipse (e = 0.5).
fn orbit() -> Figure {
    let th = linspace(0.0, 2.0 * PI, 400);
    let circle = Series::new(
        "circular, r = 1 AU",
        th.iter().map(|t| libm::cos(*t)).collect(),
        th.iter().map(|t| libm::sin(*t)).collect(),
    );
    let (a, e) = (1.5, 0.5);
    let b = a * (1.0f64 - e * e).sqrt();
    let ellipse = Series::new(
        "elliptic, e = 0.5",
        th.iter().map(|t| a * libm::cos(*t) - a * e).collect(),
        th.iter().map(|t| b * libm::sin(*t)).collect(),
    );
    Figure {
        title: "Kepler orbits".into(),
        x_label: "x [AU]".into(),
        y_label: "y [AU]".into(),
        series: vec![circle, ellipse],
        equal_aspect: true,
        markers: vec![Marker::point(0.0, 0.0, "Sun")],
        ..Default::default()
    }
}

/// Damped pendulum angle, rate and energy with event markers.
fn history() -> Figure {
    let t = linspace(0.0, 20.0, 2001);
    let q: Vec<f64> = t
        .iter()
        .map(|t| libm::exp(-0.15 * t) * libm::cos(2.0 * t))
        .collect();
    let w: Vec<f64> = t
        .iter()
        .map(|t| -libm::exp(-0.15 * t) * (2.0 * libm::sin(2.0 * t) + 0.15 * libm::cos(2.0 * t)))
        .collect();
    let e: Vec<f64> = q
        .iter()
        .zip(&w)
        .map(|(q, w)| 0.5 * w * w + 2.0 * q * q)
        .collect();
    Figure {
        title: "Damped pendulum".into(),
        x_label: "time t [s]".into(),
        y_label: "θ [rad], ω [rad/s], E [J]".into(),
        series: vec![
            Series::new("angle θ", t.clone(), q),
            Series::new("rate ω", t.clone(), w),
            Series::new("energy E", t, e),
        ],
        markers: vec![
            Marker::vline(3.0, "kick"),
            Marker::vline(3.4, "contact"),
            Marker::vline(12.5, "release"),
            Marker::hline(0.0, ""),
        ],
        ..Default::default()
    }
}

/// A projectile with quadratic drag and a drag-free reference.
fn trajectory() -> Figure3 {
    let mut series = Vec::new();
    for (label, k) in [("with drag", 0.02), ("no drag", 0.0)] {
        let (mut p, mut v) = ([0.0f64, 0.0, 0.0], [18.0f64, 8.0, 25.0]);
        let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
        let dt = 0.01;
        while p[2] >= 0.0 {
            x.push(p[0]);
            y.push(p[1]);
            z.push(p[2]);
            let s = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let a = [-k * s * v[0], -k * s * v[1] + 1.5, -9.81 - k * s * v[2]];
            for i in 0..3 {
                v[i] += a[i] * dt;
                p[i] += v[i] * dt;
            }
        }
        series.push(Series3::new(label, x, y, z));
    }
    Figure3 {
        title: "Projectile in a cross-wind".into(),
        labels: ["x [m]".into(), "y [m]".into(), "height z [m]".into()],
        series,
    }
}

/// Each coordinate of a Lissajous-like motion against time.
fn grid() -> Vec<Figure> {
    let t = linspace(0.0, 10.0, 1001);
    let panel = |name: &str, unit: &str, f: &dyn Fn(f64) -> f64, style: Style| Figure {
        title: name.to_string(),
        x_label: "t [s]".into(),
        y_label: format!("{name} [{unit}]"),
        series: vec![Series::new(
            name,
            t.clone(),
            t.iter().map(|&t| f(t)).collect(),
        )],
        style,
        ..Default::default()
    };
    vec![
        panel("x", "m", &|t| libm::sin(1.3 * t), Style::Line),
        panel("y", "m", &|t| 0.5 * libm::cos(2.1 * t), Style::Line),
        panel(
            "vx",
            "m/s",
            &|t| 1.3 * libm::cos(1.3 * t) * 1e-3,
            Style::Line,
        ),
        panel(
            "vy",
            "m/s",
            &|t| -1.05 * libm::sin(2.1 * t) + 1e4,
            Style::Line,
        ),
    ]
}

/// An inclined circular orbit and a precessing one, in 3-D.
fn orbit3d() -> Figure3 {
    let th = linspace(0.0, 6.0 * PI, 3000);
    let inc: f64 = 0.5;
    let circ = Series3::new(
        "inclined circle",
        th.iter().map(|t| 7000.0 * libm::cos(*t)).collect(),
        th.iter()
            .map(|t| 7000.0 * libm::sin(*t) * libm::cos(inc))
            .collect(),
        th.iter()
            .map(|t| 7000.0 * libm::sin(*t) * libm::sin(inc))
            .collect(),
    );
    let prec = Series3::new(
        "precessing",
        th.iter().map(|t| 9000.0 * libm::cos(t + 0.1 * t)).collect(),
        th.iter()
            .map(|t| 9000.0 * libm::sin(t * 1.1) * libm::cos(0.2 * t))
            .collect(),
        th.iter()
            .map(|t| 9000.0 * libm::sin(t * 1.1) * libm::sin(0.2 * t))
            .collect(),
    );
    Figure3 {
        title: "Satellite orbits".into(),
        labels: ["x [km]".into(), "y [km]".into(), "z [km]".into()],
        series: vec![circ, prec],
    }
}

/// A scatter of Poincaré-section points.
fn poincare() -> Figure {
    let (mut x, mut y) = (vec![], vec![]);
    let (mut q, mut p) = (0.1f64, 0.0f64);
    for _ in 0..3000 {
        p += 0.9 * libm::sin(q);
        q += p;
        x.push(q.rem_euclid(2.0 * PI));
        y.push(p);
    }
    let (mut x2, mut y2) = (vec![], vec![]);
    let (mut q, mut p) = (3.0f64, 1.0f64);
    for _ in 0..3000 {
        p += 0.9 * libm::sin(q);
        q += p;
        x2.push(q.rem_euclid(2.0 * PI));
        y2.push(p);
    }
    Figure {
        title: "Standard map, K = 0.9".into(),
        x_label: "q [rad]".into(),
        y_label: "p".into(),
        series: vec![Series::new("orbit A", x, y), Series::new("orbit B", x2, y2)],
        style: Style::Points,
        markers: vec![Marker::point(PI, 0.0, "fixed point")],
        ..Default::default()
    }
}

/// Amplitude response of a damped oscillator for three dampings, with the
/// resonance peaks marked (what `pdyn sweep` plots).
fn resonance() -> Figure {
    let w = linspace(0.0, 3.0, 600);
    let mut series = Vec::new();
    let mut markers = Vec::new();
    for zeta in [0.05f64, 0.15, 0.4] {
        let a: Vec<f64> = w
            .iter()
            .map(|w| 1.0 / ((1.0 - w * w).powi(2) + (2.0 * zeta * w).powi(2)).sqrt())
            .collect();
        let (i, peak) = a
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
        markers.push(Marker::point(
            w[i],
            peak,
            format!("{peak:.1} at {:.2}", w[i]),
        ));
        series.push(Series::new(format!("ζ = {zeta}"), w.clone(), a));
    }
    Figure {
        title: "Frequency response of a building storey (long titles shrink to fit the width)"
            .into(),
        x_label: "forcing frequency ω/ω₀".into(),
        y_label: "amplitude ratio X/X_st".into(),
        series,
        markers,
        ..Default::default()
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    std::fs::create_dir_all(&dir)?;
    for ext in ["png", "svg"] {
        save(&orbit(), &dir.join(format!("orbit.{ext}")))?;
        save(&history(), &dir.join(format!("history.{ext}")))?;
        save3(&trajectory(), &dir.join(format!("trajectory3d.{ext}")))?;
        save_grid(&grid(), 2, &dir.join(format!("grid.{ext}")))?;
        save3(&orbit3d(), &dir.join(format!("orbit3d.{ext}")))?;
        save(&poincare(), &dir.join(format!("poincare.{ext}")))?;
        save(&resonance(), &dir.join(format!("resonance.{ext}")))?;
        pdyn_plot::save_with_size(&history(), &dir.join(format!("small.{ext}")), (400, 300))?;
    }
    println!("wrote to {}", dir.display());
    Ok(())
}
