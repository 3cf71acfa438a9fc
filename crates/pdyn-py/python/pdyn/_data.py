"""Measured motion from Python: ``pdyn.kin_data`` (``pdyn kin --data``),
``pdyn.integrate_accel`` (``pdyn kin --data FILE --from accel``), ``pdyn.fuse`` (``pdyn fuse``)
and ``pdyn.read_csv``.

The computations are the library's (``pdyn::data``, crate ``pdyn-data``), the same as the
commands'; see ``docs/data.md`` for the methods (smoothing spline with λ by generalized
cross-validation, its standard errors, quadrature orders, the Kalman/RTS model). Arrays come
back as float64 NumPy arrays; bad data raise :class:`~pdyn.ModelError` located by ``file``
(the file, or the argument: ``t``, ``x``...), ``line`` and ``column`` (for arrays, the message
names the index).
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _pdyn
from ._lazy import LazyModule

np = LazyModule("numpy")  # imported on first use

_PathLike = Union[str, "os.PathLike[str]"]


def _array1(x: Any, name: str):
    a = np.ascontiguousarray(np.asarray(x, dtype=np.float64))
    if a.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional (got shape {a.shape})")
    return a


def read_csv(path: _PathLike, columns: Optional[Sequence[str]] = None,
             kind: str = "position") -> Tuple[List[str], Any, List[Any]]:
    """Reads a time series from a CSV or Parquet file (told apart by its bytes) as ``pdyn kin
    --data`` does: ``(names, t, values)``,
    the time first in ``columns`` (default ``t,x,y[,z]``, or with ``kind="accel"`` ``t`` and
    every column whose name starts with ``a``). Errors are located (file, line, column; a
    Parquet file's by row)."""
    return _pdyn._read_csv(os.fspath(path), list(columns or []), kind)


def interp(t: Any, y: Any, at: Any, kind: str = "linear"):
    """Interpolates samples ``(t, y)`` at the times ``at``: ``kind="linear"``, ``"cubic"``
    (natural cubic spline, as SciPy's ``CubicSpline(bc_type="natural")``) or ``"pchip"``
    (monotone, as SciPy's ``PchipInterpolator``). Times must increase strictly; a time in
    ``at`` outside ``[t[0], t[-1]]`` raises :class:`~pdyn.ModelError` (data say nothing
    there)."""
    at_arr = np.atleast_1d(np.asarray(at, dtype=np.float64))
    out = _pdyn._interp(_array1(t, "t"), _array1(y, "y"), np.ascontiguousarray(at_arr.ravel()), kind)
    return out.reshape(at_arr.shape) if np.ndim(at) else out[0]


class _Table:
    """A result's columns as attributes and by name."""

    def __init__(self, columns: Dict[str, Any], summary: Dict[str, Any]):
        self.columns = columns
        self.summary = summary

    def __getitem__(self, name: str):
        return self.columns[name]

    def __getattr__(self, name: str):
        cols = self.__dict__.get("columns", {})
        if name in cols:
            return cols[name]
        raise AttributeError(name)

    def keys(self):
        return self.columns.keys()

    def to_csv(self, path: _PathLike) -> None:
        """Writes the columns as CSV (the command's table)."""
        names = list(self.columns)
        data = np.column_stack([self.columns[n] for n in names])
        np.savetxt(os.fspath(path), data, delimiter=",", header=",".join(names), comments="",
                   fmt="%.17g")


class KinDataResult(_Table):
    """Kinematics from samples. Columns (``result["v_x"]`` or ``result.speed``): ``t``, the
    smoothed positions (named as the inputs: ``x``, ``y``[, ``z``]), ``v_x``..., ``a_x``...,
    ``speed``, ``T_x``... (unit tangent), ``N_x``... (principal normal), ``curvature``, ``a_t``,
    ``a_n``, ``r``, ``theta``, ``v_r``, ``v_theta``, ``a_r``, ``a_theta``, ``se_speed``,
    ``se_a_t``, ``se_a_n``, ``se_curvature``. ``velocity`` and ``acceleration`` are ``(n, dim)``
    arrays. ``fits``: per coordinate λ, its source (``gcv``/``given``), noise σ, edf and the
    standard errors of position, velocity and acceleration; ``boundary``: the standard errors
    hold farther than this from the ends."""

    def __init__(self, columns, summary, names):
        super().__init__(columns, summary)
        self.names = names
        self.fits = summary["smoothing"]
        self.boundary = summary["boundary"]
        self.position = np.column_stack([columns[n] for n in names])
        self.velocity = np.column_stack([columns["v_" + n] for n in names])
        self.acceleration = np.column_stack([columns["a_" + n] for n in names])

    def __repr__(self) -> str:
        lams = ", ".join(f"{f['column']}: λ={f['lambda']:.3g} ({f['lambda_from']})" for f in self.fits)
        return f"KinDataResult({len(self.columns['t'])} samples; {lams})"


def kin_data(t: Any, x: Any = None, y: Any = None, z: Any = None, *,
             lam: Union[None, str, float] = None,
             columns: Optional[Sequence[str]] = None) -> KinDataResult:
    """Kinematics from sampled positions (``pdyn kin --data``): each coordinate smoothed by a
    cubic smoothing spline, λ chosen by generalized cross-validation (``lam=None`` or
    ``"gcv"``) or given (``lam=1e-3``; 0 interpolates), differentiated at the sample times.

    ``t`` is the array of times (strictly increasing) with ``x``, ``y`` [, ``z``] arrays, or a
    CSV or Parquet file's path (then ``columns`` names the time and position columns, default
    ``t,x,y[,z]``)."""
    if isinstance(t, (str, os.PathLike)):
        if x is not None:
            raise TypeError("kin_data(path) reads the positions from the file: give columns=, not x, y")
        names, tt, values = read_csv(t, columns, "position")
    else:
        if x is None or y is None:
            raise TypeError("kin_data(t, x, y[, z]) needs at least x and y")
        names = ["x", "y"] + (["z"] if z is not None else [])
        values = [_array1(v, n) for v, n in zip((x, y, z), names)]
        tt = _array1(t, "t")
    if isinstance(lam, str):
        if lam.lower() != "gcv":
            raise ValueError(f"lam={lam!r}: give 'gcv', None or a number >= 0")
        lam = None
    cols, summary = _pdyn._kin_data(tt, values, list(names), lam)
    return KinDataResult(cols, json.loads(summary), list(names))


class IntegratedAccel(_Table):
    """Sampled acceleration integrated. Columns: ``t``, then per axis (named from the
    acceleration's: ``ax`` → ``x``) the position ``x``, velocity ``v_x`` and the stated error
    growth ``sigma_x``, ``sigma_v_x``. ``axes``: per axis the bias removed and its standard
    error, σ_a and where it came from, final position and velocity with their σ."""

    def __init__(self, columns, summary):
        super().__init__(columns, summary)
        self.axes = summary["axes"]

    def __repr__(self) -> str:
        return f"IntegratedAccel({len(self.columns['t'])} samples, axes {[a['axis'] for a in self.axes]})"


def _bias_text(bias: Any) -> str:
    if bias is None:
        return "none"
    if isinstance(bias, str):
        return bias
    if isinstance(bias, (tuple, list)) and len(bias) == 2:
        return f"{float(bias[0])!r}..{float(bias[1])!r}"
    return repr(float(bias))


def integrate_accel(t: Any, *a: Any, v0: Any = 0.0, x0: Any = 0.0, rule: str = "simpson",
                    bias: Any = None, sigma_a: Optional[float] = None,
                    names: Optional[Sequence[str]] = None,
                    columns: Optional[Sequence[str]] = None) -> IntegratedAccel:
    """Integrates sampled acceleration to velocity and position (``pdyn kin --data FILE
    --from accel``): ``integrate_accel(t, ax[, ay[, az]], v0=..., x0=...)`` or
    ``integrate_accel("acc.csv")``. ``rule``: ``"simpson"`` (4th order) or ``"trapezoid"``;
    ``bias``: ``None``, ``"mean"``, a quiet interval ``(t0, t1)`` or a value; ``v0``/``x0``: a
    number or one per axis; ``sigma_a``: the accelerometer noise for the error estimate."""
    if isinstance(t, (str, os.PathLike)):
        if a:
            raise TypeError("integrate_accel(path) reads the accelerations from the file")
        acc_names, tt, values = read_csv(t, columns, "accel")
    else:
        if not a:
            raise TypeError("integrate_accel(t, ax[, ay[, az]]) needs at least one acceleration array")
        acc_names = list(names) if names else ["ax", "ay", "az"][: len(a)] if len(a) <= 3 else [f"a{i}" for i in range(len(a))]
        values = [_array1(v, n) for v, n in zip(a, acc_names)]
        tt = _array1(t, "t")
    n = len(values)
    per_axis = lambda v: [float(v)] * n if np.ndim(v) == 0 else [float(x) for x in v]
    cols, summary = _pdyn._integrate_accel(tt, values, list(acc_names), per_axis(v0), per_axis(x0),
                                           rule, _bias_text(bias), sigma_a)
    return IntegratedAccel(cols, json.loads(summary))


class FuseResult(_Table):
    """The smoothed (RTS) estimate at the accelerometer's times. Columns: ``t``, then per axis
    (named as the fixes: ``x``...) ``x``, ``v_x``, ``bias_x``, their standard deviations
    ``sd_x``, ``sd_v_x``, ``sd_bias_x``, and the causal filter's ``x_filtered``. ``sigma_a``,
    ``sigma_p``, ``sigma_b``: the noise levels used (estimated unless given);
    ``log_likelihood`` of the innovations; ``covariance``: ``(axes, n, 3, 3)`` when asked for."""

    def __init__(self, columns, summary, covariance, names):
        super().__init__(columns, summary)
        self.names = names
        self.sigma_a = summary["sigma_a"]
        self.sigma_p = summary["sigma_p"]
        self.sigma_b = summary["sigma_b"]
        self.log_likelihood = summary["log_likelihood"]
        n = len(columns["t"])
        self.covariance = None if covariance is None else covariance.reshape(len(names), n, 3, 3)

    def __repr__(self) -> str:
        return (f"FuseResult({len(self.columns['t'])} samples, axes {self.names}, "
                f"sigma_a={self.sigma_a:.3g}, sigma_p={self.sigma_p:.3g})")


def fuse(ta: Any, a: Any = None, tf: Any = None, fixes: Any = None, *,
         sigma_a: Optional[float] = None, sigma_p: Optional[float] = None, sigma_b: float = 0.0,
         bias0: float = 1.0, v0_sd: float = 1e3, p0_sd: float = 1e4,
         names: Optional[Sequence[str]] = None, covariance: bool = False,
         accel_columns: Optional[Sequence[str]] = None,
         fix_columns: Optional[Sequence[str]] = None) -> FuseResult:
    """Fuses an accelerometer record with position fixes (``pdyn fuse``): a Kalman filter and
    Rauch–Tung–Striebel smoother per axis, state (position, velocity, accelerometer bias).

    Arrays: ``fuse(ta, a, tf, fixes)`` with ``a`` and ``fixes`` of shape ``(n,)`` (one axis) or
    ``(n, axes)``; files: ``fuse("imu.csv", fixes="gps.csv")`` (``tf`` unused). Noise levels
    not given are estimated: ``sigma_a`` from the accelerometer's second differences,
    ``sigma_p`` by maximum likelihood of the innovations. ``sigma_b``: bias random walk
    (0: constant bias); ``bias0``, ``v0_sd``, ``p0_sd``: prior standard deviations of the bias,
    the initial velocity and position (about 0, 0 and the first fix)."""
    if isinstance(ta, (str, os.PathLike)):
        if not isinstance(fixes, (str, os.PathLike)):
            raise TypeError("fuse(accel_path, fixes=fixes_path): both must be files")
        _, tta, avals = read_csv(ta, accel_columns, "accel")
        fnames, ttf, fvals = read_csv(fixes, fix_columns, "position")
        if not fix_columns and len(fvals) > len(avals):
            fnames, fvals = fnames[: len(avals)], fvals[: len(avals)]
        names = list(fnames)
    else:
        tta, ttf = _array1(ta, "ta"), _array1(tf, "tf")
        A = np.asarray(a, dtype=np.float64)
        F = np.asarray(fixes, dtype=np.float64)
        A = A.reshape(-1, 1) if A.ndim == 1 else A
        F = F.reshape(-1, 1) if F.ndim == 1 else F
        avals = [np.ascontiguousarray(A[:, i]) for i in range(A.shape[1])]
        fvals = [np.ascontiguousarray(F[:, i]) for i in range(F.shape[1])]
        names = list(names) if names else (["x", "y", "z"][: len(fvals)] if len(fvals) <= 3
                                             else [f"p{i}" for i in range(len(fvals))])
    cols, summary, cov = _pdyn._fuse(tta, avals, ttf, fvals, names, sigma_a, sigma_p, sigma_b,
                                     bias0, v0_sd, p0_sd, covariance)
    return FuseResult(cols, json.loads(summary), cov, names)
