//! The no-table path of ensembles and sweeps (`sim::measured::measure`) against the
//! tabulating `sim::run`: what an ensemble keeps of a run — measures, last output point,
//! first occurrence of each event, drifts, warnings, status, f-evaluations, failure and
//! non-finite columns — must be the same bits, on shipped examples with events, a failing
//! run, a drift warning and a run whose output turns NaN.

use pdyn::sim::measured::{measure, Measured};
use pdyn::sim::{self, Prepared, RunSettings, RunStatus};
use pdyn_mech::model::spec::Stat;

fn example_source(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../../examples/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

/// Every statistic of `of`, as a `[sweep]` over `parameter` with `[sweep.measures]` entries.
fn with_measures(src: &str, parameter: &str, of: &str) -> String {
    let src = match src.find("[sweep]") {
        Some(i) => &src[..i],
        None => src,
    };
    let mut s = format!(
        "{src}\n[sweep]\nparameter = \"{parameter}\"\nvalues = [1.0]\n\n[sweep.measures]\n"
    );
    for st in [
        "max",
        "min",
        "max_abs",
        "peak_to_peak",
        "final",
        "mean",
        "rms",
    ] {
        s += &format!("{st} = {{ of = \"{of}\", stat = \"{st}\" }}\n");
    }
    s
}

/// What the tabulating path gives for the same things (what `one_run` of `crates/pdyn-py`
/// computed from `sim::run`'s rows before the no-table path).
struct FromTable {
    measures: Vec<f64>,
    last: Option<(f64, Vec<f64>)>,
    first_hits: Vec<Option<(f64, Vec<f64>)>>,
    non_finite: Option<(f64, Vec<usize>)>,
    res: sim::RunResult,
}

fn from_table(p: &Prepared, set: &RunSettings, stats: &[Stat]) -> FromTable {
    let res = sim::run(p, set).unwrap();
    let ns = p.state_names.len();
    let n = p.system.n;
    let mut measures = vec![f64::NAN; stats.len()];
    if let Some(m) = &p.measures {
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
        for (j, s) in series.iter().enumerate() {
            measures[j] = sim::sweep::statistic(stats[j], &ts, s);
        }
    }
    let last = res.rows.last().map(|r| (r[0], r[1..1 + ns].to_vec()));
    let mut first_hits = vec![None; p.events.len()];
    for e in &res.events {
        let i = p.events.iter().position(|pe| pe.name == e.name).unwrap();
        if first_hits[i].is_none() {
            first_hits[i] = Some((e.t, e.state.clone()));
        }
    }
    let first_bad = res
        .rows
        .iter()
        .find(|r| r.iter().any(|x| !x.is_finite()))
        .map(|r| r[0]);
    let non_finite = first_bad.map(|t| {
        let cols = (0..res.columns.len())
            .filter(|&c| res.rows.iter().any(|r| !r[c].is_finite()))
            .collect();
        (t, cols)
    });
    FromTable {
        measures,
        last,
        first_hits,
        non_finite,
        res,
    }
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

fn point_bits(p: &Option<(f64, Vec<f64>)>) -> Option<(u64, Vec<u64>)> {
    p.as_ref().map(|(t, y)| (t.to_bits(), bits(y)))
}

/// Compares the two paths on one run; returns the no-table result.
fn same_bits(what: &str, p: &Prepared, set: &RunSettings, stats: &[Stat]) -> (Measured, FromTable) {
    let full = from_table(p, set, stats);
    let fast = measure(p, set, stats).unwrap();
    let res = &full.res;
    assert_eq!(
        bits(&fast.measures),
        bits(&full.measures),
        "{what}: measures"
    );
    assert_eq!(
        point_bits(&fast.last),
        point_bits(&full.last),
        "{what}: last"
    );
    assert_eq!(fast.first_hits.len(), full.first_hits.len(), "{what}");
    for (a, b) in fast.first_hits.iter().zip(&full.first_hits) {
        assert_eq!(point_bits(a), point_bits(b), "{what}: first hits");
    }
    assert_eq!(
        fast.non_finite
            .as_ref()
            .map(|n| (n.t.to_bits(), n.columns.clone())),
        full.non_finite
            .as_ref()
            .map(|(t, c)| (t.to_bits(), c.clone())),
        "{what}: non-finite"
    );
    assert_eq!(
        fast.non_finite,
        sim::measured::NonFinite::of_rows(&res.rows),
        "{what}"
    );
    let drift_bits = |m: &[sim::MonitorReport]| -> Vec<(String, u64, u64, u64)> {
        m.iter()
            .map(|m| {
                (
                    m.name.clone(),
                    m.drift.to_bits(),
                    m.initial.to_bits(),
                    m.scale.to_bits(),
                )
            })
            .collect()
    };
    assert_eq!(
        drift_bits(&fast.monitors),
        drift_bits(&res.monitors),
        "{what}"
    );
    assert_eq!(fast.warnings, res.warnings, "{what}");
    assert_eq!(fast.status, res.status, "{what}");
    assert_eq!(fast.stats.fevals, res.stats.fevals, "{what}");
    assert_eq!(
        fast.failure.as_ref().map(|f| f.to_string()),
        res.failure.as_ref().map(|f| f.to_string()),
        "{what}"
    );
    assert_eq!(
        format!("{:?}", fast.events),
        format!("{:?}", res.events),
        "{what}"
    );
    assert_eq!(p.columns(), res.columns, "{what}");
    (fast, full)
}

/// An ensemble over `rows` of values of `parameter`, each member on its own parameters (as
/// `Model.ensemble` does it), checked run by run.
fn ensemble(
    src: &str,
    parameter: &str,
    rows: &[f64],
    tweak: impl Fn(&mut RunSettings),
) -> Vec<(Measured, FromTable)> {
    let mut m = pdyn_mech::load(src, "<test>").unwrap_or_else(|e| panic!("{}", e.render(src)));
    let stats: Vec<Stat> = m
        .run
        .sweep
        .as_ref()
        .map(|s| s.measures.iter().map(|x| x.stat).collect())
        .unwrap_or_default();
    let mut set = RunSettings::from_spec(&m.run.simulate).unwrap();
    tweak(&mut set);
    let prep = sim::prepare(&mut m).unwrap();
    let k = prep
        .parameter_names
        .iter()
        .position(|n| n == parameter)
        .unwrap();
    rows.iter()
        .map(|&v| {
            let p = prep.with_parameters(&[(k, v)]);
            same_bits(&format!("{parameter} = {v}"), &p, &set, &stats)
        })
        .collect()
}

/// The Kremlin stone (a terminal event, energy conserved, output at every step), with every
/// statistic, at several launch speeds; also at 301 output points.
#[test]
fn kremlin_stone_terminal_event() {
    let src = with_measures(&example_source("kremlin_stone"), "v0", "z - x");
    for points in [None, Some(301)] {
        let out = ensemble(&src, "v0", &[5.0, 11.0, 20.0], |s| s.points = points);
        for (fast, _) in &out {
            assert!(matches!(fast.status, RunStatus::TerminalEvent(0)));
            assert!(fast.first_hits[0].is_some());
            assert!(fast.measures.iter().all(|x| x.is_finite()));
        }
    }
}

/// The nanoparticle: a falling `z'` event, a derived parameter (`m`), no measures.
#[test]
fn nanoparticle_apex() {
    let out = ensemble(
        &example_source("nanoparticle"),
        "T",
        &[200.0, 293.0, 400.0],
        |_| {},
    );
    for (fast, _) in &out {
        assert!(fast.first_hits[0].is_some());
        assert!(fast.measures.is_empty());
    }
}

/// The building (dense output at 2001 points, a monitor, measures) with a non-terminal event
/// that occurs many times: only the first occurrence is kept.
#[test]
fn building_with_a_repeated_event() {
    let src = with_measures(
        &example_source("building"),
        "omega",
        "y2 - (2*L - 3*m*g/(2*k))",
    ) + "\n[[events]]\nname = \"crossing\"\nwhen = \"y2 - (2*L - 3*m*g/(2*k))\"\ndirection = \"both\"\n";
    let out = ensemble(&src, "omega", &[3.0, 8.74, 22.9], |_| {});
    for (fast, _) in &out {
        assert!(fast.events.len() > 1, "{}", fast.events.len());
        assert_eq!(fast.status, RunStatus::Finished);
    }
}

/// A run that fails (too few steps allowed): status, failure and the partial run's measures.
#[test]
fn a_failing_run() {
    let src = with_measures(
        &example_source("building"),
        "omega",
        "y2 - (2*L - 3*m*g/(2*k))",
    );
    let out = ensemble(&src, "omega", &[3.0, 22.9], |s| s.max_steps = Some(50));
    for (fast, _) in &out {
        assert_eq!(fast.status, RunStatus::Failed);
        assert!(fast.failure.is_some());
        assert!(fast.last.is_some());
    }
}

/// The chapter's satellite at ODE45's settings spirals in: a drift warning, the same drift.
#[test]
fn satellite_drift_warning() {
    let out = ensemble(&example_source("satellite_ode45"), "m", &[1.0, 2.0], |_| {});
    for (fast, _) in &out {
        assert!(!fast.warnings.is_empty());
        assert!(fast.monitors.iter().any(|m| m.drift > 5e-3));
    }
}

/// A monitor that turns NaN half way: the non-finite columns and their first time.
#[test]
fn output_that_turns_nan() {
    let src = r#"
name = "fall"
gravity = "[0, 0, -g]"

[parameters]
g = 9.81
m = 1.0

[coordinates]
z = { initial = 10.0, rate = 0.0 }

[particles.p]
mass = "m"
position = "[0, 0, z]"

[monitors]
root = "sqrt(z - 5)"

[simulate]
t_end = 2.0
points = 101
"#;
    let out = ensemble(src, "g", &[9.81, 20.0], |_| {});
    for (fast, _) in &out {
        let nf = fast.non_finite.as_ref().expect("the monitor turns NaN");
        assert!(nf.t > 0.5 && nf.t < 1.1, "{nf:?}");
        assert_eq!(fast.status, RunStatus::Finished);
    }
}

/// The pulley: the cable tension `T` is a reaction, among the output columns and measured, so
/// the no-table path must solve for the unknowns at each output point; the building's
/// columns and measures read only the state, so it must not need to (and gives the same bits
/// without solving). Both are checked against the tabulating path.
#[test]
fn reactions_are_solved_for_only_when_read() {
    let src = with_measures(&example_source("pulley"), "mA", "T");
    let mut m = pdyn_mech::load(&src, "<test>").unwrap();
    let prep = sim::prepare(&mut m).unwrap();
    let base = prep.system.inputs.len();
    assert!(!prep.observer.reads_only_first(base));
    assert!(!prep.measures.as_ref().unwrap().reads_only_first(base));
    for points in [None, Some(101)] {
        let out = ensemble(&src, "mA", &[2.0, 3.5], |s| s.points = points);
        for (fast, _) in &out {
            assert_eq!(fast.status, RunStatus::Finished);
            // T = 2 mA mB g / (mA + mB) > 0, constant: every statistic but peak-to-peak.
            assert!(fast.measures.iter().all(|x| x.is_finite()), "{fast:?}");
            assert!(fast.measures[0] > 1.0, "{:?}", fast.measures);
        }
    }
    let src = with_measures(&example_source("building"), "omega", "y2 - L");
    let mut m = pdyn_mech::load(&src, "<test>").unwrap();
    let prep = sim::prepare(&mut m).unwrap();
    let base = prep.system.inputs.len();
    assert!(prep.observer.reads_only_first(base));
    assert!(prep.measures.as_ref().unwrap().reads_only_first(base));
    // It reads y2, the state's second component (input 2, after t).
    assert!(!prep.measures.as_ref().unwrap().reads_only_first(2));
}
