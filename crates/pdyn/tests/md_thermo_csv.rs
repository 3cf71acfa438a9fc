//! `thermo.csv` states the degrees of freedom of its temperature column: a last column `dof`,
//! 3N − 3 when the dynamics conserves the total momentum (NVE, as LAMMPS's `compute temp`),
//! 3N under Langevin.

use pdyn::md::{self, RunOptions};
use pdyn_jit::JitMode;
use std::path::Path;

/// 4·4³ = 256 atoms.
fn model(thermostat: &str) -> String {
    format!(
        "name = \"lj\"\n[md]\ndt = 0.005\nsteps = 20\nthermo_every = 10\n\
         [md.species.Ar]\nmass = 1.0\n\n\
         [[md.pairs]]\nkind = \"lj\"\nepsilon = 1.0\nsigma = 1.0\ncutoff = 2.5\n\n\
         [md.lattice]\nkind = \"fcc\"\ndensity = 0.8442\ncells = 4\n\n\
         [md.velocities]\ntemperature = 1.44\nseed = 3\n{thermostat}"
    )
}

fn thermo_csv(text: &str, name: &str) -> String {
    let dir =
        std::env::temp_dir().join(format!("pdyn-md-thermo-csv-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = md::load(text, "m.toml", &[]).unwrap();
    let mut prep = md::build(&spec, Path::new("."), JitMode::Auto).unwrap();
    let opts = RunOptions {
        out: Some(dir.clone()),
        ..RunOptions::default()
    };
    md::run(&mut prep, &opts, &mut |_| {}).unwrap();
    let s = std::fs::read_to_string(dir.join("thermo.csv")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    s
}

fn dof_column(csv: &str) -> Vec<String> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "step",
            "time",
            "temperature",
            "kinetic",
            "potential",
            "total",
            "pressure",
            "conserved",
            "dof"
        ]
    );
    lines
        .map(|l| l.split(',').nth(8).unwrap().to_string())
        .collect()
}

#[test]
fn thermo_csv_states_the_degrees_of_freedom() {
    let nve = dof_column(&thermo_csv(&model(""), "nve"));
    assert_eq!(nve, ["765"; 3]); // 3·256 − 3
    let langevin =
        "[md.thermostat]\nkind = \"langevin\"\ntemperature = 1.0\ndamping = 1.0\nseed = 5\n";
    let nvt = dof_column(&thermo_csv(&model(langevin), "langevin"));
    assert_eq!(nvt, ["768"; 3]); // 3·256
}
