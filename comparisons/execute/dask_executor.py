"""Running case groups on a Dask distributed cluster (``simparity run --executor dask``).

Each group is one Dask task. On the Dask worker the task runs its group in an
:class:`~comparisons.execute.isolation.IsolatedPool` of one worker process, kept for the worker's next
tasks, so a case that crashes, hangs or exhausts memory fails alone there exactly as it does
locally, and the Dask worker lives on. Without a scheduler address a ``LocalCluster`` is started on
the loopback interface with one single-threaded worker process per job. Without --case-memory, each case's
memory limit is the default of the machine it runs on (:func:`node_memory_bytes`), not of this one.

Outcomes stream back case by case, as on the local executor: the task puts each finished case on a Dask
``Queue`` of the run, so the progress bar moves and the journal keeps every finished case while its group is
still running (an interrupted run resumes without computing it again). A group whose Dask worker is lost
is retried elsewhere by Dask; a case it sends twice is taken once, and the cases of a group lost for good
that never came back fail with that cause. A finished task's future is let go at once, so neither the client nor the
scheduler keeps one per group of a run of thousands.
"""

from __future__ import annotations

import asyncio
import os
import pickle
import socket
import tempfile
import threading
import time
import uuid
from typing import Any, Iterator, cast

from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome
from simparity.comparisons.execute.isolation import MIN_MEMORY_BYTES, CaseLimits, IsolatedPool, Job
from simparity.comparisons.execute.runner import failed_outcome
from simparity.core.model.errors import SimparityError, one_line

CONNECT_SECONDS = 30
"""How long to wait for the scheduler at --scheduler to answer, once its port accepts connections."""

POLL_SECONDS = 0.05
"""How often the run's queue and tasks are looked at when nothing arrived: a finished case waits at most this long."""

REACH_SECONDS = 5
"""How long to wait for the scheduler's port to accept a connection: a refused or unresolvable address fails at
once, an unanswered one (a firewall dropping packets) after this."""

IDENTIFY_SECONDS = 10
"""How long a server at --scheduler has to say that it is a Dask scheduler (a scheduler answers in milliseconds;
a web server, the dashboard's port given by mistake, never does)."""

_pools = threading.local()
"""Each Dask worker thread's pool of one worker process, kept between tasks."""


def run_group_task(group: CaseGroup, skip: frozenset[int], limits: CaseLimits, queue: str, rank: int) -> None:
    """The Dask task: every case of ``group`` but ``skip``, run in this Dask worker's isolated process, under
    ``limits`` (a memory limit of None: :func:`node_memory_bytes`); each outcome is put on the Dask queue named
    ``queue`` as it finishes, pickled with the job's ``rank``: ``(rank, case index, outcome)``."""
    import distributed

    if limits.memory_bytes is None:
        limits = CaseLimits(limits.seconds, node_memory_bytes())
    pool = getattr(_pools, "pool", None)
    if pool is None or pool.limits != limits:
        if pool is not None:
            pool.close()
        pool = _pools.pool = IsolatedPool(1, limits)
    outbox = distributed.Queue(queue)
    for _, index, outcome in pool.run([Job(0, group, set(skip))]):
        outbox.put(pickle.dumps((rank, index, outcome), protocol=pickle.HIGHEST_PROTOCOL))


def _reach(address: str) -> None:
    """Raise OSError or ValueError unless a Dask scheduler answers at ``address`` (before Dask's client, which
    retries a refused connection for its whole timeout and waits on a service that is not Dask for ever): its
    port accepts connections within :data:`REACH_SECONDS`, and it says it is a scheduler within
    :data:`IDENTIFY_SECONDS`."""
    from distributed.comm.addressing import get_address_host_port, normalize_address

    host, port = get_address_host_port(normalize_address(address))
    socket.create_connection((host, port), timeout=REACH_SECONDS).close()
    try:
        identity = asyncio.run(asyncio.wait_for(_identity(address), IDENTIFY_SECONDS))
    except (asyncio.TimeoutError, TimeoutError):
        raise OSError(f"something listens there but gave no Dask answer within {IDENTIFY_SECONDS:g} s") from None
    except Exception as err:  # noqa: BLE001 - whatever a service that is not Dask makes Dask's protocol raise
        raise OSError(f"something listens there but does not speak Dask's protocol ({type(err).__name__})") from None
    kind = identity.get("type") if isinstance(identity, dict) else None
    if kind != "Scheduler":
        raise OSError(f"a Dask {kind or 'process'} answers there, not a scheduler")


async def _identity(address: str) -> object:
    """What the Dask server at ``address`` says it is (its ``identity``)."""
    from distributed.core import rpc
    from distributed.security import Security

    server = rpc(address, timeout=REACH_SECONDS, connection_args=Security().get_connection_args("client"))
    try:
        return await server.identity()
    finally:
        await server.close_rpc()


def node_memory_bytes() -> int:
    """The per-case memory limit by default on the machine a Dask worker runs on: the worker's own memory limit
    shared between its threads (each runs one case at a time), or, when it has none, the local default for one
    case per CPU of that machine."""
    import distributed

    try:
        worker = distributed.get_worker()
        limit, threads = worker.memory_manager.memory_limit, worker.state.nthreads
    except (ValueError, AttributeError):  # not on a worker, or a Dask without these: the machine's share
        limit, threads = None, 1
    if limit:
        return max(MIN_MEMORY_BYTES, int(limit) // max(1, threads))
    return cast(int, CaseLimits.default(os.cpu_count() or 1).memory_bytes)  # the default always sets one


class DaskExecutor:
    """Case groups as tasks on the cluster at ``scheduler`` (address), or on a new ``LocalCluster`` of
    ``workers`` processes when it is None."""

    def __init__(self, scheduler: str | None, workers: int, limits: CaseLimits) -> None:
        try:
            import distributed
        except ImportError as err:
            raise SimparityError(f"--executor dask: Dask is not installed here ({one_line(err)}) (allowed: pip install "
                                 "'simparity[dask]', or --executor local)") from None
        self.limits = limits
        self._cluster = None
        self._scratch: tempfile.TemporaryDirectory | None = None
        self.client: Any = None  # a distributed.Client once connected (Dask is imported only here)
        try:
            if scheduler is None:
                import dask.config

                # Dask's shared scratch folder (/tmp/dask-scratch-space) is purged of any other cluster's "stale"
                # lock files when a cluster starts: a second run on the machine killed the first one's workers
                # (measured: two test runs at once, 0 workers left). Each LocalCluster here has its own.
                self._scratch = tempfile.TemporaryDirectory(prefix="simparity-dask-")
                with dask.config.set({"temporary-directory": self._scratch.name}):
                    self._cluster = distributed.LocalCluster(
                        n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                        dashboard_address=":0", memory_limit=0, silence_logs=50)
                self.client = distributed.Client(self._cluster)
            else:
                _reach(scheduler)
                self.client = distributed.Client(scheduler, timeout=CONNECT_SECONDS)
        except (OSError, TimeoutError, ValueError) as err:
            self.close()
            raise SimparityError(f"--scheduler {one_line(scheduler)}: cannot reach a Dask scheduler: {one_line(err)} "
                                 "(allowed: the address a running 'dask scheduler' prints, e.g. "
                                 "tcp://10.0.0.5:8786)") from None

    def run(self, jobs: list[Job]) -> Iterator[tuple[object, int, CaseOutcome]]:
        import distributed

        queue = distributed.Queue(f"simparity-{uuid.uuid4().hex}", client=self.client)
        futures = {}
        for rank, job in enumerate(jobs):  # the costliest first: Dask runs higher priorities first
            future = self.client.submit(run_group_task, job.group, frozenset(job.skip), self.limits, queue.name,
                                        rank, pure=False, priority=len(jobs) - rank)
            futures[future] = rank
        received: list[set[int]] = [set(job.skip) for job in jobs]
        pending = set(futures)
        try:
            while pending:
                finished = {future for future in pending if future.done()}  # before the queue: their cases are on it
                messages = queue.get(batch=True)
                for rank, index, outcome in map(pickle.loads, messages):
                    if index not in received[rank]:  # a retried group sends its cases again
                        received[rank].add(index)
                        yield jobs[rank].key, index, outcome
                for future in finished:
                    rank = futures.pop(future)  # released: the cluster forgets the finished task
                    yield from self._lost(jobs[rank], received[rank], future)
                pending -= finished
                if not messages and not finished:
                    time.sleep(POLL_SECONDS)
        finally:
            queue.close()

    @staticmethod
    def _lost(job: Job, received: set[int], future) -> Iterator[tuple[object, int, CaseOutcome]]:
        """Failed outcomes of the cases of ``job`` that never came back from its finished ``future``."""
        missing = [i for i in range(len(job.group.cases)) if i not in received]
        if not missing:
            return
        error = future.exception() if future.status == "error" else None
        cause = ("crashed: the Dask task was lost: " + (f"{type(error).__name__}: {one_line(error)}" if error is not None
                                                        else f"it ended ({future.status}) before its cases came back"))
        for index in missing:
            received.add(index)
            yield job.key, index, failed_outcome(job.group, job.group.cases[index], cause)

    def close(self) -> None:
        """Disconnect, and stop the LocalCluster if this started one (again: nothing)."""
        client, self.client = self.client, None
        if client is not None:
            client.close()
        cluster, self._cluster = self._cluster, None
        if cluster is not None:
            cluster.close()
        scratch, self._scratch = self._scratch, None
        if scratch is not None:
            scratch.cleanup()
