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


def test_status_cell_names_the_metric_a_status_is_about():
    """An ok case with one saturated metric says ok, then n/a with the metric and the reason; a case n/a as a
    whole names no metric."""
    common = dict(scene="s", engine="core", integrator="rk4", dt=0.01, reference="analytic:exact")
    rows = pd.DataFrame([r.as_dict() for r in [
        ResultRow(metric="position_error_max", value=1e-3, unit="m", status="ok", detail="d", **common),
        ResultRow(metric="orientation_error_max", value=math.nan, unit="rad", status="n/a",
                  detail="saturated: orientation error 3 rad", **common),
        ResultRow(metric="time_per_step", value=1e-6, unit="s", status="ok", detail="d", **common),
    ]])
    text = render(rows, {})
    assert "| ok · n/a (orientation_error_max): saturated: orientation error 3 rad |" in text
    assert "`n/a` not measured" in text and "saturated" in text.split("## s")[0]  # the definition covers it
    assert "| n/a: no such integrator |" in render(_rows(), {})


def test_hard_cases_section_lists_the_verdict_of_every_case_of_a_hard_scene():
    """A scene of the hard suite gets a line per engine x integrator with each time step's case status;
    a scene outside the suite is not listed there."""
    rows = []
    for scene in ("stiff", "plain"):
        for engine, integrator, dt, status in [("core", "explicit_euler", 0.01, "ok"), ("core", "explicit_euler", 0.05, "diverged"),
                                               ("mujoco", "rk4", 0.01, "ok"), ("mujoco", "rk4", 0.05, "ok")]:
            value = 1e-3 if status == "ok" else math.nan
            rows.append(ResultRow(scene, engine, integrator, dt, "position_error_max", value, "m", "analytic:exact", status))
    table = pd.DataFrame([r.as_dict() for r in rows])
    info = {"scenes": {"stiff": {"suites": ["hard"], "description": "stiff drag"}, "plain": {"suites": ["default"]}}}
    text = render(table, info)
    section = text.split("## Hard cases", 1)[1].split("\n## ", 1)[0]
    assert "### stiff" in section and "### plain" not in section
    assert "| core | explicit_euler | ok | diverged |" in section
    assert "| mujoco | rk4 | ok | ok |" in section
    assert "## Hard cases" not in render(table, {"scenes": {"stiff": {"suites": ["default"]}}})
