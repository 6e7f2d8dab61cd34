"""Runs an IK scene: every engine's solvers on the random and hard targets, cross-evaluated.

Per engine x solver (the ``integrator`` column holds the solver; ``dt`` is NaN):

- on the random targets, the metrics of :data:`IK_METRICS`; the time per solve is the
  batch's wall time over its size, failed solves included (TRAC-IK protocol);
- the solve rate twice: ``solve_rate`` at the scene's tolerances (the harness's verdict) and
  ``solve_rate_own_stop`` at the stopping rule the solver declares (:class:`StoppingRule`, the
  scene's tolerances unless it says otherwise; ``own_stop_position_tolerance`` its position
  threshold [m]): a library stopped by its own default threshold scores 0 at a tighter tolerance by
  construction, and the second rate says how well it meets the rule it was configured with;
- cross-evaluation: each solution is put through every engine's forward kinematics, so
  a solver cannot pass on its own engine's kinematics alone: ``cross_eval_solve_rate_min``
  is the lowest solve rate any engine's FK grants (each judge allows its own resolution on
  top of the tolerance: PyBullet's float32 link states cannot tell 1e-6 m apart), ``cross_eval_disagreement_max`` the
  largest distance between two engines' end-effector positions for the same solution;
- each hard target: the rows of :func:`hard_metrics`: ``hard_<name>`` the position residual
  (its detail says solved or the reason, with the orientation residual), and the typed verdicts
  the shipped tolerances hold hard cases to: ``hard_<name>_solved`` (1 or 0),
  ``hard_<name>_unreachable`` (1 when the solver reported the target unreachable) and
  ``hard_<name>_limit_violation`` (how far the returned joint values lie outside the limits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome, CaseSpec
from simparity.comparisons.execute.ik_targets import ORIENTATION_ONLY, Targets, hard_target, random_targets
from simparity.comparisons.measure.rows import Case, Measured, declared_scheme, warnings_into_rows
from simparity.comparisons.common.error_text import error_text
from simparity.comparisons.measure.series import disagreement_matrix, quantiles
from simparity.comparisons.execute.timing import best_of
from simparity.core.model.engine import Engine, IKModel, KinematicsModel, StoppingRule
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.ik_result import LIMIT_TOLERANCE, IKReason, IKResult
from simparity.core.model.results import (
    FAILED,
    HARD_VERDICT_SUFFIXES,
    NOT_AVAILABLE,
    OK,
    UNSOLVED,
    ResultRow,
    SeriesRecord,
)
from simparity.core.model.scenes.ik import IKScene
from simparity.references.common.conventions import rotation_angle
from simparity.core.model.metric_catalogue import (
    units,
    CROSS_EVAL_DISAGREEMENT_MAX, CROSS_EVAL_SOLVE_RATE_MIN, FK_DEPARTURE_MAX, ITERATIONS_MEDIAN,
    JACOBIAN_DEPARTURE_MAX, LIMIT_VIOLATIONS, ORIENTATION_RESIDUAL_MAX, ORIENTATION_RESIDUAL_MEDIAN,
    OWN_STOP_POSITION_TOLERANCE, POSITION_RESIDUAL_MAX, POSITION_RESIDUAL_MEDIAN, REST_DISTANCE_MEDIAN, SOLVE_RATE,
    SOLVE_RATE_OWN_STOP, START_RANK_DEFICIENCY, TIME_PER_SOLVE, UNCONFIRMED_CLAIMS,
)

IK_METRICS = units(
    SOLVE_RATE,
    SOLVE_RATE_OWN_STOP,
    OWN_STOP_POSITION_TOLERANCE,
    POSITION_RESIDUAL_MEDIAN,
    POSITION_RESIDUAL_MAX,
    ORIENTATION_RESIDUAL_MEDIAN,
    ORIENTATION_RESIDUAL_MAX,
    ITERATIONS_MEDIAN,
    TIME_PER_SOLVE,
    LIMIT_VIOLATIONS,
    REST_DISTANCE_MEDIAN,
    CROSS_EVAL_SOLVE_RATE_MIN,
    UNCONFIRMED_CLAIMS,
    FK_DEPARTURE_MAX,
    JACOBIAN_DEPARTURE_MAX,
    CROSS_EVAL_DISAGREEMENT_MAX,
    START_RANK_DEFICIENCY,
)

RANK_TOLERANCE = 1e-9
"""A singular value below this fraction of the largest one counts as zero when the rank of a
Jacobian is taken (relative, so it holds for arms of any size); rounding leaves ~1e-16. The largest one
never vanishes at one pose only, so rounding is never read as rank (issue #38): the joint nearest the tip
that moves the end effector at all keeps a constant lever to it (a prismatic joint's column is its unit axis,
a revolute joint's angular rows are), and that column's norm bounds the largest singular value from below."""


def _summary(result: IKResult, q_start: np.ndarray, seconds: float) -> dict[str, float]:
    iterations = result.iterations[result.iterations >= 0]
    return {
        SOLVE_RATE: result.solve_rate,
        POSITION_RESIDUAL_MEDIAN: float(np.median(result.position_residual)),
        POSITION_RESIDUAL_MAX: float(result.position_residual.max()),
        ORIENTATION_RESIDUAL_MEDIAN: float(np.median(result.orientation_residual)),
        ORIENTATION_RESIDUAL_MAX: float(result.orientation_residual.max()),
        ITERATIONS_MEDIAN: float(np.median(iterations)) if iterations.size else math.nan,
        TIME_PER_SOLVE: seconds / len(result.q),
        LIMIT_VIOLATIONS: float(np.count_nonzero(result.limit_violation > LIMIT_TOLERANCE)),
        REST_DISTANCE_MEDIAN: float(np.median(np.linalg.norm(result.q - q_start, axis=1))),
    }


def stopping_rule(model: IKModel, scene: IKScene) -> StoppingRule:
    """The rule ``model`` stops by: the one it declares, else the scene's tolerances."""
    return model.stopping_rule or StoppingRule(scene.position_tolerance, scene.orientation_tolerance,
                                               "the scene's tolerances")


def own_stop_rate(result: IKResult, rule: StoppingRule) -> float:
    """The share of targets solved by ``rule`` instead of the scene's tolerances: both residuals within the
    rule's thresholds and every joint within its limits (up to :data:`LIMIT_TOLERANCE`), as ``solve_rate``
    counts; 0 for an empty batch."""
    met = ((result.position_residual <= rule.position_tolerance)
           & (result.orientation_residual <= rule.orientation_tolerance)
           & (result.limit_violation <= LIMIT_TOLERANCE))
    return float(np.mean(met)) if met.size else 0.0


def _own_stop(result: IKResult, rule: StoppingRule) -> dict[str, Measured]:
    """``solve_rate_own_stop`` (n/a flagged ``unsolved`` at 0, like ``solve_rate``) and
    ``own_stop_position_tolerance``, each noting the rule and any known limitation of the solver."""
    said = f"own stopping rule: {rule.description}: {rule.criterion}" + (f"; {rule.note}" if rule.note else "")
    rate = own_stop_rate(result, rule)
    values = {OWN_STOP_POSITION_TOLERANCE: Measured(rule.position_tolerance, "m", note=said),
              SOLVE_RATE_OWN_STOP: Measured(rate, "1", note=said)}
    if rate == 0:
        values[SOLVE_RATE_OWN_STOP] = Measured(0.0, "1", flag=UNSOLVED, unmeasurable=(
            f"unsolved: none of the reachable targets meets the solver's {said} ({_median_residuals(result)})"))
    return values


def _cross_evaluation(scene: IKScene, targets: Targets, result: IKResult, judges: dict[str, KinematicsModel],
                      reference_end: np.ndarray | None) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """(the judges' verdicts on the solutions, each judge's end-effector positions (N, 3)).

    Each judge puts the solutions through its own FK; a solution outside the joint limits is solved by none.
    The verdicts: ``cross_eval_solve_rate_min``, the lowest solve rate a judge grants, over the judges whose FK
    agrees with the reference's (``reference_end``, (N, 3); None: every judge): a judge whose FK departs from the
    reference's by more than the position tolerance would grant or refuse solves on its own error, and blames
    every solver for it; ``unconfirmed_claims``, the share of targets the solver claims solved that no judge
    confirms; ``cross_eval_disagreement_max``, the spread of the judges' end-effector positions; and the
    departure of every judge's FK from the reference's (``departure:<judge>`` [m])."""
    q = result.q
    violation = np.maximum(np.maximum(scene.chain.lower - q, q - scene.chain.upper), 0.0)
    inside = np.max(violation, axis=1, initial=0.0) <= LIMIT_TOLERANCE
    rates, ends, out = [], {}, {}
    confirmed = np.zeros(len(q), bool)
    for name, model in judges.items():
        frames = model.forward_kinematics(q)
        end, rotation = frames.position_world[:, -1], frames.rotation_world[:, -1]
        position_resolution, orientation_resolution = model.resolution
        solved = inside & (np.linalg.norm(end - targets.position_world, axis=1)
                           <= scene.position_tolerance + position_resolution)
        if targets.rotation_world is not None:
            solved &= (rotation_angle(rotation, targets.rotation_world)
                       <= scene.orientation_tolerance + orientation_resolution)
        departure = 0.0 if reference_end is None else float(np.linalg.norm(end - reference_end, axis=1).max())
        out[f"departure:{name}"] = departure
        if departure <= scene.position_tolerance + position_resolution:
            rates.append(float(np.mean(solved)))
        confirmed |= solved
        ends[name] = end
    stacked = np.stack(list(ends.values()))
    spread = np.linalg.norm(stacked[:, None] - stacked[None, :], axis=-1).max() if len(ends) > 1 else 0.0
    out |= {CROSS_EVAL_SOLVE_RATE_MIN: min(rates) if rates else math.nan,
            UNCONFIRMED_CLAIMS: float(np.mean(np.asarray(result.success, bool) & ~confirmed)),
            CROSS_EVAL_DISAGREEMENT_MAX: float(spread)}
    return out, ends


def _task_jacobian(scene: IKScene, model: KinematicsModel, q: np.ndarray) -> np.ndarray:
    """(B, 3 or 6, n) end-effector Jacobians, position rows only for position targets."""
    jacobian = model.jacobian_world(q)
    return jacobian[:, :3] if scene.target_kind == "position" else jacobian


def _rank(jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(numerical ranks (B,), smallest over largest singular value (B,)) of (B, m, n) Jacobians."""
    sigma = np.linalg.svd(jacobian, compute_uv=False)
    top = np.maximum(sigma[:, :1], np.finfo(float).tiny)
    return np.sum(sigma > RANK_TOLERANCE * top, axis=1), sigma[:, -1] / top[:, 0]


def start_rank_deficiency(scene: IKScene, model: KinematicsModel) -> Measured:
    """How many task directions the chain cannot move in at the start pose that it can elsewhere.

    The rank of the end-effector Jacobian at ``q_start`` against its largest rank over the
    scene's sampled configurations; 0 is a regular start, more is a singular one.
    """
    generic, _ = _rank(_task_jacobian(scene, model, scene.configurations()))
    rank, ratio = _rank(_task_jacobian(scene, model, scene.q_start[None]))
    deficiency = int(generic.max() - rank[0])
    verdict = "singular" if deficiency > 0 else "regular"
    return Measured(float(deficiency), "1", note=(
        f"start pose {verdict}: Jacobian rank {rank[0]} of {generic.max()} elsewhere, "
        f"sigma_min/sigma_max {ratio[0]:.2g}"))


def _judges(scene: IKScene, engines: list[Engine]) -> dict[str, KinematicsModel]:
    judges = {}
    for engine in engines:
        try:
            if engine.supports_kinematics(scene.chain).ok:
                judges[engine.name] = engine.build_kinematics(scene.chain)
        except Exception:  # noqa: BLE001 - an engine that cannot build the chain judges nothing
            continue
    return judges


def hard_metrics(name: str) -> dict[str, str]:
    """The metrics of hard target ``name`` and their units: the position residual first, then the
    typed verdicts (solved, reported unreachable, limit violation)."""
    units = dict(zip(HARD_VERDICT_SUFFIXES, ("1", "1", "rad or m")))
    return {f"hard_{name}": "m"} | {f"hard_{name}{suffix}": unit for suffix, unit in units.items()}


def _hard_rows(case: Case, hard: list[Targets], results: Sequence[IKResult | None], status: str,
               problem: str) -> list[ResultRow]:
    """The rows of :func:`hard_metrics` per hard target (or why there are none)."""
    rows = []
    for targets, result in zip(hard, results):
        metrics = hard_metrics(targets.name)
        if result is None:
            rows += case.rows(metrics, status, problem)
            continue
        verdict = "solved" if result.success[0] else f"failed: {result.reason[0]}"
        detail = (f"{verdict}; orientation residual {result.orientation_residual[0]:.3g} rad; "
                  f"limit violation {result.limit_violation[0]:.3g}; {targets.note}")
        values = [float(result.position_residual[0]), float(result.success[0]),
                  float(result.reason[0] == IKReason.UNREACHABLE), float(result.limit_violation[0])]
        rows += case.rows(metrics, OK, detail, {m: Measured(v, u) for (m, u), v in zip(metrics.items(), values)})
    return rows


def _solve(model, targets: Targets, q_start: np.ndarray) -> IKResult:
    return model.solve(targets.position_world, targets.rotation_world, q_start)


def _solve_each(model, hard: list[Targets], q_start: np.ndarray) -> list[IKResult]:
    """Every hard target (one each) solved in one batch, then one result per target: a batch costs
    its slowest target's iterations once, instead of once per target."""
    if not hard:
        return []
    rotations = None if hard[0].rotation_world is None else np.concatenate([t.rotation_world for t in hard])
    batch = model.solve(np.concatenate([t.position_world for t in hard]), rotations, q_start)
    fields = ("q", "success", "iterations", "position_residual", "orientation_residual", "limit_violation", "reason")
    return [IKResult(**{f: getattr(batch, f)[i:i + 1] for f in fields}) for i in range(len(hard))]


def _distributions(case: Case, result: IKResult) -> list[SeriesRecord]:
    """Residuals and iterations over the random targets, as quantiles (failed solves included)."""
    iterations = result.iterations[result.iterations >= 0]
    return ([quantiles(case, "position_residual", "m", result.position_residual),
             quantiles(case, "orientation_residual", "rad", result.orientation_residual)]
            + ([quantiles(case, "iterations", "1", iterations)] if iterations.size else []))


@dataclass(frozen=True)
class _Solve:
    """A solver's answers: on the random targets (timed, ``seconds``), on each hard target, its model's
    detail and the rule it stops by; or, when it could not solve, ``status`` and ``problem`` say why."""

    result: IKResult | None = None
    hard: list[IKResult] = field(default_factory=list)
    seconds: float = math.nan
    detail: str = ""
    rule: StoppingRule | None = None
    status: str = OK
    problem: str = ""


def _solved(scene: IKScene, engine: Engine, solver: str, random: Targets, hard: list[Targets], repeats: int) -> _Solve:
    """``solver`` of ``engine`` on the targets, or why it cannot solve them."""
    try:
        support = engine.supports_ik(scene.chain, solver, scene.target_kind == "position")
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return _Solve(status=FAILED, problem=error_text(err))
    if not support.ok:
        return _Solve(status=NOT_AVAILABLE, problem=support.reason)
    try:
        model = engine.build_ik(scene.chain, solver, _options(scene))
        seconds, result = best_of(lambda: _solve(model, random, scene.q_start), repeats)
        return _Solve(result, _solve_each(model, hard, scene.q_start), seconds, model.detail,
                      stopping_rule(model, scene))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return _Solve(status=FAILED, problem=error_text(err))


def _case_outcome(scene: IKScene, engine: Engine, case: Case, solved: _Solve, random: Targets, hard: list[Targets],
                  judges: dict[str, KinematicsModel], reference: KinematicsModel | None) -> CaseOutcome:
    if solved.result is None:
        return CaseOutcome(case.rows(IK_METRICS, solved.status, solved.problem)
                           + _hard_rows(case, hard, [None] * len(hard), solved.status, solved.problem))
    values = {m: Measured(v, IK_METRICS[m]) for m, v in _summary(solved.result, scene.q_start, solved.seconds).items()}
    reference_end = None if reference is None else reference.forward_kinematics(solved.result.q).position_world[:, -1]
    agreement, ends = _cross_evaluation(scene, random, solved.result, judges, reference_end)
    values.update({m: Measured(v, IK_METRICS[m]) for m, v in agreement.items() if m in IK_METRICS})
    values.update(_unsolved(values, solved.result))
    if solved.rule is not None:
        values |= _own_stop(solved.result, solved.rule)
    values |= _own_kinematics(scene, engine, solved.result.q, agreement, judges.get(engine.name), reference)
    if engine.name in judges:
        values[START_RANK_DEFICIENCY] = start_rank_deficiency(scene, judges[engine.name])
    rows = (case.rows(IK_METRICS, OK, f"{solved.detail}; {random.note}", values)
            + _hard_rows(case, hard, solved.hard, OK, ""))
    return CaseOutcome(rows, _distributions(case, solved.result), ends=ends, reference_label=case.reference)


def _own_kinematics(scene: IKScene, engine: Engine, q: np.ndarray, agreement: dict[str, float],
                    own: KinematicsModel | None, reference: KinematicsModel | None) -> dict[str, Measured]:
    """How far the solver's own engine's FK and Jacobian are from the reference's at the solutions it found:
    ``fk_departure_max`` [m] (end effector) and ``jacobian_departure_max`` (largest entry of the end effector's
    world Jacobian), so that an IK scene checks the kinematics its solver stands on, and a wrong one is blamed on
    its engine."""
    if own is None or reference is None:
        why = (f"{engine.name} has no forward kinematics of this chain, or the reference {scene.reference} has none "
               "to compare with")
        return {m: Measured(math.nan, IK_METRICS[m], unmeasurable=why)
                for m in (FK_DEPARTURE_MAX, JACOBIAN_DEPARTURE_MAX)}
    where = f"against {scene.reference}'s, at its solutions"
    jacobian = float(np.abs(own.jacobian_world(q) - reference.jacobian_world(q)).max())
    return {FK_DEPARTURE_MAX: Measured(agreement[f"departure:{engine.name}"], "m", note=where),
            JACOBIAN_DEPARTURE_MAX: Measured(jacobian, IK_METRICS[JACOBIAN_DEPARTURE_MAX], note=where)}


def _unsolved(values: dict[str, Measured], result: IKResult) -> dict[str, Measured]:
    """The solve rates of ``values`` that are 0 on the reachable random targets, as n/a flagged ``unsolved``
    with the residuals the solver stopped at: a rate of 0 says which stopping rule or cap the solver does not
    meet, not how well it solves."""
    return {metric: Measured(0.0, "1", flag=UNSOLVED, unmeasurable=(
                f"unsolved: none of the reachable targets is solved within the tolerances "
                f"({_median_residuals(result)}); the solver stops before them, or never reaches them"))
            for metric in (SOLVE_RATE, CROSS_EVAL_SOLVE_RATE_MIN) if values[metric].value == 0}


def _median_residuals(result: IKResult) -> str:
    """``median residuals 0.0107 m, 0.00163 rad``: where an unsolved solver stopped."""
    return (f"median residuals {np.median(result.position_residual):.3g} m, "
            f"{np.median(result.orientation_residual):.3g} rad")


def _skipped(scene: IKScene) -> dict[str, str]:
    """The metrics of the hard targets a position-only scene has no orientation for."""
    return {m: u for name in scene.hard_targets if scene.target_kind == "position" and name in ORIENTATION_ONLY
            for m, u in hard_metrics(name).items()}


def _options(scene: IKScene) -> IKTolerances:
    return IKTolerances(position_tolerance=scene.position_tolerance, orientation_tolerance=scene.orientation_tolerance,
                        max_iterations=scene.max_iterations)


@dataclass(frozen=True)
class IKShared:
    """What the cases of an IK group share: the targets (None when the reference cannot make them) or
    (the status, the reason) of why there are none."""

    random: Targets | None
    hard: list[Targets]
    problem: tuple[str, str]


def prepare_ik(group: CaseGroup, engine_for: Callable[[str], Engine], reference_failure: str) -> IKShared:
    """The targets of an IK group, made with the reference engine's FK. ``reference_failure``: why they are
    not to be made again (it took the worker down)."""
    scene = group.ik_scene
    if reference_failure:
        return IKShared(None, [], (FAILED, _no_targets(scene, f"failed: {reference_failure}")))
    try:
        reference = engine_for(scene.reference)
        support = reference.supports_kinematics(scene.chain)
        if not support.ok:
            return IKShared(None, [], (NOT_AVAILABLE, _no_targets(scene, support.reason)))
        fk = reference.build_kinematics(scene.chain)
        random = random_targets(scene, fk)
        hard = [hard_target(scene, name, fk) for name in scene.hard_targets
                if not (scene.target_kind == "position" and name in ORIENTATION_ONLY)]
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return IKShared(None, [], (FAILED, _no_targets(scene, f"failed: {error_text(err)}")))
    return IKShared(random, hard, ("", ""))


def _no_targets(scene: IKScene, reason: str) -> str:
    return f"reference {scene.reference} cannot make the targets: {reason}"


def ik_case(group: CaseGroup, shared: IKShared, index: int, engine_for: Callable[[str], Engine]) -> CaseOutcome:
    """One engine x solver of an IK group on the shared targets; every engine of the run that can build the
    chain judges its solutions. The judges are built here, after the solve, so no other engine's code has run
    in this process before the solver's."""
    scene, spec = group.ik_scene, group.cases[index]
    if shared.random is None:
        status, problem = shared.problem
        case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label)
        return CaseOutcome(case.rows(IK_METRICS, status, problem))
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        engine = engine_for(spec.engine)
        solved = _solved(scene, engine, spec.integrator, shared.random, shared.hard, group.repeats)
        judges = _judges(scene, [engine_for(name) for name in group.engine_names])
        reference = judges.get(scene.reference) or _judges(scene, [engine_for(scene.reference)]).get(scene.reference)
        label = f"{scene.reference}:fk (targets); cross-evaluated by {', '.join(judges)}"
        case = Case(scene.name, spec.engine, spec.integrator, math.nan, label,
                    declared_scheme(engine, spec.integrator, scene))
        outcome = _case_outcome(scene, engine, case, solved, shared.random, shared.hard, judges, reference)
        rows += outcome.rows
    outcome.rows = rows + case.rows(_skipped(scene), NOT_AVAILABLE, "position-only scene: no orientation to target")
    outcome.reference_label = label
    return outcome


def failed_ik_outcome(group: CaseGroup, spec: CaseSpec, cause: str) -> CaseOutcome:
    """``failed`` rows of every metric of an IK case that did not finish (its worker crashed, hung or ran out
    of memory), naming ``cause``."""
    scene = group.ik_scene
    case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label)
    metrics = dict(IK_METRICS)
    for name in scene.hard_targets:
        metrics |= hard_metrics(name)
    return CaseOutcome(case.rows(metrics, FAILED, cause), harness_failure=True)


def ik_scene_series(scene: IKScene, outcomes: list[CaseOutcome]) -> list[SeriesRecord]:
    """The FK agreement matrix of an IK scene: every judge's end-effector positions over every case's solutions."""
    ends: dict[str, list[np.ndarray]] = {}
    for outcome in outcomes:
        for judge, end in outcome.ends.items():
            ends.setdefault(judge, []).append(end)
    label = next((o.reference_label for o in outcomes if o.reference_label), f"{scene.reference}:fk")
    return disagreement_matrix(Case(scene.name, "", "", math.nan, label),
                               {judge: np.concatenate(parts) for judge, parts in ends.items()})
