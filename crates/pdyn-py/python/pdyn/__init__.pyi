from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union
import os
import numpy as np
import numpy.typing as npt

__version__: str

class PdynError(Exception): ...

class ModelError(PdynError, ValueError):
    file: str
    line: Optional[int]
    column: Optional[int]
    message: str
    argument: str
    def __init__(self, text: str, file: str = ..., line: Optional[int] = ...,
                 column: Optional[int] = ..., message: str = ...) -> None: ...

class ParameterError(PdynError, ValueError): ...
class DriftWarning(UserWarning):
    quantity: str
    drift: float
    tolerance: float
    relative: bool
    def __init__(self, message: str, quantity: str = ..., drift: float = ...,
                 tolerance: float = ..., relative: bool = ...) -> None: ...

class Interrupted(KeyboardInterrupt):
    result: Any
    def __init__(self, message: str, result: Any = ...) -> None: ...

class Particle:
    name: str
    m: float
    r: float
    x: float
    y: float
    z: float
    vx: float
    vy: float
    vz: float

class NBody:
    name: str
    t: float
    last: Optional[ParticleResult]
    def __init__(self, name: str = ..., **options: Any) -> None: ...
    def add(self, m: float, name: Optional[str] = ..., r: float = ...,
            primary: Optional[str] = ..., **coords: float) -> None: ...
    def integrate(self, t: float, points: Optional[int] = ...,
                  output_dt: Optional[float] = ...) -> ParticleResult: ...
    def to_toml(self, t_end: float, output: Dict[str, Any]) -> str: ...
    @property
    def particles(self) -> List[Particle]: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def masses(self) -> npt.NDArray[np.float64]: ...
    def energy(self) -> float: ...

class FitResult(Dict[str, Any]):
    x: npt.NDArray[np.float64]
    names: List[str]
    stderr: npt.NDArray[np.float64]
    corr: npt.NDArray[np.float64]
    cov: npt.NDArray[np.float64]
    cost: float
    fun: npt.NDArray[np.float64]
    jac: npt.NDArray[np.float64]
    status: int
    message: str
    success: bool
    nfev: int
    chi2: float
    dof: int
    reduced_chi2: float
    unidentifiable: List[List[str]]
    warnings: List[str]
    experiments: List[Dict[str, Any]]

class Modes:
    omega: npt.NDArray[np.float64]
    omega_squared: npt.NDArray[np.float64]
    freq_hz: npt.NDArray[np.float64]
    period: npt.NDArray[np.float64]
    shapes: npt.NDArray[np.float64]
    modal_mass: npt.NDArray[np.float64]
    participation: npt.NDArray[np.float64]
    effective_mass: npt.NDArray[np.float64]
    total_mass: npt.NDArray[np.float64]
    modal_stiffness: npt.NDArray[np.float64]
    coordinates: List[str]
    q: npt.NDArray[np.float64]
    residual: float
    solver: str
    about: str
    stiffness_asymmetry: float
    natural_frequency: Optional[npt.NDArray[np.float64]]
    damping_ratio: Optional[npt.NDArray[np.float64]]
    damped_frequency: Optional[npt.NDArray[np.float64]]
    damped_path: Optional[str]
    def __len__(self) -> int: ...

class Linearization:
    A: npt.NDArray[np.float64]
    K: npt.NDArray[np.float64]
    C: npt.NDArray[np.float64]
    f0: npt.NDArray[np.float64]
    y0: npt.NDArray[np.float64]
    state: List[str]
    analytic: bool
    def eigenvalues(self) -> npt.NDArray[np.complex128]: ...

class OdeResult(dict):
    t: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    t_events: Optional[List[npt.NDArray[np.float64]]]
    y_events: Optional[List[npt.NDArray[np.float64]]]
    status: int
    message: str
    success: bool
    nfev: int
    njev: int
    nlu: int
    sol: Optional[Callable[[Any], npt.NDArray[np.float64]]]
    stats: Dict[str, Any]
    method: str
    columns: List[str]
    monitors: List[Dict[str, Any]]
    warnings: List[str]
    non_finite: List[str]
    non_finite_t: Optional[float]
    native: bool
    hybrid: Optional[Dict[str, Any]]
    def __getitem__(self, key: str) -> Any: ...
    def column(self, name: str) -> npt.NDArray[np.float64]: ...
    def to_pandas(self) -> Any: ...
    def plot(self, *names: str, ax: Any = ...) -> Any: ...
    def plot_trajectory(self, x: Optional[str] = ..., y: Optional[str] = ..., ax: Any = ...) -> Any: ...

class Expr:
    def __init__(self, text: str, latex: str) -> None: ...
    def latex(self) -> str: ...
    def _repr_latex_(self) -> str: ...
    def to_sympy(self) -> Any: ...

class Derivation:
    equations: List[Tuple[str, Expr, Expr]]
    unknowns: List[str]
    solution: Optional[List[Tuple[str, Expr]]]
    first_order: Optional[List[Tuple[str, Expr]]]
    state: List[str]
    form: str
    notes: List[str]
    mass_matrix: Optional[List[List[Expr]]]
    forcing: Optional[List[Expr]]

class SweepResult:
    parameter: str
    values: npt.NDArray[np.float64]
    measures: Dict[str, npt.NDArray[np.float64]]
    problems: List[Tuple[float, str]]
    runs: int
    seconds: float
    threads: int
    def to_pandas(self) -> Any: ...

class EnsembleResult:
    params: Dict[str, npt.NDArray[np.float64]]
    initial: Dict[str, npt.NDArray[np.float64]]
    state_names: List[str]
    measures: Dict[str, npt.NDArray[np.float64]]
    t_final: npt.NDArray[np.float64]
    final: npt.NDArray[np.float64]
    event_t: Dict[str, npt.NDArray[np.float64]]
    event_state: Dict[str, npt.NDArray[np.float64]]
    drift: Dict[str, npt.NDArray[np.float64]]
    drifted: npt.NDArray[np.bool_]
    status: npt.NDArray[np.int32]
    nfev: npt.NDArray[np.int64]
    problems: List[Tuple[int, str]]
    seconds: float
    threads: int
    def __len__(self) -> int: ...
    def columns(self) -> Dict[str, npt.NDArray[Any]]: ...
    def column(self, name: str) -> npt.NDArray[Any]: ...
    def __getitem__(self, name: str) -> npt.NDArray[Any]: ...
    def to_pandas(self) -> Any: ...

class ForcesResult:
    instant: Dict[str, float]
    equations: List[Tuple[str, Expr, Expr]]
    unknowns: List[str]
    symbolic: Optional[Dict[str, Expr]]
    values: List[Dict[str, float]]
    checks: List[Dict[str, Any]]
    notes: List[str]

class _Parameters(Dict[str, float]):
    def __call__(self, **values: Any) -> None: ...

class Table:
    columns: List[str]
    data: np.ndarray
    def __getitem__(self, name: str) -> np.ndarray: ...
    def __len__(self) -> int: ...
    def to_pandas(self) -> Any: ...

class ParticleResult:
    kind: str
    summary: Dict[str, Any]
    success: bool
    message: str
    warnings: List[str]
    t: np.ndarray
    names: List[str]
    trajectory: Table
    elements: Table
    conservation: Table
    thermo: Table
    rdf: Optional[Tuple[np.ndarray, np.ndarray]]
    msd: Table

class Model:
    def __init__(self, name: str = ...) -> None: ...
    def coordinate(self, name: str, initial: Any = ..., rate: Any = ...,
                   expr: Any = ...) -> str: ...
    def particle(self, name: str, mass: Any, position: Any) -> str: ...
    def point(self, name: str, position: Any) -> str: ...
    def gravity(self, g: Any) -> None: ...
    def force(self, kind: str, **fields: Any) -> None: ...
    def event(self, name: str, when: Any, direction: str = ..., terminal: bool = ...,
              set: Optional[Sequence[Any]] = ...) -> None: ...
    def contact(self, name: str, **fields: Any) -> None: ...
    def monitor(self, name: str, expr: Any) -> None: ...
    def simulate(self, **settings: Any) -> None: ...
    def to_toml(self) -> str: ...
    @classmethod
    def from_file(cls, path: Union[str, os.PathLike[str]]) -> Model: ...
    @classmethod
    def from_toml(cls, text: str, origin: str = ...) -> Model: ...
    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Model: ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def parameters(self) -> _Parameters: ...
    @property
    def kind(self) -> str: ...
    def run(self, t_end: Optional[float] = ..., method: Optional[str] = ...,
            rtol: Optional[float] = ..., atol: Optional[float] = ...,
            t_eval: Optional[Sequence[float]] = ..., max_step: Optional[float] = ...,
            dt: Optional[float] = ..., max_steps: Optional[int] = ...,
            points: Optional[int] = ..., drift_tolerance: Optional[float] = ...,
            params: Optional[Mapping[str, float]] = ...,
            plots: Optional[Union[str, os.PathLike[str]]] = ...,
            jit: bool = ..., initial: Optional[Mapping[str, float]] = ...,
            out: Optional[Union[str, os.PathLike[str]]] = ...,
            restart: Optional[Union[str, os.PathLike[str]]] = ...,
            checkpoint_every: Optional[str] = ...
            ) -> Union[OdeResult, ParticleResult]: ...
    def linearize(self, op_point: Optional[Mapping[str, float]] = ...,
                  params: Optional[Mapping[str, float]] = ..., t: float = ...) -> Linearization: ...
    def fit(self, data: Any, free: Union[str, Sequence[str]],
            params: Optional[Mapping[str, float]] = ...,
            bounds: Optional[Mapping[str, Tuple[float, float]]] = ...,
            sigma: Optional[Mapping[str, float]] = ..., absolute_sigma: bool = ...,
            rtol: float = ..., atol: float = ..., max_nfev: int = ...) -> FitResult: ...

    def modes(self, count: Optional[int] = ..., about: str = ..., solver: str = ...,
              params: Optional[Mapping[str, float]] = ...) -> Modes: ...
    def derive(self) -> Derivation: ...
    def sweep(self, param: str, values: Sequence[float],
              measures: Optional[Mapping[str, Union[str, Tuple[str, str]]]] = ...,
              t_end: Optional[float] = ..., method: Optional[str] = ...,
              rtol: Optional[float] = ..., atol: Optional[float] = ...,
              max_step: Optional[float] = ..., dt: Optional[float] = ...,
              points: Optional[int] = ..., threads: Optional[int] = ...,
              params: Optional[Mapping[str, float]] = ..., jit: bool = ...) -> SweepResult: ...
    def forces(self, at: Optional[Mapping[str, float]] = ...,
               params: Optional[Mapping[str, float]] = ...) -> ForcesResult: ...
    def check_ensemble(self, params: Any = ..., initial: Any = ...) -> List[Tuple[int, str]]: ...
    def ensemble(self, params: Any = ..., initial: Any = ...,
                 measures: Optional[Mapping[str, Union[str, Tuple[str, str]]]] = ...,
                 t_end: Optional[float] = ..., method: Optional[str] = ...,
                 rtol: Optional[float] = ..., atol: Optional[float] = ...,
                 max_step: Optional[float] = ..., dt: Optional[float] = ...,
                 points: Optional[int] = ..., drift_tolerance: Optional[float] = ...,
                 threads: Optional[int] = ..., progress: bool = ...,
                 jit: bool = ...) -> EnsembleResult: ...

def methods() -> Dict[str, str]: ...

def solve_ivp(fun: Union[Callable[..., Any], Sequence[str]], t_span: Tuple[float, float],
              y0: Sequence[float], method: Union[str, type] = ...,
              t_eval: Optional[Sequence[float]] = ...,
              dense_output: bool = ..., events: Optional[Any] = ..., vectorized: bool = ...,
              args: Optional[Any] = ..., rtol: Union[float, Sequence[float]] = ...,
              atol: Union[float, Sequence[float]] = ..., max_step: float = ...,
              first_step: Optional[float] = ..., min_step: float = ...,
              jac: Optional[Any] = ..., max_steps: Optional[int] = ...,
              jit: bool = ..., **options: Any) -> OdeResult: ...

class OdeSolution:
    """``sol.sol`` of :func:`solve_ivp` with ``dense_output=True`` (every step's own
    interpolant)."""
    ts: Any
    t_min: float
    t_max: float
    n_segments: int
    interpolant: str
    def __call__(self, t: Any) -> Any: ...

class Vector(Tuple[Expr, Expr, Expr]):
    def latex(self) -> str: ...
    def _repr_latex_(self) -> str: ...
    def to_sympy(self) -> Any: ...

class KinInstant:
    at: str
    resolved: str
    exact: Dict[str, Union[Expr, Vector]]
    values: Dict[str, Any]
    def __getitem__(self, name: str) -> Any: ...

class KinResult:
    variable: str
    straight: bool
    quantities: Dict[str, Union[Expr, Vector]]
    instants: List[KinInstant]
    max: Optional[Dict[str, Any]]
    assumed_positive: List[str]
    def __getitem__(self, name: str) -> Union[Expr, Vector]: ...
    def __getattr__(self, name: str) -> Union[Expr, Vector]: ...

def kin(position: Any = ..., *, polar: Any = ..., path: Any = ..., param: str = ...,
        speed: Any = ..., at: Any = ..., params: Optional[Mapping[str, Any]] = ...,
        max: Any = ..., over: Any = ..., signed: Optional[Sequence[str]] = ...) -> KinResult: ...

class DsolveCase:
    condition: Optional[Tuple[Expr, str]]
    solution: Dict[str, Expr]
    roots: List[str]
    constants: List[str]
    values: Optional[npt.NDArray[np.float64]]

class DsolveResult:
    coords: List[str]
    method: str
    residual: Optional[float]
    cases: List[DsolveCase]
    solution: Optional[Dict[str, Expr]]
    times: npt.NDArray[np.float64]
    values: Optional[npt.NDArray[np.float64]]
    when: Optional[Dict[str, Any]]
    assumed_positive: List[str]
    def __getitem__(self, name: str) -> Expr: ...

class RuleResult:
    rule: str
    variable: str
    points: npt.NDArray[np.float64]
    quantities: Dict[str, Optional[Expr]]
    values: Dict[str, npt.NDArray[np.float64]]
    errors: Dict[str, npt.NDArray[np.float64]]
    messages: Dict[str, List[Optional[str]]]
    descriptions: Dict[str, str]
    assumed_positive: List[str]
    def __getitem__(self, name: str) -> Optional[Expr]: ...

def dsolve(*equations: Any, ic: Any = ..., rule: Any = ...,
           params: Optional[Mapping[str, Any]] = ..., at: Any = ..., when: Any = ...,
           signed: Optional[Sequence[str]] = ...) -> Union[DsolveResult, RuleResult]: ...

# Measured motion (pdyn._data; docs/data.md).
def read_csv(path: Union[str, os.PathLike], columns: Optional[Sequence[str]] = ...,
             kind: str = ...) -> Tuple[List[str], npt.NDArray[np.float64], List[npt.NDArray[np.float64]]]: ...
def interp(t: Any, y: Any, at: Any, kind: str = ...) -> Any: ...
class KinDataResult:
    columns: Dict[str, npt.NDArray[np.float64]]
    summary: Dict[str, Any]
    names: List[str]
    fits: List[Dict[str, Any]]
    boundary: float
    position: npt.NDArray[np.float64]
    velocity: npt.NDArray[np.float64]
    acceleration: npt.NDArray[np.float64]
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __getattr__(self, name: str) -> npt.NDArray[np.float64]: ...
    def keys(self) -> Any: ...
    def to_csv(self, path: Union[str, os.PathLike]) -> None: ...
class IntegratedAccel:
    columns: Dict[str, npt.NDArray[np.float64]]
    summary: Dict[str, Any]
    axes: List[Dict[str, Any]]
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __getattr__(self, name: str) -> npt.NDArray[np.float64]: ...
    def keys(self) -> Any: ...
    def to_csv(self, path: Union[str, os.PathLike]) -> None: ...
class FuseResult:
    columns: Dict[str, npt.NDArray[np.float64]]
    summary: Dict[str, Any]
    names: List[str]
    sigma_a: float
    sigma_p: float
    sigma_b: float
    log_likelihood: float
    covariance: Optional[npt.NDArray[np.float64]]
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __getattr__(self, name: str) -> npt.NDArray[np.float64]: ...
    def keys(self) -> Any: ...
    def to_csv(self, path: Union[str, os.PathLike]) -> None: ...
def kin_data(t: Any, x: Any = ..., y: Any = ..., z: Any = ..., *, lam: Union[None, str, float] = ...,
             columns: Optional[Sequence[str]] = ...) -> KinDataResult: ...
def integrate_accel(t: Any, *a: Any, v0: Any = ..., x0: Any = ..., rule: str = ..., bias: Any = ...,
                    sigma_a: Optional[float] = ..., names: Optional[Sequence[str]] = ...,
                    columns: Optional[Sequence[str]] = ...) -> IntegratedAccel: ...
def fuse(ta: Any, a: Any = ..., tf: Any = ..., fixes: Any = ..., *, sigma_a: Optional[float] = ...,
         sigma_p: Optional[float] = ..., sigma_b: float = ..., bias0: float = ..., v0_sd: float = ...,
         p0_sd: float = ..., names: Optional[Sequence[str]] = ..., covariance: bool = ...,
         accel_columns: Optional[Sequence[str]] = ...,
         fix_columns: Optional[Sequence[str]] = ...) -> FuseResult: ...
from . import study as study
from . import study as ensemble
