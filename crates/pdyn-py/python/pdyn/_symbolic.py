"""``pdyn.kin`` and ``pdyn.dsolve``: the ``pdyn kin`` and ``pdyn dsolve`` commands from Python.

The computation is the library's (``pdyn::kin``, ``pdyn::dsolve``), the same as the
commands'; expressions come back as :class:`~pdyn.Expr` (3-vectors as :class:`Vector`),
numbers as floats and float64 NumPy arrays. Bad input raises :class:`~pdyn.ModelError`
located in the argument it came from (``file``: the command's name for it, ``<position>``,
``--at``, ``<equation 1>``...; ``argument``: the Python keyword, ``position``, ``at``,
``equations``...; ``line`` and ``column`` inside an expression's text).
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

from . import _pdyn
from ._errors import ModelError
from ._lazy import LazyModule
from ._result import Expr

np = LazyModule("numpy")  # imported on first use


# The commands' names of the arguments, as the messages say them -> the Python keywords.
_KEYWORDS = {
    "<position>": "position", "--polar": "polar", "--path": "path", "--speed": "speed",
    "--at": "at", "--set": "params", "--max": "max", "--over": "over", "--ic": "ic",
    "--rule": "rule", "--when": "when",
}


def _call(fn, **kw):
    """Calls the Rust function; a ModelError gets ``argument``, the Python keyword."""
    try:
        return fn(**kw)
    except ModelError as e:
        f = e.file or ""
        e.argument = "equations" if f.startswith("<equation") else _KEYWORDS.get(f, f)
        raise


class Vector(tuple):
    """A 3-vector of :class:`~pdyn.Expr` (Cartesian ``[x, y, z]`` or polar
    ``[r, theta, z]`` components, as named): ``str(v)`` is ``[x, y, z]``, :meth:`latex`
    a column matrix, :meth:`to_sympy` a ``sympy.Matrix``."""

    def __str__(self) -> str:
        return "[" + ", ".join(str(c) for c in self) + "]"

    def __repr__(self) -> str:
        return f"Vector({str(self)!r})"

    def latex(self) -> str:
        """The vector as a LaTeX column matrix (math mode, without delimiters)."""
        return "\\begin{bmatrix} " + " \\\\ ".join(c.latex() for c in self) + " \\end{bmatrix}"

    def _repr_latex_(self) -> str:
        return f"${self.latex()}$"

    def to_sympy(self):
        """The vector as a 3x1 ``sympy.Matrix`` (needs SymPy)."""
        import sympy
        return sympy.Matrix([c.to_sympy() for c in self])


def _q(x) -> Union[Expr, Vector]:
    if isinstance(x, tuple):
        return Expr(x[0], x[1])
    return Vector(Expr(a, b) for a, b in x)


def _text(x: Any) -> str:
    """An expression argument: a string, a number, or a SymPy expression (translated by
    :func:`pdyn._sympy_text.to_pdyn_text`)."""
    if isinstance(x, str):
        return x
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(_text(c) for c in x) + "]"
    if hasattr(x, "free_symbols"):
        from ._sympy_text import to_pdyn_text
        return to_pdyn_text(x)
    return str(x).replace("**", "^")


def _assignments(x: Any) -> str:
    """``{"t": 2, "theta": "pi"}`` or ``"t=2, theta=pi"`` -> ``"t=2, theta=pi"``."""
    if isinstance(x, Mapping):
        return ", ".join(f"{k}={_text(v)}" for k, v in x.items())
    return _text(x)


def _set(params: Optional[Mapping[str, Any]]) -> List[str]:
    if params is None:
        return []
    if not isinstance(params, Mapping):
        raise TypeError("params must be a dict {name: value}")
    return [f"{k}={_text(v)}" for k, v in params.items()]


def _instants(at: Any) -> List[str]:
    if at is None:
        return []
    if isinstance(at, (str, Mapping)):
        return [_assignments(at)]
    return [_assignments(a) for a in at]


class KinInstant:
    """The quantities at one instant of :func:`kin`: ``at`` (as given), ``resolved`` (as
    solved, e.g. ``theta = pi (t = sqrt(pi))``), ``exact`` (name -> :class:`~pdyn.Expr` or
    :class:`Vector`), ``values`` (name -> float, or a float64 array of 3 for a vector;
    ``None`` where a symbol has no value)."""

    def __init__(self, spec: str, resolved: str, values):
        self.at = spec
        self.resolved = resolved
        self.exact: Dict[str, Union[Expr, Vector]] = {}
        self.values: Dict[str, Any] = {}
        for name, q, nums in values:
            self.exact[name] = _q(q)
            if nums is None:
                self.values[name] = None
            elif isinstance(q, tuple):
                self.values[name] = float(nums[0])
            else:
                self.values[name] = np.array(nums, dtype=np.float64)

    def __getitem__(self, name: str) -> Any:
        return self.values[name]

    def __repr__(self) -> str:
        return f"KinInstant(at {self.resolved!r})"


class KinResult:
    """The result of :func:`kin`, as ``pdyn kin`` prints it.

    * ``quantities`` -- name -> :class:`~pdyn.Expr` (scalars: ``speed``, ``curvature``,
      ``radius``, ``a_t``, ``a_n``) or :class:`Vector` (``r``, ``v``, ``a``, ``tangent``,
      ``normal``, ``e_r``, ``e_theta``, ``r_polar``, ``v_polar``, ``a_polar``...); also as
      attributes (``k.speed``) and items (``k["v"]``);
    * ``variable`` -- the independent variable (``t``, or the path's parameter);
    * ``straight`` -- straight-line motion (normal undefined, shown as 0; radius infinite);
    * ``instants`` -- one :class:`KinInstant` per ``at``;
    * ``max`` -- ``None`` or a dict: ``expr``, ``over``, ``variable``, ``value`` and ``at``
      (floats, or :class:`~pdyn.Expr` when ``exact``), ``parameters``;
    * ``assumed_positive`` -- parameters assumed > 0 (pass ``signed=[...]`` otherwise).
    """

    def __init__(self, raw: Dict[str, Any]):
        self.variable: str = raw["variable"]
        self.straight: bool = bool(raw["straight"])
        self.quantities: Dict[str, Union[Expr, Vector]] = {
            name: _q(q) for name, q in raw["quantities"]}
        self.instants = [KinInstant(*i) for i in raw["instants"]]
        mx = raw["max"]
        if mx is not None:
            mx = dict(mx)
            if mx["exact"]:
                mx["value"] = Expr(*mx["value"])
                mx["at"] = Expr(*mx["at"])
        self.max: Optional[Dict[str, Any]] = mx
        self.assumed_positive: List[str] = list(raw["assumed_positive"])

    def __getitem__(self, name: str) -> Union[Expr, Vector]:
        return self.quantities[name]

    def __getattr__(self, name: str) -> Any:
        q = self.__dict__.get("quantities")
        if q is not None and name in q:
            return q[name]
        raise AttributeError(name)

    def __repr__(self) -> str:
        lines = [f"{n} = {q}" for n, q in self.quantities.items()]
        return "KinResult(\n  " + "\n  ".join(lines) + "\n)"

    def _repr_latex_(self) -> str:
        rows = " \\\\ ".join(f"\\mathrm{{{n.replace('_', chr(92) + '_')}}} &= {q.latex()}"
                             for n, q in self.quantities.items())
        return "$\\begin{aligned}" + rows + "\\end{aligned}$"


def kin(position: Any = None, *, polar: Any = None, path: Any = None, param: str = "s",
        speed: Any = "V", at: Any = None, params: Optional[Mapping[str, Any]] = None,
        max: Any = None, over: Any = None, signed: Optional[Sequence[str]] = None
        ) -> KinResult:
    """Kinematics of a particle, like ``pdyn kin``: velocity, acceleration, speed, tangent
    and normal, curvature and radius, tangential and normal acceleration, polar components.

    Give exactly one of ``position`` (Cartesian ``"[x, y, z]"`` in ``t``, or a list of three
    expressions), ``polar`` (``"r = ..., theta = ..."`` or a dict ``{"r": ..., "theta":
    ...}``) or ``path`` (``"y = f(x)"``, or ``"x = f(s), y = g(s)"`` in ``param``, travelled at
    ``speed``). ``at``: an instant (``"t=2"``, ``{"theta": "pi"}``, ``"x=L/4"``) or a list of
    them; ``params``: parameter values (``{"R": 2, "omega": -3}``); ``max`` and ``over``: the
    maximum of a quantity over a range (``max="norm(a)", over="x=0..L"``); ``signed``:
    parameters that may be negative (the others are assumed positive; a value < 0 in
    ``params`` lifts the assumption). Expressions may be strings, numbers or SymPy
    expressions.

    Returns a :class:`KinResult`; raises :class:`~pdyn.ModelError` (located) on bad input.
    """
    raw = _call(
        _pdyn._kin,
        position=None if position is None else _text(position),
        polar=None if polar is None else _assignments(polar),
        path=None if path is None else _assignments(path),
        param=str(param), speed=_text(speed), at=_instants(at), set=_set(params),
        max=None if max is None else _text(max),
        over=None if over is None else _assignments(over).replace(" ", ""),
        signed=[str(s) for s in (signed or [])],
    )
    return KinResult(raw)


class DsolveCase:
    """One case of a :class:`DsolveResult` (a solution valid under its ``condition``):
    ``condition`` (``None``, or ``(Expr, relation)`` meaning ``Expr relation 0``),
    ``solution`` (coordinate -> :class:`~pdyn.Expr` in ``t``), ``roots`` (characteristic
    roots, text), ``constants`` (arbitrary constants left), ``values`` (``None``, or a float64
    array of shape ``(len(times), 2 * n_coords)``: each coordinate and its rate at each
    time)."""

    def __init__(self, raw: Dict[str, Any]):
        cond = raw["condition"]
        self.condition = None if cond is None else (Expr(*cond[0]), cond[1])
        self.solution: Dict[str, Expr] = {n: Expr(*e) for n, e in raw["solution"]}
        self.roots: List[str] = list(raw["roots"])
        self.constants: List[str] = list(raw["constants"])
        self.values = raw["values"]

    def __repr__(self) -> str:
        c = "" if self.condition is None else f"if {self.condition[0]} {self.condition[1]} 0: "
        return "DsolveCase(" + c + ", ".join(f"{n}(t) = {e}" for n, e in
                                            self.solution.items()) + ")"


class DsolveResult:
    """The result of :func:`dsolve` for equations, as ``pdyn dsolve`` prints it.

    * ``coords`` -- the coordinates, in order; ``method`` (``"exact"`` or ``"numeric"``),
      ``residual`` (numeric method: the relative residual of the fit);
    * ``cases`` -- :class:`DsolveCase` list (one unless the form depends on the sign of a
      symbolic quantity); ``solution`` -- the only case's coordinate -> :class:`~pdyn.Expr`
      (``None`` with several cases); ``d["x"]`` is ``d.solution["x"]``;
    * ``times`` -- the ``at`` times (float64 array), each case's ``values`` at them;
      ``values`` -- the only case's (``None`` with several cases or no times);
    * ``when`` -- ``None`` or a dict: ``condition``, ``t`` (:class:`~pdyn.Expr`), ``exact``,
      ``value`` (float; NaN when it depends on symbols), ``state`` (name -> (Expr, float or
      None));
    * ``assumed_positive``.
    """

    def __init__(self, raw: Dict[str, Any]):
        self.coords: List[str] = list(raw["coords"])
        self.method: str = raw["method"]
        self.residual: Optional[float] = raw["residual"]
        self.cases = [DsolveCase(c) for c in raw["cases"]]
        self.solution = self.cases[0].solution if len(self.cases) == 1 else None
        self.times = raw["times"]
        self.values = self.cases[0].values if len(self.cases) == 1 else None
        w = raw["when"]
        if w is not None:
            w = dict(w)
            w["t"] = Expr(*w["t"])
            w["state"] = {n: (Expr(*e), v) for n, e, v in w["state"]}
        self.when: Optional[Dict[str, Any]] = w
        self.assumed_positive: List[str] = list(raw["assumed_positive"])

    def __getitem__(self, name: str) -> Expr:
        if self.solution is None:
            raise KeyError(f"{name}: several cases; see .cases")
        return self.solution[name]

    def __repr__(self) -> str:
        return "DsolveResult(" + "; ".join(repr(c) for c in self.cases) + ")"

    def _repr_latex_(self) -> str:
        rows = []
        for c in self.cases:
            if c.condition is not None:
                rows.append(f"\\text{{if }} {c.condition[0].latex()} {c.condition[1]} 0: &")
            rows += [f"{n}(t) &= {e.latex()}" for n, e in c.solution.items()]
        return "$\\begin{aligned}" + " \\\\ ".join(rows) + "\\end{aligned}$"


class RuleResult:
    """The result of :func:`dsolve` with a ``rule`` (straight-line motion from ``a(t)``,
    ``v(t)``, ``a(v)`` or ``a(x)``): ``rule``, ``variable`` (``t``, ``v`` or ``x``),
    ``quantities`` (name, e.g. ``"x(t)"`` -> :class:`~pdyn.Expr`, or ``None`` when evaluated
    by quadrature), ``points`` (the ``at`` values, float64 array), ``values`` and ``errors``
    (name -> float64 array at the points; NaN where it has no value, ``messages`` says why;
    errors are quadrature estimates, 0 for closed forms), ``assumed_positive``."""

    def __init__(self, raw: Dict[str, Any]):
        self.rule: str = raw["rule"]
        self.variable: str = raw["variable"]
        self.points = raw["points"]
        self.quantities: Dict[str, Optional[Expr]] = {}
        self.values: Dict[str, Any] = {}
        self.errors: Dict[str, Any] = {}
        self.messages: Dict[str, List[Optional[str]]] = {}
        self.descriptions: Dict[str, str] = {}
        for q in raw["quantities"]:
            n = q["name"]
            self.quantities[n] = None if q["closed"] is None else Expr(*q["closed"])
            self.values[n] = q["values"]
            self.errors[n] = q["errors"]
            self.messages[n] = list(q["messages"])
            self.descriptions[n] = q["describe"]
        self.assumed_positive: List[str] = list(raw["assumed_positive"])

    def __getitem__(self, name: str) -> Optional[Expr]:
        return self.quantities[name]

    def __repr__(self) -> str:
        return "RuleResult(" + "; ".join(f"{n} = {e if e is not None else self.descriptions[n]}"
                                         for n, e in self.quantities.items()) + ")"


def _ic(ic: Any) -> Optional[str]:
    if ic is None:
        return None
    if isinstance(ic, Mapping):
        return ", ".join(f"{k}={_text(v)}" for k, v in ic.items())
    return _text(ic)


def dsolve(*equations: Any, ic: Any = None, rule: Any = None,
           params: Optional[Mapping[str, Any]] = None, at: Any = None, when: Any = None,
           signed: Optional[Sequence[str]] = None) -> Union[DsolveResult, RuleResult]:
    """Closed-form solution of linear constant-coefficient ODEs, like ``pdyn dsolve``.

    ``equations``: one or more ``"lhs = rhs"`` strings in coordinates written ``x'``,
    ``x''`` or ``x(t)`` (``"m*x'' = -k*x"``); ``ic``: initial conditions, ``"x(0)=x0,
    x'(0)=v0"`` or a dict ``{"x(0)": "x0", "x'(0)": 0}``; ``params``: values substituted
    before solving (a numeric damping ratio picks the under-, critically or over-damped
    form); ``at``: times to evaluate at (a number or a sequence); ``when``: the first
    instant t >= 0 where a condition holds (``"y = 0"``); ``signed``: parameters that may
    be negative or zero (the others are assumed positive).

    ``rule`` instead of equations: a 1-D rule of straight-line motion, ``"a(t) = ..."``,
    ``"v(t) = ..."``, ``"a(v) = ..."`` or ``"a(x) = ..."`` (``ic``: ``x(0)``, ``v(0)``;
    ``at``: values of the rule's variable).

    Returns a :class:`DsolveResult` (equations) or a :class:`RuleResult` (a rule); raises
    :class:`~pdyn.ModelError` (located) on bad input.
    """
    if at is None:
        times: List[str] = []
    elif isinstance(at, (str, int, float)):
        times = [_text(at)]
    else:
        times = [_text(a) if isinstance(a, str) else repr(float(a)) for a in at]
    raw = _call(
        _pdyn._dsolve,
        equations=[_text(e) for e in equations], ic=_ic(ic),
        rule=None if rule is None else _text(rule), set=_set(params), at=times,
        when=None if when is None else _text(when),
        signed=[str(s) for s in (signed or [])],
    )
    if raw["kind"] == "rule":
        return RuleResult(raw)
    return DsolveResult(raw)
