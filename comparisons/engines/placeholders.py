"""Engines that stand in for one that cannot run, so that every scene still gets its rows, with the reason.

:class:`UnavailableEngine` stands in for a built-in engine whose library will not import here (MuJoCo
not installed): ``n/a`` rows, as for any scene an engine cannot do.
:class:`BrokenEngine` stands in for a user's engine that does not import (a typo in its module, a
missing dependency), whose own code raised while it was loaded or built, or that broke the interface:
``failed`` rows, which fail ``simparity run`` (exit 1) and the CI gate like any other failure: an
engine the user asked for that never ran must not pass. :class:`NotAnEngine`, a BrokenEngine, stands in
for a ``module:attr`` that names no engine at all, which the command line refuses before running.
"""

from __future__ import annotations

from simparity.core.model.engine import Engine, KinematicsModel, Simulation, Support
from simparity.core.model.errors import PluginError, SimparityError

class StandInEngine(Engine):
    """An engine standing in for one that cannot run: the run's workers use it as it is, never building the
    engine it stands in for again (a plugin that hung or crashed while it was described would do so again in
    every case).

    Attributes
    ----------
    reason : str
        Why the engine cannot run, the detail of every row.
    """

    reason: str


class UnavailableEngine(StandInEngine):
    """An engine whose library failed to import: every scene gets n/a with the import error.

    Attributes
    ----------
    reason : str
        ``<name> is not importable here: <error>``, the detail of every row.
    """

    def __init__(self, name: str, error: str) -> None:
        self.name = name
        self.reason = f"{name} is not importable here: {error}"

    def version(self) -> str:
        return "unavailable"

    def integrators(self) -> tuple[str, ...]:
        return ()

    def supports_dynamics(self, scene, integrator: str) -> Support:
        return Support.no(self.reason)

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        raise SimparityError(self.reason)

    def supports_kinematics(self, chain) -> Support:
        return Support.no(self.reason)

    def build_kinematics(self, chain) -> KinematicsModel:
        raise SimparityError(self.reason)

    def supports_ik(self, chain, solver: str, position_only: bool) -> Support:
        return Support.no(self.reason)


class BrokenEngine(StandInEngine):
    """A user's engine that raised while it was loaded or built, or broke the interface: every case of every
    scene fails with that error.

    Attributes
    ----------
    reason : str
        What went wrong, the detail of every row.
    """

    def __init__(self, name: str, reason: str) -> None:
        self.name = name
        self.reason = f"{name} is broken: {reason}"

    def version(self) -> str:
        return "broken"

    def integrators(self) -> tuple[str, ...]:
        return ()

    def scene_integrators(self, scene) -> tuple[str, ...]:
        """Raises: the runner turns the scene's one case into failed rows with the reason."""
        raise PluginError(self.reason)

    def supports_dynamics(self, scene, integrator: str) -> Support:
        raise PluginError(self.reason)

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        raise PluginError(self.reason)

    def supports_kinematics(self, chain) -> Support:
        raise PluginError(self.reason)

    def build_kinematics(self, chain) -> KinematicsModel:
        raise PluginError(self.reason)

    def supports_ik(self, chain, solver: str, position_only: bool) -> Support:
        raise PluginError(self.reason)


class NotAnEngine(BrokenEngine):
    """A spec or plugin whose ``module:attr`` names no engine at all: an attribute the module lacks, a value, a class
    that is not an Engine subclass, a callable that needs arguments or returns something else. A mistake in the
    name, not in an engine's code: ``simparity run`` refuses it before any case runs (exit 2); elsewhere (the API,
    ``simparity engines``) it fails its rows like any broken engine.

    Attributes
    ----------
    mistake : str
        What ``module:attr`` names instead of an engine, and what is allowed (one line).
    """

    def __init__(self, name: str, mistake: str) -> None:
        super().__init__(name, mistake)
        self.mistake = mistake
