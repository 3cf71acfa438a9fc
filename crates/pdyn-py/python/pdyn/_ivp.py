"""``pdyn.solve_ivp``: SciPy's ``solve_ivp`` on pdyn's integrators (re-exported by
``pdyn``)."""

from __future__ import annotations

import math
from typing import Any, Callable, Mapping, Optional, Sequence, Tuple, Union

from ._lazy import LazyModule

np = LazyModule("numpy")  # imported on first use

from . import _pdyn
from ._result import DenseOutput, OdeResult, _from_ivp


def _array1(x, name: str) -> np.ndarray:
    a = np.ascontiguousarray(np.asarray(x, dtype=np.float64).ravel())
    if a.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional")
    return a


def _tol(x, name: str):
    a = np.asarray(x, dtype=np.float64).ravel()
    if a.size == 0:
        raise ValueError(f"{name} is empty")
    return [float(v) for v in a]


def solve_ivp(fun: Union[Callable[..., Any], Sequence[str]], t_span: Tuple[float, float],
              y0: Sequence[float], method: str = "DOP853",
              t_eval: Optional[Sequence[float]] = None, dense_output: bool = False,
              events: Optional[Any] = None, vectorized: bool = False,
              args: Optional[Any] = None, rtol: Union[float, Sequence[float]] = 1e-3,
              atol: Union[float, Sequence[float]] = 1e-6, max_step: float = math.inf,
              first_step: Optional[float] = None, max_steps: Optional[int] = None,
              jit: bool = True, **options: Any) -> OdeResult:
    """Solves ``y' = fun(t, y)`` with SciPy's signature and result, integrated by pdyn.

    ``fun`` is either a Python callable ``fun(t, y) -> array`` (called with the GIL held for
    each evaluation), or a list of expression strings in ``t`` and ``y0, y1, ...`` (and the
    names of ``args`` when it is a dict of numbers), compiled once: no Python in the loop,
    the GIL released. ``events``: callables with SciPy's ``terminal``/``direction``
    attributes, or expression strings (a ``(expression, terminal, direction)`` tuple sets
    them). ``method``: ``"RK45"`` (DOPRI5), ``"DOP853"``, ``"Radau"``, or pdyn's
    (``"Tsit5"``, ``"Vern9"``, ...; :func:`methods`).

    Returns an :class:`OdeResult`; ``nfev`` is the Rust solver's count (``stats`` has all).
    A numerical failure returns ``success=False``, ``status=-1`` and the partial solution.
    ``dense_output=True`` sets ``sol.sol``, a :class:`DenseOutput` callable ``sol.sol(t)``
    as SciPy's: a cubic Hermite interpolant through every step (its error is O(h^4) in the
    step size h -- coarser than the methods' own continuous extensions; the values at the
    steps are exact). ``vectorized=True`` is not supported.

    Compiled expressions run as native code (the Cranelift JIT of ``pdyn-jit``, compiled once
    per distinct list of expressions and cached), with pdyn's interpreter as the fallback
    where there is no JIT or with ``jit=False``; both give the same bits.
    ``sol.native`` says which ran.
    """
    if options:
        raise TypeError(f"pdyn.solve_ivp: unsupported options {sorted(options)}")
    t0, tf = (float(t_span[0]), float(t_span[1]))
    y0a = _array1(y0, "y0")
    named_args = []
    if args is not None:
        if isinstance(args, Mapping):
            named_args = [(str(k), float(v)) for k, v in args.items()]
        elif callable(fun):
            user_fun, extra = fun, tuple(args)
            fun = lambda t, y: user_fun(t, y, *extra)  # noqa: E731
        else:
            raise TypeError("args for expression strings must be a dict {name: value}")
    ev_list = []
    if events is not None:
        if callable(events) or isinstance(events, (str, tuple)):
            events = [events]
        for ev in events:
            if isinstance(ev, tuple):
                g, terminal, direction = (list(ev) + [False, 0])[:3]
            else:
                g = ev
                terminal = getattr(ev, "terminal", False)
                direction = getattr(ev, "direction", 0)
            if isinstance(terminal, bool):
                term = 1 if terminal else None
            else:
                term = int(terminal) if terminal else None
            ev_list.append((g, term, int(np.sign(direction))))
    if vectorized:
        raise NotImplementedError("pdyn.solve_ivp: vectorized=True is not supported (fun is "
                                  "called with one state at a time; it may still be vectorized)")
    te = None if t_eval is None else _array1(t_eval, "t_eval")
    common = (str(method), _tol(rtol, "rtol"), _tol(atol, "atol"),
              None if math.isinf(max_step) else float(max_step),
              None if first_step is None else float(first_step), max_steps, ev_list, named_args)

    def solve(t_eval_, dense):
        m_, r_, a_, ms_, fs_, mx_, ev_, na_ = common
        return _pdyn._solve_ivp(fun, t0, tf, y0a, m_, t_eval_, r_, a_, ms_, fs_, mx_, ev_, na_,
                                dense, bool(jit))

    raw = solve(te, dense_output and te is None)
    res = _from_ivp(raw, len(ev_list), len(y0a))
    if dense_output:
        # The interpolant needs every step: with t_eval, a second solve without it (the
        # same steps; the result's t and y stay at t_eval).
        steps = raw if te is None else solve(None, True)
        res["sol"] = DenseOutput(steps["t"], np.ascontiguousarray(steps["y_rows"].T),
                                 np.ascontiguousarray(steps["f_rows"].T))
    return res
