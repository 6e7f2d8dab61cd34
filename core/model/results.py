"""The results data model: one tidy row per scene x engine x integrator x dt x metric.

The stored run's one owner (``reports.store``: its writer and its readers) and everything that makes or reads
rows share these names, so a stored run means the same thing to all of them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from simparity.core.model.arrays import readonly

SCHEMA_VERSION = 2
"""2: the ``flag`` column (:data:`FLAGS`) and the ``scheme`` column (the kind of scheme of the row's integrator or
solver, ``core.engine.SCHEME_KINDS``). Version 1 runs, without them, are read with both empty."""
READ_SCHEMA_VERSIONS = (1, 2)
"""Stored runs this simparity reads."""
RESULTS_FILE = "results.csv"
RESULTS_PARQUET_FILE = "results.parquet"
"""The same rows as :data:`RESULTS_FILE`, typed (categorical keys, float64 values), beside it when pyarrow is
installed (``simparity[parquet]``): written when the run ends, removed when a run (or ``--resume``) starts writing
the CSV again, so it never holds fewer rows than the CSV; a CSV changed after it is read instead."""
RUN_INFO_FILE = "run.json"
REPORT_FILE = "report.md"
REPORT_HTML_FILE = "report.html"

COLUMNS = ("scene", "engine", "integrator", "dt", "metric", "value", "unit", "reference", "status", "detail", "flag",
           "scheme")
"""The columns of every run. A run with a swept scene (a file's ``[sweep]``) has the sweep columns after
them; a run without has exactly these."""

SWEEP_COLUMN = "sweep"
"""Sweep column: the name of the scene a variant was swept from (its file's ``[scene] name``); empty on rows
of scenes without a sweep."""

SWEEP_PREFIX = "sweep:"
"""Sweep columns after :data:`SWEEP_COLUMN`, one per swept key: this prefix and the key's path as the
``[sweep]`` table writes it (``sweep:contact.restitution``), holding the variant's value; empty on rows of
scenes that do not sweep that key. No fixed column has a colon, so none can clash."""


def sweep_column(key: str) -> str:
    """The results column of swept key ``key``."""
    return SWEEP_PREFIX + key

OK, NOT_AVAILABLE, FAILED, DIVERGED = "ok", "n/a", "failed", "diverged"
STATUSES = (OK, NOT_AVAILABLE, FAILED, DIVERGED)
"""ok: measured. n/a: the engine cannot do what the scene asks (detail says why).
failed: the engine or adapter raised (detail has the error). diverged: the run produced
non-finite values."""

SATURATED, ROUNDING_FLOOR, PRE_ASYMPTOTIC, SUPERCONVERGENT, BELOW_THEORY, NOT_CONVERGING, NOTHING_TO_MEASURE = (
    "saturated", "rounding-floor", "pre-asymptotic", "superconvergent", "below-theory", "not-converging",
    "nothing-to-measure")
UNSOLVED = "unsolved"
NOT_AT_REST = "not-at-rest"
FLAGS = {
    SATURATED: "n/a: the error is as large as the quantity it measures (the run is on another orbit, or an "
               "orientation is lost): it no longer measures how far; the detail names the scale",
    ROUNDING_FLOOR: "an error at the rounding floor of its run (ok: a number, exact up to rounding), or an order fit "
                    "of such errors (n/a)",
    PRE_ASYMPTOTIC: "n/a: an order whose local slopes disagree: the time steps are not in the asymptotic range",
    SUPERCONVERGENT: "n/a: a clean order fit above the scheme's theoretical order + 0.5: outside the scheme's "
                     "asymptotic range (the steps are before it, or error terms cancel), so no order of the scheme; "
                     "the detail gives the fitted value and the local slopes",
    BELOW_THEORY: "ok: a clean order fit below the scheme's theoretical order - 0.5: the scheme is not the one it "
                  "claims to be, or the steps are before the asymptotic range",
    NOT_CONVERGING: "n/a, and an alarm: a clean fit of order below 0.5 on errors far from saturation: the errors do "
                    "not fall with dt (the scheme is inconsistent, or something dt does not control dominates); "
                    "the gate fails it unless a bound names it",
    NOTHING_TO_MEASURE: "n/a: the physics of this run offers nothing to measure (no impact, no motion, a quantity "
                        "that is 0)",
    NOT_AT_REST: "n/a, and an alarm: a robot whose scene says it stands ([contact] stands) is not at rest at the end "
                 "(it slides, creeps or chatters), so its rest checks cannot be measured; the gate fails it unless a "
                 "bound names it",
    UNSOLVED: "n/a: an IK solver that solves none of the scene's reachable targets: a rate of 0 measures a stopping "
              "rule or a cap it does not meet, not how well it solves (the detail gives its median residuals)",
}
"""The typed qualifiers of a row (its ``flag`` column; empty for a plain measurement): why a row is n/a when the
number would mean nothing, and what an ok order fit shows beside theory. The report's findings and the gate read
them; nobody parses the detail."""

ALARM_FLAGS = (NOT_CONVERGING, NOT_AT_REST)
"""Flags that are a violation of every bound that does not name them (``na_when``): n/a, but not an honest one."""

DIMENSIONLESS = "1"
"""The unit of a dimensionless metric (a ratio, a drift, an order), as SI writes it."""


@dataclass(frozen=True)
class ResultRow:
    """One measurement (or the reason there is none).

    ``dt`` is NaN and ``integrator`` empty for kinematics scenes; ``value`` is NaN unless
    ``status`` is ok. ``flag`` qualifies the status (:data:`FLAGS`); ``scheme`` is the kind of scheme the engine
    declares its integrator or IK solver to be on the scene (``core.engine.Engine.scheme``; "" when it does not
    say), which the CI gate keys its bounds by.
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
    flag: str = ""
    scheme: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


NO_REFERENCE = "none"
"""The ``reference`` column of the cases of a scene run against no reference (a chain's contact: each engine is held
to truths that need no engine)."""


def reference_label(engine: str, integrator: str) -> str:
    """The ``reference`` column of the cases measured against ``engine`` running ``integrator``
    (``engine:integrator``): a row whose own engine and integrator give its reference is measured against itself."""
    return f"{engine}:{integrator}"


GROUND_TRUTH_ENGINES = ("analytic", "tight")
"""Engines that compute a scene's truth (closed form, or a tight adaptive solve), not schemes a user
would pick: reports rank the other engines and never offer these as the cheapest scheme."""


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
        get: Callable[[str], Any] = row.get if isinstance(row, dict) else row.__getattribute__
        dt = get("dt")
        key = (get("scene"), get("engine"), get("integrator"), "nan" if dt != dt else dt)
        cases.setdefault(key, []).append(get("status"))
    counts = {s: 0 for s in STATUSES}
    for statuses in cases.values():
        counts[case_status(statuses)] += 1
    return counts


SERIES_FILE = "series.csv.gz"
"""Sampled series of a run, next to ``results.csv``: gzip-compressed CSV, one row per point,
readable with ``pandas.read_csv`` (docs/metrics.md, "Sampled series")."""

SERIES_COLUMNS = ("scene", "engine", "integrator", "dt", "quantity", "unit", "x", "value")

SERIES_QUANTITIES = {
    "energy_change": "(E(t) - E(0)) / the energy scale of energy_drift_max, signed (x: time [s])",
    "angular_momentum_change": "|L(t) - L(0)| / |L(0)| (x: time [s])",
    "position_error": "largest body position error against the reference [m] (x: time [s])",
    "orientation_error": "largest body orientation error against the reference [rad] (x: time [s])",
    "support_height": "contact scenes: signed distance of the first body's lowest point from its nearest plane [m] "
                      "(negative: penetration; x: time [s])",
    "position_residual": "IK position residual [m] at cumulative fraction x of the random targets",
    "orientation_residual": "IK orientation residual [rad] at cumulative fraction x of the random targets",
    "iterations": "IK iterations at cumulative fraction x of the random targets (failed solves included)",
    "fk_disagreement_max": "largest end-effector distance [m] between the FK of `engine` and of the engine in "
                           "`integrator`, over every solver's solutions (x: 0)",
    "forward_difference_error": "joint-dynamics scenes: dtau/dq by forward differences of the engine's own inverse "
                                "dynamics, max |D - T| over the floored max |T| against the complex-step truth (x: the "
                                "step [rad or m])",
    "central_difference_error": "as forward_difference_error, by centred differences (x: the step [rad or m])",
}
"""What each series quantity holds. Time series keep, of each of at most ``SERIES_POINTS`` runs of
consecutive samples, the sample of largest magnitude (at its own time), so their maxima are the
run's maxima and an oscillation shows its envelope; distributions are quantiles."""

SERIES_POINTS = 101
"""Points per series: enough for a smooth curve on a report figure, small enough that a run of
the default suite keeps its series in a few megabytes."""


@dataclass(frozen=True)
class SeriesRecord:
    """One sampled series of a case: ``value`` against ``x``, both (K,) read-only arrays, K <= SERIES_POINTS."""

    scene: str
    engine: str
    integrator: str
    dt: float
    quantity: str
    unit: str
    x: np.ndarray
    value: np.ndarray

    def __post_init__(self) -> None:
        x, value = np.asarray(self.x, dtype=float), np.asarray(self.value, dtype=float)
        if x.ndim != 1 or x.shape != value.shape:
            raise ValueError(f"SeriesRecord x {x.shape} and value {value.shape} must be two (K,) arrays")
        object.__setattr__(self, "x", readonly(x))
        object.__setattr__(self, "value", readonly(value))
