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
