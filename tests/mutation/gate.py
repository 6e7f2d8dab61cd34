"""The CI gate on copies of core: ``simparity run --quick --check`` with them beside core, and its verdicts.

One process per run, the copies' folder on its import path. Violation lines (``--verbose``: one per metric, not
one per case and reason) name their engine (``violation: <scene> <engine> <integrator> [dt=...] <metric>: ...``),
so several copies can share a run.

A copy is *caught* when the run exits 1 and a violation names it on a row (scene, integrator, dt, metric) on
which the faithful copy broke no bound in the baseline run of the suite (core beside the faithful copy): a row
that fails for the unmutated code too (a bound written for engine "core" only, say) is the gate's false alarm,
not a catch. A violation naming an engine that is not a copy under test (core) on a row core did not break in
the baseline is *wrong blame*: the gate blames core for the copy's bug.

A kept run can be judged again by ``simparity check`` (:func:`check_run`): against changed bounds in seconds,
where running it again takes minutes (new metrics need a new run).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from tests.mutation.copy_of_core import CoreCopy

SIMPARITY = Path(sys.executable).with_name("simparity")
"""The console script of this environment (beside its python)."""

JOBS = 2
"""Worker processes per run: the machine's 2 cores."""

CASE_TIMEOUT = 600
"""[s] A case running longer is failed (a mutant that loops must not hold a worker for the default 900 s); the
slowest case of a quick suite takes well under a minute."""

RUN_TIMEOUT = 3 * 3600
"""[s] One run at most: a quick suite with a batch of copies beside core takes ~10-40 minutes on 2 shared cores."""

EXIT_OK, EXIT_VIOLATION = 0, 1
"""``simparity run``'s exit codes for a passed and a failed check (2: bad input, a bug of this suite)."""

VIOLATION_PREFIX = "violation: "

TIMING_SUFFIX = ".gate.json"
"""Beside a run's folder: the run's wall time and suite, for judging it again later."""


class GateError(RuntimeError):
    """A run that did not give a verdict (bad input, timeout): a bug of this suite, never a pass."""


@dataclass(frozen=True)
class Violation:
    """One printed violation line (without its ``violation: `` prefix)."""

    line: str

    @property
    def engine(self) -> str:
        return self.line.split()[1]

    @property
    def row(self) -> str:
        """``scene engine integrator [dt=...] metric``: what the line is about, without the values."""
        return self.line.split(": ", 1)[0]

    @property
    def where(self) -> str:
        """:attr:`row` without the engine: the same row of another engine has the same ``where``."""
        scene, _, rest = self.row.split(" ", 2)
        return f"{scene} {rest}"


@dataclass(frozen=True)
class GateRun:
    """One ``simparity run --quick --check`` of a suite with copies beside core."""

    suite: str
    engines: tuple[str, ...]
    exit_code: int
    violations: tuple[Violation, ...]
    seconds: float
    summary: str

    def naming(self, engine: str) -> tuple[Violation, ...]:
        return tuple(v for v in self.violations if v.engine == engine)


@dataclass(frozen=True)
class Verdict:
    """The gate's verdict on one copy in one run: ``violations`` are those naming it beyond the faithful copy's."""

    engine: str
    suite: str
    caught: bool
    violations: tuple[Violation, ...]
    wrong_blame: tuple[Violation, ...]
    seconds: float

    @property
    def first(self) -> str:
        return self.violations[0].line if self.violations else ""


def _parse(done: subprocess.CompletedProcess, command: list[str]) -> tuple[int, tuple[Violation, ...], str]:
    """(exit code, violations, the "check ..." line) of a finished ``simparity run --check`` or ``check``."""
    lines = done.stdout.splitlines()
    summary = next((line for line in reversed(lines) if line.startswith("check ")), "")
    if done.returncode not in (EXIT_OK, EXIT_VIOLATION) or not summary:
        raise GateError(f"{' '.join(command)} exited {done.returncode} without a verdict:\n"
                        f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    return done.returncode, tuple(Violation(line[len(VIOLATION_PREFIX):]) for line in lines
                                  if line.startswith(VIOLATION_PREFIX)), summary


def _history(out: Path) -> str:
    """A history database beside the run (never the checkout's)."""
    return str(out.with_name(out.name + ".sqlite"))


def run_gate(copies: list[CoreCopy], suite: str, out: Path, scenes: tuple[str, ...] = ()) -> GateRun:
    """Run the quick profile of ``suite`` (or of its built-in ``scenes`` alone, when given) with core and ``copies``
    (all materialised under one root) into ``out`` (a folder that does not exist yet), and read its verdict."""
    roots = {c.root for c in copies}
    if len(roots) != 1:
        raise GateError(f"the copies of one run must share a root folder, got {sorted(map(str, roots))}")
    out = Path(out)
    path = [str(roots.pop())] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    which = list(scenes) if scenes else ["--suite", suite]
    command = [str(SIMPARITY), "run", "--quick", "--check", "--verbose", *which, "--engines",
               ",".join(["core"] + [c.spec for c in copies]), "--out", str(out), "--jobs", str(JOBS),
               "--case-timeout", str(CASE_TIMEOUT), "--history", _history(out)]
    start = time.monotonic()
    try:
        done = subprocess.run(command, env=dict(os.environ, PYTHONPATH=os.pathsep.join(path)), cwd=out.parent,
                              capture_output=True, text=True, timeout=RUN_TIMEOUT)
    except subprocess.TimeoutExpired as err:
        raise GateError(f"{' '.join(command)}: no verdict within {RUN_TIMEOUT} s") from err
    seconds = time.monotonic() - start
    exit_code, violations, summary = _parse(done, command)
    out.with_name(out.name + TIMING_SUFFIX).write_text(json.dumps({"suite": suite, "seconds": seconds}),
                                                       encoding="utf-8")
    return GateRun(suite, ("core",) + tuple(c.engine_name for c in copies), exit_code, violations, seconds, summary)


def check_run(out: Path) -> GateRun:
    """The verdict of the shipped tolerances, as they are now, on a run :func:`run_gate` kept in ``out``."""
    out = Path(out)
    timing = json.loads(out.with_name(out.name + TIMING_SUFFIX).read_text(encoding="utf-8"))
    engines = tuple(json.loads((out / "run.json").read_text(encoding="utf-8"))["engine_versions"])
    command = [str(SIMPARITY), "check", str(out), "--verbose", "--history", _history(out)]
    exit_code, violations, summary = _parse(subprocess.run(command, capture_output=True, text=True), command)
    return GateRun(timing["suite"], engines, exit_code, violations, timing["seconds"], summary)


def verdicts(run: GateRun, names: list[str], baseline: GateRun, faithful: str) -> list[Verdict]:
    """The verdict on each copy ``names`` in ``run``, against ``baseline`` (the run of the faithful copy, engine
    ``faithful``, beside core). With several copies in one run, wrong blame is the run's, shared by all of them."""
    false_alarms = {v.where for v in baseline.naming(faithful)}
    known = {v.row for v in baseline.violations}
    blamed = tuple(v for v in run.violations if v.engine not in names and v.row not in known)
    result = []
    for name in names:
        found = tuple(v for v in run.naming(name) if v.where not in false_alarms)
        result.append(Verdict(name, run.suite, run.exit_code == EXIT_VIOLATION and bool(found), found, blamed,
                              run.seconds))
    return result
