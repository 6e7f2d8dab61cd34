"""The report's full tables (reports/tables.py): a row per key, a column per metric the rows hold, the status."""

import math

import pandas as pd

from simparity.core.model.results import ResultRow
from simparity.reports.tables import DYNAMICS_COLUMNS, metric_table, swept_value


def _row(mass, integrator, metric, value, status="ok", detail=""):
    row = ResultRow("s", "core", integrator, 0.01, metric, value, "m", "analytic:exact", status, detail).as_dict()
    return row | {"mass": mass}


def test_a_row_per_key_a_column_per_metric_present_and_the_status():
    rows = pd.DataFrame([_row(2.0, "rk4", "position_error_max", 1.23456e-6), _row(2.0, "rk4", "time_per_step", 1e-5),
                         _row(0.125, "euler", "position_error_max", math.nan, "n/a", "no reason"),
                         _row(0.125, "euler", "time_per_step", 2e-6)])
    table = metric_table(rows, DYNAMICS_COLUMNS, ["mass", "integrator", "dt"])
    assert table.head == ("mass", "integrator", "dt", "position error max [m]", "time per step [s]", "status")
    assert table.rows == (("2", "rk4", "0.01", "1.23e-06", "1e-05", "ok"),
                          ("0.125", "euler", "0.01", "—", "2e-06", "ok · n/a (position_error_max): no reason"))


def test_swept_values_read_as_written():
    assert [swept_value(v) for v in (2.0, -10, 0.3, 1 / 3)] == ["2", "-10", "0.3", "0.333333"]
