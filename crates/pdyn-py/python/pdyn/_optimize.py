"""``pdyn.Model.optimize``: the parameter values within bounds that maximise (or minimise) one
of a model's sweep measures, computed by ``pdyn optimize``'s library code (``pdyn::optimize``)."""
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple


class OptimizeResult(dict):
    """The optimum, as SciPy's ``OptimizeResult`` (a dict with attribute access):

    - ``x``: the parameters' values, in the order of ``names`` (the ``over`` keys);
    - ``fun``: the measure there; ``nfev``: runs made; ``success``;
    - ``method``: ``"brent"`` (one parameter: Brent's method, then the zero of the measure's
      slope, whose final bracket is ``slope_bracket``) or ``"nelder-mead"``;
    - ``at_bound``: the optimum is at a bound (it may lie outside).
    """

    def __init__(self, raw: Dict[str, Any]):
        super().__init__(raw)

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(name) from e


def optimize(self: Any, over: Mapping[str, Tuple[float, float]],
             maximize: Optional[str] = None, minimize: Optional[str] = None,
             params: Optional[Mapping[str, float]] = None,
             measures: Optional[Mapping[str, Tuple[str, str]]] = None,
             jit: bool = True) -> OptimizeResult:
    """Like ``pdyn optimize MODEL --maximize MEASURE --over theta=0..pi/2``: ``over`` maps each
    parameter varied to its bounds (``{"theta": (0, math.pi/2)}``), ``maximize`` (or
    ``minimize``) names a measure of the model's ``[sweep.measures]``, or of ``measures``
    (``{"range": ("x", "final")}``, as :meth:`Model.sweep` takes them); ``params`` sets other
    parameter values. Returns an :class:`OptimizeResult`."""
    from . import _pdyn
    if (maximize is None) == (minimize is None):
        raise ValueError("give exactly one of maximize= and minimize= (a measure's name)")
    measure = maximize if maximize is not None else minimize
    ms = None if measures is None else [(str(k), str(v[0]), str(v[1])) for k, v in measures.items()]
    ps = None if params is None else [(str(k), float(v)) for k, v in params.items()]
    bounds = [(str(k), float(lo), float(hi)) for k, (lo, hi) in over.items()]
    raw = _pdyn._optimize(self._mechanics(), str(measure), bounds, maximize=maximize is not None,
                          params=ps, measures=ms, jit=bool(jit))
    return OptimizeResult(raw)
