"""One BLAS thread for the bench's timed rows: NumPy's OpenBLAS is told through its own API (``openblas_set_num_threads``,
as threadpoolctl does), in this process, whatever ``OPENBLAS_NUM_THREADS`` was when NumPy was imported; the
processes the bench starts inherit ``OPENBLAS_NUM_THREADS=1`` (and OpenMP's and MKL's) from its environment.

A BLAS other than OpenBLAS (Accelerate, MKL, a system BLAS under another name) is not changed: the bench says it
could not read the thread count, and its environment variables still reach the processes it starts."""

from __future__ import annotations

import ctypes
import glob
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from simparity.comparisons.common.processes import BLAS_THREAD_VARIABLES

_SYMBOL_PREFIXES = ("openblas", "scipy_openblas")
"""OpenBLAS's function names as built: its own, and the prefixed build the NumPy and SciPy wheels bundle."""
_SYMBOL_SUFFIXES = ("", "64_")
"""The 64-bit-integer build's suffix (``scipy_openblas_get_num_threads64_``)."""


@dataclass(frozen=True)
class Blas:
    """A loaded OpenBLAS: its file and its thread-count functions."""

    path: str
    get_threads: Callable[[], int]
    set_threads: Callable[[int], None]

    @property
    def threads(self) -> int:
        return int(self.get_threads())


def _candidate_paths() -> list[str]:
    """Files of the OpenBLAS libraries in this process: the mapped ones (Linux's /proc/self/maps), else those
    bundled beside NumPy (its wheels' ``numpy.libs`` or ``numpy/.dylibs``)."""
    try:
        with open("/proc/self/maps", encoding="utf-8") as maps:
            mapped = {line.split()[-1] for line in maps if "openblas" in line.lower() and "/" in line}
    except OSError:
        mapped = set()
    if mapped:
        return sorted(mapped)
    import numpy

    root = Path(numpy.__file__).parent
    return sorted(glob.glob(str(root.parent / "numpy.libs" / "*openblas*")) +
                  glob.glob(str(root / ".dylibs" / "*openblas*")))


def loaded_blas() -> list[Blas]:
    """Every OpenBLAS this process has loaded whose thread count can be read and set."""
    found = []
    for path in _candidate_paths():
        try:
            library = ctypes.CDLL(path)
        except OSError:
            continue
        for prefix in _SYMBOL_PREFIXES:
            for suffix in _SYMBOL_SUFFIXES:
                get = getattr(library, f"{prefix}_get_num_threads{suffix}", None)
                put = getattr(library, f"{prefix}_set_num_threads{suffix}", None)
                if get is not None and put is not None:
                    put.argtypes, put.restype, get.restype = [ctypes.c_int], None, ctypes.c_int
                    found.append(Blas(path, get, put))
    return found


def describe_threads() -> str:
    """The BLAS threads in effect, for the machine section: ``1 (libscipy_openblas64_....so)`` or why unknown."""
    libraries = loaded_blas()
    if not libraries:
        return ("not read: no OpenBLAS loaded (" + ", ".join(f"{v}={os.environ.get(v, 'unset')}"
                                                             for v in BLAS_THREAD_VARIABLES) + ")")
    return ", ".join(f"{b.threads} ({Path(b.path).name})" for b in libraries)


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Inside: every loaded OpenBLAS on one thread, and :data:`BLAS_THREAD_VARIABLES` set to 1 for the processes
    started; both as they were after."""
    libraries = loaded_blas()
    threads = [b.threads for b in libraries]
    environment = {v: os.environ.get(v) for v in BLAS_THREAD_VARIABLES}
    for blas in libraries:
        blas.set_threads(1)
    os.environ.update({v: "1" for v in BLAS_THREAD_VARIABLES})
    try:
        yield
    finally:
        for blas, count in zip(libraries, threads):
            blas.set_threads(count)
        for variable, value in environment.items():
            if value is None:
                os.environ.pop(variable, None)
            else:
                os.environ[variable] = value
