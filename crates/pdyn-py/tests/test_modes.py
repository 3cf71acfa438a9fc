"""`Model.modes` (issue 33) against closed forms: the uniform chain
w_j = 2 sqrt(k/m) sin(j pi / (2 (n + 1))), dense and sparse, and the damping ratios of
mass-proportional drag."""

import math
from pathlib import Path

import numpy as np
import pytest

import pdyn

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def chain(n: int) -> pdyn.Model:
    text = (EXAMPLES / "chain_modes.toml").read_text().replace("n = 30", f"n = {n}", 1)
    return pdyn.Model.from_toml(text)


def closed_form(n: int, count: int) -> np.ndarray:
    j = np.arange(1, count + 1)
    return 2 * math.sqrt(100.0 / 1.0) * np.sin(j * math.pi / (2 * (n + 1)))


def test_dense_modes_of_the_thirty_mass_chain():
    m = chain(30).modes()
    assert m.solver == "dense" and len(m) == 30
    np.testing.assert_allclose(m.omega, closed_form(30, 30), rtol=1e-12)
    np.testing.assert_allclose(m.freq_hz, m.omega / (2 * math.pi), rtol=1e-15)
    np.testing.assert_allclose(m.period, 2 * math.pi / m.omega, rtol=1e-15)
    assert m.shapes.shape == (30, 30)
    # Mode 1 is sin(i pi / 31) along the chain (scaled to a largest component of 1).
    i = np.arange(1, 31)
    s = np.sin(i * math.pi / 31)
    np.testing.assert_allclose(m.shapes[:, 0], s / s.max(), atol=1e-10)
    # m = 1: modal mass = sum of the squared shape.
    np.testing.assert_allclose(m.modal_mass[0], np.sum((s / s.max()) ** 2), rtol=1e-10)
    assert m.damping_ratio is None


def test_effective_masses_of_the_chain_follow_the_closed_form():
    # Mode j of the fixed-fixed chain is sin(i j pi/(n+1)): its effective mass along x is
    # 2 cot^2(theta/2)/(n+1) for odd j (theta = j pi/(n+1)), 0 for even j; they add up to
    # the n unit masses, and nothing moves along y or z.
    n = 30
    m = chain(n).modes()
    assert m.effective_mass.shape == (n, 3) and m.participation.shape == (n, 3)
    np.testing.assert_allclose(m.total_mass, [n, 0, 0], atol=1e-9)
    j = np.arange(1, n + 1)
    half = j * math.pi / (2 * (n + 1))
    exact = np.where(j % 2 == 1, 2 / np.tan(half) ** 2 / (n + 1), 0.0)
    np.testing.assert_allclose(m.effective_mass[:, 0], exact, atol=1e-9)
    np.testing.assert_allclose(m.effective_mass.sum(axis=0), m.total_mass, atol=1e-9)
    np.testing.assert_allclose(m.participation[:, 0] ** 2 * m.modal_mass, m.effective_mass[:, 0], atol=1e-9)


def test_the_lowest_ten_of_a_thousand_mass_chain_by_the_sparse_solver():
    m = chain(1000).modes(count=10)
    assert m.solver == "sparse" and len(m) == 10
    assert m.shapes.shape == (1000, 10)
    np.testing.assert_allclose(m.omega, closed_form(1000, 10), rtol=1e-12)


def test_damping_ratios_of_the_net_with_drag():
    # Drag c on each particle of mass m: C = (c/m) M, so zeta * omega_n = c / (2 m) = 0.2.
    m = pdyn.Model.from_file(EXAMPLES / "hanging_net.toml").modes(count=6)
    np.testing.assert_allclose(m.damping_ratio * m.natural_frequency, 0.2, rtol=1e-9)
    np.testing.assert_allclose(m.natural_frequency, m.omega, rtol=1e-9)


def test_bad_arguments_are_value_errors():
    with pytest.raises(ValueError):
        chain(5).modes(count=0)
    with pytest.raises(ValueError):
        chain(5).modes(solver="qr")
