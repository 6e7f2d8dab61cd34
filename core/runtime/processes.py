"""Child processes that do not outlive the process that started them (case workers, probes, figure writers)."""

from __future__ import annotations

import ctypes
import os
import signal

_PR_SET_PDEATHSIG = 1
"""Linux prctl option: the signal this process gets when its parent dies."""


def die_with_parent(parent: int) -> None:
    """Ask Linux to kill this process when its parent ``parent`` (a pid) dies: a hung case or a figure being
    drawn must not outlive a killed run. Elsewhere, a child ends when its parent's pipe closes instead."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)


def kill_group(group: int) -> None:
    """SIGKILL every process of process group ``group`` (a pid that leads, or led, one); nothing if it is gone."""
    try:
        os.killpg(group, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
