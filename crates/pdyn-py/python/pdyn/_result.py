"""Result objects: :class:`OdeResult` (SciPy's shape), :class:`Derivation`, :class:`Expr`,
:class:`SweepResult`."""

from __future__ import annotations

import json
import warnings
from typing import Any, Dict, List, Optional, Tuple

from ._lazy import LazyModule

np = LazyModule("numpy")  # imported on first use

from ._errors import DriftWarning


class OdeResult(dict):
    """The result of :meth:`pdyn.Model.run` or :func:`pdyn.solve_ivp`, shaped like SciPy's.

    Attributes (also available as ``sol["name"]`` for SciPy's own fields):

    * ``t`` -- output times, 1-D float64 array of length ``n_times``;
    * ``y`` -- states, 2-D float64 array of shape ``(n_states, n_times)`` (a transposed view
      of the one table the run produced: the trajectory is copied once, from the solver);
    * ``t_events``, ``y_events`` -- one array per event (``None`` without events);
    * ``status`` (0 end reached, 1 terminal event, -1 integration failed), ``message``,
      ``success``;
    * ``nfev``, ``njev``, ``nlu`` -- the Rust solver's counts; ``stats`` has all of them;
    * pdyn's: ``columns`` (every tabulated column of a model run), ``sol.coords`` (every
      column by name: ``sol.coords.x``, ``sol.coords["y"]``; never shadowed), ``sol["x"]``
      (a column by name; a model's columns take precedence over SciPy's keys, so
      ``sol["y"]`` is a coordinate ``y`` when there is one, ``sol.y`` always the states),
      :meth:`column`,
      ``monitors`` (conserved quantities with their drift), ``warnings``,
      ``method``, :meth:`to_pandas`;
    * for a model with contacts or event actions, ``hybrid``: a dict with ``timeline`` (intervals
      of constant contact modes: ``t_from``, ``t_to``, ``modes``), ``switches`` (``t``,
      ``contact``, ``from``, ``to``, ``reason``), ``impacts`` (``t``, ``contact``,
      ``normal_speed_before``, ``normal_speed_after``, ``impulse``, ``energy_lost``), ``zeno``
      (``contact``, ``t_accumulation``, ``ratio``, ``bounces``), ``actions``, and the energy
      accounting ``work_contacts``, ``dissipated_friction``, ``dissipated_impacts``
      (``None`` for other models).
    """

    def __getattr__(self, name: str) -> Any:
        try:
            return dict.__getitem__(self, name)
        except KeyError as e:
            raise AttributeError(name) from e

    def __getitem__(self, key: str) -> Any:
        # A model's columns come first: sol["y"] is the coordinate y when the model has one
        # (sol.y is always SciPy's state matrix).
        cols = dict.get(self, "columns")
        table = dict.get(self, "_table")
        if cols is not None and table is not None and key in cols:
            return self.column(key)
        return dict.__getitem__(self, key)

    def column(self, name: str) -> np.ndarray:
        """The tabulated column ``name`` (see ``columns``) as a float64 array."""
        cols = dict.get(self, "columns")
        if cols is None or name not in cols:
            raise KeyError(f"no column {name!r} (columns: {cols})")
        return np.ascontiguousarray(dict.__getitem__(self, "_table")[:, cols.index(name)])

    @property
    def coords(self) -> "_Columns":
        """Every tabulated column by name, as attributes or items (``sol.coords.y``,
        ``sol.coords["x'"]``): a coordinate named like one of SciPy's fields (``y``, ``t``)
        is reached here without ambiguity."""
        return _Columns(self)

    def __dir__(self):
        return list(self.keys()) + list(super().__dir__())

    def _field(self, name: str) -> Any:
        # SciPy's field, never a column of the same name.
        return dict.__getitem__(self, name)

    def __repr__(self) -> str:
        shown = ["message", "success", "status", "nfev", "njev", "nlu", "method"]
        parts = [f"{k}: {dict.get(self, k)!r}" for k in shown if k in self]
        parts.append(f"t: array of {len(self._field('t'))} times")
        parts.append(f"y: array of shape {self._field('y').shape}")
        return "OdeResult(" + ", ".join(parts) + ")"

    def _repr_html_(self) -> str:
        import html
        t, y = self._field("t"), self._field("y")
        ok = dict.get(self, "success")
        rows = [("status", f"{'✓' if ok else '✗'} {html.escape(str(dict.get(self, 'message')))}"),
                ("method", html.escape(str(dict.get(self, "method")))),
                ("t", f"{len(t)} times, {t[0]:.6g} … {t[-1]:.6g}" if len(t) else "no times"),
                ("y", f"{y.shape[0]} states × {y.shape[1]} times"),
                ("evaluations", f"nfev {dict.get(self, 'nfev')}, njev {dict.get(self, 'njev')}, "
                                f"nlu {dict.get(self, 'nlu')}")]
        cols = dict.get(self, "columns")
        if cols and len(t):
            last = dict.__getitem__(self, "_table")[-1]
            final = ", ".join(f"{html.escape(c)} = {v:.6g}" for c, v in zip(cols[1:9], last[1:9]))
            rows.append(("final", final + (" …" if len(cols) > 9 else "")))
        for m in dict.get(self, "monitors") or []:
            if m["conserved"]:
                rows.append((html.escape(m["name"]), f"drift {m['drift']:.3e}"))
        for w in dict.get(self, "warnings") or []:
            rows.append(("warning", f"<span style='color:#b00'>{html.escape(w)}</span>"))
        body = "".join(f"<tr><th style='text-align:left'>{k}</th><td style='text-align:left'>"
                       f"{v}</td></tr>" for k, v in rows)
        return f"<table><caption style='text-align:left'><b>OdeResult</b></caption>{body}</table>"

    def to_pandas(self):
        """Every column (``t``, the states, positions, monitors...) as a pandas DataFrame;
        raises ImportError when pandas is not installed."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("OdeResult.to_pandas() needs pandas: pip install pandas") from e
        cols = self.get("columns")
        if cols is None:
            y = self._field("y")
            cols = ["t"] + [f"y{k}" for k in range(y.shape[0])]
            data = np.column_stack([self._field("t"), y.T])
        else:
            data = self["_table"]
        return pd.DataFrame(data, columns=list(cols))


def _plot_axes(ax):
    if ax is None:
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:
            raise ImportError("plot() needs matplotlib: pip install matplotlib (or run a model "
                              "with plots=DIR for pdyn's own PNG/SVG plots)") from e
        _, ax = plt.subplots()
    return ax


def _plot(self, *names: str, ax=None):
    """Plots columns against ``t`` (default: the states) with matplotlib; returns the axes."""
    ax = _plot_axes(ax)
    cols = self.get("columns")
    y = self._field("y")
    if not names:
        names = tuple(cols[1:1 + y.shape[0]]) if cols else tuple(
            f"y{k}" for k in range(y.shape[0]))
    for name in names:
        if cols and name in cols:
            data = self.column(name)
        else:
            data = y[int(name[1:])]
        ax.plot(self._field("t"), data, label=name)
    ax.set_xlabel("t")
    ax.legend()
    return ax


def _plot_trajectory(self, x: str = None, y: str = None, ax=None):
    """Plots column ``y`` against column ``x`` (default: the first two coordinates, or
    ``y0``, ``y1``) with matplotlib, equal aspect; returns the axes."""
    ax = _plot_axes(ax)
    cols = self.get("columns")
    if x is None or y is None:
        x, y = (cols[1], cols[2]) if cols and len(cols) > 2 else ("y0", "y1")
    get = (lambda n: self.column(n)) if cols else (lambda n: self._field("y")[int(n[1:])])
    ax.plot(get(x), get(y))
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_aspect("equal", adjustable="datalim")
    return ax


OdeResult.plot = _plot
OdeResult.plot_trajectory = _plot_trajectory


class _Columns:
    """``OdeResult.coords``: the tabulated columns by name (attributes and items)."""

    __slots__ = ("_res",)

    def __init__(self, res: OdeResult):
        self._res = res

    def __getitem__(self, name: str) -> np.ndarray:
        return self._res.column(name)

    def __getattr__(self, name: str) -> np.ndarray:
        try:
            return self._res.column(name)
        except KeyError as e:
            raise AttributeError(str(e)) from e

    def __contains__(self, name: str) -> bool:
        return name in (dict.get(self._res, "columns") or [])

    def __iter__(self):
        return iter(dict.get(self._res, "columns") or [])

    def __dir__(self):
        return [c for c in (dict.get(self._res, "columns") or []) if c.isidentifier()]

    def __repr__(self) -> str:
        return f"coords({dict.get(self._res, 'columns')})"


def _stats_counts(stats: Dict[str, Any]) -> Dict[str, int]:
    return {
        "nfev": stats["fevals"],
        "njev": stats["jacobians"],
        "nlu": stats["lu_decompositions"],
    }


def _from_run(raw: Dict[str, Any], event_names: List[str]) -> OdeResult:
    table = raw["table"]
    n = raw["n_states"]
    failure = raw["failure"]
    hits = raw["events"]
    status = raw["status"]
    if status == -1:
        message = failure
    elif status == 1:
        message = "A termination event occurred."
    else:
        message = "The solver successfully reached the end of the integration interval."
    names = list(dict.fromkeys(event_names + [h[0] for h in hits]))
    t_events = [np.array([h[1] for h in hits if h[0] == nm], dtype=np.float64) for nm in names]
    y_events = [
        np.vstack([h[2] for h in hits if h[0] == nm]) if any(h[0] == nm for h in hits)
        else np.empty((0, n), dtype=np.float64)
        for nm in names
    ]
    res = OdeResult(
        # Views of the one table the run produced: the trajectory is not copied again.
        t=table[:, 0],
        y=table[:, 1:1 + n].T,
        t_events=t_events if names else None,
        y_events=y_events if names else None,
        event_names=names,
        status=status,
        message=message,
        success=status >= 0,
        sol=None,
        columns=list(raw["columns"]),
        monitors=list(raw["monitors"]),
        warnings=list(raw["warnings"]),
        stats=dict(raw["stats"]),
        method=raw["method"],
        non_finite=list(raw.get("non_finite", [])),
        non_finite_t=raw.get("non_finite_t"),
        hybrid=json.loads(raw["hybrid_json"]) if raw.get("hybrid_json") else None,
        _table=table,
        **_stats_counts(raw["stats"]),
    )
    _warn(res, raw["drift_tolerance"])
    return res


def _warn(res: "OdeResult", tolerance: float) -> None:
    """Emits the run's warnings: a :class:`DriftWarning` (with ``quantity``, ``drift``,
    ``tolerance``) per drifting conserved quantity, a ``RuntimeWarning`` for the others."""
    drifting = {m["name"]: m for m in res["monitors"] if m["conserved"]}
    for w in res["warnings"]:
        name = w.split(" should be conserved", 1)[0] if " should be conserved" in w else None
        mon = drifting.get(name) if name is not None else None
        if mon is not None:
            warnings.warn(DriftWarning(w, mon["name"], float(mon["drift"]), float(tolerance),
                                       bool(mon["relative"])), stacklevel=4)
        else:
            warnings.warn(w, RuntimeWarning, stacklevel=4)


def _from_ivp(raw: Dict[str, Any], n_events: int, n: int) -> OdeResult:
    hits = raw["events"]
    t_events = None
    y_events = None
    if n_events:
        t_events = [np.array([h[1] for h in hits if h[0] == k], dtype=np.float64)
                    for k in range(n_events)]
        y_events = [np.array([h[2] for h in hits if h[0] == k], dtype=np.float64).reshape(-1, n)
                    for k in range(n_events)]
    return OdeResult(
        t=raw["t"],
        y=raw["y_rows"].T,  # a view: (n_states, n_times) as SciPy, not copied
        t_events=t_events,
        y_events=y_events,
        status=raw["status"],
        message=raw["message"],
        success=raw["status"] >= 0,
        sol=None,
        stats=dict(raw["stats"]),
        method=raw["method"],
        gil_released=raw["gil_released"],
        native=raw.get("native", False),
        **_stats_counts(raw["stats"]),
    )


class Expr:
    """A symbolic expression of pdyn: ``str(e)`` is re-parsable text, :meth:`latex` LaTeX;
    Jupyter renders it through :meth:`_repr_latex_`. With SymPy installed it converts
    (:meth:`to_sympy`, ``sympy.sympify(e)``, ``sympy.Matrix(rows_of_exprs)``) and takes part
    in arithmetic and :meth:`subs` as its SymPy expression."""

    __slots__ = ("_text", "_latex", "_positive")

    def __init__(self, text: str, latex: str, positive: frozenset = frozenset()):
        self._text = text
        self._latex = latex
        self._positive = positive

    def __str__(self) -> str:
        return self._text

    def __repr__(self) -> str:
        return f"Expr({self._text!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Expr) and other._text == self._text

    def __hash__(self) -> int:
        return hash(self._text)

    def latex(self) -> str:
        """The expression in LaTeX (math mode, without delimiters)."""
        return self._latex

    def _repr_latex_(self) -> str:
        return f"${self._latex}$"

    def to_sympy(self):
        """The expression as a SymPy expression (``^`` read as ``**``; primes ``x'`` become
        symbols ``x_d``, ``x''`` ``x_dd``). Every name is a SymPy ``Symbol`` of that name,
        never a SymPy constant or keyword (``E``, ``I``, ``S``, ``N``, ``Q``, ``beta``,
        ``lambda``...), ``positive=True`` where the model declares it (masses, lengths), without
        assumptions otherwise; ``pi`` is ``sympy.pi``. Raises ImportError when SymPy is not installed."""
        try:
            import sympy
        except ImportError as e:
            raise ImportError("Expr.to_sympy() needs sympy: pip install sympy") from e
        return _to_sympy(sympy, self._text, self._positive)

    def _sympy_(self):
        # sympy.sympify(e), sympy.Matrix([[e, ...]]) and arithmetic with SymPy objects.
        return self.to_sympy()

    def subs(self, *args, **kwargs):
        """``self.to_sympy().subs(...)``: SymPy's ``subs``."""
        return self.to_sympy().subs(*args, **kwargs)

    def __add__(self, other):
        return self.to_sympy() + _as_sympy(other)

    def __radd__(self, other):
        return _as_sympy(other) + self.to_sympy()

    def __sub__(self, other):
        return self.to_sympy() - _as_sympy(other)

    def __rsub__(self, other):
        return _as_sympy(other) - self.to_sympy()

    def __mul__(self, other):
        return self.to_sympy() * _as_sympy(other)

    def __rmul__(self, other):
        return _as_sympy(other) * self.to_sympy()

    def __truediv__(self, other):
        return self.to_sympy() / _as_sympy(other)

    def __rtruediv__(self, other):
        return _as_sympy(other) / self.to_sympy()

    def __pow__(self, other):
        return self.to_sympy() ** _as_sympy(other)

    def __neg__(self):
        return -self.to_sympy()


# Function names pdyn prints, as SymPy's.
_SYMPY_FUNCTIONS = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh",
                    "tanh", "exp", "log", "sqrt", "abs", "sign", "min", "max")


def _as_sympy(x):
    return x.to_sympy() if isinstance(x, Expr) else x


def _to_sympy(sympy, text: str, positive: frozenset):
    import re
    text = text.replace("^", "**")
    text = re.sub(r"([A-Za-z_][A-Za-z_0-9]*)''", r"\1_dd", text)
    text = re.sub(r"([A-Za-z_][A-Za-z_0-9]*)'", r"\1_d", text)
    functions = {"sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan, "asin": sympy.asin,
                 "acos": sympy.acos, "atan": sympy.atan, "atan2": sympy.atan2,
                 "sinh": sympy.sinh, "cosh": sympy.cosh, "tanh": sympy.tanh, "exp": sympy.exp,
                 "log": sympy.log, "sqrt": sympy.sqrt, "abs": sympy.Abs, "sign": sympy.sign,
                 "min": sympy.Min, "max": sympy.Max}
    # Every identifier becomes a placeholder bound to a Symbol of its own name: `E`, `I`,
    # `lambda` never reach SymPy's parser (constants, a keyword).
    names: Dict[str, Any] = {}

    def bind(m):
        name = m.group(0)
        if m.end() < len(text) and text[m.end()] == "(" and name in functions:
            key = f"__f_{name}"
            names[key] = functions[name]
            return key
        if name == "pi":
            names["__pi"] = sympy.pi
            return "__pi"
        key = f"__s{len(names)}"
        assumptions = {"positive": True} if name in positive else {}
        names[key] = sympy.Symbol(name, **assumptions)
        return key
    safe = re.sub(r"[A-Za-z_][A-Za-z_0-9]*", bind, text)
    return sympy.sympify(safe, locals=names)


def _expr(pair, positive: frozenset = frozenset()) -> Expr:
    return Expr(pair[0], pair[1], positive)


class Derivation:
    """The equations of motion of a model (:meth:`pdyn.Model.derive`).

    * ``equations`` -- ``[(label, lhs, rhs)]`` with :class:`Expr` sides (``lhs = rhs``);
    * ``unknowns`` -- names of the accelerations and reactions solved for;
    * ``solution`` -- ``None`` (solved numerically at each evaluation) or ``[(unknown, Expr)]``;
    * ``first_order`` -- ``None`` or ``[(state, Expr)]``: ``d/dt state = Expr``;
    * ``state`` -- names of the state components; ``form``, ``notes``;
    * ``mass_matrix`` -- ``None`` (some unknown is a reaction) or the rows of ``M`` in
      ``M(q) q'' = f(q, q', t)``, each entry an :class:`Expr` collected and factored
      (``l1*l2*(m2 + m3)*cos(q1 - q2)``); ``forcing`` -- ``None`` or the entries of ``f``.
    """

    def __init__(self, raw: Dict[str, Any]):
        pos = frozenset(raw.get("positive", ()))
        _e = lambda pair: _expr(pair, pos)  # noqa: E731
        self.equations = [(lab, _e(l), _e(r)) for lab, l, r in raw["equations"]]
        self.unknowns: List[str] = list(raw["unknowns"])
        sol = raw["solution"]
        self.solution = None if sol is None else [(u, _e(e)) for u, e in sol]
        fo = raw["first_order"]
        self.first_order = None if fo is None else [(s, _e(e)) for s, e in fo]
        self.state: List[str] = list(raw["state"])
        self.form: str = raw["form"]
        self.notes: List[str] = list(raw["notes"])
        mm = raw.get("mass_matrix")
        self.mass_matrix = None if mm is None else [[_e(e) for e in row] for row in mm]
        fo = raw.get("forcing")
        self.forcing = None if fo is None else [_e(e) for e in fo]

    def __repr__(self) -> str:
        lines = [f"{lab}: {l} = {r}" for lab, l, r in self.equations]
        return "Derivation(\n  " + "\n  ".join(lines) + "\n)"

    def _repr_latex_(self) -> str:
        rows = " \\\\ ".join(f"{l.latex()} &= {r.latex()}" for _, l, r in self.equations)
        return "$\\begin{aligned}" + rows + "\\end{aligned}$"


class SweepResult:
    """The result of :meth:`pdyn.Model.sweep`: ``parameter`` (name), ``values`` (float64
    array), ``measures`` (name -> float64 array, NaN where a run failed), ``problems``
    (``[(value, message)]``), ``runs``, ``seconds``, ``threads``; :meth:`to_pandas`."""

    def __init__(self, parameter, values, measures, problems, runs, seconds, threads):
        self.parameter: str = parameter
        self.values: np.ndarray = values
        self.measures: Dict[str, np.ndarray] = measures
        self.problems = problems
        self.runs: int = runs
        self.seconds: float = seconds
        self.threads: int = threads

    def __repr__(self) -> str:
        return (f"SweepResult({self.parameter!r}, {self.runs} runs, measures "
                f"{list(self.measures)}, {len(self.problems)} problems, {self.seconds:.3f} s)")

    def to_pandas(self):
        """One row per value: the parameter and every measure, as a pandas DataFrame."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover
            raise ImportError("SweepResult.to_pandas() needs pandas: pip install pandas") from e
        data = {self.parameter: self.values}
        data.update(self.measures)
        return pd.DataFrame(data)


class EnsembleResult:
    """The result of :meth:`pdyn.Model.ensemble`: one row per run, every field an array.

    * ``params`` -- ``{name: float64 (runs,)}``, the parameter values given;
    * ``initial`` -- ``{state: float64 (runs,)}``, the initial values given (may be empty);
    * ``measures`` -- ``{name: float64 (runs,)}`` (NaN where a run did not run);
    * ``t_final`` (runs,), ``final`` (runs, n_states) with column names ``state_names``;
    * ``event_t`` -- ``{event: float64 (runs,)}`` the time of its first occurrence (NaN when
      it did not occur); ``event_state`` -- ``{event: (runs, n_states)}``, the state then;
    * ``drift`` -- ``{conserved quantity: float64 (runs,)}``; ``drifted`` -- bool (runs,),
      whether any conserved quantity drifted beyond the tolerance;
    * ``status`` -- int32 (runs,): 0 end reached, 1 terminal event, -1 integration failed
      (partial run measured), -2 not run (e.g. a mass <= 0); ``problems`` -- ``[(row, message)]``;
    * ``nfev`` (runs,), ``seconds``, ``threads``; :meth:`to_pandas`, :meth:`column`.
    """

    def __init__(self, raw: Dict[str, Any], params: Dict[str, np.ndarray],
                 initial: Dict[str, np.ndarray]):
        self.params = params
        self.initial = initial
        self.state_names: List[str] = list(raw["state_names"])
        self.measures: Dict[str, np.ndarray] = {
            n: np.ascontiguousarray(raw["measures"][:, j])
            for j, n in enumerate(raw["measure_names"])}
        self.t_final: np.ndarray = raw["t_final"]
        self.final: np.ndarray = raw["final"]
        self.event_t: Dict[str, np.ndarray] = {
            n: np.ascontiguousarray(raw["event_t"][:, j])
            for j, n in enumerate(raw["event_names"])}
        self.event_state: Dict[str, np.ndarray] = {
            n: np.ascontiguousarray(raw["event_state"][:, j, :])
            for j, n in enumerate(raw["event_names"])}
        self.drift: Dict[str, np.ndarray] = {
            n: np.ascontiguousarray(raw["drift"][:, j])
            for j, n in enumerate(raw["monitor_names"])}
        self.drifted: np.ndarray = np.asarray(raw["drifted"], dtype=bool)
        self.status: np.ndarray = np.asarray(raw["status"], dtype=np.int32)
        self.nfev: np.ndarray = np.asarray(raw["nfev"], dtype=np.int64)
        self.problems: List[Tuple[int, str]] = [(int(r), m) for r, m in raw["problems"]]
        self.seconds: float = raw["seconds"]
        self.threads: int = raw["threads"]

    def __len__(self) -> int:
        return len(self.status)

    def __repr__(self) -> str:
        return (f"EnsembleResult({len(self)} runs, measures {list(self.measures)}, "
                f"events {list(self.event_t)}, {len(self.problems)} problems, "
                f"{self.seconds:.3f} s on {self.threads} threads)")

    def columns(self) -> Dict[str, np.ndarray]:
        """Every per-run column by name: the parameters, ``initial.<state>``, the measures,
        ``t_final``, ``final.<state>``, ``<event>.t`` and ``<event>.<state>``,
        ``drift.<quantity>``, ``drifted``, ``status``, ``nfev``."""
        out: Dict[str, np.ndarray] = {}
        out.update(self.params)
        out.update({f"initial.{k}": v for k, v in self.initial.items()})
        out.update(self.measures)
        out["t_final"] = self.t_final
        for j, s in enumerate(self.state_names):
            out[f"final.{s}"] = np.ascontiguousarray(self.final[:, j])
        for e, t in self.event_t.items():
            out[f"{e}.t"] = t
            for j, s in enumerate(self.state_names):
                out[f"{e}.{s}"] = np.ascontiguousarray(self.event_state[e][:, j])
        out.update({f"drift.{k}": v for k, v in self.drift.items()})
        out["drifted"] = self.drifted
        out["status"] = self.status
        out["nfev"] = self.nfev
        return out

    def column(self, name: str) -> np.ndarray:
        """One column of :meth:`columns` by name."""
        cols = self.columns()
        if name not in cols:
            raise KeyError(f"no column {name!r} (columns: {list(cols)})")
        return cols[name]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.column(name)

    def to_pandas(self):
        """One row per run, the columns of :meth:`columns`, as a pandas DataFrame."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover
            raise ImportError("EnsembleResult.to_pandas() needs pandas: pip install pandas") from e
        return pd.DataFrame(self.columns())


def _concat_raw(parts: List[Dict[str, Any]]) -> Dict[str, Any]:
    """Joins the raw results of consecutive slices of one ensemble."""
    if len(parts) == 1:
        return parts[0]
    out = dict(parts[0])
    for key in ("measures", "t_final", "final", "event_t", "event_state", "drift"):
        out[key] = np.concatenate([p[key] for p in parts], axis=0)
    for key in ("drifted", "status", "nfev"):
        out[key] = [x for p in parts for x in p[key]]
    offset, problems = 0, []
    for p in parts:
        problems += [(r + offset, m) for r, m in p["problems"]]
        offset += len(p["status"])
    out["problems"] = problems
    out["seconds"] = sum(p["seconds"] for p in parts)
    return out


class ForcesResult:
    """The result of :meth:`pdyn.Model.forces`.

    * ``instant`` -- ``{name: value}`` of ``t`` and the coordinates;
    * ``equations`` -- ``[(label, lhs, rhs)]`` of :class:`Expr`;
    * ``unknowns`` -- names; ``symbolic`` -- ``{unknown: Expr}`` or ``None``;
    * ``values`` -- one ``{unknown: float}`` per real solution at the instant;
    * ``checks`` -- one dict per ``[[checks]]``: ``name``, ``condition``, ``parameter``,
      ``symbolic`` (list of Expr), ``min``/``max`` (``(value, at)``), ``over``,
      ``critical`` (``[(value, {force: value})]``), ``forces_at_critical``;
    * ``notes``.
    """

    def __init__(self, raw: Dict[str, Any]):
        self.instant: Dict[str, float] = dict(raw["instant"])
        self.equations = [(lab, _expr(l), _expr(r)) for lab, l, r in raw["equations"]]
        self.unknowns: List[str] = list(raw["unknowns"])
        sym = raw["symbolic"]
        self.symbolic = None if sym is None else {
            u: _expr(e) for u, e in zip(self.unknowns, sym)}
        self.values: List[Dict[str, float]] = [dict(zip(self.unknowns, row))
                                               for row in raw["numeric"]]
        self.checks: List[Dict[str, Any]] = []
        for c in raw["checks"]:
            c = dict(c)
            c["symbolic"] = [_expr(e) for e in c["symbolic"]]
            c["critical"] = [(v, dict(f)) for v, f in c["critical"]]
            c["forces_at_critical"] = dict(c["forces_at_critical"])
            self.checks.append(c)
        self.notes: List[str] = list(raw["notes"])

    def __repr__(self) -> str:
        return f"ForcesResult(unknowns {self.unknowns}, values {self.values})"

    def _repr_latex_(self) -> str:
        rows = " \\\\ ".join(f"{l.latex()} &= {r.latex()}" for _, l, r in self.equations)
        return "$\\begin{aligned}" + rows + "\\end{aligned}$"


class Table:
    """Named columns of equal length (float64 arrays): ``tab["energy"]``, ``tab.columns``,
    ``tab.data`` (rows × columns), :meth:`to_pandas`."""

    __slots__ = ("columns", "data")

    def __init__(self, raw: Dict[str, Any]):
        self.columns: List[str] = list(raw["columns"])
        self.data = raw["data"]

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.data[:, self.columns.index(name)]
        except ValueError:
            raise KeyError(f"no column {name!r} (columns: {', '.join(self.columns)})") from None

    def __len__(self) -> int:
        return self.data.shape[0]

    def to_pandas(self) -> Any:
        """A ``pandas.DataFrame`` of the table."""
        import pandas as pd
        return pd.DataFrame(self.data, columns=self.columns)

    def __repr__(self) -> str:
        return f"Table({len(self)} rows: {', '.join(self.columns)})"


class ParticleResult:
    """What running an ``[nbody]`` or ``[md]`` model returns (:meth:`pdyn.Model.run`), with
    the numbers ``pdyn run`` prints.

    Every kind: ``kind`` (``"nbody"``, ``"md"``), ``summary`` (the dict of the CLI's
    ``summary.json``, docs/summary.md), ``success``, ``message``, ``warnings``.
    N-body: ``t`` (output times), ``names`` (bodies, in the order ``body`` indexes),
    ``trajectory`` (:class:`Table` with ``t, body, mass, x, y, z, vx, vy, vz``, one row per body
    and output; empty when trajectories are off), ``elements`` (``t, body, a, e, inc, Omega,
    omega, f, M, period``), ``conservation`` (``t, n, energy, kinetic, potential, Lx, Ly,
    Lz``). MD: ``thermo`` (``step, time, temperature, kinetic, potential, total, pressure,
    conserved``), ``rdf`` (``(r, g)`` arrays or ``None``), ``msd`` (``step, time, msd``).
    Drifting conserved quantities are warned as :class:`DriftWarning`, other warnings as
    ``RuntimeWarning``.
    """

    def __init__(self, raw: Dict[str, Any]):
        self.kind: str = raw["kind"]
        self.summary: Dict[str, Any] = json.loads(raw["summary"])
        self.success: bool = raw["failure"] is None
        self.message: str = raw["failure"] or "The run finished."
        self.warnings: List[str] = list(raw["warnings"])
        if self.kind == "nbody":
            self.t = raw["t"]
            self.names: List[str] = list(raw["names"])
            self.trajectory = Table(raw["trajectory"])
            self.elements = Table(raw["elements"])
            self.conservation = Table(raw["conservation"])
        else:
            self.thermo = Table(raw["thermo"])
            self.rdf = None if raw["rdf_r"] is None else (raw["rdf_r"], raw["rdf_g"])
            self.msd = Table(raw["msd"])
        drifting = {m["name"]: m for m in self.summary["monitors"] if not m["ok"]}
        for w in self.warnings:
            mon = next((m for name, m in drifting.items()
                        if name.replace("_", " ") in w or name in w), None)
            if mon is not None and "conserved" in w:
                drift = mon["drift"] if isinstance(mon["drift"], float) else float("nan")
                warnings.warn(DriftWarning(w, mon["name"], drift, float(mon["tolerance"]),
                                           bool(mon["relative"])), stacklevel=3)
            else:
                warnings.warn(w, RuntimeWarning, stacklevel=3)

    def __repr__(self) -> str:
        return (f"ParticleResult(kind={self.kind!r}, model={self.summary.get('model')!r}, "
                f"success={self.success})")
