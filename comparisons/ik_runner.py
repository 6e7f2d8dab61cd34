"""Runs an IK scene: every engine's solvers on the random and hard targets, cross-evaluated.

Per engine x solver (the ``integrator`` column holds the solver; ``dt`` is NaN):

- on the random targets, the metrics of :data:`IK_METRICS`; the time per solve is the
  batch's wall time over its size, failed solves included (TRAC-IK protocol);
- cross-evaluation: each solution is put through every engine's forward kinematics, so
  a solver cannot pass on its own engine's kinematics alone: ``cross_eval_solve_rate_min``
  is the lowest solve rate any engine's FK grants (each judge allows its own resolution on
  top of the tolerance: PyBullet's float32 link states cannot tell 1e-6 m apart), ``cross_eval_disagreement_max`` the
  largest distance between two engines' end-effector positions for the same solution;
- each hard target: one row ``hard_<name>`` whose value is the position residual and
  whose detail says solved or the reason, with the orientation residual.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from simparity.comparisons.ik_targets import ORIENTATION_ONLY, Targets, hard_target, random_targets
from simparity.comparisons.rows import Case, error_text
from simparity.comparisons.timing import best_of
from simparity.core.engine import Engine, KinematicsModel
from simparity.core.ik.problem import IKTolerances
from simparity.core.ik.result import IKResult
from simparity.core.results import FAILED, NOT_AVAILABLE, OK, ResultRow
from simparity.core.rotations import geodesic_angle_matrix
from simparity.core.scene import IKScene

IK_METRICS = {
    "solve_rate": "1",
    "position_residual_median": "m",
    "position_residual_max": "m",
    "orientation_residual_median": "rad",
    "orientation_residual_max": "rad",
    "iterations_median": "1",
    "time_per_solve": "s",
    "limit_violations": "1",
    "rest_distance_median": "rad or m",
    "cross_eval_solve_rate_min": "1",
    "cross_eval_disagreement_max": "m",
}


def _summary(result: IKResult, q_start: np.ndarray, seconds: float) -> dict[str, float]:
    iterations = result.iterations[result.iterations >= 0]
    return {
        "solve_rate": result.solve_rate,
        "position_residual_median": float(np.median(result.position_residual)),
        "position_residual_max": float(result.position_residual.max()),
        "orientation_residual_median": float(np.median(result.orientation_residual)),
        "orientation_residual_max": float(result.orientation_residual.max()),
        "iterations_median": float(np.median(iterations)) if iterations.size else math.nan,
        "time_per_solve": seconds / len(result.q),
        "limit_violations": float(np.count_nonzero(result.limit_violation > 0)),
        "rest_distance_median": float(np.median(np.linalg.norm(result.q - q_start, axis=1))),
    }


def _cross_evaluation(scene: IKScene, targets: Targets, q: np.ndarray,
                      judges: dict[str, KinematicsModel]) -> dict[str, float]:
    """Solve rate by each judge's FK (lowest kept) and the spread of their end-effector positions."""
    rates, ends = [], []
    for model in judges.values():
        frames = model.forward_kinematics(q)
        end, rotation = frames.position_world[:, -1], frames.rotation_world[:, -1]
        position_resolution, orientation_resolution = model.resolution
        solved = (np.linalg.norm(end - targets.position_world, axis=1)
                  <= scene.position_tolerance + position_resolution)
        if targets.rotation_world is not None:
            solved &= (geodesic_angle_matrix(rotation, targets.rotation_world)
                       <= scene.orientation_tolerance + orientation_resolution)
        rates.append(float(np.mean(solved)))
        ends.append(end)
    ends = np.stack(ends)
    spread = np.linalg.norm(ends[:, None] - ends[None, :], axis=-1).max() if len(ends) > 1 else 0.0
    return {"cross_eval_solve_rate_min": min(rates), "cross_eval_disagreement_max": float(spread)}


def _judges(scene: IKScene, engines: list[Engine]) -> dict[str, KinematicsModel]:
    judges = {}
    for engine in engines:
        if engine.supports_kinematics(scene.chain).ok:
            try:
                judges[engine.name] = engine.build_kinematics(scene.chain)
            except Exception:  # noqa: BLE001 - an engine that cannot build the chain judges nothing
                continue
    return judges


def _hard_rows(case: Case, hard: list[Targets], results: list[IKResult | None], status: str,
               problem: str) -> list[ResultRow]:
    """One row per hard target: the position residual, and solved or the reason (or why there is none)."""
    rows = []
    for targets, result in zip(hard, results):
        metric = {f"hard_{targets.name}": "m"}
        if result is None:
            rows += case.rows(metric, status, problem)
            continue
        verdict = "solved" if result.success[0] else f"failed: {result.reason[0]}"
        detail = (f"{verdict}; orientation residual {result.orientation_residual[0]:.3g} rad; "
                  f"limit violation {result.limit_violation[0]:.3g}; {targets.note}")
        rows += case.rows(metric, OK, detail, {f"hard_{targets.name}": (float(result.position_residual[0]), "m")})
    return rows


def _solve(model, targets: Targets, q_start: np.ndarray) -> IKResult:
    return model.solve(targets.position_world, targets.rotation_world, q_start)


def _case_rows(scene: IKScene, engine: Engine, case: Case, options: IKTolerances, random: Targets,
               hard: list[Targets], judges: dict[str, KinematicsModel], repeats: int) -> list[ResultRow]:
    support = engine.supports_ik(scene.chain, case.integrator, scene.target_kind == "position")
    if not support.ok:
        return (case.rows(IK_METRICS, NOT_AVAILABLE, support.reason)
                + _hard_rows(case, hard, [None] * len(hard), NOT_AVAILABLE, support.reason))
    try:
        model = engine.build_ik(scene.chain, case.integrator, options)
        seconds, result = best_of(lambda: _solve(model, random, scene.q_start), repeats)
        hard_results = [_solve(model, targets, scene.q_start) for targets in hard]
    except Exception as err:  # noqa: BLE001 - reported in the rows
        problem = error_text(err)
        return case.rows(IK_METRICS, FAILED, problem) + _hard_rows(case, hard, [None] * len(hard), FAILED, problem)
    values = _summary(result, scene.q_start, seconds)
    values.update(_cross_evaluation(scene, random, result.q, judges))
    return (case.rows(IK_METRICS, OK, f"{model.detail}; {random.note}", {m: (v, IK_METRICS[m]) for m, v in values.items()})
            + _hard_rows(case, hard, hard_results, OK, ""))


def run_ik_scene(scene: IKScene, engines: list[Engine], make_reference: Callable[[str], Engine],
                 repeats: int) -> list[ResultRow]:
    """All rows of an IK scene; the reference engine's FK generates the targets."""
    options = IKTolerances(position_tolerance=scene.position_tolerance, orientation_tolerance=scene.orientation_tolerance,
                        max_iterations=scene.max_iterations)
    reference = make_reference(scene.reference)
    support = reference.supports_kinematics(scene.chain)
    fk, status, reason = None, NOT_AVAILABLE, support.reason
    if support.ok:
        try:
            fk = reference.build_kinematics(scene.chain)
        except Exception as err:  # noqa: BLE001 - reported in the rows
            status, reason = FAILED, f"failed: {error_text(err)}"
    if fk is None:
        problem = f"reference {scene.reference} cannot make the targets: {reason}"
        return [row for engine in engines for solver in engine.ik_solvers() or ("-",)
                for row in Case(scene.name, engine.name, solver, math.nan, f"{scene.reference}:fk").rows(
                    IK_METRICS, status, problem)]
    position_only = scene.target_kind == "position"
    random = random_targets(scene, fk)
    hard = [hard_target(scene, name, fk) for name in scene.hard_targets
            if not (position_only and name in ORIENTATION_ONLY)]
    skipped = {f"hard_{name}": "m" for name in scene.hard_targets if position_only and name in ORIENTATION_ONLY}
    judges = _judges(scene, engines)
    label = f"{scene.reference}:fk (targets); cross-evaluated by {', '.join(judges)}"
    rows: list[ResultRow] = []
    for engine in engines:
        for solver in engine.ik_solvers() or ("-",):
            case = Case(scene.name, engine.name, solver, math.nan, label)
            rows += _case_rows(scene, engine, case, options, random, hard, judges, repeats)
            rows += case.rows(skipped, NOT_AVAILABLE, "position-only scene: no orientation to target")
    return rows
