"""Result objects: :class:`OdeResult` (SciPy's shape), :class:`Derivation`, :class:`Expr`,
:class:`SweepResult`."""

import warnings
from typing import Any, Dict, List, Optional

import numpy as np

from ._errors import DriftWarning


class OdeResult(dict):
    """The result of :meth:`pdyn.Model.run` or :func:`pdyn.solve_ivp`, shaped like SciPy's.

    Attributes (also available as ``sol["name"]`` for SciPy's own fields):

    * ``t`` -- output times, 1-D float64 array of length ``n_times``;
    * ``y`` -- states, 2-D float64 array of shape ``(n_states, n_times)``;
    * ``t_events``, ``y_events`` -- one array per event (``None`` without events);
    * ``status`` (0 end reached, 1 terminal event, -1 integration failed), ``message``,
      ``success``;
    * ``nfev``, ``njev``, ``nlu`` -- the Rust solver's counts; ``stats`` has all of them;
    * pdyn's: ``columns`` (every tabulated column of a model run), ``sol["x"]`` (a column by
      name; a model's columns take precedence over SciPy's keys, so ``sol["y"]`` is a
      coordinate ``y`` when there is one, ``sol.y`` always the states), :meth:`column`,
      ``monitors`` (conserved quantities with their drift), ``warnings``,
      ``method``, :meth:`to_pandas`.
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

    def __dir__(self):
        return list(self.keys()) + list(super().__dir__())

    def __repr__(self) -> str:
        shown = ["message", "success", "status", "nfev", "njev", "nlu", "method"]
        parts = [f"{k}: {self.get(k)!r}" for k in shown if k in self]
        parts.append(f"t: array of {len(self['t'])} times")
        parts.append(f"y: array of shape {self['y'].shape}")
        return "OdeResult(" + ", ".join(parts) + ")"

    def to_pandas(self):
        """Every column (``t``, the states, positions, monitors...) as a pandas DataFrame;
        raises ImportError when pandas is not installed."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("OdeResult.to_pandas() needs pandas: pip install pandas") from e
        cols = self.get("columns")
        if cols is None:
            cols = ["t"] + [f"y{k}" for k in range(self["y"].shape[0])]
            data = np.column_stack([self["t"], self["y"].T])
        else:
            data = self["_table"]
        return pd.DataFrame(data, columns=list(cols))


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
    if failure is not None:
        status, message = -1, failure
    elif hits and event_names and table.shape[0] and hits[-1][1] == table[-1, 0]:
        status, message = 1, "A termination event occurred."
    else:
        status, message = 0, "The solver successfully reached the end of the integration interval."
    names = list(dict.fromkeys(event_names + [h[0] for h in hits]))
    t_events = [np.array([h[1] for h in hits if h[0] == nm], dtype=np.float64) for nm in names]
    y_events = [
        np.vstack([h[2] for h in hits if h[0] == nm]) if any(h[0] == nm for h in hits)
        else np.empty((0, n), dtype=np.float64)
        for nm in names
    ]
    res = OdeResult(
        t=np.ascontiguousarray(table[:, 0]),
        y=np.ascontiguousarray(table[:, 1:1 + n].T),
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
        _table=table,
        **_stats_counts(raw["stats"]),
    )
    for w in res["warnings"]:
        category = DriftWarning if "should be conserved" in w else RuntimeWarning
        warnings.warn(w, category, stacklevel=3)
    return res


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
        y=np.ascontiguousarray(raw["y_rows"].T),
        t_events=t_events,
        y_events=y_events,
        status=raw["status"],
        message=raw["message"],
        success=raw["status"] >= 0,
        sol=None,
        stats=dict(raw["stats"]),
        method=raw["method"],
        gil_released=raw["gil_released"],
        **_stats_counts(raw["stats"]),
    )


class Expr:
    """A symbolic expression of pdyn: ``str(e)`` is re-parsable text, :meth:`latex` LaTeX;
    Jupyter renders it through :meth:`_repr_latex_`."""

    __slots__ = ("_text", "_latex")

    def __init__(self, text: str, latex: str):
        self._text = text
        self._latex = latex

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
        ``x_d``, ``x''`` ``x_dd``). Raises ImportError when SymPy is not installed."""
        try:
            import sympy
        except ImportError as e:
            raise ImportError("Expr.to_sympy() needs sympy: pip install sympy") from e
        import re
        text = self._text.replace("^", "**")
        text = re.sub(r"([A-Za-z_][A-Za-z_0-9]*)''", r"\1_dd", text)
        text = re.sub(r"([A-Za-z_][A-Za-z_0-9]*)'", r"\1_d", text)
        return sympy.sympify(text)


def _expr(pair) -> Expr:
    return Expr(pair[0], pair[1])


class Derivation:
    """The equations of motion of a model (:meth:`pdyn.Model.derive`).

    * ``equations`` -- ``[(label, lhs, rhs)]`` with :class:`Expr` sides (``lhs = rhs``);
    * ``unknowns`` -- names of the accelerations and reactions solved for;
    * ``solution`` -- ``None`` (solved numerically at each evaluation) or ``[(unknown, Expr)]``;
    * ``first_order`` -- ``None`` or ``[(state, Expr)]``: ``d/dt state = Expr``;
    * ``state`` -- names of the state components; ``form``, ``notes``.
    """

    def __init__(self, raw: Dict[str, Any]):
        self.equations = [(lab, _expr(l), _expr(r)) for lab, l, r in raw["equations"]]
        self.unknowns: List[str] = list(raw["unknowns"])
        sol = raw["solution"]
        self.solution = None if sol is None else [(u, _expr(e)) for u, e in sol]
        fo = raw["first_order"]
        self.first_order = None if fo is None else [(s, _expr(e)) for s, e in fo]
        self.state: List[str] = list(raw["state"])
        self.form: str = raw["form"]
        self.notes: List[str] = list(raw["notes"])

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
