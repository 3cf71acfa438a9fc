"""Results that behave like SciPy's and show well in Jupyter (issue 30, item 2): a coordinate
named `y` never shadows the state matrix in repr, plots or pandas; the columns are reached by
name through `sol.coords`; HTML reprs; LaTeX names as SymPy prints them."""

import numpy as np
import pytest

import pdyn


def test_a_coordinate_named_y_does_not_shadow_the_state_matrix(examples):
    sol = pdyn.Model.from_file(examples / "satellite.toml").run(t_end=1.0, points=11)
    # The satellite's state is x, y, x', y': four rows; its coordinate y is a column.
    assert sol.y.shape == (4, 11)
    assert "y: array of shape (4, 11)" in repr(sol)
    np.testing.assert_array_equal(sol.coords.y, sol.y[1])
    np.testing.assert_array_equal(sol.coords["y"], sol.column("y"))
    assert "x'" in sol.coords and "nope" not in sol.coords
    with pytest.raises(AttributeError):
        sol.coords.nope
    df = sol.to_pandas()
    assert list(df.columns[:5]) == ["t", "x", "y", "x'", "y'"] and len(df) == 11


def test_plot_draws_the_states_by_default(examples):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")  # a test: no display
    sol = pdyn.Model.from_file(examples / "satellite.toml").run(t_end=1.0, points=11)
    ax = sol.plot()
    assert [line.get_label() for line in ax.get_lines()] == ["x", "y", "x'", "y'"]
    np.testing.assert_array_equal(ax.get_lines()[1].get_ydata(), sol.y[1])


def test_html_repr_of_a_result(examples):
    sol = pdyn.Model.from_file(examples / "satellite.toml").run(t_end=1.0)
    page = sol._repr_html_()
    assert page.startswith("<table>") and "OdeResult" in page
    assert "4 states" in page and "energy" in page and "successfully" in page
    m = pdyn.Model.from_file(examples / "satellite.toml")
    assert "Satellite orbit" in m._repr_html_() and "GM" in m._repr_html_()


def test_latex_names_are_sympys(examples):
    d = pdyn.Model.from_file(examples / "pendulum_chain_2.toml").derive()
    latex = d._repr_latex_()
    assert "l_{1}" in latex and "\\mathrm{l1}" not in latex
    sympy = pytest.importorskip("sympy")
    assert sympy.latex(sympy.Symbol("l1")) == "l_{1}"
    assert sympy.latex(sympy.Symbol("theta1")) == "\\theta_{1}"


SHADOWED = """
name = "parameters named like SymPy's constants and keywords"
[parameters]
E = 2.0
I = 3.0
S = 5.0
N = 7.0
Q = 11.0
beta = 13.0
gamma = 17.0
zeta = 19.0
lambda = 23.0
m = 1.0
[coordinates]
x = { initial = 0.0, rate = 1.0 }
[particles.p]
mass = "m"
position = "[x, 0, 0]"
[[forces]]
kind = "applied"
on = "p"
force = "[-(E*I + S*N - Q*beta + gamma*zeta*lambda)*x, 0, 0]"
"""


def test_to_sympy_keeps_names_and_assumptions():
    sympy = pytest.importorskip("sympy")
    d = pdyn.Model.from_toml(SHADOWED).derive()
    acc = dict(d.solution)["x''"].to_sympy()
    names = {"E", "I", "S", "N", "Q", "beta", "gamma", "zeta", "lambda", "m", "x"}
    assert {s.name for s in acc.free_symbols} == names, acc.free_symbols
    # Symbols, never Euler's number, the imaginary unit, or SymPy's S/N/Q objects; the masses
    # declared positive by the model stay positive.
    sym = {s.name: s for s in acc.free_symbols}
    assert sym["m"].is_positive and sym["x"].is_positive is None
    values = {sym[k]: float(v) for k, v in
              dict(E=2, I=3, S=5, N=7, Q=11, beta=13, gamma=17, zeta=19, m=1, x=1).items()}
    values[sym["lambda"]] = 23.0
    # x'' = -(E I + S N - Q beta + gamma zeta lambda) x / m, evaluated independently.
    expected = -(2 * 3 + 5 * 7 - 11 * 13 + 17 * 19 * 23) * 1.0
    assert float(acc.subs(values)) == pytest.approx(expected, rel=1e-15)


def test_exprs_take_part_in_sympy_arithmetic(examples):
    sympy = pytest.importorskip("sympy")
    d = pdyn.Model.from_file(examples / "pendulum_chain_2.toml").derive()
    M = sympy.Matrix(d.mass_matrix)  # sympify through Expr._sympy_
    l1, l2, m1, m2 = sympy.symbols("l1 l2 m1 m2", positive=True)
    q1, q2 = sympy.symbols("q1 q2")
    expected = sympy.Matrix([[l1**2 * (m1 + m2), l1 * l2 * m2 * sympy.cos(q1 - q2)],
                             [l1 * l2 * m2 * sympy.cos(q1 - q2), l2**2 * m2]])
    assert sympy.simplify(M - expected) == sympy.zeros(2, 2)
    # Arithmetic and subs go through SymPy.
    e = d.mass_matrix[1][1]
    assert sympy.simplify((e + e) - 2 * l2**2 * m2) == 0
    assert e.subs({l2: 2, m2: 3}) == 12
    assert sympy.sympify(e) == l2**2 * m2


def test_the_builder_takes_what_sympy_writes():
    sympy = pytest.importorskip("sympy")
    from pdyn._sympy_text import to_pdyn_text
    x, y, c = sympy.symbols("x y c")
    q = sympy.Function("q")
    t = sympy.Symbol("t")
    # Each translation evaluated by pdyn must equal SymPy's value of the original.
    cases = [sympy.Abs(x - 3) * sympy.exp(1), sympy.E ** x, sympy.sqrt(y) / (x**2 + 1),
             sympy.Max(x, y, 2), sympy.Heaviside(x - 1),
             sympy.Piecewise((x**2, x > 1), (-y, x < -1), (c, True))]
    for e in cases:
        text = to_pdyn_text(e)
        for xv, yv, cv in [(2.5, 0.5, 7.0), (-2.0, 3.0, 1.5), (0.3, 1.0, -4.0)]:
            want = float(e.subs({x: xv, y: yv, c: cv}))
            m = pdyn.Model.from_toml(f"""
name = "probe"
[parameters]
x = {xv}
y = {yv}
c = {cv}
p = "{text}"
[coordinates]
z = {{ initial = 0.0, rate = 0.0 }}
[particles.a]
mass = 1.0
position = "[z, 0, 0]"
""")
            assert m.parameters["p"] == pytest.approx(want, rel=1e-14, abs=1e-14), (e, text)
    # Rates of dynamicsymbols-style coordinates and 3-vectors.
    assert to_pdyn_text(sympy.Derivative(q(t), t, 2)) == "q''"
    assert to_pdyn_text(sympy.Matrix([sympy.cos(q(t)), sympy.sin(q(t)), 0])) == \
        "[cos(q), sin(q), 0]"
    for bad in (sympy.I * x, sympy.oo, sympy.Piecewise((x, (x > 0) & (y > 0)), (y, True))):
        with pytest.raises(TypeError):
            to_pdyn_text(bad)


DUFFING = """
name = "damped Duffing oscillator: m x'' = -k x - c x' - eps x^3"
[parameters]
m = 2.0
k = 3.0
c = 0.5
eps = 0.7
[coordinates]
x = { initial = 0.4, rate = 0.0 }
[particles.p]
mass = "m"
position = "[x, 0, 0]"
[[forces]]
kind = "applied"
on = "p"
force = "[-k*x - c*x' - eps*x^3, 0, 0]"
"""


def test_linearize_matches_the_hand_derivation():
    m = pdyn.Model.from_toml(DUFFING)
    for x0 in (0.0, 0.4, -1.3):
        lin = m.linearize(op_point={"x": x0, "x'": 0.0})
        # d/dx of -(k x + eps x^3)/m is -(k + 3 eps x0^2)/m; d/dx' of -c x'/m is -c/m.
        K = (3.0 + 3 * 0.7 * x0**2) / 2.0
        C = 0.5 / 2.0
        np.testing.assert_allclose(lin.A, [[0.0, 1.0], [-K, -C]], rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(lin.K, [[K]], rtol=1e-13)
        np.testing.assert_allclose(lin.C, [[C]], rtol=1e-13)
        # f0: zero only at the equilibrium x0 = 0.
        assert abs(lin.f0[1] + (3.0 * x0 + 0.7 * x0**3) / 2.0) < 1e-14
    assert lin.state == ["x", "x'"]
    ev = m.linearize(op_point={"x": 0.0}).eigenvalues()
    # Damped oscillator roots: -C/2 ± i sqrt(K - C^2/4).
    assert np.allclose(sorted(ev.imag), [-np.sqrt(1.5 - 0.25**2 / 4), np.sqrt(1.5 - 0.25**2 / 4)])
    with pytest.raises(pdyn.ParameterError, match="not a state component"):
        m.linearize(op_point={"y": 1.0})
