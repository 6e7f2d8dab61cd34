"""A worker process: runs the case groups it is sent, one case at a time, and reports each as it goes.

Started by :mod:`comparisons.execute.isolation` as ``python -m simparity.comparisons.execute.case_worker IN_FD OUT_FD``:
it writes ``("ready",)`` once its imports are done, reads ``(group, skip, reference_failure)`` messages from IN_FD
and writes ``("start", index, pid)``
(index None: the group's shared part; pid: the process running it), ``("done", index, outcome)``,
``("crashed", code, first index)`` (the child running an engine's cases died: its exit code, negative
for a signal) and ``("group done",)`` to OUT_FD. Its parent enforces the limits: a process that crashes,
hangs or grows past its memory limit is killed, and only the case it was running fails. The worker and
its children die with its parent.
"""

from __future__ import annotations

import faulthandler
import os
import signal
import sys
import traceback
from multiprocessing.connection import Connection

from simparity.comparisons.execute.cases import CaseGroup
from simparity.comparisons.engines.registry import ENGINE_NAMES, make_engine
from simparity.comparisons.execute.runner import prepare_group, run_case
from simparity.core.model.engine import Engine
from simparity.core.runtime.processes import die_with_parent, kill_group

def serve(inbox: Connection, outbox: Connection) -> None:
    """Run every group sent on ``inbox`` until it closes, reporting on ``outbox``.

    The group's shared part (its reference) is computed here, by built-in engines only; then each engine's
    cases run in a child forked from this process (:func:`_run_in_child`), so no engine's code ever runs
    here: whatever one changes in its process (the FPU's rounding mode, a closed stream, a patched
    module) cannot reach the reference or another engine's cases. The last shared part is kept: a group
    sent again after a crash does not compute it again.
    """
    trusted: dict[str, Engine] = {}
    kept: tuple = (None, None)
    while True:
        try:
            group, skip, reference_failure = inbox.recv()
        except EOFError:
            return

        def trusted_engine(name: str) -> Engine:
            if name not in trusted:
                trusted[name] = make_engine(name)
            return trusted[name]

        key = (group.scene_hash, group.kind, float(group.dt).hex(), reference_failure)
        if kept[0] != key:
            outbox.send(("start", None, os.getpid()))
            kept = (key, prepare_group(group, trusted_engine, reference_failure))
        for spec, indices in _by_engine(group, skip):
            if spec in ENGINE_NAMES:
                trusted_engine(spec)  # built here, before the fork: its children share it
            failure = _run_in_child(group, kept[1], indices, trusted, outbox)
            if failure is not None:
                outbox.send(("crashed", failure, indices[0]))
                break
        else:
            outbox.send(("group done",))


def _by_engine(group: CaseGroup, skip: frozenset[int]) -> list[tuple[str, list[int]]]:
    """The cases not in ``skip``, by the spec of their engine, in the group's order of engines."""
    out: dict[str, list[int]] = {}
    for index, case in enumerate(group.cases):
        if index not in skip:
            out.setdefault(group.spec_of(case.engine), []).append(index)
    return list(out.items())


def _run_in_child(group: CaseGroup, shared: object, indices: list[int], trusted: dict[str, Engine],
                  outbox: Connection) -> int | None:
    """Run cases ``indices`` of one engine in a child process forked from this one; None when it finished
    them all, else its exit status as a code (negative: the signal that killed it). The child leads a process
    group of its own, killed when it ends: nothing the engine started outlives its cases (short of a process
    that leaves the group, ``setsid``)."""
    finished_read, finished_write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: report straight to the parent, never return into the loop above
        code = 1
        try:
            os.close(finished_read)
            os.setpgid(0, 0)
            die_with_parent(os.getppid())
            engines = dict(trusted) | {group.spec_of(e.name): e for e in group.stand_ins}

            def engine_for(name: str) -> Engine:
                spec = group.spec_of(name)
                if spec not in engines:
                    engines[spec] = make_engine(spec)
                return engines[spec]

            for index in indices:
                outbox.send(("start", index, os.getpid()))
                outbox.send(("done", index, run_case(group, shared, index, engine_for)))
            os.write(finished_write, b"1")
            code = 0
        except BaseException:  # noqa: BLE001 - a harness bug: the parent fails the case, with this text
            traceback.print_exc(file=sys.stderr)
        finally:
            sys.stderr.flush()
            os._exit(code)
    os.close(finished_write)
    _, status = os.waitpid(pid, 0)
    kill_group(pid)  # what the engine started and left running
    os.set_blocking(finished_read, False)  # a grandchild may hold the write end open
    try:
        finished = os.read(finished_read, 1) == b"1"
    except BlockingIOError:
        finished = False
    os.close(finished_read)
    if finished:
        return None
    return -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)


def main(argv: list[str]) -> int:
    in_fd, out_fd, parent = int(argv[1]), int(argv[2]), int(argv[3])
    die_with_parent(parent)
    faulthandler.enable()  # a crash leaves the Python stack on stderr, for the failed row's cause
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    inbox, outbox = Connection(in_fd, writable=False), Connection(out_fd, readable=False)
    try:
        outbox.send(("ready",))  # imported: the case clock of a job handed over meanwhile starts again here
        serve(inbox, outbox)
    except BrokenPipeError:  # the parent went away
        return 0
    except Exception:  # a harness bug: the parent fails the case it was on, with this text
        traceback.print_exc(file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
