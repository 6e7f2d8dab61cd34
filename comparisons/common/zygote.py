"""Processes forked from one that has already imported what they need, instead of fresh interpreters.

A case worker (:mod:`comparisons.execute.case_worker`) or an engine probe (:mod:`comparisons.engines.probe`)
started as a fresh interpreter spends ~1 CPU-s importing NumPy, SciPy and simparity before its first message: a
run pays it once per worker, a replaced worker again, a test session ~190 times (110 workers and 79 probes counted
in one). A *zygote* pays it once per
process: ``python -m simparity.comparisons.common.zygote SOCKET_FD PARENT_PID`` imports :data:`PRELOADED` and
forks a child per request that then runs ``main(argv)`` of one of them, as its ``python -m`` would.

What a child is given, it is given as a fresh interpreter would be: the requester's environment, working folder
and import path at the moment of the request (not the zygote's), its standard input and error, the file
descriptors it names in ``argv`` (handed over the socket), a session of its own, and death with its parent (the
zygote, which dies with the process that started it). It is the zygote's child, not the requester's: the zygote
reaps it and sends its exit status, which :class:`ForkedProcess` gives as ``poll``/``wait`` do for a
``subprocess.Popen`` (a negative code: the signal that killed it).

The zygote is kept for the next request while the import path and the folder stay the same (a new one is started
when they change; the modules it imported are those a fresh interpreter there would import); a process forked from
its starter does not use it. A zygote that cannot
answer (it died, or did not start within :data:`ZYGOTE_START_SECONDS`) is replaced once, then the caller starts
a fresh interpreter instead (:func:`start`), whose own failure (an import error) is reported as it always was.
"""

from __future__ import annotations

import atexit
import importlib
import os
import pickle
import resource
import select
import signal
import socket
import subprocess
import sys
import threading
import time
import traceback
from dataclasses import dataclass
from typing import IO, Protocol

from simparity.comparisons.common.processes import worker_environment
from simparity.core.runtime.processes import die_with_parent

PRELOADED = ("simparity.comparisons.execute.case_worker", "simparity.comparisons.engines.probe")
"""The modules a zygote imports before it forks, and the only ones whose ``main`` it runs (named as data: this
module, under every folder of comparisons/, imports none of them)."""

ZYGOTE_START_SECONDS = 60.0
"""How long a request may wait for the zygote's answer [s]: its imports (~1 CPU-s; ~10 s by the clock on a machine
loaded ten times over, as a fresh worker's: ``execute/isolation.py`` WORKER_START_SECONDS), then a fork."""

MESSAGE_BYTES_MAX = 1 << 20
"""The largest request the zygote reads [bytes]: an environment and an import path (a few KiB)."""


@dataclass(frozen=True)
class ChildrenUsage:
    """What finished child processes used: CPU time [s] (user + system) and the largest peak resident memory [bytes]."""

    cpu_seconds: float
    max_resident_bytes: int

    def and_(self, other: "ChildrenUsage") -> "ChildrenUsage":
        return ChildrenUsage(self.cpu_seconds + other.cpu_seconds,
                             max(self.max_resident_bytes, other.max_resident_bytes))


RESIDENT_BYTES_PER_UNIT = 1 if sys.platform == "darwin" else 1024
"""``ru_maxrss``'s unit [bytes]: bytes on macOS, KiB on Linux."""


def children_usage() -> ChildrenUsage:
    """What this process's finished children used (``RUSAGE_CHILDREN``: those waited for, with the descendants they
    waited for), and the children of its live zygotes, which the zygotes waited for and reported: a forked worker
    counts from its exit, not from its zygote's."""
    own = resource.getrusage(resource.RUSAGE_CHILDREN)
    usage = ChildrenUsage(own.ru_utime + own.ru_stime, own.ru_maxrss * RESIDENT_BYTES_PER_UNIT)
    for key, zygote in list(_zygotes.items()):
        if key[0] == os.getpid() and not zygote.dead:  # a reaped zygote's children are in RUSAGE_CHILDREN already
            usage = usage.and_(zygote.usage)
    return usage


class ProcessLike(Protocol):
    """What the pools use of a ``subprocess.Popen``: a pid, and its exit code (None while it runs)."""

    pid: int

    def poll(self) -> int | None: ...

    def wait(self, timeout: float | None = None) -> int: ...


@dataclass
class ForkedProcess:
    """A process the zygote forked: ``poll`` and ``wait`` as ``subprocess.Popen``'s."""

    pid: int
    zygote: "Zygote"
    returncode: int | None = None

    def poll(self) -> int | None:
        try:
            return self.wait(0.0)
        except subprocess.TimeoutExpired:
            return None

    def wait(self, timeout: float | None = None) -> int:
        if self.returncode is None:
            self.returncode = self.zygote.exit_code(self.pid, timeout)
            if self.returncode is None:
                raise subprocess.TimeoutExpired(f"process {self.pid}", timeout or 0.0)
        return self.returncode


class Zygote:
    """The requesting side of one zygote process: its socket, and the children it has forked and not yet reaped."""

    def __init__(self) -> None:
        self.socket, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-m", __name__, str(theirs.fileno()), str(os.getpid())], pass_fds=(theirs.fileno(),),
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                env=worker_environment(), start_new_session=True)
        finally:
            theirs.close()
        self.lock = threading.Lock()
        self.exits: dict[int, int] = {}
        self.running: set[int] = set()
        self.dead = False
        self.usage = ChildrenUsage(0.0, 0)  # of the children it reaped, until it is reaped itself

    def fork(self, module: str, stdin: int, stderr: int, argv_fds: tuple[int, ...]) -> ForkedProcess | None:
        """A child running ``module``'s ``main([module, *argv_fds, zygote pid])``, with ``stdin`` and ``stderr`` as
        its fds 0 and 2 (all handed over, still the caller's to close); None when the zygote does not answer."""
        request = pickle.dumps((module, worker_environment(), os.getcwd(), list(sys.path)))
        with self.lock:
            try:
                if not self.dead:
                    socket.send_fds(self.socket, [request], [stdin, stderr, *argv_fds])
                while (message := self._receive(ZYGOTE_START_SECONDS)) is not None:
                    if message[0] == "started":
                        self.running.add(message[1])
                        return ForkedProcess(message[1], self)
            except OSError:
                pass
            self._die()
            return None

    def exit_code(self, pid: int, timeout: float | None) -> int | None:
        """The exit code of child ``pid`` (let go of), waiting up to ``timeout`` seconds (None: until it exits);
        None if it has not exited by then."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self.lock:
            while pid not in self.exits and not self.dead:
                left = None if deadline is None else max(0.0, deadline - time.monotonic())
                if self._receive(left) is None and left == 0.0:
                    break
            return self.exits.pop(pid, None)

    def busy(self) -> bool:
        """Whether a child it forked may still run (the exits it has sent read first)."""
        with self.lock:
            while self._receive(0.0) is not None:
                pass
            return bool(self.running)

    def _receive(self, timeout: float | None) -> tuple | None:
        """The zygote's next message (its exits recorded), or None when none came within ``timeout`` or it died."""
        if self.dead or not select.select([self.socket], [], [], timeout)[0]:
            return None
        data = self.socket.recv(MESSAGE_BYTES_MAX)
        if not data:
            self._die()
            return None
        message = pickle.loads(data)
        if message[0] == "exited":
            _, pid, code, cpu_seconds, max_resident_bytes = message
            self.running.discard(pid)
            self.exits[pid] = code
            self.usage = self.usage.and_(ChildrenUsage(cpu_seconds, max_resident_bytes))
        return message

    def _die(self) -> None:
        """Stop the zygote; its children die with it (killed, as far as their callers can tell)."""
        if not self.dead:
            self.dead = True
            self.process.kill()
            self.process.wait()
            self.socket.close()
            self.exits.update((pid, -signal.SIGKILL) for pid in self.running)
            self.running.clear()

    def close(self) -> None:
        with self.lock:
            self._die()


_zygotes: dict[tuple, Zygote] = {}
"""The zygotes by (the process that started them, interpreter, folder, import path); those of another key are let go
of once their children have exited (a process forked from their starter's leaves them be: they are not its own)."""
_zygotes_lock = threading.Lock()


def start(module: str, stdin: int | None, stderr: IO[bytes], argv_fds: tuple[int, ...]) -> ProcessLike:
    """A process running ``python -m module *argv_fds PARENT``: forked from this process's zygote (started, or
    started again, as needed; PARENT is the zygote's pid), else a fresh interpreter (PARENT: this process's pid).
    ``stdin``: a readable fd, or None for nothing; ``argv_fds`` are handed to it and stay the caller's to close."""
    key = (os.getpid(), sys.executable, os.getcwd(), tuple(sys.path))
    null = os.open(os.devnull, os.O_RDONLY)
    try:
        for _ in range(2):
            with _zygotes_lock:
                mine = [k for k in _zygotes if k[0] == key[0]]
                for other in [k for k in mine if _zygotes[k].dead or k != key and not _zygotes[k].busy()]:
                    _zygotes.pop(other).close()
                if key not in _zygotes:
                    try:
                        _zygotes[key] = Zygote()
                    except OSError:  # no SOCK_SEQPACKET socket pair here (macOS), or no process to start
                        break
                zygote = _zygotes[key]
            forked = zygote.fork(module, null if stdin is None else stdin, stderr.fileno(), argv_fds)
            if forked is not None:
                return forked
    finally:
        os.close(null)
    return subprocess.Popen([sys.executable, "-m", module, *map(str, argv_fds), str(os.getpid())], pass_fds=argv_fds,
                            stdin=subprocess.DEVNULL if stdin is None else stdin, stdout=subprocess.DEVNULL,
                            stderr=stderr, env=worker_environment(), start_new_session=True)


@atexit.register
def _close_all() -> None:
    """Stop this process's zygotes (reaped: what their children used joins ``RUSAGE_CHILDREN``)."""
    for key, zygote in _zygotes.items():
        if key[0] == os.getpid():
            zygote.close()


# --- the zygote process ---------------------------------------------------------------------------------------------

def main(argv: list[str]) -> int:
    """Serve fork requests on the socket ``argv[1]`` until it closes; die with ``argv[2]`` (a pid)."""
    requests = socket.socket(fileno=int(argv[1]))
    die_with_parent(int(argv[2]))
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    for name in PRELOADED:
        importlib.import_module(name)
    woken, wake = os.pipe()
    os.set_blocking(woken, False)
    os.set_blocking(wake, False)
    signal.set_wakeup_fd(wake)
    signal.signal(signal.SIGCHLD, lambda *_: None)  # wakes the select below through ``wake``
    while True:
        readable = select.select([requests.fileno(), woken], [], [])[0]
        if woken in readable:
            while _drained(woken):
                pass
        _send_exits(requests)
        if requests.fileno() in readable:
            data, fds, _, _ = socket.recv_fds(requests, MESSAGE_BYTES_MAX, 2 + 8)
            if not data:
                return 0
            module, env, folder, path = pickle.loads(data)
            pid = os.fork()
            if pid == 0:
                _child(module, env, folder, path, fds, closing=(requests.fileno(), woken, wake))
            for fd in fds:
                os.close(fd)
            requests.send(pickle.dumps(("started", pid)))


def _drained(fd: int) -> bool:
    try:
        return bool(os.read(fd, 4096))
    except BlockingIOError:
        return False


def _send_exits(requests: socket.socket) -> None:
    """Reap every child that has exited and tell the requester how, and what it used."""
    while True:
        try:
            pid, status, usage = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        requests.send(pickle.dumps(("exited", pid, os.waitstatus_to_exitcode(status), usage.ru_utime + usage.ru_stime,
                                    usage.ru_maxrss * RESIDENT_BYTES_PER_UNIT)))


def _child(module: str, env: dict[str, str], folder: str, path: list[str], fds: list[int],
           closing: tuple[int, ...]) -> None:
    """Become the process ``python -m module`` would have been, in ``folder`` with ``env`` and ``path``; never
    returns."""
    code = 1
    try:
        signal.set_wakeup_fd(-1)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        for fd in closing:
            os.close(fd)
        os.setsid()
        stdin, stderr, *argv_fds = fds
        os.dup2(stdin, 0)
        os.dup2(stderr, 2)
        os.close(stdin)
        os.close(stderr)
        os.environ.clear()
        os.environ.update(env)
        os.chdir(folder)
        sys.path[:] = [folder, *path]
        if module not in PRELOADED:
            raise ValueError(f"{module} is not one the zygote runs ({', '.join(PRELOADED)})")
        code = importlib.import_module(module).main([module, *map(str, argv_fds), str(os.getppid())])
    except SystemExit as exit:
        code = exit.code if isinstance(exit.code, int) else 1
    except BaseException:  # noqa: BLE001 - reported as a fresh interpreter's traceback would be
        traceback.print_exc()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
