//! Times the phases of kinematics from samples on a CSV file (the benchmark of
//! docs/benchmarks.md): `cargo run --release -p pdyn-data --example bench_kin -- FILE`.
use std::time::Instant;

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: bench_kin FILE.csv (columns t,x,y)");
        std::process::exit(2);
    };
    // A bad file is the library's located error, printed, not a panic.
    if let Err(message) = bench(&path) {
        eprintln!("{message}");
        std::process::exit(2);
    }
}

fn bench(path: &str) -> Result<(), String> {
    let t0 = Instant::now();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: cannot read: {e}"))?;
    let t1 = Instant::now();
    let cols =
        pdyn_data::csv::read_columns(path, &text, &["t", "x", "y"]).map_err(|e| e.to_string())?;
    let series =
        pdyn_data::csv::Series::from_columns(cols, 5, "bench").map_err(|e| e.to_string())?;
    let t2 = Instant::now();
    let k = pdyn_data::kinematics::kinematics(&series, pdyn_data::spline::Smoothing::Gcv)
        .map_err(|e| e.to_string())?;
    let t3 = Instant::now();
    let lam: Vec<f64> = k.fits.iter().map(|f| f.lambda).collect();
    let k2 =
        pdyn_data::kinematics::kinematics(&series, pdyn_data::spline::Smoothing::Lambda(lam[0]))
            .map_err(|e| e.to_string())?;
    let t4 = Instant::now();
    println!(
        "{} samples: read {:.3} s, parse {:.3} s, kinematics with GCV {:.3} s (λ {:?}), with λ given {:.3} s ({})",
        k.t.len(),
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        (t3 - t2).as_secs_f64(),
        lam,
        (t4 - t3).as_secs_f64(),
        k2.speed.len()
    );
    Ok(())
}
