"""The bench's rigid-body stepping: B identical boxes (torque-free tumbling; falling with drag), time per body-step
of each engine's ``run`` (recording every step included), next to the error each reaches at that dt against the
tight reference (DOP853 at 1e-13, on the first :data:`ERROR_BODIES` bodies over :data:`ERROR_STEPS` steps: bodies
are independent, so the error does not depend on B)."""

from __future__ import annotations

import math
import os
from collections.abc import Callable

import numpy as np

from simparity.comparisons.bench.rows import REPEATS, BenchRow, Meter, median_time
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.metrics import trajectory_errors
from simparity.core.model.metric_catalogue import ORIENTATION_ERROR_MAX, POSITION_ERROR_MAX
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix
from simparity.references.mujoco.adapter import BatchRollout

ERROR_BODIES = 4
"""Bodies whose trajectories are compared with the tight reference."""
ERROR_STEPS = 1000
"""Steps over which the error is measured (1 s at dt = 1e-3)."""
ERROR_METRIC = {"tumbling": ORIENTATION_ERROR_MAX, "falling-drag": POSITION_ERROR_MAX}
"""The error each workload is judged by: torque-free tumbling moves only the orientation in an interesting way."""
ERROR_UNIT = {"tumbling": "rad", "falling-drag": "m"}
DT = 1e-3
"""[s] Time step of every stepping measurement."""
BUDGET_SECONDS = 20.0
"""An engine's measurement at a batch size is skipped (n/a, with the estimate) when a probe of
:data:`PROBE_STEPS` steps at that size predicts more than this per call."""
PROBE_STEPS = 5

DYNAMICS = (("core", "rk4"), ("core", "semi_implicit_euler"), ("core", "engine_euler"),
            ("mujoco", "euler"), ("mujoco", "rk4"), ("mujoco-rollout", "euler"), ("mujoco-rollout", "rk4"),
            ("pybullet", "euler"), ("pinocchio", "euler"), ("pinocchio", "rk4"))
"""(engine, integrator) of the stepping table; ``mujoco-rollout`` is :class:`BatchRollout`."""


def boxes(n_bodies: int, drag: bool, seed: int = 0) -> DynamicsScene:
    """B identical boxes (2 kg, I = diag(0.1, 0.2, 0.3) kg m^2) from seeded random states: torque-free
    tumbling without gravity, or falling under gravity with linear and angular drag."""
    rng = np.random.default_rng(seed)
    bodies = []
    for k in range(n_bodies):
        q = quat_wxyz_normalize(rng.normal(size=4))
        bodies.append(RigidBody(f"box{k}", 2.0, np.diag([0.1, 0.2, 0.3]), rng.normal(size=3), q, rng.normal(size=3),
                                quat_wxyz_to_matrix(q) @ rng.normal(0, 2, size=3)))
    ones = np.ones(n_bodies)
    forces = (Forces(np.array([0.0, 0.0, -9.81]), linear_drag=0.5 * ones, angular_linear_drag=0.05 * ones) if drag
              else Forces())
    return DynamicsScene("falling-drag" if drag else "tumbling", "benchmark", "tight", tuple(bodies), forces,
                         ERROR_STEPS * DT, (DT,))


ROLLOUT_THREADS = os.cpu_count() or 1
"""Threads of ``mujoco-rollout`` (:class:`BatchRollout`), one per CPU: the one stepping row on more than one thread
(its note says so)."""


def simulation(engine: str, integrator: str, scene: DynamicsScene):
    if engine == "mujoco-rollout":
        return BatchRollout(scene, integrator, DT, ROLLOUT_THREADS)
    return make_engine(engine).build_dynamics(scene, integrator, DT)


def _threads_note(engine: str) -> str:
    """The note of a row that does not run on one thread."""
    return f"{ROLLOUT_THREADS} threads (mujoco.rollout, one per CPU)" if engine == "mujoco-rollout" else ""


def _steps(batch: int, quick: bool) -> int:
    """Steps timed at a batch size: about 10^6 body-steps (10^4 quick: a check that every row runs), 10 to 1000
    steps."""
    return int(min(1000, max(10, (10_000 if quick else 1_000_000) // batch)))


def dynamics_rows(batches: list[int], quick: bool, say: Callable[[str], None]) -> list[BenchRow]:
    rows = []
    for drag in (False, True):
        workload = boxes(1, drag).name
        small = boxes(ERROR_BODIES, drag)
        reference = make_engine("tight").build_dynamics(small, "dop853", DT).run(ERROR_STEPS)
        for engine, integrator in DYNAMICS:
            try:
                errors = trajectory_errors(simulation(engine, integrator, small).run(ERROR_STEPS), reference)
                error, note = errors[ERROR_METRIC[workload]].value, _threads_note(engine)
            except Exception as err:  # noqa: BLE001 - an engine that cannot do the workload is a row saying why
                rows += [BenchRow("dynamics", workload, engine, integrator, b, math.nan, "us/body-step", math.nan,
                                  ERROR_UNIT[workload], f"n/a: {err}") for b in batches]
                continue
            for batch in batches:
                steps = _steps(batch, quick)
                try:
                    sim = simulation(engine, integrator, boxes(batch, drag))
                    # A short probe at this batch size predicts the call (a smaller batch's cost per body-step
                    # would not: batching makes it fall up to a hundredfold).
                    probe = median_time(lambda: sim.run(PROBE_STEPS), 0) / PROBE_STEPS * steps
                    if probe > BUDGET_SECONDS:
                        rows.append(BenchRow("dynamics", workload, engine, integrator, batch, math.nan,
                                             "us/body-step", error, ERROR_UNIT[workload],
                                             f"n/a: skipped, {PROBE_STEPS} steps predict {probe:.0f} s per call of "
                                             f"{steps} steps (budget {BUDGET_SECONDS:g} s)"))
                        continue
                    with Meter() as meter:
                        seconds = median_time(lambda: sim.run(steps), 1 if probe > 1.0 else REPEATS)
                except Exception as err:  # noqa: BLE001
                    rows.append(BenchRow("dynamics", workload, engine, integrator, batch, math.nan, "us/body-step",
                                         error, ERROR_UNIT[workload], f"n/a: {err}"))
                    continue
                per_body_step = seconds / (batch * steps)
                rows.append(meter.stamp(BenchRow("dynamics", workload, engine, integrator, batch, per_body_step * 1e6,
                                                 "us/body-step", error, ERROR_UNIT[workload], note)))
                say(f"  {workload:<13} {engine:<15} {integrator:<20} B={batch:<6} {per_body_step * 1e6:9.3f} "
                    f"us/body-step   error {error:.2e} {ERROR_UNIT[workload]}")
    return rows
