"""Exceptions and warnings of pdyn (raised by the Rust part, ``pdyn._pdyn``)."""

from typing import Optional


class PdynError(Exception):
    """Base class of every error pdyn raises."""


class ModelError(PdynError, ValueError):
    """A model that does not load.

    ``str(e)`` is the full report (file:line:column, the offending line, a caret, help);
    the attributes locate it: ``file``, ``line`` and ``column`` (1-based, ``None`` when
    unknown) and ``message`` (what is wrong, one line). From :func:`pdyn.kin` and
    :func:`pdyn.dsolve`, ``file`` names the command's argument (``<position>``, ``--at``) and
    ``argument`` the Python keyword (``position``, ``at``); ``""`` otherwise.
    """

    def __init__(self, text: str, file: str = "", line: Optional[int] = None,
                 column: Optional[int] = None, message: str = ""):
        super().__init__(text)
        self.file = file
        self.line = line
        self.column = column
        self.message = message or text
        self.argument = ""


class ParameterError(PdynError, ValueError):
    """An invalid argument: an unknown parameter or method, a value out of range
    (a mass <= 0, rtol < 0, t_eval outside [0, t_end]...)."""


class DriftWarning(UserWarning):
    """A quantity that should be conserved (energy, angular momentum) drifted by more than
    the drift tolerance: the result cannot be trusted (tighten rtol or use a symplectic
    method).

    Typed: ``quantity`` (the monitor's name, e.g. ``"energy"``), ``drift`` (relative to the
    quantity's scale, or absolute when ``relative`` is False; NaN when it became NaN),
    ``tolerance`` (the run's drift tolerance). ``str(w)`` is the full message.
    """

    def __init__(self, message: str, quantity: str = "", drift: float = float("nan"),
                 tolerance: float = float("nan"), relative: bool = True):
        super().__init__(message)
        self.quantity = quantity
        self.drift = drift
        self.tolerance = tolerance
        self.relative = relative


class Interrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) stopped a long call: ``Model.run``, ``sweep``, ``ensemble`` or
    ``solve_ivp``.

    A subclass of ``KeyboardInterrupt`` (``except KeyboardInterrupt`` catches it): the call
    stopped at its next step, within tens of milliseconds, and ``result`` holds what was
    computed until then (the partial :class:`OdeResult`, ``ParticleResult``, ``SweepResult`` or
    ``EnsembleResult``; runs that had not finished carry their failure, measures NaN;
    ``solve_ivp``'s partial ``OdeResult``, ``status`` -1).
    """

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result
