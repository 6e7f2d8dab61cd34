"""The results model: how a case's status follows from its rows."""

import math

from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow, case_counts, case_status


def test_case_status_precedence():
    """Failed beats diverged beats ok beats n/a; a case with one measured metric is ok."""
    assert case_status([OK, NOT_AVAILABLE]) == OK
    assert case_status([NOT_AVAILABLE, NOT_AVAILABLE]) == NOT_AVAILABLE
    assert case_status([OK, DIVERGED, NOT_AVAILABLE]) == DIVERGED
    assert case_status([DIVERGED, FAILED, OK]) == FAILED


def test_case_counts_group_rows_by_case():
    """Rows of one scene x engine x integrator x dt are one case; NaN dt groups like any other."""
    def row(engine, dt, status):
        return ResultRow("s", engine, "i", dt, "m", 0.0, "1", "r", status)

    rows = [row("a", 0.1, OK), row("a", 0.1, NOT_AVAILABLE), row("a", 0.2, FAILED), row("b", math.nan, NOT_AVAILABLE),
            row("b", math.nan, NOT_AVAILABLE)]
    assert case_counts(rows) == {OK: 1, NOT_AVAILABLE: 1, FAILED: 1, DIVERGED: 0}
    assert case_counts([r.as_dict() for r in rows]) == case_counts(rows)
