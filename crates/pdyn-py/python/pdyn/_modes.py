"""The result of :meth:`pdyn.Model.modes`."""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional


class Modes:
    """Natural frequencies and mode shapes of ``K φ = ω² M φ`` about a state at rest, lowest
    first (what ``pdyn modes`` prints).

    ``omega`` (rad/s; NaN for an unstable mode, ``omega_squared < 0``), ``freq_hz``, ``period``
    (s), ``omega_squared``, ``shapes`` (``n × k``: column ``j`` is mode ``j``, scaled so that its
    largest component is +1, rows in the order of ``coordinates``), ``modal_mass`` and
    ``modal_stiffness`` (``φᵀ M φ``, ``φᵀ K φ`` with that scaling), ``q`` (the state),
    ``residual`` (``|f|`` there), ``solver`` (``"dense"``: every mode; ``"sparse"``: the lowest
    ``count`` by shift-invert Lanczos), ``about``. ``participation`` and ``effective_mass``
    (``k × 3``: per mode, along x, y, z) are ``Γ = φᵀ M r / φᵀ M φ`` and ``(φᵀ M r)² / φᵀ M φ``,
    with ``M r`` the inertia load of a unit ground acceleration along the axis; ``total_mass``
    (3) is what all modes' effective masses add up to, so ``effective_mass.sum(axis=0) /
    total_mass`` is the share the modes found carry. With damping (``C ≠ 0``),
    ``natural_frequency``, ``damping_ratio`` and ``damped_frequency`` of the roots of
    ``det(s² M + s C + K) = 0``, and ``damped_path`` says how they were found:
    ``"classical"`` (``C M⁻¹ K = K M⁻¹ C``: from the undamped modes computed, one oscillator
    each, any size), ``"companion"`` (every root of the dense companion form, up to 1,000
    coordinates) or ``"not_computed"`` (non-classical damping on more coordinates: the
    arrays are ``None``); without damping all four are ``None``."""

    def __init__(self, raw: Dict[str, Any]):
        import numpy as np
        self.omega = raw["omega"]
        self.omega_squared = raw["omega_squared"]
        self.freq_hz = self.omega / (2 * math.pi)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.period = 2 * math.pi / self.omega
        self.shapes = raw["shapes"]
        self.modal_mass = raw["modal_mass"]
        self.modal_stiffness = raw["modal_stiffness"]
        self.participation = raw["participation"]
        self.effective_mass = raw["effective_mass"]
        self.total_mass = raw["total_mass"]
        self.coordinates: List[str] = list(raw["coordinates"])
        self.q = raw["q"]
        self.residual: float = float(raw["residual"])
        self.solver: str = raw["solver"]
        self.about: str = raw["about"]
        self.stiffness_asymmetry: float = float(raw["stiffness_asymmetry"])
        damped: Optional[Dict[str, Any]] = raw["damped"]
        self.natural_frequency = damped["natural_frequency"] if damped else None
        self.damping_ratio = damped["damping_ratio"] if damped else None
        self.damped_frequency = damped["damped_frequency"] if damped else None
        self.damped_path: Optional[str] = raw.get("damped_path")

    def __len__(self) -> int:
        return len(self.omega)

    def __repr__(self) -> str:
        shown = ", ".join(f"{w:.6g}" for w in self.omega[:4])
        more = ", ..." if len(self.omega) > 4 else ""
        return f"Modes({len(self)} modes, {self.solver}, omega = [{shown}{more}] rad/s)"
