"""Runs cases on engines and measures them against each scene's reference.

Every scene x engine x integrator x dt gets one row per metric: ``ok`` with a value, or
``n/a`` / ``failed`` / ``diverged`` with the reason in ``detail``. An engine that raises
becomes ``failed`` rows; the run goes on.

A scene is planned into groups of cases (:mod:`comparisons.execute.cases`); :func:`run_group` runs one
group wherever it is sent (this process, a worker process, a Dask worker), yielding each case's
outcome as it finishes; :func:`assemble_scene` puts a scene's outcomes together in its stored
order, with the observed orders of convergence and the IK agreement matrix
(:mod:`comparisons.execute.session` runs scenes through them, wherever their cases execute).
"""

from __future__ import annotations

import math
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Callable, Iterator, cast

import numpy as np

from simparity.comparisons.execute.cases import (
    DYNAMICS,
    IK,
    JOINT_DYNAMICS,
    JOINT_MOTION,
    KINEMATICS,
    NO_INTEGRATOR,
    STABILITY,
    CaseGroup,
    CaseOutcome,
    CaseSpec,
)
from simparity.comparisons.measure.contact_metrics import contact_blow_up, contact_metrics, read_contact
from simparity.comparisons.measure.divergence import blow_up_of
from simparity.comparisons.execute.ik_runner import failed_ik_outcome, ik_case, ik_scene_series, prepare_ik
from simparity.comparisons.measure.metrics import (
    KINEMATICS_METRICS,
    ORDER_METRICS,
    ORDER_SOURCES,
    ROTATIONAL_ORDERS,
    at_rounding_floor,
    drifts_of,
    dynamics_metrics,
    frame_validity,
    judged_errors,
    kinematics_errors,
    observed_order,
    rounding_floors_of,
    saturation_ratios,
    saturation_scales_of,
    state_validity,
)
from simparity.comparisons.measure.joint_dynamics_metrics import (
    JOINT_DYNAMICS_METRICS,
    REFERENCE_ERRORS,
    identities,
    reference_errors,
    reference_values,
    shape_problem,
    timed_values,
)
from simparity.comparisons.measure.joint_force_scale import ForceScale, force_scale
from simparity.comparisons.measure.joint_motion_metrics import (
    JOINT_MOTION_ORDERS, JOINT_ORDER_SOURCES, motion_metrics,
)
from simparity.comparisons.measure.rows import Case, Measured, declared_scheme, error_text, warnings_into_rows
from simparity.comparisons.measure.stability import STABILITY_METRICS, stable_dt_max
from simparity.comparisons.measure.streamed import (
    AlignedPieces, CaseReading, piece_problem, samples_per_piece,
)
from simparity.comparisons.execute.case_cost import case_cost, theory
from simparity.comparisons.execute.motion_runner import motion_case, prepare_motion
from simparity.comparisons.execute.timing import best_after, best_of
from simparity.core.model.engine import (
    TRUTH_SCHEMES, Engine, JointDynamicsModel, Simulation, Support, streams_in_pieces,
)
from simparity.core.model.errors import DivergedError, SimparityError
from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow, SeriesRecord
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.references.common.scene_inputs import as_given
from simparity.core.model.trajectory import Trajectory, joined, trajectory_pieces
from simparity.core.model.metric_catalogue import (
    STABLE_DT_MAX, TIME_PER_FK, TIME_PER_JACOBIAN, TIME_PER_STEP,
)

EngineFor = Callable[[str], Engine]
"""The engine of a name (the run's engines, the scene's reference)."""

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
    def theory(self) -> int | None:
        """The theoretical order the engine declares for the integrator (None unless its cases that say one agree)."""
        orders = {case.theoretical_order for case in self.cases if case.theoretical_order is not None}
        return orders.pop() if len(orders) == 1 else None


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


@dataclass(frozen=True)
class _ReferenceRun:
    """A dynamics group's reference run at the group's dt: its whole trajectory when it is short (computed once,
    shared by the group's cases), else its simulation, streamed again beside each case's run (memory flat in the
    steps; a closed form or a dense output costs little to stream again)."""

    whole: Trajectory | None
    simulation: Simulation | None

    def pieces(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        """The run's samples in pieces, each call from the start."""
        if self.whole is not None:
            return trajectory_pieces(self.whole, samples_per_piece)
        assert self.simulation is not None  # one of the two is set (_reference_run)
        return self.simulation.stream(n_steps, samples_per_piece)


@dataclass(frozen=True)
class _DynamicsShared:
    """What the cases of a dynamics group share: the reference, its run at the group's dt (None when there is
    none) and (why there is none, the status that gives)."""

    reference: str
    integrator: str
    run: _ReferenceRun | None
    problem: tuple[str, str]


def _prepare_dynamics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _DynamicsShared:
    scene = group.dynamics_scene
    reference = engine_for(scene.reference)
    integrator = reference.scene_integrators(scene)[0]
    run, problem = _reference_run(scene, reference, integrator, group.dt, group.reference_label, reference_failure)
    return _DynamicsShared(reference.name, integrator, run, problem)


def _dynamics_case_at(group: CaseGroup, shared: _DynamicsShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    scene, dt, spec = group.dynamics_scene, group.dt, group.cases[index]
    metrics = dynamics_metrics(scene)
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, dt, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    if spec.integrator == NO_INTEGRATOR:
        return CaseOutcome(_no_integrator_rows(scene, engine, case, metrics))
    rows: list[ResultRow] = []
    is_reference = (spec.engine, spec.integrator) == (shared.reference, shared.integrator)
    with warnings_into_rows(rows):
        outcome = _dynamics_case(scene, engine, case, metrics, scene.n_steps(dt), shared.run, shared.problem,
                                 group.repeats, is_reference)
        rows += outcome.rows
    outcome.rows = rows
    outcome.theoretical_order = theory(engine, spec.integrator)
    return outcome


def _no_integrator_rows(scene: DynamicsScene, engine: Engine, case: Case, metrics: dict) -> list[ResultRow]:
    """The rows of an engine that runs none of the scene's integrators: n/a with why (the engine's own refusal
    when it offers none, e.g. its library does not import), failed when it cannot even say."""
    try:
        offered = tuple(engine.scene_integrators(scene))
        if offered:
            reason = f"the scene runs only {', '.join(scene.integrators)}; {engine.name} offers {', '.join(offered)}"
        else:
            reason = engine.supports_dynamics(scene, NO_INTEGRATOR).reason or f"{engine.name} offers no integrator"
    except Exception as err:  # noqa: BLE001 - a user's engine failed to describe itself
        return case.rows(metrics, FAILED, error_text(err))
    return case.rows(metrics, NOT_AVAILABLE, reason)


SHORT_REFERENCE_PIECES = 4
"""A reference run of at most this many pieces (:func:`samples_per_piece`) is computed once and shared by its
group's cases; a longer one is streamed again beside each case (its memory would grow with the steps)."""


def _reference_run(scene: DynamicsScene, reference: Engine, integrator: str, dt: float, label: str,
                   reference_failure: str) -> tuple[_ReferenceRun | None, tuple[str, str]]:
    """(the reference's run at ``dt`` or None, (why there is none, the status that gives)); ``label`` names the
    reference in the reasons. A long run of a reference that streams (without contact, whose metrics read whole
    runs) is streamed with each case; its failure then shows in each case's rows, with the same reasons."""
    if reference_failure:
        return None, (f"reference {label} failed: {reference_failure}", FAILED)
    try:
        support = reference.supports_dynamics(scene, integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        support = Support.no(f"failed: {error_text(err)}")
    if not support.ok:
        return None, (f"reference {label} cannot do this scene: {support.reason}", NOT_AVAILABLE)
    n = scene.n_steps(dt)
    try:
        sim = reference.build_dynamics(scene, integrator, dt)
        if (scene.contact is None and streams_in_pieces(sim)
                and n + 1 > SHORT_REFERENCE_PIECES * samples_per_piece(scene)):
            return _ReferenceRun(None, sim), ("", NOT_AVAILABLE)
        with np.errstate(all="ignore"):
            traj = sim.run(n)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return None, (f"reference {label} failed: {error_text(err)}", FAILED)
    if not traj.is_finite():
        return None, (_reference_diverged(label), NOT_AVAILABLE)
    return _ReferenceRun(traj, None), ("", NOT_AVAILABLE)


def _reference_diverged(label: str) -> str:
    return f"reference {label} diverged (non-finite state)"


def _prepare_nothing(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> None:
    """The stability limits share nothing: each case bisects on its own."""
    return None


def _stability_case_at(group: CaseGroup, shared: None, index: int, engine_for: EngineFor) -> CaseOutcome:
    """The measured stability limit of one penalty-method integrator (:mod:`comparisons.measure.stability`)."""
    scene, spec = group.dynamics_scene, group.cases[index]
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        try:
            support = engine.supports_dynamics(scene, spec.integrator)
            if not support.ok:
                rows += case.rows(STABILITY_METRICS, NOT_AVAILABLE, support.reason)
            else:
                limit = stable_dt_max(scene, engine, spec.integrator)
                rows += case.rows(STABILITY_METRICS, OK, f"measured by bisection on {scene.name}",
                                  {STABLE_DT_MAX: limit})
        except Exception as err:  # noqa: BLE001 - reported in the rows
            rows += case.rows(STABILITY_METRICS, FAILED, error_text(err))
    return CaseOutcome(rows)


def _dynamics_case(scene, engine: Engine, case: Case, metrics: dict, n: int, ref: _ReferenceRun | None,
                   ref_problem: tuple[str, str], repeats: int, is_reference: bool) -> CaseOutcome:
    """One case; ``ref_problem`` is (why there is no reference run, the status that gives). The outcome's
    ``errors`` are the raw error values (saturated ones included), ``floors`` their rounding floors, for the order
    fits; both empty when nothing was measured.

    A run without contact of an engine that streams (``Simulation.stream``) is measured piece by piece as it is
    stepped (memory flat in the steps); a contact scene's (its impacts are read from whole runs) and an engine's
    that returns only whole trajectories are measured whole, the latter's detail saying its memory grows."""
    try:
        support = engine.supports_dynamics(scene, case.integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    if not support.ok:
        return CaseOutcome(case.rows(metrics, NOT_AVAILABLE, support.reason))
    try:
        sim = engine.build_dynamics(scene, case.integrator, case.dt)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    measured = as_given(scene)  # judged by the physics the references derive from the file's numbers, not core's
    if scene.contact is None and streams_in_pieces(sim):
        return _streamed_case(measured, engine, sim, case, metrics, n, ref, ref_problem, repeats, is_reference)
    return _whole_case(measured, engine, sim, case, metrics, n, ref, ref_problem, repeats, is_reference)


def _whole_case(scene: DynamicsScene, engine: Engine, sim: Simulation, case: Case, metrics: dict, n: int,
                ref: _ReferenceRun | None, ref_problem: tuple[str, str], repeats: int,
                is_reference: bool) -> CaseOutcome:
    """A case measured from the engine's whole trajectory (``Simulation.run``)."""
    try:
        with np.errstate(all="ignore"):  # a diverging run overflows; it is reported as diverged
            seconds, traj = best_of(lambda: sim.run(n), repeats)
            cost = case_cost(engine, sim, case, n, repeats)
    except DivergedError as err:
        return CaseOutcome(case.rows(metrics, DIVERGED, str(err)))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    grows = n + 1 > samples_per_piece(scene) and not streams_in_pieces(sim)
    detail = sim.detail + ("; its memory grew with the steps (the engine returns whole trajectories: "
                           "Simulation.stream steps in pieces)" if grows else "")
    try:
        problem = sampling_problem(scene, traj, n, case.dt)
        if problem:
            return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory does not sample the scene: {problem}"))
        ref_traj, ref_problem = _whole_reference(ref, n, case.reference, ref_problem)
        reading = CaseReading(scene, n, ref_traj is not None)
        with np.errstate(all="ignore"):
            reading.add(traj, ref_traj)
        return _measured_case(scene, sim, case, metrics, n, reading, {TIME_PER_STEP: Measured(seconds / n, "s")} | cost,
                              ref_problem, is_reference, detail, (traj, ref_traj))
    except Exception as err:  # noqa: BLE001 - a user's engine returned what cannot be measured
        return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory cannot be measured: {error_text(err)}"))


def _whole_reference(ref: _ReferenceRun | None, n: int, label: str,
                     ref_problem: tuple[str, str]) -> tuple[Trajectory | None, tuple[str, str]]:
    """(the reference's whole trajectory or None, why there is none): a streamed reference run whole for a case
    measured whole (whose memory grows with the steps anyway)."""
    if ref is None:
        return None, ref_problem
    try:
        with np.errstate(all="ignore"):
            traj = joined(ref.pieces(n, n + 1))
    except Exception as err:  # noqa: BLE001 - the reference's failure, reported in the rows
        return None, (f"reference {label} failed: {error_text(err)}", FAILED)
    if not traj.is_finite():
        return None, (_reference_diverged(label), NOT_AVAILABLE)
    return traj, ref_problem


def _streamed_case(scene: DynamicsScene, engine: Engine, sim: Simulation, case: Case, metrics: dict, n: int,
                   ref: _ReferenceRun | None, ref_problem: tuple[str, str], repeats: int,
                   is_reference: bool) -> CaseOutcome:
    """A case measured piece by piece as the engine steps (``Simulation.stream``), beside the reference's pieces;
    its time is the engine's alone (the measuring between pieces left out), best of the measured run and
    ``repeats`` runs drained unmeasured (as :func:`best_of`)."""
    size = samples_per_piece(scene)
    reading = CaseReading(scene, n, ref is not None)
    reference = None if ref is None else AlignedPieces(ref.pieces(n, size))
    pieces, stepping = sim.stream(n, size), 0.0
    with np.errstate(all="ignore"):  # a diverging run overflows; it is reported as diverged
        while True:
            try:
                start = time.perf_counter()
                piece = next(pieces, None)
                stepping += time.perf_counter() - start
            except DivergedError as err:
                return CaseOutcome(case.rows(metrics, DIVERGED, str(err)))
            except Exception as err:  # noqa: BLE001 - reported in the rows
                return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
            if piece is None:
                break
            problem = piece_problem(scene, piece, reading.samples, n, case.dt)
            if problem:
                return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory does not sample the scene: {problem}"))
            ref_piece = None
            if reference is not None:
                try:
                    ref_piece = reference.take(len(piece.times))
                except Exception as err:  # noqa: BLE001 - the reference's failure, reported in the rows
                    ref_problem, reference = (f"reference {case.reference} failed: {error_text(err)}", FAILED), None
                    reading.stop_comparing()
            try:
                reading.add(piece, ref_piece)
            except Exception as err:  # noqa: BLE001 - a user's engine yielded what cannot be measured
                return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory cannot be measured: {error_text(err)}"))
        if reading.samples != n + 1:
            return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory does not sample the scene: it has "
                                         f"{reading.samples} samples (expected {n + 1}: the initial state and {n} steps)"))
        try:
            seconds = best_after(stepping, lambda: deque(sim.stream(n, size), maxlen=0), repeats)
            cost = case_cost(engine, sim, case, n, repeats)
        except DivergedError as err:
            return CaseOutcome(case.rows(metrics, DIVERGED, str(err)))
        except Exception as err:  # noqa: BLE001 - reported in the rows
            return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    if not reading.reference_finite:
        ref_problem = (_reference_diverged(case.reference), NOT_AVAILABLE)
        reading.stop_comparing()
    try:
        return _measured_case(scene, sim, case, metrics, n, reading, {TIME_PER_STEP: Measured(seconds / n, "s")} | cost,
                              ref_problem, is_reference, sim.detail, None)
    except Exception as err:  # noqa: BLE001 - a user's engine returned what cannot be measured
        return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory cannot be measured: {error_text(err)}"))


def sampling_problem(scene: DynamicsScene, traj, n: int, dt: float) -> str:
    """What is wrong with ``traj`` as the samples of ``n`` steps of ``dt`` of ``scene`` ("" when nothing): a
    Trajectory of n + 1 samples of every body, at times k * dt (:func:`piece_problem`)."""
    if not isinstance(traj, Trajectory):
        return f"run() returned a value of type {type(traj).__name__} (allowed: a simparity.core.trajectory.Trajectory)"
    times = np.asarray(traj.times)
    if times.shape != (n + 1,):
        return f"its times have shape {times.shape} (expected ({n + 1},): the initial state and {n} steps)"
    return piece_problem(scene, traj, 0, n, dt)


def _measured_case(scene: DynamicsScene, sim: Simulation, case: Case, metrics: dict, n: int, reading: CaseReading,
                   timed: dict[str, Measured], ref_problem: tuple[str, str], is_reference: bool, detail: str,
                   whole: tuple[Trajectory, Trajectory | None] | None) -> CaseOutcome:
    """The rows of a case whose simulation ran, from what ``reading`` read of its run and its reference's (compared
    unless ``ref_problem`` says why not); ``timed``: its time and cost, measured as it ran; ``whole``: the run's and
    the reference's whole trajectories, for a contact scene's impacts (None: read in pieces)."""
    values = dict(timed)
    run = reading.run
    assert run is not None  # a run has at least its initial sample (checked by the callers)
    with np.errstate(all="ignore"):
        blown = blow_up_of(scene, run)
        contact = None
        if not blown and scene.contact is not None and whole is not None:
            contact = read_contact(scene, whole[0])
            blown = contact_blow_up(scene, contact)
        if blown:
            return CaseOutcome(case.rows(metrics, DIVERGED, f"{blown}; {detail}", values),
                               integrates_rotation=sim.integrates_rotation)
        values.update(drifts_of(scene, run) | state_validity(run))
        heights = None if contact is None else contact.distance[:, 0].min(axis=-1)
        series = reading.series.records(case, run, heights, None if whole is None else np.asarray(whole[0].times))
        floors = rounding_floors_of(scene, run, n)
        ref_traj = None if whole is None else whole[1]
        if reading.errors is None or reading.reference is None:
            if contact is not None and whole is not None:
                values.update(contact_metrics(scene, whole[0], None, contact))
            problem, status = ref_problem
            return CaseOutcome(case.partial_rows(metrics, values, detail, status, problem), series, floors=floors,
                               integrates_rotation=sim.integrates_rotation)
        scales = saturation_scales_of(scene, reading.reference)
        values.update(at_rounding_floor(judged_errors(reading.errors, scales), floors))
        saturation = saturation_ratios(reading.errors, scales)
        if contact is not None and whole is not None:
            values.update(contact_metrics(scene, whole[0], ref_traj, contact))
    detail = ("this is the reference; " if is_reference else "") + detail
    return CaseOutcome(case.rows(metrics, OK, detail, values), series, {m: v.value for m, v in values.items()},
                       floors, sim.integrates_rotation, saturation=saturation)


@dataclass(frozen=True)
class _KinematicsShared:
    """The configurations of a kinematics group, the reference's (poses, Jacobians) there (None when there
    are none) and (why there are none, the status that gives)."""

    q: np.ndarray
    reference: tuple | None
    problem: tuple[str, str]


def _reference_values(label: str, reference_failure: str, supports: Callable[[], Support],
                      evaluate: Callable[[], object]) -> tuple[object | None, tuple[str, str]]:
    """(the reference's values at a chain group's samples, ("", n/a)), or (None, (why there are none, the status
    that gives)): its worker failed, it cannot do the chain (``supports``), or ``evaluate`` raised."""
    if reference_failure:
        return None, (f"reference {label} failed: {reference_failure}", FAILED)
    try:
        support = supports()
        if not support.ok:
            return None, (f"reference {label} cannot do this chain: {support.reason}", NOT_AVAILABLE)
        return evaluate(), ("", NOT_AVAILABLE)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return None, (f"reference {label} failed: {error_text(err)}", FAILED)


def _prepare_kinematics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _KinematicsShared:
    scene = group.kinematics_scene
    q = scene.configurations()

    def evaluate() -> tuple:
        model = engine_for(scene.reference).build_kinematics(scene.chain)
        return model.forward_kinematics(q), model.jacobian_world(q)

    values, problem = _reference_values(group.reference_label, reference_failure,
                                        lambda: engine_for(scene.reference).supports_kinematics(scene.chain), evaluate)
    return _KinematicsShared(q, cast(tuple | None, values), problem)


def _kinematics_case_at(group: CaseGroup, shared: _KinematicsShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    scene, spec = group.kinematics_scene, group.cases[index]
    case = Case(scene.name, spec.engine, "", math.nan, group.reference_label)
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        rows += _kinematics_case(scene, engine_for(spec.engine), case, shared.q, shared.reference, shared.problem,
                                 group.repeats, spec.engine == scene.reference)
    return CaseOutcome(rows)


def _kinematics_case(scene: KinematicsScene, engine: Engine, case: Case, q: np.ndarray, ref, ref_problem: tuple[str, str],
                     repeats: int, is_reference: bool) -> list[ResultRow]:
    """Rows of one engine's FK and Jacobian at configurations ``q`` against ``ref`` = (poses, Jacobians) or None."""
    try:
        support = engine.supports_kinematics(scene.chain)
        if not support.ok:
            return case.rows(KINEMATICS_METRICS, NOT_AVAILABLE, support.reason)
        model = engine.build_kinematics(scene.chain)
        fk_seconds, poses = best_of(lambda: model.forward_kinematics(q), repeats)
        jac_seconds, jac = best_of(lambda: model.jacobian_world(q), repeats)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(KINEMATICS_METRICS, FAILED, error_text(err))
    values = {TIME_PER_FK: Measured(fk_seconds / len(q), "s"), TIME_PER_JACOBIAN: Measured(jac_seconds / len(q), "s")}
    values.update(frame_validity(poses))
    if not (np.all(np.isfinite(poses.position_world)) and np.all(np.isfinite(jac))):
        return case.rows(KINEMATICS_METRICS, DIVERGED, "non-finite FK or Jacobian", values)
    if ref is None:
        problem, status = ref_problem
        return case.partial_rows(KINEMATICS_METRICS, values, model.detail, status, problem)
    values.update(kinematics_errors(poses, jac, *ref))
    return case.rows(KINEMATICS_METRICS, OK, ("this is the reference; " if is_reference else "") + model.detail, values)


@dataclass(frozen=True)
class _JointDynamicsShared:
    """The states of a joint-dynamics group, the reference's values there and its force scale (None when there are
    none) and (why there are none, the status that gives)."""

    states: tuple[np.ndarray, ...]
    reference: dict | None
    problem: tuple[str, str]
    scale: ForceScale | None = None


def _prepare_joint_dynamics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _JointDynamicsShared:
    scene, label = group.joint_dynamics_scene, group.reference_label
    states, method = scene.states(), label.split(":", 1)[1]

    def evaluate() -> tuple[dict, ForceScale]:
        model = engine_for(scene.reference).build_joint_dynamics(scene.chain, method, scene.gravity_world)
        values = reference_values(model, states)
        problem = shape_problem(values, len(states[0]), scene.chain.n_joints)
        if problem:
            raise SimparityError(f"unusable: {problem}")
        return values, _force_scale(scene, engine_for(scene.reference), method, model, states, values)

    evaluated, problem = _reference_values(label, reference_failure,
                                           lambda: engine_for(scene.reference).supports_joint_dynamics(scene.chain,
                                                                                                      method), evaluate)
    if evaluated is None:
        return _JointDynamicsShared(states, None, problem)
    values, scale = cast(tuple[dict, ForceScale], evaluated)
    return _JointDynamicsShared(states, values, problem, scale)


def _force_scale(scene: JointDynamicsScene, engine: Engine, method: str, model: JointDynamicsModel,
                 states: tuple[np.ndarray, ...], values: dict) -> ForceScale:
    """The chain's force scale by ``engine``'s ``model`` (method ``method``) and its ``values`` at ``states``."""
    return force_scale(model, lambda gravity: engine.build_joint_dynamics(scene.chain, method, gravity),
                       scene.gravity_world, states, values)


def _joint_dynamics_case_at(group: CaseGroup, shared: _JointDynamicsShared, index: int,
                            engine_for: EngineFor) -> CaseOutcome:
    scene, spec = group.joint_dynamics_scene, group.cases[index]
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        rows += _joint_dynamics_case(scene, engine, case, shared, group.repeats,
                                     f"{spec.engine}:{spec.integrator}" == group.reference_label)
    return CaseOutcome(rows)


def _joint_dynamics_case(scene: JointDynamicsScene, engine: Engine, case: Case, shared: _JointDynamicsShared,
                         repeats: int, is_reference: bool) -> list[ResultRow]:
    """Rows of one engine's joint-space dynamics at the scene's states: errors against the reference's values,
    the identities of its own, its times."""
    try:
        support = engine.supports_joint_dynamics(scene.chain, case.integrator)
        if not support.ok:
            return case.rows(JOINT_DYNAMICS_METRICS, NOT_AVAILABLE, support.reason)
        model = engine.build_joint_dynamics(scene.chain, case.integrator, scene.gravity_world)
        own, values = timed_values(model, shared.states, lambda fn: best_of(fn, repeats))
        problem = shape_problem(own, len(shared.states[0]), scene.chain.n_joints)
        if problem:
            status = DIVERGED if problem.startswith("non-finite") else FAILED
            return case.rows(JOINT_DYNAMICS_METRICS, status, problem, values)
        scale = (shared.scale if shared.scale is not None  # else its own: identities need no reference
                 else _force_scale(scene, engine, case.integrator, model, shared.states, own))
        values.update(identities(model, scene.chain, shared.states, own, scale))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(JOINT_DYNAMICS_METRICS, FAILED, error_text(err))
    detail = ("this is the reference; " if is_reference else "") + model.detail
    if shared.reference is None:
        problem, status = shared.problem
        order = list(JOINT_DYNAMICS_METRICS)
        return sorted(case.partial_rows({m: u for m, u in JOINT_DYNAMICS_METRICS.items() if m not in REFERENCE_ERRORS},
                                        values, detail, status, problem)
                      + case.rows({m: JOINT_DYNAMICS_METRICS[m] for m in REFERENCE_ERRORS}, status, problem),
                      key=lambda row: order.index(row.metric))
    values.update(reference_errors(own, shared.reference, scale))
    return case.rows(JOINT_DYNAMICS_METRICS, OK, detail, {m: values[m] for m in JOINT_DYNAMICS_METRICS})


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
        rows += case.rows(ORDER_METRICS, OK, f"against {ref_label}", values)
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
        rows += case.rows(JOINT_MOTION_ORDERS, OK, f"against {ref_label}", values)
    return rows


_KINDS = {DYNAMICS: _Kind(_prepare_dynamics, _dynamics_case_at), STABILITY: _Kind(_prepare_nothing, _stability_case_at),
          KINEMATICS: _Kind(_prepare_kinematics, _kinematics_case_at), IK: _Kind(prepare_ik, ik_case),
          JOINT_DYNAMICS: _Kind(_prepare_joint_dynamics, _joint_dynamics_case_at),
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
