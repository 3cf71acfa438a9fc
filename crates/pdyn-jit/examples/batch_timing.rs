//! Time per point of a [`BatchKernel`]: the Lennard-Jones pair `(u, f/r)` (ε = σ = 1) at 55
//! squared distances per call (a particle's neighbours in LAMMPS's in.lj), native and
//! interpreted, written in `s = r²` (as `pdyn::md::formula` compiles it: no square root,
//! one division) and in `r`. Best of 5 runs of 400,000 calls.
//!
//! `cargo run --release -p pdyn-jit --example batch_timing`
use pdyn_expr::{Id, Pool, Program};
use pdyn_jit::{BatchKernel, JitMode};
use std::time::Instant;

type Error = Box<dyn std::error::Error>;

fn kernel(vars: &str, srcs: &[&str], mode: JitMode) -> Result<BatchKernel, Error> {
    let mut p = Pool::new();
    let x = p.var(vars);
    let mut outs: Vec<Id> = Vec::with_capacity(srcs.len());
    for s in srcs {
        outs.push(p.parse_scalar(s).map_err(|e| format!("{s}: {e:?}"))?);
    }
    let prog = Program::compile(&mut p, &[x], &outs).map_err(|e| format!("{e:?}"))?;
    Ok(BatchKernel::new(&prog, mode).ok_or("an operation the batch kernel does not know")?)
}

fn main() -> Result<(), Error> {
    let n = 55;
    let s: Vec<f64> = (0..n).map(|k| 0.8 + 5.4 * k as f64 / n as f64).collect();
    let r: Vec<f64> = s.iter().map(|x| x.sqrt()).collect();
    let cases = [
        (
            "s",
            vec!["4*(s^(-6) - s^(-3))", "48*s^(-7) - 24*s^(-4)"],
            &s,
        ),
        (
            "r",
            vec!["4*(r^(-12) - r^(-6))", "48*r^(-14) - 24*r^(-8)"],
            &r,
        ),
    ];
    for mode in [JitMode::Auto, JitMode::Off] {
        for (v, srcs, x) in &cases {
            let k = kernel(v, &srcs.iter().map(|s| &**s).collect::<Vec<_>>(), mode)?;
            let (mut u, mut f) = (vec![0.0; n], vec![0.0; n]);
            let reps = 400_000;
            let mut best = f64::INFINITY;
            for _ in 0..5 {
                let t = Instant::now();
                for _ in 0..reps {
                    k.run(&[std::hint::black_box(&x[..])], &mut [&mut u, &mut f]);
                }
                best = best.min(t.elapsed().as_secs_f64() / (reps * n) as f64);
            }
            println!(
                "{mode:?} {} steps={} {:.2} ns/pair",
                srcs[0],
                k.len(),
                best * 1e9
            );
        }
    }
    Ok(())
}
