"""Whether a copy of core behaves differently from core: its rows against core's on one built-in scene.

Run in the calling process on the scene's quick profile (``simparity.run_scene``), a dynamics scene at its
coarsest time step only, with the copy's folder on the import path; timing rows are left out (they differ
between any two runs).
"""

from __future__ import annotations

import math
from dataclasses import replace

from simparity import load_scene, run_scene
from simparity.comparisons.scenes.profiles import apply_profile
from simparity.core.model.scenes.dynamics import DynamicsScene
from tests.mutation.copy_of_core import CoreCopy

TIMING_PREFIX = "time_"
"""Metrics that are wall times, not results."""

NO_REPEATS = 0
"""One cold timing per case: only the results are compared."""


def _rows(table, engine: str) -> dict[tuple, tuple]:
    mine = table[(table["engine"] == engine) & ~table["metric"].str.startswith(TIMING_PREFIX)]
    return {(r.integrator, "nan" if math.isnan(r.dt) else r.dt, r.metric): (r.status, r.value)
            for r in mine.itertuples()}


def _same(a: tuple, b: tuple) -> bool:
    (status_a, value_a), (status_b, value_b) = a, b
    return status_a == status_b and (value_a == value_b or (math.isnan(value_a) and math.isnan(value_b)))


def witness_scene(name: str):
    """The built-in scene ``name`` on the quick profile; a dynamics scene at its coarsest time step alone (a
    third of the cost, and a bug that acts shows at every step)."""
    scene = apply_profile([load_scene(name)], "quick")[0]
    return replace(scene, dts=(max(scene.dts),)) if isinstance(scene, DynamicsScene) else scene


def differences(copy: CoreCopy, scene_name: str) -> list[str]:
    """The rows (``integrator dt metric: core's -> the copy's``) where the copy's results differ from core's on
    :func:`witness_scene` of ``scene_name``. The copy's root must be on ``sys.path``."""
    scene = witness_scene(scene_name)
    table = run_scene(scene, engines=["core", copy.spec], repeats=NO_REPEATS)
    core, mine = _rows(table, "core"), _rows(table, copy.engine_name)
    if set(core) != set(mine):
        return [f"rows differ: only core {sorted(set(core) - set(mine))[:3]}, only the copy "
                f"{sorted(set(mine) - set(core))[:3]}"]
    return [f"{' '.join(map(str, key))}: {core[key]} -> {mine[key]}" for key in core if not _same(core[key], mine[key])]
