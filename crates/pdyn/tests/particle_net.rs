//! Many free particles in Cartesian coordinates (`pdyn::sim::net`, issue 33): the per-template
//! kernels against the generic symbolic derivation on small nets, energy conservation on an
//! undamped net, set-up that grows linearly (counted, not timed), and the statics (`pdyn modes`,
//! `pdyn equilibrium`) by the kernels against the symbolic linearization and closed forms.

use pdyn::sim::net::linearization::NetLinearization;
use pdyn::sim::net::statics::{equilibrium_from, EquilibriumReport};
use pdyn::sim::{self, NetPath, RunSettings};
use pdyn_jit::JitMode;
use pdyn_mech::equilibrium::{EquilibriumError, EquilibriumOptions};
use pdyn_mech::linearization::Linearize;
use pdyn_mech::statics::{modes_of, About, ModesRequest, Solver, StaticsError};
use pdyn_mech::Model;
use pdyn_ode::OdeSystem;

mod common;
use common::max_relative_difference;

/// An `nx × ny` net as `examples/hanging_net.toml` writes it (corners `P[0,0]` and
/// `P[nx-1,0]` pinned), with drag coefficient `c` (none when `None`).
fn net_source(nx: i64, ny: i64, c: Option<f64>) -> String {
    net_source_with_mass(nx, ny, c, "m")
}

/// [`net_source`] with each particle's mass `mass` (may read `i`, `j`).
fn net_source_with_mass(nx: i64, ny: i64, c: Option<f64>, mass: &str) -> String {
    let mut s = format!(
        r#"
name = "net"
gravity = "[0, 0, -g]"
[indices]
nx = {nx}
ny = {ny}
i = "0..nx-1"
j = "0..ny-1"
[parameters]
m = 0.05
k = 400.0
kd = 100.0
a = 0.1
g = 9.81
c = {c}
[coordinates]
"x[i,j]" = {{ initial = "i*a", rate = 0, where = "not (j == 0 and (i == 0 or i == nx-1))" }}
"y[i,j]" = {{ initial = "j*a", rate = 0, where = "not (j == 0 and (i == 0 or i == nx-1))" }}
"z[i,j]" = {{ initial = 0, rate = 0, where = "not (j == 0 and (i == 0 or i == nx-1))" }}
[points]
"P[i,j]" = {{ position = "[i*a, j*a, 0]", where = "j == 0 and (i == 0 or i == nx-1)" }}
[particles."P[i,j]"]
where = "not (j == 0 and (i == 0 or i == nx-1))"
mass = "{mass}"
position = "[x[i,j], y[i,j], z[i,j]]"
[[forces]]
kind = "spring"
name = "horizontal"
for = "i in 0..nx-2, j"
between = ["P[i,j]", "P[i+1,j]"]
k = "k"
l0 = "a"
[[forces]]
kind = "spring"
name = "vertical"
for = "i, j in 0..ny-2"
between = ["P[i,j]", "P[i,j+1]"]
k = "k"
l0 = "a"
[[forces]]
kind = "spring"
name = "diagonal"
for = "i in 0..nx-2, j in 0..ny-2"
between = ["P[i,j]", "P[i+1,j+1]"]
k = "kd"
l0 = "sqrt(2)*a"
[[forces]]
kind = "spring"
name = "antidiagonal"
for = "i in 0..nx-2, j in 0..ny-2"
between = ["P[i+1,j]", "P[i,j+1]"]
k = "kd"
l0 = "sqrt(2)*a"
"#,
        c = c.unwrap_or(0.0)
    );
    if c.is_some() {
        s += r#"
[[forces]]
kind = "linear_drag"
name = "drag"
for = "i, j"
where = "not (j == 0 and (i == 0 or i == nx-1))"
on = "P[i,j]"
c = "c"
"#;
    }
    s + "[simulate]\nt_end = 0.3\nmethod = \"dop853\"\nrtol = 1e-11\natol = 1e-13\npoints = 4\n"
}

fn load(src: &str) -> Model {
    pdyn_mech::load(src, "<net>").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

fn prepare(src: &str, path: NetPath) -> (Model, sim::Prepared) {
    let mut m = load(src);
    let prep = sim::prepare_on(&mut m, &sim::run_options(), JitMode::Auto, path).unwrap();
    (m, prep)
}

/// A perturbed state of `prep` and the input vector `[t, q, q', parameters]` of the kernels at
/// it, `t = 0.25`.
fn perturbed_input(prep: &sim::Prepared) -> (Vec<f64>, Vec<f64>) {
    let y = perturbed(&prep.y0);
    let parameters = prep.system.parameters();
    let input = [0.25]
        .iter()
        .chain(&y)
        .chain(&parameters)
        .copied()
        .collect();
    (y, input)
}

/// A state away from the initial one, deterministic: every coordinate moved and moving.
fn perturbed(y0: &[f64]) -> Vec<f64> {
    y0.iter()
        .enumerate()
        .map(|(k, &v)| v + 0.01 * libm::sin(1.7 * k as f64 + 0.3))
        .collect()
}

/// The right-hand sides (to 1e-13) and Jacobians (to 1e-12) of `fast` and `generic` agree
/// at the initial state and at a perturbed one.
fn assert_same_derivatives(fast: &sim::Prepared, generic: &sim::Prepared, label: &str) {
    let dim = generic.system.dim();
    assert!(fast.system.has_jacobian() && generic.system.has_jacobian());
    for y in [generic.y0.clone(), perturbed(&generic.y0)] {
        let (mut f1, mut f2) = (vec![0.0; dim], vec![0.0; dim]);
        fast.system.rhs(0.0, &y, &mut f1);
        generic.system.rhs(0.0, &y, &mut f2);
        let d = max_relative_difference(&f2, &f1);
        assert!(d < 1e-13, "{label}: right-hand sides differ by {d:e}");
        let (mut j1, mut j2) = (vec![0.0; dim * dim], vec![0.0; dim * dim]);
        fast.system.jacobian(0.0, &y, &mut j1);
        generic.system.jacobian(0.0, &y, &mut j2);
        let d = max_relative_difference(&j2, &j1);
        assert!(d < 1e-12, "{label}: Jacobians differ by {d:e}");
    }
}

/// The right-hand side, its Jacobian and a short run agree with the generic symbolic path
/// (A x = b solved by the diagonal rule, the Jacobian differentiated entry by entry) on nets
/// of 4, 10 and 23 particles, to round-off.
#[test]
fn kernels_agree_with_the_generic_derivation() {
    for (nx, ny, mass) in [
        (3, 2, "m"),
        (3, 4, "m"),
        (5, 5, "m"),
        // Every particle its own mass: a spring's two ends divide by different masses.
        (4, 3, "m*(1 + i + 2*j)"),
    ] {
        let src = net_source_with_mass(nx, ny, Some(0.02), mass);
        let (_, fast) = prepare(&src, NetPath::Always);
        let (_, generic) = prepare(&src, NetPath::Never);
        assert!(fast.system.net_kernels().is_some(), "{nx}x{ny}: not a net");
        assert!(generic.system.net_kernels().is_none());
        assert_eq!(fast.state_names, generic.state_names);
        assert_eq!(fast.y0, generic.y0);
        assert_eq!(fast.observer.names, generic.observer.names);
        assert_same_derivatives(&fast, &generic, &format!("{nx}x{ny}"));
        let set = RunSettings::from_spec(&load(&src).run.simulate).unwrap();
        let r1 = sim::run(&fast, &set).unwrap();
        let r2 = sim::run(&generic, &set).unwrap();
        assert!(r1.failure.is_none() && r2.failure.is_none());
        let (a, b) = (r1.rows.last().unwrap(), r2.rows.last().unwrap());
        // Positions are ~0.1-0.5 m, speeds ~1 m/s: the adaptive steps amplify round-off.
        let d = max_relative_difference(b, a);
        assert!(d < 1e-9, "{nx}x{ny}: final rows differ by {d:e}");
    }
}

/// A Jacobian by central differences of the kernels' own right-hand side agrees with their
/// analytic one (a wrong derivative or scatter index fails it).
#[test]
fn analytic_jacobian_matches_finite_differences() {
    let src = net_source(3, 3, Some(0.5));
    let (_, prep) = prepare(&src, NetPath::Always);
    let sys = &prep.system;
    let dim = sys.dim();
    let y = perturbed(&prep.y0);
    let mut jac = vec![0.0; dim * dim];
    sys.jacobian(0.0, &y, &mut jac);
    let (mut fp, mut fm) = (vec![0.0; dim], vec![0.0; dim]);
    for j in 0..dim {
        let h = 1e-6;
        let (mut yp, mut ym) = (y.clone(), y.clone());
        yp[j] += h;
        ym[j] -= h;
        sys.rhs(0.0, &yp, &mut fp);
        sys.rhs(0.0, &ym, &mut fm);
        for i in 0..dim {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            let an = jac[i * dim + j];
            assert!(
                (fd - an).abs() <= 1e-5 * (1.0 + an.abs()),
                "∂f{i}/∂y{j}: analytic {an}, finite differences {fd}"
            );
        }
    }
}

/// Without drag the net conserves its energy (springs and gravity have potentials): the run
/// monitors it, and a tight tolerance keeps its drift at round-off.
#[test]
fn undamped_net_conserves_energy() {
    let src = net_source(4, 4, None);
    let (_, prep) = prepare(&src, NetPath::Auto);
    assert!(prep.system.net_kernels().is_some());
    let set = RunSettings::from_spec(&load(&src).run.simulate).unwrap();
    let res = sim::run(&prep, &set).unwrap();
    let energy = res
        .monitors
        .iter()
        .find(|m| m.name == "energy")
        .expect("energy is monitored");
    assert!(energy.conserved && energy.relative);
    assert!(energy.drift < 1e-8, "energy drift {:e}", energy.drift);
    assert!(res.warnings.is_empty(), "{:?}", res.warnings);
    // It moved: the net fell (a run that did nothing would conserve energy too).
    let z = RunSettings::final_value(&res, "z[3,3]").unwrap();
    assert!(z < -0.05, "far corner z = {z}");
}

/// With drag, energy is not monitored as conserved.
#[test]
fn damped_net_monitors_no_energy() {
    let (_, prep) = prepare(&net_source(4, 4, Some(0.02)), NetPath::Auto);
    assert!(prep.system.net_kernels().is_some());
    assert!(!prep.observer.names.iter().any(|n| n == "energy"));
}

/// Set-up grows linearly with the particles (counts, not times): the templates are the same
/// dozen at every size, the kernels' operations per particle and the expression nodes per
/// particle stay constant from ~10^2 to ~10^4 particles.
#[test]
fn setup_counts_grow_linearly() {
    let mut rows = Vec::new();
    for n in [10, 32, 100] {
        let src = net_source(n, n, Some(0.02));
        let (m, prep) = prepare(&src, NetPath::Auto);
        let k = prep.system.net_kernels().expect("a net");
        let particles = (n * n - 2) as f64;
        rows.push((
            n,
            k.len(),
            k.operations() as f64 / particles,
            m.pool.len() as f64 / particles,
        ));
    }
    // What one more particle costs, between consecutive sizes: the boundary (fewer springs
    // per edge particle) makes small nets a little cheaper per particle, so the increments,
    // not the averages, are compared.
    let templates = rows[0].1;
    let increments: Vec<(f64, f64)> = rows
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let (pa, pb) = ((a.0 * a.0 - 2) as f64, (b.0 * b.0 - 2) as f64);
            let d = pb - pa;
            ((b.2 * pb - a.2 * pa) / d, (b.3 * pb - a.3 * pa) / d)
        })
        .collect();
    for &(n, t, _, _) in &rows {
        assert_eq!(t, templates, "templates at n = {n}: {rows:?}");
    }
    let (first, second) = (increments[0], increments[1]);
    assert!(
        (second.0 / first.0 - 1.0).abs() < 0.1,
        "operations per particle: {increments:?}"
    );
    assert!(
        (second.1 / first.1 - 1.0).abs() < 0.1,
        "nodes per particle: {increments:?}"
    );
}

/// A spring between two particles is one element (its force evaluated once for both ends),
/// and the kernels gather only coordinates, each parameter's column being filled once: the
/// counts of an `nx × ny` net with two pinned corners, from its springs (6 of which end at a
/// corner: 3 loads on one particle each) and its particles (one gravity and one drag load
/// each; gravity reads nothing, drag the particle's 3 velocities, a spring its ends' 3
/// positions each).
#[test]
fn each_spring_is_one_element_and_parameters_are_not_gathered() {
    for (nx, ny) in [(3, 3), (5, 4), (10, 10)] {
        let (_, prep) = prepare(&net_source(nx, ny, Some(0.02)), NetPath::Always);
        let k = prep.system.net_kernels().expect("a net");
        let springs = (nx - 1) * ny + nx * (ny - 1) + 2 * (nx - 1) * (ny - 1);
        let at_corners = 6;
        let particles = nx * ny - 2;
        assert_eq!(
            k.elements() as i64,
            springs + 2 * particles,
            "{nx}x{ny}: elements"
        );
        assert_eq!(
            k.gathered() as i64,
            6 * (springs - at_corners) + 3 * at_corners + 3 * particles,
            "{nx}x{ny}: gathered values"
        );
        // Terms of the accelerations: a spring's force on each free end (three components),
        // the drag on each particle (three), gravity (along z). Declared as families, the
        // outputs and the accelerations they add to step together: the sums go by runs, at
        // least four terms each on average. (Summed particle by particle instead, all but
        // gravity's terms would go three at a time, a particle's x, y and z together.)
        let together = 6 * (springs - at_corners) + 3 * at_corners + 3 * particles;
        let terms = (together + particles) as usize;
        match k.summed_by_runs() {
            Some(runs) => {
                assert_eq!(k.terms_summed(), (0, terms), "{nx}x{ny}: terms summed");
                assert!(4 * runs <= terms, "{nx}x{ny}: {runs} runs of {terms} terms");
            }
            None => assert_eq!(k.terms_summed(), (together as usize, terms), "{nx}x{ny}"),
        }
        // The interior springs and the drag read their inputs (the 3 + 3 positions of a
        // spring's ends, the 3 velocities of a drag) in place, stretch by stretch, at 10 x 10,
        // where each family's stretches are 8 or more elements long: two spring templates
        // (the horizontal and vertical springs share one, same k and l0; the two diagonal
        // families the other) and the drag. The springs at the corners (one free end each)
        // are too few and gather.
        let (in_place, stretches, reading) = k.read_in_place();
        if (nx, ny) == (10, 10) {
            assert!(
                k.summed_by_runs().is_some(),
                "the 10 x 10 net's sums go by runs"
            );
            assert_eq!(
                (in_place, reading),
                (3, 3 + 4),
                "{nx}x{ny}: kernels read in place"
            );
            // The drag's one stretch; the structural springs: the horizontal ones (i, j) for
            // i < 9 one stretch but at a corner's spring, the vertical ones (i, j) for j < 9
            // one per i; the diagonals: one per i for each family.
            assert!(
                stretches <= 1 + (2 + 10) + 2 * 9 + 4,
                "{stretches} stretches"
            );
        }
        assert!(in_place <= reading);
    }
}

/// The springs at the pinned corners are templates of a few elements, interpreted: after
/// `NATIVE_AFTER` evaluations they are compiled too, and give the same bits.
#[test]
fn small_templates_compiled_late_give_the_interpreters_bits() {
    use pdyn::sim::net::kernels::NATIVE_AFTER;
    let (_, prep) = prepare(&net_source(5, 4, Some(0.02)), NetPath::Always);
    let k = prep.system.net_kernels().expect("a net");
    let (y, input) = perturbed_input(&prep);
    let n = y.len() / 2;
    let mut first = vec![0.0; n];
    k.accelerations(&input, &mut first);
    let mut again = vec![0.0; n];
    for _ in 1..NATIVE_AFTER {
        k.accelerations_of_state(&y, &input, &mut again);
    }
    assert_eq!(
        k.compiled_late(),
        0,
        "not before {NATIVE_AFTER} evaluations"
    );
    k.accelerations(&input, &mut again);
    if k.is_native() {
        // The two corners' springs (one free end each): one template per corner and family
        // kind (structural, diagonal), each a few elements.
        assert_eq!(k.compiled_late(), 4);
    }
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&again), bits(&first));
}

/// The kernels that read their inputs in place, stretch by stretch, give the bits of the
/// same kernels gathering every input into columns, on a 10 x 10 net at a perturbed state.
#[test]
fn kernels_reading_in_place_give_the_bits_of_gathered_columns() {
    let (_, prep) = prepare(&net_source(10, 10, Some(0.02)), NetPath::Always);
    let k = prep.system.net_kernels().expect("a net");
    let gathering = k.gathering_copy();
    assert_eq!(k.read_in_place().0, 3);
    assert_eq!(gathering.read_in_place(), (0, 0, 7));
    let (y, input) = perturbed_input(&prep);
    let n = y.len() / 2;
    let (mut in_place, mut gathered) = (vec![0.0; n], vec![1.0; n]);
    k.accelerations_of_state(&y, &input, &mut in_place);
    gathering.accelerations_of_state(&y, &input, &mut gathered);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&in_place), bits(&gathered));
    assert!(in_place.iter().all(|a| a.is_finite()) && in_place.iter().any(|&a| a != 0.0));
}

/// The right-hand side reads the state where the integrator keeps it and writes the
/// accelerations where they go (`NetKernels::accelerations_of_state`): the same bits as the
/// accelerations from the input vector `[t, q, q', parameters]`, whatever stale state that
/// vector holds.
#[test]
fn the_state_read_in_place_gives_the_accelerations_of_the_input_vector() {
    let (_, prep) = prepare(&net_source(5, 4, Some(0.02)), NetPath::Always);
    let k = prep.system.net_kernels().expect("a net");
    let (y, input) = perturbed_input(&prep);
    let n = y.len() / 2;
    let mut from_input = vec![0.0; n];
    k.accelerations(&input, &mut from_input);
    // A stale state in the vector: only t and the parameters are read from it.
    let stale: Vec<f64> = [0.25]
        .iter()
        .chain(&prep.y0)
        .chain(&prep.system.parameters())
        .copied()
        .collect();
    let mut in_place = vec![f64::NAN; n];
    k.accelerations_of_state(&y, &stale, &mut in_place);
    for (r, (a, b)) in in_place.iter().zip(&from_input).enumerate() {
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "acceleration {r}: {a:e} against {b:e}"
        );
    }
    // And the system's right-hand side is that: the rates, then the accelerations.
    let mut dydt = vec![f64::NAN; 2 * n];
    prep.system.rhs(0.25, &y, &mut dydt);
    assert_eq!(&dydt[..n], &y[n..]);
    assert!(dydt[n..]
        .iter()
        .zip(&from_input)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
}

/// A parameter's column, filled once, is filled again when the parameter changes (a sweep's
/// `--set`): after new values the right-hand side is still the generic path's, not the one
/// of the old values.
#[test]
fn new_parameter_values_reach_the_kernels() {
    let src = net_source(4, 3, Some(0.02));
    let (_, fast) = prepare(&src, NetPath::Always);
    let (_, generic) = prepare(&src, NetPath::Never);
    let dim = generic.system.dim();
    let y = perturbed(&generic.y0);
    let (mut f1, mut f2) = (vec![0.0; dim], vec![0.0; dim]);
    fast.system.rhs(0.0, &y, &mut f1);
    let before = f1.clone();
    // Every parameter changed: m, k, kd, a, g, c each by its own factor.
    let values: Vec<f64> = fast
        .system
        .parameters()
        .iter()
        .enumerate()
        .map(|(k, v)| v * (1.5 + 0.25 * k as f64))
        .collect();
    fast.system.set_parameters(&values);
    generic.system.set_parameters(&values);
    fast.system.rhs(0.0, &y, &mut f1);
    generic.system.rhs(0.0, &y, &mut f2);
    let d = max_relative_difference(&f2, &f1);
    assert!(
        d < 1e-13,
        "after new parameters, right-hand sides differ by {d:e}"
    );
    assert!(
        max_relative_difference(&before, &f1) > 1e-3,
        "the parameters changed nothing"
    );
}

fn load_deferring(src: &str) -> Model {
    pdyn_mech::model::load_deferring(src, "<net>").unwrap_or_else(|e| panic!("{}", e.render(src)))
}

/// A family's members left unexpanded at load (`load_deferring`: one representative per
/// family, the others index arrays) run as the fully expanded model does: right-hand side,
/// Jacobian and a short run against the generic path, to round-off; and a deferred model
/// sent down the generic path is expanded first (its right-hand side is then the expanded
/// model's, bit for bit).
#[test]
fn deferred_families_agree_with_the_expanded_model() {
    for (nx, ny, mass, c) in [
        (3, 2, "m", Some(0.02)),
        (3, 4, "m", Some(0.02)),
        (5, 5, "m", None),
        (4, 3, "m*(1 + i + 2*j)", Some(0.02)),
    ] {
        let src = net_source_with_mass(nx, ny, c, mass);
        let mut deferred = load_deferring(&src);
        // With masses `m (1 + i + 2 j)` only members whose particles' masses coincide share
        // a representative.
        assert!(deferred.has_deferred(), "{nx}x{ny}");
        let fast = sim::prepare_on(
            &mut deferred,
            &sim::run_options(),
            JitMode::Auto,
            NetPath::Always,
        )
        .unwrap();
        let mut expanded = load_deferring(&src);
        let generic = sim::prepare_on(
            &mut expanded,
            &sim::run_options(),
            JitMode::Auto,
            NetPath::Never,
        )
        .unwrap();
        assert!(!expanded.has_deferred(), "the generic path expands");
        let (_, reference) = prepare(&src, NetPath::Never);
        assert!(fast.system.net_kernels().is_some());
        assert_eq!(fast.state_names, generic.state_names);
        assert_eq!(fast.observer.names, generic.observer.names);
        assert_eq!(fast.y0, generic.y0);
        // The fully loaded model on the fast path: the deferred members join their group
        // where the expanded members stand, so the same terms in the same order.
        let (_, full_fast) = prepare(&src, NetPath::Always);
        let dim = generic.system.dim();
        for y in [generic.y0.clone(), perturbed(&generic.y0)] {
            let (mut f2, mut f3) = (vec![0.0; dim], vec![0.0; dim]);
            generic.system.rhs(0.0, &y, &mut f2);
            reference.system.rhs(0.0, &y, &mut f3);
            assert_eq!(f2, f3, "{nx}x{ny}: the expanded model is the full load's");
            let (mut f1, mut f4) = (vec![0.0; dim], vec![0.0; dim]);
            fast.system.rhs(0.0, &y, &mut f1);
            full_fast.system.rhs(0.0, &y, &mut f4);
            assert_eq!(
                f1, f4,
                "{nx}x{ny}: deferred and full loads on the fast path"
            );
        }
        assert_same_derivatives(&fast, &generic, &format!("{nx}x{ny}"));
        let set = RunSettings::from_spec(&load(&src).run.simulate).unwrap();
        let r1 = sim::run(&fast, &set).unwrap();
        let r2 = sim::run(&generic, &set).unwrap();
        let (a, b) = (r1.rows.last().unwrap(), r2.rows.last().unwrap());
        let d = max_relative_difference(b, a);
        assert!(d < 1e-9, "{nx}x{ny}: final rows differ by {d:e}");
        // Undamped: the energy, formed from every spring's potential (the deferred members'
        // substituted from their representative's), is monitored and agrees.
        let energy = |r: &sim::RunResult| {
            let j = r.columns.iter().position(|c| c == "energy");
            j.map(|j| (r.rows[0][j], r.rows.last().unwrap()[j]))
        };
        assert_eq!(energy(&r1).is_some(), c.is_none(), "{nx}x{ny}");
        if let (Some(e1), Some(e2)) = (energy(&r1), energy(&r2)) {
            // The flat net at rest has energy 0 (its springs at rest length, z = 0); its
            // energies in motion are ~m g a ~ 0.05 J: agreement to 1e-12 J is round-off.
            assert!((e1.0 - e2.0).abs() <= 1e-12, "{e1:?} {e2:?}");
            assert!((e1.1 - e2.1).abs() <= 1e-12, "{e1:?} {e2:?}");
        }
    }
}

/// Loading with deferral builds one member per family (and each spring at a pinned corner,
/// whose pin is a point of its own): the loads and the expression nodes per particle do not
/// grow with the springs. Fails when members are expanded one by one (the loads then grow
/// by ~8 per particle: 4 springs × 2 ends).
#[test]
fn family_members_are_not_expanded_one_by_one() {
    let mut rows = Vec::new();
    for n in [10i64, 20, 40] {
        let m = load_deferring(&net_source(n, n, Some(0.02)));
        let particles = (n * n - 2) as usize;
        let springs = ((n - 1) * n * 2 + 2 * (n - 1) * (n - 1)) as usize;
        let deferred: usize = m.deferred.iter().map(|d| d.len()).sum();
        // 4 spring families and the drag: one representative each; 6 springs end at a pin.
        assert_eq!(m.deferred.len(), 5, "n = {n}");
        assert_eq!(
            deferred,
            springs - 4 - 6 + particles - 1,
            "n = {n}: deferred members"
        );
        // Gravity (one load per particle), the representatives (2 loads per spring, 1 for
        // the drag), the springs at the pins (1 load each).
        assert_eq!(m.loads.len(), particles + 4 * 2 + 1 + 6, "n = {n}: loads");
        rows.push((particles, m.pool.len()));
    }
    // Nodes per added particle: the coordinates, positions, gravity and initial values,
    // not the springs (whose expansion alone made ~100 nodes per particle).
    let per = |a: (usize, usize), b: (usize, usize)| (b.1 - a.1) as f64 / (b.0 - a.0) as f64;
    let (first, second) = (per(rows[0], rows[1]), per(rows[1], rows[2]));
    assert!(second < 40.0, "nodes per particle: {first}, {second}");
    assert!(
        (second / first - 1.0).abs() < 0.1,
        "nodes per particle: {first}, {second}"
    );
}

/// A deferred load gives the errors of a full load, located and naming the member.
#[test]
fn deferred_loading_keeps_the_errors() {
    let good = net_source(4, 4, Some(0.02));
    for (from, to) in [
        // A spring joining a particle to itself, in one member.
        (
            "between = [\"P[i,j]\", \"P[i+1,j]\"]",
            "between = [\"P[i,j]\", \"P[i,j]\"]",
        ),
        // A member outside the family.
        (
            "between = [\"P[i,j]\", \"P[i,j+1]\"]",
            "between = [\"P[i,j]\", \"P[i,j+2]\"]",
        ),
    ] {
        assert!(good.contains(from));
        let bad = good.replacen(from, to, 1);
        let full = pdyn_mech::load(&bad, "<net>").unwrap_err();
        let deferred = pdyn_mech::model::load_deferring(&bad, "<net>").unwrap_err();
        assert_eq!(full, deferred);
        assert!(full.message.contains("[i="), "{}", full.message);
    }
}

/// A deferred model expanded for the generic path keeps the parameter values set before
/// (`--set`), and the initial state that follows from them: it is then the full load with
/// the same values, bit for bit.
#[test]
fn expanding_keeps_the_parameter_values_set() {
    let src = net_source(4, 3, Some(0.02));
    let values = [("k".to_string(), 800.0), ("a".to_string(), 0.2)];
    let mut deferred = load_deferring(&src);
    assert!(deferred.has_deferred());
    pdyn_mech::parameters::set_values(&mut deferred, &values).unwrap();
    let expanded = sim::prepare_on(
        &mut deferred,
        &sim::run_options(),
        JitMode::Auto,
        NetPath::Never,
    )
    .unwrap();
    let mut full = load(&src);
    pdyn_mech::parameters::set_values(&mut full, &values).unwrap();
    let reference = sim::prepare_on(
        &mut full,
        &sim::run_options(),
        JitMode::Auto,
        NetPath::Never,
    )
    .unwrap();
    // The new mesh size moved the initial positions (`initial = "i*a"`).
    assert_eq!(expanded.y0, reference.y0);
    assert!(
        expanded.y0.iter().any(|&x| (x - 0.6).abs() < 1e-12),
        "{:?}",
        expanded.y0
    );
    let dim = reference.system.dim();
    let y = perturbed(&reference.y0);
    let (mut f1, mut f2) = (vec![0.0; dim], vec![0.0; dim]);
    expanded.system.rhs(0.0, &y, &mut f1);
    reference.system.rhs(0.0, &y, &mut f2);
    assert_eq!(f1, f2);
}

// ---- Statics of a net by its kernels (`pdyn modes`, `pdyn equilibrium`) ----

/// `examples/chain_modes.toml` with `n` masses.
fn chain_source(n: usize) -> String {
    let src = include_str!("../../../examples/chain_modes.toml");
    assert!(src.contains("\nn = 30\n"));
    src.replace("\nn = 30\n", &format!("\nn = {n}\n"))
}

/// The net's linearization by its kernels (taken whatever the number of particles).
fn net_linearization(model: &mut Model) -> NetLinearization {
    NetLinearization::new(model, JitMode::Auto, 0).expect("a net of free particles")
}

/// `max |a - b| / max |b|` over two matrices' entries (column-major, as nalgebra iterates).
fn matrix_difference<'a>(
    a: impl Iterator<Item = &'a f64>,
    b: impl Iterator<Item = &'a f64>,
) -> f64 {
    let (a, b): (Vec<f64>, Vec<f64>) = (a.copied().collect(), b.copied().collect());
    assert_eq!(a.len(), b.len());
    max_relative_difference(&b, &a)
}

/// `M`, `K`, `C`, `f` and `M r_d` of the net's kernels agree with the symbolic linearizer's
/// (the model derived, each row's sum of loads differentiated) to 1e-12 of each matrix's
/// largest entry, at the initial state and at a perturbed one: the chain of
/// examples/chain_modes.toml, nets of 4, 10 and 23 particles with and without drag (`C ≠ 0`),
/// loaded in full and with deferred families (as `pdyn modes` loads).
#[test]
fn a_nets_linearization_by_kernels_agrees_with_the_symbolic_one() {
    let sources = [
        ("chain of 30", chain_source(30)),
        ("3x2 net with drag", net_source(3, 2, Some(0.5))),
        ("4x3 net with drag", net_source(4, 3, Some(0.02))),
        ("5x5 net", net_source(5, 5, None)),
        ("5x5 net with drag", net_source(5, 5, Some(0.02))),
    ];
    for (label, src) in &sources {
        let mut symbolic_model = load(src);
        let (_, symbolic) = pdyn_mech::statics::linearize(&mut symbolic_model).unwrap();
        for deferred in [false, true] {
            let mut model = if deferred {
                load_deferring(src)
            } else {
                load(src)
            };
            let net = net_linearization(&mut model);
            assert_eq!(net.names(), &symbolic.names[..], "{label}");
            assert_eq!(net.initial(), &symbolic.initial[..], "{label}");
            for q in [symbolic.initial.clone(), perturbed(&symbolic.initial)] {
                let (a, b) = (net.at(&q), symbolic.at(&q));
                let label = format!("{label} (deferred: {deferred})");
                for (what, x, y) in [
                    ("M", &a.mass, &b.mass),
                    ("K", &a.stiffness, &b.stiffness),
                    ("C", &a.damping, &b.damping),
                ] {
                    let d = matrix_difference(x.iter(), y.iter());
                    assert!(d <= 1e-12, "{label}: {what} differs by {d:e}");
                }
                let d = matrix_difference(a.force.iter(), b.force.iter());
                assert!(d <= 1e-12, "{label}: f differs by {d:e}");
                let has_drag = label.contains("drag");
                assert_eq!(b.damping.iter().any(|&c| c != 0.0), has_drag, "{label}: C");
                assert!(b.stiffness.iter().any(|&k| k != 0.0), "{label}: K = 0");
                for (x, y) in net.inertia_at(&q).iter().zip(symbolic.inertia_at(&q)) {
                    assert_eq!(x, &y, "{label}: M r_d");
                }
                // The sparse form holds the dense one's entries.
                let s = net.at_sparse(&q);
                let d = matrix_difference(s.stiffness.to_dense().iter(), a.stiffness.iter());
                assert_eq!(d, 0.0, "{label}");
            }
        }
    }
}

/// ω_j = 2 sqrt(k/m) sin(j π / (2 (n + 1))) of the uniform chain fixed at both ends.
fn chain_omega(j: usize, n: usize) -> f64 {
    let (k, m) = (100.0f64, 1.0f64); // examples/chain_modes.toml's parameters
    2.0 * (k / m).sqrt() * libm::sin(j as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64))
}

/// The chain's modes on the net path about its equilibrium: all 30 by the dense solver, and
/// the lowest 10 of 1,000 masses by the sparse one, against the closed form to 1e-12.
#[test]
fn the_chains_modes_by_kernels_match_the_closed_form() {
    for (n, solver, count) in [(30, Solver::Dense, None), (1000, Solver::Sparse, Some(10))] {
        let mut model = load_deferring(&chain_source(n));
        let lin = net_linearization(&mut model);
        let request = ModesRequest {
            about: About::Equilibrium,
            solver,
            count,
        };
        let report = modes_of(&lin, &request).unwrap();
        assert_eq!(report.sparse, solver == Solver::Sparse);
        assert_eq!(report.modes.modes.len(), count.unwrap_or(n));
        for (j, mode) in report.modes.modes.iter().enumerate() {
            let exact = chain_omega(j + 1, n);
            let e = (mode.omega - exact).abs() / exact;
            assert!(
                e <= 1e-12,
                "n = {n}, mode {}: {} vs {exact} ({e:e})",
                j + 1,
                mode.omega
            );
        }
        assert!(!report.has_damping);
    }
}

/// `pdyn equilibrium` of the hanging net with drag on the net path equals the symbolic
/// path's: coordinates to 1e-10 m, reactions and tensions to 1e-10 of the weight.
#[test]
fn the_nets_equilibrium_by_kernels_equals_the_symbolic_one() {
    let src = net_source(5, 5, Some(0.02));
    let opts = EquilibriumOptions::default();
    let solve = |from: usize| -> EquilibriumReport {
        equilibrium_from(&mut load_deferring(&src), &opts, from).unwrap()
    };
    let (fast, generic) = (solve(0), solve(usize::MAX));
    assert!(fast.net && !generic.net);
    assert_eq!(fast.names, generic.names);
    for ((name, a), b) in fast.names.iter().zip(&fast.q).zip(&generic.q) {
        assert!((a - b).abs() <= 1e-10, "{name}: {a} vs {b}");
    }
    // The net hangs: it moved from its flat start.
    let sag = fast
        .q
        .iter()
        .zip(&load(&src).coordinates)
        .fold(0.0f64, |s, (q, c)| match c.kind {
            pdyn_mech::model::CoordinateKind::Free { initial, .. } => s.max((q - initial).abs()),
            _ => s,
        });
    assert!(sag > 0.05, "sag {sag}");
    let weight = 23.0 * 0.05 * 9.81;
    assert_eq!(fast.reactions.len(), 2);
    for ((na, ra), (nb, rb)) in fast.reactions.iter().zip(&generic.reactions) {
        assert_eq!(na, nb);
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() <= 1e-10 * weight, "{na}: {ra:?} vs {rb:?}");
        }
    }
    assert_same_tensions(&fast.axial, &generic.axial, 1e-10 * weight);
}

/// Tensions by element: the family (a member's indices dropped: a deferred member is labelled
/// `horizontal (A, B)`, an expanded one `horizontal[i=0, j=1] (A, B)`) and its ends.
fn by_element(axial: &[(String, f64)]) -> std::collections::BTreeMap<(String, String), f64> {
    let mut out = std::collections::BTreeMap::new();
    for (label, t) in axial {
        let cut = label.rfind(" (").unwrap_or(label.len());
        let family = label[..cut].split('[').next().unwrap().to_string();
        let ends = label[cut..].to_string();
        assert!(out.insert((family, ends), *t).is_none(), "{label} twice");
    }
    out
}

fn assert_same_tensions(a: &[(String, f64)], b: &[(String, f64)], tol: f64) {
    assert_eq!(a.len(), b.len());
    let (a, b) = (by_element(a), by_element(b));
    assert_eq!(a.len(), b.len());
    for ((key, ta), (kb, tb)) in a.iter().zip(&b) {
        assert_eq!(key, kb);
        assert!((ta - tb).abs() <= tol, "{key:?}: {ta} vs {tb}");
    }
}

/// `pdyn equilibrium` on a net loaded with its families deferred (one representative per
/// family, index arrays: issue 33) equals the same net loaded in full: the same Newton steps,
/// coordinates, reactions and every spring's tension (the deferred members' computed from
/// their representative's expression) to round-off.
#[test]
fn the_equilibrium_of_a_deferred_net_equals_the_expanded_nets() {
    let src = net_source(6, 5, Some(0.02));
    let opts = EquilibriumOptions::default();
    let mut compact = load_deferring(&src);
    assert!(compact.has_deferred());
    let springs = 5 * 5 + 6 * 4 + 2 * 5 * 4;
    let a = equilibrium_from(&mut compact, &opts, 0).unwrap();
    // Still compact afterwards: nothing was expanded.
    assert!(compact.has_deferred());
    assert!(compact.axial.len() < springs / 2, "{}", compact.axial.len());
    let b = equilibrium_from(&mut load(&src), &opts, 0).unwrap();
    assert!(a.net && b.net);
    assert_eq!(a.names, b.names);
    assert_eq!(a.steps, b.steps);
    for ((name, x), y) in a.names.iter().zip(&a.q).zip(&b.q) {
        assert!((x - y).abs() <= 1e-13, "{name}: {x} vs {y}");
    }
    let weight = 28.0 * 0.05 * 9.81;
    assert_eq!(a.reactions.len(), 2);
    for ((na, ra), (nb, rb)) in a.reactions.iter().zip(&b.reactions) {
        assert_eq!(na, nb);
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() <= 1e-12 * weight, "{na}: {ra:?} vs {rb:?}");
        }
    }
    assert_eq!(a.axial.len(), springs);
    assert_same_tensions(&a.axial, &b.axial, 1e-12 * weight);
}

/// A chain of `n` masses with no walls under gravity along it: a mechanism whose free
/// direction, the rigid translation, the load pushes along.
fn free_chain(n: usize) -> String {
    format!(
        r#"
name = "free chain"
gravity = "[g, 0, 0]"
[indices]
n = {n}
i = "1..n"
[parameters]
m = 1.0
k = 100.0
L = 0.1
g = 9.81
[coordinates]
"x[i]" = {{ initial = "i*L", rate = 0 }}
[particles."P[i]"]
mass = "m"
position = "[x[i], 0, 0]"
[[forces]]
kind = "spring"
name = "spring"
for = "i in 1..n-1"
between = ["P[i+1]", "P[i]"]
k = "k"
l0 = "L"
"#
    )
}

/// A free chain under a load along it has no equilibrium: on the net path, by the dense and
/// the sparse solver, the error names the free direction, every mass moving alike, as the
/// symbolic path does.
#[test]
fn a_free_net_under_load_is_a_mechanism_on_the_net_path() {
    for n in [12, 400] {
        for from in [0, usize::MAX] {
            let mut model = load_deferring(&free_chain(n));
            let e = equilibrium_from(&mut model, &EquilibriumOptions::default(), from);
            let Err(StaticsError::Equilibrium(EquilibriumError::Mechanism { directions, .. })) = e
            else {
                panic!("n = {n}, from {from}: {e:?}");
            };
            assert_eq!(directions.len(), 1, "n = {n}");
            let d = &directions[0];
            assert_eq!(d.moved, n, "n = {n}: {d}");
            let first = d.components[0].1;
            assert!(
                d.components
                    .iter()
                    .all(|(_, c)| (c - first).abs() < 1e-9 * first),
                "n = {n}: {d}"
            );
        }
    }
}

/// Radau5's sparse iteration matrices for many-particle models (issue 33, item 3): the
/// sparse Jacobian a model gives Radau5 is, entry for entry and bit for bit, its dense one
/// (on the kernels' path and on the generic one: the same terms summed in the same order),
/// with nothing outside the pattern; and a Radau5 run of a stiff net then factors sparsely
/// and follows the dense LU's run to round-off.
#[test]
fn radau_gets_the_dense_jacobian_as_a_sparse_one() {
    // 6 × 6 with two pins: 34 particles, 204 states (Radau5 factors sparsely from 200).
    let src = net_source(6, 6, Some(0.5));
    for path in [NetPath::Always, NetPath::Never] {
        let (_, prep) = prepare(&src, path);
        let sys = &prep.system;
        let dim = sys.dim();
        assert!(dim >= pdyn_ode::IMPLICIT_SPARSE_FROM, "{dim} states");
        let pattern = sys.jacobian_sparsity().expect("a pattern for Radau5");
        assert!(sys.has_sparse_jacobian());
        let y = perturbed(&prep.y0);
        let mut dense = vec![0.0; dim * dim];
        sys.jacobian(0.0, &y, &mut dense);
        let mut values = vec![0.0; pattern.nnz()];
        sys.sparse_jacobian(0.0, &y, &mut values);
        let mut in_pattern = vec![false; dim * dim];
        let mut p = 0;
        for j in 0..dim {
            for &i in pattern.column(j) {
                assert_eq!(
                    values[p].to_bits(),
                    dense[i * dim + j].to_bits(),
                    "{path:?}: ∂f{i}/∂y{j}"
                );
                in_pattern[i * dim + j] = true;
                p += 1;
            }
        }
        for (k, &v) in dense.iter().enumerate() {
            assert!(
                in_pattern[k] || v == 0.0,
                "{path:?}: entry {k} = {v} outside the pattern"
            );
        }
        // A net is sparse: each particle meets its neighbours only.
        assert!(pattern.nnz() * 10 < dim * dim, "{} entries", pattern.nnz());
    }
    assert_sparse_follows_dense(pdyn_ode::Method::Radau5, 1e-6);
}

/// The 6 × 6 net with stiff springs (k = 4e5 against m = 0.05: ω ≈ 2,800 rad/s; 204 states)
/// over 0.05 s by `method`, its iteration matrices factored as `LinearSolver::Auto` decides
/// (sparse) and densely: `(auto, dense)`.
fn stiff_net_runs(method: pdyn_ode::Method) -> (pdyn_ode::Solution, pdyn_ode::Solution) {
    use pdyn_ode::{solve, LinearSolver, Options};
    let stiff = net_source(6, 6, Some(0.5)).replace("k = 400.0", "k = 4.0e5");
    let (_, prep) = prepare(&stiff, NetPath::Auto);
    let run = |solver: LinearSolver| {
        let opts = Options {
            rtol: 1e-6.into(),
            atol: 1e-9.into(),
            linear_solver: solver,
            ..Default::default()
        };
        solve(method, &prep.system, (0.0, 0.05), &prep.y0, &opts).unwrap()
    };
    (run(LinearSolver::Auto), run(LinearSolver::Dense))
}

/// The stiff net's run by `method` factors sparsely under `LinearSolver::Auto`, takes the
/// dense LU's number of steps within 2 % (more than 20 of them) and ends within `tolerance`
/// (relative) of the dense run.
fn assert_sparse_follows_dense(method: pdyn_ode::Method, tolerance: f64) {
    let (sparse, dense) = stiff_net_runs(method);
    assert!(sparse.stats.sparse_lu && !dense.stats.sparse_lu);
    let (na, nb) = (dense.stats.accepted, sparse.stats.accepted);
    assert!(na > 20, "{method:?}: {na} steps: not exercised");
    assert!(
        na.abs_diff(nb) * 50 <= na,
        "{method:?}: accepted steps: dense {na}, sparse {nb}"
    );
    let (_, a) = dense.last().unwrap();
    let (_, b) = sparse.last().unwrap();
    let d = max_relative_difference(a, b);
    assert!(
        d < tolerance,
        "{method:?}: sparse and dense runs differ by {d:e}"
    );
}

/// BDF (MATLAB's `ode15s`, SciPy's `BDF`) factors `I − c·J` of a stiff net on the model's
/// sparse pattern too, and follows the dense LU's run to the Newton tolerance.
#[test]
fn bdf_factors_a_stiff_net_sparsely() {
    assert_sparse_follows_dense(pdyn_ode::Method::Bdf, 1e-5);
}

/// Damped Newton on the 20 × 20 hanging net released flat (issue 33): steps that lower the
/// energy carry it down in few steps (a deterministic count; with steps required to lower
/// `|f|` it took 111), to an equilibrium converged to round-off, which the dense path (where
/// the net is small enough for it) finds too.
#[test]
fn the_hanging_nets_newton_takes_few_steps() {
    let opts = EquilibriumOptions::default();
    let big = equilibrium_from(
        &mut load_deferring(&net_source(20, 20, Some(0.02))),
        &opts,
        0,
    )
    .unwrap();
    assert!(big.net);
    assert_eq!(big.q.len(), 1194);
    assert!(big.steps <= 25, "{} Newton steps", big.steps);
    assert!(big.residual <= 1e-13 * big.scale, "{:e}", big.residual);
    // The pins carry the weight of the 398 free nodes, half each.
    let weight = 398.0 * 0.05 * 9.81;
    for (name, r) in &big.reactions {
        assert!((r[2] - weight / 2.0).abs() < 1e-9 * weight, "{name}: {r:?}");
    }
    // A 10 × 10 net (294 coordinates: the dense LU) and the same net by the envelope LDLᵀ
    // from the same start reach one equilibrium.
    let small = net_source(10, 10, Some(0.02));
    let dense = equilibrium_from(&mut load_deferring(&small), &opts, 0).unwrap();
    assert!(dense.steps <= 25, "{} Newton steps", dense.steps);
    let mut model = load_deferring(&small);
    let lin = net_linearization(&mut model);
    let sparse = pdyn_mech::sparse_statics::solve(&lin, None, &opts).unwrap();
    for ((name, a), b) in dense.names.iter().zip(&dense.q).zip(&sparse.q) {
        assert!((a - b).abs() <= 1e-10, "{name}: {a} vs {b}");
    }
}

/// `auto` at a model file's default rtol 1e-6 integrates a net with DOP853 (issue 33's 8 s run
/// of the 20 × 20 net: 35,294 → 17,026 f-evaluations; `Method::auto_explicit`): on the
/// hanging net of the example, released flat with its drag for 2 s, it picks DOP853, spends at
/// most three quarters of DOPRI5's evaluations, and ends where DOPRI5 ends to the tolerance's
/// level.
#[test]
fn auto_takes_dop853_for_a_net_at_the_default_rtol() {
    use pdyn_ode::{solve, Method, Options};
    let (_, prep) = prepare(&net_source(5, 5, Some(0.02)), NetPath::Auto);
    let opts = Options {
        rtol: 1e-6.into(),
        atol: 1e-9.into(),
        ..Default::default()
    };
    let run = |method| solve(method, &prep.system, (0.0, 2.0), &prep.y0, &opts).unwrap();
    let (auto, dopri5) = (run(Method::Auto), run(Method::Dopri5));
    assert_eq!(auto.method, Method::Dop853);
    let (fa, fd) = (auto.stats.fevals, dopri5.stats.fevals);
    assert!(fd > 1000, "{fd} evaluations: not exercised");
    assert!(4 * fa <= 3 * fd, "auto {fa}, DOPRI5 {fd} f-evaluations");
    let (_, a) = auto.last().unwrap();
    let (_, d) = dopri5.last().unwrap();
    let gap = a
        .iter()
        .zip(d)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(gap < 1e-4, "auto and DOPRI5 end {gap:e} apart");
}

/// The net's linearization counting what damped Newton asks of it: the matrices (`K`, `C`,
/// `M` with `f`) and `f` alone. With `force_alone` false it hides that the kernels compute
/// `f` apart (as the symbolic linearizer cannot), and damped Newton computes the whole
/// linearization at every trial step.
struct Counted<'a> {
    lin: &'a NetLinearization,
    force_alone: bool,
    matrices: std::cell::Cell<usize>,
    forces: std::cell::Cell<usize>,
}

impl<'a> Counted<'a> {
    fn new(lin: &'a NetLinearization, force_alone: bool) -> Counted<'a> {
        Counted {
            lin,
            force_alone,
            matrices: Default::default(),
            forces: Default::default(),
        }
    }
}

impl Linearize for Counted<'_> {
    fn names(&self) -> &[String] {
        self.lin.names()
    }
    fn initial(&self) -> &[f64] {
        self.lin.initial()
    }
    fn at_sparse(&self, q: &[f64]) -> pdyn_mech::linearization::SparseLinearization {
        self.matrices.set(self.matrices.get() + 1);
        self.lin.at_sparse(q)
    }
    fn force(&self, q: &[f64]) -> Vec<f64> {
        self.forces.set(self.forces.get() + 1);
        self.lin.force(q)
    }
    fn force_alone(&self) -> bool {
        self.force_alone
    }
    fn at_sparse_with(
        &self,
        q: &[f64],
        force: Vec<f64>,
    ) -> pdyn_mech::linearization::SparseLinearization {
        self.matrices.set(self.matrices.get() + 1);
        self.lin.at_sparse_with(q, force)
    }
    fn inertia_at(&self, q: &[f64]) -> [Vec<f64>; 3] {
        self.lin.inertia_at(q)
    }
}

/// Damped Newton judges a trial step by `f` at its end and computes the matrices only for
/// the steps it takes: on the 10 × 10 hanging net, by the sparse path and by the dense one,
/// the matrices are computed once at the start and once per step taken, `f` once more per
/// trial than when each trial computes the whole linearization, and the path is the same to
/// the last bit (the same `f` at each trial, the same decisions).
#[test]
fn newton_computes_the_matrices_only_for_the_steps_it_takes() {
    let opts = EquilibriumOptions::default();
    let mut model = load_deferring(&net_source(10, 10, Some(0.02)));
    let lin = net_linearization(&mut model);
    let bits = |q: &[f64]| q.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
    for sparse in [true, false] {
        let solve = |counted: &Counted| -> (Vec<f64>, f64, usize) {
            if sparse {
                let e = pdyn_mech::sparse_statics::solve(counted, None, &opts).unwrap();
                (e.q, e.residual, e.steps)
            } else {
                let e = pdyn_mech::equilibrium::solve(counted, None, &opts).unwrap();
                (e.q, e.residual, e.steps)
            }
        };
        let (whole, alone) = (Counted::new(&lin, false), Counted::new(&lin, true));
        let (q_whole, r_whole, steps_whole) = solve(&whole);
        let (q_alone, r_alone, steps) = solve(&alone);
        let path = if sparse { "sparse" } else { "dense" };
        assert_eq!(bits(&q_whole), bits(&q_alone), "{path}");
        assert_eq!(r_whole.to_bits(), r_alone.to_bits(), "{path}");
        assert_eq!(steps_whole, steps, "{path}");
        // Each trial step computed the whole linearization at its end (after the start's).
        let trials = whole.matrices.get() - 1;
        assert_eq!(alone.matrices.get(), 1 + steps, "{path}: {trials} trials");
        assert_eq!(
            alone.forces.get(),
            whole.forces.get() + trials,
            "{path}: {steps} steps of {trials} trials"
        );
        // Some trial steps were refused (their matrices are what is saved).
        assert!(trials > steps, "{path}: {steps} steps of {trials} trials");
    }
}
