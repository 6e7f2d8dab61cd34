"""The unit of work: a case (scene x engine x integrator or solver x dt), grouped by what its cases share.

A scene is planned (:func:`plan_scene`) into :class:`CaseGroup` s: a dynamics scene into one group per
time step (its cases share that step's reference trajectory) and one for the penalty integrators'
stability limits; a kinematics scene into one group (the reference FK); an IK scene into one group
(the targets and the judges' FK). A group runs in one worker (``runner.run_group``), case by case,
each case giving a :class:`CaseOutcome`; :func:`assemble_scene` puts a scene's outcomes back together
with what needs them all (observed orders of convergence, the IK agreement matrix), in the same
order whatever ran where. Every case has a :class:`CaseKey` a finished outcome is stored under, so an
interrupted run resumes where it stopped.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from typing import Callable, cast

import numpy as np

from simparity.comparisons.common.scene_hash import scene_hash
from simparity.comparisons.common.integrators import NO_INTEGRATOR, motion_reference_integrator
from simparity.comparisons.engines.placeholders import StandInEngine
from simparity.core.model.engine import Engine
from simparity.core.model.results import ResultRow, SeriesRecord
from simparity.core.model.scenes.contact import PENALTY_PREFIX
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinds import Scene
from simparity.core.model.scenes.kinematics import KinematicsScene

DYNAMICS, STABILITY, KINEMATICS, IK, JOINT_DYNAMICS, JOINT_MOTION = (
    "dynamics", "stability", "kinematics", "ik", "joint_dynamics", "joint_motion")
"""What a group computes: stepping at one dt, the penalty integrators' stability limits, FK and
Jacobians, IK solves, joint-space dynamics at states."""

EngineFor = Callable[[str], Engine]
"""The engine of a name (the run's engines, the scene's reference), as a group's cases are run with it."""


@dataclass(frozen=True)
class CaseSpec:
    """One case of a group: ``integrator`` holds the IK solver for IK, the method for joint dynamics, "" for
    kinematics."""

    engine: str
    integrator: str


@dataclass(frozen=True)
class CaseGroup:
    """Cases that share what is computed once for them, run together in one worker.

    Attributes
    ----------
    scene : Scene
    scene_hash : str
        :func:`scene_hash` of ``scene``.
    kind : str
        DYNAMICS, STABILITY, KINEMATICS, IK, JOINT_DYNAMICS or JOINT_MOTION.
    dt : float
        The time step [s] of a DYNAMICS or JOINT_MOTION group; NaN otherwise.
    cases : tuple of CaseSpec
    engines : tuple of (str, str)
        (name, spec) of every engine of the run, in order (an IK group's judges); a worker builds an
        engine from its spec (``comparisons.engines.registry.make_engine``), a reference from its name.
    repeats : int
        Timed repeats per case.
    reference_label : str
        The reference named in the rows (``engine:integrator``).
    stand_ins : tuple of StandInEngine
        The run's engines that cannot run (:mod:`comparisons.engines.placeholders`): a worker uses them as they
        are instead of building the engine again.
    """

    scene: Scene
    scene_hash: str
    kind: str
    dt: float
    cases: tuple[CaseSpec, ...]
    engines: tuple[tuple[str, str], ...]
    repeats: int
    reference_label: str
    stand_ins: tuple[StandInEngine, ...] = ()

    @property
    def engine_names(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.engines)

    @property
    def dynamics_scene(self) -> DynamicsScene:
        """The scene of a DYNAMICS or STABILITY group (planned only for dynamics scenes)."""
        return cast(DynamicsScene, self.scene)

    @property
    def kinematics_scene(self) -> KinematicsScene:
        """The scene of a KINEMATICS group."""
        return cast(KinematicsScene, self.scene)

    @property
    def joint_dynamics_scene(self) -> JointDynamicsScene:
        """The scene of a JOINT_DYNAMICS group."""
        return cast(JointDynamicsScene, self.scene)

    @property
    def joint_motion_scene(self) -> JointMotionScene:
        """The scene of a JOINT_MOTION group."""
        return cast(JointMotionScene, self.scene)

    @property
    def ik_scene(self) -> IKScene:
        """The scene of an IK group."""
        return cast(IKScene, self.scene)

    def spec_of(self, name: str) -> str:
        """What to build engine ``name`` from: its spec if it is one of the run's, else the name itself."""
        return dict(self.engines).get(name, name)


@dataclass
class CaseOutcome:
    """What one case produced.

    Attributes
    ----------
    rows : list of ResultRow
    series : list of SeriesRecord
    errors, floors : dict
        A dynamics case's raw errors and their rounding floors, for the order fits.
    saturation : dict
        A dynamics case's saturation ratio of each error (>= 1: saturated; ``metrics.saturation_ratios``).
    integrates_rotation : bool
    ends : dict of str to ndarray
        An IK case's end-effector positions (N, 3) [m] of its solutions by each judge's FK.
    reference_label : str
        An IK case's label naming its judges (the agreement matrix's).
    theoretical_order : int or None
        A dynamics case's integrator's theoretical order, as its engine declares it (None: unknown).
    harness_failure : bool
        True when the case did not finish (its worker crashed, hung or ran out of memory): a resumed
        run computes it again.
    """

    rows: list[ResultRow]
    series: list[SeriesRecord] = field(default_factory=list)
    errors: dict[str, float] = field(default_factory=dict)
    floors: dict[str, float] = field(default_factory=dict)
    integrates_rotation: bool = True
    ends: dict[str, np.ndarray] = field(default_factory=dict)
    reference_label: str = ""
    harness_failure: bool = False
    saturation: dict[str, float] = field(default_factory=dict)
    theoretical_order: int | None = None


@dataclass(frozen=True)
class CaseKey:
    """What a finished case is stored and found again under: the scene's content, the engine and its
    version, the integrator (or solver) and the time step, and what the group computes."""

    scene_hash: str
    engine: str
    engine_version: str
    integrator: str
    dt: float
    kind: str

    def digest(self) -> str:
        """A file-name-safe hash of the key (hex, 64 characters)."""
        text = "\0".join([self.scene_hash, self.engine, self.engine_version, self.integrator,
                          float(self.dt).hex(), self.kind])
        return hashlib.sha256(text.encode("utf-8")).hexdigest()


def case_key(group: CaseGroup, spec: CaseSpec, versions: dict[str, str]) -> CaseKey:
    """The key of ``spec`` of ``group``; ``versions`` maps engine names to their versions."""
    return CaseKey(group.scene_hash, spec.engine, versions[spec.engine], spec.integrator, group.dt, group.kind)


def _integrators(scene: DynamicsScene, engine: Engine) -> list[str]:
    """The engine's integrators the scene runs (all it offers unless the scene names some); none when the
    engine fails to say (its one case then fails in a worker, with the error)."""
    try:
        offered = tuple(engine.scene_integrators(scene))
    except Exception:  # noqa: BLE001 - a user's engine: its n/a case reports the error
        return []
    return [i for i in offered if not scene.integrators or i in scene.integrators]


def _solvers(engine: Engine) -> tuple[str, ...]:
    """The engine's IK solvers; none when it fails to say (its one case then fails with the error)."""
    try:
        return tuple(engine.ik_solvers())
    except Exception:  # noqa: BLE001 - a user's engine: its case reports the error
        return ()


def _methods(engine: Engine) -> tuple[str, ...]:
    """The engine's joint-dynamics methods; none when it fails to say (its one case then reports the error)."""
    try:
        return tuple(engine.joint_dynamics_methods())
    except Exception:  # noqa: BLE001 - a user's engine: its case reports the error
        return ()


def _motion_integrators(scene: JointMotionScene, engine: Engine) -> list[str]:
    """The engine's joint-motion integrators the scene runs (all it offers unless the scene names some); none when
    the engine fails to say (its one case then reports the error)."""
    try:
        offered = tuple(engine.joint_motion_integrators())
    except Exception:  # noqa: BLE001 - a user's engine: its case reports the error
        return []
    return [i for i in offered if not scene.integrators or i in scene.integrators]


def plan_scene(scene, engines: list[Engine], reference: Engine, repeats: int,
               specs: dict[str, str] | None = None) -> list[CaseGroup]:
    """The groups of ``scene`` on ``engines`` (built engines, in the run's order) measured against
    ``reference``, in the order their rows are stored; ``specs`` maps engine names to what they were built
    from when that is not the name."""
    names = tuple((e.name, (specs or {}).get(e.name, e.name)) for e in engines)
    stand_ins = tuple(e for e in engines if isinstance(e, StandInEngine))
    digest = scene_hash(scene)

    def group(kind: str, dt: float, cases: list[CaseSpec], label: str) -> CaseGroup:
        return CaseGroup(scene, digest, kind, dt, tuple(cases), names, repeats, label, stand_ins)

    if isinstance(scene, IKScene):
        cases = [CaseSpec(e.name, s) for e in engines for s in _solvers(e) or (NO_INTEGRATOR,)]
        return [group(IK, math.nan, cases, f"{scene.reference}:fk")]
    if isinstance(scene, JointDynamicsScene):
        cases = [CaseSpec(e.name, m) for e in engines for m in _methods(e) or (NO_INTEGRATOR,)]
        return [group(JOINT_DYNAMICS, math.nan, cases, f"{reference.name}:{(_methods(reference) or (NO_INTEGRATOR,))[0]}")]
    if isinstance(scene, JointMotionScene):
        cases = [CaseSpec(e.name, i) for e in engines for i in (_motion_integrators(scene, e) or [NO_INTEGRATOR])]
        label = f"{reference.name}:{motion_reference_integrator(scene, reference)}"
        return [group(JOINT_MOTION, dt, cases, label) for dt in scene.dts]
    if not isinstance(scene, DynamicsScene):
        return [group(KINEMATICS, math.nan, [CaseSpec(e.name, "") for e in engines], f"{reference.name}:fk")]
    label = f"{reference.name}:{reference.scene_integrators(scene)[0]}"
    cases = [CaseSpec(e.name, i) for e in engines for i in (_integrators(scene, e) or [NO_INTEGRATOR])]
    groups = [group(DYNAMICS, dt, cases, label) for dt in scene.dts]
    if scene.contact is not None:
        penalty = [c for c in cases if c.integrator.startswith(PENALTY_PREFIX)]
        if penalty:
            groups.append(group(STABILITY, math.nan, penalty, label))
    return groups
