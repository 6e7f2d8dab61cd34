"""A JSON file read as input: of bounded size, nesting and integer length, then held to a declared shape.

Python's ``json`` recurses once per level of nesting (100,000 levels: ``RecursionError``) and parses integers of
any length until ``int`` refuses (more than 4,300 digits: ``ValueError``); :func:`read_json` refuses both before
either happens. A :class:`Shape` says what each key holds (text, a whole number, a table of ..., a list of ...); the
first key that holds something else is named (``scenes.drop.bodies``), with what it holds and what is allowed.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simparity.core.model.errors import echo, one_line
from simparity.core.model.files import file_problem

MAX_JSON_DEPTH = 32
"""Deepest nesting of tables and lists a JSON input may have [levels]: ``run.json`` nests 6 deep
(scenes / scene / contact / restitution / row); ``json`` and ``dataclasses`` recurse once per level."""
MAX_INTEGER_DIGITS = 40
"""Longest integer a JSON input may spell [digits]: the largest integers simparity records are 64-bit seeds and
byte counts (at most 20 digits); Python refuses more than 4,300 with a ValueError."""

_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)
_OPEN, _CLOSE = (np.frombuffer(b"[{", np.uint8), np.frombuffer(b"]}", np.uint8))


class JSONInputError(Exception):
    """Why a JSON input was refused, in words to follow its file's name (``key: problem (allowed: ...)``)."""


def nesting_depth(text: str) -> int:
    """The deepest nesting of ``[`` and ``{`` in JSON ``text`` outside its strings [levels]; vectorised, no recursion."""
    codes = np.frombuffer(_STRING.sub('""', text).encode("utf-8"), np.uint8)
    steps = np.isin(codes, _OPEN).astype(np.int64) - np.isin(codes, _CLOSE)
    return int(np.cumsum(steps).max(initial=0))


def _integer(text: str) -> int:
    if len(text.lstrip("-")) > MAX_INTEGER_DIGITS:
        raise JSONInputError(f"an integer of {len(text.lstrip('-')):,} digits (allowed: at most {MAX_INTEGER_DIGITS})")
    return int(text)


def read_json(path: Path, max_bytes: int, allowed: str) -> object:
    """The parsed JSON of the regular file ``path`` [at most ``max_bytes`` bytes, :data:`MAX_JSON_DEPTH` deep,
    integers of at most :data:`MAX_INTEGER_DIGITS` digits]; raises :class:`JSONInputError` saying what was wrong,
    ``allowed`` describing the file expected."""
    problem = file_problem(path)
    if problem:
        raise JSONInputError(f"{problem} (allowed: {allowed})")
    try:
        with open(path, "rb") as handle:
            data = handle.read(max_bytes + 1)
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise JSONInputError(f"unreadable: {one_line(err)} (allowed: {allowed})") from None
    if len(data) > max_bytes:
        raise JSONInputError(f"more than {max_bytes:,} bytes (allowed: {allowed})")
    depth = nesting_depth(text)
    if depth > MAX_JSON_DEPTH:
        raise JSONInputError(f"nested {depth:,} levels deep (allowed: at most {MAX_JSON_DEPTH}; {allowed})")
    try:
        value = json.loads(text, parse_int=_integer, parse_constant=_constant, object_pairs_hook=_table)
    except json.JSONDecodeError as err:
        raise JSONInputError(f"not JSON: {one_line(err)} (allowed: {allowed})") from None
    except _NotJSON as err:
        raise JSONInputError(f"{err} (allowed: {allowed})") from None
    lone = _lone_surrogate(value)
    if lone is not None:
        raise JSONInputError(f"text holding a lone surrogate escape {lone!r:.40} (allowed: {allowed}, UTF-8 text)")
    return value


class _NotJSON(JSONInputError):
    """A value JSON does not have, or a table JSON leaves ambiguous (the file's ``allowed`` is added to it)."""


def _constant(name: str) -> float:
    """``NaN``, ``Infinity``, ``-Infinity``: not JSON (Python's writer alone emits them), never a run's value."""
    raise _NotJSON(f"{name}, which is not JSON")


def _table(pairs: list[tuple[str, object]]) -> dict:
    """A JSON object whose keys are distinct (a repeated key would be read as its last value, silently)."""
    table = dict(pairs)
    if len(table) != len(pairs):
        seen: set[str] = set()
        twice = next(key for key, _ in pairs if key in seen or seen.add(key))  # type: ignore[func-returns-value]
        raise _NotJSON(f"the key {twice!r:.40} given twice")
    return table


def _lone_surrogate(value: object) -> str | None:
    """The first text (key or value) in ``value`` holding a lone UTF-16 surrogate (``"\\ud800"``), else None: it
    cannot be written back as UTF-8."""
    stack = [value]
    while stack:
        item = stack.pop()
        texts: list[object] = []
        if isinstance(item, dict):
            texts, stack = list(item), stack + list(item.values())
        elif isinstance(item, list):
            stack += item
        else:
            texts = [item]
        for text in texts:
            if isinstance(text, str):
                try:
                    text.encode("utf-8")
                except UnicodeEncodeError:
                    return text
    return None


@dataclass(frozen=True)
class Shape:
    """What a JSON value must be: ``accepts(value)`` true, described by ``text``; ``items`` the shape of every value
    of a table (or item of a list), ``fields`` the shapes of a table's named keys (others are left unchecked)."""

    text: str
    accepts: Callable[[object], bool]
    items: Shape | None = None
    fields: dict[str, Shape] = field(default_factory=dict)

    def problem(self, value: object, key: str = "") -> str | None:
        """``key: what it holds (allowed: ...)`` for the first key in ``value`` that breaks the shape (``key`` "": the
        file's top level, named by no key), else None."""
        if not self.accepts(value):
            return f"{one_line(key) + ': ' if key else ''}{_kind(value)} {echo(value, 40)} (allowed: {self.text})"
        inner: list[tuple[str, object, Shape]] = []
        if isinstance(value, dict):
            named = (lambda name: f"{key}.{name}") if key else (lambda name: name)
            inner = [(named(name), value[name], shape) for name, shape in self.fields.items() if name in value]
            if self.items is not None:
                inner += [(named(name), item, self.items) for name, item in value.items()]
        elif isinstance(value, list) and self.items is not None:
            inner = [(f"{key}[{index}]", item, self.items) for index, item in enumerate(value)]
        for name, item, shape in inner:
            found = shape.problem(item, name)
            if found:
                return found
        return None


def _kind(value: object) -> str:
    return {dict: "a table", list: "a list", str: "text", bool: "a boolean", type(None): "null"}.get(
        type(value), "a number")


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


TEXT = Shape("text", lambda v: isinstance(v, str))
WHOLE = Shape("a whole number", lambda v: isinstance(v, int) and not isinstance(v, bool))
COUNT = Shape("a whole number >= 0", lambda v: WHOLE.accepts(v) and v >= 0)  # type: ignore[operator]
NUMBER = Shape("a number", _is_number)
FINITE = Shape("a finite number", lambda v: _is_number(v) and math.isfinite(v))  # type: ignore[arg-type]
POSITIVE = Shape("a finite number > 0", lambda v: FINITE.accepts(v) and v > 0)  # type: ignore[operator]
SCALAR = Shape("text, a number, a boolean or null", lambda v: v is None or isinstance(v, (str, int, float, bool)))


def table_of(items: Shape) -> Shape:
    """A table (JSON object) whose every value is ``items``."""
    return Shape(f"a table of {items.text}", lambda v: isinstance(v, dict), items=items)


def list_of(items: Shape, length: int | None = None) -> Shape:
    """A list whose every item is ``items`` (of ``length`` items, when given)."""
    text = f"a list of {length} {items.text}" if length is not None else f"a list of {items.text}"
    return Shape(text, lambda v: isinstance(v, list) and (length is None or len(v) == length), items=items)


def record(text: str, **fields: Shape) -> Shape:
    """A table whose keys ``fields`` (where present) hold their shapes; other keys are left unchecked."""
    return Shape(text, lambda v: isinstance(v, dict), fields=fields)
