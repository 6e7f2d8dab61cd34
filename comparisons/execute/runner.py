"""Runs cases on engines and measures them against each scene's reference.

Every scene x engine x integrator x dt gets one row per metric: ``ok`` with a value, or
``n/a`` / ``failed`` / ``diverged`` with the reason in ``detail``. An engine that raises
becomes ``failed`` rows; the run goes on.

A scene is planned into groups of cases (:mod:`comparisons.execute.cases`); :func:`run_group` runs one
group wherever it is sent (this process, a worker process, a Dask worker), yielding each case's
outcome as it finishes, each kind of group by its runner (:mod:`comparisons.execute.dynamics_runner`,
:mod:`comparisons.execute.chain_runner`, :mod:`comparisons.execute.ik_runner`,
:mod:`comparisons.execute.motion_runner`); :func:`assemble_scene` puts a scene's outcomes together in its stored
order, with the observed orders of convergence and the IK agreement matrix
(:mod:`comparisons.pipeline.session` runs scenes through them, wherever their cases execute).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterator

from simparity.comparisons.execute.cases import (
    DYNAMICS,
    IK,
    JOINT_DYNAMICS,
    JOINT_MOTION,
    KINEMATICS,
    STABILITY,
    CaseGroup,
    CaseOutcome,
    CaseSpec,
    EngineFor,
)
from simparity.comparisons.common.integrators import NO_INTEGRATOR
from simparity.comparisons.execute.ik_runner import failed_ik_outcome, ik_case, ik_scene_series, prepare_ik
from simparity.comparisons.measure.metrics import (
    KINEMATICS_METRICS,
    ORDER_METRICS,
    ORDER_SOURCES,
    ROTATIONAL_ORDERS,
    dynamics_metrics,
    observed_order,
)
from simparity.comparisons.measure.held_forcing import HELD_DETAIL, HELD_ORDER, HELD_PREFIX
from simparity.comparisons.measure.joint_dynamics_metrics import JOINT_DYNAMICS_METRICS
from simparity.comparisons.measure.joint_motion_metrics import (
    JOINT_MOTION_ORDERS, JOINT_ORDER_SOURCES, motion_metrics,
)
from simparity.comparisons.measure.rows import Case, Measured
from simparity.comparisons.measure.stability import STABILITY_METRICS
from simparity.comparisons.execute.motion_runner import motion_case, prepare_motion
from simparity.comparisons.execute.chain_runner import (
    joint_dynamics_case, kinematics_case, prepare_joint_dynamics, prepare_kinematics,
)
from simparity.comparisons.execute.dynamics_runner import dynamics_case, prepare_dynamics, prepare_stability, stability_case
from simparity.core.model.engine import TRUTH_SCHEMES
from simparity.core.model.results import FAILED, OK, ResultRow, SeriesRecord
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_motion import JointMotionScene

OnStart = Callable[[int | None], None]
"""Called before a group's shared part (None: the reference) and before each case (its index)."""

DEFAULT_REPEATS = 3
"""Timed repeats per measurement (the minimum is kept), after one warm-up run."""

@dataclass
class _Ladder:
    """The cases of one engine x integrator over the scene's time steps, for the order fits."""

    dts: list[float] = field(default_factory=list)
    cases: list[CaseOutcome] = field(default_factory=list)

    @property
    def integrates_rotation(self) -> bool:
        return all(case.integrates_rotation for case in self.cases)

    @property
    def scheme(self) -> str:
        """The kind of scheme the engine declared for the integrator (its cases' rows'; "" when they disagree)."""
        schemes = {row.scheme for case in self.cases for row in case.rows}
        return schemes.pop() if len(schemes) == 1 else ""

    @property
    def held(self) -> bool:
        """Whether a held load jumps inside the steps of its cases (:mod:`comparisons.measure.held_forcing`)."""
        return self.scheme.startswith(HELD_PREFIX)

    @property
    def theory(self) -> int | None:
        """The theoretical order the engine declares for the integrator (None unless its cases that say one agree),
        at most 1 where a held load jumps inside steps (:attr:`held`)."""
        orders = {case.theoretical_order for case in self.cases if case.theoretical_order is not None}
        order = orders.pop() if len(orders) == 1 else None
        return min(order, HELD_ORDER) if order is not None and self.held else order

    def detail(self, ref_label: str) -> str:
        """The order rows' detail: the reference, and the held load's order loss where there is one."""
        return f"against {ref_label}" + (f"; {HELD_DETAIL}" if self.held else "")


def _ignore_start(index: int | None) -> None:
    return None


@dataclass(frozen=True)
class _Kind:
    """How a kind of group runs: ``prepare(group, engine_for, reference_failure)`` computes what its cases share
    (the reference), ``case(group, shared, index, engine_for)`` one case's outcome."""

    prepare: Callable
    case: Callable


def prepare_group(group: CaseGroup, engine_for: EngineFor, reference_failure: str = "") -> object:
    """What the cases of ``group`` share (its reference trajectory, FK or targets), computed once.

    ``reference_failure``, when given, is why it is not to be computed again (it took its worker down): the
    cases run without it.
    """
    return _KINDS[group.kind].prepare(group, engine_for, reference_failure)


def run_case(group: CaseGroup, shared: object, index: int, engine_for: EngineFor) -> CaseOutcome:
    """The outcome of case ``index`` of ``group``, given what :func:`prepare_group` computed."""
    return _KINDS[group.kind].case(group, shared, index, engine_for)


def run_group(group: CaseGroup, engine_for: EngineFor, on_start: OnStart = _ignore_start,
              skip: frozenset[int] = frozenset(), reference_failure: str = "") -> Iterator[tuple[int, CaseOutcome]]:
    """(index, outcome) of every case of ``group`` but those in ``skip``, as each finishes, in this process."""
    on_start(None)
    shared = prepare_group(group, engine_for, reference_failure)
    for index in range(len(group.cases)):
        if index not in skip:
            on_start(index)
            yield index, run_case(group, shared, index, engine_for)



def _orders(scene: DynamicsScene, ladders: dict[tuple[str, str], _Ladder], ref_label: str) -> list[ResultRow]:
    """Observed orders of convergence per engine and integrator over the scene's time steps."""
    rows = []
    for (engine, integrator), ladder in ladders.items():
        case = Case(scene.name, engine, integrator, math.nan, ref_label, ladder.scheme)
        values = {}
        for metric, source in ORDER_SOURCES.items():
            if scene.contact is not None:
                values[metric] = Measured(math.nan, "1", unmeasurable=(
                    "contact: an impact timed a fraction of a step off makes the error jump with dt; the error "
                    "has no asymptotic order"))
                continue
            if metric in ROTATIONAL_ORDERS and not ladder.integrates_rotation:
                values[metric] = Measured(math.nan, "1", unmeasurable=(
                    "point-mass rule: the integrator does not move orientation, so it has no rotational order"))
                continue
            values[metric] = observed_order(ladder.dts, [c.errors.get(source, math.nan) for c in ladder.cases],
                                            [c.floors.get(source, 0.0) for c in ladder.cases],
                                            [c.saturation.get(source, 0.0) for c in ladder.cases], ladder.theory)
        rows += case.rows(ORDER_METRICS, OK, ladder.detail(ref_label), values)
    return rows


def _joint_orders(scene: JointMotionScene, ladders: dict[tuple[str, str], _Ladder], ref_label: str) -> list[ResultRow]:
    """Observed orders of convergence of the joint values and velocities per engine and integrator."""
    rows = []
    for (engine, integrator), ladder in ladders.items():
        case = Case(scene.name, engine, integrator, math.nan, ref_label, ladder.scheme)
        if ladder.scheme in TRUTH_SCHEMES:  # its error is set by a tolerance or by rounding, not by dt
            values = {metric: Measured(math.nan, "1", unmeasurable=(
                f"a truth ({ladder.scheme.replace('_', ' ')}) does not step at dt: its error has no order"))
                for metric in JOINT_ORDER_SOURCES}
        else:
            values = {metric: observed_order(ladder.dts, [c.errors.get(source, math.nan) for c in ladder.cases],
                                             [c.floors.get(source, 0.0) for c in ladder.cases],
                                             [c.saturation.get(source, 0.0) for c in ladder.cases], ladder.theory)
                      for metric, source in JOINT_ORDER_SOURCES.items()}
        rows += case.rows(JOINT_MOTION_ORDERS, OK, ladder.detail(ref_label), values)
    return rows


_KINDS = {DYNAMICS: _Kind(prepare_dynamics, dynamics_case), STABILITY: _Kind(prepare_stability, stability_case),
          KINEMATICS: _Kind(prepare_kinematics, kinematics_case), IK: _Kind(prepare_ik, ik_case),
          JOINT_DYNAMICS: _Kind(prepare_joint_dynamics, joint_dynamics_case),
          JOINT_MOTION: _Kind(prepare_motion, motion_case)}


def failed_outcome(group: CaseGroup, spec: CaseSpec, cause: str) -> CaseOutcome:
    """The outcome of a case that did not finish (its worker crashed, hung or ran out of memory):
    ``failed`` rows of every metric the case has, naming ``cause``."""
    if group.kind == IK:
        return failed_ik_outcome(group, spec, cause)
    scene = group.scene
    metrics = {DYNAMICS: lambda: dynamics_metrics(group.dynamics_scene), STABILITY: lambda: STABILITY_METRICS,
               KINEMATICS: lambda: KINEMATICS_METRICS, JOINT_DYNAMICS: lambda: JOINT_DYNAMICS_METRICS,
               JOINT_MOTION: lambda: motion_metrics(group.joint_motion_scene)}[group.kind]()
    case = Case(scene.name, spec.engine, spec.integrator, group.dt, group.reference_label)
    return CaseOutcome(case.rows(metrics, FAILED, cause), harness_failure=True)


def assemble_scene(scene, groups: list[CaseGroup],
                   outcomes: list[list[CaseOutcome]]) -> tuple[list[ResultRow], list[SeriesRecord]]:
    """A scene's rows and series in their stored order from every case's outcome (``outcomes[g][c]`` of
    case c of group g), with what needs them all: the observed orders of a dynamics scene (after the
    time steps' rows, before the stability limits), the FK agreement matrix of an IK scene."""
    ladders: dict[tuple[str, str], _Ladder] = {}
    for group, results in zip(groups, outcomes):
        for spec, outcome in zip(group.cases, results):
            if group.kind in (DYNAMICS, JOINT_MOTION) and spec.integrator != NO_INTEGRATOR:
                ladder = ladders.setdefault((spec.engine, spec.integrator), _Ladder())
                ladder.dts.append(group.dt)
                ladder.cases.append(outcome)
    rows = [row for group, results in zip(groups, outcomes) if group.kind != STABILITY
            for outcome in results for row in outcome.rows]
    if isinstance(scene, DynamicsScene) and len(scene.dts) > 1:
        rows += _orders(scene, ladders, groups[0].reference_label)
    if isinstance(scene, JointMotionScene) and len(scene.dts) > 1:
        rows += _joint_orders(scene, ladders, groups[0].reference_label)
    rows += [row for group, results in zip(groups, outcomes) if group.kind == STABILITY
             for outcome in results for row in outcome.rows]
    series = [record for results in outcomes for outcome in results for record in outcome.series]
    if isinstance(scene, IKScene):
        series += ik_scene_series(scene, [outcome for results in outcomes for outcome in results])
    return rows, series
