"""Whether a bound's scene, engine, integrator and scheme can match something that exists.

A bound whose pattern can match nothing holds nothing, and the gate passes on it: an unknown engine, a misspelled
scene, a regular expression where a glob is meant (``ur.*``, ``(a|b)``, ``^x$``). Each of a user's bounds (the
shipped ones are tested) is held against what exists, widening only while a pattern still matches nothing (each step
costs more than the one before):

- scene: the run's (or the session's) scenes, then the built-in scenes and the variants of the built-in sweeps;
- engine: the run's engines, then the built-ins and the installed plugins;
- integrator (an integrator, IK solver or joint-dynamics method): the run's, then every built-in engine's, then
  every installed plugin's (each described in a process of its own);
- scheme: the run's, then the kinds (:data:`core.model.engine.SCHEME_KINDS`) and every label of up to
  :data:`SCHEME_PARTS` kinds joined by ``+``.

A pattern that matches nothing there is refused (:class:`ToleranceError`, exit 2) naming the file, the bound, the
closest names and, for a pattern that reads as a regular expression, that patterns are globs. The metric is checked
when the file is read (:mod:`comparisons.gate.metric_names`): it needs no run.
"""

from __future__ import annotations

import difflib
import functools
import itertools
import re
from typing import Callable, Iterable, Mapping

from simparity.comparisons.gate.bound_index import literal_head, unmatched_patterns
from simparity.comparisons.gate.tolerances import Bound
from simparity.core.model.engine import SCHEME_KINDS
from simparity.core.model.errors import ToleranceError

NAMED_KEYS = ("scene", "engine", "integrator", "scheme")
"""A bound's keys held against what exists here (the metric: when the file is read)."""

SCHEME_PARTS = 3
"""Kinds a scheme label joins at most (``damped_least_squares+nullspace+limits``)."""

CLOSEST_NAMES = 3

REGEX_SIGNS = re.compile(r"\.[*+]|[()|^$\\{}]")
"""What a regular expression has and a glob of names does not: ``.*``, ``.+``, groups, alternatives, anchors (and a
negated class: fnmatch negates with ``[!...]``), escapes, counts."""

GLOBS = "patterns are globs (fnmatch: * any text, ? one character, [abc] one of them), not regular expressions"


def patterns_of(bound: Bound, key: str) -> tuple[str, ...]:
    """A bound's patterns for ``key`` (a scheme may be a list)."""
    return bound.scheme if key == "scheme" else (getattr(bound, key),)


def refuse_impossible(bounds: list[Bound], seen: Mapping[str, Iterable[str]]) -> None:
    """Raise :class:`ToleranceError` for the first of ``bounds`` (a user's, not the shipped file's) with a pattern that
    matches nothing that exists: the values ``seen`` per key (the run's, or the session's scenes and engines), then
    what exists here (module docstring)."""
    mine = [bound for bound in bounds if not bound.shipped]
    for key in NAMED_KEYS:
        left = {pattern for bound in mine for pattern in patterns_of(bound, key)}
        for values in ((lambda: tuple(seen.get(key, ()))),) + _EXISTING[key]:
            if not left:
                break
            left = unmatched_patterns(left, values())
        if left:
            bound, pattern = next((b, p) for b in mine for p in patterns_of(b, key) if p in left)
            raise _refusal(bound, key, pattern, tuple(seen.get(key, ())))


def _refusal(bound: Bound, key: str, pattern: str, seen: tuple[str, ...]) -> ToleranceError:
    """The one line refusing ``pattern``, with the closest of the names seen and of the first that exist."""
    known = sorted(set(seen) | set(_EXISTING[key][0]()))
    closest = difflib.get_close_matches(literal_head(pattern) or pattern, known, n=CLOSEST_NAMES)
    regex = f"; it reads as a regular expression: {GLOBS}" if REGEX_SIGNS.search(pattern) else ""
    allowed = (f"closest: {', '.join(closest)}; or " if closest else "") + {
        "scene": "a scene of the run or a built-in scene ('simparity list'), or a glob matching one",
        "engine": "an engine of the run, a built-in or an installed plugin ('simparity engines'), or a glob matching one",
        "integrator": "an integrator, IK solver or joint-dynamics method of an engine, or a glob matching one",
        "scheme": "a kind of scheme (docs/check.md: rk4, penalty+rk4, damped_least_squares+nullspace), or a glob "
                  "matching one"}[key]
    return ToleranceError(bound.source, f"bound[{bound.order}].{key}",
                          f"{pattern!r:.80} matches no {key} that exists{regex}", allowed)


@functools.lru_cache(maxsize=1)
def builtin_scenes() -> tuple[str, ...]:
    """The built-in scenes' names and the names of the built-in sweeps' variants."""
    from simparity.comparisons.scenes.library import builtin_paths
    from simparity.comparisons.scenes.sweep import SWEEP_TABLE, read_sweep
    from simparity.core.model.files import read_toml

    names = []
    for name, path in builtin_paths().items():
        names.append(name)
        data = read_toml(path, what="scene file")
        if SWEEP_TABLE in data:
            names += read_sweep(data[SWEEP_TABLE], data, str(path), name).names()
    return tuple(names)


def _engines() -> tuple[str, ...]:
    from simparity.comparisons.engines.registry import ENGINE_NAMES, plugin_names

    return ENGINE_NAMES + plugin_names()


def offered(engines) -> tuple[str, ...]:
    """Every integrator, IK solver, joint-dynamics method and joint-motion integrator of ``engines``, and "" (a
    kinematics row has none)."""
    names = {""}
    for engine in engines:
        for names_of in (engine.integrators, engine.ik_solvers, engine.joint_dynamics_methods,
                         engine.joint_motion_integrators):
            names.update(names_of())
    return tuple(sorted(names))


@functools.lru_cache(maxsize=1)
def _builtin_integrators() -> tuple[str, ...]:
    from simparity.comparisons.engines.registry import _built_ins

    return offered(_built_ins())


def _plugin_integrators() -> tuple[str, ...]:
    from simparity.comparisons.engines.registry import describe_engines, plugin_names

    plugins = plugin_names()
    return offered(describe_engines(plugins)) if plugins else ()


def _kinds() -> tuple[str, ...]:
    return ("",) + tuple(SCHEME_KINDS)


@functools.lru_cache(maxsize=1)
def _labels() -> tuple[str, ...]:
    """Every label of up to :data:`SCHEME_PARTS` kinds joined by ``+``."""
    return tuple("+".join(parts) for count in range(2, SCHEME_PARTS + 1)
                 for parts in itertools.product(SCHEME_KINDS, repeat=count))


_EXISTING: dict[str, tuple[Callable[[], Iterable[str]], ...]] = {
    "scene": (builtin_scenes,),
    "engine": (_engines,),
    "integrator": (_builtin_integrators, _plugin_integrators),
    "scheme": (_kinds, _labels),
}
"""What exists beside what was seen, per key, the cheapest first (the installed plugins' integrators are described in
processes of their own; the joined labels are ~20,000); the closest names are offered from the first."""
