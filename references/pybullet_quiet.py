"""PyBullet, imported without its "pybullet build time" banner.

The banner is printed by the C extension to C's stdout, so it lands in the output of
``simparity export ... > model.urdf``. File descriptor 1 points at /dev/null for the import,
and C's buffered output is flushed there before it is restored (else the banner would be
flushed at exit, into the real stdout).
"""

from __future__ import annotations

import ctypes
import os
import sys


def _import_quietly():
    sys.stdout.flush()
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        import pybullet as module
    finally:
        ctypes.CDLL(None).fflush(None)
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
    return module


pybullet = _import_quietly()
