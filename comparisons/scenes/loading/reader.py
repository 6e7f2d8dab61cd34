"""Typed access to the tables of a scene file (:class:`TableReader`), and the limits every kind shares."""

from __future__ import annotations

import math

import numpy as np

from simparity.comparisons.scenes.limits import DEFAULT_LIMITS, Limits, allowed_at_most
from simparity.core.model.errors import SceneError, echo
from simparity.core.model.names import NAME_RULE, TEXT_RULE, name_problem, text_problem
from simparity.core.model.ranges import NORM_RANGES, RANGES, SUBNORMAL_RULE, safe_norm, subnormal

MAX_SEED = 2**63 - 1
"""The largest seed a scene may give (a seeded sampler takes any int64 >= 0)."""
SAMPLES_WHY = "; simparity run --max-samples N raises it"
"""Ends the refusal of a count of samples, configurations, states or targets above the limit."""

_REQUIRED = object()  # marks a key without a default


class TableReader:
    """Typed access to one table of a scene file, with key paths for error messages."""

    def __init__(self, source: str, table: dict, path: str, allowed: tuple[str, ...], length_scale: float,
                 limits: Limits = DEFAULT_LIMITS) -> None:
        self.source, self.table, self.path, self.scale, self.limits = source, table, path, length_scale, limits
        unknown = sorted(set(table) - set(allowed))
        if unknown:
            raise SceneError(source, self._key(unknown[0]), "unknown key", ", ".join(allowed))

    def _key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def fail(self, key: str, problem: str, allowed: str) -> SceneError:
        """The error for ``key``: what was wrong and what is allowed (every rejection says both)."""
        return SceneError(self.source, self._key(key), problem, allowed)

    def has(self, key: str) -> bool:
        return key in self.table

    def _get(self, key: str, default, allowed: str):
        if key in self.table:
            return self.table[key]
        if default is _REQUIRED:
            raise self.fail(key, "missing required key", allowed)
        return default

    def string(self, key: str, default=None, choices: tuple[str, ...] | None = None) -> str:
        allowed = ", ".join(choices) if choices else "a non-empty string"
        value = self._get(key, _REQUIRED if default is None else default, allowed)
        if not isinstance(value, str) or not value:
            raise self.fail(key, f"expected a non-empty string, got {echo(value)}", allowed)
        if choices and value not in choices:
            raise self.fail(key, f"{echo(value)} is not allowed", allowed)
        return value

    def boolean(self, key: str, default: bool) -> bool:
        """A TOML boolean (``true`` / ``false``); ``default`` when the key is absent."""
        value = self._get(key, default, "true or false")
        if not isinstance(value, bool):
            raise self.fail(key, f"expected true or false, got {echo(value)}", "true or false")
        return value

    def text(self, key: str, default: str) -> str:
        """Free text for people (a description): one line of printable characters (:mod:`core.model.names`); ``default``
        when the key is absent."""
        if not self.has(key):
            return default
        value = self.string(key)
        problem = text_problem(value)
        if problem:
            raise self.fail(key, problem, TEXT_RULE)
        return value

    def name(self, key: str, default=None) -> str:
        """A string that names something (see :mod:`core.model.names`)."""
        value = self.string(key, default)
        problem = name_problem(value)
        if problem:
            raise self.fail(key, problem, NAME_RULE)
        return value

    def in_range(self, key: str, value: float) -> float:
        """``value`` (SI) if its magnitude is in the key's physical range (:data:`RANGES`)."""
        allowed = RANGES.get(key.rsplit(".", 1)[-1].split("[", 1)[0])
        if allowed is not None and not allowed.allows(abs(value)):
            raise self.fail(key, f"{value:.6g} is outside the physical range", allowed.text())
        return value

    def checked(self, key: str, value) -> float:
        """``value`` as a float if it is a finite, normal number (what every number of a scene file must be)."""
        return self._checked(key, value, False)

    def _checked(self, key: str, value, positive: bool) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(key, f"expected a number, got {echo(value)}", "a number" + (" > 0" if positive else ""))
        try:
            finite = math.isfinite(value)
        except OverflowError:
            finite = False
        if not finite:
            raise self.fail(key, f"{value!s:.30} is not finite", "finite numbers")
        if subnormal(value):
            raise self.fail(key, f"{value:.3g} is a subnormal number", SUBNORMAL_RULE)
        if positive and value <= 0:
            raise self.fail(key, f"{value} is not positive", "numbers > 0")
        return float(value)

    def number(self, key: str, default=None, *, positive=False, length=0) -> float:
        value = self._get(key, _REQUIRED if default is None else default, "a number" + (" > 0" if positive else ""))
        return self.in_range(key, self._checked(key, value, positive) * self.scale**length)

    def integer(self, key: str, default=None, *, minimum=0, maximum=2**63 - 1, why: str = "") -> int:
        value = self._get(key, _REQUIRED if default is None else default, f"whole numbers {minimum} to {maximum:,}")
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"expected a whole number, got {echo(value)}", f"whole numbers {minimum} to {maximum}")
        if not minimum <= value <= maximum:
            raise self.fail(key, f"{value} is out of range", f"whole numbers {minimum} to {maximum:,}{why}")
        return value

    def vector(self, key: str, size: int, default=None, *, length=0, nonzero=False, positive=False) -> np.ndarray:
        allowed = f"a list of {size} numbers"
        value = self._get(key, _REQUIRED if default is None else default, allowed)
        if not isinstance(value, list) or len(value) != size:
            got = f"{len(value):,} values" if isinstance(value, list) else echo(value)
            raise self.fail(key, f"expected a list of {size} numbers, got {got}", allowed)
        out = np.array([self._checked(f"{key}[{i}]", v, positive) for i, v in enumerate(value)])
        out *= self.scale**length
        if nonzero and not np.any(out):
            raise self.fail(key, "is all zeros", "a vector with a non-zero entry")
        norm_range = NORM_RANGES.get(key)
        if norm_range is not None and not norm_range.allows(norm := safe_norm(out)):
            raise self.fail(key, f"its norm {norm:.3g} is outside the usable range", norm_range.text())
        for i, v in enumerate(out):
            self.in_range(f"{key}[{i}]", v)
        return out

    def matrix(self, key: str, size: int, *, length=0) -> np.ndarray:
        allowed = f"{size} rows of {size} numbers"
        rows = self._get(key, _REQUIRED, allowed)
        if not isinstance(rows, list) or len(rows) != size:
            raise self.fail(key, f"expected {size} rows of {size} numbers", allowed)
        for i, row in enumerate(rows):
            if not isinstance(row, list) or len(row) != size:
                got = f"{len(row):,} values" if isinstance(row, list) else echo(row)
                raise self.fail(f"{key}[{i}]", f"expected a list of {size} numbers, got {got}", allowed)
        values = [[self._checked(f"{key}[{i}][{j}]", v, False) for j, v in enumerate(row)] for i, row in enumerate(rows)]
        return np.array(values) * self.scale**length

    def numbers(self, key: str) -> tuple[float, ...]:
        """A non-empty list of positive numbers."""
        value = self._get(key, _REQUIRED, "a list like [0.01, 0.02]")
        if not isinstance(value, list) or not value:
            raise self.fail(key, f"expected a non-empty list of numbers, got {echo(value)}", "a list like [0.01, 0.02]")
        return tuple(self.in_range(f"{key}[{i}]", self._checked(f"{key}[{i}]", v, True)) for i, v in enumerate(value))

    def strings(self, key: str, choices: tuple[str, ...], unknown: str = "{} is not allowed") -> tuple[str, ...]:
        """A non-empty list of distinct names, each one of ``choices`` (``unknown`` words the error)."""
        allowed = f"a list of distinct names from: {', '.join(choices)}"
        value = self._get(key, _REQUIRED, allowed)
        if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
            raise self.fail(key, f"expected a non-empty list of names, got {echo(value)}", allowed)
        for i, name in enumerate(value):
            if name not in choices:
                raise self.fail(f"{key}[{i}]", unknown.format(echo(name)), allowed)
            if name in value[:i]:
                raise self.fail(f"{key}[{i}]", f"{echo(name)} is given twice", allowed)
        return tuple(value)

    def subtable(self, key: str, allowed: tuple[str, ...]) -> "TableReader":
        """The table ``key``, which must be there."""
        found = self.optional_subtable(key, allowed)
        if found is None:
            raise self.fail(key, "missing required table", f"a [{self._key(key)}] table of {', '.join(allowed)}")
        return found

    def optional_subtable(self, key: str, allowed: tuple[str, ...]) -> "TableReader | None":
        """The table ``key``, or None when the file has none."""
        table = f"a [{self._key(key)}] table of {', '.join(allowed)}"
        if key not in self.table:
            return None
        value = self.table[key]
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a table, got {echo(value)}", table)
        return TableReader(self.source, value, self._key(key), allowed, self.scale, self.limits)

    def array_of_tables(self, key: str, allowed: tuple[str, ...], limit: str) -> list["TableReader"]:
        """One reader per ``[[key]]`` entry; at most the ``limit`` field of :class:`Limits`."""
        tables = f"[[{self._key(key)}]] entries"
        value = self._get(key, _REQUIRED, tables)
        if not isinstance(value, list) or not value or not all(isinstance(v, dict) for v in value):
            raise self.fail(key, "expected one or more tables", tables)
        if len(value) > getattr(self.limits, limit):
            raise self.fail(key, f"{len(value):,} entries", allowed_at_most(self.limits, limit))
        return [TableReader(self.source, v, f"{self._key(key)}[{i}]", allowed, self.scale, self.limits)
                for i, v in enumerate(value)]
