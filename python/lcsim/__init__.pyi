# Type stub of the package lcsim (the extension lcsim._lcsim and __init__.py).
from os import PathLike
from typing import Any, Callable, Iterable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
import scipy.sparse

ArrayLike = npt.ArrayLike
MatrixLike = Union[npt.ArrayLike, scipy.sparse.spmatrix]
Path = Union[str, PathLike[str]]

FRICTION_MODES: tuple[str, str, str, str]  # ("open", "stick", "slip+", "slip-")

class InputError(ValueError):
    """Invalid input: the library's message names the file or field, the element and the value."""

class Model:
    """A mechanical model or a general LCS, checked by the library."""
    @staticmethod
    def mechanical(M: MatrixLike, K: Optional[MatrixLike] = None, E: Optional[MatrixLike] = None,
                   D: Optional[MatrixLike] = None, f: Optional[ArrayLike] = None,
                   g: Optional[ArrayLike] = None, restitution: Optional[ArrayLike] = None,
                   names: Sequence[str] = ..., constraint_names: Sequence[str] = ...,
                   name: str = "model", initial: Optional[ArrayLike] = None,
                   t_end: Optional[float] = None,
                   friction: Optional[Sequence[dict[str, Any]]] = None) -> Model: ...
    @staticmethod
    def lcs(A: ArrayLike, B: ArrayLike, C: ArrayLike, D: ArrayLike, name: str = "lcs",
            initial: Optional[ArrayLike] = None, t_end: Optional[float] = None) -> Model: ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def is_mechanical(self) -> bool: ...
    @property
    def is_scene(self) -> bool: ...
    @property
    def state_size(self) -> int: ...
    @property
    def num_constraints(self) -> int: ...
    @property
    def dofs(self) -> int: ...
    @property
    def initial(self) -> Optional[np.ndarray]: ...
    @property
    def t_end(self) -> Optional[float]: ...
    @property
    def M(self) -> scipy.sparse.csc_matrix: ...
    @property
    def D(self) -> scipy.sparse.csc_matrix: ...
    @property
    def K(self) -> scipy.sparse.csc_matrix: ...
    @property
    def E(self) -> scipy.sparse.csc_matrix: ...
    @property
    def g(self) -> np.ndarray: ...
    @property
    def f(self) -> np.ndarray: ...
    @property
    def restitution(self) -> np.ndarray: ...
    @property
    def coordinates(self) -> list[str]: ...
    @property
    def constraints(self) -> list[str]: ...

class Event:
    """An event of a run: an impact, a contact, a release, an accumulation, the start, a frictional contact starting to stick or to slip, or a breakpoint of an input (`schedule`, docs/inputs.md)."""
    t: float
    type: str
    state_before: np.ndarray
    state_after: np.ndarray
    impulse: np.ndarray
    mode: list[int]
    note: str
    friction_impulse: np.ndarray  # per frictional contact (empty without friction)
    friction_impulse2: np.ndarray  # along the second tangents (empty without 3-D friction)
    friction_modes: list[str]  # 'open', 'stick', 'slip+', 'slip-', 'slip-edge-<i>', 'slip-face-<i>'
    dt: list[Optional[float]]  # d t_event / d sensitivity column, None where absent

class Trajectory:
    """The result of simulate: samples as numpy arrays, events, status, diagnostics."""
    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    u_t: np.ndarray  # tangential multipliers, (n, frictional contacts)
    friction_modes: np.ndarray  # int8 (n, frictional contacts): FRICTION_MODES index, -1 none
    u_t2: np.ndarray  # second tangents' multipliers, (n, contacts) with 3-D friction, else (n, 0)
    friction_facets: np.ndarray  # int16 like u_t2: 2i edge i, 2i+1 face i, -1 none
    @property
    def friction_mode_names(self) -> list[list[Optional[str]]]: ...
    y: np.ndarray
    modes: np.ndarray
    @property
    def q(self) -> np.ndarray: ...
    @property
    def v(self) -> np.ndarray: ...
    events: list[Event]
    final_state: np.ndarray
    status: str
    ok: bool
    message: str
    method: str
    impact_law: str
    t_end: float
    energy_initial: float
    energy_final: float
    max_violation: float
    lcp_solves: int
    steps: int
    warnings: list[dict[str, Any]]  # {kind, count, first_t, message} per kind
    warning_count: int
    events_not_recorded: int
    wall_time_s: float
    model: Model
    # Forward sensitivities (simulate(..., sensitivity=[...]), docs/sensitivities.md):
    sensitivity_columns: list[str]
    dx_dx0: Optional[np.ma.MaskedArray]  # (n, state, state), None unless 'x0' was asked
    dx_dp: dict[str, np.ma.MaskedArray]  # name as asked -> (n, state)
    sensitivity_losses: list[dict[str, Any]]  # {t, contact, reason, columns}
    def to_csv(self, path: Optional[Path] = None) -> Optional[str]: ...
    def to_json(self, path: Optional[Path] = None) -> Optional[str]: ...

class ImpactResult:
    """The outcome of one impact law."""
    ok: bool
    status: str
    message: str
    v_after: np.ndarray
    impulse: np.ndarray
    mode: list[int]
    energy_before: float
    energy_after: float
    worst_rate: float
    admissible: bool
    friction_impulse: np.ndarray
    friction_impulse2: np.ndarray
    friction_outcome: list[str]
    friction_mode: list[str]

class LcpResult:
    """The solution of an LCP w = M z + q."""
    status: str
    ok: bool
    z: np.ndarray
    w: np.ndarray
    residual: float
    pivots: int
    iterations: int
    message: str

def load(path: Path) -> Model: ...
def simulate(model: Model, x0: Optional[ArrayLike] = None, t_end: Optional[float] = None,
             method: str = "event", h: Optional[float] = None, theta: Optional[float] = None,
             impact: Optional[str] = None, dt_out: float = 0.0,
             lcp_solver: Optional[str] = None, force: bool = False,
             max_output: Optional[float] = None,
             progress: Optional[Callable[[float], Any]] = None,
             sensitivity: Iterable[str] = ()) -> Trajectory: ...
def impacts(model: Model, x0: Optional[ArrayLike] = None,
            rules: Optional[Iterable[str]] = None,
            restitution: Optional[ArrayLike] = None) -> dict[str, ImpactResult]: ...
def impact_map(model: Model, v1: tuple[float, float] = (-1.0, 1.0),
               v2: tuple[float, float] = (-1.0, 1.0), n: int = 41,
               x0: Optional[ArrayLike] = None, law: str = "newton") -> str: ...
def solve_lcp(M: ArrayLike, q: ArrayLike, solver: str = "lemke") -> LcpResult: ...
def analyze(model: Model, full: bool = False,
            linearisation_threshold: float = 0.01) -> dict[str, Any]: ...
def sweep(model: Model, methods: Iterable[str], hs: Iterable[float],
          x0: Optional[ArrayLike] = None, t_end: Optional[float] = None,
          impact: Optional[str] = None, theta: Optional[float] = None,
          repeat: int = 3, sensitivity: Iterable[str] = ()) -> dict[str, Any]: ...
def integrator_names() -> list[str]: ...
def impact_law_names() -> list[str]: ...
def solver_names() -> list[str]: ...

class StudyTable:
    """The table of a study (the text `lcsim study --out` writes), its parsed rows and
    the run summary."""
    text: str
    rows: list[Any]
    total: int
    resumed: int
    computed: int
    failed: int
    wall_time_s: float

def study(path: Union[str, Path], out: Optional[Union[str, Path]] = None, resume: bool = False,
          jobs: int = 0, progress: Optional[Callable[[str], None]] = None) -> StudyTable: ...
