"""A user's engine for test_probe, in a module of its own: its probe and its worker import this module, and
importing the test module (pandas, pytest, the command line) cost each ~2 CPU-s more."""

from __future__ import annotations

from simparity.core.model.engine import Engine, Support
from simparity.core.inhouse import InHouseEngine


class OwnIntegrators(Engine):
    """A user's engine with an integrator name no built-in has: core's RK4, called ``own_rk4``."""

    name = "own"

    def __init__(self) -> None:
        self._core = InHouseEngine()

    def version(self) -> str:
        return self._core.version()

    def integrators(self):
        return ("own_rk4",)

    def supports_dynamics(self, scene, integrator):
        return self._core.supports_dynamics(scene, "rk4")

    def build_dynamics(self, scene, integrator, dt):
        return self._core.build_dynamics(scene, "rk4", dt)

    def supports_kinematics(self, chain):
        return Support.no("dynamics only")

    def build_kinematics(self, chain):
        raise NotImplementedError("dynamics only")

    def theoretical_order(self, integrator):
        return 4
