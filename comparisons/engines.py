"""The engines simparity knows, by name, imported only when asked for."""

from __future__ import annotations

import importlib

from simparity.core.engine import Engine, KinematicsModel, Simulation, Support
from simparity.core.errors import UnknownEngineError, one_line

_ENGINES = {
    "core": ("simparity.core.inhouse", "InHouseEngine"),
    "analytic": ("simparity.references.analytic", "AnalyticEngine"),
    "mujoco": ("simparity.references.mujoco_adapter", "MujocoEngine"),
    "pybullet": ("simparity.references.pybullet_adapter", "PybulletEngine"),
    "pinocchio": ("simparity.references.pinocchio_adapter", "PinocchioEngine"),
    "tight": ("simparity.references.tight", "TightSolveEngine"),
}
ENGINE_NAMES = tuple(_ENGINES)
DEFAULT_ENGINES = ("core", "analytic", "mujoco", "pybullet", "pinocchio")
"""What ``simparity run`` runs unless told otherwise; ``tight`` serves as a reference only."""


class UnavailableEngine(Engine):
    """An engine whose library failed to import: every scene gets n/a with the import error."""

    def __init__(self, name: str, error: str) -> None:
        self.name = name
        self._reason = f"{name} is not importable here: {error}"

    def version(self) -> str:
        return "unavailable"

    def integrators(self) -> tuple[str, ...]:
        return ("-",)

    def supports_dynamics(self, scene, integrator: str) -> Support:
        return Support.no(self._reason)

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        raise RuntimeError(self._reason)

    def supports_kinematics(self, chain) -> Support:
        return Support.no(self._reason)

    def build_kinematics(self, chain) -> KinematicsModel:
        raise RuntimeError(self._reason)

    def supports_ik(self, chain, solver: str, position_only: bool) -> Support:
        return Support.no(self._reason)


def check_engine_names(names) -> tuple[str, ...]:
    """The names, checked against :data:`ENGINE_NAMES`, duplicates dropped; raises UnknownEngineError."""
    unknown = [n for n in names if n not in _ENGINES]
    if unknown:
        raise UnknownEngineError(
            f"unknown engine(s): {one_line(', '.join(unknown))} (allowed: {', '.join(ENGINE_NAMES)})"
        )
    if not names:
        raise UnknownEngineError(f"no engine named (allowed: {', '.join(ENGINE_NAMES)})")
    return tuple(dict.fromkeys(names))


def make_engine(name: str) -> Engine:
    """The engine called ``name``, or an :class:`UnavailableEngine` if its library won't import."""
    check_engine_names([name])
    module, cls = _ENGINES[name]
    try:
        return getattr(importlib.import_module(module), cls)()
    except ImportError as err:
        return UnavailableEngine(name, str(err))


def known_integrators() -> tuple[str, ...]:
    """Every integrator name some engine offers (for checking scene files)."""
    names = {}
    for engine in ENGINE_NAMES:
        names.update(dict.fromkeys(make_engine(engine).integrators()))
    names.pop("-", None)
    return tuple(names)
