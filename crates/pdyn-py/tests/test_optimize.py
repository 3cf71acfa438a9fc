"""``pdyn.Model.optimize`` (issue 26): the twin of ``pdyn optimize``. Truth: without drag the
longest range is at θ = π/4 (v0² sin 2θ / g); with drag the same angle as the command."""
import math
import os

import pytest

import pdyn

HERE = os.path.dirname(os.path.abspath(__file__))
MODEL = os.path.join(HERE, "..", "..", "..", "examples", "data", "launch_angle.toml")


def test_quarter_turn_without_drag():
    m = pdyn.Model.from_file(MODEL)
    r = m.optimize({"theta": (0.0, math.pi / 2)}, maximize="range", params={"c": 0.0})
    assert abs(r.x[0] - math.pi / 4) < 1e-8
    assert abs(r.fun - 400 / 9.81) < 1e-9
    assert r.method == "brent" and r.success and not r.at_bound


def test_measures_given_in_python_and_errors():
    m = pdyn.Model.from_file(MODEL)
    r = m.optimize({"theta": (0.0, math.pi / 2)}, maximize="far", measures={"far": ("x", "final")})
    assert 0.6 < r.x[0] < 0.7
    with pytest.raises(pdyn.PdynError, match="not a measure"):
        m.optimize({"theta": (0.0, 1.0)}, maximize="height")
    with pytest.raises(ValueError):
        m.optimize({"theta": (0.0, 1.0)})
