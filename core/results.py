"""The results data model: one tidy row per scene x engine x integrator x dt x metric.

The writer (``comparisons.store``) and the reader (``reports.store``) share these names,
so a stored run means the same thing to both.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

SCHEMA_VERSION = 1
RESULTS_FILE = "results.csv"
RUN_INFO_FILE = "run.json"
REPORT_FILE = "report.md"

COLUMNS = ("scene", "engine", "integrator", "dt", "metric", "value", "unit", "reference", "status", "detail")

OK, NOT_AVAILABLE, FAILED, DIVERGED = "ok", "n/a", "failed", "diverged"
STATUSES = (OK, NOT_AVAILABLE, FAILED, DIVERGED)
"""ok: measured. n/a: the engine cannot do what the scene asks (detail says why).
failed: the engine or adapter raised (detail has the error). diverged: the run produced
non-finite values."""


@dataclass(frozen=True)
class ResultRow:
    """One measurement (or the reason there is none).

    ``dt`` is NaN and ``integrator`` empty for kinematics scenes; ``value`` is NaN unless
    ``status`` is ok.
    """

    scene: str
    engine: str
    integrator: str
    dt: float
    metric: str
    value: float
    unit: str
    reference: str
    status: str
    detail: str = ""

    def as_dict(self) -> dict:
        return asdict(self)
