"""The largest time step at which a penalty-method integrator stays stable on a scene, measured.

The penalty method's spring makes the system stiff: an explicit integrator is stable only below a
step of order 1 / omega, omega = sqrt(k_s / m), by a factor that depends on the scheme (semi-implicit
Euler 2, RK4 about 2.8 for an undamped spring; explicit Euler never without damping). The limit is
measured, not quoted: the scene is run at trial steps and a run counts as **unstable** when it

- blows up (non-finite state, or :func:`comparisons.measure.divergence.divergence`),
- gains energy: kinetic plus potential rises across a contact by more than
  :data:`comparisons.measure.contact_metrics.UNSTABLE_ENERGY_GAIN` of its largest kinetic energy (contact only
  takes energy away; the runner marks such a case diverged too).

(A plane is a half-space: a spring that is integrated stably always pushes a body back out, so a
body that goes through and stays has blown up or gained energy first.)

From :data:`SEARCH_FACTOR` below the scene's finest step (but no finer than the scene's duration /
:data:`TRIAL_STEPS`) the step doubles until a run is unstable (at most that factor above the
coarsest step), and bisection on log(dt) between the last stable and the first unstable step finds
the boundary to :data:`BISECTIONS` halvings of that octave. (Stability need not be monotonic in dt:
a step longer than a contact can skip the spring's growth; the limit reported is the first
instability met from below.) Every trial runs the scene's whole duration; a trial that touches no
plane has nothing to be unstable at, and the limit is then n/a.
"""

from __future__ import annotations

import math

import numpy as np

from simparity.comparisons.measure.divergence import blow_up
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.engine import Engine
from simparity.core.model.errors import SimparityError
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.metric_catalogue import STABLE_DT_MAX

STABILITY_METRICS = {STABLE_DT_MAX: "s"}

SEARCH_FACTOR = 8.0
"""The search spans the scene's ladder widened by this factor on both sides."""

BISECTIONS = 8
"""Halvings of the log of the octave that holds the limit: to 2^(1/256), 0.3 %."""

TRIAL_STEPS = 5000
"""The most steps a trial runs: every trial covers the scene's whole duration (so it meets the same contacts as
the scene's own runs), so the finest step tried is at least duration / TRIAL_STEPS."""


class _NoContact(Exception):
    """A trial run touched no plane: there is nothing to be unstable at."""


def _unstable(scene: DynamicsScene, engine: Engine, integrator: str, dt: float) -> str:
    """Why a run of ``scene`` (its whole duration) at ``dt`` is unstable, or "" when it is not."""
    try:
        with np.errstate(all="ignore"):
            traj = engine.build_dynamics(scene, integrator, dt).run(max(1, math.ceil(scene.duration / dt)))
    except SimparityError as err:
        return str(err)
    with np.errstate(all="ignore"):
        blown, reading = blow_up(scene, traj)
    if reading is not None and not any(reading.episodes.values()):
        raise _NoContact(f"the run at {dt:.3g} s touches no plane")
    return blown


def stable_dt_max(scene: DynamicsScene, engine: Engine, integrator: str) -> Measured:
    """The largest step [s] at which ``integrator`` runs ``scene`` stably (see the module docstring)."""
    low = max(min(scene.dts) / SEARCH_FACTOR, scene.duration / TRIAL_STEPS)
    high = max(max(scene.dts) * SEARCH_FACTOR, low)
    try:
        return _bisect(scene, engine, integrator, low, high)
    except _NoContact as err:
        return Measured(math.nan, "s", unmeasurable=f"{err}: no contact, no limit to measure")


def _bisect(scene: DynamicsScene, engine: Engine, integrator: str, low: float, high: float) -> Measured:
    """Climb from ``low`` by octaves to the first unstable step (stability need not be monotonic in dt: a
    step longer than a contact may skip the spring's growth), then bisect between it and the last stable one."""
    why_low = _unstable(scene, engine, integrator, low)
    if why_low:
        return Measured(math.nan, "s", unmeasurable=f"unstable at every step tried, down to {low:.3g} s ({why_low})")
    reason, step = "", low
    while not reason:
        if step >= high:
            return Measured(math.nan, "s", unmeasurable=f"stable at every step tried, up to {high:.3g} s: no limit "
                            "found")
        low, step = step, min(2.0 * step, high)
        reason = _unstable(scene, engine, integrator, step)
    high = step
    for _ in range(BISECTIONS):
        middle = math.sqrt(low * high)
        why = _unstable(scene, engine, integrator, middle)
        if why:
            high, reason = middle, why
        else:
            low = middle
    return Measured(low, "s", note=f"stable at {low:.4g} s (and at every octave below it down to the finest step "
                    f"tried), unstable at {high:.4g} s ({reason})")
