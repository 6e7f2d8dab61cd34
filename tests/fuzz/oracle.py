"""One fuzzed input, how it is tried, and the oracle that judges what came back.

An input is refused when the command exits 2 with exactly one line on stderr, ``simparity: error: ...``, that names
what was wrong (the file, key or option the case says), with no traceback and no warning. A *silent pass* is exit 0
on an input that is not valid. Inputs are tried in this process (``comparisons.cli.main.main(argv)``, stdout and
stderr captured, warnings recorded as a user's terminal would show them) or, for a few, as a ``simparity``
subprocess; either way under a per-input timeout, so no input can hang the sweep.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import signal
import subprocess
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

CPU_SECONDS = 30.0
"""Per-input timeout in CPU time of this process [s]: a refusal is made before anything runs (well under a second);
an input that is wrongly run goes through the tiny scene of :class:`Base` (a few seconds) or a stored run's report
(~8 s); past this it is a hang (the issue's 100,000-bound tolerance file ran past 60 s). CPU time, not wall time:
the machine the sweep runs on may be shared."""
WALL_SECONDS = 240.0
"""Per-input timeout in wall time [s]: for what waits without using CPU here (worker processes, a lock)."""

ERROR_PREFIX = "simparity: error: "
REFUSED, FAILS, VALID, VALID_OR_FAILS, EITHER = (frozenset({2}), frozenset({1, 2}), frozenset({0}), frozenset({0, 1}),
                                                 frozenset({0, 2}))
"""Exit codes a case accepts. REFUSED: bad input. FAILS: a check that must not pass (a run that checks nothing:
exit 1 or a refusal). VALID: a control. VALID_OR_FAILS: a control whose verdict may go either way (a check of a
baseline that moved). EITHER: debatable inputs (a lenient reader or a refusal are both honest): only tracebacks,
warnings and a refusal that is not one line fail."""

_SHOWN_WARNINGS_IGNORED = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)
"""Warning categories Python's default filters hide from a user's terminal: the rest reach stderr."""


@dataclass(frozen=True)
class Base:
    """What the inputs are made from: a valid stored run (``run_dir``: results.csv, run.json, series.csv.gz of one
    scene on one engine), the history database it was recorded in, and a scene file cheap enough to run (a few
    steps, for options that need ``simparity run``)."""

    run_dir: Path
    history: Path
    scene: Path


@dataclass(frozen=True)
class Call:
    """What a case asks of simparity: a command line (``argv``), or a library ``function`` of no arguments whose
    SimparityError is its refusal. ``names``: texts of which the refusal line must hold one (the file, key or
    option). ``keeps``: paths that must exist afterwards if their folder does (the results of a run that started
    before an output path failed)."""

    argv: tuple[str, ...] = ()
    function: Callable[[], object] | None = None
    names: tuple[str, ...] = ()
    keeps: tuple[Path, ...] = ()
    subprocess: bool = False


@dataclass(frozen=True)
class Case:
    """One fuzzed input: ``build(folder, base)`` writes it into ``folder`` and returns the :class:`Call`;
    ``accept``: the exit codes that are right for it."""

    family: str
    name: str
    build: Callable[[Path, Base], Call]
    accept: frozenset[int] = REFUSED
    note: str = ""

    @property
    def id(self) -> str:
        return f"{self.family}/{self.name}"


@dataclass
class Outcome:
    code: int | None
    out: str = ""
    err: str = ""
    escaped: str = ""              # "ExceptionType: message" of an exception no handler turned into a line
    warned: list[str] = field(default_factory=list)
    timed_out: bool = False


class InputTimeout(BaseException):
    """The per-input timeout: a BaseException, so no ``except Exception`` of the code under test swallows it."""


@contextlib.contextmanager
def _deadline(cpu_seconds: float, wall_seconds: float):
    def expire(signum, frame):
        raise InputTimeout()

    timers = ((signal.SIGPROF, signal.ITIMER_PROF, cpu_seconds), (signal.SIGALRM, signal.ITIMER_REAL, wall_seconds))
    previous = [signal.signal(sig, expire) for sig, _, _ in timers]
    for _, timer, seconds in timers:
        signal.setitimer(timer, seconds)
    try:
        yield
    finally:
        for (sig, timer, _), handler in zip(timers, previous):
            signal.setitimer(timer, 0)
            signal.signal(sig, handler)


def try_call(call: Call, folder: Path, cpu_seconds: float = CPU_SECONDS, wall_seconds: float = WALL_SECONDS) -> Outcome:
    """Run ``call`` from ``folder`` (the working directory, so a path like ``''`` lands there) under the timeouts."""
    if call.subprocess:
        return _in_subprocess(call, folder, wall_seconds)
    from simparity.comparisons.cli.main import main
    from simparity.core.model.errors import SimparityError

    out, err = io.StringIO(), io.StringIO()
    outcome = Outcome(code=None)
    here, argv = os.getcwd(), sys.argv
    os.chdir(folder)
    sys.argv = ["simparity", *call.argv]
    try:
        with warnings.catch_warnings(record=True) as caught, contextlib.redirect_stdout(out), \
                contextlib.redirect_stderr(err), _deadline(cpu_seconds, wall_seconds):
            warnings.simplefilter("always")
            for category in _SHOWN_WARNINGS_IGNORED:
                warnings.simplefilter("ignore", category)
            try:
                if call.function is not None:
                    call.function()
                    outcome.code = 0
                else:
                    outcome.code = main(list(call.argv), out)
            except SystemExit as stop:
                outcome.code = stop.code if isinstance(stop.code, int) else 1
            except SimparityError as error:  # a library call's refusal
                print(ERROR_PREFIX + str(error), file=sys.stderr)
                outcome.code = 2
            except InputTimeout:
                outcome.timed_out = True
            except Exception as error:  # noqa: BLE001 - what escaped is the finding
                outcome.escaped = f"{type(error).__name__}: {str(error)[:200]}"
        outcome.warned = [f"{w.category.__name__}: {str(w.message)[:120]}" for w in caught]
    finally:
        os.chdir(here)
        sys.argv = argv
    outcome.out, outcome.err = out.getvalue(), err.getvalue()
    return outcome


_WARNING_LINE = re.compile(r"\b(\w+Warning): ")


def _in_subprocess(call: Call, folder: Path, seconds: float) -> Outcome:
    try:
        done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", *call.argv], cwd=folder,
                              capture_output=True, text=True, timeout=seconds, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return Outcome(code=None, timed_out=True)
    escaped = ""
    if "Traceback (most recent call last)" in done.stderr:
        escaped = done.stderr.strip().splitlines()[-1][:200]
    warned = [m.group(0) + line[m.end():][:120] for line in done.stderr.splitlines()
              if (m := _WARNING_LINE.search(line)) and not line.startswith(ERROR_PREFIX)]
    return Outcome(code=done.returncode, out=done.stdout, err=done.stderr, escaped=escaped, warned=warned)


def judge(case: Case, call: Call, outcome: Outcome) -> str | None:
    """The class of failure of ``case`` given ``outcome`` (None: as it should be). Classes: ``timeout``,
    ``traceback``, ``warning``, ``silent pass``, ``not refused (exit N)``, ``refused a valid input``,
    ``refusal not one line``, ``refusal names nothing`` and ``results not kept``."""
    if outcome.timed_out:
        return "timeout: no answer within the per-input timeout"
    if outcome.escaped:
        return f"traceback: {outcome.escaped.splitlines()[0] if outcome.escaped else ''}"
    if outcome.warned:
        return f"warning: {outcome.warned[0]}"
    code = outcome.code
    if code not in case.accept:
        if code == 0:
            return "silent pass: exit 0 on an input that is not valid"
        if code == 2:
            return f"refused a valid input: {outcome.err.strip()[:300]}"
        return f"not refused (exit {code}): {_last_line(outcome)[:200]}"
    if code == 2:
        lines = outcome.err.splitlines()
        if len(lines) != 1 or not lines[0].startswith(ERROR_PREFIX):
            return f"refusal not one line: {len(lines)} lines on stderr: {outcome.err[:200]!r}"
        if call.names and not any(name in lines[0] for name in call.names):
            return f"refusal names nothing: none of {list(call.names)} in {lines[0][:300]}"
    missing = [str(path) for path in call.keeps if path.parent.is_dir() and not path.exists()]
    if missing:
        return f"results not kept: {missing[0]}"
    return None


def _last_line(outcome: Outcome) -> str:
    lines = (outcome.out + outcome.err).strip().splitlines()
    return lines[-1] if lines else ""


def failure_class(verdict: str) -> str:
    """The class of a verdict of :func:`judge`, without the input's own text (to group failures): what escaped or
    warned is named by its type."""
    parts = verdict.split(":")
    return ":".join(parts[:2]) if parts[0] in ("traceback", "warning") else parts[0]
