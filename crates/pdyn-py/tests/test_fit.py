"""`pdyn.Model.fit` side by side with SciPy: `least_squares` over `solve_ivp` (DOP853, tight
tolerances, a finite-difference Jacobian) on the same data, and the command's JSON."""
import json
import math
import subprocess

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

import pdyn


def drop_data(examples):
    d = np.loadtxt(examples / "data" / "drop.csv", delimiter=",", comments="#", skiprows=2)
    return d[:, 0], d[:, 1]


def scipy_fit(t, z, x0, g=9.81):
    """z'' = −g − c |z'| z' (quadratic drag on a falling ball), θ = (c, z0, v0)."""

    def residuals(theta):
        c, z0, v0 = theta
        sol = solve_ivp(lambda _t, y: [y[1], -g - c * abs(y[1]) * y[1]], (0.0, t[-1]),
                        [z0, v0], method="DOP853", t_eval=t, rtol=1e-13, atol=1e-13)
        return sol.y[0] - z

    return least_squares(residuals, x0, jac="3-point", method="lm", x_scale="jac",
                         ftol=1e-15, xtol=1e-15, gtol=1e-15)


def test_fit_matches_scipy_least_squares_to_1e8(examples):
    t, z = drop_data(examples)
    model = pdyn.Model.from_file(examples / "data" / "drop.toml")
    # Both integrate at the same tight tolerances.
    r = model.fit(examples / "data" / "drop.csv", free=["c", "initial.z", "rate.z"],
                  rtol=1e-13, atol=1e-13)
    assert r.success and r.names == ["c", "initial.z", "rate.z"]
    ref = scipy_fit(t, z, [0.02, 49.0, -0.5])
    assert ref.success
    print("max relative difference from SciPy:", np.max(np.abs(r.x - ref.x) / np.abs(ref.x)))
    np.testing.assert_allclose(r.x, ref.x, rtol=1e-8, atol=0)
    np.testing.assert_allclose(r.cost, ref.cost, rtol=1e-10)
    # Standard errors from SciPy's (finite-difference) Jacobian at its optimum.
    J = ref.jac
    s2 = 2 * ref.cost / (len(z) - 3)
    se = np.sqrt(np.diag(np.linalg.inv(J.T @ J)) * s2)
    np.testing.assert_allclose(r.stderr, se, rtol=1e-5)
    # The sensitivities' Jacobian against SciPy's at the same point.
    np.testing.assert_allclose(r.jac, J, rtol=1e-5, atol=1e-8)
    # And the truth of examples/data/generate_drop.py within two standard errors.
    for value, se_i, truth in zip(r.x, r.stderr, [0.05, 50.0, -0.8]):
        assert abs(value - truth) < 2 * se_i


def test_fit_from_arrays_equals_the_file_and_the_command(examples, pdyn_bin):
    t, z = drop_data(examples)
    model = pdyn.Model.from_file(examples / "data" / "drop.toml")
    a = model.fit({"t": t, "z": z}, free="c,initial.z,rate.z")
    b = model.fit(examples / "data" / "drop.csv", free=["c", "initial.z", "rate.z"])
    np.testing.assert_array_equal(a.x, b.x)
    out = subprocess.run([pdyn_bin, "fit", str(examples / "data" / "drop.toml"), "--data",
                          str(examples / "data" / "drop.csv"), "--free", "c,initial.z,rate.z",
                          "--json"], capture_output=True, text=True, check=True)
    cli = json.loads(out.stdout)
    assert [e["value"] for e in cli["estimates"]] == list(b.x)
    assert cli["status"] == b.status


def test_fit_weights_and_bounds(examples):
    t, z = drop_data(examples)
    model = pdyn.Model.from_file(examples / "data" / "drop.toml")
    r = model.fit({"t": t, "z": z, "sigma_z": np.full_like(t, 0.02)},
                  free=["c", "initial.z", "rate.z"], absolute_sigma=True)
    assert 0.8 < r.reduced_chi2 < 1.25
    bounded = model.fit({"t": t, "z": z}, free=["c", "initial.z", "rate.z"],
                        bounds={"c": (0.0, 0.04)})
    assert bounded.x[0] == pytest.approx(0.04, abs=1e-12)
    assert any("at its bound" in w for w in bounded.warnings)


def test_fit_errors(examples):
    model = pdyn.Model.from_file(examples / "data" / "drop.toml")
    with pytest.raises(pdyn.PdynError, match="not a parameter"):
        model.fit(examples / "data" / "drop.csv", free=["k"])
    with pytest.raises(pdyn.ModelError, match="NaN"):
        model.fit({"t": [0.0, 0.1, 0.2], "z": [1.0, math.nan, 0.9]}, free=["c"])
    with pytest.raises(pdyn.ModelError, match="no column"):
        model.fit({"t": [0.0, 0.1, 0.2], "sigma_z": [1.0, 1.0, 1.0]}, free=["c"])
