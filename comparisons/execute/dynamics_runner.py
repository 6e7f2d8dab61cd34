"""A dynamics group's cases: each engine's run at the group's dt measured against the reference's run, and the
penalty method's measured stability limit.

Without contact a run is measured piece by piece as the engine steps it (:mod:`comparisons.measure.streamed`: memory
flat in the steps), a long reference run streamed again beside each case; a contact scene's runs are measured whole
(its impacts are read from whole runs). :mod:`comparisons.execute.runner` dispatches groups here.
"""

from __future__ import annotations

import math
import time
from collections import deque
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from simparity.comparisons.common.integrators import NO_INTEGRATOR
from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome, EngineFor
from simparity.comparisons.measure.contact_metrics import contact_blow_up, contact_metrics, read_contact
from simparity.comparisons.measure.divergence import blow_up_of
from simparity.comparisons.measure.metrics import (
    at_rounding_floor,
    drifts_of,
    dynamics_metrics,
    judged_errors,
    rounding_floors_of,
    saturation_ratios,
    saturation_scales_of,
    state_validity,
)
from simparity.comparisons.measure.held_forcing import forcing_scheme
from simparity.comparisons.measure.rows import Case, Measured, declared_scheme, warnings_into_rows
from simparity.comparisons.common.error_text import error_text
from simparity.comparisons.measure.stability import STABILITY_METRICS, stable_dt_max
from simparity.comparisons.measure.streamed import (
    AlignedPieces, CaseReading, piece_problem, samples_per_piece,
)
from simparity.comparisons.execute.case_cost import case_cost, theory
from simparity.comparisons.execute.timing import best_after, best_of
from simparity.core.model.engine import Engine, Simulation, Support, streams_in_pieces
from simparity.core.model.errors import DivergedError
from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.references.common.scene_inputs import as_given
from simparity.core.model.trajectory import Trajectory, joined, trajectory_pieces
from simparity.core.model.metric_catalogue import STABLE_DT_MAX, TIME_PER_STEP


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


def prepare_dynamics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _DynamicsShared:
    scene = group.dynamics_scene
    reference = engine_for(scene.reference)
    integrator = reference.scene_integrators(scene)[0]
    run, problem = _reference_run(scene, reference, integrator, group.dt, group.reference_label, reference_failure)
    return _DynamicsShared(reference.name, integrator, run, problem)


def dynamics_case(group: CaseGroup, shared: _DynamicsShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    scene, dt, spec = group.dynamics_scene, group.dt, group.cases[index]
    metrics = dynamics_metrics(scene)
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, dt, group.reference_label,
                forcing_scheme(declared_scheme(engine, spec.integrator, scene), scene))
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


def prepare_stability(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> None:
    """The stability limits share nothing: each case bisects on its own."""
    return None


def stability_case(group: CaseGroup, shared: None, index: int, engine_for: EngineFor) -> CaseOutcome:
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
