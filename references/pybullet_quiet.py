"""PyBullet, imported without its "pybullet build time" banner.

The C extension prints the banner through C's stdio (seen on stdout and on stderr depending
on how the streams are attached), so it would land in ``simparity export ... > model.urdf``
and in every log. File descriptors 1 and 2 point at /dev/null for the import, and C's
buffered output is flushed there before they are restored (else it would reappear at exit).
A failing import still raises as usual.
"""

from __future__ import annotations

import ctypes
import os
import sys


def _import_quietly():
    sys.stdout.flush()
    sys.stderr.flush()
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    devnull = os.open(os.devnull, os.O_WRONLY)
    for fd in saved:
        os.dup2(devnull, fd)
    try:
        import pybullet as module
    finally:
        ctypes.CDLL(None).fflush(None)
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)
    return module


pybullet = _import_quietly()
