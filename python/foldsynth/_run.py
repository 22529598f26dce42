"""A search run as data: ``synthesize`` runs one, ``Run.open`` reads any run directory.

A run directory is what ``foldsynth synthesize`` (or ``foldsynth merge``) writes:
``settings.json``, ``alternatives.jsonl`` (one record per alternative), ``summary.json``
(the counts and the ranking), ``designs/<id>.json`` (each design with its motion),
``designs/<id>.fold`` and, for the most robust, ``designs/<id>/`` (the files).
docs/outputs.md describes every field; nothing here reads anything else.
"""

from __future__ import annotations

import json
import numbers
import os
import pathlib
from typing import Any, Callable, Dict, Iterator, List, NamedTuple, Optional, Union

import numpy as np

from . import _native

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["Design", "Frames", "ProgressEvent", "Run", "synthesize"]


class ProgressEvent(NamedTuple):
    """One step of a run's progress, as ``synthesize(progress=callback)`` hands it over.

    ``phase`` is e.g. ``"compile + optimize + check"``, ``unit`` what it counts
    (``"alternatives"``; empty when nothing), ``done`` the items done so far in the phase,
    ``total`` the phase's items (``None`` when unknown), ``finished`` whether the phase has
    just ended. Steps within a phase arrive at most every 0.1 s, carrying the latest count.
    """

    phase: str
    unit: str
    done: int
    total: Optional[int]
    finished: bool


class _Bar:
    """A tqdm bar per phase (``tqdm.auto``: a widget in notebooks, text elsewhere)."""

    def __init__(self, tqdm: Any) -> None:
        self._tqdm = tqdm
        self._bar: Any = None
        self._phase: Optional[str] = None

    def __call__(self, e: ProgressEvent) -> None:
        if e.phase != self._phase:
            self.close()
            self._phase = e.phase
            self._bar = self._tqdm(total=e.total, desc=e.phase, unit=e.unit or "it", leave=True)
        self._bar.update(e.done - self._bar.n)
        if e.finished:
            self.close()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
        self._bar, self._phase = None, None


def _progress_callback(progress: Union[bool, Callable[[ProgressEvent], Any], None]):
    """(callback for the native search, what to close afterwards)."""
    if callable(progress):
        return (lambda *step: progress(ProgressEvent(*step))), None
    if not progress:
        return None, None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None, None
    bar = _Bar(tqdm)
    return (lambda *step: bar(ProgressEvent(*step))), bar


def _export_count(export: Union[bool, int, str]):
    """``export`` as the native search takes it: (write files, how many most robust
    designs get every file (``None``: the default), every design gets every file)."""
    if export is True or export is False:
        return export, None, False
    if isinstance(export, numbers.Integral) and export >= 0:
        return True, int(export), False
    if isinstance(export, str) and export.strip().lower() == "all":
        return True, None, True
    raise ValueError(
        f"export={export!r}: True (the 20 most robust designs' files), False (none), "
        "a number of designs (the most robust) or 'all'"
    )


def _count_or_all(name: str, value: Union[int, str], default: int):
    """``(N, False)`` for a number of designs, ``(None, True)`` for ``"all"``."""
    if isinstance(value, str) and value.strip().lower() == "all":
        return None, True
    if isinstance(value, numbers.Integral) and not isinstance(value, bool) and value >= 0:
        return int(value), False
    raise ValueError(f"{name}={value!r}: a number of designs (default {default}) or 'all'")


def synthesize(
    task: Union[_native.Task, PathLike],
    *,
    out: PathLike,
    n_max: Optional[int] = None,
    jobs: int = 0,
    starts: int = 16,
    seed: int = 0,
    sweep: int = 181,
    resume: bool = False,
    force: bool = False,
    export: Union[bool, int, str] = True,
    report_motions: Union[int, str] = 100,
    report_designs: Union[int, str] = 1000,
    shard: Optional[str] = None,
    rules: str = "r1,r2",
    post_check_only: bool = False,
    strategy: str = "exhaustive",
    budget_alternatives: Optional[int] = None,
    budget_cpu: Optional[float] = None,
    warm_starts: bool = True,
    progress: Union[bool, Callable[[ProgressEvent], Any]] = True,
) -> "Run":
    """Run the whole method on ``task`` (a ``Task`` or a task file) into the directory
    ``out``, as ``foldsynth synthesize TASK --out OUT`` does, and return the ``Run``.

    The options are the CLI's: ``n_max`` (``--n-max``, default the task's), ``jobs``
    (worker threads, 0 = one per core), ``starts`` and ``seed`` (the optimizer's starting
    points), ``sweep`` (states of the verification sweep), ``resume`` (keep the records
    of an earlier run of the same settings and evaluate only the rest), ``force`` (use a
    directory holding something else), ``export`` (``--export``: ``True`` writes every
    design's FOLD file and the other files of the 20 most robust, a number ``N`` those of
    the ``N`` most robust, ``"all"`` every design's, ``False`` = ``--no-export``),
    ``report_motions`` (``--report-motions``: how many of the most robust designs
    ``report.html`` draws with their whole motion, or ``"all"``), ``report_designs``
    (``--report-designs``: how many of the most robust designs it carries in full, every
    design being a row of its table, or ``"all"``),
    ``shard`` (``--shard``: ``"K/N"`` runs only shard K of N into ``out``, records only;
    ``foldsynth merge`` joins the shards, ``Run.open`` reads each), ``rules`` (``"r1,r2"``
    or ``"r1,r2,r2p"``), ``post_check_only``, ``strategy`` (``--strategy``: ``"exhaustive"``
    or ``"guided"``), ``budget_alternatives`` and ``budget_cpu`` (a guided search's budget
    in alternatives or CPU seconds), ``warm_starts`` (``False`` = ``--no-warm-starts``).

    The search runs natively with the GIL released. ``progress``: ``True`` shows a tqdm bar
    per phase where tqdm is installed (nothing otherwise), ``False`` nothing, a callable is
    called with a ``ProgressEvent`` on this thread. Ctrl-C (or an exception from the
    callback) stops the search after the alternatives in flight: the records so far stay,
    and ``resume=True`` continues. Errors in the task or settings raise ``FoldsynthError``.
    """
    if not isinstance(task, _native.Task):
        task = _native.Task.load(os.fspath(task))
    on, top, every = _export_count(export)
    motions, motions_all = _count_or_all("report_motions", report_motions, 100)
    designs, designs_all = _count_or_all("report_designs", report_designs, 1000)
    callback, bar = _progress_callback(progress)
    try:
        _native.synthesize(
            task,
            os.fspath(out),
            jobs=jobs,
            starts=starts,
            seed=seed,
            resume=resume,
            force=force,
            n_max=n_max,
            sweep=sweep,
            export=on,
            export_top=top,
            export_all=every,
            report_motions=motions,
            report_motions_all=motions_all,
            report_designs=designs,
            report_designs_all=designs_all,
            shard=shard,
            rules=rules,
            post_check_only=post_check_only,
            strategy=strategy,
            budget_alternatives=budget_alternatives,
            budget_cpu=budget_cpu,
            warm_starts=warm_starts,
            callback=callback,
        )
    finally:
        if bar is not None:
            bar.close()
    return Run(out, task=task)


def _read_json(path: pathlib.Path) -> Any:
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError:
        raise _native.FoldsynthError(f"{path}: no such file") from None
    except json.JSONDecodeError as e:
        raise _native.FoldsynthError(f"{path}: not JSON ({e})") from None


def _flat(record: Dict[str, Any], prefix: str = "") -> Dict[str, Any]:
    """Nested objects as dotted columns (``verification.isometry_max``,
    ``robustness.rigid_margin.value``, ``variables.α_3``); lists stay lists."""
    row: Dict[str, Any] = {}
    for key, value in record.items():
        name = prefix + key
        if isinstance(value, dict):
            row.update(_flat(value, name + "."))
        else:
            row[name] = value
    return row


def _table(rows: List[Dict[str, Any]], kind: str) -> Any:
    """Flat rows as a pandas DataFrame, a pyarrow Table or the rows themselves."""
    if kind == "auto":
        try:
            import pandas  # noqa: F401

            kind = "pandas"
        except ImportError:
            try:
                import pyarrow  # noqa: F401

                kind = "arrow"
            except ImportError:
                kind = "records"
    columns: Dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    # A nested field that is null in some records (`verification` of an alternative that
    # was not verified) and an object in others is its dotted columns alone.
    nested = {c.split(".", 1)[0] for c in columns if "." in c}
    for c in nested & set(columns):
        if all(row.get(c) is None for row in rows):
            del columns[c]
    if kind == "pandas":
        import pandas

        return pandas.DataFrame(rows, columns=list(columns))
    if kind == "arrow":
        import pyarrow

        # Every row's keys (from_pylist would take the first row's only).
        return pyarrow.table({c: [row.get(c) for row in rows] for c in columns})
    if kind == "records":
        return rows
    raise ValueError(f"as_={kind!r}: expected 'auto', 'pandas', 'arrow' or 'records'")


class Frames(NamedTuple):
    """A design's folded states: ``t`` (F,), vertex ``coords`` (F, V, 3) and each
    crease's ``fold_angles`` (F, E) in radians (valley positive), F states over [0, t_max],
    V vertices and E edges in the order of the design's pattern (and its FOLD file)."""

    t: np.ndarray
    coords: np.ndarray
    fold_angles: np.ndarray


class Design:
    """One design of a run: ``designs/<id>.json`` (docs/outputs.md lists every field).

    ``data`` is the whole file as a dict; the attributes below are its common fields.
    """

    def __init__(self, run: "Run", design_id: str) -> None:
        self.run = run
        #: The design's id, ``g<graph>-c<candidate>-<modes>``.
        self.id = design_id
        #: The design JSON file.
        self.path = run.path / "designs" / f"{design_id}.json"
        if not self.path.exists():
            raise _native.FoldsynthError(
                f"{self.path}: no such design in {run.path} (its designs: {', '.join(run.design_ids[:5])}"
                + (", …)" if len(run.design_ids) > 5 else ")")
            )
        #: The design file as a dict.
        self.data: Dict[str, Any] = _read_json(self.path)

    @property
    def rank(self) -> int:
        """1 for the most robust design."""
        return self.data["rank"]

    @property
    def sequence(self) -> str:
        """The graph's rule sequence."""
        return self.data["sequence"]

    @property
    def candidate(self) -> int:
        """The gripping candidate, 1–3."""
        return self.data["candidate"]

    @property
    def gripping_vertex(self) -> int:
        """The gripping vertex's number K (``v<K>``; row K − 1 of the coordinates)."""
        return self.data["gripping_vertex"]

    @property
    def modes(self) -> List[str]:
        """``"up"``/``"down"`` per internal vertex, in extension order."""
        return list(self.data["modes"])

    @property
    def objective(self) -> float:
        """Ω* (Eq. 37/38) at the design."""
        return self.data["objective"]

    @property
    def variables(self) -> Dict[str, float]:
        """The optimized free variables by name (radians, lengths in the task's units)."""
        return dict(self.data["variables"])

    def x(self, model: Optional[_native.Model] = None) -> np.ndarray:
        """The free variables as an array in the order of ``model.names`` (``model``:
        this design's, ``self.model()``, unless given), ready for
        ``model.value_and_grad(design.x(model), design.modes)``."""
        model = model or self.model()
        values = self.data["variables"]
        missing = [n for n in model.names if n not in values]
        if missing or len(values) != len(model.names):
            raise _native.FoldsynthError(
                f"{self.path}: its variables ({', '.join(values)}) are not those of "
                f"{model!r} ({', '.join(model.names)})"
            )
        return np.array([values[n] for n in model.names], dtype=float)

    @property
    def robustness(self) -> Optional[Dict[str, Any]]:
        """The margins measured on the sweep and the score (None when not measured)."""
        return self.data.get("robustness")

    @property
    def verification(self) -> Dict[str, Any]:
        """The independent verification on the sweep (isometry, closure, rigidity…)."""
        return self.data["verification"]

    @property
    def frames(self) -> Frames:
        """The folded states as NumPy arrays (see ``Frames``)."""
        # The file stores positions only; the native reader adds the fold angles.
        t, coords, angles = _native.design_frames(os.fspath(self.path))
        return Frames(
            t=np.array(t, dtype=float),
            coords=np.array(coords, dtype=float).reshape(len(t), -1, 3),
            fold_angles=np.array(angles, dtype=float).reshape(len(t), -1),
        )

    @property
    def tip_path(self) -> np.ndarray:
        """The gripping vertex's position in every state: an (F, 3) array."""
        return self.frames.coords[:, self.gripping_vertex - 1, :]

    def fold(self) -> Dict[str, Any]:
        """The design's FOLD 1.2 document as a dict (``vertices_coords``,
        ``edges_vertices``, ``edges_assignment``, ``faces_vertices``, ``file_frames``…,
        the FOLD format's own keys) with every frame of its motion, made from the design
        file exactly as ``foldsynth export`` makes it (the run's own FOLD file of a design
        outside ``--export N`` holds the folded form only)."""
        return json.loads(_native.design_fold(os.fspath(self.path)))

    def save_fold(self, path: PathLike) -> pathlib.Path:
        """Write the FOLD document (``fold()``) to ``path``; returns the path."""
        path = pathlib.Path(path)
        path.write_text(json.dumps(self.fold(), indent=1) + "\n", encoding="utf-8")
        return path

    def model(self, task: Optional[_native.Task] = None) -> _native.Model:
        """The compiled design model of this design's graph and gripping candidate
        (``task.model(sequence, candidate)``): evaluate it at ``x`` with ``modes``. The
        task is the run's (``Run(path, task=…)``, or the one ``synthesize`` ran) unless
        given; a run directory does not keep its task file."""
        task = task or self.run.task
        if task is None:
            raise _native.FoldsynthError(
                f"{self.run.path}: the run does not know its task: pass it, "
                "design.model(foldsynth.Task.load('TASK.toml')), or open the run with "
                "Run.open(path, task=…)"
            )
        if task.name != self.data["task"]:
            raise _native.FoldsynthError(
                f"design {self.id} is of task '{self.data['task']}', not '{task.name}'"
            )
        return task.model(self.sequence, candidate=self.candidate)

    def __repr__(self) -> str:
        return f"Design('{self.id}', rank={self.rank}, sequence='{self.sequence}')"


class Run:
    """A run directory: its settings, summary, records and designs.

    ``Run.open(path)`` reads any run directory — one ``foldsynth synthesize`` or
    ``foldsynth.synthesize`` wrote, one ``foldsynth merge`` made of shards, or a single
    shard (which has records but no summary or designs yet).
    """

    def __init__(self, path: PathLike, task: Optional[_native.Task] = None) -> None:
        #: The run directory.
        self.path = pathlib.Path(path)
        #: The task (for ``Design.model``), when known.
        self.task = task
        #: ``settings.json``: what decides the records (task, digest, n_max, starts, seed…).
        self.settings: Dict[str, Any] = _read_json(self.path / "settings.json")
        self._summary: Optional[Dict[str, Any]] = None

    @classmethod
    def open(cls, path: PathLike, task: Optional[_native.Task] = None) -> "Run":
        """Open the run directory ``path`` (``task``: the run's task, for ``Design.model``)."""
        path = pathlib.Path(path)
        if not path.is_dir():
            raise _native.FoldsynthError(f"{path}: not a directory")
        if not (path / "settings.json").exists():
            raise _native.FoldsynthError(
                f"{path}: not a foldsynth run (no settings.json; a run directory holds "
                "settings.json, alternatives.jsonl and, once finished, summary.json)"
            )
        return cls(path, task=task)

    @property
    def finished(self) -> bool:
        """Whether the run wrote its summary (a shard or an interrupted run has not)."""
        return (self.path / "summary.json").exists()

    @property
    def summary(self) -> Dict[str, Any]:
        """``summary.json``: the counts, timings, settings and the ranking."""
        if self._summary is None:
            if not self.finished:
                what = "a shard: merge the shards" if (self.path / "shard.json").exists() else (
                    "an unfinished run: run it again with resume=True"
                )
                raise _native.FoldsynthError(f"{self.path}: no summary.json yet ({what})")
            self._summary = _read_json(self.path / "summary.json")
        return self._summary

    @property
    def ranking(self) -> List[str]:
        """The design ids, most robust first."""
        return [r["id"] for r in self.summary["ranking"]]

    @property
    def design_ids(self) -> List[str]:
        """Every design's id (as ``summary.json``'s ``designs``)."""
        return list(self.summary["designs"])

    @property
    def parquet(self) -> Optional[pathlib.Path]:
        """``alternatives.parquet`` when the run wrote one (pandas, Polars and DuckDB read
        it directly), else None."""
        p = self.path / "alternatives.parquet"
        return p if p.exists() else None

    def records(self) -> Iterator[Dict[str, Any]]:
        """The records of ``alternatives.jsonl``, one dict per alternative, in file
        order (streamed: memory does not grow with the run)."""
        path = self.path / "alternatives.jsonl"
        try:
            f = open(path, encoding="utf-8")
        except FileNotFoundError:
            raise _native.FoldsynthError(f"{path}: no such file") from None
        with f:
            for n, line in enumerate(f, 1):
                if not line.strip():
                    continue
                try:
                    yield json.loads(line)
                except json.JSONDecodeError as e:
                    raise _native.FoldsynthError(f"{path}, line {n}: not JSON ({e})") from None

    def alternatives(self, as_: str = "auto") -> Any:
        """Every alternative (``alternatives.jsonl``), one row each, nested fields as dotted
        columns (``verification.rigid_over_motion``, ``robustness.score``, ``variables.α_3``),
        plus ``id`` (the design id the alternative would have). ``as_``: ``"pandas"`` (a
        DataFrame), ``"arrow"`` (a pyarrow Table), ``"records"`` (a list of dicts), or
        ``"auto"``: pandas where installed, else pyarrow, else records."""
        return _table([self._row(r) for r in self.records()], as_)

    def designs(self, as_: str = "auto") -> Any:
        """The designs, most robust first: their records as in ``alternatives()`` with
        ``rank`` (1 = most robust) and ``score`` (the smallest margin over its setting)."""
        ranked = {r["id"]: (k + 1, r["score"]) for k, r in enumerate(self.summary["ranking"])}
        rows = []
        for r in self.records():
            row = self._row(r)
            if row["id"] in ranked:
                row["rank"], row["score"] = ranked[row["id"]]
                rows.append(row)
        rows.sort(key=lambda row: row["rank"])
        return _table(rows, as_)

    @staticmethod
    def _row(record: Dict[str, Any]) -> Dict[str, Any]:
        row = {"id": _design_id(record)}
        row.update(_flat(record))
        return row

    def design(self, which: Union[str, int]) -> Design:
        """A design by id (``"g01-c2-d"``) or by rank (1 = the most robust)."""
        if isinstance(which, numbers.Integral) and not isinstance(which, bool):
            which = int(which)
            ranking = self.ranking
            if not 1 <= which <= len(ranking):
                raise _native.FoldsynthError(
                    f"{self.path}: no design of rank {which} ({len(ranking)} designs)"
                )
            which = ranking[which - 1]
        return Design(self, str(which))

    def __repr__(self) -> str:
        state = (
            f"{len(self.summary['designs'])} designs of {self.summary['alternatives']} alternatives"
            if self.finished
            else "not finished"
        )
        return f"Run('{self.path}', task='{self.settings.get('task')}', {state})"


def _design_id(record: Dict[str, Any]) -> str:
    """``g<graph + 1, two digits>-c<candidate>-<u/d per mode>``, as the search names a
    design (search::record::AlternativeRecord::id)."""
    modes = "".join(m[:1] for m in record["modes"])
    return f"g{record['graph'] + 1:02}-c{record['candidate']}-{modes}"
