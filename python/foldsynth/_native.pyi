"""Type stubs of foldsynth's native extension (python/src/*.rs), re-exported by the
``foldsynth`` package."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "PathLike[str]"]
_Modes = Union[str, Sequence[float], Sequence[str], npt.NDArray[np.float64]]
_Array = Union[Sequence[float], npt.NDArray[np.float64]]

__version__: str

class FoldsynthError(ValueError):
    """An error reported by foldsynth: a bad task file, graph, vertex notation or search
    setting, or an unreadable run directory; the message names the file and the field."""

class Task:
    """A design task (a task file: G0, N_max, motion, bounds, objective, checks)."""

    @staticmethod
    def load(path: _Path) -> Task:
        """Load and validate a task file (e.g. grammar/gripper.toml)."""
    @property
    def name(self) -> str:
        """The task's name."""
    @property
    def n_max(self) -> int:
        """N_max: the maximum number of internal vertices."""
    @property
    def t_max(self) -> Optional[float]:
        """The end of the motion t_max (None when the task defines no motion)."""
    def enumerate(self, n_max: Optional[int] = None) -> List[Graph]:
        """The meaningful graphs of the task up to ``n_max`` internal vertices."""
    def model(self, graph: Union[Graph, str], candidate: int = 1) -> Model:
        """The compiled design model of ``graph`` (a Graph or a rule sequence) gripping
        with candidate 1, 2 or 3."""
    def synthesize(
        self,
        out: _Path,
        *,
        jobs: int = 0,
        starts: int = 16,
        seed: int = 0,
        resume: bool = False,
        force: bool = False,
        n_max: Optional[int] = None,
        sweep: int = 181,
        export: bool = True,
    ) -> Dict[str, Any]:
        """The whole search into ``out``; returns the summary (summary.json's content).
        ``foldsynth.synthesize`` is the same search returning a ``Run``."""

class Graph:
    """A crease-pattern graph of a task."""

    @property
    def sequence(self) -> str:
        """The rule sequence, e.g. "2, 3, (4, 8), 4, (7, 8)"."""
    @property
    def level(self) -> int:
        """Rule applications."""
    @property
    def n_internal(self) -> int:
        """Internal (extended) vertices."""
    @property
    def alternatives(self) -> int:
        """Design alternatives: 2^n_internal modes × 3 gripping candidates."""

class Model:
    """A compiled design model: one graph, one gripping candidate, one task; objective,
    constraints g ≥ 0 and all gradients from one native call (the GIL released)."""

    @property
    def names(self) -> List[str]:
        """The variables' names (the order of x)."""
    @property
    def bounds(self) -> npt.NDArray[np.float64]:
        """An (n_vars, 2) array of [lower, upper]."""
    @property
    def n_vars(self) -> int:
        """Number of variables."""
    @property
    def n_constraints(self) -> int:
        """Number of constraints g ≥ 0."""
    @property
    def n_modes(self) -> int:
        """Number of internal vertices (= number of modes)."""
    @property
    def times(self) -> npt.NDArray[np.float64]:
        """The values of t the model folds at by default (t_max first)."""
    @property
    def constraint_labels(self) -> List[str]:
        """A readable label per constraint."""
    @property
    def graph(self) -> str:
        """The graph's rule sequence."""
    @property
    def candidate(self) -> int:
        """The gripping candidate (1, 2 or 3)."""
    @property
    def threshold(self) -> float:
        """The task's success threshold on Ω (Eq. 37/38)."""
    @property
    def objective_target(self) -> float:
        """The value of the compiled objective that means the target is met."""
    def value_and_grad(
        self, x: _Array, modes: _Modes, t: Optional[Union[float, _Array]] = None
    ) -> Tuple[float, npt.NDArray[np.float64]]:
        """``(f, df)``, as ``scipy.optimize.minimize(..., jac=True)`` expects."""
    def constraints_and_jacobian(
        self, x: _Array, modes: _Modes, t: Optional[Union[float, _Array]] = None
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``(g, J)``: g ≥ 0 when satisfied, J of shape (n_constraints, n_vars)."""
    def evaluate(
        self, x: _Array, modes: _Modes, t: Optional[Union[float, _Array]] = None
    ) -> Tuple[
        float, npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]
    ]:
        """``(f, g, df, J)`` from one call."""
    def omega(self, x: _Array, modes: _Modes) -> float:
        """Ω as the thesis states it (Eq. 37/38), from the plain f64 kinematics."""
    def optimize(
        self, modes: Optional[_Modes] = None, starts: int = 32, seed: int = 0
    ) -> Dict[str, Any]:
        """foldsynth's optimizer: a dict with x, objective, omega, constraints,
        violation, feasible, met_target, evaluations, starts_run."""

def vertex(spec: str, t: Union[float, _Array]) -> Dict[str, Any]:
    """The PTU of one vertex in the thesis's notation at t (a number or an array)."""

def synthesize(
    task: Task,
    out: _Path,
    *,
    jobs: int = 0,
    starts: int = 16,
    seed: int = 0,
    resume: bool = False,
    force: bool = False,
    n_max: Optional[int] = None,
    sweep: int = 181,
    export: bool = True,
    export_top: Optional[int] = None,
    export_all: bool = False,
    report_motions: Optional[int] = None,
    report_motions_all: bool = False,
    report_designs: Optional[int] = None,
    report_designs_all: bool = False,
    shard: Optional[str] = None,
    rules: str = "r1,r2",
    post_check_only: bool = False,
    strategy: str = "exhaustive",
    budget_alternatives: Optional[int] = None,
    budget_cpu: Optional[float] = None,
    warm_starts: bool = True,
    callback: Optional[Callable[[str, str, int, Optional[int], bool], Any]] = None,
) -> Dict[str, Any]:
    """The search (native half of ``foldsynth.synthesize``): ``callback(phase, unit,
    done, total, finished)`` hears its progress on the calling thread; returns the
    summary."""

def design_fold(path: _Path) -> str:
    """The FOLD 1.2 document (JSON text) of a design file ``designs/<id>.json``."""

def design_frames(
    path: _Path,
) -> Tuple[List[float], List[List[Tuple[float, float, float]]], List[List[float]]]:
    """A design file's frames as ``(t, coords, fold_angles)``, the fold angles the file
    leaves out read from the vertex positions."""
