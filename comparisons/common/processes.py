"""What every process simparity starts shares: its environment (one BLAS thread, this import path), why it died
(from its exit code and the end of its standard error), and its memory read from /proc."""

from __future__ import annotations

import os
import signal
import sys
import sysconfig

BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""Set to 1 in every worker: each worker is one CPU, many small matrix products gain nothing from BLAS
threads, and results do not depend on how many threads summed them."""


def worker_environment() -> dict[str, str]:
    """The environment of a worker: this one, with one BLAS thread and this process's import path."""
    env = dict(os.environ)
    for variable in BLAS_THREAD_VARIABLES:
        env[variable] = "1"
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    return env


def death_cause(code: int, stderr: str, process: str = "the worker") -> str:
    """Why ``process`` died, from its exit code and the end of its standard error (faulthandler's stack)."""
    if code < 0:
        name = signal.Signals(-code).name if -code in signal.valid_signals() else f"signal {-code}"
        cause = f"crashed: {process} was killed by signal {-code} ({name})"
        if -code == signal.SIGKILL:
            cause += " (the system's out-of-memory killer, or another process)"
    else:
        cause = f"crashed: {process} exited with code {code}" + (" before its cases finished" if code == 0 else "")
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    frames = [line for line in lines if line.startswith("File ")]
    faulthandler_stack = any(line.startswith(("Current thread", "Thread 0x")) for line in lines)
    if faulthandler_stack and frames:  # most recent call first
        cause += f", in {frames[0]}"
        own = next((f for f in frames if not _in_stdlib(f)), frames[0])
        if own != frames[0]:  # the crash is in the standard library (ctypes): say whose code called it
            cause += f", called from {own}"
    elif lines:  # a Python traceback: its last line is the error
        cause += f": {lines[-1][:300]}" + (f" ({frames[-1][:200]})" if frames else "")
    return cause


def _in_stdlib(frame: str) -> bool:
    """True when a faulthandler frame line (``File "path", line N in name``) is in Python's standard library."""
    path = frame.split('"')[1] if frame.count('"') >= 2 else ""
    stdlib = sysconfig.get_paths()["stdlib"]
    return path.startswith(stdlib + os.sep) and "site-packages" not in path


def status_bytes(field: str, pid: int | str = "self") -> int | None:
    """A memory field of a process from Linux's /proc (``VmHWM``, ``VmRSS``, ...) [bytes]; None when it cannot be
    read (not Linux, the process is gone)."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as status:
            for line in status:
                if line.startswith(f"{field}:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError):
        return None
    return None
