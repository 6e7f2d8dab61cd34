"""`simparity bench`'s small batches (issue #41): core at B = 1 and B = 3 against MuJoCo's integrator of the same
scheme, with the ratio."""

from __future__ import annotations

import math

from simparity.comparisons.bench import small_batch, stepping
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes import library


def test_the_pairs_are_every_core_and_mujoco_integrator_of_one_scheme():
    box = stepping.boxes(1, False)
    pairs = small_batch.same_scheme_pairs("bodies", box)
    core, mujoco = make_engine("core"), make_engine("mujoco")
    assert all(core.scheme(mine, box) == mujoco.scheme(theirs, box) == scheme != "" for scheme, mine, theirs in pairs)
    assert {("rk4", "rk4", "rk4"), ("engine_euler", "engine_euler", "euler")} <= set(pairs)
    arm = library.load([small_batch.ARM])[0]
    schemes = {scheme for scheme, _, _ in small_batch.same_scheme_pairs("arm", arm)}
    assert {"rk4", "semi_implicit_euler", "implicit_damping"} <= schemes  # MuJoCo's implicit (velocity) has no pair


def test_a_tiny_run_times_both_engines_at_b_1_and_3_and_divides_them(monkeypatch):
    monkeypatch.setattr(small_batch, "STEPS", {"bodies": 5, "arm": 5})
    monkeypatch.setattr(small_batch, "same_scheme_pairs", lambda kind, scene: [("rk4", "rk4", "rk4")])
    monkeypatch.setattr(small_batch, "REPEATS", 1)
    rows = small_batch.small_batch_rows(False, lambda line: None)
    timed = {(r.workload, r.engine, r.batch): r for r in rows if r.section == small_batch.SECTION}
    ratios = [r for r in rows if r.section == small_batch.RATIO_SECTION]
    assert {(w, b) for w, _, b in timed} == {(w, b) for w in ("tumbling", small_batch.ARM) for b in small_batch.BATCHES}
    assert all(math.isfinite(r.value) and r.value > 0 and math.isfinite(r.wall_seconds) for r in timed.values())
    for r in ratios:
        assert r.value == timed[r.workload, "core", r.batch].value / timed[r.workload, "mujoco", r.batch].value
    text = "\n".join(small_batch.markdown_lines(rows))
    assert text.count("| tumbling | rk4 | rk4 | rk4 |") == 1 and "B = 3 core | B = 3 MuJoCo | B = 3 ratio" in text
