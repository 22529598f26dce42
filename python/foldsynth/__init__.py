"""foldsynth: synthesis of rigidly foldable origami crease patterns, from Python.

The search and its results::

    run = foldsynth.synthesize("grammar/gripper.toml", n_max=2, out="out/py")
    run.alternatives()          # every alternative: a pandas DataFrame
    best = run.design(run.ranking[0])
    best.fold()                 # its FOLD document as a dict
    best.frames                 # its folded states as NumPy arrays
    best.model()                # its compiled design model (a Model)

and the design model itself: ``Task.load`` → ``task.enumerate()`` → ``task.model(graph)``
→ ``model.value_and_grad(x, modes)`` on NumPy arrays (native, the GIL released).
"""

from ._native import FoldsynthError, Graph, Model, Task, vertex, __version__
from ._run import Design, ProgressEvent, Run, synthesize

__all__ = [
    "Design",
    "FoldsynthError",
    "Graph",
    "Model",
    "ProgressEvent",
    "Run",
    "Task",
    "synthesize",
    "vertex",
    "__version__",
]
