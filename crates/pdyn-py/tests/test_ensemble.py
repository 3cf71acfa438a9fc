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
