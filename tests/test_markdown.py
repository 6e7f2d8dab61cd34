"""report.md rendering from a stored table."""

import math

import pandas as pd

from simparity.core.results import ResultRow
from simparity.reports.markdown import render


def _rows():
    common = dict(scene="s", integrator="rk4", dt=0.01, reference="analytic:exact")
    return pd.DataFrame([r.as_dict() for r in [
        ResultRow(engine="core", metric="position_error_max", value=1.5e-9, unit="m", status="ok", detail="d", **common),
        ResultRow(engine="core", metric="time_per_step", value=2e-6, unit="s", status="ok", detail="d", **common),
        ResultRow(engine="pybullet", metric="position_error_max", value=math.nan, unit="m", status="n/a",
                  detail="no such integrator", **common),
    ]])


def test_report_has_scene_table_with_values_and_reasons():
    """Values appear with 3 significant digits, n/a rows carry their reason, the reference is named."""
    text = render(_rows(), {"engine_versions": {"core": "x"}, "scenes": {"s": {"description": "a test scene"}}})
    assert "## s (dynamics)" in text and "a test scene" in text
    assert "Reference: `analytic:exact`" in text
    assert "| core | rk4 | 0.01 | 1.5e-09 |" in text
    assert "n/a: no such integrator" in text
    assert "ok 1, n/a 1, failed 0, diverged 0" in text
