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


HARD_VERDICT_SUFFIXES = ("_solved", "_unreachable", "_limit_violation")
"""A hard IK target ``<name>`` has the row ``hard_<name>`` (position residual [m]) and one row per
suffix: ``_solved`` 1 or 0, ``_unreachable`` 1 when the solver reported the target unreachable,
``_limit_violation`` how far the solution lies outside the joint limits [rad or m]."""


_PRECEDENCE = (FAILED, DIVERGED, OK, NOT_AVAILABLE)


def case_status(statuses) -> str:
    """The status of a case (scene x engine x integrator x dt) from its rows' statuses: failed if
    any row failed, else diverged if any diverged, else ok if anything was measured, else n/a."""
    present = set(statuses)
    return next((s for s in _PRECEDENCE if s in present), NOT_AVAILABLE)


def case_counts(rows) -> dict[str, int]:
    """Number of cases per status, from rows with scene, engine, integrator, dt and status.

    ``rows`` is an iterable of mappings (or ResultRow); dt NaN is one case key like any other.
    """
    cases: dict[tuple, list[str]] = {}
    for row in rows:
        get = row.get if isinstance(row, dict) else row.__getattribute__
        dt = get("dt")
        key = (get("scene"), get("engine"), get("integrator"), "nan" if dt != dt else dt)
        cases.setdefault(key, []).append(get("status"))
    counts = {s: 0 for s in STATUSES}
    for statuses in cases.values():
        counts[case_status(statuses)] += 1
    return counts
