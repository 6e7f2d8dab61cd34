"""Each kind of scene the report tells apart has a section module of its own (issue #40; the modules' sizes:
tests/system/test_module_sizes.py)."""

import math
from pathlib import Path

import pandas as pd

from simparity.core.model.metric_catalogue import MASS_MATRIX_ERROR_MAX, POSITION_ERROR_MAX, SOLVE_RATE
from simparity.reports.sections import context

REPORTS = Path(__file__).resolve().parents[2] / "reports"


def _rows(metric: str, dt: float) -> pd.DataFrame:
    return pd.DataFrame({"metric": [metric], "dt": [dt]})


KINDS = {"ik": _rows(SOLVE_RATE, math.nan), "joint_dynamics": _rows(MASS_MATRIX_ERROR_MAX, math.nan),
         "dynamics": _rows(POSITION_ERROR_MAX, 0.01), "kinematics": _rows(POSITION_ERROR_MAX, math.nan)}
"""A scene's rows of each kind :func:`reports.sections.context.scene_kind` tells apart (the metric that marks it,
a time step or none)."""


def test_each_kind_of_scene_has_its_section_module():
    modules = {path.stem for path in (REPORTS / "sections").glob("*.py")}
    for kind, rows in KINDS.items():
        assert context.scene_kind(rows) == kind
        assert kind in modules, f"reports/sections/{kind}.py"
