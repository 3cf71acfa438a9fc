"""Tests of the Python package: the numbers are the CLI's, SciPy's and the textbook's."""

import json
import math
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

import pdyn

RADIAL_FALL = (
    'name = "radial fall"\n[parameters]\nGM = 1.0\n[coordinates]\n'
    'x = { initial = 1.0, rate = 0.0 }\ny = { initial = 0.0, rate = 0.0 }\n'
    '[particles.p]\nmass = 1\nposition = "[x, y, 0]"\n[points]\nO = "[0, 0, 0]"\n'
    '[[forces]]\nkind = "inverse_square"\non = "p"\nto = "O"\nstrength = "GM"\n'
    '[simulate]\nt_end = 10\nmethod = "dopri5"\n'
)


def cli_json(pdyn_bin, *args):
    out = subprocess.run([pdyn_bin, *args, "--json"], capture_output=True, text=True)
    return out.returncode, json.loads(out.stdout)


def rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def test_projectile_drag_state_at_5_equals_the_cli(examples, pdyn_bin):
    path = examples / "projectile_drag.toml"
    sol = pdyn.Model.from_file(path).run()
    assert sol.success and sol.status == 0
    assert sol.t[-1] == 5.0
    code, summary = cli_json(pdyn_bin, "run", str(path))
    assert code == 0
    final = summary["final"]
    for name in ["x", "y", "z", "x'", "y'", "z'"]:
        assert rel(sol[name][-1], final[name]) <= 1e-12, (name, sol[name][-1], final[name])
    # The textbook's values (crates/pdyn/tests/run.rs), 8 digits.
    assert abs(sol["z"][-1] - (-15.7308060)) < 1e-6
    assert sol.y.shape == (6, len(sol.t))
    np.testing.assert_array_equal(sol.y[2], sol["z"])


def test_kremlin_range_from_the_terminal_event_equals_the_cli(examples, pdyn_bin):
    path = examples / "kremlin_stone.toml"
    m = pdyn.Model.from_file(path)
    sol = m.run()
    assert sol.status == 1 and sol.success
    assert len(sol.t_events) == 1 and sol.t_events[0].shape == (1,)
    assert sol.y_events[0].shape == (1, 4)
    p = m.parameters
    vz = p["v0"] * math.sin(p["theta"])
    t_hit = (vz + math.sqrt(vz * vz + 2 * p["g"] * p["H"])) / p["g"]
    rng = p["v0"] * math.cos(p["theta"]) * t_hit
    assert rel(sol.t_events[0][0], t_hit) < 1e-10
    assert rel(sol.y_events[0][0, 0], rng) < 1e-8
    assert sol.t[-1] == sol.t_events[0][0]
    code, summary = cli_json(pdyn_bin, "run", str(path))
    assert code == 0
    ev = summary["events"][0]
    assert rel(sol.t_events[0][0], ev["t"]) <= 1e-12
    assert rel(sol["x"][-1], summary["final"]["x"]) <= 1e-12


def test_arrays_are_float64_with_scipy_shapes(examples):
    sol = pdyn.Model.from_file(examples / "projectile_drag.toml").run(t_eval=np.linspace(0, 5, 11))
    for a in (sol.t, sol.y, sol["x"]):
        assert isinstance(a, np.ndarray) and a.dtype == np.float64
    assert sol.t.shape == (11,) and sol.y.shape == (6, 11)
    assert sol.columns[:7] == ["t", "x", "y", "z", "x'", "y'", "z'"]
    assert sol.nfev > 0 and sol.nfev == sol.stats["fevals"]


def test_params_override_like_set_and_are_checked(examples):
    m = pdyn.Model.from_file(examples / "projectile_drag.toml")
    no_drag = m.run(params={"c": 1e-12}, t_end=1.0)
    assert abs(no_drag["z"][-1] - (20 - 9.81 / 2)) < 1e-6
    with pytest.raises(pdyn.ParameterError, match="mass"):
        m.run(params={"m": -1.0})
    with pytest.raises(pdyn.ParameterError, match="not a parameter"):
        m.run(params={"nope": 1.0})
    assert m.parameters["c"] == 0.5  # unchanged


def test_drift_warning_on_the_satellite_at_ode45_settings(examples):
    m = pdyn.Model.from_file(examples / "satellite_ode45.toml")
    with pytest.warns(pdyn.DriftWarning, match="should be conserved"):
        sol = m.run()
    assert any(mon["conserved"] and mon["drift"] > 5e-3 for mon in sol.monitors)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m.run(rtol=1e-9, atol=1e-12)


def test_broken_model_raises_model_error_with_its_line():
    with pytest.raises(pdyn.ModelError) as info:
        pdyn.Model.from_toml('name = "broken"\n[parameters]\nm = "2 *"\n', "broken.toml")
    e = info.value
    assert isinstance(e, ValueError) and isinstance(e, pdyn.PdynError)
    assert e.file == "broken.toml" and e.line == 3 and e.column >= 5
    assert "broken.toml:3:" in str(e)


def test_failing_run_returns_the_partial_solution():
    with pytest.warns(pdyn.DriftWarning):
        sol = pdyn.Model.from_toml(RADIAL_FALL, "radial_fall.toml").run()
    assert sol.success is False and sol.status == -1
    assert "integration failed" in sol.message or "step" in sol.message
    assert len(sol.t) > 1 and sol.t[-1] < 10
    assert sol["x"][-1] < 1.0


def test_from_dict_equals_from_toml(examples):
    d = {
        "name": "fall",
        "gravity": "[0, 0, -g]",
        "parameters": {"g": 9.81},
        "coordinates": {"z": {"initial": 10.0, "rate": 0.0}},
        "particles": {"p": {"mass": 1.0, "position": "[0, 0, z]"}},
        "simulate": {"t_end": 1.0, "rtol": 1e-10, "atol": 1e-12},
    }
    sol = pdyn.Model.from_dict(d).run()
    assert abs(sol["z"][-1] - (10 - 9.81 / 2)) < 1e-9


def test_derive_gives_expressions(examples):
    d = pdyn.Model.from_file(examples / "projectile_drag.toml").derive()
    assert d.unknowns == ["x''", "y''", "z''"]
    assert d.solution is not None and len(d.solution) == 3
    assert len(d.equations) == 3
    label, lhs, rhs = d.equations[2]
    assert isinstance(lhs, pdyn.Expr) and "z''" in str(lhs)
    u, acc = d.solution[2]
    assert u == "z''"
    assert acc._repr_latex_().startswith("$") and acc._repr_latex_().endswith("$")
    assert d.first_order[0] == ("x", pdyn.Expr("x'", "x'"))
    assert [s for s, _ in d.first_order] == ["x", "y", "z", "x'", "y'", "z'"]
    sympy = pytest.importorskip("sympy")
    # g and c are declared positive in the model: their symbols carry it (coordinates do not).
    g, c = sympy.symbols("g c", positive=True)
    xd, yd, zd = sympy.symbols("x_d y_d z_d")
    expected = -g - c * zd * sympy.sqrt(xd**2 + yd**2 + zd**2)
    assert sympy.simplify(acc.to_sympy() - expected) == 0, acc


def test_derive_gives_the_mass_matrix_and_forcing(examples):
    # The double pendulum's M(q) q'' = f, as a textbook writes it: M symmetric, factored.
    d = pdyn.Model.from_file(examples / "pendulum_chain_2.toml").derive()
    mm, f = d.mass_matrix, d.forcing
    assert len(mm) == 2 and all(len(row) == 2 for row in mm) and len(f) == 2
    assert all(isinstance(e, pdyn.Expr) for row in mm for e in row)
    assert str(mm[0][1]) == str(mm[1][0]) == "l1*l2*m2*cos(q1 - q2)"
    assert str(mm[0][0]) == "l1^2*(m1 + m2)"
    assert str(mm[1][1]) == "l2^2*m2"
    sympy = pytest.importorskip("sympy")
    g, l1, l2, m1, m2 = sympy.symbols("g l1 l2 m1 m2", positive=True)
    q1, q2, q2d = sympy.symbols("q1 q2 q2_d")
    expected = -g * l1 * (m1 + m2) * sympy.sin(q1) - l1 * l2 * m2 * q2d**2 * sympy.sin(q1 - q2)
    assert sympy.simplify(f[0].to_sympy() - expected) == 0, f[0]
    # Newton's form: the diagonal m; a model whose unknowns include a reaction (the pulley's
    # tension) has no mass matrix of the coordinates.
    n = pdyn.Model.from_file(examples / "projectile_drag.toml").derive()
    assert [[str(e) for e in row] for row in n.mass_matrix] == [
        ["m", "0", "0"], ["0", "m", "0"], ["0", "0", "m"]]
    p = pdyn.Model.from_file(examples / "pulley.toml").derive()
    assert p.mass_matrix is None and p.forcing is None


def arenstorf(t, y):
    mu = 0.012277471
    mp = 1 - mu
    d1 = ((y[0] + mu) ** 2 + y[1] ** 2) ** 1.5
    d2 = ((y[0] - mp) ** 2 + y[1] ** 2) ** 1.5
    return [y[2], y[3],
            y[0] + 2 * y[3] - mp * (y[0] + mu) / d1 - mu * (y[0] - mp) / d2,
            y[1] - 2 * y[2] - mp * y[1] / d1 - mu * y[1] / d2]


ARENSTORF_EXPR = [
    "y2", "y3",
    "y0 + 2*y3 - mp*(y0 + mu)/((y0 + mu)^2 + y1^2)^(3/2) - mu*(y0 - mp)/((y0 - mp)^2 + y1^2)^(3/2)",
    "y1 - 2*y2 - mp*y1/((y0 + mu)^2 + y1^2)^(3/2) - mu*y1/((y0 - mp)^2 + y1^2)^(3/2)",
]
ARENSTORF_Y0 = [0.994, 0.0, 0.0, -2.00158510637908252240537862224]
ARENSTORF_T = 17.0652165601579625588917206249


def test_solve_ivp_compiled_and_callable_agree_and_count_evaluations():
    mu = 0.012277471
    calls = [0]

    def f(t, y):
        calls[0] += 1
        return arenstorf(t, y)

    tol = dict(rtol=1e-10, atol=1e-10)
    a = pdyn.solve_ivp(ARENSTORF_EXPR, (0, ARENSTORF_T), ARENSTORF_Y0, method="DOP853",
                       args={"mu": mu, "mp": 1 - mu}, **tol)
    b = pdyn.solve_ivp(f, (0, ARENSTORF_T), ARENSTORF_Y0, method="DOP853", **tol)
    assert a.success and b.success
    assert a.gil_released and not b.gil_released
    # nfev is the Rust solver's count: exactly the number of Python calls made.
    assert b.nfev == calls[0]
    assert a.nfev == b.nfev
    # Same steps; the arithmetic differs in rounding only (x^(3/2) compiled vs x**1.5).
    np.testing.assert_allclose(a.y[:, -1], b.y[:, -1], rtol=0, atol=1e-9)
    # One period: back at the start.
    assert np.max(np.abs(a.y[:, -1] - ARENSTORF_Y0)) < 1e-5


def test_solve_ivp_matches_scipy_dop853_on_arenstorf():
    scipy_integrate = pytest.importorskip("scipy.integrate")
    tol = dict(rtol=1e-10, atol=1e-10)
    te = np.linspace(0, ARENSTORF_T, 50)
    ours = pdyn.solve_ivp(arenstorf, (0, ARENSTORF_T), ARENSTORF_Y0, method="DOP853", t_eval=te, **tol)
    ref = scipy_integrate.solve_ivp(arenstorf, (0, ARENSTORF_T), ARENSTORF_Y0, method="DOP853",
                                    t_eval=te, **tol)
    assert ours.y.shape == ref.y.shape == (4, 50)
    np.testing.assert_array_equal(ours.t, ref.t)
    # Both are within the tolerance of the true orbit; the orbit amplifies errors ~1e3-fold.
    err = np.max(np.abs(ours.y - ref.y))
    assert err < 1e-5, err
    assert np.max(np.abs(ours.y[:, -1] - ARENSTORF_Y0)) < 1e-5


def test_solve_ivp_events_and_scipy_method_names():
    def hit(t, y):
        return y[0]
    hit.terminal = True
    hit.direction = -1
    sol = pdyn.solve_ivp(lambda t, y: [y[1], -9.81], (0, 10), [10.0, 0.0], method="RK45",
                         events=hit, rtol=1e-10, atol=1e-12)
    assert sol.status == 1
    assert abs(sol.t_events[0][0] - math.sqrt(20 / 9.81)) < 1e-9
    compiled = pdyn.solve_ivp(["y1", "-9.81"], (0, 10), [10.0, 0.0], method="Radau",
                              events=[("y0", True, -1)], rtol=1e-10, atol=1e-12)
    assert compiled.status == 1 and compiled.method == "radau5"
    assert abs(compiled.t_events[0][0] - math.sqrt(20 / 9.81)) < 1e-8


def test_solve_ivp_failure_and_python_errors():
    sol = pdyn.solve_ivp(["y0^2"], (0, 2), [1.0])  # blows up at t = 1
    assert sol.success is False and sol.status == -1 and 0.99 < sol.t[-1] < 1.01
    with pytest.raises(ZeroDivisionError):
        pdyn.solve_ivp(lambda t, y: [1 / 0], (0, 1), [0.0])
    with pytest.raises(pdyn.ParameterError):
        pdyn.solve_ivp(["y1"], (0, 1), [0.0])
    with pytest.raises(pdyn.ParameterError):
        pdyn.solve_ivp(["y0"], (0, 1), [0.0], method="nope")


def test_sweep_measures_and_pandas(examples):
    m = pdyn.Model.from_file(examples / "projectile_drag.toml")
    values = np.array([0.1, 0.5, 1.0])
    sw = m.sweep("c", values, measures={"zfinal": ("z", "final")}, threads=2)
    assert sw.values.dtype == np.float64 and sw.measures["zfinal"].shape == (3,)
    for c, z in zip(values, sw.measures["zfinal"]):
        single = m.run(params={"c": float(c)})
        assert rel(z, single["z"][-1]) < 1e-12
    pd = pytest.importorskip("pandas")
    df = sw.to_pandas()
    assert list(df.columns) == ["c", "zfinal"]
    assert isinstance(m.run().to_pandas(), pd.DataFrame)


def test_sweep_releases_the_gil(examples, gil_probe):
    m = pdyn.Model.from_file(examples / "projectile_drag.toml")

    def sweep(n):
        return m.sweep("c", np.linspace(0.1, 1.0, n), measures={"zmin": ("z", "min")},
                       threads=1)

    sw, runs, seconds, ticks = gil_probe(sweep, 500)
    assert sw.runs == runs
    # With the GIL held the ticker could not run at all while the sweep ran.
    assert seconds > 0.05, "the sweep is too short to tell"
    assert ticks >= 10, (ticks, seconds)


def test_from_file_error_names_the_file_and_methods_are_listed(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n[parameters]\nm = 1.0\n[coordinates]\nq = { initial = "m +" }\n')
    with pytest.raises(pdyn.ModelError) as info:
        pdyn.Model.from_file(bad)
    assert info.value.file == str(bad) and info.value.line == 5
    names = pdyn.methods()
    assert {"dopri5", "dop853", "radau5", "tsit5", "vern9"} <= set(names)
    with pytest.raises(pdyn.ParameterError, match="unknown method"):
        pdyn.Model.from_file(
            pathlib.Path(__file__).resolve().parents[3] / "examples" / "kremlin_stone.toml"
        ).run(method="nope")


PENDULUM_TOML = '''name = "pendulum"
gravity = "[0, -g, 0]"
[parameters]
g = 9.81
L = 1.0
m = 1.0
[coordinates]
q = { initial = 0.3, rate = 0.0 }
[particles.bob]
mass = "m"
position = "L*[sin(q), -cos(q), 0]"
'''


def test_builder_model_derives_the_same_equations_as_its_toml():
    m = pdyn.Model("pendulum")
    q = m.coordinate("q", initial=0.3, rate=0.0)
    assert q == "q"
    m.particle("bob", mass="m", position="L*[sin(q), -cos(q), 0]")
    m.gravity("[0, -g, 0]")
    m.parameters(g=9.81, L=1, m=1)
    assert m.parameters == {"g": 9.81, "L": 1.0, "m": 1.0}
    built = m.derive()
    loaded = pdyn.Model.from_toml(PENDULUM_TOML).derive()
    assert [(l, str(a), str(b)) for l, a, b in built.equations] == \
        [(l, str(a), str(b)) for l, a, b in loaded.equations]
    assert [(s, str(e)) for s, e in built.first_order] == \
        [(s, str(e)) for s, e in loaded.first_order]
    a = m.run(t_end=2.0, rtol=1e-10, atol=1e-12)
    b = pdyn.Model.from_toml(PENDULUM_TOML).run(t_end=2.0, rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(a.y, b.y)
    with pytest.raises(pdyn.ParameterError, match="loaded"):
        pdyn.Model.from_toml(PENDULUM_TOML).parameters(g=1.0)
    sympy = pytest.importorskip("sympy")
    L, qs = sympy.symbols("L q")
    s = pdyn.Model("pendulum")
    s.coordinate("q", initial=0.3)
    s.particle("bob", mass="m", position=[L * sympy.sin(qs), -L * sympy.cos(qs), 0])
    s.gravity("[0, -g, 0]")
    s.parameters(g=9.81, L=1, m=1)
    c = s.run(t_end=2.0, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(c.y, b.y, rtol=0, atol=1e-9)


def test_notebooks_are_stored_without_outputs(examples):
    notebooks = sorted((examples / "notebooks").glob("*.ipynb"))
    assert {p.name for p in notebooks} >= {"satellite_drift.ipynb", "building_resonance.ipynb",
                                           "pendulum_chain.ipynb"}
    for p in notebooks:
        nb = json.loads(p.read_text())
        for cell in nb["cells"]:
            if cell["cell_type"] == "code":
                assert cell["outputs"] == [] and cell["execution_count"] is None, p.name


def test_dense_output_interpolates_like_scipy():
    for fun in (["y1", "-y0"], lambda t, y: [y[1], -y[0]]):
        te = np.linspace(0, 10, 7)
        sol = pdyn.solve_ivp(fun, (0, 10), [1.0, 0.0], rtol=1e-10, atol=1e-12,
                             dense_output=True, t_eval=te)
        assert sol.t.shape == (7,) and sol.sol is not None
        tt = np.linspace(0, 10, 1001)
        y = sol.sol(tt)
        assert y.shape == (2, 1001) and sol.sol(3.0).shape == (2,)
        h = np.max(np.diff(sol.sol.ts))
        # Cubic Hermite: error <= h^4/384 max|y''''| (= 1 here), plus the solver's error.
        assert np.max(np.abs(y[0] - np.cos(tt))) < h**4 / 384 + 1e-8
        np.testing.assert_allclose(sol.sol(te), sol.y, rtol=0, atol=h**4 / 384 + 1e-8)
        # Exact at the steps.
        plain = pdyn.solve_ivp(fun, (0, 10), [1.0, 0.0], rtol=1e-10, atol=1e-12)
        np.testing.assert_array_equal(sol.sol(plain.t), plain.y)


def test_forces_mirror_the_cli(examples, pdyn_bin):
    path = examples / "banked_curve.toml"
    m = pdyn.Model.from_file(path)
    res = m.forces()
    code, cli = cli_json(pdyn_bin, "forces", str(path))
    assert code == 0
    assert res.unknowns == cli["unknowns"]
    for ours, theirs in zip(res.values, cli["solutions"]):
        for k, v in theirs.items():
            assert rel(ours[k], v) <= 1e-12
    crit = res.checks[0]["critical"]
    assert [round(v, 9) for v, _ in crit] == \
        [round(k["value"], 9) for k in cli["checks"][0]["critical"]]
    # V^2 = g R (sin b -+ mu cos b)/(cos b +- mu sin b): the least and the greatest speed.
    g, R, b, mu = 9.81, 50.0, math.radians(30), 0.2
    vmin = math.sqrt(g * R * (math.sin(b) - mu * math.cos(b)) / (math.cos(b) + mu * math.sin(b)))
    assert abs(crit[0][0] - vmin) < 1e-9
    faster = m.forces(params={"V": 20.0})
    assert faster.values[0]["N"] > res.values[0]["N"]
    assert isinstance(res.equations[0][1], pdyn.Expr)


def test_plots_with_and_without_matplotlib(examples, tmp_path):
    m = pdyn.Model.from_file(examples / "projectile_drag.toml")
    sol = m.run(plots=tmp_path / "plots")
    written = [p.suffix for p in (tmp_path / "plots").iterdir()]
    assert ".png" in written or ".svg" in written, written
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    ax = sol.plot("x", "z")
    assert len(ax.get_lines()) == 2
    ax = sol.plot_trajectory("x", "z")
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), sol["z"])
    ivp = pdyn.solve_ivp(["y1", "-y0"], (0, 1), [1.0, 0.0])
    assert len(ivp.plot().get_lines()) == 2


def test_the_trajectory_is_not_copied_beyond_one(examples):
    sol = pdyn.Model.from_file(examples / "projectile_drag.toml").run()
    table = dict.__getitem__(sol, "_table")
    assert np.shares_memory(sol.y, table) and np.shares_memory(sol.t, table)
    assert table.flags.owndata or table.base is not None
    ivp = pdyn.solve_ivp(["y1", "-y0"], (0, 1), [1.0, 0.0])
    assert ivp.y.shape == (2, len(ivp.t)) and ivp.y.base is not None


def test_method_exact_runs_the_closed_form_like_the_cli(examples, pdyn_bin):
    """`method="exact"` (issue 25: it raised UnknownMethod) is the library's `--method exact`:
    the same numbers as the CLI, and a tight DOP853 integration agrees near the building's
    first resonance, where the closed form is evaluated stably (issue 34)."""
    path = examples / "building.toml"
    m = pdyn.Model.from_file(path)
    t = np.linspace(0.0, 5.0, 11)
    params = {"omega": 8.740320488976}
    ex = m.run(method="exact", t_eval=t, params=params)
    assert ex.success and ex.method == "exact"
    num = m.run(method="DOP853", rtol=1e-12, atol=1e-13, t_eval=t, params=params)
    scale = np.max(np.abs(num.y[:2] - num.y[:2, :1]))
    assert np.max(np.abs(ex.y[:2] - num.y[:2])) < 1e-8 * max(scale, 1.0)
    code, summary = cli_json(pdyn_bin, "run", str(path), "--method", "exact",
                             "--t-eval", ",".join(repr(float(x)) for x in t),
                             "--set", "omega=8.740320488976")
    assert code == 0
    for name in ["y1", "y2", "y1'", "y2'"]:
        assert ex[name][-1] == summary["final"][name], name
