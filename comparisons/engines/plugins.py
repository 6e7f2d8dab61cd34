"""Engines from outside simparity: installed plugins and ``module:attr`` specs, found and built without ever raising.

An installed package registers an engine in the entry-point group :data:`ENTRY_POINT_GROUP`
(``name = "module:attr"``, e.g. in ``[project.entry-points."simparity.engines"]``); code that is not
packaged is named by its spec directly (``--engines my_module:MyEngine``). ``attr`` is an
:class:`~simparity.core.model.engine.Engine` subclass or a zero-argument callable returning an Engine.

Whatever goes wrong comes back as an engine standing in for the one asked for
(:mod:`comparisons.engines.placeholders`), never as an exception: a module that will not import (a
missing dependency) gives n/a rows, like a built-in engine's missing library; a module or constructor
that raises, or an engine whose ``version()``, ``integrators()``, ``ik_solvers()``, ``joint_dynamics_methods()``, ``joint_motion_integrators()``,
``theoretical_order()``, ``stages()`` or ``integrator_variant()`` raises or returns what the interface
does not allow, gives failed rows with the error. How to write one: docs/plugins.md.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import os
import re
import sys
from dataclasses import dataclass
from importlib import metadata
from typing import Callable, cast

from simparity.comparisons.engines.placeholders import BrokenEngine, NotAnEngine
from simparity.comparisons.common.error_text import error_text
from simparity.core.model.engine import Engine
from simparity.core.model.errors import echo, one_line

ENTRY_POINT_GROUP = "simparity.engines"

ENGINE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}", re.ASCII)
"""An engine's name as ``--engines`` takes it: no comma (the list's separator) and no colon (a spec's)."""
ENGINE_NAME_RULE = "letters, digits and _ . - (not first: . -), at most 64 characters"

SPEC = re.compile(r"[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*:[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*", re.ASCII)
"""``some.module:Attr`` (dotted Python names on both sides), as entry points write their values."""

OFFERED_NAME = re.compile(r"[^\s,]+")
"""An integrator or IK solver name: a CSV cell and a list item, so no white space and no comma."""

MAKER_RULE = "allowed: an Engine subclass or a zero-argument callable returning an Engine"
"""What ``module:attr`` (a spec's, or a plugin's entry point's) must name."""

RESERVED_OFFERED = ("-",)
"""Not an integrator or solver name: the runner's mark of a case of an engine that offers none."""


@dataclass(frozen=True)
class Plugin:
    """One entry point of :data:`ENTRY_POINT_GROUP`.

    Attributes
    ----------
    name : str
        The entry point's name: what ``--engines`` takes and what the rows call the engine.
    target : str
        Its value, ``module:attr``.
    distribution : str
        ``<name> <version>`` of the installed package that registers it.
    problem : str
        Why it is not used ("" when it is): shadowed by a built-in or an earlier plugin of the same
        name, or a name ``--engines`` could not take.
    """

    name: str
    target: str
    distribution: str
    problem: str = ""


@dataclass(frozen=True)
class Discovery:
    """Every plugin found, in import-path order, and why the search itself failed ("" when it did not)."""

    plugins: tuple[Plugin, ...]
    error: str = ""

    def usable(self) -> dict[str, Plugin]:
        """The plugins ``--engines`` can name, by name."""
        return {p.name: p for p in self.plugins if not p.problem}


@functools.lru_cache(maxsize=1)
def discover(builtin: tuple[str, ...]) -> Discovery:
    """The installed plugins; a name in ``builtin`` or taken by an earlier plugin is shadowed (the first found
    on the import path wins). Cached: the packages installed do not change while simparity runs."""
    try:
        found = list(metadata.entry_points(group=ENTRY_POINT_GROUP))
    except Exception as err:  # noqa: BLE001 - broken package metadata must not break a run
        return Discovery((), f"reading the installed packages' entry points raised {one_line(error_text(err))}")
    plugins: list = []
    taken: dict = {}
    for entry in found:
        distribution = _distribution(entry)
        if entry.name in builtin:
            problem = f"shadowed by the built-in engine {entry.name}"
        elif entry.name in taken:
            problem = f"shadowed by the plugin of {taken[entry.name]}, found first on the import path"
        elif not ENGINE_NAME.fullmatch(entry.name):
            problem = f"the name {echo(entry.name)} is not an engine name (allowed: {ENGINE_NAME_RULE})"
        else:
            problem = ""
            taken[entry.name] = distribution
        plugins.append(Plugin(entry.name, entry.value, distribution, problem))
    return Discovery(tuple(plugins))


def _distribution(entry: metadata.EntryPoint) -> str:
    try:
        dist = cast(metadata.Distribution, entry.dist)  # None (no metadata) raises below, as unreadable metadata does
        return f"{dist.name} {dist.version}"
    except Exception:  # noqa: BLE001 - no or unreadable metadata: the entry point still counts
        return "an unknown distribution"


def is_spec(text: str) -> bool:
    """True when ``text`` names an engine by ``module:attr``."""
    return SPEC.fullmatch(text) is not None


def load_engine(target: str, name: str | None = None, taken: frozenset[str] = frozenset()) -> Engine:
    """The engine ``target`` (``module:attr``) gives, checked against the interface; never raises.

    ``name``: what the engine is called (a plugin's entry-point name). None (a spec): its own ``name``
    unless that is empty, not an engine name (:data:`ENGINE_NAME`) or in ``taken`` (a built-in's or a
    plugin's), then ``target`` itself. A spec's module is looked for on the import path, then in the
    current folder. Returns the engine, or a :class:`BrokenEngine` when it does not import (a typo in its
    module, a missing dependency: the user asked for it, so its rows fail rather than pass the gate as n/a),
    its code raised or it broke the interface; a :class:`NotAnEngine` (a BrokenEngine the command line refuses
    before running) when ``attr`` is missing from the module or names what cannot make an engine: a value, a
    class that is not an Engine subclass, a callable that needs arguments or returned something else.
    """
    label = name or target
    if name is None and os.getcwd() not in sys.path:
        sys.path.append(os.getcwd())  # last: a file here never shadows an installed module
    entry = metadata.EntryPoint(label, target, ENTRY_POINT_GROUP)
    try:
        module = importlib.import_module(entry.module)
    except ImportError as err:  # where: always the import machinery, so not said
        return BrokenEngine(label, f"{target} does not import here: {one_line(f'{type(err).__name__}: {err}')}")
    except (Exception, SystemExit) as err:  # noqa: BLE001 - a user's code: its cases fail with the error
        return BrokenEngine(label, f"importing {target} raised {one_line(error_text(err))}")
    try:
        found: object = functools.reduce(getattr, entry.attr.split(".") if entry.attr else (), module)
    except AttributeError as err:  # the module imported: the name after the colon is the mistake
        return NotAnEngine(label, f"{target}: {entry.module} has no attribute {entry.attr} (AttributeError: "
                           f"{one_line(err)}; {MAKER_RULE})")
    except (Exception, SystemExit) as err:  # noqa: BLE001 - a module's own __getattr__ raised
        return BrokenEngine(label, f"importing {target} raised {one_line(error_text(err))}")
    mistake = _not_an_engine_maker(found, target)
    if mistake:
        return NotAnEngine(label, mistake)
    try:
        engine = cast(Callable[[], object], found)()  # callable: _not_an_engine_maker said so
    except (Exception, SystemExit) as err:  # noqa: BLE001 - a user's code: its cases fail with the error
        return BrokenEngine(label, f"constructing {target} raised {one_line(error_text(err))}")
    if not isinstance(engine, Engine):
        return NotAnEngine(label, f"{target}() returned a value of type {type(engine).__name__}, not a "
                           f"simparity.core.engine.Engine ({MAKER_RULE})")
    try:
        own = engine.name
        engine.name = name or (own if isinstance(own, str) and ENGINE_NAME.fullmatch(own) and own not in taken
                               else target)
        problem = _interface_problem(engine)
    except (Exception, SystemExit) as err:  # noqa: BLE001 - e.g. a read-only name property
        problem = f"naming it raised {one_line(error_text(err))}"
    return BrokenEngine(label, f"{target}: {problem}") if problem else engine


def _not_an_engine_maker(found: object, target: str) -> str:
    """Why what ``target`` names cannot make an engine, told without calling it ("" when it may): a value, a class
    that is not an :class:`Engine` subclass, a callable that needs arguments."""
    if not callable(found):
        return f"{target} is a value of type {type(found).__name__} ({MAKER_RULE})"
    if isinstance(found, type) and not issubclass(found, Engine):
        return f"{target} is the class {found.__name__}, not a simparity.core.engine.Engine subclass ({MAKER_RULE})"
    try:
        inspect.signature(found).bind()
    except TypeError as err:
        return f"{target} cannot be called without arguments ({one_line(err)}; {MAKER_RULE})"
    except ValueError:  # a built-in without a signature: only calling it tells
        pass
    return ""


def _interface_problem(engine: Engine) -> str:
    """What the engine's description of itself breaks ("" when nothing): ``version()`` a str,
    ``integrators()``, ``ik_solvers()``, ``joint_dynamics_methods()`` and ``joint_motion_integrators()`` tuples of names
    (:data:`OFFERED_NAME`), ``theoretical_order(i)`` an int or None, ``stages(i)`` an int >= 1 or None and
    ``integrator_variant(i)`` two strs for each integrator of either kind.
    Their errors are problems too."""
    step = "version()"
    try:
        version = engine.version()
        if not isinstance(version, str):
            return f"version() returned {echo(version)} (allowed: a str)"
        step = "integrators()"
        integrators = engine.integrators()
        problem = _names_problem("integrators()", integrators)
        step = "ik_solvers()"
        problem = problem or _names_problem("ik_solvers()", engine.ik_solvers())
        step = "joint_dynamics_methods()"
        problem = problem or _names_problem("joint_dynamics_methods()", engine.joint_dynamics_methods())
        step = "joint_motion_integrators()"
        motion = engine.joint_motion_integrators()
        problem = problem or _names_problem("joint_motion_integrators()", motion)
        for integrator in () if problem else dict.fromkeys(integrators + motion):
            step = f"theoretical_order({integrator!r})"
            order = engine.theoretical_order(integrator)
            if order is not None and (isinstance(order, bool) or not isinstance(order, int)):
                return f"{step} returned {echo(order)} (allowed: an int or None)"
            step = f"stages({integrator!r})"
            stages = engine.stages(integrator)
            if stages is not None and (isinstance(stages, bool) or not isinstance(stages, int) or stages < 1):
                return f"{step} returned {echo(stages)} (allowed: an int >= 1, force evaluations per step, or None)"
            step = f"integrator_variant({integrator!r})"
            variant = engine.integrator_variant(integrator)
            if not (isinstance(variant, tuple) and len(variant) == 2 and all(isinstance(v, str) for v in variant)):
                return f"{step} returned {echo(variant)} (allowed: a (scheme, variant) tuple of two str)"
        return problem
    except (Exception, SystemExit) as err:  # noqa: BLE001 - a user's code
        return f"{step} raised {one_line(error_text(err))}"


def _names_problem(method: str, names: object) -> str:
    if not isinstance(names, tuple):
        return f"{method} returned {echo(names)} (allowed: a tuple of str)"
    bad = [n for n in names if not (isinstance(n, str) and OFFERED_NAME.fullmatch(n)) or n in RESERVED_OFFERED]
    if bad:
        return f"{method} returned the name {echo(bad[0])} (allowed: non-empty, no white space or comma, not '-')"
    return ""
