"""A free-body scene (``kind = "dynamics"``): ``[world]``, ``[[body]]``, ``[simulation]``, and contact with
``[[plane]]``."""

from __future__ import annotations

import numpy as np

from simparity.comparisons.engines.registry import EngineSet
from simparity.comparisons.scenes.loading.bodies import BODY_KEYS, DRAG_KEYS, read_body, read_body_forces
from simparity.comparisons.scenes.loading.contact import read_contact
from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.comparisons.scenes.loading.time_functions import read_loads
from simparity.comparisons.scenes.loading.time_steps import time_step_ladder
from simparity.core.model.scenes.bodies import Forces
from simparity.core.model.scenes.dynamics import DynamicsScene


def read_dynamics(top: TableReader, head: dict, engines: EngineSet) -> DynamicsScene:
    """The free-body scene of the file's tables ``top``; ``head``: its ``[scene]`` keys; ``engines`` offer the
    integrators it may name."""
    world = top.optional_subtable("world", ("gravity_world", "air_velocity_world"))
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    air = world.vector("air_velocity_world", 3, length=1) if world and world.has("air_velocity_world") else None
    readers = top.array_of_tables("body", BODY_KEYS, "max_bodies")
    bodies = tuple(read_body(r) for r in readers)
    per_body = [read_body_forces(r, i) for i, r in enumerate(readers)]
    drag = {
        key: np.array([d.get(key, 0.0) for d, _ in per_body]) if any(key in d for d, _ in per_body) else None
        for key in DRAG_KEYS
    }
    if world is not None and air is not None and drag["linear_drag"] is None and drag["quadratic_drag"] is None:
        raise world.fail("air_velocity_world", "wind needs a body with linear_drag or quadratic_drag to act on",
                         "wind with a drag on some body, or no air_velocity_world")
    sim = top.subtable("simulation", ("duration", "dt", "rate_hz", "integrators"))
    duration = sim.number("duration", positive=True)
    timed = tuple(load for i, r in enumerate(readers) for load in read_loads(r, i, duration))
    forces = Forces(gravity_world=gravity, air_velocity_world=air,
                    applied=tuple(a for _, applied in per_body for a in applied), timed=timed, **drag)
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        repeated = next(n for i, n in enumerate(names) if n in names[:i])
        raise top.fail("body", f"the body name {repeated!r} repeats", "distinct names")
    contact = read_contact(top, readers, bodies)
    if contact is not None and timed:
        loaded = next(i for i, r in enumerate(readers) if r.has("load"))
        raise readers[loaded].fail("load", "a load that changes with time on a scene with contact planes",
                                   "time-varying loads on free bodies without [[plane]] (contact methods step "
                                   "constant forces only)")
    if sim.has("dt") == sim.has("rate_hz"):
        raise sim.fail("dt", "give exactly one of dt and rate_hz", "dt = [time steps in s] or rate_hz = [steps per s]")
    dts = time_step_ladder(sim, duration, len(bodies))
    integrators = _integrators(sim, engines) if sim.has("integrators") else ()
    return DynamicsScene(bodies=bodies, forces=forces, duration=duration, dts=dts, integrators=integrators,
                         contact=contact, **head)


def _integrators(sim: TableReader, engines: EngineSet) -> tuple[str, ...]:
    """The integrators a scene names, each offered by some engine: a built-in or one of the command's
    ``engines``, else an installed plugin (asked only then)."""
    named, choices = sim.table["integrators"], engines.integrators
    if isinstance(named, list) and any(isinstance(n, str) and n not in choices for n in named):
        choices = engines.installed_integrators
    return sim.strings("integrators", choices, "no engine has an integrator {}")
