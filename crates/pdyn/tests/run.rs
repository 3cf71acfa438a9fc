//! `pdyn run` and `pdyn sweep` on the chapter's examples (library API).

use pdyn::sim::{self, RunSettings};
use pdyn_mech::Model;

fn example(name: &str) -> Model {
    let path = format!("{}/../../examples/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    pdyn_mech::load(&src, &path).unwrap_or_else(|e| panic!("{}", e.render(&src)))
}

fn run_example(name: &str, tweak: impl FnOnce(&mut RunSettings)) -> (Model, sim::RunResult) {
    let mut m = example(name);
    let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
    tweak(&mut set);
    let prep = sim::prepare(&mut m).unwrap();
    let res = sim::run(&prep, &set).unwrap();
    (m, res)
}

fn last(res: &sim::RunResult, col: &str) -> f64 {
    RunSettings::final_value(res, col)
        .unwrap_or_else(|| panic!("no column {col}: {:?}", res.columns))
}

#[test]
fn projectile_with_drag_state_at_5_seconds() {
    let (_, res) = run_example("projectile_drag", |_| {});
    assert!(res.failure.is_none());
    let expected = [
        ("x", 2.7309863f64),
        ("y", 2.7309863),
        ("z", -15.7308060),
        ("x'", 1.3833e-4),
        ("y'", 1.3833e-4),
        ("z'", -4.4294469),
    ];
    for (c, e) in expected {
        let v = last(&res, c);
        // The reference values are printed to 8 significant digits (5 for the tiny rates).
        let tol = if e.abs() < 1e-3 { 5e-8 } else { 6e-8 * e.abs() };
        assert!((v - e).abs() < tol, "{c} = {v}, expected {e}");
    }
    assert_eq!(last(&res, "t"), 5.0);
}

#[test]
fn satellite_warns_at_ode45_settings_and_not_at_rtol_1e5() {
    let (_, loose) = run_example("satellite_ode45", |_| {});
    assert!(
        loose
            .warnings
            .iter()
            .any(|w| w.contains("energy should be conserved")),
        "{:?}",
        loose.warnings
    );
    let energy = loose.monitors.iter().find(|m| m.name == "energy").unwrap();
    assert!(
        energy.drift > 0.1,
        "ode45 settings drift a lot: {}",
        energy.drift
    );

    let (_, tight) = run_example("satellite", |_| {});
    assert!(tight.warnings.is_empty(), "{:?}", tight.warnings);
    let (xi, yi) = (
        tight.columns.iter().position(|c| c == "x").unwrap(),
        tight.columns.iter().position(|c| c == "y").unwrap(),
    );
    let worst = tight
        .rows
        .iter()
        .map(|r| ((r[xi] * r[xi] + r[yi] * r[yi]).sqrt() - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-3, "radius strays by {worst}");
    assert_eq!(last(&tight, "t"), 100.0);
}

#[test]
fn symplectic_satellite_keeps_energy_bounded_over_ten_thousand_orbits() {
    let orbits = 1e4;
    let (_, res) = run_example("satellite", |s| {
        s.method = "symplectic".into();
        s.dt = Some(0.05);
        s.t_end = orbits * 2.0 * std::f64::consts::PI;
        s.points = Some(2001);
    });
    assert!(res.failure.is_none(), "{:?}", res.failure);
    let e = res.columns.iter().position(|c| c == "energy").unwrap();
    let e0 = res.rows[0][e];
    let drift = |rows: &[Vec<f64>]| {
        rows.iter()
            .map(|r| ((r[e] - e0) / e0).abs())
            .fold(0.0, f64::max)
    };
    let half = drift(&res.rows[..1000]);
    let whole = drift(&res.rows);
    assert!(whole < 1e-5, "energy error {whole}");
    // Bounded: the second half of the run does not make it worse in any significant way.
    assert!(
        whole < 1.5 * half,
        "secular growth: first half {half}, whole {whole}"
    );
    assert!(res.warnings.is_empty(), "{:?}", res.warnings);
}

#[test]
fn kremlin_stone_range_from_the_terminal_event() {
    let (m, res) = run_example("kremlin_stone", |_| {});
    let par = |n: &str| m.parameters.iter().find(|p| p.name == n).unwrap().value;
    let (g, h, v0, th) = (par("g"), par("H"), par("v0"), par("theta"));
    let vz = v0 * libm::sin(th);
    let t_hit = (vz + (vz * vz + 2.0 * g * h).sqrt()) / g;
    let range = v0 * libm::cos(th) * t_hit;
    assert_eq!(res.events.len(), 1);
    let ev = &res.events[0];
    assert_eq!(ev.name, "hits the ground");
    assert!(
        ((ev.t - t_hit) / t_hit).abs() < 1e-10,
        "t = {} vs {t_hit}",
        ev.t
    );
    assert!(
        ((ev.state[0] - range) / range).abs() < 1e-8,
        "D = {} vs {range}",
        ev.state[0]
    );
    assert!((range - 37.1).abs() < 0.05, "about 37.1 m: {range}");
    // Terminal: the solution stops exactly at the event.
    assert_eq!(last(&res, "t"), ev.t);
}

#[test]
fn nanoparticle_apex_is_kt_over_mg() {
    let (m, res) = run_example("nanoparticle", |_| {});
    let par = |n: &str| m.parameters.iter().find(|p| p.name == n).unwrap().value;
    let h = par("kB") * par("T") / (par("m") * par("g"));
    let ev = &res.events[0];
    assert!(
        ((ev.state[0] - h) / h).abs() < 1e-8,
        "apex {} vs kT/mg = {h}",
        ev.state[0]
    );
    assert!((h - 0.01).abs() < 0.005, "about 10 mm: {h}");
}

#[test]
fn building_sweep_finds_the_natural_frequencies() {
    let mut m = example("building");
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let spec = m.run.sweep.clone().unwrap();
    let stats: Vec<_> = spec.measures.iter().map(|x| x.stat).collect();
    let prep = sim::prepare(&mut m).unwrap();
    let res = sim::sweep::sweep(&prep, &set, &spec, &stats, &sim::sweep::quiet).unwrap();
    assert!(res.problems.is_empty(), "{:?}", res.problems);
    assert_eq!(res.slices.len(), 1);
    let y: Vec<f64> = res.slices[0].table.iter().map(|r| r[0]).collect();
    let peaks = sim::sweep::peaks(&res.values, &y);
    let resolution = res.values[1] - res.values[0];
    // k = 100, m = 1: omega^2 = (k/m)(3 -+ sqrt(5))
    let w1 = (100.0f64 * (3.0 - 5f64.sqrt())).sqrt();
    let w2 = (100.0f64 * (3.0 + 5f64.sqrt())).sqrt();
    assert_eq!(peaks.len(), 2, "{peaks:?}");
    assert!((peaks[0].0 - w1).abs() < resolution, "{peaks:?} vs {w1}");
    assert!((peaks[1].0 - w2).abs() < resolution, "{peaks:?} vs {w2}");
    assert!((w1 - 8.74).abs() < 0.01 && (w2 - 22.88).abs() < 0.01);
}

#[test]
fn prescribed_and_constrained_models_run() {
    let (_, res) = run_example("rotating_rod_block", |_| {});
    assert!(res.failure.is_none());
    // r(t) = V e^{-mu w t} sinh(sqrt(1+mu^2) w t)/(w sqrt(1+mu^2)) with V = 1, w = 2, mu = 0.3
    let (v, w, mu, t) = (1.0f64, 2.0f64, 0.3f64, 2.0f64);
    let s = (1.0 + mu * mu).sqrt();
    let exact = v * libm::exp(-mu * w * t) * libm::sinh(s * w * t) / (w * s);
    assert!(
        (last(&res, "r") - exact).abs() < 1e-6 * exact,
        "{} vs {exact}",
        last(&res, "r")
    );
    // N = 2 m w r' is reported as a column.
    let n = last(&res, "N");
    assert!((n - 2.0 * w * last(&res, "r'")).abs() < 1e-9 * n.abs());
    let (_, res) = run_example("pulley", |_| {});
    let t = last(&res, "T");
    assert!((t - 2.0 * 2.0 * 1.0 * 9.81 / 3.0).abs() < 1e-12);
    let e = res.monitors.iter().find(|m| m.name == "energy").unwrap();
    assert!(e.drift < 1e-6);
}

/// The numeric path (A x = b compiled and LU-solved per evaluation) agrees with the exact one.
#[test]
fn numeric_linear_solve_matches_the_exact_elimination() {
    use pdyn_mech::DeriveOptions;
    use pdyn_ode::OdeSystem;
    for name in ["pendulum_chain_3", "pulley", "bicycle"] {
        let mut exact_model = example(name);
        // The full budget eliminates all three exactly (a run's own budget leaves the 3-link
        // chain to the numeric path).
        let exact_opts = DeriveOptions {
            simplify_printed: false,
            solve_budget: pdyn_mech::derive::FULL_SOLVE_BUDGET,
            ..DeriveOptions::default()
        };
        let exact = sim::prepare_with(&mut exact_model, &exact_opts).unwrap();
        let mut numeric_model = example(name);
        let opts = DeriveOptions {
            symbolic_limit: 0,
            ..DeriveOptions::default()
        };
        let numeric = sim::prepare_with(&mut numeric_model, &opts).unwrap();
        let n = exact.system.dim();
        let mut seed = 11u64;
        for _ in 0..10 {
            let y: Vec<f64> = (0..n)
                .map(|_| {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                    ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
                })
                .collect();
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            exact.system.rhs(0.3, &y, &mut a);
            numeric.system.rhs(0.3, &y, &mut b);
            for (x, z) in a.iter().zip(&b) {
                assert!(
                    (x - z).abs() < 1e-10 * (1.0 + x.abs()),
                    "{name}: {a:?} vs {b:?}"
                );
            }
            // Reactions too.
            let (mut ia, mut ib) = (Vec::new(), Vec::new());
            exact.system.observation_input(0.3, &y, &mut ia);
            numeric.system.observation_input(0.3, &y, &mut ib);
            for (x, z) in ia.iter().zip(&ib) {
                assert!(
                    (x - z).abs() < 1e-10 * (1.0 + x.abs()),
                    "{name}: {ia:?} vs {ib:?}"
                );
            }
        }
        assert!(exact.system.has_jacobian() && !numeric.system.has_jacobian());
    }
}

/// The analytic Jacobian handed to the stiff solver agrees with finite differences.
#[test]
fn analytic_jacobian_matches_finite_differences() {
    use pdyn_ode::OdeSystem;
    let mut m = example("pendulum_chain_2");
    let prep = sim::prepare(&mut m).unwrap();
    let sys = &prep.system;
    let n = sys.dim();
    let y = [0.3, -0.4, 0.7, 0.2];
    let mut jac = vec![0.0; n * n];
    sys.jacobian(0.0, &y, &mut jac);
    for j in 0..n {
        let h = 1e-6;
        let (mut yp, mut ym) = (y.to_vec(), y.to_vec());
        yp[j] += h;
        ym[j] -= h;
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        sys.rhs(0.0, &yp, &mut fp);
        sys.rhs(0.0, &ym, &mut fm);
        for i in 0..n {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            assert!(
                (fd - jac[i * n + j]).abs() < 1e-6 * (1.0 + fd.abs()),
                "J[{i}][{j}] = {} vs {fd}",
                jac[i * n + j]
            );
        }
    }
    // And the stiff method runs with it.
    let set = RunSettings {
        method: "radau5".into(),
        t_end: 1.0,
        ..RunSettings::from_spec(&m.run.simulate).unwrap()
    };
    let res = sim::run(&prep, &set).unwrap();
    assert!(res.failure.is_none());
    assert!(res.stats.jacobians > 0);
}

/// The 2-storey building's closed form (dsolve on the derived equations) agrees with `pdyn run`.
#[test]
fn building_exact_solution_agrees_with_the_integration() {
    let mut m = example("building");
    let exact = sim::exact::closed_form(&mut m).unwrap();
    let prep = sim::prepare(&mut m).unwrap();
    let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
    set.rtol = Some(1e-12);
    set.atol = Some(1e-12);
    let rep = sim::exact::check(&prep, &exact, &set).unwrap();
    for (name, err, size) in &rep.errors {
        assert!(
            *err < 1e-8 * size.max(1.0),
            "{name}: error {err} (size {size})"
        );
    }
    let ex = sim::exact::run_exact(&prep, &exact, &set).unwrap();
    assert_eq!(ex.method, pdyn::sim::Solver::Exact);
    assert_eq!(ex.rows.len(), rep.run.rows.len());
    // The suspension's closed form is the chapter's.
    let mut s = example("suspension");
    let ex = sim::exact::closed_form(&mut s).unwrap();
    let x = ex.closed.unique().unwrap()[0];
    let mut scope = pdyn_expr::FreeScope::default();
    let expected = s
        .pool
        .parse_in("(L - L0 + m*g/k)*cos(sqrt(k/m)*t) + L0 - m*g/k", &mut scope)
        .unwrap()
        .scalar()
        .unwrap();
    assert!(s.pool.provably_equal(x, expected), "{}", s.pool.to_text(x));
    // Non-linear models say why there is no closed form.
    let mut sat = example("satellite");
    let e = sim::exact::closed_form(&mut sat).err().unwrap();
    assert!(e.to_string().contains("use `pdyn run`"), "{e}");
}

/// A sweep over two parameters covers the grid: the building is linear, so the response to the
/// ground amplitude d0 doubles when d0 doubles, at every frequency.
#[test]
fn two_parameter_sweep_covers_the_grid() {
    let path = format!(
        "{}/../../examples/building.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let src = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "from = 2.0\nto = 30.0\nsteps = 281",
            "values = [5.0, 8.0, 12.0]",
        )
        .replace(
            "[sweep.measures]",
            "[sweep.also]\nd0 = [0.05, 0.1]\n\n[sweep.measures]",
        );
    let mut m =
        pdyn_mech::load(&src, "building2.toml").unwrap_or_else(|e| panic!("{}", e.render(&src)));
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let spec = m.run.sweep.clone().unwrap();
    let stats: Vec<_> = spec.measures.iter().map(|x| x.stat).collect();
    let prep = sim::prepare(&mut m).unwrap();
    let res = sim::sweep::sweep(&prep, &set, &spec, &stats, &sim::sweep::quiet).unwrap();
    assert_eq!(res.runs, 6);
    assert_eq!(res.slices.len(), 2);
    assert_eq!(res.slices[0].fixed, vec![("d0".to_string(), 0.05)]);
    for k in 0..3 {
        let (a, b) = (res.slices[0].table[k][0], res.slices[1].table[k][0]);
        assert!(
            (b / a - 2.0).abs() < 1e-6,
            "omega = {}: {a} vs {b}",
            res.values[k]
        );
    }
}

fn run_source(src: &str, tweak: impl FnOnce(&mut RunSettings)) -> sim::RunResult {
    let mut m = pdyn_mech::load(src, "<test>").unwrap_or_else(|e| panic!("{}", e.render(src)));
    let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
    tweak(&mut set);
    let prep = sim::prepare(&mut m).unwrap();
    sim::run(&prep, &set).unwrap()
}

fn energy(res: &sim::RunResult) -> &sim::MonitorReport {
    res.monitors
        .iter()
        .find(|m| m.name == "energy")
        .expect("energy is monitored")
}

/// The First Law's safeguard measures drift against the quantity's physical scale, so it
/// flags the same run at any scale of units (issue 11: a 1e-25 kg satellite spiralling in was
/// reported "ok").
#[test]
fn drift_is_flagged_at_any_scale_of_units() {
    let satellite = std::fs::read_to_string(format!(
        "{}/../../examples/satellite_ode45.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let mut drifts = Vec::new();
    for mass in ["1.0", "1e-25", "1e30"] {
        let src = satellite.replace("m = 1.0", &format!("m = {mass}"));
        let res = run_source(&src, |_| {});
        let e = energy(&res);
        assert!(e.relative, "{mass}");
        assert!(
            !res.warnings.is_empty(),
            "m = {mass}: the spiral must be flagged"
        );
        drifts.push(e.drift);
    }
    for d in &drifts {
        assert!((d / drifts[0] - 1.0).abs() < 1e-6, "scale-free: {drifts:?}");
    }
}

/// A pendulum released from the horizontal has E = 0 (datum at the pivot): an accurate run is
/// not flagged (issue 11: it was reported DRIFTING by 4.8e8), and an inaccurate one is.
#[test]
fn zero_initial_energy_is_measured_against_the_motion_s_energy() {
    let src = r#"
name = "pendulum released from the horizontal"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
m = 2.0
l = 1.5
[coordinates]
q = { initial = 1.5707963267948966, rate = 0.0 }
[particles.bob]
mass = "m"
position = "l*[sin(q), -cos(q), 0]"
[simulate]
t_end = 10.0
rtol = 1e-10
atol = 1e-12
"#;
    let res = run_source(src, |_| {});
    let e = energy(&res);
    assert!(e.initial.abs() < 1e-12, "E0 = {}", e.initial);
    assert!(e.relative && e.scale > 1.0, "scale {}", e.scale);
    assert!(e.drift < 1e-6, "drift {}", e.drift);
    assert!(res.warnings.is_empty(), "{:?}", res.warnings);
    let coarse = run_source(src, |s| {
        s.rtol = Some(1e-2);
        s.atol = Some(1e-2);
    });
    assert!(energy(&coarse).drift > 5e-3, "{}", energy(&coarse).drift);
    assert!(!coarse.warnings.is_empty());
}

/// Near the building's first resonance (8.7403 rad/s) the formula cancels large terms (issue
/// 11: at ω = 8.7403 it was 3 % off with no warning; then it warned). The stable evaluation
/// (issue 34) is right there, so the DOP853 cross-check that `--method exact` always runs finds
/// nothing to warn about; `tests/resonance.rs` measures it against a 60-digit reference.
#[test]
fn the_closed_form_near_resonance_passes_its_cross_check() {
    let exact_run = |omega: f64| {
        let mut m = example("building");
        let i = m.parameters.iter().position(|p| p.name == "omega").unwrap();
        m.parameters[i].value = omega;
        let exact = sim::exact::closed_form(&mut m).unwrap();
        let prep = sim::prepare(&mut m).unwrap();
        let set = RunSettings::from_spec(&m.run.simulate).unwrap();
        sim::exact::run_exact(&prep, &exact, &set).unwrap()
    };
    for omega in [9.0, 8.7403, 8.740320488976] {
        let res = exact_run(omega);
        assert!(res.warnings.is_empty(), "{omega}: {:?}", res.warnings);
    }
}

/// DOPRI5 forced onto a stiff problem runs out of steps; the failure says why, as dopri5.f
/// does, and what to use instead (issue 11).
#[test]
fn an_explicit_method_stalling_on_a_stiff_problem_says_stiff() {
    let src = r#"
name = "Van der Pol, mu = 1000"
[parameters]
mu = 1000.0
[coordinates]
x = { initial = 2.0, rate = 0.0 }
[particles.p]
mass = 1
position = "[x, 0, 0]"
[[forces]]
kind = "applied"
on = "p"
force = "[mu*(1 - x^2)*x' - x, 0, 0]"
[simulate]
t_end = 3000
method = "dopri5"
max_steps = 20000
"#;
    let res = run_source(src, |_| {});
    let f = res.failure.expect("runs out of steps");
    assert!(f.stiff_at.is_some());
    let text = f.to_string();
    assert!(text.contains("stiff") && text.contains("radau5"), "{text}");
    // And auto (DOPRI5 switching to Radau5) gets through the same span.
    let res = run_source(src, |s| {
        s.method = "auto".into();
        s.t_end = 100.0;
    });
    assert!(
        res.failure.is_none(),
        "{:?}",
        res.failure.map(|f| f.to_string())
    );
}

/// An initial state off a constraint is refused, naming the constraint and the level
/// (issue 11: it was accepted, the only symptom an energy-drift warning).
#[test]
fn initial_states_that_violate_a_constraint_are_refused() {
    let pulley = std::fs::read_to_string(format!(
        "{}/../../examples/pulley.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    for (initial, level) in [
        ("yB = { initial = 0.5, rate = 0.0 }", "position"),
        ("yB = { initial = 0.0, rate = 1.0 }", "velocity"),
    ] {
        let src = pulley.replace("yB = { initial = 0.0, rate = 0.0 }", initial);
        let mut m = pdyn_mech::load(&src, "<test>").unwrap();
        match sim::prepare(&mut m) {
            Err(sim::SimError::InitialStateViolatesConstraint {
                label, level: l, ..
            }) => {
                assert_eq!((label.as_str(), l), ("inextensible cable", level));
            }
            Err(e) => panic!("{initial}: {e}"),
            Ok(_) => panic!("{initial}: accepted"),
        }
    }
    // The example itself satisfies it.
    let mut m = pdyn_mech::load(&pulley, "<test>").unwrap();
    assert!(sim::prepare(&mut m).is_ok());
}

/// The n-link chain of issue 12 (symbolic masses and lengths, the generator of
/// `bench/chain_model.py`), with unequal values and a large swing.
fn chain_source(n: usize) -> String {
    let mut s =
        String::from("name = \"chain\"\ngravity = \"[0, -g, 0]\"\n\n[parameters]\ng = 9.81\n");
    for i in 1..=n {
        s += &format!(
            "m{i} = {}\nl{i} = {}\n",
            0.5 + 0.1 * i as f64,
            1.2 - 0.05 * i as f64
        );
    }
    s += "\n[coordinates]\n";
    for i in 1..=n {
        s += &format!("q{i} = {{ initial = {}, rate = 0.0 }}\n", 0.1 * i as f64);
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
    s + "\n[simulate]\nt_end = 10.0\nrtol = 1e-9\natol = 1e-12\n"
}

/// `pdyn run` of the 10-link chain (numeric solve of `M q'' = f` at every step) conserves
/// energy over 10 s to the order of the tolerance, and a coarse tolerance drifts visibly: the
/// monitor can fail.
#[test]
fn ten_link_chain_conserves_energy_over_ten_seconds() {
    let src = chain_source(10);
    let res = run_source(&src, |s| {
        s.t_end = 10.0;
        s.rtol = Some(1e-9);
        s.atol = Some(1e-12);
    });
    assert!(res.failure.is_none(), "{:?}", res.failure);
    let e = energy(&res);
    assert!(e.drift < 1e-6, "drift {}", e.drift);
    assert!(res.warnings.is_empty(), "{:?}", res.warnings);
    let coarse = run_source(&src, |s| {
        s.t_end = 10.0;
        s.rtol = Some(1e-3);
        s.atol = Some(1e-3);
    });
    assert!(
        energy(&coarse).drift > 10.0 * e.drift,
        "coarse {} vs fine {}",
        energy(&coarse).drift,
        e.drift
    );
}

/// A run eliminates the accelerations symbolically only when that is cheap: the 1- and
/// 2-link chains get a closed form; from 3 links on `M q'' = f` is solved numerically (the
/// elimination of the 3- to 6-link chains took most of their `pdyn run`, which made the
/// run's time fall from n = 4 to n = 8).
#[test]
fn a_run_eliminates_symbolically_only_small_chains() {
    for n in 1..=6 {
        let mut m = pdyn_mech::load(&chain_source(n), "<chain>").unwrap();
        let d = pdyn_mech::derive(&mut m, &sim::run_options()).unwrap();
        assert_eq!(d.solution.is_some(), n <= 2, "n = {n}");
    }
}

/// The full path's measures: `run`, then each statistic over the measure's values at the rows
/// (what sweeps computed before `sim::measured`).
fn measures_from_rows(
    p: &sim::Prepared,
    set: &RunSettings,
    stats: &[pdyn_mech::model::spec::Stat],
) -> (Vec<f64>, sim::RunResult) {
    let res = sim::run(p, set).unwrap();
    let m = p.measures.as_ref().unwrap();
    let n = p.system.n;
    let mut series = vec![Vec::new(); m.len()];
    let mut ts = Vec::new();
    let (mut input, mut out) = (Vec::new(), vec![0.0; m.len()]);
    for row in &res.rows {
        p.system
            .observation_input(row[0], &row[1..1 + 2 * n], &mut input);
        m.eval(&input, &mut out);
        ts.push(row[0]);
        for (s, &o) in series.iter_mut().zip(&out) {
            s.push(o);
        }
    }
    let vals = series
        .iter()
        .zip(stats)
        .map(|(s, &st)| sim::sweep::statistic(st, &ts, s))
        .collect();
    (vals, res)
}

/// Every statistic of `of`, as `[sweep.measures]` entries.
fn all_stats(of: &str) -> String {
    [
        "max",
        "min",
        "max_abs",
        "peak_to_peak",
        "final",
        "mean",
        "rms",
    ]
    .iter()
    .map(|s| format!("{s} = {{ of = \"{of}\", stat = \"{s}\" }}\n"))
    .collect()
}

/// A sweep's measures-only path gives the full path's results bit for bit: measures (every
/// statistic), drift reports, warnings, events, status; on the building (dense output at 2001
/// points, a conserved-free forced system with a monitor) and on the Kremlin stone (a terminal
/// event, energy conserved, output at every step and at given points).
#[test]
fn sweep_measures_equal_the_full_path() {
    let building = std::fs::read_to_string(format!(
        "{}/../../examples/building.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let i = building.find("[sweep.measures]").unwrap();
    let building = format!(
        "{}[sweep.measures]\n{}",
        &building[..i],
        all_stats("y2 - (2*L - 3*m*g/(2*k))")
    )
    .replace(
        "from = 2.0\nto = 30.0\nsteps = 281",
        "values = [3.0, 8.74, 22.9]",
    );
    let kremlin = std::fs::read_to_string(format!(
        "{}/../../examples/kremlin_stone.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
        + "\n[sweep]\nparameter = \"v0\"\nvalues = [5.0, 11.0, 20.0]\n\n[sweep.measures]\n"
        + &all_stats("z - x");
    let (mut checked, mut warned, mut events) = (0, 0, 0);
    for (src, tweaks) in [
        (&building, vec![None, Some(1e-300)]),
        (&kremlin, vec![None, Some(1e-300)]),
    ] {
        let mut m = pdyn_mech::load(src, "<test>").unwrap_or_else(|e| panic!("{}", e.render(src)));
        let spec = m.run.sweep.clone().unwrap();
        let stats: Vec<_> = spec.measures.iter().map(|x| x.stat).collect();
        assert_eq!(stats.len(), 7);
        let prep = sim::prepare(&mut m).unwrap();
        for drift_tolerance in tweaks {
            for points in [None, Some(301)] {
                let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
                if let Some(d) = drift_tolerance {
                    set.drift_tolerance = d;
                }
                if points.is_some() {
                    set.points = points;
                }
                let sw = sim::sweep::sweep(&prep, &set, &spec, &stats, &sim::sweep::quiet).unwrap();
                for (k, &v) in spec.values.iter().enumerate() {
                    let p = prep.with_parameters(&[(spec.parameter, v)]);
                    let (full, res) = measures_from_rows(&p, &set, &stats);
                    let fast = sim::measured::measure(&p, &set, &stats).unwrap();
                    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&fast.measures), bits(&full), "{v}: {full:?}");
                    assert_eq!(bits(&sw.slices[0].table[k]), bits(&full));
                    assert!(full.iter().all(|x| x.is_finite()), "{full:?}");
                    assert_eq!(fast.warnings, res.warnings);
                    assert_eq!(fast.status, res.status);
                    assert_eq!(fast.failure.is_some(), res.failure.is_some());
                    assert_eq!(
                        format!("{:?}", fast.monitors),
                        format!("{:?}", res.monitors)
                    );
                    assert_eq!(format!("{:?}", fast.events), format!("{:?}", res.events));
                    assert_eq!(format!("{:?}", fast.stats), format!("{:?}", res.stats));
                    let problem = sw.problems.iter().find(|(at, _)| at[0].1 == v);
                    assert_eq!(problem.is_some(), !res.warnings.is_empty());
                    if let Some((_, sim::sweep::RunProblem::Warnings(w))) = problem {
                        assert_eq!(w, &res.warnings);
                    }
                    checked += 1;
                    warned += usize::from(!res.warnings.is_empty());
                    events += res.events.len();
                }
            }
        }
    }
    assert_eq!(checked, 24);
    assert!(
        warned >= 6 && events >= 6,
        "{warned} runs warned, {events} events"
    );
}
