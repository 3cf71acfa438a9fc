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

/// The model file of an n-link chain.
fn chain_toml(n: usize) -> String {
    let mut s =
        String::from("name = \"chain\"\ngravity = \"[0, -g, 0]\"\n\n[parameters]\ng = 9.81\n");
    for i in 1..=n {
        s += &format!("m{i} = 1.0\nl{i} = 1.0\n");
    }
    s += "\n[coordinates]\n";
    for i in 1..=n {
        s += &format!("q{i} = {{ initial = 0.1, rate = 0.0 }}\n");
    }
    for i in 1..=n {
        let pos: Vec<String> = (1..=i)
            .map(|j| format!("l{j}*[sin(q{j}), -cos(q{j}), 0]"))
            .collect();
        s += &format!(
            "\n[particles.p{i}]\nmass = \"m{i}\"\nposition = \"{}\"\n",
            pos.join(" + ")
        );
    }
    s
}

#[divan::bench(args = [2, 4, 8, 16, 32, 64, 100], sample_count = 5, sample_size = 1)]
fn derive_chain(b: Bencher, n: usize) {
    let src = chain_toml(n);
    let opts = DeriveOptions {
        form: Form::Projected,
        symbolic_limit: 0,
        simplify: false,
    };
    b.bench(|| {
        let mut m = load(black_box(&src), "chain.toml").unwrap();
        let d = derive(&mut m, &opts).unwrap();
        black_box(d.system.a.len())
    });
}
