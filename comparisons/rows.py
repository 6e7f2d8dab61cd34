"""Building result rows: one per metric of a case, and error text for failed ones."""

from __future__ import annotations

import math
import traceback
from dataclasses import dataclass

from simparity.core.results import NOT_AVAILABLE, OK, ResultRow


@dataclass(frozen=True)
class Case:
    """One scene x engine x integrator (or IK solver) x dt: the key its rows share.

    ``rows`` takes values as ``{metric: (value, unit)}``.
    """

    scene: str
    engine: str
    integrator: str
    dt: float
    reference: str

    def rows(self, metrics: dict[str, str], status: str, detail: str, values: dict | None = None) -> list[ResultRow]:
        """One row per metric; an ok metric without a finite value becomes n/a (nothing to measure)."""
        values = values or {}
        rows = []
        for metric, unit in metrics.items():
            value = values.get(metric, (math.nan, unit))[0]
            if status == OK and not math.isfinite(value):
                rows.append(ResultRow(self.scene, self.engine, self.integrator, self.dt, metric, value, unit,
                                      self.reference, NOT_AVAILABLE, f"nothing to measure {metric} against; {detail}"))
            else:
                rows.append(ResultRow(self.scene, self.engine, self.integrator, self.dt, metric, value, unit,
                                      self.reference, status, detail))
        return rows


    def partial_rows(self, metrics: dict[str, str], values: dict, detail: str, missing_status: str,
                     missing_detail: str) -> list[ResultRow]:
        """Rows of the metrics measured (ok), then of the others with why they are missing."""
        measured = {m: u for m, u in metrics.items() if m in values}
        missing = {m: u for m, u in metrics.items() if m not in values}
        return self.rows(measured, OK, detail, values) + self.rows(missing, missing_status, missing_detail)


def error_text(err: BaseException) -> str:
    """``Type: message at file:line`` of an exception, on one line."""
    where = traceback.extract_tb(err.__traceback__)[-1] if err.__traceback__ else None
    at = f" at {where.filename.rsplit('/', 1)[-1]}:{where.lineno}" if where else ""
    return f"{type(err).__name__}: {err}{at}".replace("\n", " ")
