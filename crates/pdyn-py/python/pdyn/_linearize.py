"""The result of :meth:`pdyn.Model.linearize`."""

from __future__ import annotations

from typing import Any, Dict, List


class Linearization:
    """``δy' = A δy`` about ``y0`` (``state`` names its components), and for ``y = (q, q')``
    the second-order form ``δq'' + C δq' + K δq = 0``.

    ``A`` (``2n × 2n``), ``K`` and ``C`` (``n × n``), ``f0`` (``f(t, y0)``: zero at an
    equilibrium), ``y0``, ``state``, ``analytic``; :meth:`eigenvalues` of ``A`` (the
    linearized motion's rates: ``±iω`` for an undamped oscillation)."""

    def __init__(self, raw: Dict[str, Any]):
        self.A = raw["A"]
        self.K = raw["K"]
        self.C = raw["C"]
        self.f0 = raw["f0"]
        self.y0 = raw["y0"]
        self.state: List[str] = list(raw["state"])
        self.analytic: bool = bool(raw["analytic"])

    def eigenvalues(self):
        """The eigenvalues of ``A`` (NumPy)."""
        import numpy as np
        return np.linalg.eigvals(self.A)

    def __repr__(self) -> str:
        return f"Linearization(state={self.state}, |f0| = {abs(self.f0).max():.3g})"
