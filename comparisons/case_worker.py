"""A worker process: runs the case groups it is sent, one case at a time, and reports each as it goes.

Started by :mod:`comparisons.isolation` as ``python -m simparity.comparisons.case_worker IN_FD OUT_FD``:
it reads ``(group, skip, reference_failure)`` messages from IN_FD and writes ``("start", index)``
(None: the group's shared part), ``("done", index, outcome)`` and ``("group done",)`` to OUT_FD. Its
parent enforces the limits: a worker that crashes, hangs or grows past its memory limit is killed
and replaced, and only the case it was running fails. The worker dies with its parent.
"""

from __future__ import annotations

import ctypes
import faulthandler
import os
import signal
import sys
import traceback
from multiprocessing.connection import Connection

from simparity.comparisons.engines import make_engine
from simparity.comparisons.runner import run_group

_PR_SET_PDEATHSIG = 1
"""Linux prctl option: the signal this process gets when its parent dies."""


def _die_with_parent(parent: int) -> None:
    """Ask Linux to kill this process when its parent dies (a hung case must not outlive a killed run)."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):  # not Linux: the worker ends at its next message instead
        return
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)


def serve(inbox: Connection, outbox: Connection) -> None:
    """Run every group sent on ``inbox`` until it closes, reporting on ``outbox``."""
    engines: dict = {}
    while True:
        try:
            group, skip, reference_failure = inbox.recv()
        except EOFError:
            return

        def engine_for(name: str, group=group):
            spec = group.spec_of(name)
            if spec not in engines:
                engines[spec] = make_engine(spec)
            return engines[spec]

        for index, outcome in run_group(group, engine_for, lambda index: outbox.send(("start", index)), skip,
                                        reference_failure):
            outbox.send(("done", index, outcome))
        outbox.send(("group done",))


def main(argv: list[str]) -> int:
    in_fd, out_fd, parent = int(argv[1]), int(argv[2]), int(argv[3])
    _die_with_parent(parent)
    faulthandler.enable()  # a crash leaves the Python stack on stderr, for the failed row's cause
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    inbox, outbox = Connection(in_fd, writable=False), Connection(out_fd, readable=False)
    try:
        serve(inbox, outbox)
    except BrokenPipeError:  # the parent went away
        return 0
    except Exception:  # a harness bug: the parent fails the case it was on, with this text
        traceback.print_exc(file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
