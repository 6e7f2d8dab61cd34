"""Bounds looked up by row without scanning them all: matching costs what the matching bounds cost, not bounds x rows.

Bounds with the same keys (scene, engine, integrator, metric, scheme, dt, reference) are one *group*, matched once.
Each key has an index from the row's value to the groups whose pattern for that key matches it: a name written out
by a dictionary, an fnmatch pattern under its text before the first wildcard (a value can only match a pattern it
begins with), a time step by bisection. A row's candidates are the groups of its most selective key (the one whose
matching patterns hold the fewest groups); only they are matched on every key. Each distinct value is looked up once
per key: a run's rows repeat a few hundred names. :attr:`BoundIndex.attempts` counts the groups matched, what a test
holds linear.
"""

from __future__ import annotations

import bisect
import fnmatch
import heapq
import math
from typing import TYPE_CHECKING, Hashable

from simparity.comparisons.gate.metric_names import WILDCARDS
from simparity.core.model.derivatives import ANALYTIC, DIFFERENCE_KINDS

if TYPE_CHECKING:
    from simparity.comparisons.gate.tolerances import Bound

PATTERN_KEYS = ("scene", "engine", "integrator", "metric")
DT_MATCH = 1e-9
"""Relative difference under which a bound's ``dt`` [s] names a row's time step."""
ROUNDING = 1e-15
"""Relative rounding of a division, by which a step's search interval is widened."""


def literal_head(pattern: str) -> str:
    """The text of ``pattern`` before its first wildcard (all of it for a name written out)."""
    return WILDCARDS.split(pattern, maxsplit=1)[0]


class PatternIndex:
    """Items (groups of bounds, or the patterns themselves) by an fnmatch pattern each has; an item may have several
    (a list of schemes)."""

    def __init__(self) -> None:
        self._by_name: dict[str, list] = {}
        self._by_head: dict[str, dict[str, list]] = {}  # literal head -> pattern -> items
        self._found: dict[str, tuple] = {}

    def add(self, pattern: str, group) -> None:
        if WILDCARDS.search(pattern):
            self._by_head.setdefault(literal_head(pattern), {}).setdefault(pattern, []).append(group)
        else:
            self._by_name.setdefault(pattern, []).append(group)

    def groups(self, value: str) -> tuple:
        """Every item one of whose patterns matches ``value``, each once."""
        if value not in self._found:
            found = list(self._by_name.get(value, ()))
            for end in range(len(value) + 1):
                for pattern, groups in self._by_head.get(value[:end], {}).items():
                    if fnmatch.fnmatchcase(value, pattern):
                        found += groups
            self._found[value] = tuple(dict.fromkeys(found))
        return self._found[value]


class _StepIndex:
    """Groups by the time step they hold: every row (None), every row with a step ("*"), or one step [s]."""

    def __init__(self, match: float) -> None:
        self._match = match
        self._every: list[int] = []
        self._stepped: list[int] = []
        self._steps: list[tuple[float, int]] = []
        self._keys: list[float] = []
        self._found: dict[float, tuple[int, ...]] = {}

    def add(self, dt: float | str | None, group: int) -> None:
        if dt is None:
            self._every.append(group)
        elif dt == "*":
            self._stepped.append(group)
        else:
            self._steps.append((float(dt), group))

    def close(self) -> None:
        self._steps.sort()
        self._keys = [dt for dt, _ in self._steps]

    def groups(self, dt: float) -> tuple[int, ...]:
        """Every group that may hold a row at ``dt`` [s] (NaN: an order row, which has none)."""
        if math.isnan(dt):
            return tuple(self._every)
        if dt not in self._found:
            # a bound's step b names dt when |dt - b| <= match * b: b within [dt / (1 + match), dt / (1 - match)],
            # widened by a rounding of each side (Bound.matches decides)
            low = bisect.bisect_left(self._keys, dt / (1 + self._match) * (1 - ROUNDING))
            high = bisect.bisect_right(self._keys, dt / (1 - self._match) * (1 + ROUNDING))
            self._found[dt] = tuple(self._every + self._stepped + [group for _, group in self._steps[low:high]])
        return self._found[dt]


DERIVATIVE_KINDS = (ANALYTIC, *DIFFERENCE_KINDS.values())
"""The scheme kinds a derivative row's scheme ends with (core.model.derivatives)."""


def case_schemes(scheme: str) -> tuple[str, ...]:
    """The labels a bound's ``scheme`` may match for a row of scheme ``scheme``: itself, and for a derivative row
    ("rk4+analytic_derivatives": its case's scheme joined with what its derivatives declare) also its case's, so that
    a bound keyed by the case's scheme (a hard case's verdict) holds its derivative rows too."""
    case, _, kind = scheme.rpartition("+")
    return (scheme, case) if case and kind in DERIVATIVE_KINDS else (scheme,)


class BoundIndex:
    """The bounds of a tolerances file (and the files it extends), found by row (module docstring)."""

    def __init__(self, bounds: list[Bound], dt_match: float = DT_MATCH) -> None:
        groups: dict[Hashable, list[Bound]] = {}
        for bound in bounds:
            groups.setdefault(_group_key(bound), []).append(bound)
        self._groups = [sorted(members, key=lambda b: b.precedence, reverse=True) for members in groups.values()]
        self._patterns = {key: PatternIndex() for key in PATTERN_KEYS + ("scheme",)}
        self._steps = _StepIndex(dt_match)
        for number, members in enumerate(self._groups):
            first = members[0]
            for key in PATTERN_KEYS:
                self._patterns[key].add(getattr(first, key), number)
            for pattern in first.scheme:
                self._patterns["scheme"].add(pattern, number)
            self._steps.add(first.dt, number)
        self._steps.close()
        self._bounds = bounds
        self.attempts = 0
        """Groups matched against a row on every key so far: the cost of matching."""
        self._matched: set[int] = set()

    def _matching_groups(self, scene: str, engine: str, integrator: str, metric: str, dt: float, scheme: str,
                         own_reference: bool) -> list[list[Bound]]:
        """The groups that match a row (each sorted, the deciding bound first), noted as having matched one."""
        values = {"scene": scene, "engine": engine, "integrator": integrator, "metric": metric}
        choices = [self._patterns[key].groups(value) for key, value in values.items()] + [self._steps.groups(dt)]
        choices.append(tuple(dict.fromkeys(number for label in case_schemes(scheme)
                                           for number in self._patterns["scheme"].groups(label))))
        candidates = min(choices, key=len)
        self.attempts += len(candidates)
        found = [number for number in candidates
                 if self._groups[number][0].matches(scene, engine, integrator, metric, dt, scheme, own_reference)]
        self._matched.update(found)
        return [self._groups[number] for number in found]

    def matching(self, scene: str, engine: str, integrator: str, metric: str, dt: float = math.nan,
                 scheme: str = "", own_reference: bool = False) -> list[Bound]:
        """Every bound that matches a row, the deciding one first (highest :attr:`Bound.precedence`)."""
        groups = self._matching_groups(scene, engine, integrator, metric, dt, scheme, own_reference)
        return list(heapq.merge(*groups, key=lambda b: b.precedence, reverse=True))

    def decider(self, scene: str, engine: str, integrator: str, metric: str, dt: float = math.nan,
                scheme: str = "", own_reference: bool = False) -> Bound | None:
        """The bound that decides a row (the first of :meth:`matching`), or None."""
        groups = self._matching_groups(scene, engine, integrator, metric, dt, scheme, own_reference)
        return max((members[0] for members in groups), key=lambda b: b.precedence, default=None)

    def unmatched(self) -> list[Bound]:
        """The bounds that matched no row looked up so far, in their order."""
        matched = {id(bound) for number in self._matched for bound in self._groups[number]}
        return [bound for bound in self._bounds if id(bound) not in matched]


def _group_key(bound: Bound) -> Hashable:
    """What a bound matches a row by: bounds with equal keys match the same rows."""
    return (bound.scene, bound.engine, bound.integrator, bound.metric, bound.scheme, bound.dt, bound.against_self)


def unmatched_patterns(patterns, values) -> set[str]:
    """The ``patterns`` none of ``values`` matches (each value looked up once: values x patterns never arises)."""
    index = PatternIndex()
    for pattern in patterns:
        index.add(pattern, pattern)
    matched = {pattern for value in values for pattern in index.groups(value)}
    return set(patterns) - matched
