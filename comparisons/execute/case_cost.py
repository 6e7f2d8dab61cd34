"""A case's cost beside its errors: the integrator's declared order and stages, its evaluations per simulated
second, and its batched timing (copies of the scene stepped together)."""

from __future__ import annotations

import math

from simparity.comparisons.execute.timing import best_of
from simparity.comparisons.measure.rows import Case, Measured
from simparity.comparisons.common.error_text import error_text
from simparity.core.model.engine import Engine, JointSimulation, Simulation
from simparity.core.model.errors import NotBatchedError
from simparity.core.model.metric_catalogue import EVALUATIONS_PER_SECOND, TIME_PER_STEP_BATCHED, unit_of

BATCH_COPIES = 100
"""Copies of a scene an engine that batches steps together for ``time_per_step_batched``: at 100 a vectorised
engine's fixed cost per call (Python dispatch: core's RK4 step costs about the same for 1 body as for 100) is
spread over the copies, which is what batching is for, while a batch still fits in cache (100 x 13 floats) and adds
little to a run."""

BATCH_STEPS = 10
"""Steps of the batched timing at most (the case's own when fewer), from the scene's start: 10^3 copy-steps take
milliseconds, far above the clock's resolution. Measured on the quick profile: 9 s of batched stepping over its
~500 batched cases, about 1.5 % of its wall time on two workers (100 steps would be ten times that). A free
flight's steps all cost the same; a contact scene's events later in its run are not in them."""


def theory(engine: Engine, integrator: str) -> int | None:
    """The integrator's theoretical order as the engine declares it; None when it does not say (or fails to: a
    user's engine whose other answers are its rows' business)."""
    try:
        order = engine.theoretical_order(integrator)
    except Exception:  # noqa: BLE001 - a user's engine; its rows report what fails
        return None
    return order if isinstance(order, int) and not isinstance(order, bool) and order > 0 else None


def declared_stages(engine: Engine, integrator: str) -> int | None:
    """The integrator's force evaluations per step as the engine declares them; None when it does not say (or fails
    to: a plugin's answer was checked when it loaded, :mod:`comparisons.engines.plugins`)."""
    try:
        stages = engine.stages(integrator)
    except Exception:  # noqa: BLE001 - a user's engine; its rows report what fails
        return None
    return stages if isinstance(stages, int) and not isinstance(stages, bool) and stages >= 1 else None


def case_cost(engine: Engine, sim: Simulation | JointSimulation, case: Case, n: int, repeats: int) -> dict[str, Measured]:
    """A case's hardware-neutral cost and its batched timing, measured right after its own timing.

    ``evaluations_per_second`` = stages / dt [1/s], the force evaluations per simulated second the engine declares
    (n/a when it declares no stage count); ``time_per_step_batched`` [s], the wall time per copy and step of
    :data:`BATCH_COPIES` copies of the scene's initial state stepped together for min(n, :data:`BATCH_STEPS`) steps,
    best of ``repeats`` like the case's own (n/a with the engine's reason when it cannot batch).
    """
    stages = declared_stages(engine, case.integrator)
    evaluations = (Measured(stages / case.dt, unit_of(EVALUATIONS_PER_SECOND)) if stages is not None else
                   Measured(math.nan, unit_of(EVALUATIONS_PER_SECOND), unmeasurable=(
                       f"{engine.name} declares no stage count for {case.integrator} (Engine.stages)")))
    return {EVALUATIONS_PER_SECOND: evaluations, TIME_PER_STEP_BATCHED: batched_time(sim, n, repeats)}


def batched_time(sim: Simulation | JointSimulation, n: int, repeats: int) -> Measured:
    """Wall time [s] per copy and step of :data:`BATCH_COPIES` copies stepped together (:meth:`Simulation.batched`,
    built untimed) for min(n, :data:`BATCH_STEPS`) steps; n/a with the engine's reason when it cannot batch, or with
    the error when its batched stepping raised (the case's own rows stand)."""
    steps = min(n, BATCH_STEPS)
    try:
        run = sim.batched(BATCH_COPIES)
        seconds, _ = best_of(lambda: run(steps), repeats)
    except NotBatchedError as why:
        return Measured(math.nan, unit_of(TIME_PER_STEP_BATCHED), unmeasurable=str(why))
    except Exception as err:  # noqa: BLE001 - a user's engine: its batched timing is lost, not the case it ran
        return Measured(math.nan, unit_of(TIME_PER_STEP_BATCHED),
                        unmeasurable=f"its batched stepping raised: {error_text(err)}")
    return Measured(seconds / (BATCH_COPIES * steps), unit_of(TIME_PER_STEP_BATCHED))
