//! `pdyn derive` on an n-link planar pendulum chain (particles joined by massless rigid links,
//! coordinates = link angles): parse the model file, differentiate, and form the projected
//! equations `M(q) q'' = f` — the work SymPy's `KanesMethod.kanes_equations` does
//! (`bench/sympy_chain.py`; both in one run: `bench/chain_vs_sympy.sh`).

use divan::{black_box, Bencher};
use pdyn_mech::derive::Form;
use pdyn_mech::{derive, load, DeriveOptions};

fn main() {
    divan::main();
}

#[path = "../tests/common/chain.rs"]
mod chain;
use chain::chain_toml;

#[divan::bench(args = [2, 4, 8, 16, 32, 64, 100], sample_count = 5, sample_size = 1)]
fn derive_chain(b: Bencher, n: usize) {
    let src = chain_toml(n);
    let opts = DeriveOptions {
        form: Form::Projected,
        symbolic_limit: 0,
        simplify: false,
        ..DeriveOptions::default()
    };
    b.bench(|| {
        let mut m = load(black_box(&src), "chain.toml").unwrap();
        let d = derive(&mut m, &opts).unwrap();
        black_box(d.system.a.len())
    });
}
