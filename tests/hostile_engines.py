"""Engines that misbehave the ways a user's engine can take a process down, for tests/comparisons/execute/test_isolation.py.

Each is core's in-house engine with a ``run`` that, instead of simulating, segfaults, hangs in C
code (the GIL held: no Python-level timeout could stop it) or allocates without bound. They are
named by spec in ``--engines``: ``tests.hostile_engines:SegfaultingEngine``.
"""

from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time

import numpy as np

from simparity.core.model.engine import Simulation
from simparity.core.inhouse import InHouseEngine

ALLOCATION_BYTES = 100 * 1024 ** 2
"""Each allocation of the hogging engine: 100 MiB, touched so it is resident."""


class _Segfault(Simulation):
    def run(self, n_steps: int):
        ctypes.string_at(0)  # reads address 0: SIGSEGV


class _Hang(Simulation):
    def run(self, n_steps: int):
        while True:
            time.sleep(3600)


class _Hog(Simulation):
    def run(self, n_steps: int):
        blocks = []
        while True:
            blocks.append(np.ones(ALLOCATION_BYTES // 8))


class _Malformed(Simulation):
    def run(self, n_steps: int):
        return {"not": "a trajectory"}


class _Misbehaving(InHouseEngine):
    simulation: type[Simulation]

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        return self.simulation()


class SegfaultingEngine(_Misbehaving):
    name = "segfaulting"
    simulation = _Segfault


class HangingEngine(_Misbehaving):
    name = "hanging"
    simulation = _Hang


class HoggingEngine(_Misbehaving):
    name = "hogging"
    simulation = _Hog


class HangingTwin(HangingEngine):
    """Another engine called ``hanging``: a run may not have two engines of one name."""


class MalformedEngine(_Misbehaving):
    name = "malformed"
    simulation = _Malformed


FE_UPWARD = 0x800
"""glibc's x86-64 value of FE_UPWARD (fenv.h): every later floating-point operation of the process rounds up."""


class RoundingEngine(InHouseEngine):
    """Core's engine that first switches its process's FPU to round upward (a legitimate library can do this and
    forget to restore it): results computed after it in the same process would change in their last bits."""

    name = "rounding"

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        ctypes.CDLL("libm.so.6").fesetround(FE_UPWARD)
        return super().build_dynamics(scene, integrator, dt)


class _Exit(Simulation):
    def run(self, n_steps: int):
        os._exit(0)


class ExitingEngine(_Misbehaving):
    """Ends its process with exit code 0 in the middle of a case, as if all were well."""

    name = "exiting"
    simulation = _Exit


def _parent(pid: int) -> int:
    with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
        return int(stat.read().rsplit(")", 1)[1].split()[1])


class _KillHost(Simulation):
    def run(self, n_steps: int):
        host = _parent(os.getppid())  # the case worker's parent: the zygote it was forked from, or what started it
        with open(f"/proc/{host}/cmdline", "rb") as command:
            if b"simparity.comparisons.common.zygote" in command.read():
                host = _parent(host)  # the zygote's parent started it: the Dask worker
        os.kill(host, signal.SIGKILL)
        while True:
            time.sleep(3600)


class HostKillingEngine(_Misbehaving):
    """Kills the process that started its case's worker, as a lost node would lose it: on Dask, the Dask worker."""

    name = "host-killing"
    simulation = _KillHost


LEFTOVER_MARK = "simparity-test-leftover-process"
"""On the command line of the process :class:`ForkingEngine` leaves running, to find it."""


class ForkingEngine(InHouseEngine):
    """Core's engine that starts a process in every case and leaves it running (a simulator's server, say)."""

    name = "forking"

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)", LEFTOVER_MARK])
        return super().build_dynamics(scene, integrator, dt)


def leftovers() -> list[int]:
    """The pids of the processes :class:`ForkingEngine` left running."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as cmdline:
                if LEFTOVER_MARK.encode() in cmdline.read():
                    found.append(int(pid))
        except OSError:  # gone meanwhile
            pass
    return found


class SegfaultOnConstruction(InHouseEngine):
    """Segfaults as it is constructed: before any case, where simparity itself would build it."""

    name = "segfault-on-construction"

    def __init__(self) -> None:
        ctypes.string_at(0)


class ExitInVersion(InHouseEngine):
    """Ends its process (code 3) when asked its version."""

    name = "exit-in-version"

    def version(self) -> str:
        os._exit(3)


class HangInIntegrators(InHouseEngine):
    """Never answers which integrators it offers."""

    name = "hang-in-integrators"

    def integrators(self):
        while True:
            time.sleep(3600)
