"""Held loads whose jumps fall inside steps: the order every scheme keeps there, and the label that says so.

A zero-order hold (:mod:`core.model.scenes.time_functions`) jumps at its sample instants. A step whose ends are
instants sees one constant value and loses nothing; a step with an instant strictly inside sees the jump between two
of its stages, an O(dt) error once per jump, so every scheme is first order over the run. Such rows carry the scheme
``held+<scheme>`` (:data:`HELD_PREFIX`), which the shipped tolerances hold to order 1 whatever the scheme, and the
truths (a closed form, an adaptive solve restarted at each jump) keep their own label.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.engine import TRUTH_SCHEMES
from simparity.core.model.scenes.time_functions import HeldFunction

HELD_PREFIX = "held+"
"""Before the kind of scheme of a case whose steps straddle a held load's jump."""

HELD_ORDER = 1
"""The order every scheme keeps where a held load jumps inside its steps: the theory an order row is held to there."""

HELD_DETAIL = ("a held load jumps inside steps: an O(dt) error at each jump makes every scheme first order "
               "(its theory lowered to 1)")
"""What the order rows of such a case say."""

ON_STEP = 1e-9
"""[control periods] An instant this close to a step boundary is on it (step times and instants round differently,
~1e-16 relative)."""


def held_functions(scene) -> list[HeldFunction]:
    """The zero-order holds of a dynamics or joint-motion scene."""
    forces = getattr(scene, "forces", None)
    functions = [f for load in forces.timed for f in load.functions()] if forces is not None else []
    functions.append(getattr(scene, "timed_torque", None))
    return [f for f in functions if isinstance(f, HeldFunction)]


def jumps(function: HeldFunction) -> np.ndarray:
    """The instants where the hold's value changes (from 0 before its first instant): a sample equal to the one
    before it is no jump."""
    previous = np.vstack([np.zeros((1, function.size)), function.samples[:-1]])
    changes = np.any(function.samples != previous, axis=1)
    return (function.phase_s + function.period_s * np.arange(len(function.samples)))[changes]


def straddled_instants(scene, dt: float) -> int:
    """How many of the scene's holds' jumps inside (0, duration) fall strictly inside a step of ``dt`` [s]."""
    count = 0
    for function in held_functions(scene):
        instants = jumps(function)
        instants = instants[(instants > 0) & (instants < scene.duration)]
        off = np.abs(instants - np.round(instants / dt) * dt)
        count += int(np.sum(off > ON_STEP * function.period_s))
    return count


def straddles(scene) -> bool:
    """Whether some time step of the scene's ladder has a hold's jump inside a step."""
    return any(straddled_instants(scene, dt) for dt in scene.dts)


def forcing_scheme(label: str, scene) -> str:
    """``label`` (an engine's declared kind of scheme) as it steps ``scene``: ``held+label`` when a hold's jumps fall
    inside its steps (module docstring), ``label`` itself for a truth, an engine that does not say ("") or a scene
    without such jumps."""
    if not label or label in TRUTH_SCHEMES or not straddles(scene):
        return label
    return HELD_PREFIX + label
