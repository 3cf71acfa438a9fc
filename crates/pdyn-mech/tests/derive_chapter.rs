//! Derived equations of the chapter's systems match the chapter's (examples/ hold the models).

use pdyn_expr::{FreeScope, Id, Pool, Program};
use pdyn_mech::derive::UnknownKind;
use pdyn_mech::model::CoordinateKind;
use pdyn_mech::{derive, load, DeriveOptions, Model};

fn example(name: &str) -> Model {
    let path = format!("{}/../../examples/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&path).unwrap();
    match load(&src, &path) {
        Ok(m) => m,
        Err(e) => panic!("{}", e.render(&src)),
    }
}

/// Solved expression for the unknown named `name`.
fn solved(m: &mut Model, name: &str) -> Id {
    let d = derive(m, &DeriveOptions::default()).unwrap();
    let sol = d.solution.as_ref().expect("solved symbolically");
    let k = d.unknowns.iter().position(|u| u.name == name).unwrap();
    sol[k]
}

/// Parses `expected` with the model's free coordinates as functions of time.
fn same(m: &mut Model, got: Id, expected: &str) {
    let coords: Vec<String> = m
        .coordinates
        .iter()
        .filter(|c| matches!(c.kind, CoordinateKind::Free { .. }))
        .map(|c| c.name.clone())
        .collect();
    let mut scope = FreeScope::with_coordinates(coords.iter().map(String::as_str));
    let p = &mut m.pool;
    let e = p.parse_in(expected, &mut scope).unwrap().scalar().unwrap();
    assert!(
        p.provably_equal(got, e),
        "got {}, expected {expected}",
        p.to_text(got)
    );
}

#[test]
fn suspension_3_3_2_example_2() {
    let mut m = example("suspension");
    let x = solved(&mut m, "x''");
    same(&mut m, x, "-(g + k*(x - L0)/m)");
    let r = solved(&mut m, "R");
    assert_eq!(r, Pool::ZERO);
}

#[test]
fn rotating_rod_pushing_block_3_3_2_example_3() {
    let mut m = example("rotating_rod_block");
    let r = solved(&mut m, "r''");
    // r'' + 2 mu omega r' - omega^2 r = 0
    same(&mut m, r, "-2*mu*omega*r' + omega^2*r");
    let n = solved(&mut m, "N");
    same(&mut m, n, "2*m*omega*r'");
}

#[test]
fn projectile_with_drag_3_3_3_example_1() {
    let mut m = example("projectile_drag");
    let v = "sqrt(x'^2 + y'^2 + z'^2)";
    let x = solved(&mut m, "x''");
    same(&mut m, x, &format!("-c*{v}*x'"));
    let z = solved(&mut m, "z''");
    same(&mut m, z, &format!("-g - c*{v}*z'"));
}

#[test]
fn satellite_3_3_3_example_2() {
    let mut m = example("satellite");
    let x = solved(&mut m, "x''");
    same(&mut m, x, "-GM*x/(x^2 + y^2)^(3/2)");
    let y = solved(&mut m, "y''");
    same(&mut m, y, "-GM*y/(x^2 + y^2)^(3/2)");
}

#[test]
fn building_3_3_3_example_3_keeps_gravity_on_the_first_floor() {
    let mut m = example("building");
    let y1 = solved(&mut m, "y1''");
    // The chapter's derivation (its MATLAB listing drops the -g):
    same(
        &mut m,
        y1,
        "-g - 2*k/m*(y1 - d0*sin(omega*t) - L) + 2*k/m*(y2 - y1 - L)",
    );
    let y2 = solved(&mut m, "y2''");
    same(&mut m, y2, "-g - 2*k/m*(y2 - y1 - L)");
}

#[test]
fn pulley_3_2_example_4_reports_the_tension() {
    let mut m = example("pulley");
    let t = solved(&mut m, "T");
    same(&mut m, t, "2*mA*mB*g/(mA + mB)");
    let a = solved(&mut m, "yA''");
    same(&mut m, a, "g*(mB - mA)/(mA + mB)");
}

/// Independent hand derivation of an n-link chain (Lagrange): with μ_jk = Σ_{p ≥ max(j,k)} m_p,
/// Σ_k μ_jk l_j l_k [cos(q_j - q_k) q_k'' + sin(q_j - q_k) q_k'^2] + g l_j sin(q_j) Σ_{p≥j} m_p = 0.
#[allow(clippy::needless_range_loop)] // Gaussian elimination reads best with indices
fn chain_accelerations(m: &[f64], l: &[f64], q: &[f64], qd: &[f64], g: f64) -> Vec<f64> {
    let n = m.len();
    let mu = |j: usize, k: usize| -> f64 { m[j.max(k)..].iter().sum() };
    let mut a = vec![vec![0.0; n + 1]; n];
    for j in 0..n {
        let mut rhs = -g * l[j] * libm::sin(q[j]) * mu(j, j);
        for k in 0..n {
            a[j][k] = mu(j, k) * l[j] * l[k] * libm::cos(q[j] - q[k]);
            rhs -= mu(j, k) * l[j] * l[k] * libm::sin(q[j] - q[k]) * qd[k] * qd[k];
        }
        a[j][n] = rhs;
    }
    // Gaussian elimination with partial pivoting.
    for c in 0..n {
        let piv = (c..n)
            .max_by(|&i, &k| a[i][c].abs().total_cmp(&a[k][c].abs()))
            .unwrap();
        a.swap(c, piv);
        for i in c + 1..n {
            let f = a[i][c] / a[c][c];
            for k in c..=n {
                a[i][k] -= f * a[c][k];
            }
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| a[i][k] * x[k]).sum();
        x[i] = (a[i][n] - s) / a[i][i];
    }
    x
}

/// The accelerations `eval(q, q', out)` of an n-link chain against the hand derivation at 20
/// random states, with the masses, lengths and g of the model's parameters.
fn assert_matches_hand_derivation(
    model: &Model,
    n: usize,
    seed: u64,
    mut eval: impl FnMut(&[f64], &[f64], &mut [f64]),
) {
    let param = |name: &str| {
        model
            .parameters
            .iter()
            .find(|p| p.name == name)
            .unwrap()
            .value
    };
    let masses: Vec<f64> = (1..=n).map(|i| param(&format!("m{i}"))).collect();
    let lengths: Vec<f64> = (1..=n).map(|i| param(&format!("l{i}"))).collect();
    let g = param("g");
    let mut seed = seed;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    };
    for _ in 0..20 {
        let q: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let qd: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let mut out = vec![0.0; n];
        eval(&q, &qd, &mut out);
        let expected = chain_accelerations(&masses, &lengths, &q, &qd, g);
        for (o, e) in out.iter().zip(&expected) {
            assert!(
                (o - e).abs() < 1e-9 * (1.0 + e.abs()),
                "n={n}: {out:?} vs {expected:?}"
            );
        }
    }
}

fn check_chain(n: usize) {
    let mut model = example(&format!("pendulum_chain_{n}"));
    let opts = DeriveOptions {
        solve_budget: pdyn_mech::derive::FULL_SOLVE_BUDGET,
        ..DeriveOptions::default()
    };
    let d = derive(&mut model, &opts).unwrap();
    let acc = d
        .accelerations()
        .expect("small chains are solved symbolically");
    assert!(d
        .unknowns
        .iter()
        .all(|u| matches!(u.kind, UnknownKind::Acceleration(_))));
    let mut inputs = d.state.clone();
    inputs.extend(model.parameters.iter().map(|p| p.id));
    let prog = Program::compile(&mut model.pool, &inputs, &acc).unwrap();
    let mut ws = prog.workspace();
    let params: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
    assert_matches_hand_derivation(&model, n, 7, |q, qd, out| {
        let input: Vec<f64> = q.iter().chain(qd).chain(&params).copied().collect();
        prog.eval(&input, &mut ws, out);
    });
}

#[test]
fn two_link_chain_matches_hand_derivation() {
    check_chain(2);
}

#[test]
fn three_link_chain_matches_hand_derivation() {
    check_chain(3);
}

#[path = "common/chain.rs"]
mod chain;

/// The derived `M q'' = f` of the 5-link chain, compiled and solved numerically as `pdyn run`
/// does, against the hand derivation at random states and unequal masses and lengths, with both
/// the default options and a run's (`simplify_printed: false`, which may skip exact
/// elimination).
#[test]
fn five_link_chain_matches_hand_derivation() {
    let n = 5;
    for opts in [
        DeriveOptions::default(),
        DeriveOptions {
            simplify_printed: false,
            ..DeriveOptions::default()
        },
    ] {
        let mut model = load(&chain::chain_toml(n), "chain5.toml").unwrap();
        for par in model.parameters.iter_mut() {
            let k: f64 = par.name[1..].parse().unwrap_or(0.0);
            if par.name.starts_with('m') {
                par.value = 0.5 + 0.3 * k;
            } else if par.name.starts_with('l') {
                par.value = 1.7 - 0.2 * k;
            }
        }
        let d = derive(&mut model, &opts).unwrap();
        let mut inputs = vec![model.pool.time()];
        inputs.extend(&d.state);
        inputs.extend(model.parameters.iter().map(|p| p.id));
        let mut sys =
            pdyn_expr::compile::CompiledLinearSystem::new(&mut model.pool, &d.system, &inputs)
                .unwrap();
        let params: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
        assert_matches_hand_derivation(&model, n, 11, |q, qd, out| {
            let input: Vec<f64> = [0.0]
                .iter()
                .chain(q)
                .chain(qd)
                .chain(&params)
                .copied()
                .collect();
            sys.solve(&input, out).unwrap();
        });
    }
}

/// Neither a run nor `pdyn derive` eliminates the 4-link chain's accelerations exactly by
/// default (it took 3 s of a 3.1 s `pdyn run`): `A x = b` is solved numerically; the double
/// pendulum is still solved exactly.
#[test]
fn runs_eliminate_exactly_only_when_cheap() {
    let run = DeriveOptions {
        simplify_printed: false,
        ..DeriveOptions::default()
    };
    let mut m4 = load(&chain::chain_toml(4), "chain4.toml").unwrap();
    assert!(derive(&mut m4, &run).unwrap().solution.is_none());
    let mut m4 = load(&chain::chain_toml(4), "chain4.toml").unwrap();
    assert!(derive(&mut m4, &DeriveOptions::default())
        .unwrap()
        .solution
        .is_none());
    let mut m2 = example("pendulum_chain_2");
    assert!(derive(&mut m2, &run).unwrap().solution.is_some());
}

#[test]
fn bicycle_on_a_massless_frame_3_2_example_3() {
    let mut m = example("bicycle");
    let na = solved(&mut m, "N_A");
    // N_A = W (L - d - mu h)/(L - mu h): the bike tips (N_A = 0) when mu > (L - d)/h.
    same(&mut m, na, "m*g*(L - d - mu*h)/(L - mu*h)");
    let a = solved(&mut m, "x''");
    same(&mut m, a, "-mu*g*d/(L - mu*h)");
}

/// The projected form drops the rod tensions; they are recovered from F = m a and agree with
/// the Newton form, which solves for them directly.
#[test]
fn projected_form_recovers_declared_reactions() {
    use pdyn_mech::derive::Form;
    let src = format!(
        "{}\n{}",
        std::fs::read_to_string(format!(
            "{}/../../examples/pendulum_chain_2.toml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
        r#"
[definitions]
u1 = "[sin(q1), -cos(q1), 0]"
u2 = "[sin(q2), -cos(q2), 0]"

[[forces]]
kind = "reaction"
name = "T1"
on = "p1"
direction = "-u1"

[[forces]]
kind = "reaction"
name = "T2"
on = "p2"
direction = "-u2"

[[forces]]
kind = "reaction"
name = "T2"
on = "p1"
direction = "u2"
"#
    );
    let mut newton_model =
        load(&src, "chain.toml").unwrap_or_else(|e| panic!("{}", e.render(&src)));
    let mut proj_model = load(&src, "chain.toml").unwrap();
    let newton = derive(
        &mut newton_model,
        &DeriveOptions {
            form: Form::Newton,
            ..DeriveOptions::default()
        },
    )
    .unwrap();
    let proj = derive(
        &mut proj_model,
        &DeriveOptions {
            form: Form::Projected,
            ..DeriveOptions::default()
        },
    )
    .unwrap();
    assert_eq!(proj.recovered.len(), 2);
    let nsol = newton.reactions().unwrap();
    for (name, rec) in &proj.recovered {
        let (_, nexpr) = nsol.iter().find(|(n, _)| n == name).unwrap();
        // Compare numerically at a few states.
        let mut inputs = proj.state.clone();
        inputs.extend(proj_model.parameters.iter().map(|p| p.id));
        let p1 = Program::compile(&mut proj_model.pool, &inputs, &[*rec]).unwrap();
        let mut inputs_n = newton.state.clone();
        inputs_n.extend(newton_model.parameters.iter().map(|p| p.id));
        let p2 = Program::compile(&mut newton_model.pool, &inputs_n, &[*nexpr]).unwrap();
        let (mut w1, mut w2) = (p1.workspace(), p2.workspace());
        for state in [[0.3, -0.2, 0.5, 1.0], [1.0, 2.0, -0.7, 0.1]] {
            let mut input = state.to_vec();
            input.extend(proj_model.parameters.iter().map(|p| p.value));
            let (mut a, mut b) = ([0.0], [0.0]);
            p1.eval(&input, &mut w1, &mut a);
            p2.eval(&input, &mut w2, &mut b);
            assert!(
                (a[0] - b[0]).abs() < 1e-9 * (1.0 + b[0].abs()),
                "{name}: {} vs {}",
                a[0],
                b[0]
            );
        }
    }
}
