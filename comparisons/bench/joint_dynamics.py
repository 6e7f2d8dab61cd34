"""``simparity bench``'s joint-space dynamics: evaluations per second of M + h, RNEA and forward dynamics (ABA) on
the ``articulated`` suite's real arms, core batched over B states against each engine's fastest Python path, with
each one's largest relative difference to Pinocchio at the same states.

Engines answer one state per call through their adapters (Pinocchio's ``crba`` + ``nle``, ``rnea``, ``aba``;
MuJoCo's ``mj_fullM`` after ``mj_forward``, ``mj_inverse``, ``mj_forward``; PyBullet's ``calculateMassMatrix`` and
``calculateInverseDynamics``): their time per state is measured on at most :data:`ENGINE_STATES`. Pinocchio's batched
C++ API (``ModelPool`` with ``rneaInParallel`` / ``abaInParallel`` on ONE thread, the published fast path) is timed
at every B, as is MuJoCo's ``mujoco.rollout`` of one step from B states (its forward dynamics plus one Euler step).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from simparity.comparisons.bench.rows import Meter, by_batch
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes import library

ARMS = ("iiwa-dynamics", "ur5-dynamics", "panda-dynamics")
"""The ``articulated`` suite's real arms the bench times."""
ENGINES = (("core", "recursive"), ("core", "jacobian_sum"), ("pinocchio", "recursive"), ("mujoco", "recursive"),
           ("pybullet", "recursive"))
ENGINE_STATES = 1000
"""States an adapter that answers one per call is timed on (its time per state does not depend on B)."""
ERROR_STATES = 100
"""States of each batch (its first) compared with Pinocchio."""
SEED = 11
OPERATIONS = ("M+h", "rnea", "aba")
"""What is timed: the mass matrix and the bias forces; inverse dynamics; forward dynamics."""
ABA_OVER_POOL = 1.5
"""The issue's (#41) target: core's ABA at the largest B this many times as fast per state as Pinocchio's batched
API on one thread, on every arm (a ratio of two rows of the same run)."""
ABA_MISSED = (
    "measured on 2026-11-29 (cProfile at B = 10,000; core and the pool timed side by side in one process, 8 runs): "
    "core's ABA is NumPy over the batch, joint by joint: its own per-entry loops 30 %, carrying the articulated "
    "inertia to the parent 23 % (a 21 x 21 product of mostly zero entries), cos and sin 11 %, the rotations 10 %, the "
    "force cross products 8 %. Side by side it is 1.2-1.3x the pool on every arm, the three arms alike per joint; a "
    "row timed at another moment than the pool's reads anywhere from 0.6x to 1.7x. NumPy-only changes were estimated "
    "at 15-25 %, short of 1.5x: a compiled per-state kernel would close it.")


def _states(scene, count: int) -> tuple[np.ndarray, ...]:
    """``count`` seeded states of the scene's chain (q, qdot, qddot, tau), each (count, n)."""
    from dataclasses import replace

    return replace(scene, n_states=count, seed=SEED).states()


def _operations(model, states) -> dict[str, Callable[[], np.ndarray]]:
    q, qd, qdd, tau = states
    return {"M+h": lambda: np.concatenate([model.mass_matrix(q).reshape(len(q), -1), model.bias_forces(q, qd)], axis=1),
            "rnea": lambda: model.inverse_dynamics(q, qd, qdd),
            "aba": lambda: model.forward_dynamics(q, qd, tau)}


def _relative(values: np.ndarray, reference: np.ndarray) -> float:
    return float(np.max(np.abs(values - reference)) / np.max(np.abs(reference)))


def _pinocchio_batched(scene, states, median_time) -> dict[str, float]:
    """Seconds per state of Pinocchio's ModelPool + rneaInParallel / abaInParallel on one thread (continuous joints
    as (cos, sin))."""
    import pinocchio as pin

    from simparity.references.common.dynamics_urdf import dynamics_urdf

    model = pin.buildModelFromXML(dynamics_urdf(scene.chain))
    model.gravity.linear = np.zeros(3) if scene.gravity_world is None else np.asarray(scene.gravity_world)
    q, qd, qdd, tau = states
    if model.nq != model.nv or model.nv != scene.chain.n_joints:
        return {}  # a continuous joint (nq = 2) or a joint off the chain: the one-to-one mapping below does not hold
    damping = np.array([j.damping for j in scene.chain.joints])
    pool = pin.ModelPool(model, 1)
    # Pinocchio's algorithms have no damping: ABA gets tau - D qdot (RNEA's + D qdot would be one more vector add)
    columns = [np.asfortranarray(x.T) for x in (q, qd, qdd, tau - damping * qd)]
    out = np.zeros_like(columns[0], order="F")
    rnea = median_time(lambda: pin.rneaInParallel(1, pool, columns[0], columns[1], columns[2], out))
    aba = median_time(lambda: pin.abaInParallel(1, pool, columns[0], columns[1], columns[3], out))
    return {"rnea": rnea / len(q), "aba": aba / len(q)}


def joint_dynamics_rows(batches: list[int], median_time, row, say: Callable[[str], None]) -> list:
    """Bench rows (``row(section, workload, engine, method, batch, value, unit, accuracy, accuracy_unit, note)``) of
    every arm x engine x operation x batch, in us per state; ``median_time(fn)`` -> seconds."""
    rows = []
    for scene in library.load(list(ARMS)):
        judged = _states(scene, ERROR_STATES)
        judge = _operations(make_engine("pinocchio").build_joint_dynamics(scene.chain, "recursive",
                                                                          scene.gravity_world), judged)
        truth = {name: fn() for name, fn in judge.items()}
        for engine, method in ENGINES:
            try:
                model = make_engine(engine).build_joint_dynamics(scene.chain, method, scene.gravity_world)
            except Exception as err:  # noqa: BLE001 - an engine that cannot: its rows say why
                rows += [row("joint_dynamics", scene.name, engine, f"{method} {op}", b, math.nan, "us/state", math.nan,
                             "1", f"n/a: {err}") for op in OPERATIONS for b in batches]
                continue
            errors = {name: _relative(fn(), truth[name]) for name, fn in _operations(model, judged).items()}
            for batch in batches:
                count = batch if engine == "core" else min(batch, ENGINE_STATES)
                for name, fn in _operations(model, _states(scene, count)).items():
                    with Meter() as meter:
                        seconds = median_time(fn) / count
                    rows.append(meter.stamp(row("joint_dynamics", scene.name, engine, f"{method} {name}", batch,
                                                seconds * 1e6, "us/state", errors[name], "1",
                                                "vs pinocchio" if engine != "pinocchio" else "")))
                    say(f"  {scene.name:<15} {engine:<9} {method:<12} {name:<4} B={batch:<6} "
                        f"{seconds * 1e6:9.3f} us/state")
        for batch in batches:
            states = _states(scene, batch)
            with Meter() as meter:  # both operations' measurements: the load and CPU time of the pair
                batched = _pinocchio_batched(scene, states, median_time)
            for name, seconds in batched.items():
                rows.append(meter.stamp(row("joint_dynamics", scene.name, "pinocchio-pool", f"recursive {name}", batch,
                                            seconds * 1e6, "us/state", 0.0, "1", "ModelPool, 1 thread")))
                say(f"  {scene.name:<15} pinocchio-pool {name:<4} B={batch:<6} {seconds * 1e6:9.3f} us/state")
    return rows


def markdown_lines(rows: list) -> list[str]:
    """The BENCHMARKS.md section: a row per arm x engine x method, a column per batch size, and the difference."""
    mine = [r for r in rows if r.section == "joint_dynamics"]
    if not mine:
        return []
    batches = sorted({r.batch for r in mine})
    lines = ["## Joint-space dynamics (us per state; largest relative difference to Pinocchio at 100 states)", "",
             f"Adapters answer one state per call; their time per state is measured on at most {ENGINE_STATES:,}. "
             "`pinocchio-pool` is Pinocchio's batched C++ API (ModelPool + rneaInParallel / abaInParallel) on one "
             "thread.", "",
             "| arm | engine | method | " + " | ".join(f"B = {b:,}" for b in batches) + " | difference |",
             "|---|---|---|" + "---|" * (len(batches) + 1)]
    for (arm, engine, method), _, values, difference in by_batch(mine):
        lines.append(f"| {arm} | {engine} | {method} | {values} | {difference:.1e} |")
    return lines + [""]


def target_lines(rows: list) -> list[tuple[str, str, bool, tuple]]:
    """(target, compared, met, the two rows compared) of the issue's speed target: core at the largest B at least
    :data:`ABA_OVER_POOL` times as fast per forward dynamics as Pinocchio's batched API on one thread, per arm."""
    out = []
    mine = [r for r in rows if r.section == "joint_dynamics" and math.isfinite(r.value)]
    for arm in dict.fromkeys(r.workload for r in mine):
        big = max(r.batch for r in mine if r.workload == arm)
        core = next((r for r in mine if (r.workload, r.engine, r.method, r.batch) == (arm, "core", "recursive aba",
                                                                                        big)), None)
        pool = [r for r in mine if (r.workload, r.engine, r.method) == (arm, "pinocchio-pool", "recursive aba")]
        if core is None or not pool:
            continue
        best = min(pool, key=lambda r: r.value)
        out.append((f"{arm}: core ABA at the largest B at least {ABA_OVER_POOL:g}x as fast per state as Pinocchio's "
                    "ModelPool (1 thread)",
                    f"core at B = {big:,}: {core.value:.3g} us vs Pinocchio pool at B = {best.batch:,}: "
                    f"{best.value:.3g} us ({best.value / core.value:.2f}x)", best.value / core.value >= ABA_OVER_POOL,
                    (core, best)))
    return out
