"""pdyn.NBody: an N-body system built in code, as REBOUND users build theirs (issue 30, item
6), on the engine the [nbody] files use, with the same numbers bit for bit."""

import math

import numpy as np
import pytest

import pdyn

# The outer Solar System of examples/nbody/outer_solar_system.toml: REBOUND's
# examples/outer_solar_system data (Applegate et al. 1986), AU, days, solar masses.
BODIES = [
    ("Sun", 1.00000597682, (-4.06428567034226e-3, -6.08813756435987e-3, -1.66162304225834e-6),
     (6.69048890636161e-6, -6.33922479583593e-6, -3.13202145590767e-9)),
    ("Jupiter", 1 / 1047.355, (3.40546614227466e+0, 3.62978190075864e+0, 3.42386261766577e-2),
     (-5.59797969310664e-3, 5.51815399480116e-3, -2.66711392865591e-6)),
    ("Saturn", 1 / 3501.6, (6.60801554403466e+0, 6.38084674585064e+0, -1.36145963724542e-1),
     (-4.17354020307064e-3, 3.99723751748116e-3, 1.67206320571441e-5)),
    ("Uranus", 1 / 22869, (1.11636331405597e+1, 1.60373479057256e+1, 3.61783279369958e-1),
     (-3.25884806151064e-3, 2.06438412905916e-3, -2.17699042180559e-5)),
    ("Neptune", 1 / 19314, (-3.01777243405203e+1, 1.91155314998064e+0, -1.53887595621042e-1),
     (-2.17471785045538e-4, -3.11361111025884e-3, 3.58344705491441e-5)),
]


def test_the_outer_solar_system_in_code_is_the_example_file_bit_for_bit(examples):
    year, P_J = 365.25, 4332.59
    sim = pdyn.NBody("outer", units="au-day-msun", integrator="whfast", dt=P_J / 20,
                     corrector=11)
    for name, m, (x, y, z), (vx, vy, vz) in BODIES:
        sim.add(m=m, name=name, x=x, y=y, z=z, vx=vx, vy=vy, vz=vz)
    t_end = 100 * year
    res = sim.integrate(t_end, output_dt=P_J / 10)
    ref = pdyn.Model.from_file(examples / "nbody" / "outer_solar_system.toml").run(t_end=t_end)
    np.testing.assert_array_equal(res.trajectory.data, ref.trajectory.data)
    np.testing.assert_array_equal(res.conservation.data, ref.conservation.data)
    assert sim.t == t_end and sim.energy() == ref.conservation["energy"][-1]
    final = ref.trajectory.data[ref.trajectory["t"] == ref.t[-1]]
    np.testing.assert_array_equal(sim.positions, final[:, 3:6])
    np.testing.assert_array_equal(sim.velocities, final[:, 6:9])
    assert [p.name for p in sim.particles] == [b[0] for b in BODIES]
    assert sim.particles[1].x == final[1, 3]


def test_elements_and_a_continued_run():
    # A test particle on a circular orbit of a = 1 about a unit mass (G = 1): period 2 pi.
    # After one period it is back where it started; two calls agree with one to round-off.
    def system():
        sim = pdyn.NBody(integrator="ias15")
        sim.add(m=1.0, name="star")
        sim.add(m=1e-12, a=1.0, e=0.0, primary="star", name="p")
        return sim
    one = system()
    one.integrate(2 * math.pi)
    p = one.particles[1]
    star = one.particles[0]
    assert math.hypot(p.x - star.x, p.y - star.y) == pytest.approx(1.0, abs=1e-12)
    assert p.x - star.x == pytest.approx(1.0, abs=1e-9) and abs(p.y - star.y) < 1e-9
    two = system()
    two.integrate(math.pi)
    two.integrate(2 * math.pi)
    np.testing.assert_allclose(two.positions, one.positions, rtol=0, atol=1e-12)


def test_builder_refuses_what_it_cannot_run():
    with pytest.raises(pdyn.ParameterError, match="unknown option"):
        pdyn.NBody(intgrator="whfast")
    sim = pdyn.NBody()
    with pytest.raises(pdyn.ParameterError, match="no primary"):
        sim.add(m=1.0, a=1.0)
    sim.add(m=1.0)
    with pytest.raises(pdyn.ParameterError, match="either a Cartesian state or orbital"):
        sim.add(m=1.0, x=1.0, a=2.0)
    with pytest.raises(pdyn.ParameterError, match="unknown argument"):
        sim.add(m=1.0, q=2.0)
    sim.add(m=-1.0, x=1.0)
    with pytest.raises(pdyn.ModelError, match="mass"):
        sim.integrate(1.0)
