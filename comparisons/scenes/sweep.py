"""A scene file's ``[sweep]``: numeric keys of the same file and the values each takes, expanded into variants.

Each entry names a key of the file by its path (``"body[ball].restitution"``) and gives its values: a list, or
a range ``{start, stop, num}`` (linear; ``spacing = "log"`` for geometric steps). Several entries combine as
their Cartesian product, the first key varying slowest; ``combine = "zip"`` pairs their k-th values instead.
A variant is the file with its values written in, so :mod:`comparisons.scenes.loader` checks it exactly like a
file written by hand; this module only reads the ``[sweep]`` table, finds the keys and writes the values.
Format and path syntax: ``docs/scenes.md`` ("Sweeps").
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import cast

from simparity.core.model.errors import SceneError, echo
from simparity.core.model.names import NAME_MAX, name_problem
from simparity.core.model.scene import SweepPoint

SWEEP_TABLE = "sweep"
"""The top-level table of a scene file that declares a sweep."""

COMBINE_KEY = "combine"
COMBINES = ("product", "zip")
"""How the entries of a ``[sweep]`` combine (``combine = ...``, default ``product``)."""

MAX_VARIANTS = 1000
"""Variants one file may expand into. Each is a whole scene run by every engine and integrator: a run streams its
cases back one by one and keeps only those of the scenes not yet stored, and past
:data:`reports.sweep_compact.COMPACT_SWEEP_VARIANTS` variants the report shows their distribution, not a row each,
so the client's memory and the report stay bounded (``simparity bench``'s sweep rows: 1,000 variants of a thrown
ball, 2,000 cases, in 154 s on 2 cores, the client's peak 483 MiB). The limit is what a run's cost still justifies:
the 4 variants of the built-in ``restitution-sweep`` took 9 s on 2 cores, a real arm's IK scene takes minutes per
variant, so 1,000 of those are already a day; a bigger study is several files."""

MAX_KEYS = 6
"""Keys one ``[sweep]`` may name: each is a column of ``results.csv`` and an axis of the report's figures (one
figure per headline metric and swept key), and 6 keys of three values each are already 729 variants, near
:data:`MAX_VARIANTS`."""

_WHY_LIMIT = ("a fixed limit: each variant is a whole scene run by every engine and integrator; a bigger study is "
              "several files")
"""Why a sweep past :data:`MAX_VARIANTS` is refused, in its one-line message."""

RANGE_KEYS = ("start", "stop", "num", "spacing")
SPACINGS = ("linear", "log")

RANGE_DIGITS = 12
"""Significant digits a range's values are rounded to, so equal steps between decimal numbers give those
decimals (0.7, not 0.7000000000000001), while any two values a range of at most :data:`MAX_VARIANTS` could
tell apart stay apart."""

INTEGER_KEYS = ("configurations", "seed", "count", "max_iterations")
"""Keys the loader reads as whole numbers: their swept values must be whole, and stay ints."""
_MAX_WHOLE = 2**63 - 1
"""The largest whole number a swept whole-number key may take: the loader's largest seed."""

LADDER_KEYS = (("simulation", "dt"), ("simulation", "rate_hz"))
"""List-valued keys that may be swept whole: each variant runs at the one time step (or rate) it is given."""

REFUSED = {"scene": "what the scene is, not a number it runs with (a variant's name is derived from the values)",
           SWEEP_TABLE: "the sweep itself"}
"""Tables whose keys are never swept, and why."""

PATH_RULE = ("a key path of the file: table and key names joined by '.', an entry of an array of tables by its "
             "name or index in brackets (body[ball], plane[0], contact.pair[ball,floor]), an entry of a list of "
             "numbers by its index (position_world[2])")
VALUES_RULE = ("a non-empty list of distinct numbers, or a range {start = a, stop = b, num = n} (spacing = "
               '"log" for geometric steps; quote a dotted key: "simulation.dt" = [...])')

_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_SELECTOR = re.compile(r"\[([^\[\]]+)\]")
_INDEX = re.compile(r"[0-9]+")
_LABEL_CHARACTERS = re.compile(r"[^A-Za-z0-9_-]")


def _steps(path: str) -> list[tuple[str, str]] | None:
    """The steps of a key path: ("key", name) into a table, ("select", text) into a list; None if malformed."""
    steps, at = [], 0
    while True:
        key = _KEY.match(path, at)
        if key is None:
            return None
        steps.append(("key", key.group()))
        at = key.end()
        while (selector := _SELECTOR.match(path, at)) is not None:
            steps.append(("select", selector.group(1)))
            at = selector.end()
        if at == len(path):
            return steps
        if path[at] != ".":
            return None
        at += 1


def loader_key(location: tuple) -> str:
    """The key path the loader names a location by in its messages: ``body[0].position_world[2]``."""
    text = ""
    for part in location:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


@dataclass(frozen=True)
class SweepEntry:
    """One swept key: its path as written in ``[sweep]``, where it is in the file (``location``: the table keys
    and list indices from the file's top), the values it takes (ints for whole-number keys, else floats), and
    whether it is a ladder swept whole (each variant holds a list of one value)."""

    path: str
    location: tuple
    values: tuple
    whole_list: bool

    @property
    def key(self) -> str:
        return f"{SWEEP_TABLE}.{self.path}"

    def related(self, key: str) -> bool:
        """True when the loader's ``key`` is this entry's key, inside it, or the vector holding it."""
        mine = loader_key(self.location)
        return any(a == b or a.startswith(b + "[") or a.startswith(b + ".") for a, b in ((key, mine), (mine, key)))


class _Finder:
    """Finds the key a path names in a scene file's parsed TOML; failures name the sweep entry."""

    def __init__(self, source: str, path: str) -> None:
        self.source, self.path = source, path

    def fail(self, problem: str, allowed: str) -> SceneError:
        return SceneError(self.source, f"{SWEEP_TABLE}.{self.path}", problem, allowed)

    def find(self, data: dict) -> tuple[tuple, bool]:
        """(the location of the key, True when it is a ladder swept whole)."""
        steps = _steps(self.path)
        if steps is None:
            raise self.fail("not a key path", PATH_RULE)
        if steps[0][1] in REFUSED:
            raise self.fail(f"[{steps[0][1]}] is never swept: {REFUSED[steps[0][1]]}", "a numeric key of another table")
        node, location = data, cast(tuple[str, ...], ())
        for kind, text in steps:
            where = loader_key(location) or "the file's top level"
            if kind == "key":
                if not isinstance(node, dict):
                    raise self.fail(f"{where} is not a table, so it has no key {text}", PATH_RULE)
                if text not in node:
                    raise self.fail(f"the file sets no key {text} in {where} (a sweep replaces a value the file "
                                    "gives)", f"a key the file sets there: {', '.join(sorted(node))}")
                node, location = node[text], location + (text,)
            else:
                if not isinstance(node, list):
                    raise self.fail(f"{where} is not a list, so [{text}] selects nothing", PATH_RULE)
                index = self._select(node, text, where)
                node, location = node[index], location + (index,)
        whole_list = location in LADDER_KEYS
        if not whole_list and (isinstance(node, bool) or not isinstance(node, (int, float))):
            raise self.fail(f"{loader_key(location)} holds {self._what(node)}, not a number",
                            "a key holding one number" + (", e.g. " + self.path + "[0]" if isinstance(node, list)
                                                          and node and not isinstance(node[0], dict) else ""))
        return location, whole_list

    def _select(self, items: list, text: str, where: str) -> int:
        """The index of the entry ``[text]`` selects: an index, an entry's name, or a pair's ``body,plane``."""
        tables = all(isinstance(item, dict) for item in items)
        if _INDEX.fullmatch(text):
            index = int(text)
            if index >= len(items):
                entries = "1 entry" if len(items) == 1 else f"{len(items)} entries"
                raise self.fail(f"{where} has {entries}: there is no [{text}]",
                                f"an index from 0 to {len(items) - 1}")
            if tables and any(item.get("name") == text for k, item in enumerate(items) if k != index):
                raise self.fail(f"[{text}] is index {text} of {where} and the name of another entry",
                                "an index no entry has as its name, or the entry's own name")
            return index
        if not tables:
            raise self.fail(f"{where} is a list of values: [{text}] is not an index", "a whole-number index from 0")
        if "," in text:
            body, plane = text.split(",", 1)
            matches = [k for k, item in enumerate(items) if item.get("body") == body and item.get("plane") == plane]
            rule = "a pair's body,plane as the file writes them, or its index"
        else:
            matches = [k for k, item in enumerate(items) if item.get("name") == text]
            rule = "an entry's name as the file writes it, or its index"
        if len(matches) != 1:
            raise self.fail(f"{len(matches) or 'no'} entries of {where} match [{text}]", rule)
        return matches[0]

    @staticmethod
    def _what(node) -> str:
        if isinstance(node, dict):
            return "a table"
        if isinstance(node, list):
            return f"a list of {len(node)} values"
        return f"the value {echo(node)}"


def _number(fail, where: str, value, integer: bool) -> int | float:
    """A listed or range value: finite, whole for an integer key (then an int)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise fail(where, f"expected a number, got {echo(value)}", VALUES_RULE)
    if integer and not isinstance(value, int):
        raise fail(where, f"{value!r} is not a whole number", "whole numbers for a whole-number key (a seed, a count)")
    if integer:
        if abs(value) > _MAX_WHOLE:
            raise fail(where, f"{echo(value, 30)} is out of range", f"whole numbers up to {_MAX_WHOLE:,} in magnitude")
        return value
    try:
        number = float(value)
    except OverflowError:  # a TOML integer of hundreds of digits
        number = math.inf
    if not math.isfinite(number):
        raise fail(where, f"{echo(value, 30)} is not a finite float", "finite numbers")
    return number


def _rounded(value: float) -> float:
    return float(f"{value:.{RANGE_DIGITS}g}")


def _range(fail, spec: dict, integer: bool) -> tuple:
    """The values of a range table: ``num`` from ``start`` to ``stop`` inclusive, in equal steps (linear) or
    equal ratios (log); inner values rounded to :data:`RANGE_DIGITS`, or whole for an integer key."""
    unknown = sorted(set(spec) - set(RANGE_KEYS))
    if unknown:
        raise fail("", f"{echo(unknown[0])} is not a range key", VALUES_RULE)
    for key in ("start", "stop", "num"):
        if key not in spec:
            raise fail("", f"the range has no {key}", VALUES_RULE)
    start = _number(fail, "range start: ", spec["start"], integer)
    stop = _number(fail, "range stop: ", spec["stop"], integer)
    num = spec["num"]
    if isinstance(num, bool) or not isinstance(num, int) or not 2 <= num <= MAX_VARIANTS:
        raise fail("range num: ", f"{echo(num)} values", f"a whole number from 2 to {MAX_VARIANTS:,} ({_WHY_LIMIT})")
    spacing = spec.get("spacing", "linear")
    if spacing not in SPACINGS:
        raise fail("range spacing: ", f"{echo(spacing)} is not a spacing", ", ".join(SPACINGS))
    if start == stop:
        raise fail("", f"start and stop are both {start:g}", "a range from one number to another")
    steps = range(1, num - 1)
    inner: list
    if spacing == "log":
        if start <= 0 or stop <= 0:
            raise fail("", f"a log range from {start:g} to {stop:g} reaches zero or below",
                       'start and stop > 0 for spacing = "log"')
        low, high = math.log(start), math.log(stop)
        inner = [_rounded(math.exp(low + (high - low) * k / (num - 1))) for k in steps]
    elif integer:
        inner = [start + Fraction(cast(int, stop - start) * k, num - 1) for k in steps]   # exact: a seed may need 19 digits
    else:
        inner = [_rounded(start + (stop - start) * k / (num - 1)) for k in steps]
    values = [start] + inner + [stop]
    if not all(math.isfinite(v) for v in values):
        raise fail("", f"the steps from {start:g} to {stop:g} overflow", "a range whose steps are finite numbers")
    if len(set(values)) < len(values):
        raise fail("", f"{num} values from {value_text(start)} to {value_text(stop)} are too close to tell apart "
                   f"at {RANGE_DIGITS} significant digits", f"a range whose values differ in the first {RANGE_DIGITS} "
                   "digits, or a list of the values")
    if integer:
        fractional = next((v for v in values if v != round(v)), None)
        if fractional is not None:
            raise fail("", f"gives {float(fractional):g}, not a whole number", "start, stop and num whose steps are "
                       "whole numbers, for a whole-number key (a seed, a count)")
        return tuple(int(round(v)) for v in values)
    return tuple(values)


def _values(source: str, path: str, spec, integer: bool) -> tuple:
    """The values of one entry, checked: numbers, distinct, at most :data:`MAX_VARIANTS`."""
    def fail(where: str, problem: str, allowed: str) -> SceneError:
        return SceneError(source, f"{SWEEP_TABLE}.{path}", f"{where}{problem}", allowed)

    if isinstance(spec, dict):
        values = _range(fail, spec, integer)
    elif isinstance(spec, list):
        if not spec:
            raise fail("", "an empty list", VALUES_RULE)
        if len(spec) > MAX_VARIANTS:
            raise fail("", f"{len(spec):,} values", f"at most {MAX_VARIANTS:,} ({_WHY_LIMIT})")
        values = tuple(_number(fail, f"value {i + 1} of the list: ", v, integer) for i, v in enumerate(spec))
    else:
        raise fail("", f"expected a list of numbers or a range table, got {echo(spec)}", VALUES_RULE)
    for i, value in enumerate(values):
        if value in values[:i]:
            raise fail("", f"the value {value!r} is given twice", "distinct values")
    return values


def value_text(value: int | float) -> str:
    """A swept value as a variant's name shows it: Python's repr (reads back as the same number, so distinct
    values have distinct texts), ``e+`` as ``e`` (``1e+20`` -> ``1e20``: ``+`` is no name character)."""
    return str(value) if isinstance(value, int) else repr(value).replace("e+", "e")


def _labels(paths: list[str]) -> list[str]:
    """The shortest trailing part of each path that no other path ends in, in name characters: a key with
    its selectors is one part (``body[ball].restitution`` -> ``restitution``, or ``body.ball.restitution``
    beside ``contact.restitution``)."""
    parts = []
    for path in paths:
        groups: list[list[str]] = []
        for kind, text in cast(list[tuple[str, str]], _steps(path)):  # checked well-formed when read
            if kind == "key":
                groups.append([text])
            else:
                groups[-1].append(_LABEL_CHARACTERS.sub("_", text))
        parts.append([".".join(group) for group in groups])
    lengths = [1] * len(paths)
    while True:
        labels = [".".join(p[-n:]) for p, n in zip(parts, lengths)]
        shared = [k for k, label in enumerate(labels) if labels.count(label) > 1 and lengths[k] < len(parts[k])]
        if not shared:
            return labels
        for k in shared:
            lengths[k] += 1


@dataclass(frozen=True)
class Sweep:
    """A file's ``[sweep]``, checked against the file: the keys it sweeps and how they combine.

    Attributes
    ----------
    source : str
        The scene file.
    base : str
        The name the file gives its scene.
    entries : tuple of SweepEntry
        The swept keys in the table's order.
    combine : str
        ``product`` or ``zip`` (:data:`COMBINES`).
    """

    source: str
    base: str
    entries: tuple[SweepEntry, ...]
    combine: str

    def combinations(self) -> list[tuple]:
        """The values of every variant, in the sweep's order (the first key varies slowest)."""
        columns = [entry.values for entry in self.entries]
        return list(zip(*columns)) if self.combine == "zip" else list(itertools.product(*columns))

    def names(self) -> list[str]:
        """Each variant's name: the base name and ``_label-value`` per key (``ball_restitution-0.5``), or the
        base name and the variant's number where those would not make distinct valid names."""
        labels = _labels([entry.path for entry in self.entries])
        combinations = self.combinations()
        names = [self.base + "".join(f"_{label}-{value_text(v)}" for label, v in zip(labels, values))
                 for values in combinations]
        if len(set(names)) == len(names) and not any(name_problem(name) for name in names):
            return names
        width = len(str(len(combinations)))
        return [f"{self.base[:NAME_MAX - width - 1]}_{k + 1:0{width}d}" for k in range(len(combinations))]

    def variants(self, data: dict) -> list[tuple[str, dict, SweepPoint]]:
        """(name, the file's data with the variant's values written in, its sweep point) of every variant."""
        combinations = self.combinations()
        out = []
        for k, (name, values) in enumerate(zip(self.names(), combinations)):
            variant = data
            for entry, value in zip(self.entries, values):
                variant = _with_value(variant, entry.location, [value] if entry.whole_list else value)
            swept = tuple((entry.path, value) for entry, value in zip(self.entries, values))
            out.append((name, variant, SweepPoint(self.base, swept, k, len(combinations))))
        return out

    def refusal(self, err: SceneError, point: SweepPoint) -> SceneError:
        """A variant's error, naming the sweep key (or every key of the variant) and the value that caused it."""
        related = [k for k, entry in enumerate(self.entries) if entry.related(err.key)]
        at = f"variant {point.index + 1} of {point.count}"
        if len(related) == 1:
            entry, value = self.entries[related[0]], point.values[related[0]][1]
            others = [f"{key} = {value_text(v)}" for k, (key, v) in enumerate(point.values) if k != related[0]]
            at += f", with {', '.join(others)}" if others else ""
            return SceneError(self.source, entry.key, f"{value_text(value)} ({at}): {err.key}: {err.problem}",
                              err.allowed)
        values = ", ".join(f"{key} = {value_text(value)}" for key, value in point.values)
        return SceneError(self.source, SWEEP_TABLE, f"{at} ({values}): {err.key}: {err.problem}", err.allowed)


def _with_value(data, location: tuple, value):
    """``data`` with ``value`` at ``location``: the tables and lists along the way copied, the rest shared."""
    if not location:
        return value
    head, rest = location[0], location[1:]
    copy = dict(data) if isinstance(data, dict) else list(data)
    copy[head] = _with_value(data[head], rest, value)
    return copy


def read_sweep(table, data: dict, source: str, base: str) -> Sweep:
    """The ``[sweep]`` table ``table`` of the file ``source`` (parsed TOML ``data``, scene named ``base``), checked:
    every key found in the file, every value a number, at most :data:`MAX_KEYS` keys and :data:`MAX_VARIANTS`
    variants. Raises SceneError naming the sweep key."""
    if not isinstance(table, dict):
        raise SceneError(source, SWEEP_TABLE, f"expected a table, got {echo(table)}",
                         '[sweep] with entries like "contact.restitution" = [0.5, 0.8]')
    combine = table.get(COMBINE_KEY, "product")
    if combine not in COMBINES:
        raise SceneError(source, f"{SWEEP_TABLE}.{COMBINE_KEY}", f"{echo(combine)} is not allowed", ", ".join(COMBINES))
    paths = [path for path in table if path != COMBINE_KEY]
    if not paths:
        raise SceneError(source, SWEEP_TABLE, "sweeps no key",
                         'one or more entries like "contact.restitution" = [0.5, 0.8]')
    if len(paths) > MAX_KEYS:
        raise SceneError(source, SWEEP_TABLE, f"{len(paths)} keys", f"at most {MAX_KEYS} (a fixed limit: each key is "
                         "a column of results.csv and an axis of the report's figures)")
    entries: list = []
    seen: dict = {}
    for path in paths:
        spec = table[path]
        if isinstance(spec, dict) and spec and not set(spec) & set(RANGE_KEYS):
            nested = next(iter(spec))
            raise SceneError(source, f"{SWEEP_TABLE}.{path}", f"a table of {', '.join(map(echo, list(spec)[:5]))}, "
                             f"not a range: TOML reads a bare dotted key ({path}.{nested} = ...) as nested tables",
                             f'the key path in quotes: "{path}.{nested}" = [...]')
        location, whole_list = _Finder(source, path).find(data)
        if location in seen:
            raise SceneError(source, f"{SWEEP_TABLE}.{path}", f"the key {seen[location]} sweeps too",
                             "each key of the file swept once")
        seen[location] = path
        integer = next(part for part in reversed(location) if isinstance(part, str)) in INTEGER_KEYS
        entries.append(SweepEntry(path, location, _values(source, path, spec, integer), whole_list))
    counts = [len(entry.values) for entry in entries]
    if combine == "zip" and len(set(counts)) > 1:
        raise SceneError(source, SWEEP_TABLE, f"zips keys of {', '.join(map(str, counts))} values",
                         'the same number of values for every key with combine = "zip"')
    total = counts[0] if combine == "zip" else math.prod(counts)
    if total > MAX_VARIANTS:
        raise SceneError(source, SWEEP_TABLE, f"{' x '.join(map(str, counts))} = {total:,} variants",
                         f"at most {MAX_VARIANTS:,} variants ({_WHY_LIMIT})")
    return Sweep(source, base, tuple(entries), combine)
