"""Worker processes that run case groups with a time and a memory limit per case.

Each worker is a Python process of its own (:mod:`comparisons.execute.case_worker`), forked from this process's
zygote (:mod:`comparisons.common.zygote`: its imports done once, not once per worker), speaking over two pipes. The
pool hands a worker one group at a time and watches it: a worker that dies (a segfault in an engine,
``os._exit``), goes past the per-case time limit or past the per-case memory limit (resident memory,
read from /proc) is killed and replaced; the case it was running becomes ``failed`` rows naming the
cause, and the rest of its group goes on in the new worker. A group's shared part (its reference)
that takes a worker down is not tried again: its cases run without it.
"""

from __future__ import annotations

import collections
import os
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from typing import Iterator, cast

from simparity.comparisons.common import zygote
from simparity.comparisons.common.processes import death_cause, status_bytes
from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome
from simparity.comparisons.execute.runner import failed_outcome
from simparity.core.runtime.processes import kill_group

GIB = 1024 ** 3

CASE_WORKER = "simparity.comparisons.execute.case_worker"

DEFAULT_CASE_SECONDS = 900.0
"""Per-case time limit [s] by default: 15 minutes, ~5x the longest case of the built-in suites (the
bench suite's 10,000 IK targets on PyBullet, ~3 min); a case that needs more is given --case-timeout."""

MIN_CASE_SECONDS = 1.0
"""The shortest per-case time limit --case-timeout takes [s]: a case's fixed cost alone (a child forked, the engine's
model built, its rows sent back) is modelled at 0.5 s (``execute/estimate.py`` CASE_OVERHEAD_SECONDS); below a second
cases are killed before they measure anything."""

MAX_CASE_SECONDS = 1e7
"""The longest per-case time limit [s]: four months, the longest scene duration a scene file may give."""

MEMORY_SHARE = 0.8
"""Share of the machine's memory the workers may use together by default; the rest is the system's
and the parent's."""

MIN_CASE_MEMORY_BYTES = 160 * 1024 ** 2
"""The smallest per-case memory limit ``--case-memory`` takes: an idle worker with every built-in engine imported
holds ~150 MiB resident (measured: 150 MiB with core, MuJoCo, PyBullet and Pinocchio built; 79 MiB with core
only), and the case's process forked from it starts there: below it every case would be killed before it
computed anything. The smallest built-in scene runs within it (lecture-projectile, quick, on core, MuJoCo and
Pinocchio at 0.16 GiB: no case killed)."""

MIN_MEMORY_BYTES = 1 * GIB
"""The smallest per-case memory limit by default, on small machines: every built-in scene fits in 1 GiB."""

POLL_SECONDS = 0.05
"""How often a worker's time and memory are looked at: an allocation of ~1 GB/s overshoots the limit
by ~50 MB before it is caught."""


EXIT_GRACE_SECONDS = 1.0
"""How long a worker whose pipe closed is given to exit by itself before it is killed (a Python exception or
``sys.exit`` takes milliseconds; killing it at once would report signal 9 instead of its exit code)."""

WORKER_START_SECONDS = 60.0
"""How long a new worker may take to say it is ready (forked from the zygote: milliseconds; a fresh interpreter, when no
zygote answers, importing simparity, NumPy and SciPy: ~1.2 s of CPU, ~10 s by the clock on a machine loaded ten times
over), on top of the per-case limit of the job handed to it
meanwhile: its start does not count against that case, whose clock starts again when it is ready."""

STDERR_TAIL_BYTES = 64 * 1024
"""How much of a dead worker's standard error is read for the cause of its death."""


def physical_memory_bytes() -> int:
    """The machine's memory [bytes]."""
    return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")


@dataclass(frozen=True)
class CaseLimits:
    """What one case may take: wall time [s] and resident memory of its worker [bytes]; None: the default of the
    machine that runs it, resolved there (a Dask node's, :func:`comparisons.execute.dask_executor.node_memory_bytes`)."""

    seconds: float
    memory_bytes: int | None

    @classmethod
    def default(cls, workers: int) -> "CaseLimits":
        """:data:`DEFAULT_CASE_SECONDS`, and :data:`MEMORY_SHARE` of the machine split between ``workers``."""
        share = int(MEMORY_SHARE * physical_memory_bytes() / max(1, workers))
        return cls(DEFAULT_CASE_SECONDS, max(MIN_MEMORY_BYTES, share))


@dataclass
class Job:
    """A group to run: ``key`` names it to the caller; ``skip`` are its cases already done."""

    key: object
    group: CaseGroup
    skip: set[int] = field(default_factory=set)
    reference_failure: str = ""


class _Worker:
    """One worker process, the job it runs and what it is doing."""

    def __init__(self) -> None:
        child_reads, parent_writes = os.pipe()
        parent_reads, child_writes = os.pipe()
        self.stderr = tempfile.TemporaryFile(mode="a+b")  # append mode: the parent may truncate it
        try:
            self.process = zygote.start(CASE_WORKER, None, self.stderr, (child_reads, child_writes))
        finally:
            os.close(child_reads)
            os.close(child_writes)
        self.outbox = Connection(parent_writes, readable=False)
        self.inbox = Connection(parent_reads, writable=False)
        self.job: Job | None = None
        self.phase: int | None = None
        self.phase_pid = self.process.pid
        self.since = time.monotonic()
        self.ready = False  # its imports done (its first message)

    def start(self, job: Job) -> None:
        self.stderr.truncate(0)
        self.job, self.phase, self.phase_pid, self.since = job, None, self.process.pid, time.monotonic()
        self.outbox.send((job.group, frozenset(job.skip), job.reference_failure))

    def kill(self, grace_seconds: float = 0.0) -> int:
        """Kill the process (if still alive after ``grace_seconds`` to exit by itself) and return its exit code."""
        try:
            self.process.wait(timeout=grace_seconds)
        except subprocess.TimeoutExpired:
            pass
        kill_group(self.process.pid)  # the worker and what it forked, but the child running a case ...
        if self.phase_pid != self.process.pid:
            kill_group(self.phase_pid)  # ... which leads a group of its own (case_worker), with what it started
        code = self.process.wait()
        for end in (self.inbox, self.outbox):
            end.close()
        return code

    def stderr_tail(self) -> str:
        self.stderr.seek(0, os.SEEK_END)
        size = self.stderr.tell()
        self.stderr.seek(max(0, size - STDERR_TAIL_BYTES))
        return self.stderr.read().decode("utf-8", "replace")

    def close(self) -> None:
        self.kill()
        self.stderr.close()


class IsolatedPool:
    """Up to ``workers`` worker processes running jobs under ``limits``; replaced when one is killed. A process is
    started when a job needs it and none is free: a run of one group starts one, not one per CPU (the zygote's imports,
    ~1.2 CPU-s, are paid once per process), and a killed one is replaced only if a job is waiting."""

    def __init__(self, workers: int, limits: CaseLimits) -> None:
        if workers < 1:
            raise ValueError(f"workers {workers}: at least 1")
        self.limits = limits
        self._size = workers
        self._workers: list[_Worker] = []

    def run(self, jobs: list[Job]) -> Iterator[tuple[object, int, CaseOutcome]]:
        """(job key, case index, outcome) of every case of ``jobs`` not skipped, as each finishes; jobs start
        in the given order."""
        pending = collections.deque(jobs)
        while True:
            for k in range(len(self._workers)):
                if self._workers[k].job is None and pending:
                    self._start(k, pending.popleft())
            while pending and len(self._workers) < self._size:  # a job waits and no worker is free: one more
                self._workers.append(_Worker())
                self._start(len(self._workers) - 1, pending.popleft())
            busy = [w for w in self._workers if w.job is not None]
            if not busy:
                return
            ready = wait([w.inbox for w in busy], timeout=POLL_SECONDS)
            for worker in busy:
                if worker.inbox in ready:
                    yield from self._receive(worker, pending)
                elif worker.job is not None:
                    yield from self._enforce_limits(worker, pending)

    def _start(self, k: int, job: Job) -> None:
        """Hand ``job`` to worker ``k``, replacing the worker first if it died while idle."""
        try:
            self._workers[k].start(job)
        except OSError:
            self._workers[k].close()
            self._workers[k] = _Worker()
            self._workers[k].start(job)

    def _receive(self, worker: _Worker, pending: collections.deque) -> Iterator[tuple[object, int, CaseOutcome]]:
        try:
            message = worker.inbox.recv()
        except (EOFError, OSError):  # the worker is exiting: its own exit code says more than a kill's
            code = worker.kill(EXIT_GRACE_SECONDS)
            yield from self._replace(worker, death_cause(code, worker.stderr_tail()), pending)
            return
        except Exception as err:  # noqa: BLE001 - bytes that are no message: something else wrote to the pipe
            worker.kill()
            yield from self._replace(worker, f"crashed: the case's process wrote what is not a message to its pipe "
                                     f"({type(err).__name__}); the worker was killed", pending)
            return
        job = cast(Job, worker.job)  # a worker's messages are read only while it runs a job
        if message[0] == "ready":  # a new worker's imports are done: its first case's time starts now, not before them
            worker.ready, worker.since = True, time.monotonic()
        elif message[0] == "start":
            worker.phase, worker.phase_pid, worker.since = message[1], message[2], time.monotonic()
        elif message[0] == "crashed":  # the child running the cases of one engine died; the worker lives on
            cause = death_cause(message[1], worker.stderr_tail(), "the case's process")
            worker.phase = message[2] if worker.phase is None else worker.phase
            yield from self._fail_phase(worker, cause, pending)
            worker.job = None
        elif message[0] == "done":
            job.skip.add(message[1])
            yield job.key, message[1], message[2]
        else:  # the group is done
            worker.job = None

    def _enforce_limits(self, worker: _Worker, pending) -> Iterator[tuple[object, int, CaseOutcome]]:
        if worker.process.poll() is not None:  # died, its pipe held open by a child it forked
            code = worker.kill()
            yield from self._replace(worker, death_cause(code, worker.stderr_tail()), pending)
            return
        start = 0.0 if worker.ready else WORKER_START_SECONDS
        if time.monotonic() - worker.since > self.limits.seconds + start:
            worker.kill()
            late = (f"no result within the per-case time limit of {self.limits.seconds:g} s" if worker.ready else
                    f"the worker process did not start (its imports) within {start:g} s and the per-case time limit "
                    f"of {self.limits.seconds:g} s")
            yield from self._replace(worker, f"hung: {late}; the worker was killed", pending)
            return
        limit = self.limits.memory_bytes
        if limit is not None and (status_bytes("VmRSS", worker.phase_pid) or 0) > limit:
            worker.kill()
            # not how far past: the memory at the instant it was looked at differs from run to run, the rows must not
            cause = (f"out of memory: the worker's resident memory went past the per-case limit of "
                     f"{limit / GIB:.3g} GiB; the worker was killed")
            yield from self._replace(worker, cause, pending)

    def _replace(self, worker: _Worker, cause: str, pending: collections.deque) -> Iterator[tuple[object, int, CaseOutcome]]:
        """``worker`` (killed) let go; the case it ran fails with ``cause``, the rest of its job goes first in the
        queue. A new process takes its place when a job waits for one (:meth:`run`), not before: the last case of a
        run that hangs leaves no worker started for nothing."""
        worker.stderr.close()
        self._workers.remove(worker)
        yield from self._fail_phase(worker, cause, pending)

    def _fail_phase(self, worker: _Worker, cause: str, pending: collections.deque) -> Iterator[tuple[object, int, CaseOutcome]]:
        """The case ``worker`` was running fails with ``cause`` (its shared part: the group's cases run again
        without it); the rest of its job goes first in the queue."""
        job, phase = cast(Job, worker.job), worker.phase  # a worker fails a phase only while it runs a job
        if phase is None and not job.reference_failure:
            job.reference_failure = cause  # its cases run again, without it
        else:
            failing = [phase] if phase is not None else [i for i in range(len(job.group.cases)) if i not in job.skip]
            for index in failing:
                job.skip.add(index)
                yield job.key, index, failed_outcome(job.group, job.group.cases[index], cause)
        if len(job.skip) < len(job.group.cases):
            pending.appendleft(job)

    def close(self) -> None:
        """Stop every worker (again: nothing)."""
        for worker in self._workers:
            worker.close()
        self._workers = []

    def __enter__(self) -> "IsolatedPool":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
