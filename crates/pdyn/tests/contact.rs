//! Hybrid mechanics against closed forms (issue 31): friction that sticks and slips, contact
//! that is lost and regained, impacts, Zeno bounces, event actions. Every expected value is
//! derived here from the textbook formula, not from pdyn's output.

use pdyn::sim::{self, RunSettings};
use std::path::Path;

fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/contact")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Loads `src` with `--set`-style parameter values, runs it, and returns the result.
fn run(
    src: &str,
    set_values: &[(&str, f64)],
    tweak: impl FnOnce(&mut RunSettings),
) -> sim::RunResult {
    let mut m = pdyn_mech::load(src, "<test>").unwrap_or_else(|e| panic!("{}", e.render(src)));
    let values: Vec<(String, f64)> = set_values
        .iter()
        .map(|(n, v)| (n.to_string(), *v))
        .collect();
    pdyn::params::set_parameter_values(&mut m, &values, "--set").unwrap();
    let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
    tweak(&mut set);
    let prep = sim::prepare(&mut m).unwrap_or_else(|e| panic!("{e}"));
    sim::run(&prep, &set).unwrap_or_else(|e| panic!("{e}"))
}

fn col(res: &sim::RunResult, name: &str) -> usize {
    res.columns
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", res.columns))
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(1e-300),
        "{what}: got {got:.15e}, want {want:.15e} (relative error {:.3e})",
        (got - want).abs() / want.abs()
    );
}

fn balance_closes(res: &sim::RunResult, tol: f64) {
    let b = res
        .monitors
        .iter()
        .find(|m| m.name == "energy_balance")
        .expect("the energy balance is monitored");
    assert!(b.drift <= tol, "energy balance off by {:e}", b.drift);
    assert!(res.warnings.is_empty(), "warnings: {:?}", res.warnings);
}

/// A ball dropped from h with restitution e: bounce k at t_1 (1 + 2 (e + ... + e^(k-1))),
/// resting at t_inf = t_1 (1 + e)/(1 - e), t_1 = sqrt(2h/g).
#[test]
fn bouncing_ball_bounce_times_and_zeno_rest_time() {
    // The last two start every segment with a step of 0.3 s, longer than most flights: a
    // step from the floor (gap 0) over a whole flight into the floor must not go unseen.
    for (e, first_step) in [(0.5, None), (0.8, None), (0.5, Some(0.3)), (0.8, Some(0.3))] {
        let res = run(&example("bouncing_ball.toml"), &[("e", e)], |s| {
            s.t_end = 12.0;
            s.dt = first_step;
        });
        let h = res.hybrid.as_ref().unwrap();
        let (g, h0) = (9.81f64, 1.0f64);
        let t1 = (2.0 * h0 / g).sqrt();
        let mut want = t1;
        for (k, im) in h.impacts.iter().take(8).enumerate() {
            close(im.t, want, 1e-9, &format!("bounce {k} (e = {e})"));
            close(
                im.normal_speed_after,
                e * im.normal_speed_before,
                1e-12,
                "rebound speed",
            );
            want += 2.0 * t1 * e.powi(k as i32 + 1);
        }
        assert_eq!(h.zeno.len(), 1, "one accumulation");
        close(
            h.zeno[0].t_accumulation,
            t1 * (1.0 + e) / (1.0 - e),
            1e-9,
            "t_inf",
        );
        // At rest on the floor afterwards, with N = m g.
        let last = res.rows.last().unwrap();
        assert!(last[col(&res, "y")].abs() < 1e-9);
        close(last[col(&res, "N_floor")], 0.1 * g, 1e-9, "N at rest");
        close(
            h.dissipated_impacts,
            0.1 * g * h0,
            1e-9,
            "all the energy lost in impacts",
        );
        balance_closes(&res, 1e-9);
    }
}

/// A block launched at v0 on a rough floor stops at v0/(mu_k g) after v0²/(2 mu_k g), and
/// stays (static friction holds it: no chattering, no max_steps failure).
#[test]
fn block_slides_to_rest_and_stays() {
    let res = run(&example("block_sliding.toml"), &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    let (g, v0, mu_k) = (9.81, 3.0, 0.4);
    assert_eq!(h.switches.len(), 1, "{:?}", h.switches);
    close(h.switches[0].t, v0 / (mu_k * g), 1e-9, "time to rest");
    assert_eq!(h.switches[0].to, "stuck");
    let last = res.rows.last().unwrap();
    close(
        last[col(&res, "x")],
        v0 * v0 / (2.0 * mu_k * g),
        1e-9,
        "distance",
    );
    assert_eq!(last[col(&res, "x'")], 0.0);
    close(
        h.dissipated_friction,
        0.5 * 2.0 * v0 * v0,
        1e-9,
        "friction dissipates the kinetic energy",
    );
    balance_closes(&res, 1e-9);
}

const INCLINE: &str = r#"
name = "block on a rough incline"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
m = 1.5
alpha = 0.5
v0 = 4.0
mu_s = 0.6
mu_k = 0.45
[coordinates]
s = { initial = 0, rate = "v0" }        # up the slope
[particles.block]
mass = "m"
position = "s*[cos(alpha), sin(alpha), 0]"
[[contacts]]
name = "slope"
on = "block"
surface = "dot(r, [-sin(alpha), cos(alpha), 0])"
mu_s = "mu_s"
mu_k = "mu_k"
[simulate]
t_end = 3.0
rtol = 1e-11
atol = 1e-12
"#;

/// Launched up a rough incline: up at -g (sin a + mu_k cos a) to a stop; then held when
/// tan a <= mu_s, else sliding back down at g (sin a - mu_k cos a).
#[test]
fn block_on_incline_stops_then_holds_or_slides_back() {
    let g = 9.81f64;
    let v0 = 4.0;
    for (alpha, holds) in [(0.5f64, true), (0.7, false)] {
        let res = run(INCLINE, &[("alpha", alpha)], |_| {});
        assert_eq!(libm::tan(alpha) <= 0.6, holds);
        let h = res.hybrid.as_ref().unwrap();
        let up = g * (libm::sin(alpha) + 0.45 * libm::cos(alpha));
        let t_stop = v0 / up;
        let s_stop = v0 * v0 / (2.0 * up);
        close(h.switches[0].t, t_stop, 1e-9, "stop time");
        let last = res.rows.last().unwrap();
        if holds {
            assert_eq!(h.switches.len(), 1);
            assert_eq!(h.switches[0].to, "stuck");
            close(last[col(&res, "s")], s_stop, 1e-9, "rest position");
            // Static friction holds m g sin a.
            close(
                last[col(&res, "F_slope")].abs(),
                1.5 * g * libm::sin(alpha),
                1e-9,
                "holding force",
            );
        } else {
            assert_eq!(h.switches.len(), 1, "{:?}", h.switches);
            assert!(h.switches[0].to.starts_with("sliding"));
            let down = g * (libm::sin(alpha) - 0.45 * libm::cos(alpha));
            let dt = 3.0 - t_stop;
            close(
                last[col(&res, "s")],
                s_stop - 0.5 * down * dt * dt,
                1e-9,
                "position sliding back",
            );
            close(
                last[col(&res, "s'")],
                -down * dt,
                1e-9,
                "speed sliding back",
            );
        }
        balance_closes(&res, 1e-9);
    }
}

const RAMP: &str = r#"
name = "crate under a ramped force"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
m = 10.0
c = 20.0         # N/s
mu_s = 0.5
mu_k = 0.3
[coordinates]
x = { initial = 0, rate = 0 }
[particles.crate]
mass = "m"
position = "[x, 0, 0]"
[[forces]]
kind = "applied"
on = "crate"
force = "[c*t, 0, 0]"
[[contacts]]
name = "floor"
on = "crate"
surface = "r.y"
mu_s = "mu_s"
mu_k = "mu_k"
[simulate]
t_end = 4.0
rtol = 1e-11
atol = 1e-13
"#;

/// A crate at rest under F = c t breaks away at t_b = mu_s m g / c, then slides with
/// a = (c t - mu_k m g)/m.
#[test]
fn ramped_force_breakaway_time_and_position_after() {
    let res = run(RAMP, &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    let (g, m, c, mu_s, mu_k) = (9.81f64, 10.0, 20.0, 0.5, 0.3);
    let tb = mu_s * m * g / c;
    assert_eq!(h.switches.len(), 1, "{:?}", h.switches);
    close(h.switches[0].t, tb, 1e-9, "break-away time");
    assert_eq!(h.switches[0].to, "sliding +");
    let t = 4.0;
    let x = c / (6.0 * m) * (t * t * t - tb * tb * tb)
        - c / (2.0 * m) * tb * tb * (t - tb)
        - mu_k * g * (t - tb) * (t - tb) / 2.0;
    let v = c / (2.0 * m) * (t * t - tb * tb) - mu_k * g * (t - tb);
    let last = res.rows.last().unwrap();
    close(last[col(&res, "x")], x, 1e-9, "position");
    close(last[col(&res, "x'")], v, 1e-9, "speed");
    assert!(
        res.rows.iter().all(|r| r[col(&res, "x")] >= 0.0),
        "never moves backwards"
    );
}

/// Mass on a spring with Coulomb friction: the amplitude drops by 2 mu_k m g/k per half
/// cycle (each half cycle lasts pi sqrt(m/k)), and the mass sticks at the first turning point
/// inside |x| <= mu_s m g / k.
#[test]
fn stick_slip_oscillator_amplitude_loss_and_rest_position() {
    let res = run(&example("stick_slip.toml"), &[], |s| s.t_end = 10.0);
    let h = res.hybrid.as_ref().unwrap();
    let (g, m, k, x0, mu_s, mu_k) = (9.81f64, 1.0, 100.0, 0.5, 0.35, 0.3);
    let step = 2.0 * mu_k * m * g / k;
    let half = std::f64::consts::PI * (m / k).sqrt();
    let mut amp = x0;
    let mut turns = 0;
    while amp > mu_s * m * g / k {
        amp -= step;
        turns += 1;
    }
    assert_eq!(h.switches.len(), turns + 1, "{:?}", h.switches);
    for (j, sw) in h.switches[1..].iter().enumerate() {
        close(sw.t, half * (j + 1) as f64, 1e-9, "turning time");
    }
    let last = res.rows.last().unwrap();
    let rest = last[col(&res, "x")];
    let want = if turns % 2 == 0 { amp } else { -amp };
    close(rest, want, 1e-8, "rest position");
    assert!(rest.abs() <= mu_s * m * g / k);
    assert_eq!(h.switches.last().unwrap().to, "stuck");
    balance_closes(&res, 1e-8);
}

/// A particle released at rest at theta0 on a smooth hemisphere leaves it where
/// cos(theta) = (2/3) cos(theta0), then lands where the projectile from there meets y = 0.
#[test]
fn hemisphere_leaves_at_two_thirds_and_lands() {
    let res = run(&example("hemisphere.toml"), &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    let (g, r, th0) = (9.81f64, 1.0, 0.1f64);
    let release = h
        .switches
        .iter()
        .find(|s| s.contact == "dome")
        .expect("leaves the dome");
    let k = res
        .rows
        .iter()
        .position(|row| row[0] == release.t)
        .expect("the release is a row");
    let row = &res.rows[k];
    let (x, y) = (row[col(&res, "x")], row[col(&res, "y")]);
    let cos_l = 2.0 / 3.0 * libm::cos(th0);
    close(y / r, cos_l, 1e-9, "cos(theta) at release");
    // Projectile from the release point with the speed of the slide, along the tangent.
    let v = (2.0 * g * r * (libm::cos(th0) - cos_l)).sqrt();
    let sin_l = (1.0 - cos_l * cos_l).sqrt();
    close(x, r * sin_l, 1e-9, "x at release");
    let (vx, vy) = (v * cos_l, -v * sin_l);
    let t_fall = (vy + (vy * vy + 2.0 * g * y).sqrt()) / g;
    let landing = h
        .impacts
        .iter()
        .find(|i| i.contact == "floor")
        .expect("lands");
    close(landing.t - release.t, t_fall, 1e-9, "flight time");
    let k = res.rows.iter().position(|row| row[0] == landing.t).unwrap();
    close(
        res.rows[k][col(&res, "x")],
        x + vx * t_fall,
        1e-9,
        "landing point",
    );
    balance_closes(&res, 1e-9);
}

/// Head-on collision: momentum conserved, kinetic energy lost (1 - e²) μ u²/2 with μ the
/// reduced mass and u the approach speed; the relative speed after is e u.
#[test]
fn two_particle_collision_conserves_momentum() {
    for e in [0.0, 0.7, 1.0] {
        let res = run(&example("two_balls.toml"), &[("e", e)], |_| {});
        let h = res.hybrid.as_ref().unwrap();
        let (ma, mb, va, vb) = (1.0f64, 3.0, 2.0, -1.0);
        assert_eq!(h.impacts.len(), 1, "e = {e}: {:?}", h.impacts);
        let im = &h.impacts[0];
        close(im.t, 0.8 / 3.0, 1e-12, "collision time");
        let mu = ma * mb / (ma + mb);
        let u = va - vb;
        if e > 0.0 {
            close(
                im.energy_lost,
                (1.0 - e * e) * mu * u * u / 2.0,
                1e-12,
                "energy lost",
            );
        } else {
            close(
                im.energy_lost,
                mu * u * u / 2.0,
                1e-12,
                "energy lost (plastic)",
            );
        }
        let last = res.rows.last().unwrap();
        let (a, b) = (last[col(&res, "xA'")], last[col(&res, "xB'")]);
        close(ma * a + mb * b, ma * va + mb * vb, 1e-12, "momentum");
        close(
            b - a,
            e * u,
            1e-12 + if e == 0.0 { 1.0 } else { 0.0 },
            "separation speed",
        );
        balance_closes(&res, 1e-12);
    }
}

const BURN: &str = r#"
name = "impulsive burn at an event"
[parameters]
GM = 1.0
dv = 0.2
[coordinates]
x = { initial = 1, rate = 0 }
y = { initial = 0, rate = 1 }
[particles.sat]
mass = 1
position = "[x, y, 0]"
[[forces]]
kind = "inverse_square"
on = "sat"
to = "O"
strength = "GM"
[points]
O = "[0, 0, 0]"
[[events]]
name = "burn at apoapsis side"
when = "x"
direction = "falling"
set = ["x' = x'*(1 + dv)", "y' = y'*(1 + dv)"]
terminal = false
[simulate]
t_end = 6.0
rtol = 1e-11
atol = 1e-12
"#;

/// An event that changes the state: a prograde burn on a circular orbit at x = 0 scales the
/// velocity by 1 + dv; afterwards the specific energy is (1 + dv)²/2 - 1.
#[test]
fn event_action_applies_an_impulsive_burn() {
    let res = run(BURN, &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    assert_eq!(h.actions.len(), 1, "{:?}", h.actions);
    close(
        h.actions[0].t,
        std::f64::consts::FRAC_PI_2,
        1e-9,
        "burn time",
    );
    let last = res.rows.last().unwrap();
    let (x, y, vx, vy) = (
        last[col(&res, "x")],
        last[col(&res, "y")],
        last[col(&res, "x'")],
        last[col(&res, "y'")],
    );
    let energy = 0.5 * (vx * vx + vy * vy) - 1.0 / (x * x + y * y).sqrt();
    close(
        energy,
        0.5 * 1.2f64.powi(2) - 1.0,
        1e-8,
        "energy after the burn",
    );
}

fn load_err(src: &str) -> String {
    match pdyn_mech::load(src, "m.toml") {
        Ok(_) => panic!("loaded"),
        Err(e) => e.render(src),
    }
}

/// A free body diagram that declares the normal force as a reaction *and* as the friction's
/// normal force counts it twice: refused, naming both.
#[test]
fn normal_force_declared_twice_is_refused() {
    let src = r#"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
[coordinates]
x = { initial = 0, rate = 1 }
[particles.b]
mass = 1
position = "[x, 0, 0]"
[[forces]]
kind = "reaction"
name = "N"
on = "b"
direction = "[0, 1, 0]"
[[forces]]
kind = "friction"
on = "b"
normal = "[0, 1, 0]"
mode = "coulomb"
mu = 0.3
"#;
    let e = load_err(src);
    assert!(e.contains("counted twice"), "{e}");
    assert!(e.contains("m.toml:16"), "{e}");
    // The same model without the reaction loads, and slides to rest under Coulomb friction.
    let ok = src.replace(
        "[[forces]]\nkind = \"reaction\"\nname = \"N\"\non = \"b\"\ndirection = \"[0, 1, 0]\"\n",
        "",
    ) + "[simulate]\nt_end = 1.0\nrtol = 1e-10\natol = 1e-12\n";
    let res = run(&ok, &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    close(
        h.switches[0].t,
        1.0 / (0.3 * 9.81),
        1e-9,
        "friction kind: time to rest",
    );
    close(
        res.rows.last().unwrap()[col(&res, "N")],
        9.81,
        1e-12,
        "N counted once",
    );
}

/// Bad contact input: located errors.
#[test]
fn bad_contacts_are_located_errors() {
    let base = |contact: &str| {
        format!(
            "gravity = \"[0, -9.81, 0]\"\n[coordinates]\ny = {{ initial = 1, rate = 0 }}\n[particles.b]\nmass = 1\nposition = \"[0, y, 0]\"\n[[contacts]]\n{contact}\n"
        )
    };
    for (contact, says) in [
        ("on = \"b\"\nsurface = \"r.y\"\ne = 1.5", "between 0 and 1"),
        ("on = \"b\"\nsurface = \"r.y\"\nmu = -0.1", "at least 0"),
        ("on = \"b\"\nsurface = \"2\"", "has no normal"),
        ("on = \"c\"\nsurface = \"r.y\"", "unknown particle `c`"),
        ("on = \"b\"", "needs a `surface`"),
        (
            "on = \"b\"\nsurface = \"r.y\"\nmu_s = 0.2\nmu_k = 0.3",
            "cannot exceed static",
        ),
        ("surface = \"r.y\"", "needs `on` or `between`"),
        // A surface with no inside: the particle would pass through it unseen.
        ("on = \"b\"\nsurface = \"norm(r)\"", "never negative"),
        ("on = \"b\"\nsurface = \"2*r.y^2\"", "never negative"),
    ] {
        let e = load_err(&base(contact));
        assert!(e.contains(says), "{contact}: {e}");
        assert!(e.contains("m.toml:"), "{e}");
    }
    // An event that assigns to something that is not a state or parameter.
    let src = base("on = \"b\"\nsurface = \"r.y\"")
        + "[[events]]\nwhen = \"y - 0.5\"\nset = [\"g = 2\"]\n";
    let e = load_err(&src);
    assert!(e.contains("not a free coordinate or a parameter"), "{e}");
    // An assignment that reads a contact force, which has no value at the jump.
    let src = base("on = \"b\"\nsurface = \"r.y\"")
        + "[[events]]\nwhen = \"y - 0.5\"\nset = [\"y' = N_contact1\"]\n";
    let e = load_err(&src);
    assert!(e.contains("cannot use a reaction or contact force"), "{e}");
    assert!(e.contains("m.toml:12:14:"), "{e}");
}

/// A contact that starts penetrated is refused with its gap; a held contact that would have
/// to pull warns loudly.
#[test]
fn penetration_and_tension_are_not_silent() {
    let src = example("bouncing_ball.toml");
    let mut m = pdyn_mech::load(&src, "<t>").unwrap();
    pdyn::params::set_parameter_values(&mut m, &[("h".to_string(), -0.1)], "--set").unwrap();
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let prep = sim::prepare(&mut m).unwrap();
    let err = sim::run(&prep, &set).unwrap_err().to_string();
    assert!(err.contains("starts penetrated"), "{err}");

    // Gravity pulls the block off a ceiling it is held to by its coordinates.
    let ceiling = example("block_sliding.toml").replace("surface = \"r.y\"", "surface = \"-r.y\"");
    let res = run(&ceiling, &[], |_| {});
    assert!(
        res.warnings.iter().any(|w| w.contains("pull")),
        "{:?}",
        res.warnings
    );
}

const CRATE: &str = r#"
name = "crate at rest, friction drawn by hand"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
[coordinates]
x = { initial = 0, rate = 0 }
[particles.crate]
mass = 5
position = "[x, 0, 0]"
[[forces]]
kind = "friction"
on = "crate"
normal = "[0, 1, 0]"
mode = "slip"
mu = 0.3
FIELD
[simulate]
t_end = 2.0
"#;

/// Friction drawn with a fixed `opposes` on a crate at rest pushes it backwards: the run says
/// so loudly. Without `opposes`, the same friction is Coulomb's: the crate stays put.
#[test]
fn friction_doing_positive_work_is_not_silent() {
    let wrong = CRATE.replace("FIELD", "opposes = \"[1, 0, 0]\"");
    let res = run(&wrong, &[], |_| {});
    assert!(res.rows.last().unwrap()[col(&res, "x")] < -1.0);
    assert!(
        res.warnings
            .iter()
            .any(|w| w.contains("positive work") && w.contains("friction")),
        "{:?}",
        res.warnings
    );
    let right = CRATE.replace("FIELD", "");
    let res = run(&right, &[], |_| {});
    assert!(res.hybrid.is_some());
    for r in &res.rows {
        assert_eq!(r[col(&res, "x")], 0.0, "a crate at rest stays at rest");
    }
    assert!(res.warnings.is_empty(), "{:?}", res.warnings);
}

/// On a moving belt the mass sticks until the spring pulls mu_s m g, then slips for
/// (pi + 2 asin(V/(A w)))/w, A the amplitude about mu_k m g/k; the belt's work feeds the
/// friction's dissipation and the balance closes.
#[test]
fn belt_stick_slip_phases() {
    let res = run(&example("belt.toml"), &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    let (g, m, k, v, mu_s, mu_k) = (9.81f64, 1.0f64, 50.0f64, 0.2, 0.6, 0.4);
    let w = (k / m).sqrt();
    close(
        h.switches[0].t,
        mu_s * m * g / (k * v),
        1e-9,
        "first stick phase",
    );
    let d = (mu_s - mu_k) * m * g / k;
    let a = (d * d + (v / w).powi(2)).sqrt();
    let slip = (std::f64::consts::PI + 2.0 * libm::asin(v / (a * w))) / w;
    close(h.switches[1].t - h.switches[0].t, slip, 1e-9, "slip phase");
    // It sticks again at mu_k m g/k - d (the slip is symmetric about mu_k m g/k), and the
    // belt carries it back to mu_s m g/k = mu_k m g/k + d.
    close(
        h.switches[2].t - h.switches[1].t,
        2.0 * d / v,
        1e-9,
        "later stick phases",
    );
    assert!(h.work_contacts > 0.0 || h.dissipated_friction > 0.0);
    balance_closes(&res, 1e-8);
}

const PUCK: &str = r#"
name = "puck on a rough table, sliding in two directions"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
vx = 3.0
vz = -4.0
[coordinates]
x = { initial = 0, rate = "vx" }
z = { initial = 0, rate = "vz" }
[particles.puck]
mass = 0.2
position = "[x, 0, z]"
[[contacts]]
name = "table"
on = "puck"
surface = "r.y"
mu = 0.25
[simulate]
t_end = 3.0
rtol = 1e-11
atol = 1e-12
"#;

/// In a tangent plane the slip is a direction: the puck decelerates at mu g along its
/// velocity, stops at |v0|/(mu g) after |v0|²/(2 mu g) on its initial line, and stays.
#[test]
fn slip_in_a_tangent_plane_stops_on_its_line() {
    let res = run(PUCK, &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    let (g, mu, v0) = (9.81f64, 0.25, 5.0);
    let stop = h
        .switches
        .iter()
        .find(|s| s.to == "stuck")
        .unwrap_or_else(|| panic!("{:?}", h.switches));
    close(stop.t, v0 / (mu * g), 1e-9, "time to rest");
    let last = res.rows.last().unwrap();
    let dist = v0 * v0 / (2.0 * mu * g);
    close(last[col(&res, "x")], dist * 3.0 / 5.0, 1e-9, "x at rest");
    close(last[col(&res, "z")], -dist * 4.0 / 5.0, 1e-9, "z at rest");
    balance_closes(&res, 1e-9);
}

/// A sweep over a contact model runs each member through the hybrid loop (not the reference
/// mode alone): the block's slide distance is v0²/(2 mu_k g) for every mu_k.
#[test]
fn sweeps_run_hybrid_models_through_their_switches() {
    let src = example("block_sliding.toml")
        + "\n[sweep]\nparameter = \"mu_k\"\nvalues = [0.1, 0.2, 0.3, 0.4]\n[sweep.measures]\ndistance = { of = \"x\", stat = \"final\" }\n";
    let mut m = pdyn_mech::load(&src, "<t>").unwrap_or_else(|e| panic!("{}", e.render(&src)));
    let set = RunSettings::from_spec(&m.run.simulate).unwrap();
    let spec = m.run.sweep.clone().unwrap();
    let stats: Vec<_> = spec.measures.iter().map(|x| x.stat).collect();
    let prep = sim::prepare(&mut m).unwrap();
    let res = sim::sweep::sweep(&prep, &set, &spec, &stats, &sim::sweep::quiet).unwrap();
    assert!(res.problems.is_empty(), "{:?}", res.problems);
    for (row, mu_k) in res.slices[0].table.iter().zip([0.1, 0.2, 0.3, 0.4]) {
        // mu_k = 0.1 slides 4.6 m and stops at 3.06 s: after t_end = 2, still sliding.
        let t = (3.0f64 / (mu_k * 9.81)).min(2.0);
        let want = 3.0 * t - 0.5 * mu_k * 9.81 * t * t;
        close(row[0], want, 1e-9, &format!("distance at mu_k = {mu_k}"));
    }
}

/// A reaction declared one-sided that has to pull (a car over a hump too fast, held to the
/// road by its coordinates) is a loud warning; the same reaction pushing is silent.
#[test]
fn one_sided_reaction_that_pulls_warns() {
    let hump = |v: f64| {
        format!(
            r#"
gravity = "[0, -9.81, 0]"
[coordinates]
s = {{ initial = 0, rate = {v} }}
[particles.car]
mass = 1000
position = "[20*sin(s/20), 20*cos(s/20), 0]"    # over the top of a hump of radius 20 m
[[forces]]
kind = "reaction"
name = "N"
on = "car"
direction = "[sin(s/20), cos(s/20), 0]"
one_sided = true
[simulate]
t_end = 1.0
"#
        )
    };
    // N = m (g cos - v²/R) at the top: pulls above sqrt(g R) = 14.0 m/s.
    let res = run(&hump(10.0), &[], |_| {});
    assert!(res.warnings.is_empty(), "{:?}", res.warnings);
    let res = run(&hump(16.0), &[], |_| {});
    assert!(
        res.warnings
            .iter()
            .any(|w| w.contains("one-sided") && w.contains("`N`")),
        "{:?}",
        res.warnings
    );
    let e = load_err(&hump(10.0).replace("direction = \"[sin(s/20), cos(s/20), 0]\"\n", ""));
    assert!(e.contains("needs the `direction`"), "{e}");
}

const INCLINE_PULLEY: &str = r#"
name = "block on a rough incline, tied over a pulley to a hanging mass"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
mA = 10.0
mB = 4.0
alpha = "pi/6"
mu_s = 0.2
mu_k = 0.1
[coordinates]
s = { initial = 0, rate = 0 }       # A up the slope
yB = { initial = 0, rate = 0 }      # B's height
[particles.A]
mass = "mA"
position = "s*[cos(alpha), sin(alpha), 0]"
[particles.B]
mass = "mB"
position = "[5, yB, 0]"
[[forces]]
kind = "reaction"
name = "T"
on = "A"
direction = "[cos(alpha), sin(alpha), 0]"
[[forces]]
kind = "reaction"
name = "T"
on = "B"
direction = "[0, 1, 0]"
[[constraints]]
equation = "s + yB = 0"
[[contacts]]
name = "slope"
on = "A"
surface = "dot(r, [-sin(alpha), cos(alpha), 0])"
mu_s = "mu_s"
mu_k = "mu_k"
[simulate]
t_end = 2.0
rtol = 1e-11
atol = 1e-12
"#;

/// An incline with a pulley (a constraint and a cable tension besides the contact): static
/// friction holds the pair when |mB g - mA g sin a| <= mu_s mA g cos a, with the friction
/// it needs; otherwise A slides down at (mA g sin a - mB g - mu_k mA g cos a)/(mA + mB).
#[test]
fn incline_and_pulley_held_by_static_friction_or_sliding() {
    let (g, ma, mb, a) = (9.81f64, 10.0, 4.0, std::f64::consts::PI / 6.0);
    let res = run(INCLINE_PULLEY, &[], |_| {});
    let h = res.hybrid.as_ref().unwrap();
    assert!(h.switches.is_empty(), "{:?}", h.switches);
    assert_eq!(h.timeline[0].modes[0].1, "stuck");
    let last = res.rows.last().unwrap();
    assert!(last[col(&res, "s")].abs() < 1e-12);
    // The friction the slope supplies along its tangent holds mA g sin a - mB g = 9.81 N.
    close(
        last[col(&res, "F_slope")].abs(),
        ma * g * libm::sin(a) - mb * g,
        1e-9,
        "friction needed",
    );
    close(last[col(&res, "T")], mb * g, 1e-9, "tension");
    // mu_s = 0.1 cannot hold it: it slides down the slope, friction pointing up-slope.
    let res = run(INCLINE_PULLEY, &[("mu_s", 0.1)], |_| {});
    let acc = (ma * g * libm::sin(a) - mb * g - 0.1 * ma * g * libm::cos(a)) / (ma + mb);
    let last = res.rows.last().unwrap();
    close(last[col(&res, "s")], -0.5 * acc * 4.0, 1e-9, "slid down");
    close(last[col(&res, "s'")], -acc * 2.0, 1e-9, "speed down-slope");
    assert!(res
        .rows
        .iter()
        .all(|r| r[col(&res, "dissipated.friction")] >= 0.0));
    balance_closes(&res, 1e-9);
}
