"""pdyn.kin and pdyn.dsolve equal the commands `pdyn kin` and `pdyn dsolve` (the same library
call); non-finite run outputs fail as `pdyn run` does; compiled right-hand sides run natively."""

import json
import math
import subprocess
import warnings

import numpy as np
import pytest

import pdyn


def cli_json(pdyn_bin, *args):
    out = subprocess.run([pdyn_bin, *args, "--json"], capture_output=True, text=True)
    return out.returncode, json.loads(out.stdout) if out.stdout.strip() else None


# --- kin -----------------------------------------------------------------------------------

def test_kin_circular_motion_closed_forms():
    k = pdyn.kin("[R*cos(omega*t), R*sin(omega*t), 0]")
    assert isinstance(k.speed, pdyn.Expr)
    assert str(k.speed) == "R*omega"
    assert str(k["curvature"]) == "1/R"
    assert isinstance(k.v, pdyn.Vector) and len(k.v) == 3
    assert str(k.a_n) == "R*omega^2"
    assert k.assumed_positive == ["R", "omega"]
    assert k.speed.latex() and k.speed._repr_latex_().startswith("$")
    assert k.v.latex().startswith("\\begin{bmatrix}")


def test_kin_negative_omega_gives_speed_6_and_tangent_along_v():
    k = pdyn.kin("[R*cos(omega*t), R*sin(omega*t), 0]", params={"R": 2, "omega": -3},
                 at="t=0.5")
    (i,) = k.instants
    assert i["speed"] == pytest.approx(6.0, rel=1e-14)
    v, tan = i["v"], i["tangent"]
    assert isinstance(v, np.ndarray) and v.dtype == np.float64 and v.shape == (3,)
    assert np.dot(v, tan) == pytest.approx(6.0, rel=1e-12)
    assert "omega" not in k.assumed_positive


def test_kin_equals_the_cli(pdyn_bin):
    args = ["[R*cos(omega*t), R*sin(omega*t), 0]", "--set", "R=2,omega=-3", "--at", "t=0.5"]
    code, js = cli_json(pdyn_bin, "kin", *args)
    assert code == 0
    k = pdyn.kin(args[0], params={"R": 2, "omega": -3}, at={"t": 0.5})
    for name, q in js["quantities"].items():
        got = k.quantities[name]
        if isinstance(q, list):
            assert [str(c) for c in got] == [c["text"] for c in q]
            assert [c.latex() for c in got] == [c["latex"] for c in q]
        else:
            assert str(got) == q["text"] and got.latex() == q["latex"]
    (ji,) = js["at"]
    (i,) = k.instants
    assert i.resolved == ji["resolved"]
    for name, v in ji["values"].items():
        mine = i.values[name]
        assert np.array_equal(np.atleast_1d(mine), np.array(v["value"]))
    assert k.assumed_positive == js["assumed_positive"]


def test_kin_path_maximum_equals_the_cli(pdyn_bin):
    code, js = cli_json(pdyn_bin, "kin", "--path", "y = A*sin(2*pi*x/L)", "--speed", "V",
                        "--max", "norm(a)", "--over", "x=0..L", "--set", "A=2,L=50,V=10")
    assert code == 0
    k = pdyn.kin(path="y = A*sin(2*pi*x/L)", speed="V", max="norm(a)", over="x=0..L",
                 params={"A": 2, "L": 50, "V": 10})
    assert k.variable == "x"
    assert k.max["value"] == js["max"]["value"] and k.max["at"] == js["max"]["at"]


def test_kin_polar_instant_solved_for_t(pdyn_bin):
    code, js = cli_json(pdyn_bin, "kin", "--polar", "r = t/sqrt(pi), theta = t^2",
                        "--at", "theta=pi")
    assert code == 0
    k = pdyn.kin(polar={"r": "t/sqrt(pi)", "theta": "t^2"}, at={"theta": "pi"})
    assert k.instants[0].resolved == js["at"][0]["resolved"]
    assert str(k.instants[0].exact["speed"]) == js["at"][0]["values"]["speed"]["exact"]["text"]


def test_kin_errors_are_located_model_errors():
    with pytest.raises(pdyn.ModelError) as ei:
        pdyn.kin("[R*cos(omega*t), R*sin(omega*t) +, 0]")
    e = ei.value
    assert isinstance(e, ValueError)
    assert e.file == "<position>" and e.line == 1 and e.column is not None and e.column > 10
    assert e.argument == "position"
    with pytest.raises(pdyn.ModelError) as ei:
        pdyn.kin("[t, 0, 0]", polar="r = 1, theta = t")
    assert "exactly one" in str(ei.value)


def test_kin_accepts_sympy_expressions():
    sympy = pytest.importorskip("sympy")
    R, w, t = sympy.symbols("R omega t", positive=True)
    k = pdyn.kin([R * sympy.cos(w * t), R * sympy.sin(w * t), 0])
    assert sympy.simplify(k.speed.to_sympy() - sympy.Symbol("R") * sympy.Symbol("omega")) == 0


# --- dsolve --------------------------------------------------------------------------------

def test_dsolve_equals_the_cli(pdyn_bin):
    eq = "x'' + 2*zeta*wn*x' + wn^2*x = 0"
    code, js = cli_json(pdyn_bin, "dsolve", eq, "--ic", "x(0)=1, x'(0)=0",
                        "--set", "zeta=0.1,wn=2", "--at", "0,0.5,1")
    assert code == 0
    d = pdyn.dsolve(eq, ic={"x(0)": 1, "x'(0)": 0}, params={"zeta": 0.1, "wn": 2},
                    at=[0, 0.5, 1])
    assert isinstance(d, pdyn.DsolveResult)
    assert d.coords == js["coords"] and d.method == js["method"]
    (case,) = js["cases"]
    assert str(d["x"]) == case["solution"]["x"]["text"]
    assert d["x"].latex() == case["solution"]["x"]["latex"]
    assert d.values.shape == (3, 2) and d.values.dtype == np.float64
    assert np.array_equal(d.values, np.array([row["values"] for row in case["at"]]))
    assert d.values[0, 0] == 1.0


def test_dsolve_harmonic_oscillator_closed_form():
    d = pdyn.dsolve("x'' + w^2*x = 0", ic="x(0)=1, x'(0)=0", params={"w": 3}, at=[0.7])
    assert d.values[0, 0] == pytest.approx(math.cos(2.1), rel=1e-13)
    assert d.values[0, 1] == pytest.approx(-3 * math.sin(2.1), rel=1e-13)


def test_dsolve_projectile_when_landing(pdyn_bin):
    args = ["x'' = 0", "y'' = -g"]
    ic = "x(0)=0, x'(0)=V*cos(a), y(0)=h, y'(0)=V*sin(a)"
    code, js = cli_json(pdyn_bin, "dsolve", *args, "--ic", ic, "--set", "g=9.81,V=20,a=0.5,h=2",
                        "--when", "y = 0")
    assert code == 0
    d = pdyn.dsolve(*args, ic=ic, params={"g": 9.81, "V": 20, "a": 0.5, "h": 2}, when="y = 0")
    assert d.when["value"] == js["when"]["t"]
    # the closed form of the landing time
    g, V, a, h = 9.81, 20.0, 0.5, 2.0
    vy = V * math.sin(a)
    assert d.when["value"] == pytest.approx((vy + math.sqrt(vy * vy + 2 * g * h)) / g, rel=1e-12)
    assert set(d.when["state"]) == set(js["when"]["state"])


def test_dsolve_rule_equals_the_cli(pdyn_bin):
    code, js = cli_json(pdyn_bin, "dsolve", "--rule", "a(v) = -g - c*v^2", "--ic",
                        "x(0)=0, v(0)=v0", "--set", "g=9.81,c=0.01,v0=30", "--at", "0.5,1")
    assert code == 0
    r = pdyn.dsolve(rule="a(v) = -g - c*v^2", ic="x(0)=0, v(0)=v0",
                    params={"g": 9.81, "c": 0.01, "v0": 30}, at=[0.5, 1])
    assert isinstance(r, pdyn.RuleResult) and r.variable == js["variable"]
    for q in js["quantities"]:
        mine = r.quantities[q["name"]]
        if q["closed_form"] is None:
            assert mine is None
        else:
            assert str(mine) == q["closed_form"]["text"]
        assert list(r.values[q["name"]]) == [p["value"] for p in q["at"]]


def test_dsolve_errors_are_located_model_errors():
    with pytest.raises(pdyn.ModelError) as ei:
        pdyn.dsolve("x'' + * x = 0")
    assert ei.value.file == "<equation 1>" and ei.value.column is not None
    assert ei.value.argument == "equations"
    with pytest.raises(pdyn.ModelError) as ei:
        pdyn.dsolve("x'' + x = 0", ic="x(0)=1, x'(0)=0", at=["1 +"])
    assert ei.value.argument == "at" and ei.value.file == "--at"
    with pytest.raises(pdyn.ModelError):
        pdyn.dsolve("x'' + x = 0", ic="x(0)=1, z(0)=2")


# --- non-finite outputs --------------------------------------------------------------------

FALL_OVER_L = (
    'name = "fall over L"\ngravity = "[0, 0, -g]"\n[parameters]\nL = 2.0\ng = 9.81\n'
    '[coordinates]\nz = { initial = 10.0, rate = 0.0 }\n'
    '[particles.p]\nmass = 1\nposition = "[0, 0, z]"\n'
    '[monitors]\nheight_over_L = "z/L"\n'
    '[simulate]\nt_end = 1\nmethod = "dop853"\n'
)


def test_a_run_whose_output_becomes_non_finite_fails(pdyn_bin, tmp_path):
    m = pdyn.Model.from_toml(FALL_OVER_L, "fall_over_L.toml")
    ok = m.run()
    assert ok.success and ok.status == 0 and ok.non_finite == []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = m.run(params={"L": 0.0})
    assert sol.success is False and sol.status < 0
    assert sol.non_finite == ["height_over_L"] and sol.non_finite_t == 0.0
    assert "`height_over_L`" in sol.message and "first at t = 0e0" in sol.message
    assert "not finite" in sol.message
    assert len(sol.t) > 1  # the partial (here: whole) solution is kept
    # the CLI exits 1 with a non_finite error on the same run
    f = tmp_path / "fall_over_L.toml"
    f.write_text(FALL_OVER_L)
    out = subprocess.run([pdyn_bin, "run", str(f), "--set", "L=0", "--json"],
                         capture_output=True, text=True)
    assert out.returncode == 1 and "non_finite" in out.stdout


# --- JIT -----------------------------------------------------------------------------------

def test_compiled_rhs_runs_natively_and_equals_the_interpreter():
    exprs = ["y1", "-k*y0 - c*y1"]
    a = pdyn.solve_ivp(exprs, (0, 10), [1.0, 0.0], rtol=1e-10, atol=1e-12,
                       args={"k": 4.0, "c": 0.1})
    b = pdyn.solve_ivp(exprs, (0, 10), [1.0, 0.0], rtol=1e-10, atol=1e-12,
                       args={"k": 4.0, "c": 0.1}, jit=False)
    assert b.native is False
    # native where the platform has a JIT (x86_64, aarch64); the same bits either way
    assert a.native in (True, False)
    assert np.array_equal(a.t, b.t) and np.array_equal(a.y, b.y) and a.nfev == b.nfev
    # a cached program with other parameter values
    c = pdyn.solve_ivp(exprs, (0, 10), [1.0, 0.0], rtol=1e-10, atol=1e-12,
                       args={"k": 9.0, "c": 0.0})
    assert c.y[0, -1] == pytest.approx(math.cos(30.0), abs=1e-7)


def test_model_paths_native_and_interpreted_agree(examples):
    m = pdyn.Model.from_file(examples / "building.toml")
    values = np.linspace(5, 12, 6)
    meas = {"top": ("y2 - (2*L - 3*m*g/(2*k))", "max_abs")}
    a = m.sweep("omega", values, measures=meas, t_end=2.0, jit=True)
    b = m.sweep("omega", values, measures=meas, t_end=2.0, jit=False)
    assert np.array_equal(a.measures["top"], b.measures["top"])
    ea = m.ensemble(params={"omega": values}, measures=meas, t_end=2.0)
    eb = m.ensemble(params={"omega": values}, measures=meas, t_end=2.0, jit=False)
    assert np.array_equal(ea.final, eb.final) and np.array_equal(ea["top"], eb["top"])
    ra = m.run(t_end=2.0)
    rb = m.run(t_end=2.0, jit=False)
    assert np.array_equal(ra.y, rb.y) and ra.columns == rb.columns
