//! The model file of an n-link planar pendulum chain (unit masses and lengths, as
//! `examples/pendulum_chain_3.toml`), shared by pdyn-mech's tests and benchmark and
//! pdyn-jit's agreement test.

/// The model file of an n-link chain.
pub fn chain_toml(n: usize) -> String {
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
