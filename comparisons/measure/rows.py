"""Building result rows: one per metric of a case, and error text for failed ones."""

from __future__ import annotations

import contextlib
import math
import warnings
from dataclasses import dataclass, replace

from simparity.core.model.engine import is_scheme_label
from simparity.core.model.results import NOT_AVAILABLE, OK, ResultRow


@dataclass(frozen=True)
class Measured:
    """One metric's value, or why it has none that means anything.

    Attributes
    ----------
    value : float
        In ``unit``; NaN when there is nothing to measure. An unmeasurable value keeps the raw
        number for the harness (order fits see a saturated error as saturated); its row gets NaN.
    unit : str
    unmeasurable : str
        Non-empty when the value is not a meaningful number (saturated, at the rounding
        floor, nothing to compare against): the row is then ``n/a`` with this reason.
    note : str
        How it was measured when that differs from the metric's definition (a fallback);
        it goes first in the row's detail.
    flag : str
        The row's typed qualifier (:data:`core.results.FLAGS`): why it is unmeasurable (saturated, at the
        rounding floor, superconvergent, ...), or what an ok value shows beside theory (below-theory); "" for a plain
        measurement.
    """

    value: float
    unit: str
    unmeasurable: str = ""
    note: str = ""
    flag: str = ""


@dataclass(frozen=True)
class Case:
    """One scene x engine x integrator (or IK solver) x dt: the key its rows share, and the kind of scheme the
    engine declares (:func:`declared_scheme`)."""

    scene: str
    engine: str
    integrator: str
    dt: float
    reference: str
    scheme: str = ""

    def _row(self, metric: str, value: float, unit: str, status: str, detail: str, flag: str = "") -> ResultRow:
        return ResultRow(self.scene, self.engine, self.integrator, self.dt, metric, value, unit, self.reference,
                         status, detail, flag, self.scheme)

    def rows(self, metrics: dict[str, str], status: str, detail: str,
             values: dict[str, Measured] | None = None) -> list[ResultRow]:
        """One row per metric of ``metrics`` ({metric: unit}) with the case's ``status`` and ``detail``.

        In an ok case a metric without a finite value, or one marked unmeasurable, is ``n/a``
        with its own reason only (the case's detail is on its ok rows); a measured value's flag goes
        into the row's ``flag`` (rows of a case that is not ok carry none: the case's status says all).
        """
        values = values or {}
        rows = []
        for metric, unit in metrics.items():
            measured = values.get(metric, Measured(math.nan, unit))
            if status != OK:
                rows.append(self._row(metric, measured.value, unit, status, detail))
            elif measured.unmeasurable:
                rows.append(self._row(metric, math.nan, unit, NOT_AVAILABLE, measured.unmeasurable, measured.flag))
            elif not math.isfinite(measured.value):
                rows.append(self._row(metric, math.nan, unit, NOT_AVAILABLE, f"nothing to measure {metric} against"))
            else:
                note = f"{measured.note}; " if measured.note else ""
                rows.append(self._row(metric, measured.value, unit, OK, note + detail, measured.flag))
        return rows

    def partial_rows(self, metrics: dict[str, str], values: dict[str, Measured], detail: str, missing_status: str,
                     missing_detail: str) -> list[ResultRow]:
        """Rows of the metrics measured (ok), then of the others with why they are missing."""
        measured = {m: u for m, u in metrics.items() if m in values}
        missing = {m: u for m, u in metrics.items() if m not in values}
        return self.rows(measured, OK, detail, values) + self.rows(missing, missing_status, missing_detail)


def declared_scheme(engine, name: str, scene) -> str:
    """The kind of scheme ``engine`` declares integrator or IK solver ``name`` to be on ``scene``
    (``Engine.scheme``); "" when it does not say, or answers what the interface does not allow (a user's engine:
    the gate then holds it only to the bounds for every scheme)."""
    try:
        label = engine.scheme(name, scene)
    except Exception:  # noqa: BLE001 - a user's engine; its rows report what else fails
        return ""
    return label if isinstance(label, str) and is_scheme_label(label) else ""


@contextlib.contextmanager
def warnings_into_rows(rows: list[ResultRow]):
    """Keep Python and NumPy warnings raised while a case runs off the console and in its rows' detail.

    ``rows`` is the list the case's rows are appended to inside the block; those appended in it
    get ``warnings: ...`` (each distinct message once) at the end of their detail.
    """
    start = len(rows)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    messages = list(dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught))
    if messages:
        note = "warnings: " + "; ".join(messages)
        rows[start:] = [replace(r, detail=f"{r.detail}; {note}" if r.detail else note) for r in rows[start:]]
