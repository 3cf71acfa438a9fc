"""pdyn: analyse the motion of systems of particles from Python.

A model file (TOML) -> derived equations of motion -> integration with conservation checks,
the same engine as the ``pdyn`` command::

    import pdyn
    m = pdyn.Model.from_file("examples/projectile_drag.toml")
    sol = m.run(t_end=5.0)            # SciPy-shaped result: sol.t, sol.y (n_states, n_times)
    sol["z"], sol.columns, sol.monitors
    d = m.derive()                    # d.equations: [(label, lhs, rhs)] of pdyn.Expr
    sw = m.sweep("c", numpy.linspace(0.1, 1, 10), measures={"zmin": ("z", "min")})

    # SciPy's solve_ivp, with a compiled right-hand side (no Python in the loop):
    sol = pdyn.solve_ivp(["y1", "-y0"], (0, 10), [1.0, 0.0], method="DOP853")

Errors: :class:`ModelError` (with ``file``, ``line``, ``column``), :class:`ParameterError`,
both :class:`PdynError`; a drifting conserved quantity warns with :class:`DriftWarning`.
A numerical failure returns ``success=False`` with the partial solution, as SciPy does.

The symbolic commands: :func:`kin` (``pdyn kin``) and :func:`dsolve` (``pdyn dsolve``).
"""

from __future__ import annotations

import math
import os
import warnings
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from ._lazy import LazyModule

np = LazyModule("numpy")  # imported on first use

from . import _pdyn
from ._errors import DriftWarning, Interrupted, ModelError, ParameterError, PdynError
from ._nbody import NBody, Particle
from ._linearize import Linearization
from ._modes import Modes
from ._result import (Derivation, EnsembleResult, Expr, ForcesResult,
                      OdeResult, ParticleResult, SweepResult, Table,
                      _concat_raw, _from_run)
from ._symbolic import (DsolveCase, DsolveResult, KinInstant, KinResult, RuleResult, Vector,
                        dsolve, kin)
from ._ivp import solve_ivp  # SciPy's solve_ivp on pdyn's integrators
from ._data import (FuseResult, IntegratedAccel, KinDataResult, fuse, integrate_accel, interp,
                    kin_data, read_csv)

__version__ = _pdyn.__version__


def __getattr__(name: str):
    # pdyn.study (alias pdyn.ensemble) is imported on first use: `import pdyn` stays light.
    if name in ("study", "ensemble"):
        import importlib
        return importlib.import_module(".study", __name__)
    raise AttributeError(f"module 'pdyn' has no attribute {name!r}")

__all__ = [
    "Model", "NBody", "Particle", "Linearization", "Modes", "solve_ivp", "methods", "OdeResult", "Derivation", "Expr", "SweepResult",
    "EnsembleResult", "ForcesResult",
    "kin", "dsolve", "KinResult", "KinInstant", "DsolveResult", "DsolveCase", "RuleResult",
    "Vector",
    "kin_data", "integrate_accel", "fuse", "read_csv", "interp", "KinDataResult", "IntegratedAccel",
    "FuseResult",
    "PdynError", "ModelError", "ParameterError", "DriftWarning", "Interrupted", "__version__",
]


def _array1(x, name: str) -> np.ndarray:
    a = np.ascontiguousarray(np.asarray(x, dtype=np.float64).ravel())
    if a.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional")
    return a


class _Parameters(dict):
    """``Model.parameters``: a dict of the values, callable on a built model to set them."""

    def __init__(self, model: "Model", values: Dict[str, float]):
        super().__init__(values)
        self._model = model

    def __call__(self, **values: Any) -> None:
        self._model._edit().setdefault("parameters", {}).update(
            {k: _value(v) for k, v in values.items()})

    def _read_only(self, *args: Any, **kwargs: Any) -> None:
        # Assigning into a copy would change nothing and say nothing: refuse it.
        raise TypeError(
            "Model.parameters is a read-only view: pass params={'name': value} to run, sweep "
            "or ensemble (or call m.parameters(name=value) on a model built in code)")

    __setitem__ = __delitem__ = update = pop = popitem = clear = setdefault = _read_only


def _text(x: Any) -> str:
    """An expression as pdyn text: a string as is, a SymPy expression translated
    (:func:`pdyn._sympy_text.to_pdyn_text`: ``Abs``, ``E``, ``Derivative``, ``Piecewise``,
    3-vector matrices), a list of three as a vector."""
    if isinstance(x, str):
        return x
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(_text(e) for e in x) + "]"
    if isinstance(x, (int, float)) and not isinstance(x, bool):
        return repr(float(x))
    if hasattr(x, "free_symbols"):  # SymPy
        from ._sympy_text import to_pdyn_text
        return to_pdyn_text(x)
    raise TypeError(f"cannot use {x!r} as an expression (give a string or a SymPy expression)")


def _value(x: Any) -> Any:
    """A number stays a number; anything else becomes expression text."""
    if isinstance(x, (int, float)) and not isinstance(x, bool):
        return float(x)
    return _text(x)


def _field(x: Any) -> Any:
    if isinstance(x, (list, tuple)) and all(isinstance(e, str) for e in x):
        return list(x)
    if isinstance(x, (bool, dict)):
        return x
    return _value(x)


def _measures(measures):
    if measures is None:
        return None
    ms = []
    for name, spec in measures.items():
        if isinstance(spec, str):
            ms.append((str(name), spec, "max_abs"))
        else:
            of, stat = spec
            ms.append((str(name), str(of), str(stat)))
    return ms


def _params(params: Optional[Mapping[str, float]]):
    if params is None:
        return None
    return [(str(k), float(v)) for k, v in params.items()]


class Model:
    """A model (particles, coordinates, forces, ``[simulate]``...) loaded from TOML.

    Build it with :meth:`from_file`, :meth:`from_toml` or :meth:`from_dict`; a model that
    does not load raises :class:`ModelError` with the file, line and column.
    """

    __slots__ = ("_inner", "_spec")

    def __init__(self, name: Union[str, "_pdyn.Model"] = "model"):
        """``Model("pendulum")`` starts a model built in code (see :meth:`coordinate`,
        :meth:`particle`, :meth:`gravity`, :meth:`parameters`...); the class methods
        :meth:`from_file`, :meth:`from_toml` and :meth:`from_dict` load one."""
        if isinstance(name, str):
            self._inner = None
            self._spec: Optional[Dict[str, Any]] = {"name": name}
        else:
            self._inner = name
            self._spec = None

    @property
    def _m(self) -> "_pdyn.Model":
        # A built model is loaded (and checked, with its errors located in the generated
        # TOML) when first used; changing it again reloads it.
        if self._inner is None:
            self._inner = _pdyn.Model.from_dict(self._spec)
        return self._inner

    # -- the builder ------------------------------------------------------------------------

    def _edit(self) -> Dict[str, Any]:
        if self._spec is None:
            raise ParameterError("this model was loaded from a file or text; build one with "
                                 "pdyn.Model(name), or pass params= to run/sweep/ensemble")
        self._inner = None
        return self._spec

    def coordinate(self, name: str, initial: Any = 0.0, rate: Any = 0.0,
                   expr: Any = None) -> str:
        """Adds a generalized coordinate with its initial value and rate (numbers or
        expressions of the parameters), or, with ``expr``, a prescribed function of ``t``
        (``m.coordinate("d", expr="d0*sin(omega*t)")``). Returns the name."""
        table = self._edit().setdefault("coordinates", {})
        table[name] = _text(expr) if expr is not None else {
            "initial": _value(initial), "rate": _value(rate)}
        return name

    def particle(self, name: str, mass: Any, position: Any) -> str:
        """Adds a particle: ``mass`` (a number or expression), ``position`` (an expression
        of a 3-vector, ``"L*[sin(q), -cos(q), 0]"``, or a list of three expressions)."""
        self._edit().setdefault("particles", {})[name] = {
            "mass": _value(mass), "position": _text(position)}
        return name

    def point(self, name: str, position: Any) -> str:
        """Adds a named point (a fixed or moving position forces can attach to)."""
        self._edit().setdefault("points", {})[name] = _text(position)
        return name

    def gravity(self, g: Any) -> None:
        """Uniform gravity, a 3-vector: ``m.gravity("[0, -g, 0]")``."""
        self._edit()["gravity"] = _text(g)

    def force(self, kind: str, **fields: Any) -> None:
        """Adds a ``[[forces]]`` entry: ``m.force("spring", between=["a", "b"], k="k",
        l0="L")`` (fields as in docs/model-format.md; expressions as strings or SymPy)."""
        entry = {"kind": kind}
        entry.update({k: _field(v) for k, v in fields.items()})
        self._edit().setdefault("forces", []).append(entry)

    def event(self, name: str, when: Any, direction: str = "both",
              terminal: bool = False, set: Optional[Sequence[Any]] = None) -> None:
        """Adds an ``[[events]]`` entry: the zeros of ``when``; ``set``: assignments made when
        it fires (``["y' = -0.8*y'"]``: free coordinates, their rates, parameters)."""
        entry = {"name": name, "when": _text(when), "direction": direction,
                 "terminal": bool(terminal)}
        if set is not None:
            entry["set"] = [_text(a) for a in set]
        self._edit().setdefault("events", []).append(entry)

    def contact(self, name: str, **fields: Any) -> None:
        """Adds a ``[[contacts]]`` entry: ``m.contact("floor", on="ball", surface="r.y",
        e=0.8, mu_s=0.5, mu_k=0.4)`` (a particle against a surface, or ``between=["A",
        "B"]`` with ``distance``; fields as in docs/model-format.md)."""
        entry = {"name": name}
        entry.update({k: _field(v) for k, v in fields.items()})
        self._edit().setdefault("contacts", []).append(entry)

    def monitor(self, name: str, expr: Any) -> None:
        """Tabulates ``expr`` as a column of every run."""
        self._edit().setdefault("monitors", {})[name] = _text(expr)

    def simulate(self, **settings: Any) -> None:
        """The model's default run settings (``t_end``, ``method``, ``rtol``, ...)."""
        self._edit().setdefault("simulate", {}).update(settings)

    def to_toml(self) -> str:
        """The model as the text of a model file."""
        return self._m.source

    @classmethod
    def from_file(cls, path: Union[str, "os.PathLike[str]"]) -> "Model":
        """Loads a model file (TOML): a mechanics model (docs/model-format.md), an N-body
        model (an ``[nbody]`` table, docs/nbody.md) or a molecular-dynamics model (``[md]``,
        docs/md.md), as ``pdyn run`` reads them."""
        path = os.fspath(path)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        return cls(_pdyn.load_model(text, path))

    @classmethod
    def from_toml(cls, text: str, origin: str = "<string>") -> "Model":
        """Loads a model from TOML text (any kind, as :meth:`from_file`); ``origin`` names it
        in error messages."""
        return cls(_pdyn.load_model(text, origin))

    @property
    def kind(self) -> str:
        """``"mechanics"``, ``"nbody"`` or ``"md"``."""
        m = self._m
        return m.kind if isinstance(m, _pdyn.ParticleModel) else "mechanics"

    def _mechanics(self) -> "_pdyn.Model":
        # The commands for mechanics models only refuse an [nbody] or [md] model with the
        # CLI's located error (ModelError) saying that `run` runs it.
        m = self._m
        if isinstance(m, _pdyn.ParticleModel):
            m.refuse()
        return m

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Model":
        """Loads a model from a dict laid out as a model file
        (``{"parameters": {"g": 9.81}, "coordinates": {...}, ...}``)."""
        return cls(_pdyn.Model.from_dict(d))

    @property
    def name(self) -> str:
        """The model's name."""
        return self._m.name

    @property
    def source(self) -> str:
        """The TOML text the model was loaded from."""
        return self._m.source

    @property
    def parameters(self) -> "_Parameters":
        """Parameter values in SI units, in file order (read-only: assigning raises
        ``TypeError``; pass ``params=`` to :meth:`run` to change them). On a model built in code, calling it sets values:
        ``m.parameters(g=9.81, L=1, m=1)`` (numbers, or quantities with units as text)."""
        if self._spec is not None and self._inner is None and "parameters" not in self._spec:
            return _Parameters(self, {})
        return _Parameters(self, dict(self._m.parameters))

    def _repr_html_(self) -> str:
        import html
        if self._spec is not None and self._inner is None:
            return f"<b>pdyn.Model</b> {html.escape(repr(self._spec.get('name')))} (built in code)"
        params = ", ".join(f"{html.escape(k)} = {v:.6g}" for k, v in self.parameters.items())
        rows = [("kind", self.kind), ("file", html.escape(str(self._m.origin))),
                ("parameters", params or "none")]
        body = "".join(f"<tr><th style='text-align:left'>{k}</th><td style='text-align:left'>"
                       f"{v}</td></tr>" for k, v in rows)
        return (f"<table><caption style='text-align:left'><b>pdyn.Model</b> "
                f"{html.escape(self.name)}</caption>{body}</table>")

    def __repr__(self) -> str:
        if self._spec is not None and self._inner is None:
            return f"pdyn.Model({self._spec.get('name')!r}, built in code, not yet loaded)"
        return f"pdyn.Model({self.name!r}, origin={self._m.origin!r})"

    def run(self, t_end: Optional[float] = None, method: Optional[str] = None,
            rtol: Optional[float] = None, atol: Optional[float] = None,
            t_eval: Optional[Sequence[float]] = None, max_step: Optional[float] = None,
            dt: Optional[float] = None, max_steps: Optional[int] = None,
            points: Optional[int] = None, drift_tolerance: Optional[float] = None,
            params: Optional[Mapping[str, float]] = None,
            plots: Optional[Union[str, "os.PathLike[str]"]] = None,
            jit: bool = True, initial: Optional[Mapping[str, float]] = None,
            out: Optional[Union[str, "os.PathLike[str]"]] = None,
            restart: Optional[Union[str, "os.PathLike[str]"]] = None,
            checkpoint_every: Optional[str] = None) -> OdeResult:
        """Integrates the equations of motion, like ``pdyn run``.

        Every argument left ``None`` takes the model's ``[simulate]`` value, then pdyn's
        default (method ``auto``, rtol 1e-6, atol 1e-9). ``method``: SciPy's names
        (``"RK45"``, ``"DOP853"``, ``"Radau"``) or pdyn's (:func:`methods`). ``t_eval``:
        output times within [0, t_end]; ``points``: that many equally spaced outputs;
        ``dt``: the fixed step (symplectic methods, RK4) or the first step; ``params``:
        parameter values (checked like ``pdyn run --set``); ``plots``: a directory where
        pdyn's own PNG/SVG plots are written, as ``pdyn run --out DIR`` (no matplotlib
        needed; ``sol.plot()`` and ``sol.plot_trajectory()`` use matplotlib); ``initial``:
        initial values of state components by name (``{"x": 2.0, "x'": 0.5}``; the
        model's own for the others; checked against its constraints); ``jit``:
        the right-hand side as native code (Cranelift), ``False`` for the interpreter (the
        same results bit for bit).

        An ``[nbody]`` or ``[md]`` model runs on its own engine, as ``pdyn run`` runs it
        (``method``: ``whfast``, ``ias15``, ``leapfrog`` for N-body; ``dt``, ``t_end``,
        ``points``/``t_eval``, ``drift_tolerance``, ``params``; ``plots``: a directory for the
        files and plots ``pdyn run --out DIR --plot`` writes; ``out``: a directory for the
        files without plots, as ``pdyn run --out DIR``) and returns a :class:`ParticleResult`.
        Long runs (docs/long-runs.md): ``checkpoint_every`` (``"15min"``, ``"30s"``,
        ``"500steps"``, ``"off"``) writes ``out/checkpoint.json`` as ``pdyn run
        --checkpoint-every`` does (also when Ctrl-C stops the run), and ``restart`` (a
        checkpoint's path) continues that run bit for bit, appending to the files of ``out``
        as ``pdyn run --restart`` does (the same model, options and ``out``). With either,
        the rows go to the files as the run goes and an N-body result holds only the first
        and last output (the files hold every row); an MD result keeps its thermo records.

        Returns an :class:`OdeResult` (``success=False`` with the partial solution when the
        integration fails, or when an output column becomes NaN or infinite: ``status``
        -1, ``message`` naming the columns and the first time, ``non_finite`` the columns,
        as ``pdyn run`` exits 1 with a ``non_finite`` error). Warns :class:`DriftWarning`
        when a conserved quantity drifts
        more than ``drift_tolerance`` (relative, default 5e-3). The GIL is released while
        the integration runs.
        """
        m = self._m
        if isinstance(m, _pdyn.ParticleModel):
            if initial is not None:
                raise ParameterError(
                    f"initial= applies to mechanics models; a {m.kind} model's initial state is "
                    "its bodies or atoms in the file")
            return self._run_particles(m, t_end, method, rtol, atol, t_eval, max_step, dt,
                                       max_steps, points, drift_tolerance, params, plots, jit,
                                       out, restart, checkpoint_every)
        for name, given in (("out", out), ("restart", restart),
                            ("checkpoint_every", checkpoint_every)):
            if given is not None:
                raise ParameterError(
                    f"{name}= applies to [nbody] and [md] models (streamed files, checkpoints); "
                    "a mechanics model's files are written with plots=DIR")
        te = None if t_eval is None else _array1(t_eval, "t_eval")
        raw = self._m.run(t_end=t_end, method=method, rtol=rtol, atol=atol, t_eval=te,
                          max_step=max_step, dt=dt, max_steps=max_steps, points=points,
                          drift_tolerance=drift_tolerance, params=_params(params),
                          plots=None if plots is None else os.fspath(plots), jit=bool(jit),
                          initial=_params(initial))
        if raw.get("interrupted"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                partial = _from_run(raw, list(raw["event_names"]))
            _interrupted("Model.run", partial)
        return _from_run(raw, list(raw["event_names"]))

    def _run_particles(self, m: "_pdyn.ParticleModel", t_end, method, rtol, atol, t_eval,
                       max_step, dt, max_steps, points, drift_tolerance, params, plots,
                       jit, out=None, restart=None, checkpoint_every=None) -> ParticleResult:
        # Options with no meaning for the kind (rtol for WHFast, method for MD) are refused by
        # the library, by name, as `pdyn run` refuses them.
        te = None if t_eval is None else [float(x) for x in _array1(t_eval, "t_eval")]
        if out is not None and plots is not None and os.fspath(out) != os.fspath(plots):
            raise ParameterError("out= and plots= name two directories: give one (plots= "
                                 "writes the files and the plots, out= the files only)")
        directory = plots if plots is not None else out
        raw = m.run(t_end=t_end, method=method, dt=dt, points=points, t_eval=te,
                    drift_tolerance=drift_tolerance, params=_params(params),
                    out=None if directory is None else os.fspath(directory),
                    plots=plots is not None,
                    jit=bool(jit), rtol=rtol, atol=atol, max_step=max_step,
                    max_steps=max_steps,
                    checkpoint_every=None if checkpoint_every is None else str(checkpoint_every),
                    restart=None if restart is None else os.fspath(restart))
        if raw.get("interrupted"):
            _interrupted("Model.run", ParticleResult(raw))
        return ParticleResult(raw)

    def linearize(self, op_point: Optional[Mapping[str, float]] = None,
                  params: Optional[Mapping[str, float]] = None, t: float = 0.0) -> "Linearization":
        """The equations of motion linearized about a state, as PyDy's ``linearize`` (without
        inputs): ``δy' = A δy`` with ``A = ∂f/∂y`` at ``(t, y0)``; ``y0`` is the model's initial
        state with ``op_point`` (``{"x": 0.1, "x'": 0.0}``) on top. Returns a
        :class:`Linearization`: ``A``, and for the state ``(q, q')`` the second-order form
        ``δq'' + C δq' + K δq = 0`` (``K``, ``C``: the mass matrix divided out), ``f0`` (zero
        at an equilibrium), ``state``, ``analytic`` (``A`` from the compiled analytic
        Jacobian, else central differences)."""
        return Linearization(self._mechanics().linearize(at=_params(op_point),
                                                          params=_params(params), t=float(t)))

    def fit(self, data: Any, free: Sequence[str],
            params: Optional[Mapping[str, float]] = None,
            bounds: Optional[Mapping[str, Tuple[float, float]]] = None,
            sigma: Optional[Mapping[str, float]] = None, absolute_sigma: bool = False,
            rtol: float = 1e-10, atol: float = 1e-12, max_nfev: int = 200) -> "FitResult":
        """Parameters and initial values fitted to measured runs by least squares, like
        ``pdyn fit``: Levenberg–Marquardt within ``bounds`` (``{"c": (0, 1)}``), the Jacobian
        from the sensitivity equations derived from the model. ``data`` is one experiment or
        a list of them, each a CSV path or a mapping of arrays with ``"t"`` and columns named
        as the model's coordinates (``"x"``) or rates (``"x'"``), optionally ``"sigma_x"``;
        ``free`` names parameters, ``initial.x`` and ``rate.x`` (per experiment); ``params``
        sets parameter values (the starting values of the free ones); ``sigma`` a column's
        standard deviation. Returns a :class:`FitResult` (SciPy's ``least_squares`` fields
        plus ``stderr``, ``corr``, ``cov``, ``chi2``, ``dof``)."""
        import os
        from ._fit import FitResult
        items = data if isinstance(data, (list, tuple)) else [data]
        args = []
        for i, item in enumerate(items):
            if isinstance(item, (str, os.PathLike)):
                args.append((os.fspath(item), None))
            elif isinstance(item, Mapping):
                if "t" not in item:
                    raise ValueError(f"data[{i}]: no array named 't' (the time)")
                cols = [(str(k), [float(v) for v in item[k]]) for k in item if k != "t"]
                args.append((f"data[{i}]", ([float(v) for v in item["t"]], cols)))
            else:
                raise TypeError(f"data[{i}]: expected a CSV path or a mapping of arrays, "
                                f"got {type(item).__name__}")
        if isinstance(free, str):
            free = [f.strip() for f in free.split(",")]
        raw = self._mechanics().fit(
            args, list(free), params=_params(params),
            bounds=[(k, float(lo), float(hi)) for k, (lo, hi) in (bounds or {}).items()],
            sigma=[(k, float(v)) for k, v in (sigma or {}).items()],
            absolute_sigma=bool(absolute_sigma), rtol=float(rtol), atol=float(atol),
            max_nfev=int(max_nfev))
        return FitResult(raw)

    def modes(self, count: Optional[int] = None, about: str = "equilibrium",
              solver: str = "auto", params: Optional[Mapping[str, float]] = None) -> Modes:
        """Natural frequencies and mode shapes, like ``pdyn modes``: the model linearized
        about its static equilibrium (``about="equilibrium"``, found by Newton's method) or its
        initial state at rest (``"initial"``), ``K φ = ω² M φ`` solved densely for every mode
        (``solver="dense"``) or for the lowest ``count`` (default 20) by sparse shift-invert
        Lanczos (``"sparse"``); ``"auto"`` is dense below 300 coordinates. Returns
        :class:`Modes` (NumPy arrays: ``omega``, ``freq_hz``, ``period``, ``shapes``,
        ``modal_mass``...; damping ratios when the model has damping)."""
        return Modes(self._mechanics().modes(count=count, about=about, solver=solver,
                                             params=_params(params)))

    def derive(self) -> Derivation:
        """The equations of motion (F = ma or the projected form), the unknowns, their exact
        solution when the system is small, and the first-order system."""
        return Derivation(self._mechanics().derive())

    def forces(self, at: Optional[Mapping[str, float]] = None,
               params: Optional[Mapping[str, float]] = None) -> ForcesResult:
        """The unknown forces (reactions, friction, ...) of a prescribed motion at an instant,
        like ``pdyn forces``: ``at`` sets ``t`` and coordinates (``{"theta": 0.3}``; default:
        the initial values), ``params`` parameter values. Returns a :class:`ForcesResult`:
        the equations, the unknowns, their exact solution (``symbolic``) and values
        (``values``: one dict per real solution), and the ``[[checks]]`` (critical values
        of a parameter, e.g. the speeds at which a car skids)."""
        raw = self._mechanics().forces(at=_params(at), params=_params(params))
        return ForcesResult(raw)

    def sweep(self, param: str, values: Sequence[float],
              measures: Optional[Mapping[str, Union[str, Tuple[str, str]]]] = None,
              t_end: Optional[float] = None, method: Optional[str] = None,
              rtol: Optional[float] = None, atol: Optional[float] = None,
              max_step: Optional[float] = None, dt: Optional[float] = None,
              points: Optional[int] = None, threads: Optional[int] = None,
              params: Optional[Mapping[str, float]] = None, jit: bool = True) -> SweepResult:
        """Runs the model once per value of parameter ``param``, in parallel on all cores
        (``threads`` to limit), with the GIL released, like ``pdyn sweep``.

        ``measures``: ``{name: (expression, statistic)}`` (statistic: max, min, max_abs,
        peak_to_peak, final, mean, rms; a bare expression means ``max_abs``), or ``None``
        for the model's ``[sweep.measures]``. Returns a :class:`SweepResult` with one
        float64 array per measure (NaN where a run failed; see ``problems``). The right-hand
        side, output columns and measures run as native code (``jit=False``: the
        interpreter; the same results).
        """
        ms = _measures(measures)
        raw = self._mechanics().sweep(str(param), _array1(values, "values"), measures=ms, t_end=t_end,
                            method=method, rtol=rtol, atol=atol, max_step=max_step, dt=dt,
                            points=points, threads=threads, params=_params(params),
                            jit=bool(jit))
        res = SweepResult(
            parameter=raw["parameter"], values=raw["values"], measures=dict(raw["measures"]),
            problems=list(raw["problems"]), runs=raw["runs"], seconds=raw["seconds"],
            threads=raw["threads"],
        )
        if raw.get("interrupted"):
            _interrupted("Model.sweep", res)
        return res


    def _names(self) -> Tuple[List[str], List[str]]:
        """(parameter names, state names) in model order."""
        raw = self._mechanics().ensemble([], np.empty((0, 0)), [], dry_run=True)
        return list(self.parameters), list(raw["state_names"])

    def check_ensemble(self, params: Any = None, initial: Any = None) -> List[Tuple[int, str]]:
        """Checks an ensemble's rows without running anything: unknown names raise
        :class:`ParameterError`; returns ``[(row, message)]`` for the rows whose parameter
        values the model refuses (a mass <= 0, a value that is not finite)."""
        pn, pm, sn, sm = self._ensemble_inputs(params, initial)
        raw = self._mechanics().ensemble(pn, pm, sn, sm, dry_run=True)
        return [(int(r), m) for r, m in raw["problems"]]

    def _ensemble_inputs(self, params: Any, initial: Any):
        def columns(x, what, default_names):
            if x is None:
                return [], None
            if hasattr(x, "columns") and hasattr(x, "to_numpy"):  # a pandas DataFrame
                names = [str(c) for c in x.columns]
                return names, np.ascontiguousarray(x.to_numpy(dtype=np.float64))
            if isinstance(x, Mapping):
                names = [str(k) for k in x]
                cols = [np.asarray(v, dtype=np.float64).ravel() for v in x.values()]
                if len({len(c) for c in cols}) > 1:
                    raise ParameterError(f"{what}: the columns have different lengths "
                                         f"{[len(c) for c in cols]}")
                if not cols:
                    return [], None
                return names, np.ascontiguousarray(np.column_stack(cols))
            a = np.asarray(x, dtype=np.float64)
            if a.ndim != 2:
                raise ParameterError(f"{what} must be a dict of columns, a DataFrame, or a "
                                     f"2-D array (runs, columns); got shape {a.shape}")
            names = default_names()
            if a.shape[1] != len(names):
                raise ParameterError(f"{what} has {a.shape[1]} columns; a bare 2-D array needs "
                                     f"one per name, in order: {names}")
            return names, np.ascontiguousarray(a)

        pn, pm = columns(params, "params", lambda: self._names()[0])
        sn, sm = columns(initial, "initial", lambda: self._names()[1])
        if pm is None and sm is None:
            raise ParameterError("an ensemble needs params or initial (one row per run)")
        if pm is None:
            pm = np.empty((sm.shape[0], 0))
        if sm is not None and sm.shape[0] != pm.shape[0]:
            raise ParameterError(f"params has {pm.shape[0]} rows and initial {sm.shape[0]}: "
                                 "one row per run in both")
        return pn, pm, sn, sm

    def ensemble(self, params: Any = None, initial: Any = None,
                 measures: Optional[Mapping[str, Union[str, Tuple[str, str]]]] = None,
                 t_end: Optional[float] = None, method: Optional[str] = None,
                 rtol: Optional[float] = None, atol: Optional[float] = None,
                 max_step: Optional[float] = None, dt: Optional[float] = None,
                 points: Optional[int] = None, drift_tolerance: Optional[float] = None,
                 threads: Optional[int] = None, progress: bool = False,
                 jit: bool = True) -> EnsembleResult:
        """Runs the model once per parameter set (and initial state), in parallel on all
        cores in Rust with the GIL released; returns one array per quantity.

        ``params``: ``{name: values}`` (equal lengths), a pandas DataFrame, or a 2-D array
        ``(runs, n_parameters)`` in the order of :attr:`parameters`; parameters not given
        keep their value. ``initial``: the same for state components (``"x"``, ``"x'"``...;
        a bare 2-D array is ``(runs, n_states)`` in the state order); components not given
        take the model's initial conditions evaluated with the run's parameters.
        ``measures``: as in :meth:`sweep` (``None``: the model's ``[sweep.measures]``, if any).
        Every run also records its final state, the first occurrence of each event (time and
        state), the drift of each conserved quantity, and its status.

        A run that fails is not an exception: its ``status`` is -1 (or -2 when it could not
        start, e.g. a mass <= 0) and ``problems`` says why. ``progress=True`` shows a tqdm
        bar (when tqdm is installed; the runs are then done in slices). ``jit=False``: the
        interpreter instead of native code (the same results).
        """
        pn, pm, sn, sm = self._ensemble_inputs(params, initial)
        ms = _measures(measures)
        kw = dict(measures=ms, t_end=t_end, method=method, rtol=rtol, atol=atol,
                  max_step=max_step, dt=dt, points=points, drift_tolerance=drift_tolerance,
                  threads=threads, jit=bool(jit))
        runs = pm.shape[0]
        bar = None
        if progress:
            try:
                from tqdm.auto import tqdm
                bar = tqdm(total=runs, unit="run")
            except ImportError:
                bar = None
        if bar is None:
            raw = self._mechanics().ensemble(pn, pm, sn, sm, **kw)
        else:
            parts = []
            step = max(1, -(-runs // 20))
            for a in range(0, runs, step):
                b = min(runs, a + step)
                parts.append(self._mechanics().ensemble(pn, np.ascontiguousarray(pm[a:b]), sn,
                                              None if sm is None else
                                              np.ascontiguousarray(sm[a:b]), **kw))
                bar.update(b - a)
                if parts[-1].get("interrupted"):
                    break
            bar.close()
            raw = _concat_raw(parts)
            raw["interrupted"] = any(p.get("interrupted") for p in parts)
            # Slices after an interrupted one never ran: the result holds the runs that did.
            done = len(raw["status"])
            pm = pm[:done]
            sm = None if sm is None else sm[:done]
        res = EnsembleResult(
            raw,
            {n: np.ascontiguousarray(pm[:, j]) for j, n in enumerate(pn)},
            {} if sm is None else {n: np.ascontiguousarray(sm[:, j]) for j, n in enumerate(sn)},
        )
        if raw.get("interrupted"):
            _interrupted("Model.ensemble", res)
        return res

def _interrupted(call: str, partial: Any) -> None:
    raise Interrupted(f"{call} interrupted (Ctrl-C); what was computed is in .result", partial)


def methods() -> Dict[str, str]:
    """pdyn's integration methods: name -> description (order, adaptivity, paper)."""
    return dict(_pdyn.methods())


from ._optimize import OptimizeResult, optimize as _model_optimize  # noqa: E402 (issue 26)
Model.optimize = _model_optimize  # type: ignore[attr-defined]
