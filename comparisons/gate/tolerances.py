"""Tolerances: the bounds ``simparity check`` holds a run to, each with its reason.

A tolerances file is TOML with one ``[[bound]]`` table per bound (format: ``docs/check.md``)::

    [[bound]]
    scene = "*"                      # fnmatch patterns; "*" (the default) matches anything
    engine = "*"
    integrator = "*"
    scheme = "rk4"                   # the kind of scheme the engine declares its integrator to be
    metric = "order_position"
    expected = 4.0                   # |value - expected| <= band
    band = 0.3
    reason = "RK4 is fourth order; 0.3 covers the next term at the ladders used"

Kinds of bound (one table may combine them): ``max`` (value <= max), ``min`` (value >= min),
``expected`` with ``band`` (absolute, +-) or ``rel`` (relative to ``expected``), any of them scaled
by dt^``dt_power`` (a scheme's known error, e.g. C dt^1 for Euler), and ``status`` (the statuses the
row may have; default ``ok`` when a number is bounded, so a metric that went ``n/a`` is a
violation, not a pass; ``status = "diverged"`` makes a blow-up the expected verdict). ``na_when``
lists the flags (``core.results.FLAGS``) with which an ``n/a`` row is the right answer although the
bound wants a number (``na_when = ["nothing-to-measure"]``: a resting run has no energy to gain). A
row flagged with an alarm (``not-converging``) breaks every bound whose ``na_when`` does not name it,
whatever its status.

A bound may name one time step (``dt``, in seconds) or ``dt = "*"`` (every time step, but not
the order rows, which have none); without ``dt`` it holds for every row.
``scheme`` matches the kind of scheme the engine declares the row's integrator or IK solver to be
(``core.engine.SCHEME_KINDS``; ``soft+*`` any time integrator under MuJoCo's soft contact; a list of
patterns matches any of them): a bound keyed by scheme holds every engine's scheme of that kind, a
user's plugin included, whatever it calls it.
A user's file extends the shipped one (``extends = "default"``, the default), starts empty (``extends =
"none"``) or extends another file (``extends = "path.toml"``, relative to the file). Which bound decides a
row: first the file — a bound of the extending file beats every bound of the file it extends, however
specific (where a user's bound and a shipped one both match a row, the user's wins) — then, within one file,
the most specific: a key written out exactly counts 2, a pattern other than ``*`` counts 1, ``*`` counts 0,
summed over scene, engine, integrator, scheme, metric and dt; among equally specific bounds the later one in
the file wins. ``simparity check --explain ENGINE --metric M`` lists, for each row, every bound that matched
and which one decided.

Every bound's ``metric`` is checked against the metric catalogue (:mod:`comparisons.gate.metric_names`): a name
no run can write is refused with the closest names; its other keys are checked against what exists when it is held to
a run (:mod:`comparisons.gate.bound_names`). ``reference = "self"`` holds only rows measured against themselves. A
bound that holds no value is refused: an empty interval, every value below 0 on a metric that is never negative, a
``dt_power`` beyond :data:`DT_POWER_MAX`; so is a chain of files with more than :data:`MAX_BOUNDS` bounds. Rows find
their bounds through :class:`comparisons.gate.bound_index.BoundIndex`, never by scanning them all. Top-level ``check_engines = [...]`` names the engines the gate
holds (the others' violations are findings, never blocking) and ``require_engines = [...]`` those that must have
measured something (:func:`load_gate`; the nearest file of an ``extends`` chain that names them wins).
"""

from __future__ import annotations

import fnmatch
import math
from typing import Any
from dataclasses import dataclass, replace
from pathlib import Path

from simparity.comparisons.gate.bound_index import DT_MATCH, BoundIndex, case_schemes
from simparity.comparisons.gate.metric_names import allowed_text, non_negative, unknown_metric
from simparity.core.model.errors import SceneError, ToleranceError, one_line
from simparity.core.model.files import read_toml
from simparity.core.model.ranges import RANGES
from simparity.core.model.results import FLAGS, OK, STATUSES


DEFAULT_TOLERANCES = Path(__file__).resolve().parents[1] / "tolerances" / "default.toml"
"""The shipped tolerances: every built-in scene, each bound with its reason."""

MATCH_KEYS = ("scene", "engine", "integrator", "metric")
NUMBER_KEYS = ("max", "min", "expected", "band", "rel", "dt_power")
REFERENCE_KEY, ANY_REFERENCE, SELF_REFERENCE = "reference", "*", "self"
"""``reference = "self"``: the bound holds only rows measured against themselves (their own engine and integrator are
the case's reference, :func:`core.model.results.reference_label`): a truth's zero error against itself, which the same
truth measured against another engine's reference does not have."""
ALLOWED_KEYS = MATCH_KEYS + ("scheme", "dt", REFERENCE_KEY) + NUMBER_KEYS + ("status", "na_when", "reason")
EXTENDS_DEFAULT, EXTENDS_NONE = "default", "none"
"""``extends`` values: the shipped tolerances (the default of every file but the shipped one), or nothing."""
MAX_EXTENDS_DEPTH = 16
"""Files at most in one chain of ``extends``: deeper is a loop or a mistake, refused in one line."""
DT_POWER_MAX = 16.0
"""Largest magnitude of ``dt_power``: a scheme's error is C dt^p with p its order (8 at most for a scheme simparity
knows, DOP853), a rounding floor's grows as dt^-1; twice the highest order, and dt^p stays finite over every time step
a scene may have (1e-9 to 1e3 s), where 1e308 overflows to a bound of 0 or infinity that holds nothing."""
REL_MAX = 1.0
"""Largest ``rel``: a share of ``|expected|``; beyond 1 the band takes in values of the other sign, no longer a
tolerance relative to the expected value (``band``, ``min`` or ``max`` say what is meant)."""
MAX_BOUNDS = 100_000
"""Bounds a tolerances file and the files it extends may hold together: a blessed run of every built-in suite in the
full profile is ~40,000; parsing TOML costs ~0.2 ms a bound, so more is a mistake or an attack, refused in one line."""


@dataclass(frozen=True)
class Bound:
    """One bound of a tolerances file.

    Attributes
    ----------
    scene, engine, integrator, metric : str
        fnmatch patterns the row's fields must match.
    scheme : tuple of str
        fnmatch patterns of which the row's ``scheme`` column must match one.
    dt : float, "*" or None
        The time step [s] the bound is for; ``"*"``: every time step (the per-time-step rows, not
        the order rows, which have none); None: every row.
    max, min, expected, band, rel, dt_power : float or None
        See the module docstring; ``None`` where not given.
    statuses : tuple of str
        Statuses the row may have.
    na_when : tuple of str
        Flags with which an n/a row passes although ``statuses`` does not allow n/a; an alarm flag passes
        only when named here.
    reason : str
        Why the bound is what it is.
    where : str
        ``file: bound[i]``, for messages.
    order : int
        Position in the file (later wins among equally specific bounds).
    layer : int
        The file's place in its ``extends`` chain: 0 for the first file extended (the shipped one), one more
        for each file that extends it; a higher layer wins whatever the specificity.
    source : str
        The file the bound is in.
    against_self : bool
        ``reference = "self"``: the bound holds only rows measured against themselves (:data:`SELF_REFERENCE`).
    shipped : bool
        Whether the bound is the shipped file's (:data:`DEFAULT_TOLERANCES`): a bound of a user's file that
        matches no row of a run is said so (:func:`comparisons.gate.check.unmatched_bounds`), a shipped one not
        (it holds every built-in scene, most of which a run leaves out).
    """

    scene: str
    engine: str
    integrator: str
    scheme: tuple[str, ...]
    metric: str
    dt: float | str | None
    max: float | None
    min: float | None
    expected: float | None
    band: float | None
    rel: float | None
    dt_power: float | None
    statuses: tuple[str, ...]
    reason: str
    where: str
    order: int
    na_when: tuple[str, ...] = ()
    layer: int = 0
    shipped: bool = False
    against_self: bool = False
    source: str = ""

    @property
    def specificity(self) -> int:
        patterns = (self.scene, self.engine, self.integrator, self.metric)
        dt_weight = 0 if self.dt is None else 1 if self.dt == "*" else 2
        scheme_weight = max(_weight(p) for p in self.scheme) if len(self.scheme) == 1 else min(
            1, *(_weight(p) for p in self.scheme))
        return dt_weight + scheme_weight + sum(_weight(p) for p in patterns)

    def matches(self, scene: str, engine: str, integrator: str, metric: str, dt: float = math.nan,
                scheme: str = "", own_reference: bool = False) -> bool:
        """Whether the bound holds a row (``own_reference``: the row is measured against itself)."""
        if self.against_self and not own_reference:
            return False
        if self.dt == "*" and math.isnan(dt):
            return False
        if isinstance(self.dt, float) and not abs(dt - self.dt) <= DT_MATCH * self.dt:
            return False
        return any(fnmatch.fnmatchcase(label, p) for p in self.scheme for label in case_schemes(scheme)) and all(
            fnmatch.fnmatchcase(value, pattern) for value, pattern in
            zip((scene, engine, integrator, metric), (self.scene, self.engine, self.integrator, self.metric)))

    @property
    def bounds_a_number(self) -> bool:
        return self.max is not None or self.min is not None or self.expected is not None

    @property
    def bounds_the_value(self) -> bool:
        """Whether a row this bound decides is held to more than "it ran": a number's limits, or a verdict other
        than a number (``status = "diverged"``). A status-only bound that allows ``ok`` (the shipped catch-all)
        checks no value."""
        return self.bounds_a_number or OK not in self.statuses

    @property
    def precedence(self) -> tuple[int, int, int]:
        """The key by which the matching bound with the highest wins: file layer, specificity, order in the file."""
        return self.layer, self.specificity, self.order

    def status_text(self) -> str:
        """The statuses in words, e.g. ``status ok or n/a``."""
        return "status " + " or ".join(self.statuses)

    def limits(self, dt: float) -> tuple[float, float]:
        """(lowest, highest) value allowed at time step ``dt`` [s] (NaN dt: no scaling)."""
        try:
            scale = dt ** self.dt_power if self.dt_power is not None and math.isfinite(dt) else 1.0
        except OverflowError:  # a huge negative power of a small step: no finite limit
            scale = math.inf
        low, high = -math.inf, math.inf
        if self.max is not None:
            high = self.max * scale
        if self.min is not None:
            low = self.min * scale
        if self.expected is not None:
            centre = self.expected * scale
            half = (self.band or 0.0) + (self.rel or 0.0) * abs(centre)
            low, high = max(low, centre - half), min(high, centre + half)
        return low, high

    def describe(self, dt: float) -> str:
        """The bound in words, e.g. ``<= 1e-06`` or ``4 +- 0.3``."""
        low, high = self.limits(dt)
        if self.expected is not None or (self.max is not None and self.min is not None):
            return f"in [{low:.3g}, {high:.3g}]"
        return f"<= {high:.3g}" if self.max is not None else f">= {low:.3g}"


FLOAT_BITS = 1024
"""The bits of the largest integer a float64 holds (~1.8e308): a larger one cannot be compared, nor printed in full."""


def _weight(pattern: str) -> int:
    """How specific one pattern is: 0 for ``*``, 1 for another pattern, 2 for a name written out."""
    return 0 if pattern == "*" else 1 if any(c in pattern for c in "*?[") else 2


def _number(source: str, key: str, value, non_negative: bool = False) -> float:
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > FLOAT_BITS:
        raise ToleranceError(source, key, f"an integer of {value.bit_length():,} bits, beyond any float",
                             "finite numbers")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ToleranceError(source, key, f"expected a finite number, got {value!r:.60}", "finite numbers")
    if non_negative and value < 0:
        raise ToleranceError(source, key, f"{value!r} is negative", "numbers >= 0")
    return float(value)


def _bound(source: str, index: int, table) -> Bound:
    where = f"bound[{index}]"
    if not isinstance(table, dict):
        raise ToleranceError(source, where, "expected a table", "[[bound]] tables")
    unknown = sorted(set(table) - set(ALLOWED_KEYS))
    if unknown:
        raise ToleranceError(source, f"{where}.{unknown[0]}"[:120], "unknown key", ", ".join(ALLOWED_KEYS))
    patterns: dict[str, Any] = {}
    for key in MATCH_KEYS:
        value = table.get(key, "*")
        if not isinstance(value, str) or not value:
            raise ToleranceError(source, f"{where}.{key}", f"expected a non-empty pattern, got {value!r:.60}",
                                 "a name or an fnmatch pattern such as rk4*")
        patterns[key] = value
    unknown_why = unknown_metric(patterns["metric"])
    if unknown_why:
        raise ToleranceError(source, f"{where}.metric", unknown_why, allowed_text(patterns["metric"]))
    scheme = table.get("scheme", "*")
    schemes = (scheme,) if isinstance(scheme, str) else tuple(scheme) if isinstance(scheme, list) else ()
    if not schemes or not all(isinstance(p, str) and p for p in schemes):
        raise ToleranceError(source, f"{where}.scheme", f"expected a pattern or a list of them, got {scheme!r:.60}",
                             "kinds of scheme (core.engine.SCHEME_KINDS) or fnmatch patterns such as soft+*")
    patterns["scheme"] = schemes
    dt = table.get("dt")
    if dt is not None and dt != "*":
        dt = _number(source, f"{where}.dt", table["dt"])
        if not (dt > 0 and RANGES["dt"].allows(dt)):
            raise ToleranceError(source, f"{where}.dt", f"{dt!r} is not a time step", f"a time step > 0 [s], "
                                 f"{RANGES['dt'].text()}")
    reference = table.get(REFERENCE_KEY, ANY_REFERENCE)
    if reference not in (ANY_REFERENCE, SELF_REFERENCE):
        raise ToleranceError(source, f"{where}.{REFERENCE_KEY}", f"{reference!r:.60} is not allowed",
                             f'"{SELF_REFERENCE}" (only rows measured against themselves: their own engine and '
                             f'integrator are the reference) or "{ANY_REFERENCE}" (every row, the default)')
    numbers: dict[str, Any] = {key: None for key in NUMBER_KEYS}
    for key in NUMBER_KEYS:
        if key in table:
            numbers[key] = _number(source, f"{where}.{key}", table[key], non_negative=key in ("band", "rel"))
    if (numbers["band"] is not None or numbers["rel"] is not None) and numbers["expected"] is None:
        raise ToleranceError(source, f"{where}.band", "band and rel need an expected value", "expected = ...")
    reason = table.get("reason")
    if not isinstance(reason, str) or not reason.strip():
        raise ToleranceError(source, f"{where}.reason", "every bound needs its reason", "a non-empty string")
    status = table.get("status")
    if status is None:
        statuses = (OK,)
    else:
        statuses = (status,) if isinstance(status, str) else tuple(status) if isinstance(status, list) else ()
        if not statuses or any(s not in STATUSES for s in statuses):
            raise ToleranceError(source, f"{where}.status", f"{status!r:.60} is not a status or a list of them",
                                 ", ".join(STATUSES))
    na_when = table.get("na_when", [])
    if isinstance(na_when, str):
        na_when = [na_when]
    if not isinstance(na_when, list) or any(f not in FLAGS for f in na_when):
        raise ToleranceError(source, f"{where}.na_when", f"{na_when!r:.60} is not a flag or a list of them",
                             ", ".join(FLAGS))
    bound = Bound(**patterns, dt=dt, **numbers, statuses=statuses, reason=reason.strip(), where=f"{source}: {where}",
                  order=index, na_when=tuple(na_when), against_self=reference == SELF_REFERENCE, source=source)
    if not bound.bounds_a_number and status is None:
        raise ToleranceError(source, where, "bounds nothing", "max, min, expected or status")
    empty = _empty(bound)
    if empty:
        key, problem, allowed = empty
        raise ToleranceError(source, f"{where}.{key}", problem, allowed)
    return bound


def _empty(bound: Bound) -> tuple[str, str, str] | None:
    """(key, problem, allowed) when ``bound`` holds no value its rows could have (an empty interval, every value
    below 0 for a metric that is never negative) or scales by a meaningless power of dt; None when it means
    something. With ``dt_power`` and a ``band`` the interval depends on dt: only ``min > max`` is then decided."""
    if bound.dt_power is not None and not abs(bound.dt_power) <= DT_POWER_MAX:
        return "dt_power", f"{bound.dt_power!r} is no scheme's order", (
            f"-{DT_POWER_MAX:g} to {DT_POWER_MAX:g}: a scheme's error C dt^p has p its order (8 at most), a rounding "
            "floor's -1")
    if bound.rel is not None and bound.rel > REL_MAX:
        return "rel", f"{bound.rel:g} is more than the expected value itself", (
            f"0 to {REL_MAX:g}, a share of |expected| (beyond it the band takes in the other sign: use band, min or max)")
    if bound.min is not None and bound.max is not None and bound.min > bound.max:
        return "min", f"min {bound.min:g} > max {bound.max:g}: the bound in [{bound.min:g}, {bound.max:g}] holds no value", \
            "min <= max"
    scale_free = bound.dt_power is None or not bound.band  # every limit then scales alike (or not at all)
    low, high = bound.limits(math.nan)
    key = "expected" if bound.expected is not None else "max" if bound.max is not None else "min"
    if scale_free and low > high:
        return key, f"the bound in [{low:.3g}, {high:.3g}] holds no value", (
            "limits that leave a value: expected +- band or rel inside [min, max]")
    if non_negative(bound.metric) and bound.bounds_a_number and (high < 0 if scale_free else
                                                                  bound.max is not None and bound.max < 0):
        return key, (f"{bound.describe(math.nan)} holds no value of {bound.metric!r:.60}, which is never "
                     "negative"), "limits that admit a value >= 0 (an error, drift, residual, time or rate is >= 0)"
    return None


CHECK_ENGINES, REQUIRE_ENGINES = "check_engines", "require_engines"
"""Top-level keys of a tolerances file naming engines: those the gate holds (the others' violations are findings,
never blocking; default: every engine of the run) and those it requires to have measured something."""
ENGINE_KEYS = (CHECK_ENGINES, REQUIRE_ENGINES)


@dataclass(frozen=True)
class EngineNames:
    """Engines named for the gate (:data:`ENGINE_KEYS`), and where: ``file: check_engines`` or ``--check-engines``."""

    names: tuple[str, ...]
    where: str


@dataclass(frozen=True)
class Gate:
    """What a tolerances file asks: its bounds (with those of the files it extends), and the engines it holds and
    requires (the nearest file in the ``extends`` chain that names them; None: not named)."""

    bounds: list[Bound]
    check_engines: EngineNames | None = None
    require_engines: EngineNames | None = None


def load_tolerances(path: str | Path = DEFAULT_TOLERANCES) -> list[Bound]:
    """The bounds of a tolerances file and of the files it extends (module docstring), each with its layer;
    raises :class:`ToleranceError` naming the file and key."""
    return load_gate(path).bounds


def load_gate(path: str | Path = DEFAULT_TOLERANCES) -> Gate:
    """A tolerances file's bounds (:func:`load_tolerances`) and the engines it holds and requires."""
    return _load(Path(path), ())


def _load(path: Path, chain: tuple[Path, ...]) -> Gate:
    source = str(path)
    try:
        data = read_toml(source, what="tolerances file")
    except SceneError as err:  # the file itself: missing, not a regular file, too large, not TOML
        raise ToleranceError(err.source, err.key, err.problem, err.allowed) from None
    unknown = sorted(set(data) - {"bound", "extends", *ENGINE_KEYS})
    if unknown:
        kind = "table" if isinstance(data[unknown[0]], (dict, list)) else "key"
        raise ToleranceError(source, unknown[0][:80], f"unknown {kind}",
                             "[[bound]] tables, extends = ..., " + " = [...], ".join(ENGINE_KEYS) + " = [...]")
    base = _extended(path, data.get("extends", _default_extends(path)), chain + (_resolved(path),))
    tables = data.get("bound", [])
    if isinstance(tables, list) and len(base.bounds) + len(tables) > MAX_BOUNDS:
        raise ToleranceError(source, "bound", f"{len(tables):,} bounds" + (
            f" and {len(base.bounds):,} in the files it extends" if base.bounds else ""), f"at most {MAX_BOUNDS:,} "
            "bounds in a file and the files it extends together (a blessed run of every built-in suite has ~40,000)")
    inherits = "extends" in data or any(key in data for key in ENGINE_KEYS)
    if not isinstance(tables, list) or not (tables or (inherits and base.bounds)):
        raise ToleranceError(source, "bound", "no bounds", "one or more [[bound]] tables, or extends = a file that has some")
    layer, shipped = max((b.layer for b in base.bounds), default=-1) + 1, _resolved(path) == _resolved(DEFAULT_TOLERANCES)
    bounds = [replace(_bound(source, i, table), layer=layer, shipped=shipped) for i, table in enumerate(tables)]
    named = {key: _engine_names(source, key, data[key]) if key in data else getattr(base, key) for key in ENGINE_KEYS}
    return Gate(base.bounds + bounds, **named)


def _engine_names(source: str, key: str, value) -> EngineNames:
    """A list of engine names (as the run's ``engine`` column spells them)."""
    if not isinstance(value, list) or not value or not all(isinstance(n, str) and n.strip() for n in value):
        raise ToleranceError(source, key, f"expected a list of engine names, got {value!r:.60}",
                             'a non-empty list of engine names as the run\'s rows spell them, e.g. ["core", "myengine"]')
    return EngineNames(tuple(dict.fromkeys(n.strip() for n in value)), f"{source}: {key}")


def _resolved(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError):  # a symlink loop: read_toml names the problem
        return path.absolute()


def _default_extends(path: Path) -> str:
    """What a file without ``extends`` extends: nothing for the shipped file, the shipped file for any other."""
    return EXTENDS_NONE if _resolved(path) == _resolved(DEFAULT_TOLERANCES) else EXTENDS_DEFAULT


def _extended(path: Path, extends, chain: tuple[Path, ...]) -> Gate:
    """What the file ``extends`` names asks (relative to ``path``'s folder); nothing for ``none``."""
    allowed = f'"{EXTENDS_DEFAULT}" (the shipped tolerances), "{EXTENDS_NONE}" or a tolerances file\'s path'
    if not isinstance(extends, str) or not extends.strip():
        raise ToleranceError(str(path), "extends", f"expected text, got {extends!r:.60}", allowed)
    if extends == EXTENDS_NONE:
        return Gate([])
    target = DEFAULT_TOLERANCES if extends == EXTENDS_DEFAULT else path.parent / extends
    if _resolved(target) in chain:
        raise ToleranceError(str(path), "extends", f"{extends!r:.80} closes a loop of extends", allowed)
    if not target.is_file():
        problem = "not a regular file" if target.exists() else "no such file"
        raise ToleranceError(str(path), "extends", f"{extends!r:.80}: {problem} ({one_line(target)})", allowed)
    if len(chain) >= MAX_EXTENDS_DEPTH:
        raise ToleranceError(str(path), "extends", f"more than {MAX_EXTENDS_DEPTH} files in a chain of extends",
                             allowed)
    try:
        return _load(target, chain)
    except ToleranceError as err:  # the message names the file the user gave, and the file its extends reached
        raise ToleranceError(str(path), "extends", f"{extends!r:.80}: {one_line(err.source)}: {err.key}: "
                             f"{err.problem}", err.allowed) from None


def matching_bounds(bounds: list[Bound], scene: str, engine: str, integrator: str, metric: str,
                    dt: float = math.nan, scheme: str = "", own_reference: bool = False) -> list[Bound]:
    """Every bound that matches a row, the deciding one first (highest :attr:`Bound.precedence`)."""
    return BoundIndex(bounds).matching(scene, engine, integrator, metric, dt, scheme, own_reference)


def bound_for(bounds: list[Bound], scene: str, engine: str, integrator: str, metric: str,
              dt: float = math.nan, scheme: str = "", own_reference: bool = False) -> Bound | None:
    """The bound that decides a row (highest :attr:`Bound.precedence` among those that match), or None."""
    return BoundIndex(bounds).decider(scene, engine, integrator, metric, dt, scheme, own_reference)
