"""Engines that misbehave the ways a user's engine can take a process down, for tests/test_isolation.py.

Each is core's in-house engine with a ``run`` that, instead of simulating, segfaults, hangs in C
code (the GIL held: no Python-level timeout could stop it) or allocates without bound. They are
named by spec in ``--engines``: ``tests.hostile_engines:SegfaultingEngine``.
"""

from __future__ import annotations

import ctypes
import time

import numpy as np

from simparity.core.engine import Simulation
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
