"""One run, whoever asks for it: ``simparity run``, :func:`simparity.run_scene` and the pytest fixture.

A :class:`Session` owns a run from its scenes to its verdict: the scenes (as its profile runs them), the
engines (described once; a user's engine is asked about itself in a process of its own), where the cases
execute (:class:`Execution`: isolated worker processes, a Dask cluster, or this process when asked), the
journal and the stored run when it has a folder, the history it is recorded in, and the tolerances it is
held to. The CLI parses arguments into a session and prints what it hands back; the API and the fixture
build one with their defaults. Nothing of a session outlives it: no module state, its engines are its own.

Isolation costs a process's first session about a second (the zygote's imports, :mod:`comparisons.common.zygote`;
each worker is forked from it) and cannot reach an engine that only exists in the calling process: a class defined
in ``__main__`` (a script run directly, a notebook) cannot be imported by a worker, which starts as a fresh
interpreter would (like multiprocessing's *spawn*). Such an engine is refused with one line naming both ways out: move it into a
module on the import path, or run in this process (``isolate=False``), where a crash of the engine ends the
caller's interpreter.
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence, TypeVar

import pandas as pd

from simparity.comparisons.engines.registry import EngineSet, check_engine_names, make_engine
from simparity.comparisons.execute.execution import Executor, default_jobs, estimate, run_scenes
from simparity.comparisons.execute.in_process import InProcessExecutor
from simparity.comparisons.execute.isolation import DEFAULT_CASE_SECONDS, CaseLimits, IsolatedPool
from simparity.comparisons.execute.journal import Journal, run_lock, write_request
from simparity.comparisons.execute.progress import ProgressBar
from simparity.comparisons.execute.runner import DEFAULT_REPEATS
from simparity.comparisons.gate.bound_names import offered, refuse_impossible
from simparity.comparisons.gate.check import CheckResult, check_table
from simparity.comparisons.gate.history import record_run
from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, Bound, load_tolerances
from simparity.comparisons.gate.check_output import report_verdict
from simparity.comparisons.invariance.invariance_run import invariance_rows
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.comparisons.scenes.profiles import apply_profile
from simparity.core.model.engine import Engine
from simparity.core.model.errors import HistoryError, SimparityError, one_line
from simparity.core.model.results import (COLUMNS, FAILED, REPORT_FILE, REPORT_HTML_FILE, RESULTS_FILE, ResultRow,
                                          SeriesRecord, case_counts)
from simparity.reports.store import RunWriter, read_info, read_run

ISOLATED, DASK, IN_PROCESS = "local", "dask", "inline"
"""Where a session's cases run: worker processes here (each case's engine in a child of its own), a Dask
cluster (the same worker inside each task), or this process (``isolate=False``: fastest, unprotected)."""

Say = Callable[[str], None]


def _silent(line: str) -> None:
    return None


@dataclass(frozen=True)
class Execution:
    """Where and under which limits a session's cases run.

    ``limits`` None: a share of this machine's memory per worker (:meth:`CaseLimits.default`) here, each
    node's own limit on Dask. ``scheduler``: a Dask scheduler's address (None: a local cluster)."""

    where: str = ISOLATED
    jobs: int = field(default_factory=default_jobs)
    limits: CaseLimits | None = None
    scheduler: str | None = None

    @property
    def workers(self) -> int:
        """Cases that run at once: ``jobs``, one in this process (``inline``)."""
        return 1 if self.where == IN_PROCESS else self.jobs

    @property
    def case_seconds(self) -> float | None:
        """The wall time [s] a case may take before it is killed; None in this process (nothing kills it)."""
        return None if self.where == IN_PROCESS else (self.limits.seconds if self.limits else DEFAULT_CASE_SECONDS)

    def executor(self, engine_for: Callable[[str], Engine]) -> Executor:
        """A new executor of this kind; ``engine_for`` builds an engine in this process (``inline`` only)."""
        if self.where == IN_PROCESS:
            return InProcessExecutor(engine_for)
        if self.where == DASK:
            from simparity.comparisons.execute.dask_executor import DaskExecutor  # imports Dask: only when asked

            return DaskExecutor(self.scheduler, self.jobs, self.limits or CaseLimits(DEFAULT_CASE_SECONDS, None))
        return IsolatedPool(self.jobs, self.limits or CaseLimits.default(self.jobs))


@dataclass(frozen=True)
class WallSplit:
    """Where a session's wall time went [s]: ``cases`` (run by the workers, each journaled, the scenes assembled,
    the workers started and stopped), ``storing`` (results.csv, the series, the typed copy, the history) and
    ``report`` (report.md, report.html and the figures; 0 when none was drawn)."""

    cases: float = 0.0
    storing: float = 0.0
    report: float = 0.0

    def line(self, total: float) -> str:
        """One line of the split of a command that took ``total`` seconds of wall time, the rest named."""
        rest = max(total - self.cases - self.storing - self.report, 0.0)
        return (f"wall time by part: cases {self.cases:.1f} s, storing {self.storing:.1f} s, report "
                f"{self.report:.1f} s, the rest {rest:.1f} s (start-up, imports, planning, the check)")


@dataclass(frozen=True)
class SessionResult:
    """What a session hands back.

    ``table``: every row (the columns of ``results.csv``); ``failed_cases``: cases whose engine raised or
    crashed; ``unfinished``: cases that did not finish (``--resume`` tries them again); ``unreadable``: kept
    cases of a resumed run that could not be read and were computed again; ``check``: the verdict when the
    session was given tolerances; ``wall``: where its wall time went."""

    out_dir: Path | None
    table: pd.DataFrame
    failed_cases: int = 0
    unfinished: int = 0
    unreadable: int = 0
    check: CheckResult | None = None
    interrupted: bool = False
    wall: WallSplit = WallSplit()


T = TypeVar("T")


def _timed(fn: Callable[[], T]) -> tuple[float, T]:
    """(wall time [s] of ``fn()``, its result)."""
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


def engine_specs(engines) -> tuple[str, ...]:
    """The names or ``module:Class`` specs of ``engines`` (names, Engine subclasses or instances, mixed): what a
    worker process builds them from. An instance is built again there from its class."""
    specs = []
    for engine in engines:
        if isinstance(engine, str):
            specs.append(engine)
            continue
        cls = engine if isinstance(engine, type) else type(engine)
        if not (isinstance(cls, type) and issubclass(cls, Engine)):
            raise SimparityError(f"engines: {one_line(repr(engine))} is neither an engine name nor an Engine (allowed: "
                                 "names as 'simparity engines' lists them, module:Class, Engine subclasses or instances)")
        specs.append(f"{cls.__module__}:{cls.__qualname__}")
    return tuple(specs)


def refuse_unreachable(specs: tuple[str, ...]) -> None:
    """Refuse, in one line, an engine a worker process cannot import: one defined in ``__main__``."""
    for spec in specs:
        module, _, attr = spec.partition(":")
        if attr and module == "__main__":
            raise SimparityError(
                f"engine {one_line(spec)}: defined in __main__ (a script run directly, or a notebook), which a worker "
                "process cannot import: isolated runs start each worker as a fresh interpreter would be (allowed: move the "
                "engine into a module on the import path, or run it in this process with isolate=False, where a "
                "crash of the engine ends this interpreter)")


class Session:
    """One run of ``scenes`` (loaded with the same ``engines``; the profile is applied here) on ``engines``.

    ``out_dir`` None keeps the run in memory (no journal, report or history); with a folder, the run is
    stored there as it goes (``results.csv``, the journal of finished cases, ``report.md``/``.html`` when
    ``report``), recorded in ``history`` (a database path; None: not recorded) and, with ``request``,
    resumable (``resume.json``). ``resume``: keep the folder's finished cases. ``bounds``: tolerances the
    finished run is held to; ``held``: the engines that gate holds (None: every one), whose report opens with "is
    my engine right?" for each of the user's. ``say`` hears, before the cases start, how long they are modelled to
    take (:mod:`comparisons.execute.estimate`), then one line per scene as it finishes and what the run wrote (without
    ``report``: where the report would be and the command that draws it), ``warn`` what went wrong beside the run
    (default: ``say``); ``progress`` is a stream for the progress bar, or its heartbeat lines when the stream is no
    terminal (None: neither). :attr:`SessionResult.wall` says where the run's wall time went."""

    def __init__(self, scenes: list, engines: EngineSet, *, profile: str = "full", repeats: int = DEFAULT_REPEATS,
                 execution: Execution = Execution(), out_dir: Path | None = None, history: Path | None = None,
                 bounds: list[Bound] | None = None, held: tuple[str, ...] | None = None, transforms: tuple = (),
                 command: str = "", report: bool = True,
                 request: dict | None = None, resume: bool = False, say: Say = _silent, warn: Say | None = None,
                 progress=None) -> None:
        self.names = check_engine_names(engines.names)
        if execution.where != IN_PROCESS:
            refuse_unreachable(self.names)
        self.scenes, self.profile = apply_profile(list(scenes), profile, engines), profile
        self.repeats, self.execution, self.out_dir = repeats, execution, out_dir
        self.history, self.bounds, self.transforms, self.command = history, bounds, tuple(transforms), command
        self.held = held
        self.report, self.request, self.resume, self.say, self.progress = report, request, resume, say, progress
        self.warn = warn or say
        if execution.where == IN_PROCESS:
            self.engines = [make_engine(n) for n in self.names]  # the caller asked for its engines in its process
        else:
            self.engines = engines.describe(self.names, self.scenes)
        self.probes = engines.probes  # kept to ask the engines about transformed scenes; without any, ended now:
        if not self.transforms:       # no idle process holds a user's engine through the run's cases
            self.probes.close()
        check_distinct(self.engines, self.names, self.scenes)
        self.specs = dict(zip((e.name for e in self.engines), self.names))
        if bounds is not None:  # before any case runs: a bound that can match nothing is bad input
            refuse_impossible(bounds, {"scene": [s.name for s in self.scenes], "engine": [e.name for e in self.engines],
                                       "integrator": offered(self.engines)})

    def run(self, start: Callable[[], str] | None = None) -> SessionResult:
        """Run every case, store and check the run; a SimparityError raised midway keeps what was computed
        (stored and reported) and is raised again. ``start()``, once the executor and the folder are ready, gives
        a line to say first (what the run will do)."""
        engines = {e.name: e for e in self.engines}

        def engine_for(name: str) -> Engine:
            if name not in engines:
                engines[name] = make_engine(self.specs.get(name, name))
            return engines[name]

        executor = self.execution.executor(engine_for)  # an unreachable scheduler fails before a folder is made
        with contextlib.closing(executor), self._folder():
            if start is not None:
                self.say(start())
            return self._run(executor)

    @contextlib.contextmanager
    def _folder(self):
        if self.out_dir is None:
            yield
            return
        with run_lock(made(self.out_dir)):
            if not self.resume:  # a new run: nothing of a run --force replaces is reused
                if self.request is not None:
                    write_request(self.out_dir, self.request)
                Journal(self.out_dir).clear()
            yield

    def _run(self, executor: Executor) -> SessionResult:
        journal = Journal(self.out_dir) if self.out_dir is not None else None
        store = _Store(self.out_dir, self.engines, self.command, self.scenes, self.profile)
        sizes, cost = estimate(self.scenes, self.engines, make_engine, self.execution.workers, journal, self.specs)
        self.say(cost.line(self.execution.case_seconds))
        bar = ProgressBar(sum(sizes), self.progress, estimate=cost) if self.progress is not None else None
        size = {scene.name: n for scene, n in zip(self.scenes, sizes)}
        failed, started = 0, time.perf_counter()

        def scene_done(scene, rows: list[ResultRow]) -> None:  # as it finishes, whatever order the scenes finish in
            counts = case_counts(rows)
            if bar is not None:
                bar.scene_done(scene.name, size[scene.name])
            self.say(f"{scene.name}: {sum(counts.values())} cases (" + ", ".join(f"{s} {c}" for s, c in counts.items()
                                                                                if c) + ")")

        try:
            # the workers stop as soon as the cases do, before the report; the store then writes its typed copy
            with contextlib.closing(executor), contextlib.closing(store), \
                    bar if bar is not None else contextlib.nullcontext():
                base_rows = []
                for scene, rows, series in run_scenes(self.scenes, self.engines, make_engine, self.repeats, executor,
                                                      journal, bar.case_done if bar is not None else None, self.specs,
                                                      scene_done):
                    store.append(rows, series)
                    failed += case_counts(rows)[FAILED]
                    if self.transforms:  # the invariance rows need them; else they are in the store alone
                        base_rows.append(rows)
                if self.transforms:
                    if bar is not None:
                        bar.clear()
                    for rows in invariance_rows(self.scenes, base_rows, self.transforms, self.engines, executor,
                                                journal, self.specs, self.probes, self.say):
                        store.append(rows)
                        failed += sum(1 for r in rows if r.status == FAILED)
        except KeyboardInterrupt:
            if self.out_dir is not None:
                self.say(f"interrupted; results so far are in {self.out_dir / RESULTS_FILE}; finish the run with: "
                         f"simparity run --resume {self.out_dir}")
            cases = time.perf_counter() - started - store.seconds
            wall = WallSplit(cases, store.seconds, _timed(lambda: self._write_report(store.table()))[0])
            return SessionResult(self.out_dir, store.table(), failed, interrupted=True, wall=wall)
        except SimparityError:
            if store.closed:
                self._write_report(store.table())  # keep what was computed, then report the error
            raise
        unfinished = unreadable = 0
        if journal is not None:
            unfinished, unreadable = journal.unfinished, journal.unreadable
            if unreadable:
                self.say(f"{unreadable} kept cases could not be read (damaged, or kept by another version of "
                         "simparity) and were computed again")
            if unfinished:
                self.say(f"{unfinished} cases did not finish (crashed, hung or out of memory): 'simparity run "
                         f"--resume {self.out_dir}' tries them again")
            else:
                journal.remove()
        table, cases = store.table(), time.perf_counter() - started - store.seconds
        recording, _ = _timed(lambda: self._record(table))  # before the report: a report that cannot be drawn never
        drawing, checked = _timed(lambda: self._write_report(table))  # costs the run its history
        check = None
        if self.bounds is not None:
            check = checked if checked is not None else check_table(table, self.bounds)
        return SessionResult(self.out_dir, table, failed, unfinished, unreadable, check,
                             wall=WallSplit(cases, store.seconds + recording, drawing))

    def _write_report(self, table: pd.DataFrame) -> CheckResult | None:
        """report.md, report.html and figures/ of a stored run (when asked for), ``table`` its rows; its metrics held to
        the session's bounds (default: the shipped tolerances) for the report's flagged findings. Returns that verdict."""
        if self.out_dir is None or table.empty:  # empty: interrupted before its first row
            return None
        if not self.report:
            self.say(f"results: {self.out_dir / RESULTS_FILE}\nreport:  not drawn (asked for none); 'simparity report "
                     f"{self.out_dir}' draws {self.out_dir / REPORT_FILE} and {REPORT_HTML_FILE} beside it")
            return None
        return write_run_report(self.out_dir, self.say, self.bounds, self.held, table)

    def _record(self, table: pd.DataFrame) -> None:
        """Copy a stored run (``table``: its rows) into the history database; a database problem is one line, never a
        lost run."""
        if self.out_dir is None or self.history is None:
            return
        try:
            record_run(self.history, self.out_dir.resolve(), read_info(self.out_dir), table)
        except HistoryError as err:
            self.warn(f"simparity: history not updated: {one_line(err, 1000)}; the run is in {self.out_dir}")


class _Store:
    """Where a session's rows go: the run folder (``RunWriter``), or memory when it has none."""

    def __init__(self, out_dir: Path | None, engines: list[Engine], command: str, scenes: list, profile: str) -> None:
        self.writer = RunWriter(out_dir, describe_run(engines, command, scenes, profile)) if out_dir is not None else None
        self.rows: list[ResultRow] = []
        self.written: pd.DataFrame | None = None
        self.closed = False
        self.seconds = 0.0
        """Wall time [s] spent storing rows so far."""

    def append(self, rows: list[ResultRow], series: Sequence[SeriesRecord] = ()) -> None:
        start = time.perf_counter()
        if self.writer is not None:
            self.writer.append(rows, series)
        else:
            self.rows += rows
        self.seconds += time.perf_counter() - start

    def close(self) -> None:
        """Every row is in: the stored run read back once and its typed copy (``results.parquet``) written, when it
        has a folder."""
        start = time.perf_counter()
        if self.writer is not None:
            self.written = self.writer.finish()
        self.closed = True
        self.seconds += time.perf_counter() - start

    def table(self) -> pd.DataFrame:
        """Every row of the run (after :meth:`close`): as the writer read ``results.csv`` back, or from memory."""
        if self.written is not None:
            return self.written
        return pd.DataFrame([r.as_dict() for r in self.rows], columns=list(COLUMNS))


def write_run_report(out_dir: Path, say: Say, bounds: list[Bound] | None = None,
                     held: tuple[str, ...] | None = None, table: pd.DataFrame | None = None) -> CheckResult:
    """report.md, report.html and figures/ of the run in ``out_dir`` (``table``: its rows, as the writer handed them
    back; None: read from the folder); its metrics are held to ``bounds`` (default: the shipped tolerances) for the
    report's flagged findings, which never changes an exit code. Returns that verdict."""
    from simparity.reports.render import write_report  # imports matplotlib: only when a report is drawn

    if table is None:
        table, _ = read_run(out_dir)
    result = check_table(table, bounds if bounds is not None else load_tolerances(DEFAULT_TOLERANCES))
    verdict = report_verdict(result, held)
    markdown, page = write_report(out_dir, verdict, table)
    say(f"results: {Path(out_dir) / RESULTS_FILE}\nreport:  {markdown}\n         {page}")
    return result


def made(out_dir: Path) -> Path:
    """``out_dir``, created if it is not there."""
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except (OSError, ValueError) as err:  # ValueError: a NUL byte in the name
        raise SimparityError(f"--out {one_line(out_dir)}: cannot create the folder: {getattr(err, 'strerror', None) or err} "
                             "(allowed: a folder you can write)") from None
    return out_dir


def check_distinct(engines: list[Engine], names: tuple[str, ...], scenes: list) -> None:
    """Refuse two engines or two scenes of one name: their rows would be indistinguishable."""
    seen: dict[str, str] = {}
    for engine, name in zip(engines, names):
        if engine.name in seen:
            raise SimparityError(f"--engines: {one_line(seen[engine.name])} and {one_line(name)} are both named "
                                 f"{one_line(engine.name)} (allowed: engines of distinct names)")
        seen[engine.name] = name
    files: dict[str, str] = {}
    sweeps: dict[str, str] = {}
    for scene in scenes:
        if scene.name in files:
            raise SimparityError(f"{one_line(scene.source or scene.name)}: a second scene named {one_line(scene.name)} "
                                 f"(the first from {one_line(files[scene.name])}) (allowed: scenes of distinct names)")
        files[scene.name] = scene.source or scene.name
        if scene.sweep is not None and sweeps.setdefault(scene.sweep.base, scene.source) != scene.source:
            raise SimparityError(f"{one_line(scene.source)}: a second sweep named {one_line(scene.sweep.base)} (the "
                                 f"first from {one_line(sweeps[scene.sweep.base])}): the results and the report group a "
                                 "sweep's variants by that name (allowed: sweeps of distinct [scene] names)")

