//! Library-internal timing: a throughput loop over 2·10^7 arguments per function, then the
//! number of arguments (of 3·10^6) where std and libm give different bits. The std calls are
//! the point of the comparison (clippy.toml forbids them in pdyn itself).
#![allow(clippy::disallowed_methods)]
use std::hint::black_box;
use std::time::Instant;
fn bench(name: &str, f: impl Fn(f64) -> f64) {
    let n = 20_000_000;
    let t = Instant::now();
    let mut s = 0.0;
    for i in 0..n { s += f(black_box(i as f64 * 1.7e-6 + 0.1)); }
    black_box(s);
    println!("{name}: {:.2} ns", t.elapsed().as_secs_f64() / n as f64 * 1e9);
}
fn main() {
    bench("std sin", |x| x.sin()); bench("libm sin", libm::sin);
    bench("std cos", |x| x.cos()); bench("libm cos", libm::cos);
    bench("std exp", |x| x.exp()); bench("libm exp", libm::exp);
    bench("std ln", |x| x.ln()); bench("libm log", libm::log);
    bench("std powf", |x| x.powf(-0.2)); bench("libm pow", |x| libm::pow(x, -0.2));
    bench("std atan2", |x| x.atan2(0.3)); bench("libm atan2", |x| libm::atan2(x, 0.3));
    let mut diff = 0; let n=1_000_000;
    for i in 0..n { let x = i as f64 * 1.3e-4 - 50.0; if x.sin()!=libm::sin(x) {diff+=1;} if x.exp()!=libm::exp(x){diff+=1;} if x.abs().powf(0.37)!=libm::pow(x.abs(),0.37){diff+=1;} }
    println!("differ: {diff} of {}", 3*n);
}
