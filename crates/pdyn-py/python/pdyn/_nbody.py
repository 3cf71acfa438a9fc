"""``pdyn.NBody``: an N-body system built in code, as REBOUND users build theirs.

The builder writes the ``[nbody]`` model a file would hold (every float as its exact
``repr``) and runs it on the same engine, through the same library entry as ``pdyn run`` and
:meth:`pdyn.Model.run`: a system built here and the same system in a file give the same
numbers, bit for bit (``crates/pdyn-py/tests/test_nbody_builder.py`` checks the outer Solar
System against ``examples/nbody/outer_solar_system.toml``).
"""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional

from ._errors import ParameterError
from ._lazy import LazyModule

np = LazyModule("numpy")

_CARTESIAN = ("x", "y", "z", "vx", "vy", "vz")
_ELEMENTS = ("a", "e", "inc", "Omega", "omega", "f", "M")
# The [nbody] keys a simulation takes (docs/nbody.md), with their Python types.
_OPTIONS = {"units": str, "G": float, "integrator": str, "dt": float, "corrector": int,
            "epsilon": float, "gravity": str, "theta": float, "quadrupole": bool,
            "softening": float, "drift_tolerance": float, "collisions": str,
            "escape_radius": float, "escape": str, "center_of_mass": bool}


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ParameterError(f"{v} is not a finite number")
        return repr(v)  # round-trips exactly
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise ParameterError(f"cannot write {v!r} into a model")


class Particle:
    """One body of an :class:`NBody` (REBOUND's ``sim.particles[i]``): ``name``, ``m``,
    ``x, y, z, vx, vy, vz`` (the state at :attr:`NBody.t`, inertial frame), ``r``."""

    __slots__ = ("name", "m", "r", "x", "y", "z", "vx", "vy", "vz")

    def __init__(self, name: str, m: float, r: float, state):
        self.name, self.m, self.r = name, m, r
        self.x, self.y, self.z, self.vx, self.vy, self.vz = (float(s) for s in state)

    def __repr__(self) -> str:
        return (f"Particle({self.name!r}, m={self.m!r}, x={self.x!r}, y={self.y!r}, "
                f"z={self.z!r}, vx={self.vx!r}, vy={self.vy!r}, vz={self.vz!r})")


class NBody:
    """An N-body simulation built in code, run on pdyn's N-body engine.

    ``NBody(units="au-day-msun", integrator="whfast", dt=4332.59/20, corrector=11)``: the
    keys of an ``[nbody]`` table (``units`` or ``G``, ``integrator``, ``dt``, ``corrector``,
    ``epsilon``, ``gravity``, ``softening``, ``collisions``, ...; docs/nbody.md).
    :meth:`add` adds a body (Cartesian or orbital elements about a primary);
    :meth:`integrate` runs to a time and keeps the state there; :attr:`particles`,
    :attr:`positions`, :attr:`velocities`, :attr:`masses` read it; :meth:`energy`.
    """

    def __init__(self, name: str = "N-body system built in Python", **options: Any):
        unknown = sorted(set(options) - set(_OPTIONS))
        if unknown:
            raise ParameterError(f"unknown option {unknown[0]!r} (options: "
                                 f"{', '.join(sorted(_OPTIONS))})")
        self.name = name
        self._options = {k: _OPTIONS[k](v) for k, v in options.items()}
        self._bodies: List[Dict[str, Any]] = []
        self.t = 0.0
        self.last: Optional[Any] = None  # the ParticleResult of the last integrate

    def add(self, m: float, name: Optional[str] = None, r: float = 0.0,
            primary: Optional[str] = None, **coords: float) -> None:
        """Adds a body of mass ``m`` (> 0), by its Cartesian state ``x, y, z, vx, vy, vz``
        (missing components 0) or its orbital elements ``a, e, inc, Omega, omega`` and ``f``
        or ``M`` about ``primary`` (a body added before; default: Jacobi elements about the
        centre of mass of the bodies before it, as REBOUND). ``r``: collision radius."""
        if self.t != 0.0:
            raise ParameterError("add bodies before integrating (the system is at "
                                 f"t = {self.t})")
        cart = {k: v for k, v in coords.items() if k in _CARTESIAN}
        elem = {k: v for k, v in coords.items() if k in _ELEMENTS}
        other = sorted(set(coords) - set(cart) - set(elem))
        if other:
            raise ParameterError(f"add: unknown argument {other[0]!r} (Cartesian: "
                                 f"{', '.join(_CARTESIAN)}; elements: {', '.join(_ELEMENTS)})")
        if cart and (elem or primary is not None):
            raise ParameterError("add: give either a Cartesian state or orbital elements")
        if elem and not self._bodies:
            raise ParameterError("add: the first body has no primary for its elements: "
                                 "give it a Cartesian state")
        body: Dict[str, Any] = {"name": name or f"body{len(self._bodies)}", "mass": float(m)}
        if r:
            body["radius"] = float(r)
        if elem or primary is not None:
            if primary is not None:
                body["primary"] = str(primary)
            body.update({k: float(v) for k, v in elem.items()})
        else:
            body["position"] = [float(cart.get(k, 0.0)) for k in ("x", "y", "z")]
            body["velocity"] = [float(cart.get(k, 0.0)) for k in ("vx", "vy", "vz")]
        self._bodies.append(body)

    def to_toml(self, t_end: float, output: Dict[str, Any]) -> str:
        """The ``[nbody]`` model file this system is, run to ``t_end``."""
        if not self._bodies:
            raise ParameterError("the system has no bodies: add some with NBody.add")
        lines = [f"name = {_toml_value(self.name)}", "", "[nbody]"]
        for k, v in {**self._options, "t_end": float(t_end), **output,
                     "trajectory": True}.items():
            lines.append(f"{k} = {_toml_value(v)}")
        for b in self._bodies:
            lines += ["", "[[nbody.bodies]]"] + [f"{k} = {_toml_value(v)}" for k, v in b.items()]
        return "\n".join(lines) + "\n"

    def integrate(self, t: float, points: Optional[int] = None,
                  output_dt: Optional[float] = None) -> Any:
        """Runs from :attr:`t` to ``t`` and keeps the state there; returns the run's
        :class:`ParticleResult` (outputs: ``points`` equally spaced, or every ``output_dt``;
        default the two ends). A second call continues from the state reached (rebuilt from
        it: WHFast restarts its Jacobi and corrector state there, so a run made in two calls
        agrees with one call to round-off, not bit for bit)."""
        from . import Model
        span = float(t) - self.t
        if not span > 0:
            raise ParameterError(f"integrate: t = {t} is not after the current time {self.t}")
        if points is not None and output_dt is not None:
            raise ParameterError("integrate: give points or output_dt, not both")
        output = ({"output_dt": float(output_dt)} if output_dt is not None
                  else {"points": int(points) if points is not None else 2})
        text = self.to_toml(span, output)
        res = Model.from_toml(text, origin=f"<NBody {self.name!r}>").run()
        if self.t != 0.0:
            res.t = res.t + self.t
        self.last = res
        self.t = float(t)
        self._take_final_state(res)
        return res

    def _take_final_state(self, res: Any) -> None:
        tr = res.trajectory
        last = tr["t"] == tr["t"][-1]
        bodies = []
        for row in tr.data[last]:
            i = int(row[1])
            old = next((b for b in self._bodies if b["name"] == res.names[i]), {})
            body = {"name": res.names[i], "mass": float(row[2])}
            if old.get("radius"):
                body["radius"] = old["radius"]
            body["position"] = [float(v) for v in row[3:6]]
            body["velocity"] = [float(v) for v in row[6:9]]
            bodies.append(body)
        self._bodies = bodies

    def _state(self) -> List[Dict[str, Any]]:
        if any("position" not in b for b in self._bodies):
            raise ParameterError("the state of bodies given by orbital elements is known after "
                                 "integrate (pdyn converts the elements when it builds the run)")
        return self._bodies

    @property
    def particles(self) -> List[Particle]:
        """The bodies at :attr:`t` (copies: change the system with :meth:`add`)."""
        return [Particle(b["name"], b["mass"], b.get("radius", 0.0),
                         b["position"] + b["velocity"]) for b in self._state()]

    @property
    def positions(self) -> Any:
        """``(N, 3)`` float64 array of positions at :attr:`t`."""
        return np.array([b["position"] for b in self._state()], dtype=np.float64)

    @property
    def velocities(self) -> Any:
        """``(N, 3)`` float64 array of velocities at :attr:`t`."""
        return np.array([b["velocity"] for b in self._state()], dtype=np.float64)

    @property
    def masses(self) -> Any:
        """``(N,)`` float64 array of masses."""
        return np.array([b["mass"] for b in self._bodies], dtype=np.float64)

    def energy(self) -> float:
        """The total energy at :attr:`t` as the last run reported it (its conservation
        table's final value)."""
        if self.last is None:
            raise ParameterError("energy: integrate first (the energy is the engine's, in the "
                                 "run's units and frame)")
        return float(self.last.conservation["energy"][-1])

    def __repr__(self) -> str:
        return f"NBody({self.name!r}, {len(self._bodies)} bodies, t = {self.t})"
