"""``pdyn.solve_ivp``: SciPy's ``solve_ivp`` on pdyn's integrators (re-exported by
``pdyn``)."""

from __future__ import annotations

import math
from typing import Any, Callable, Mapping, Optional, Sequence, Tuple, Union

from ._lazy import LazyModule

np = LazyModule("numpy")  # imported on first use

from . import _pdyn
from ._result import OdeResult, _from_ivp


# SciPy's names of methods pdyn runs with another of its own methods, and what it says.
_MAPPED = {
    "lsoda": ("auto", "LSODA ran as pdyn's auto (DOPRI5, or DOP853 at rtol <= 1e-6, "
                      "switching to Radau when it detects stiffness, as LSODA switches "
                      "from Adams to BDF)"),
}
_IMPLICIT = {"radau", "radau5", "bdf", "ode15s", "lsoda", "auto"}
_EXPLICIT = {"rk45", "rk23", "dop853", "dopri5", "tsit5", "vern9", "ode45", "ode23", "rk4"}
_EPS = 2.220446049250313e-16


def _tol(x, name: str, n: int):
    a = np.asarray(x, dtype=np.float64)
    if a.ndim > 0 and a.shape != (n,):
        raise ValueError(f"`{name}` has wrong shape.")
    a = a.ravel()
    if a.size == 0:
        raise ValueError(f"`{name}` is empty")
    return a


def _bind(f, args):
    """``f`` with ``args`` appended to its arguments, keeping an event's ``terminal`` and
    ``direction`` (SciPy passes ``args`` to ``fun``, ``jac`` and the events alike)."""
    if not args or not callable(f):
        return f
    def bound(t, y, _f=f):
        return _f(t, y, *args)
    for attr in ("terminal", "direction"):
        if hasattr(f, attr):
            setattr(bound, attr, getattr(f, attr))
    return bound


def solve_ivp(fun: Union[Callable[..., Any], Sequence[str]], t_span: Tuple[float, float],
              y0: Sequence[float], method: Union[str, Any] = "RK45",
              t_eval: Optional[Sequence[float]] = None, dense_output: bool = False,
              events: Optional[Any] = None, vectorized: bool = False,
              args: Optional[Any] = None, rtol: Union[float, Sequence[float]] = 1e-3,
              atol: Union[float, Sequence[float]] = 1e-6, max_step: float = math.inf,
              first_step: Optional[float] = None, min_step: float = 0.0,
              jac: Optional[Any] = None, max_steps: Optional[int] = None,
              jit: bool = True, **options: Any) -> OdeResult:
    """Solves ``y' = fun(t, y)`` as SciPy's ``scipy.integrate.solve_ivp`` does (same
    signature, defaults, result and errors), integrated by pdyn.

    ``fun`` is either a Python callable ``fun(t, y, *args) -> array`` (called with the GIL
    held for each evaluation), or a list of expression strings in ``t`` and ``y0, y1, ...``
    (and the names of ``args`` when it is a dict of numbers), compiled once: no Python in the
    loop, the GIL released. ``args`` (a tuple) is passed to ``fun``, ``jac`` and every event
    function, as SciPy does.

    ``method``: ``"RK45"`` (default; DOPRI5), ``"RK23"`` (Bogacki-Shampine), ``"DOP853"``,
    ``"Radau"``, ``"BDF"`` (variable order 1-5 with the NDF coefficients, as SciPy's);
    ``"LSODA"`` runs as pdyn's ``auto`` (DOPRI5, or DOP853 at ``rtol <= 1e-6``, switching to
    Radau when stiff) -- the ``message`` says so; or pdyn's own (``"Tsit5"``, ``"Vern9"``,
    ...; :func:`pdyn.methods`).

    ``jac_sparsity`` (an ``(n, n)`` array or sparse matrix, nonzero where the Jacobian may be)
    groups the columns of the finite-difference Jacobian of Radau, BDF and LSODA, one
    evaluation of ``fun`` per group; ``lband``/``uband`` give LSODA a banded pattern. Other
    methods warn about them, as SciPy's do.

    ``t_eval``: the result's ``t`` is exactly these times (up to a terminal event, whose time
    and state are in ``t_events``/``y_events``). ``events``: callables with SciPy's
    ``terminal`` (``True`` or a count) and ``direction`` attributes, or expression strings (a
    ``(expression, terminal, direction)`` tuple sets them). ``jac``: the Jacobian
    ``df/dy`` as an array or a callable ``jac(t, y, *args)`` (used by Radau, BDF and LSODA;
    otherwise finite differences, in one call of ``fun`` when ``vectorized=True``).
    ``vectorized=True``: ``fun`` is called with ``y`` of shape ``(n, k)`` (``k = 1`` for a
    single state), as SciPy calls it. ``first_step``, ``max_step``, ``min_step`` bound the
    step size (``min_step`` for every adaptive method: a step of that size that fails ends the
    solve with ``status=-1``).

    ``dense_output=True`` sets ``sol.sol``, an ``OdeSolution`` callable ``sol.sol(t)`` built
    from every step's own interpolant: the method's continuous extension (order 7 for DOP853,
    4 for RK45 and Tsit5, 3 for RK23 and Radau; cubic Hermite for Vern9 and fixed steps).

    ``nfev``: the calls of ``fun`` that were made (the solver's count for compiled
    expressions); ``njev``: Jacobian evaluations (calls of ``jac``, or finite-difference
    Jacobians); ``nlu``: LU factorizations (Radau factors a real and a complex matrix per
    iteration matrix: 2). ``stats`` has pdyn's counts.

    Ctrl-C stops the solve at its next step and raises :class:`pdyn.Interrupted` (a
    ``KeyboardInterrupt``) whose ``result`` is the :class:`OdeResult` of what was computed
    (``status=-1``, the ``message`` says where it stopped).

    There is no step cap unless ``max_steps`` is given, but a memory guard: when what is
    stored grows with the steps (the outputs without ``t_eval``, the dense output), a solve
    that would store more than 2^28 doubles (2 GiB) stops with ``status=-1`` and a message
    saying so. A numerical failure returns ``success=False``, ``status=-1`` and the partial
    solution, as SciPy does. Options SciPy's solvers do not use are warned about
    (``UserWarning``), as SciPy does.

    Compiled expressions run as native code (the Cranelift JIT of ``pdyn-jit``, compiled once
    per distinct list of expressions and cached), with pdyn's interpreter as the fallback
    where there is no JIT or with ``jit=False``; both give the same bits.
    ``sol.native`` says which ran.
    """
    import warnings

    import numpy as np  # the module itself, not the lazy stand-in: this runs once per call
    if isinstance(method, type):
        method = method.__name__
    # Structure hints of the Jacobian, used by the implicit methods' finite differences as
    # SciPy uses them: `jac_sparsity` (Radau, BDF; pdyn's LSODA too) groups the columns,
    # `lband`/`uband` (LSODA's) give a band. For a method that does not use them they are
    # warned about, as SciPy warns.
    sparsity = options.pop("jac_sparsity", None)
    lband, uband = options.pop("lband", None), options.pop("uband", None)
    implicit = isinstance(method, str) and method.lower() in _IMPLICIT
    if not implicit and sparsity is not None:
        options["jac_sparsity"] = sparsity
    if not (isinstance(method, str) and method.lower() == "lsoda"):
        for k, v in (("lband", lband), ("uband", uband)):
            if v is not None:
                options[k] = v
        lband = uband = None
    if options:
        warnings.warn("The following arguments have no effect for a chosen solver: "
                      + ", ".join(f"`{k}`" for k in options) + ".", stacklevel=2)
    if not isinstance(method, str):
        raise ValueError("`method` must be one of RK45, RK23, DOP853, Radau, BDF, LSODA, "
                         "pdyn's methods, or an OdeSolver class.")
    t0, tf = map(float, t_span)
    y0_in = np.asarray(y0)
    if np.iscomplexobj(y0_in):
        raise ValueError("pdyn.solve_ivp integrates real systems: `y0` is complex (split it "
                         "into real and imaginary parts)")
    if y0_in.ndim != 1:
        raise ValueError("`y0` must be 1-dimensional.")
    y0a = np.ascontiguousarray(y0_in, dtype=np.float64)
    n = len(y0a)
    named_args = []
    if args is not None:
        if isinstance(args, Mapping):
            if callable(fun):
                raise TypeError("args should be a tuple (a dict of values is for expression "
                                "strings)")
            named_args = [(str(k), float(v)) for k, v in args.items()]
            args = None
        else:
            try:
                args = tuple(args)
            except TypeError as e:
                raise TypeError("args should be a tuple") from e
            if not callable(fun):
                raise TypeError("args for expression strings must be a dict {name: value}")
    fun = _bind(fun, args)
    jac = _bind(jac, args)
    key = method.lower()
    note = None
    if key in _MAPPED:
        key, note = _MAPPED[key]
    if jac is not None and key in _EXPLICIT:
        warnings.warn("The following arguments have no effect for a chosen solver: `jac`.",
                      stacklevel=2)
        jac = None
    if jac is not None and not callable(jac):
        jac = np.asarray(jac, dtype=np.float64)
        if jac.shape != (n, n):
            raise ValueError(f"`jac` is expected to have shape {(n, n)}, but actually has "
                             f"{jac.shape}.")
    ev_list = []
    if events is not None:
        # One event: a callable, an expression, or an (expression, terminal, direction)
        # tuple; otherwise a sequence of them (SciPy passes a list or a tuple of callables).
        if callable(events) or isinstance(events, str) or (
                isinstance(events, tuple) and events and isinstance(events[0], str)):
            events = [events]
        for ev in events:
            if isinstance(ev, tuple):
                g, terminal, direction = (list(ev) + [False, 0])[:3]
            else:
                g = _bind(ev, args)
                terminal = getattr(ev, "terminal", False)
                direction = getattr(ev, "direction", 0)
            if isinstance(terminal, (bool, np.bool_)):
                term = 1 if terminal else None
            else:
                if int(terminal) != terminal or terminal < 0:
                    raise ValueError("`terminal` must be a bool or a non-negative int")
                term = int(terminal) if terminal else None
            ev_list.append((g, term, int(np.sign(direction))))
    te = None
    if t_eval is not None:
        te = np.asarray(t_eval, dtype=np.float64)
        if te.ndim != 1:
            raise ValueError("`t_eval` must be 1-dimensional.")
        lo, hi = min(t0, tf), max(t0, tf)
        if np.any(te < lo) or np.any(te > hi):
            raise ValueError("Values in `t_eval` are not within `t_span`.")
        d = np.diff(te)
        if (tf >= t0 and np.any(d <= 0)) or (tf < t0 and np.any(d >= 0)):
            raise ValueError("Values in `t_eval` are not properly sorted.")
        te = np.ascontiguousarray(te)
    if max_step is None or not max_step > 0:
        raise ValueError("`max_step` must be positive.")
    if first_step is not None:
        if not first_step > 0:
            raise ValueError("`first_step` must be positive.")
        if first_step > abs(tf - t0):
            raise ValueError("`first_step` exceeds bounds.")
    if not (min_step >= 0) or math.isinf(min_step):
        raise ValueError("`min_step` must be finite and non-negative.")
    radau = key in ("radau", "radau5")
    if type(rtol) in (float, int) and type(atol) in (float, int) and not radau:
        # The common case, checked without NumPy (this runs once per call, and a compiled
        # solve can take less than 0.1 ms).
        r, a = [float(rtol)], [float(atol)]
        if r[0] < 100 * _EPS:
            warnings.warn("At least one element of `rtol` is too small. Setting "
                          f"`rtol = np.maximum(rtol, {100 * _EPS})`.", stacklevel=2)
            r = [100 * _EPS]
        if a[0] < 0:
            raise ValueError("`atol` must be positive.")
    else:
        r = _tol(rtol, "rtol", n)
        if np.any(r < 100 * _EPS):
            warnings.warn("At least one element of `rtol` is too small. Setting "
                          f"`rtol = np.maximum(rtol, {100 * _EPS})`.", stacklevel=2)
            r = np.maximum(r, 100 * _EPS)
        a = _tol(atol, "atol", n)
        if np.any(a < 0):
            raise ValueError("`atol` must be positive.")
        if radau:
            # Hairer's Radau5 reads its tolerances as rtol' = 0.1 rtol^(2/3),
            # atol' = rtol' atol/rtol (radau5.f); SciPy's Radau applies rtol and atol as
            # given. These are the tolerances that Radau5 turns into the requested ones, so
            # that the error test is SciPy's.
            rh = np.maximum((10.0 * r) ** 1.5, 1e-14)
            a, r = a * rh / r, rh
        r, a = r.tolist(), a.tolist()
    pattern = None
    if sparsity is not None and jac is None:
        # As (rows, columns) of the entries: a sparse matrix is never made dense (a 10^5
        # state's n × n array would not fit), and the pattern reaches Radau5's sparse LU.
        if hasattr(sparsity, "tocoo"):
            coo = sparsity.tocoo()
            if coo.shape != (n, n):
                raise ValueError("`jac_sparsity` has wrong shape.")
            nz = np.asarray(coo.data) != 0
            rows, cols = np.asarray(coo.row)[nz], np.asarray(coo.col)[nz]
        else:
            sp = np.asarray(sparsity)
            if sp.shape != (n, n):
                raise ValueError("`jac_sparsity` has wrong shape.")
            rows, cols = np.nonzero(sp)
        pattern = (rows.astype(np.int64).tolist(), cols.astype(np.int64).tolist())
    elif (lband is not None or uband is not None) and jac is None:
        lo, up = int(lband or 0), int(uband or 0)
        if lo < 0 or up < 0:
            raise ValueError("`lband` and `uband` must be non-negative")
        rows, cols = [], []
        for offset in range(-min(lo, n - 1), min(up, n - 1) + 1):
            i = np.arange(max(0, -offset), min(n, n - offset))
            rows.append(i)
            cols.append(i + offset)
        pattern = (np.concatenate(rows).tolist(), np.concatenate(cols).tolist())
    if max_steps is not None and int(max_steps) < 1:
        raise ValueError("`max_steps` must be a positive integer")
    raw = _pdyn._solve_ivp(fun, t0, tf, y0a, key, te, r, a,
                           None if math.isinf(max_step) else float(max_step),
                           None if first_step is None else float(first_step),
                           float(min_step) if min_step > 0 else None,
                           None if max_steps is None else int(max_steps), ev_list, named_args,
                           bool(dense_output), bool(jit), jac, bool(vectorized), pattern)
    if note is not None:
        raw["message"] = f"{raw['message']} ({note})"
    res = _from_ivp(raw, len(ev_list), n)
    res["nfev"], res["njev"], res["nlu"] = raw["nfev"], raw["njev"], raw["nlu"]
    res["sol"] = raw.get("sol")
    if raw.get("interrupted"):
        from ._errors import Interrupted
        raise Interrupted(f"solve_ivp {raw['message'].split(';')[0]}; what was computed is in "
                          ".result", res)
    return res
