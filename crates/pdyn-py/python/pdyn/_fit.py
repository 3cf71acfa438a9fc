"""The result of :meth:`pdyn.Model.fit`: SciPy's ``least_squares`` fields plus the statistics
of the estimates."""
from typing import Any, Dict


class FitResult(dict):
    """Parameters and initial values fitted to measured runs, as SciPy's ``OptimizeResult``
    (a dict with attribute access):

    - ``x``: the estimates, in the order of ``names`` (the free quantities; an initial value
      per experiment when there are several, ``initial.x[run2]``);
    - ``cost`` (``½ Σ fun²``), ``fun`` (the weighted residuals ``(model − data)/σ``,
      experiment by experiment, column by column, sample by sample), ``jac`` (``∂fun/∂x``,
      from the sensitivity equations), ``status``, ``message``, ``success``, ``nfev``;
    - ``stderr``, ``corr``, ``cov`` (``s² (JᵀJ)⁻¹`` with ``s² = χ²/dof``, or ``(JᵀJ)⁻¹`` with
      ``absolute_sigma=True``), ``chi2``, ``dof``, ``reduced_chi2``;
    - ``unidentifiable`` (groups of names the data cannot tell apart), ``warnings``;
    - ``experiments``: per experiment ``t`` and for each column ``data``, ``model``,
      ``sigma``, ``rms``.
    """

    def __init__(self, raw: Dict[str, Any]):
        super().__init__(raw)
        self["reduced_chi2"] = raw["chi2"] / raw["dof"]

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(name) from e

    def __dir__(self):
        return list(self.keys())

    def __repr__(self) -> str:
        return self["summary"]
