"""The report's modules stay small enough to read (issue #40): none over :data:`MAX_LINES` lines unless its docstring
says why, and each kind of scene the report tells apart has a section module of its own."""

import ast
import math
from pathlib import Path

import pandas as pd

from simparity.core.model.metric_catalogue import MASS_MATRIX_ERROR_MAX, POSITION_ERROR_MAX, SOLVE_RATE
from simparity.reports.sections import context

REPORTS = Path(__file__).resolve().parents[2] / "reports"
MAX_LINES = 600
"""Lines a module of reports/ stays within (issue #40): past it a module glues several concepts."""
REASON = "lines:"
"""What a longer module's docstring says its length with, its reason after it (``700 lines: ...``)."""


def _rows(metric: str, dt: float) -> pd.DataFrame:
    return pd.DataFrame({"metric": [metric], "dt": [dt]})


KINDS = {"ik": _rows(SOLVE_RATE, math.nan), "joint_dynamics": _rows(MASS_MATRIX_ERROR_MAX, math.nan),
         "dynamics": _rows(POSITION_ERROR_MAX, 0.01), "kinematics": _rows(POSITION_ERROR_MAX, math.nan)}
"""A scene's rows of each kind :func:`reports.sections.context.scene_kind` tells apart (the metric that marks it,
a time step or none)."""


def test_no_report_module_is_long_without_a_reason():
    long = []
    for path in sorted(REPORTS.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        docstring = ast.get_docstring(ast.parse(text)) or ""
        if text.count("\n") > MAX_LINES and REASON not in docstring:
            long.append(f"{path.relative_to(REPORTS)}: {text.count(chr(10))} lines")
    assert not long, long


def test_each_kind_of_scene_has_its_section_module():
    modules = {path.stem for path in (REPORTS / "sections").glob("*.py")}
    for kind, rows in KINDS.items():
        assert context.scene_kind(rows) == kind
        assert kind in modules, f"reports/sections/{kind}.py"
