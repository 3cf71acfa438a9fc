"""Model.ensemble: parameter sets and initial states run in Rust on all cores, as arrays."""

import math
import os
import warnings

import numpy as np
import pytest

import pdyn


def kremlin_range(v0, theta, g=9.81, H=71.0):
    vz = v0 * math.sin(theta)
    t = (vz + math.sqrt(vz * vz + 2 * g * H)) / g
    return t, v0 * math.cos(theta) * t


def test_ensemble_equals_single_runs_bit_for_bit(examples):
    m = pdyn.Model.from_file(examples / "kremlin_stone.toml")
    rng = np.random.default_rng(1)
    v0 = 11.176 + 0.5 * rng.standard_normal(50)
    theta = math.radians(45) + 0.05 * rng.standard_normal(50)
    ens = m.ensemble(params={"v0": v0, "theta": theta}, measures={"top": ("z", "max")})
    assert len(ens) == 50 and ens.threads >= 1
    assert set(ens.status) == {1}  # every run stopped by the terminal event
    hit = "hits the ground"
    assert ens.event_t[hit].dtype == np.float64 and ens.event_t[hit].shape == (50,)
    assert ens.final.shape == (50, 4) and ens.state_names == ["x", "z", "x'", "z'"]
    for k in (0, 17, 49):
        single = m.run(params={"v0": float(v0[k]), "theta": float(theta[k])})
        assert single.t_events[0][0] == ens.event_t[hit][k]
        np.testing.assert_array_equal(single.y[:, -1], ens.final[k])
        assert single["z"].max() == ens.measures["top"][k]
        t, x = kremlin_range(v0[k], theta[k])
        assert abs(ens.event_state[hit][k, 0] - x) < 1e-8 * x
    # The same rows on one thread and on all give the same bits.
    one = m.ensemble(params={"v0": v0, "theta": theta}, threads=1)
    np.testing.assert_array_equal(one.final, ens.final)
    df = pytest.importorskip("pandas").DataFrame(ens.columns())
    assert {"v0", "theta", "top", f"{hit}.t", f"{hit}.x", "status", "drifted"} <= set(df.columns)


def test_ensemble_initial_states_and_a_bare_parameter_array(examples):
    m = pdyn.Model.from_file(examples / "kremlin_stone.toml")
    heights = np.array([10.0, 71.0, 200.0])
    ens = m.ensemble(initial={"z": heights})
    for k, h in enumerate(heights):
        t, _ = kremlin_range(11.176, math.radians(45), H=h)
        assert abs(ens.event_t["hits the ground"][k] - t) < 1e-8
    np.testing.assert_array_equal(ens.initial["z"], heights)
    # A 2-D array with one column per parameter, in model order.
    p = m.parameters
    table = np.array([[p["g"], 30.0, p["v0"], p["theta"]], [p["g"], 71.0, p["v0"], p["theta"]]])
    ens2 = m.ensemble(params=table)
    assert list(ens2.params) == ["g", "H", "v0", "theta"]
    assert ens2.event_t["hits the ground"][1] == ens.event_t["hits the ground"][1]
    with pytest.raises(pdyn.ParameterError, match="columns"):
        m.ensemble(params=np.ones((2, 3)))
    with pytest.raises(pdyn.ParameterError, match="not a parameter"):
        m.ensemble(params={"nope": [1.0]})
    with pytest.raises(pdyn.ParameterError, match="not a state component"):
        m.ensemble(initial={"q": [1.0]})


def test_ensemble_bad_rows_are_reported_not_raised(examples):
    m = pdyn.Model.from_file(examples / "projectile_drag.toml")
    masses = np.array([1.0, -1.0, 2.0])
    assert m.check_ensemble(params={"m": masses}) == [(1, m.check_ensemble(params={"m": masses})[0][1])]
    assert "mass" in m.check_ensemble(params={"m": masses})[0][1]
    ens = m.ensemble(params={"m": masses})
    assert list(ens.status) == [0, -2, 0]
    assert np.isnan(ens.final[1]).all() and ens.problems[0][0] == 1


def test_ensemble_drift_flags(examples):
    m = pdyn.Model.from_file(examples / "satellite_ode45.toml")
    ens = m.ensemble(params={n: [v, v] for n, v in list(m.parameters.items())[:1]},
                     rtol=1e-3)
    assert ens.drifted.all()
    assert all((d > 5e-3).all() for d in ens.drift.values() if not np.isnan(d).all())


def test_typed_drift_warning(examples):
    m = pdyn.Model.from_file(examples / "satellite_ode45.toml")
    with pytest.warns(pdyn.DriftWarning) as record:
        m.run()
    w = [r.message for r in record if isinstance(r.message, pdyn.DriftWarning)][0]
    assert w.quantity and w.drift > w.tolerance == 5e-3


def test_ensemble_releases_the_gil_and_uses_every_core(examples, gil_probe):
    m = pdyn.Model.from_file(examples / "projectile_drag.toml")
    # (the derivation is cached: only the runs are timed)
    ens, runs, seconds, ticks = gil_probe(
        lambda n: m.ensemble(params={"c": np.linspace(0.1, 1.0, n)}), 600)
    assert len(ens) == runs
    assert seconds > 0.05, "too short to tell"
    # A Python thread kept running (about one tick per ms) while Rust worked.
    assert ticks >= 10, (ticks, seconds)
    # All cores: rayon's pool has one thread per core this process may use.
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert ens.threads == usable or (usable >= 2 and ens.threads >= 2), (ens.threads, usable)


def test_derived_parameters_follow_in_run_sweep_and_ensemble(examples):
    # The nanoparticle's mass is defined by its radius (m = 4/3*pi*a^3*rho); it rises to
    # h = kB*T/(m*g) (all kinetic energy kB*T into height), so h scales as a^-3.
    m = pdyn.Model.from_file(examples / "nanoparticle.toml")

    def height(a):
        mass = 4 / 3 * math.pi * a**3 * 2330.0
        return 1.3806503e-23 * 293.0 / (mass * 9.81)

    radii = np.array([10e-9, 20e-9, 40e-9])
    single = m.run(params={"a": 10e-9})
    assert abs(single["z"].max() - height(10e-9)) < 1e-6 * height(10e-9)
    ens = m.ensemble(params={"a": radii}, measures={"top": ("z", "max")})
    np.testing.assert_allclose(ens.measures["top"], [height(a) for a in radii], rtol=1e-6)
    # A value given for the derived parameter itself wins over its definition.
    given = m.ensemble(params={"a": radii, "m": np.full(3, 1e-19)},
                       measures={"top": ("z", "max")})
    np.testing.assert_allclose(given.measures["top"], 1.3806503e-23 * 293.0 / (1e-19 * 9.81),
                               rtol=1e-6)


BLOW_UP = """
name = "x' = c x^2 in disguise: x'' = 2 c^2 x^3 blows up at t = 1/(c x0) for c > 0"
[parameters]
c = 0.0
m = 1.0
[coordinates]
x = { initial = 1.0, rate = "c" }
[particles.p]
mass = "m"
position = "[x, 0, 0]"
[[forces]]
kind = "applied"
on = "p"
force = "[2*m*c^2*x^3, 0, 0]"
[simulate]
t_end = 2.0
[sweep]
parameter = "c"
values = [0.1, 1.0, 2.0]
[sweep.measures]
xmax = { of = "x", stat = "max" }
"""


def test_failed_runs_give_nan_measures_never_a_number_in_sweeps_and_ensembles():
    # c = 0.1 is smooth to t = 2 (blow-up at t = 10); c = 1 and c = 2 blow up at t = 1 and
    # 0.5: the integrations stop there, and their measures must be NaN with a problem each
    # (the statistics over the rows before the failure are not the run's).
    m = pdyn.Model.from_toml(BLOW_UP)
    exact = 1.0 / (1.0 - 0.1 * 2.0)  # x(t) = x0/(1 - c x0 t), the maximum at t_end
    for res in (m.sweep("c", [0.1, 1.0, 2.0]),
                m.ensemble(params={"c": [0.1, 1.0, 2.0]})):
        xmax = np.asarray(res.measures["xmax"])
        assert abs(xmax[0] - exact) < 1e-4 * exact, xmax
        assert np.isnan(xmax[1]) and np.isnan(xmax[2]), xmax
        assert sorted(int(r) if not isinstance(r, float) else r
                      for r, _ in res.problems)[-2:] in ([1, 2], [1.0, 2.0]), res.problems


def test_parameters_cannot_be_assigned_silently(examples):
    m = pdyn.Model.from_file(examples / "satellite.toml")
    for change in (lambda p: p.__setitem__("GM", 2.0), lambda p: p.update(GM=2.0),
                   lambda p: p.pop("GM"), lambda p: p.clear()):
        with pytest.raises(TypeError, match="params="):
            change(m.parameters)
    assert m.parameters["GM"] == 1.0


def test_run_from_another_initial_state(examples):
    # The satellite from (x, y) = (2, 0) with speed 1/sqrt(2): a circular orbit of radius 2
    # (GM = 1), period 2*pi*2^1.5. Independent of the file's own circle of radius 1.
    m = pdyn.Model.from_file(examples / "satellite.toml")
    v = 2 ** -0.5
    period = 2 * np.pi * 2 ** 1.5
    sol = m.run(initial={"x": 2.0, "x'": 0.0, "y": 0.0, "y'": v}, t_end=period, rtol=1e-10,
                atol=1e-12, t_eval=[0.0, period / 4, period])
    assert sol.success
    assert abs(sol.column("x")[0] - 2.0) < 1e-15
    assert abs(sol.column("y")[1] - 2.0) < 1e-6 and abs(sol.column("x")[1]) < 1e-6
    assert abs(sol.column("x")[2] - 2.0) < 1e-6
    # The same as an ensemble member with that initial state, bit for bit.
    ens = m.ensemble(initial={"x": [2.0], "x'": [0.0], "y": [0.0], "y'": [v]}, t_end=period,
                     rtol=1e-10, atol=1e-12)
    assert ens.final[0][0] == sol.y[0][-1]
    with pytest.raises(pdyn.ParameterError, match="initial: `z` is not a state component"):
        m.run(initial={"z": 1.0})
    with pytest.raises(pdyn.ParameterError, match="not a finite number"):
        m.run(initial={"x": float("nan")})
    with pytest.raises(pdyn.ParameterError, match="closed form"):
        m.run(initial={"x": 2.0}, method="exact", t_end=1.0)
    with pytest.raises(pdyn.ParameterError, match="mechanics models"):
        pdyn.Model.from_file(examples / "nbody" / "figure_eight.toml").run(initial={"x": 1.0})
