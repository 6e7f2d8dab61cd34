"""``simparity engines``: every engine, built-in and plugin, one line each with what it offers.

A line names the engine, where it comes from (built-in, or the plugin's distribution and entry point),
its version and what it supports: dynamics integrators, IK solvers, and kinematics (yes or no, asked
with a one-joint revolute chain, which every engine that does kinematics at all can do). An engine
that cannot run says why (``n/a: ...`` when its library does not import, ``failed: ...`` when its code
raised); a plugin that is not used (shadowed, a bad name) says that instead.
"""

from __future__ import annotations

from simparity.comparisons.engines.probe import PROBE_CHAIN
from simparity.comparisons.engines.registry import ENGINE_NAMES, describe_engines
from simparity.comparisons.engines.placeholders import BrokenEngine, UnavailableEngine
from simparity.comparisons.engines.plugins import discover
from simparity.comparisons.common.error_text import error_text
from simparity.core.model.engine import Engine
from simparity.core.model.errors import one_line

DETAIL_LIMIT = 600
"""Characters of a reason printed (an import error can be long): the line stays readable."""


def engine_lines() -> list[str]:
    """One line per engine: the built-ins, then every plugin found (used or not), then why the search for
    plugins failed if it did."""
    discovery = discover(ENGINE_NAMES)
    entries = [(name, "built-in", "") for name in ENGINE_NAMES]
    entries += [(one_line(p.name), f"plugin {one_line(p.name)} = {one_line(p.target)} from {one_line(p.distribution)}",
                 p.problem) for p in discovery.plugins]
    width = max(len(name) for name, _, _ in entries)
    used = [name for name, _, problem in entries if not problem]
    engines = dict(zip(used, describe_engines(used)))
    lines = [f"{name:<{width}}  {origin}; " + (f"not used: {problem}" if problem else _offers(engines[name]))
             for name, origin, problem in entries]
    if discovery.error:
        lines.append(f"plugins not searched: {discovery.error}")
    return lines


def _offers(engine: Engine) -> str:
    """``version V; dynamics: ...; IK: ...; kinematics: yes|no; joint dynamics: ...``, or why the engine cannot
    run."""
    if isinstance(engine, UnavailableEngine):
        return f"n/a: {one_line(engine.reason, DETAIL_LIMIT)}"
    if isinstance(engine, BrokenEngine):
        return f"failed: {one_line(engine.reason, DETAIL_LIMIT)}"
    return (f"version {engine.version()}; dynamics: {', '.join(engine.integrators()) or 'none'}; "
            f"IK: {', '.join(engine.ik_solvers()) or 'none'}; kinematics: {_kinematics(engine)}; "
            f"joint dynamics: {', '.join(engine.joint_dynamics_methods()) or 'none'}; "
            f"joint motion: {', '.join(engine.joint_motion_integrators()) or 'none'}")


def _kinematics(engine: Engine) -> str:
    try:
        return "yes" if engine.supports_kinematics(PROBE_CHAIN).ok else "no"
    except Exception as err:  # noqa: BLE001 - a user's engine: say what it raised
        return f"unknown ({one_line(error_text(err))})"
