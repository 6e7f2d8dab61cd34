"""The largest time step at which a penalty-method integrator stays stable on a scene, measured.

The penalty method's spring makes the system stiff: an explicit integrator is stable only below a
step of order 1 / omega, omega = sqrt(k_s / m), by a factor that depends on the scheme (semi-implicit
Euler 2, RK4 about 2.8 for an undamped spring; explicit Euler never without damping). The limit is
measured, not quoted: the scene is run at trial steps and a run counts as **unstable** when it

- blows up (non-finite state, or :func:`comparisons.divergence.divergence`),
- gains energy: kinetic plus potential rises by more than :data:`UNSTABLE_ENERGY_GAIN` of its
  largest kinetic energy between clear samples (contact only takes energy away).

(A plane is a half-space: a spring that is integrated stably always pushes a body back out, so a
body that goes through and stays has blown up or gained energy first.)

Bisection on log(dt) between :data:`SEARCH_FACTOR` below the scene's finest step and that factor
above its coarsest finds the boundary to :data:`BISECTIONS` halvings of that range. A trial runs
the scene for at most :data:`TRIAL_STEPS` steps (its whole duration when that is fewer), which
covers the first impacts of the built-in scenes at every trial step.
"""

from __future__ import annotations

import math

import numpy as np

from simparity.comparisons.contact_metrics import read_contact
from simparity.comparisons.divergence import divergence
from simparity.comparisons.rows import Measured
from simparity.core.engine import Engine
from simparity.core.errors import SimparityError
from simparity.core.scene import DynamicsScene

STABILITY_METRICS = {"stable_dt_max": "s"}

UNSTABLE_ENERGY_GAIN = 0.1
"""Energy gained at an impact above 10 % of the run's largest kinetic energy is instability, not
truncation error: a stable first-order scheme errs by O(omega dt) per contact, a few per cent at the
steps measured, while an unstable one multiplies the energy by a growing factor each oscillation."""

SEARCH_FACTOR = 8.0
"""The search spans the scene's ladder widened by this factor on both sides."""

BISECTIONS = 10
"""Halvings of the log range: the limit to 2^(log2(span) / 1024), under 1 % for the spans used."""

TRIAL_STEPS = 5000
"""Steps per trial run: enough for the first impacts at the finest trial step, cheap at the coarsest."""


def _unstable(scene: DynamicsScene, engine: Engine, integrator: str, dt: float) -> str:
    """Why a run of ``scene`` at ``dt`` is unstable, or "" when it is not."""
    steps = min(max(1, math.ceil(scene.duration / dt)), TRIAL_STEPS)
    try:
        with np.errstate(all="ignore"):
            traj = engine.build_dynamics(scene, integrator, dt).run(steps)
    except SimparityError as err:
        return str(err)
    if not traj.is_finite():
        return "non-finite state"
    with np.errstate(all="ignore"):
        blown = divergence(scene, traj)
        if blown:
            return blown
        reading = read_contact(scene, traj)
    clear = (reading.distance > 0).all(axis=2)
    scale = reading.kinetic.max(axis=0)
    for b in range(len(scene.bodies)):
        energy = reading.energy[clear[:, b], b]
        if len(energy) > 1 and scale[b] > 0 and np.diff(energy).max() > UNSTABLE_ENERGY_GAIN * scale[b]:
            return f"energy of {scene.bodies[b].name} rose by more than {UNSTABLE_ENERGY_GAIN:.0%} at an impact"
    return ""


def stable_dt_max(scene: DynamicsScene, engine: Engine, integrator: str) -> Measured:
    """The largest step [s] at which ``integrator`` runs ``scene`` stably (see the module docstring)."""
    low, high = min(scene.dts) / SEARCH_FACTOR, max(scene.dts) * SEARCH_FACTOR
    why_low = _unstable(scene, engine, integrator, low)
    if why_low:
        return Measured(math.nan, "s", unmeasurable=f"unstable at every step tried, down to {low:.3g} s ({why_low})")
    why_high = _unstable(scene, engine, integrator, high)
    if not why_high:
        return Measured(math.nan, "s", unmeasurable=f"stable at every step tried, up to {high:.3g} s: no limit found")
    reason = why_high
    for _ in range(BISECTIONS):
        middle = math.sqrt(low * high)
        why = _unstable(scene, engine, integrator, middle)
        if why:
            high, reason = middle, why
        else:
            low = middle
    return Measured(low, "s", note=f"stable at {low:.4g} s, unstable at {high:.4g} s ({reason})")
