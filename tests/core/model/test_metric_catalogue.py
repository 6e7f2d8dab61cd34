"""The metric catalogue: one place for every metric's name, unit and kind, used by all who measure and judge."""

import ast
import dataclasses
from pathlib import Path

import pytest

from simparity.comparisons.execute.ik_runner import IK_METRICS
from simparity.comparisons.execute.in_process import run_in_process
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.contact_metrics import CONTACT_METRICS
from simparity.comparisons.measure.metrics import DRIFT_METRICS, DYNAMICS_METRICS, KINEMATICS_METRICS, ORDER_METRICS
from simparity.core.model.metric_catalogue import (
    CATALOGUE,
    HARD_TARGET_ERROR,
    HARD_TARGET_SOLVED,
    KINDS,
    family_of,
    is_cost,
    is_timing,
    unit_of,
)
from tests.helpers import builtin, smoke

ROOT = Path(__file__).resolve().parents[3]


def test_every_metric_has_a_kind_and_orders_name_their_error():
    for metric in CATALOGUE.values():
        assert metric.kind in KINDS
        assert (metric.kind == "order") == bool(metric.source) and (not metric.source or metric.source in CATALOGUE)
    assert is_timing("time_per_step") and not is_timing("position_error_max") and not is_timing("nonsense")
    # Issue #26: the batched time is a wall time; force evaluations per second an exact cost, neither timing nor
    # numerics (the gate neither counts nor holds a series by it).
    assert is_timing("time_per_step_batched") and not is_cost("time_per_step_batched")
    assert is_cost("evaluations_per_second") and not is_timing("evaluations_per_second") and not is_cost("nonsense")
    assert unit_of("evaluations_per_second") == "1/s" and unit_of("time_per_step_batched") == "s"


def test_the_measuring_code_takes_its_units_from_the_catalogue():
    for table in (DYNAMICS_METRICS, DRIFT_METRICS, ORDER_METRICS, KINEMATICS_METRICS, CONTACT_METRICS, IK_METRICS):
        assert all(CATALOGUE[name].unit == unit for name, unit in table.items())


def test_families_name_the_metrics_a_scene_chooses():
    assert family_of("hard_wrist_flip_solved") is HARD_TARGET_SOLVED  # not the residual of target "wrist_flip_solved"
    assert family_of("hard_wrist_flip") is HARD_TARGET_ERROR and unit_of("hard_wrist_flip") == "m"
    assert unit_of("invariance_ratio_translate") == "1"
    with pytest.raises(KeyError):
        unit_of("position_eror_max")


BOUNCE_UNTIL = 0.5
"""Seconds of the bouncing particle the test runs: past its first impact (sqrt(2 x 1 m / g) = 0.45 s)."""

BOUNCE_DTS = (0.01, 0.02)
"""The bouncing particle's steps in the test: its coarsest and twice it. Its penalty schemes' stability searches
run the whole duration from dt / 8 up (80 % of the smoke run's time at 5 and 10 ms over 1 s, 10 CPU-s); over
:data:`BOUNCE_UNTIL` at these steps the run costs a quarter and writes the same 34 (metric, unit) pairs as the quick
profile (2.5 s at 2.5, 5 and 10 ms; measured)."""


def _smaller(scene):
    """``scene`` as the test runs it: the smoke version (the bouncing particle cut further, see BOUNCE_DTS)."""
    scene = smoke(scene)
    if scene.name != "lecture-bouncing-particle":
        return scene
    return dataclasses.replace(scene, duration=BOUNCE_UNTIL, dts=BOUNCE_DTS)


@pytest.mark.parametrize("scene", [pytest.param("lecture-projectile", marks=pytest.mark.slow),
                                   pytest.param("lecture-bouncing-particle", marks=pytest.mark.slow),
                                   pytest.param("lecture-2link-ik", marks=pytest.mark.slow), "lecture-planar-arm"])
def test_every_metric_a_run_writes_is_catalogued_with_its_unit(scene):
    # smoke: the quick profile at its two coarsest steps, which writes the same (metric, unit) pairs as quick (the
    # order rows too, n/a with their reason), in a third of the time
    rows = run_in_process(_smaller(builtin(scene)), [make_engine("core")], make_engine, repeats=0)
    assert rows
    for row in rows:
        assert unit_of(row.metric) == row.unit, row.metric


def _spelled(path: Path) -> list[str]:
    """Metric names written out as whole string literals (docstrings and f-strings aside)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef)) and n.body and isinstance(n.body[0], ast.Expr)}
    return [f"{path.relative_to(ROOT)}:{n.lineno} {n.value}" for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and n.value in CATALOGUE and id(n) not in docs]


@pytest.mark.slow
def test_no_module_spells_a_metric_name_the_catalogue_owns():
    """Measuring, judging and reporting code names metrics by the catalogue's constants: a rename is one edit."""
    catalogue = ROOT / "core" / "model" / "metric_catalogue.py"
    found = [hit for layer in ("comparisons", "reports") for path in sorted((ROOT / layer).rglob("*.py"))
             if path != catalogue for hit in _spelled(path)]
    assert not found, found
