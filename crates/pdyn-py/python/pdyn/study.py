"""Parameter studies and Monte Carlo ensembles: a model, a design, measures -- run on this
machine (the Rust ensemble on all cores) or on a Dask cluster, checkpointed chunk by chunk
to Parquet.

::

    import pdyn
    from pdyn.study import Study, Samples, normal

    m = pdyn.Model.from_file("examples/kremlin_stone.toml")
    design = Samples(2000, seed=1, v0=normal(11.176, 1.0), theta=normal(0.785, 0.087))
    study = Study(m, design, measures={"range": ("x", "final")}, out="kremlin-study")
    res = study.run()                         # local: all cores
    res = study.run(client=distributed.Client("tcp://scheduler:8786"))   # the same on Dask
    res.table                                 # pandas DataFrame, one row per sample
    res.probability("range > 40")             # estimate and Wilson confidence interval

A design is refused before anything runs when a name is not a parameter or a state
component, a distribution's spread is negative, a grid is empty, or a sample gives the model
an invalid value (a mass <= 0): :class:`DesignError`.

With ``out=DIR`` every finished chunk is written to ``DIR/chunk-NNNNN-KEY.parquet`` (the key
hashes the model text, the design, the measures and settings, and the chunk's rows) with
the model text, pdyn's version, the seed and the design in the file's metadata. Running the
same study again skips the chunks already written: an interrupted study resumes, and no
chunk is ever counted twice. A folder holds one study (``_pdyn_study.json`` names it): another
study's ``out=`` there raises :class:`OutputFolderError`, so that ``pandas.read_parquet(DIR)``
never mixes two. The files are written by the client, so a worker lost in the
middle of a chunk loses nothing written (Dask runs its chunk again elsewhere).

Command line: ``python -m pdyn.study MODEL --design study.toml --out DIR
[--scheduler ADDRESS]`` (also installed as ``pdyn-study``).
"""

import hashlib
import itertools
import json
import math
import os
import sys
import time
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ._errors import ParameterError

__all__ = [
    "Study", "StudyResult", "Grid", "Sets", "Samples", "normal", "uniform", "lognormal",
    "DesignError", "OutputFolderError", "Probability", "load_design", "main",
]

#: Runs per task when ``chunk_size`` is not given: the smallest chunk at which the measured
#: Dask per-task overhead (~15 ms) is a few per cent of a chunk of building runs
#: (docs/benchmarks-python.md).
DEFAULT_CHUNK_SIZE = 1000


class DesignError(ParameterError):
    """A design the model cannot run: an unknown name, a negative spread, an empty grid, a
    sample that gives an invalid value (a mass <= 0). Raised before any run starts."""


class OutputFolderError(ParameterError):
    """``out=`` names a folder that holds another study (another model, design, measures or
    settings): its chunks and this study's would be read back mixed (``pandas.read_parquet``
    of the folder). Raised before any run starts; choose another folder or empty it."""


# The study a folder holds; underscore-prefixed, so that pyarrow and pandas reading the folder
# as a dataset skip it (as they skip the hidden temporary files of chunks being written).
MANIFEST = "_pdyn_study.json"


# ---------------------------------------------------------------------------------------
# Distributions and designs
# ---------------------------------------------------------------------------------------

class Distribution:
    """A distribution of one design variable: :func:`normal`, :func:`uniform`,
    :func:`lognormal`."""

    def __init__(self, kind: str, a: float, b: float):
        self.kind, self.a, self.b = kind, float(a), float(b)

    def describe(self) -> Dict[str, Any]:
        names = {"normal": ("mean", "sd"), "uniform": ("low", "high"),
                 "lognormal": ("mu", "sigma")}[self.kind]
        return {"dist": self.kind, names[0]: self.a, names[1]: self.b}

    def check(self, name: str) -> None:
        if not (math.isfinite(self.a) and math.isfinite(self.b)):
            raise DesignError(f"design variable `{name}`: {self.describe()} has a value that "
                              "is not finite")
        if self.kind in ("normal", "lognormal") and self.b < 0:
            what = "standard deviation" if self.kind == "normal" else "sigma"
            raise DesignError(f"design variable `{name}`: the {what} of a {self.kind} "
                              f"distribution must be >= 0, not {self.b}")
        if self.kind == "uniform" and self.b < self.a:
            raise DesignError(f"design variable `{name}`: uniform(low={self.a}, high={self.b})"
                              " has high < low")

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        if self.kind == "normal":
            return rng.normal(self.a, self.b, n)
        if self.kind == "uniform":
            return rng.uniform(self.a, self.b, n)
        return rng.lognormal(self.a, self.b, n)

    def ppf(self, u: np.ndarray) -> np.ndarray:
        from scipy import stats
        if self.kind == "normal":
            return stats.norm.ppf(u, loc=self.a, scale=self.b)
        if self.kind == "uniform":
            return self.a + (self.b - self.a) * u
        return np.exp(stats.norm.ppf(u, loc=self.a, scale=self.b))

    def __repr__(self) -> str:
        return f"{self.kind}({self.a!r}, {self.b!r})"


def normal(mean: float, sd: float) -> Distribution:
    """Normal distribution with mean ``mean`` and standard deviation ``sd`` (>= 0)."""
    return Distribution("normal", mean, sd)


def uniform(low: float, high: float) -> Distribution:
    """Uniform distribution on ``[low, high)``."""
    return Distribution("uniform", low, high)


def lognormal(mu: float, sigma: float) -> Distribution:
    """``exp(N(mu, sigma))``: NumPy's ``lognormal(mean=mu, sigma=sigma)``."""
    return Distribution("lognormal", mu, sigma)


class Design:
    """A table of runs: ``names`` (parameters or state components) and one row per run."""

    seed: Optional[int] = None

    def names(self) -> List[str]:
        raise NotImplementedError

    def matrix(self) -> np.ndarray:
        """The runs, ``(n_runs, len(names()))`` float64, in a fixed order."""
        raise NotImplementedError

    def describe(self) -> Dict[str, Any]:
        """A JSON description from which the same design can be rebuilt."""
        raise NotImplementedError


class Grid(Design):
    """Every combination of the given values: ``Grid(omega=np.linspace(2, 30, 281),
    zeta=[0.01, 0.02])``; the last name varies fastest."""

    def __init__(self, **axes: Sequence[float]):
        if not axes:
            raise DesignError("an empty grid: give at least one variable and its values")
        self.axes = {k: np.asarray(v, dtype=np.float64).ravel() for k, v in axes.items()}
        for k, v in self.axes.items():
            if v.size == 0:
                raise DesignError(f"an empty grid: variable `{k}` has no values")

    def names(self) -> List[str]:
        return list(self.axes)

    def shape(self) -> Tuple[int, ...]:
        return tuple(v.size for v in self.axes.values())

    def matrix(self) -> np.ndarray:
        mesh = np.meshgrid(*self.axes.values(), indexing="ij")
        return np.ascontiguousarray(np.column_stack([m.ravel() for m in mesh]))

    def describe(self) -> Dict[str, Any]:
        return {"kind": "grid", "variables": {k: v.tolist() for k, v in self.axes.items()}}


class Sets(Design):
    """A list of runs: ``Sets({"v0": [10, 11], "theta": [0.7, 0.8]})``, a pandas DataFrame,
    or ``Sets([{"v0": 10, "theta": 0.7}, ...])``."""

    def __init__(self, table: Any):
        if hasattr(table, "columns") and hasattr(table, "to_numpy"):
            cols = {str(c): table[c].to_numpy(dtype=np.float64) for c in table.columns}
        elif isinstance(table, Mapping):
            cols = {str(k): np.asarray(v, dtype=np.float64).ravel() for k, v in table.items()}
        else:
            rows = list(table)
            keys = list(rows[0]) if rows else []
            cols = {k: np.array([float(r[k]) for r in rows]) for k in keys}
        if not cols or min(len(v) for v in cols.values()) == 0:
            raise DesignError("an empty list of runs")
        if len({len(v) for v in cols.values()}) > 1:
            raise DesignError(f"the columns of the list of runs have different lengths: "
                              f"{ {k: len(v) for k, v in cols.items()} }")
        self.cols = cols

    def names(self) -> List[str]:
        return list(self.cols)

    def matrix(self) -> np.ndarray:
        return np.ascontiguousarray(np.column_stack(list(self.cols.values())))

    def describe(self) -> Dict[str, Any]:
        return {"kind": "list", "variables": {k: v.tolist() for k, v in self.cols.items()}}


class Samples(Design):
    """``n`` random samples: ``Samples(2000, seed=1, v0=normal(11.2, 1), theta=uniform(0.6,
    0.9))``. ``method``: ``"random"`` (NumPy's ``default_rng(seed)``, one variable after the
    other in the order given), ``"lhs"`` (Latin hypercube) or ``"sobol"`` (scrambled Sobol
    points), the last two through ``scipy.stats.qmc`` and the distributions' inverse CDFs.
    The samples are drawn once, on the client, so the runs do not depend on the chunking or
    the backend."""

    def __init__(self, n: int, seed: Optional[int] = None, method: str = "random",
                 **variables: Distribution):
        if int(n) != n or n <= 0:
            raise DesignError(f"the number of samples must be a positive integer, not {n!r}")
        if not variables:
            raise DesignError("no variables to sample: give name=normal(...), ...")
        if method not in ("random", "lhs", "sobol"):
            raise DesignError(f"unknown sampling method `{method}` (random, lhs, sobol)")
        for k, d in variables.items():
            if not isinstance(d, Distribution):
                raise DesignError(f"design variable `{k}` must be normal(...), uniform(...) "
                                  f"or lognormal(...), not {d!r}")
            d.check(k)
        self.n, self.seed, self.method, self.variables = int(n), seed, method, dict(variables)

    def names(self) -> List[str]:
        return list(self.variables)

    def matrix(self) -> np.ndarray:
        dists = list(self.variables.values())
        if self.method == "random":
            rng = np.random.default_rng(self.seed)
            return np.ascontiguousarray(np.column_stack([d.draw(rng, self.n) for d in dists]))
        try:
            from scipy.stats import qmc
        except ImportError as e:
            raise DesignError(f"method={self.method!r} needs SciPy: pip install scipy") from e
        d = len(dists)
        if self.method == "lhs":
            u = qmc.LatinHypercube(d=d, seed=self.seed).random(self.n)
        else:
            u = qmc.Sobol(d=d, scramble=True, seed=self.seed).random(self.n)
        return np.ascontiguousarray(np.column_stack([dist.ppf(u[:, j])
                                                     for j, dist in enumerate(dists)]))

    def describe(self) -> Dict[str, Any]:
        return {"kind": "samples", "n": self.n, "seed": self.seed, "method": self.method,
                "variables": {k: d.describe() for k, d in self.variables.items()}}


def design_from_dict(d: Mapping[str, Any]) -> Design:
    """A design from its description (:meth:`Design.describe`, or a ``[design]`` table of a
    study file)."""
    kind = d.get("kind")
    variables = d.get("variables") or {}
    if kind == "grid":
        axes = {}
        for k, v in variables.items():
            if isinstance(v, Mapping):
                try:
                    axes[k] = np.linspace(float(v["from"]), float(v["to"]), int(v["steps"]))
                except KeyError as e:
                    raise DesignError(f"grid variable `{k}`: give a list of values or "
                                      f"{{from, to, steps}} (missing {e})") from None
            else:
                axes[k] = v
        return Grid(**axes)
    if kind == "list":
        return Sets(variables)
    if kind == "samples":
        dists = {}
        for k, v in variables.items():
            if not isinstance(v, Mapping) or "dist" not in v:
                raise DesignError(f"sample variable `{k}`: give {{dist = \"normal\", mean, "
                                  "sd}, {dist = \"uniform\", low, high} or "
                                  "{dist = \"lognormal\", mu, sigma}")
            kinds = {"normal": ("mean", "sd"), "uniform": ("low", "high"),
                     "lognormal": ("mu", "sigma")}
            if v["dist"] not in kinds:
                raise DesignError(f"sample variable `{k}`: unknown distribution "
                                  f"`{v['dist']}` (normal, uniform, lognormal)")
            a, b = kinds[v["dist"]]
            try:
                dists[k] = Distribution(v["dist"], v[a], v[b])
            except KeyError as e:
                raise DesignError(f"sample variable `{k}`: {v['dist']} needs `{a}` and "
                                  f"`{b}` (missing {e})") from None
        if "n" not in d:
            raise DesignError("a samples design needs `n`, the number of samples")
        return Samples(d["n"], seed=d.get("seed"), method=d.get("method", "random"), **dists)
    raise DesignError(f"unknown design kind {kind!r}: grid, list or samples")


# ---------------------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------------------

_MODELS: Dict[Tuple[str, str], Any] = {}


def _model(source: str, origin: str):
    """The model for a chunk, loaded once per process: a worker running many chunks of a
    study derives and compiles it once (the compiled form is cached in the model)."""
    from . import Model
    key = (source, origin)
    m = _MODELS.get(key)
    if m is None:
        if len(_MODELS) >= 8:
            _MODELS.clear()
        m = _MODELS[key] = Model.from_toml(source, origin)
    return m


def _run_chunk(source: str, origin: str, param_names: List[str], params: np.ndarray,
               state_names: List[str], initial: Optional[np.ndarray],
               measures: Optional[Dict[str, Tuple[str, str]]], settings: Dict[str, Any],
               first: int, threads: Optional[int] = None,
               _delay: float = 0.0) -> Dict[str, np.ndarray]:
    """One chunk: the Rust ensemble over ``params``' rows (GIL released), as columns.
    Runs on a Dask worker as well as locally; everything it needs is in its arguments."""
    if _delay:
        time.sleep(_delay)
    m = _model(source, origin)
    res = m.ensemble(params=dict(zip(param_names, params.T)) if param_names else None,
                     initial=None if initial is None else dict(zip(state_names, initial.T)),
                     measures=measures, threads=threads, **settings)
    cols = {"sample": np.arange(first, first + len(res), dtype=np.int64)}
    cols.update(res.columns())
    return cols


class Probability:
    """An estimated probability ``p = k/n`` with its Wilson score interval at ``level``."""

    def __init__(self, condition: str, k: int, n: int, level: float):
        from statistics import NormalDist
        self.condition, self.k, self.n, self.level = condition, int(k), int(n), level
        self.p = k / n if n else float("nan")
        z = NormalDist().inv_cdf(0.5 + level / 2)
        denom = 1 + z * z / n
        centre = (self.p + z * z / (2 * n)) / denom
        half = z * math.sqrt(self.p * (1 - self.p) / n + z * z / (4 * n * n)) / denom
        self.low, self.high = max(0.0, centre - half), min(1.0, centre + half)

    def __contains__(self, x: float) -> bool:
        return self.low <= x <= self.high

    def __float__(self) -> float:
        return self.p

    def __repr__(self) -> str:
        return (f"P({self.condition}) = {self.p:.4g}  [{self.low:.4g}, {self.high:.4g}] "
                f"({self.level:.0%} Wilson interval, {self.k}/{self.n})")


class StudyResult:
    """A finished study: ``table`` (pandas DataFrame, one row per run in design order, with
    ``sample``, the design's parameters, its state components as ``initial.<name>``, the
    measures, event times and states, drift flags
    and status); ``chunks_run`` and ``chunks_skipped`` (already on disk); ``seconds``."""

    def __init__(self, study: "Study", table: Any, chunks_run: int, chunks_skipped: int,
                 seconds: float):
        self.study, self.table = study, table
        self.chunks_run, self.chunks_skipped, self.seconds = chunks_run, chunks_skipped, seconds

    def __repr__(self) -> str:
        return (f"StudyResult({len(self.table)} runs, {self.chunks_run} chunks run, "
                f"{self.chunks_skipped} resumed from disk, {self.seconds:.2f} s)")

    def probability(self, condition: str, level: float = 0.95) -> Probability:
        """The fraction of runs where ``condition`` (a pandas expression over the table's
        columns, e.g. ``"range > 40"``; quote odd names with backticks) holds, with a Wilson
        confidence interval. Runs that did not run (status -2) or whose condition is NaN
        are left out of ``n``."""
        t = self.table
        ok = t["status"] >= -1
        hit = t.eval(condition)
        used = ok & ~hit.isna() if hit.dtype == object else ok
        k = int((hit[used] == True).sum())  # noqa: E712 (a pandas Series)
        return Probability(condition, k, int(used.sum()), level)

    def summary(self):
        """Count, mean, std, quantiles of every numeric column (pandas ``describe``)."""
        return self.table.describe()

    def to_xarray(self):
        """A grid study as an xarray Dataset with one dimension per grid variable."""
        if not isinstance(self.study.design, Grid):
            raise TypeError("to_xarray() is for grid designs; use .table")
        import xarray as xr
        g = self.study.design
        shape = g.shape()
        data = {c: (list(g.axes), self.table[c].to_numpy().reshape(shape))
                for c in self.table.columns if c not in g.axes and c != "sample"}
        return xr.Dataset(data, coords=dict(g.axes))

    def plot(self, column: str, bins: int = 50, ax=None):
        """A histogram of ``column`` (matplotlib)."""
        import matplotlib.pyplot as plt
        if ax is None:
            _, ax = plt.subplots()
        ax.hist(self.table[column].dropna(), bins=bins)
        ax.set_xlabel(column)
        ax.set_ylabel("runs")
        return ax


class Study:
    """A model, a design and measures; :meth:`run` runs it locally or on Dask.

    ``measures``: ``{name: (expression, statistic)}`` as in :meth:`pdyn.Model.sweep`
    (every run also records final state, event times and states, drifts, status).
    ``settings``: run settings (``t_end``, ``method``, ``rtol``, ``atol``, ``max_step``,
    ``dt``, ``points``, ``drift_tolerance``). ``chunk_size``: runs per task.
    ``out``: directory for the Parquet chunks (checkpoint and resume).
    """

    def __init__(self, model: Any, design: Design,
                 measures: Optional[Mapping[str, Union[str, Tuple[str, str]]]] = None,
                 settings: Optional[Mapping[str, Any]] = None,
                 chunk_size: int = DEFAULT_CHUNK_SIZE, out: Optional[str] = None):
        from . import Model
        if not isinstance(model, Model):
            raise TypeError("model must be a pdyn.Model")
        if int(chunk_size) != chunk_size or chunk_size <= 0:
            raise DesignError(f"chunk_size must be a positive integer, not {chunk_size!r}")
        allowed = {"t_end", "method", "rtol", "atol", "max_step", "dt", "points",
                   "drift_tolerance"}
        settings = dict(settings or {})
        if set(settings) - allowed:
            raise DesignError(f"unknown settings {sorted(set(settings) - allowed)} "
                              f"(allowed: {sorted(allowed)})")
        self.model, self.design, self.settings = model, design, settings
        self.measures = None if measures is None else {
            str(k): (v, "max_abs") if isinstance(v, str) else (str(v[0]), str(v[1]))
            for k, v in measures.items()}
        self.chunk_size, self.out = int(chunk_size), out
        self._matrix: Optional[np.ndarray] = None
        self._key: Optional[str] = None
        self._meta: Optional[Dict[str, Any]] = None
        self._split: Optional[Tuple[List[str], List[int], List[str], List[int]]] = None

    # -- the design against the model ----------------------------------------------------

    def _resolve(self):
        """Which design columns are parameters and which are state components."""
        if self._split is None:
            params, states = self.model._names()
            pn, pi, sn, si = [], [], [], []
            for j, name in enumerate(self.design.names()):
                key = name[len("initial."):] if name.startswith("initial.") else name
                if name in params and not name.startswith("initial."):
                    pn.append(name)
                    pi.append(j)
                elif key in states:
                    sn.append(key)
                    si.append(j)
                else:
                    raise DesignError(
                        f"design variable `{name}` is neither a parameter ({', '.join(params)})"
                        f" nor a state component ({', '.join(states)}) of {self.model.name!r}")
            self._split = (pn, pi, sn, si)
        return self._split

    def matrix(self) -> np.ndarray:
        """The design's runs, ``(n_runs, n_variables)``, drawn once."""
        if self._matrix is None:
            self._matrix = self.design.matrix()
        return self._matrix

    def check(self) -> None:
        """Refuses a design the model cannot run (:class:`DesignError`), before any run:
        unknown names, values that are not finite, invalid values (a mass <= 0), bad
        measures or settings."""
        pn, pi, sn, si = self._resolve()
        x = self.matrix()
        if x.shape[0] == 0:
            raise DesignError("the design has no runs")
        bad = ~np.isfinite(x).all(axis=1)
        if bad.any():
            r = int(np.argmax(bad))
            raise DesignError(f"{int(bad.sum())} runs of the design have values that are "
                              f"not finite; the first is run {r}: "
                              f"{dict(zip(self.design.names(), x[r].tolist()))}")
        problems = self.model.check_ensemble(params={n: x[:, j] for n, j in zip(pn, pi)}
                                             if pn else None,
                                             initial={n: x[:, j] for n, j in zip(sn, si)}
                                             if sn else None)
        if problems:
            r, msg = problems[0]
            raise DesignError(
                f"{len(problems)} of {x.shape[0]} runs of the design give the model an "
                f"invalid value; the first is run {r} "
                f"({dict(zip(self.design.names(), x[r].tolist()))}): {msg}")
        # Measures and settings: one run of the first row compiles and checks them.
        _run_chunk(*self._chunk_args(0, 1))

    # -- chunks -----------------------------------------------------------------------------

    def _chunk_args(self, a: int, b: int, threads=None, delay=0.0):
        pn, pi, sn, si = self._resolve()
        x = self.matrix()
        params = np.ascontiguousarray(x[a:b, pi]) if pi else np.empty((b - a, 0))
        initial = np.ascontiguousarray(x[a:b, si]) if si else None
        return (self.model.source, self.model._m.origin, pn, params, sn, initial,
                self.measures, self.settings, a, threads, delay)

    def chunks(self) -> List[Tuple[int, int, int]]:
        """``[(index, first row, end row)]``."""
        n = self.matrix().shape[0]
        return [(i, a, min(n, a + self.chunk_size))
                for i, a in enumerate(range(0, n, self.chunk_size))]

    def metadata(self) -> Dict[str, Any]:
        """What makes a result file reproducible on its own."""
        if self._meta is None:
            self._meta = self._metadata()
        return dict(self._meta)

    def _metadata(self) -> Dict[str, Any]:
        from . import __version__
        return {"model": self.model.source, "origin": self.model._m.origin,
                "pdyn_version": __version__, "design": self.design.describe(),
                "seed": self.design.seed, "measures": self.measures,
                "settings": self.settings, "chunk_size": self.chunk_size}

    def _study_key(self) -> str:
        # Computed once: it hashes the whole design (a per-chunk cost otherwise).
        if self._key is not None:
            return self._key
        meta = self.metadata()
        meta.pop("pdyn_version")
        h = hashlib.sha256(json.dumps(meta, sort_keys=True, default=str).encode())
        h.update(self.matrix().tobytes())
        self._key = h.hexdigest()
        return self._key

    def chunk_key(self, index: int, a: int, b: int) -> str:
        """The checkpoint key of a chunk: a hash of model, design, measures, settings and
        the chunk's bounds."""
        return hashlib.sha256(f"{self._study_key()}:{index}:{a}:{b}".encode()).hexdigest()[:20]

    def _path(self, index: int, key: str) -> str:
        return os.path.join(self.out, f"chunk-{index:05d}-{key}.parquet")

    def _write(self, index: int, a: int, b: int, key: str, cols: Dict[str, np.ndarray]):
        import pyarrow as pa
        import pyarrow.parquet as pq
        meta = self.metadata()
        meta.update({"chunk": index, "rows": [a, b], "key": key})
        table = pa.table(cols)
        table = table.replace_schema_metadata({b"pdyn": json.dumps(meta).encode()})
        path = self._path(index, key)
        # Hidden while written (a dot: dataset readers skip it), then renamed: a chunk is on
        # disk whole or not at all.
        tmp = os.path.join(self.out, f".{os.path.basename(path)}.tmp{os.getpid()}")
        pq.write_table(table, tmp)
        os.replace(tmp, path)

    def _claim_folder(self, keys: Dict[int, str]) -> None:
        """Makes ``out`` this study's folder, or refuses a folder that holds another study."""
        os.makedirs(self.out, exist_ok=True)
        manifest = os.path.join(self.out, MANIFEST)
        mine = self._study_key()
        if os.path.exists(manifest):
            try:
                with open(manifest) as f:
                    theirs = json.load(f).get("study_key")
            except (OSError, ValueError, AttributeError) as e:
                raise OutputFolderError(
                    f"{manifest} cannot be read ({e}): it should name the study the folder "
                    "holds; use another out= folder, or empty this one") from e
            if theirs != mine:
                raise OutputFolderError(
                    f"{self.out} holds another study (key {str(theirs)[:12]}…, this one "
                    f"{mine[:12]}…: a different model, design, measures or settings); "
                    "its results and these would be read back mixed: use another out= "
                    "folder, or empty this one")
        else:
            ours = {f"chunk-{i:05d}-{k}.parquet" for i, k in keys.items()}
            foreign = sorted(n for n in os.listdir(self.out)
                             if n.endswith(".parquet") and n not in ours)
            if foreign:
                raise OutputFolderError(
                    f"{self.out} holds {len(foreign)} result files of another study "
                    f"({foreign[0]}, ...): use another out= folder, or empty this one")
            tmp = manifest + f".tmp{os.getpid()}"
            with open(tmp, "w") as f:
                json.dump({"study_key": mine, "metadata": self.metadata()}, f, default=str)
            os.replace(tmp, manifest)

    def run(self, client: Any = None, threads: Optional[int] = None,
            progress: bool = False, on_chunk: Optional[Callable[[int, int], None]] = None,
            _delay: float = 0.0) -> StudyResult:
        """Runs every chunk not already in ``out`` and returns the whole table.

        ``client``: a ``distributed.Client`` -- each chunk is one task running the Rust
        ensemble on a worker (``threads`` per task; default: the worker's cores), results
        streamed back as they finish and written here; ``None``: this machine, all cores.
        ``progress``: a tqdm bar (when tqdm is installed). ``on_chunk(done, total)`` is
        called after each chunk is stored. ``_delay`` (seconds, before each chunk) is for
        fault-injection tests only.
        """
        import pandas as pd
        self.check()
        start = time.perf_counter()
        chunks = self.chunks()
        keys = {i: self.chunk_key(i, a, b) for i, a, b in chunks}
        done: Dict[int, Any] = {}
        if self.out is not None:
            self._claim_folder(keys)
            for i, a, b in chunks:
                if os.path.exists(self._path(i, keys[i])):
                    done[i] = None
        skipped = len(done)
        todo = [(i, a, b) for i, a, b in chunks if i not in done]
        bar = _progress(len(chunks), skipped) if progress else None
        results: Dict[int, Dict[str, np.ndarray]] = {}
        count = [skipped]

        def store(i: int, cols: Dict[str, np.ndarray]):
            a, b = chunks[i][1], chunks[i][2]
            if len(cols["sample"]) != b - a or cols["sample"][0] != a:
                raise RuntimeError(f"chunk {i} came back with the wrong rows")
            if self.out is not None:
                self._write(i, a, b, keys[i], cols)
            else:
                results[i] = cols
            count[0] += 1
            if bar is not None:
                bar.update(1)
            if on_chunk is not None:
                on_chunk(count[0], len(chunks))

        try:
            if client is None:
                for i, a, b in todo:
                    store(i, _run_chunk(*self._chunk_args(a, b, threads, _delay)))
            else:
                from distributed import as_completed
                futures = {}
                for i, a, b in todo:
                    f = client.submit(_run_chunk, *self._chunk_args(a, b, threads, _delay),
                                      key=f"pdyn-chunk-{keys[i]}", pure=False, retries=3)
                    futures[f] = i
                try:
                    for f in as_completed(list(futures)):
                        store(futures[f], f.result())
                finally:
                    for f in futures:
                        f.cancel()
        finally:
            if bar is not None:
                bar.close()
        if self.out is not None:
            table = self.load(chunks, keys)
        else:
            table = pd.concat([pd.DataFrame(results[i]) for i, _, _ in chunks],
                              ignore_index=True)
        return StudyResult(self, table, len(todo), skipped, time.perf_counter() - start)

    def load(self, chunks=None, keys=None):
        """The stored chunks of this study (each exactly once, in order) as a DataFrame."""
        import pandas as pd
        import pyarrow.parquet as pq
        chunks = chunks or self.chunks()
        keys = keys or {i: self.chunk_key(i, a, b) for i, a, b in chunks}
        frames = []
        for i, a, b in chunks:
            path = self._path(i, keys[i])
            if not os.path.exists(path):
                raise FileNotFoundError(f"chunk {i} ({path}) has not been run")
            frames.append(pq.read_table(path).to_pandas())
        return pd.concat(frames, ignore_index=True)


def _progress(total: int, initial: int):
    try:
        from tqdm.auto import tqdm
        return tqdm(total=total, initial=initial, unit="chunk")
    except ImportError:
        class Line:
            def __init__(self):
                self.n = initial

            def update(self, k):
                self.n += k
                print(f"\r{self.n}/{total} chunks", end="", file=sys.stderr, flush=True)

            def close(self):
                print(file=sys.stderr)
        return Line()


def read_metadata(path: str) -> Dict[str, Any]:
    """The metadata of one result file: model text, pdyn version, design, seed, chunk."""
    import pyarrow.parquet as pq
    return json.loads(pq.read_schema(path).metadata[b"pdyn"])


# ---------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------

def load_design(path: str) -> Dict[str, Any]:
    """Reads a study file (TOML): ``[design]`` (kind = grid | list | samples, ...),
    ``[measures]`` (name = {of, stat}), ``[settings]``, ``chunk_size``, ``probabilities``."""
    try:
        import tomllib  # Python >= 3.11
    except ImportError:  # pragma: no cover - Python < 3.11
        try:
            import tomli as tomllib
        except ImportError as e:
            raise ImportError("reading a study file needs Python >= 3.11 or tomli") from e
    with open(path, "rb") as f:
        return tomllib.load(f)


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``pdyn-study MODEL --design study.toml --out DIR [--scheduler ADDRESS]``."""
    import argparse
    from . import Model, ModelError
    ap = argparse.ArgumentParser(
        prog="pdyn-study",
        description="Run a parameter study or Monte Carlo ensemble of a pdyn model, locally "
                    "or on a Dask cluster, checkpointed to Parquet (reruns resume).")
    ap.add_argument("model", help="model file (TOML)")
    ap.add_argument("--design", required=True, help="study file (TOML): [design], [measures], "
                    "[settings], chunk_size, probabilities")
    ap.add_argument("--out", required=True, help="output directory (Parquet chunks)")
    ap.add_argument("--scheduler", help="Dask scheduler address (default: this machine)")
    ap.add_argument("--chunk-size", type=int, help="runs per task")
    ap.add_argument("--no-progress", action="store_true")
    a = ap.parse_args(argv)
    try:
        model = Model.from_file(a.model)
        spec = load_design(a.design)
        design = design_from_dict(spec.get("design", {}))
        measures = {k: (v["of"], v.get("stat", "max_abs")) if isinstance(v, Mapping) else v
                    for k, v in spec.get("measures", {}).items()} or None
        study = Study(model, design, measures=measures, settings=spec.get("settings"),
                      chunk_size=a.chunk_size or spec.get("chunk_size", DEFAULT_CHUNK_SIZE),
                      out=a.out)
        client = None
        if a.scheduler:
            from distributed import Client
            client = Client(a.scheduler)
        res = study.run(client=client, progress=not a.no_progress)
    except (ModelError, DesignError, ParameterError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"{len(res.table)} runs in {res.chunks_run + res.chunks_skipped} chunks "
          f"({res.chunks_run} run now, {res.chunks_skipped} already in {a.out}), "
          f"{res.seconds:.2f} s")
    for cond in spec.get("probabilities", []):
        print(res.probability(cond))
    return 0


if __name__ == "__main__":
    sys.exit(main())
