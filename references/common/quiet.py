"""Engines' console output, kept off simparity's own.

PyBullet prints its import banner and URDF warnings through C's stdio (on stdout, often
without a newline), MuJoCo and Pinocchio may print parser warnings: left alone, that text
lands in ``simparity export ... > model.xml``, in every log and in the middle of
simparity's own lines. :func:`captured_output` points file descriptors 1 and 2 at a
temporary file while an engine call runs, flushes C's buffers into it, restores the
streams and hands back what was written, so an adapter can report it where it matters.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
import tempfile
from dataclasses import dataclass

_LIBC = ctypes.CDLL(None)
_MAX_KEPT = 2000
"""Characters of captured output kept for a detail (an engine can print megabytes)."""


@dataclass
class Captured:
    """What an engine printed during a :func:`captured_output` block (filled on exit)."""

    text: str = ""


@contextlib.contextmanager
def captured_output():
    """Capture everything written to file descriptors 1 and 2 (C and Python) in the block."""
    sys.stdout.flush()
    sys.stderr.flush()
    captured = Captured()
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    with tempfile.TemporaryFile() as sink:
        for fd in saved:
            os.dup2(sink.fileno(), fd)
        try:
            yield captured
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            _LIBC.fflush(None)
            for fd, copy in saved.items():
                os.dup2(copy, fd)
                os.close(copy)
            sink.seek(0)
            captured.text = sink.read(_MAX_KEPT).decode("utf-8", "replace").strip()
