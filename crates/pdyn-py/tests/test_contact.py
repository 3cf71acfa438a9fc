"""Hybrid models from Python: the same runs as `pdyn run`, with the mode timeline, switches,
impacts and Zeno accumulation in the result (issue 31). Expected values are the textbook's
closed forms."""
import math
import warnings

import numpy as np
import pytest

import pdyn


def test_bouncing_ball_timeline_and_zeno(examples):
    sol = pdyn.Model.from_file(examples / "contact" / "bouncing_ball.toml").run(params={"e": 0.5})
    assert sol.success
    h = sol.hybrid
    t1 = math.sqrt(2 * 1.0 / 9.81)
    assert h["impacts"][0]["t"] == pytest.approx(t1, rel=1e-9)
    assert h["impacts"][1]["t"] == pytest.approx(2 * t1, rel=1e-9)
    assert h["impacts"][0]["normal_speed_after"] == pytest.approx(
        0.5 * h["impacts"][0]["normal_speed_before"], rel=1e-12)
    assert h["zeno"][0]["t_accumulation"] == pytest.approx(3 * t1, rel=1e-9)
    assert h["timeline"][-1]["modes"] == {"floor": "in contact"}
    assert sol["N_floor"][-1] == pytest.approx(0.1 * 9.81, rel=1e-9)
    assert h["dissipated_impacts"] == pytest.approx(0.1 * 9.81, rel=1e-9)
    assert [m["name"] for m in sol.monitors] == ["energy_balance"]


def test_stick_slip_switches_and_rest(examples):
    sol = pdyn.Model.from_file(examples / "contact" / "stick_slip.toml").run(t_end=10.0)
    sw = sol.hybrid["switches"]
    assert sw[-1]["to"] == "stuck"
    step = 2 * 0.3 * 9.81 / 100
    assert abs(sol["x"][-1]) == pytest.approx(0.5 - 8 * step, rel=1e-8)
    assert abs(sol["x"][-1]) <= 0.35 * 9.81 / 100
    half = math.pi * math.sqrt(1 / 100)
    assert np.allclose([s["t"] for s in sw[1:]], half * np.arange(1, len(sw)), rtol=1e-9)


def test_models_without_contacts_have_no_hybrid_part(examples):
    sol = pdyn.Model.from_file(examples / "kremlin_stone.toml").run()
    assert sol.hybrid is None


def test_friction_doing_work_warns(examples):
    src = (examples / "contact" / "block_sliding.toml").read_text()
    # The block held to a ceiling by its coordinates would have to be pulled: warned.
    m = pdyn.Model.from_toml(src.replace('surface = "r.y"', 'surface = "-r.y"'))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        m.run()
    assert any("pull" in str(x.message) for x in w)


def test_contacts_and_event_actions_built_in_code():
    m = pdyn.Model("ball built in code")
    m.coordinate("y", initial=2.0, rate=0.0)
    m.particle("ball", mass=1.0, position="[0, y, 0]")
    m.gravity("[0, -g, 0]")
    m.parameters(g=9.81)
    m.contact("floor", on="ball", surface="r.y", e=1.0)
    m.event("top", when="y'", direction="falling", set=["g = 2*g"])
    m.simulate(t_end=3.0, rtol=1e-10, atol=1e-12)
    sol = m.run()
    h = sol.hybrid
    t1 = math.sqrt(2 * 2.0 / 9.81)
    assert h["impacts"][0]["t"] == pytest.approx(t1, rel=1e-9)
    # e = 1: back to the top at 2 t1, where gravity doubles; the next fall takes t1/sqrt(2).
    assert h["actions"][0]["t"] == pytest.approx(2 * t1, rel=1e-9)
    assert h["impacts"][1]["t"] == pytest.approx(2 * t1 + t1 / math.sqrt(2), rel=1e-9)
