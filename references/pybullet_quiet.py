"""PyBullet, imported without its "pybullet build time" banner.

The banner is printed by the C extension straight to file descriptor 1, so it lands in the
output of ``simparity export ... > model.urdf``; it is silenced for the import only.
"""

from __future__ import annotations

import os
import sys


def _import_quietly():
    sys.stdout.flush()
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        import pybullet as module
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
    return module


pybullet = _import_quietly()
