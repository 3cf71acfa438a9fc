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
    def __init__(self, text: str, file: str = ..., line: Optional[int] = ...,
                 column: Optional[int] = ..., message: str = ...) -> None: ...

class ParameterError(PdynError, ValueError): ...
class DriftWarning(UserWarning): ...

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
    sol: None
    stats: Dict[str, Any]
    method: str
    columns: List[str]
    monitors: List[Dict[str, Any]]
    warnings: List[str]
    def __getitem__(self, key: str) -> Any: ...
    def column(self, name: str) -> npt.NDArray[np.float64]: ...
    def to_pandas(self) -> Any: ...

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

class SweepResult:
    parameter: str
    values: npt.NDArray[np.float64]
    measures: Dict[str, npt.NDArray[np.float64]]
    problems: List[Tuple[float, str]]
    runs: int
    seconds: float
    threads: int
    def to_pandas(self) -> Any: ...

class Model:
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
    def parameters(self) -> Dict[str, float]: ...
    def run(self, t_end: Optional[float] = ..., method: Optional[str] = ...,
            rtol: Optional[float] = ..., atol: Optional[float] = ...,
            t_eval: Optional[Sequence[float]] = ..., max_step: Optional[float] = ...,
            dt: Optional[float] = ..., max_steps: Optional[int] = ...,
            points: Optional[int] = ..., drift_tolerance: Optional[float] = ...,
            params: Optional[Mapping[str, float]] = ...) -> OdeResult: ...
    def derive(self) -> Derivation: ...
    def sweep(self, param: str, values: Sequence[float],
              measures: Optional[Mapping[str, Union[str, Tuple[str, str]]]] = ...,
              t_end: Optional[float] = ..., method: Optional[str] = ...,
              rtol: Optional[float] = ..., atol: Optional[float] = ...,
              max_step: Optional[float] = ..., dt: Optional[float] = ...,
              points: Optional[int] = ..., threads: Optional[int] = ...,
              params: Optional[Mapping[str, float]] = ...) -> SweepResult: ...

def methods() -> Dict[str, str]: ...

def solve_ivp(fun: Union[Callable[..., Any], Sequence[str]], t_span: Tuple[float, float],
              y0: Sequence[float], method: str = ..., t_eval: Optional[Sequence[float]] = ...,
              dense_output: bool = ..., events: Optional[Any] = ..., vectorized: bool = ...,
              args: Optional[Any] = ..., rtol: Union[float, Sequence[float]] = ...,
              atol: Union[float, Sequence[float]] = ..., max_step: float = ...,
              first_step: Optional[float] = ..., max_steps: Optional[int] = ...,
              **options: Any) -> OdeResult: ...
