"""Run profiles: the ``quick`` CI profile shrinks a scene to a smoke test of the same physics.

``quick`` keeps every scene and every engine, and keeps what the verdicts need (the time steps
of the order fits and of the hard cases' verdicts, the hard IK targets), but

- a dynamics scene runs for at most :data:`QUICK_MAX_STEPS` of its finest kept time step
  (:data:`QUICK_CONTACT_STEPS` for a contact scene; a whole number of the coarsest), with one
  orientation update per scheme (the default; the ``+matrix`` / ``+expmap`` variants are left to the
  full run), except on a rotating scene of at most :data:`QUICK_VARIANT_STEPS` steps, which runs
  every variant, so that CI exercises every orientation update. Which time steps it keeps is chosen by what the
  scene's rows judge: a scene without contact keeps its whole ladder, so that its order fits find
  the asymptotic range in it (the finest steps whose local slopes agree, above the rounding floor;
  coarse steps alone saturate or sit before it, fine ones alone may reach the floor); a contact
  scene, which has no order of convergence (an impact timed a fraction of a step off makes the
  error jump with dt), keeps its :data:`QUICK_LADDER` coarsest, where its verdicts lie (stability
  limits, tunnelling, the hard cases' blow-ups);
- a kinematics scene samples at most :data:`QUICK_SAMPLES` configurations, an IK scene at most
  :data:`QUICK_TARGETS` random targets;
- a joint-motion scene runs its :data:`QUICK_MOTION_LADDER` coarsest time steps (a chain's steps cost far more than a
  free body's; three steps still give an order).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from simparity.comparisons.engines.registry import EngineSet
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene

QUICK_MAX_STEPS = 2000
QUICK_MOTION_LADDER = 3
"""Time steps of a joint-motion scene the quick profile runs: its three coarsest, the fewest an order fit needs."""
"""Steps at the finest kept time step: every built-in scene but the long horizons (the
Dzhanibekov flip and the separatrix over 10-20 s, 10^5 and 10^6 steps) runs whole, so the hard
cases show the verdict they show in the full run and the closed-form bounds hold for the whole
horizon; a long horizon is cut to 2,000 steps, which keeps the suite near a minute on 2 cores."""

QUICK_CONTACT_STEPS = 1000
"""Steps at the finest kept time step of a contact scene: its coarsest steps are what its verdicts need, and a
contact step costs several free steps (event detection, every engine's contact solver), so the contact scenes
keep the horizon they had (the first bounces of every built-in one, the hard cases whole)."""

QUICK_VARIANT_STEPS = 1000
"""A rotating scene of at most this many steps at its finest kept step runs every orientation variant in the
quick profile: the variants triple the cost of the rigid-body schemes, which a scene this short (the hard
fast spinner, 400 steps) pays in seconds; every other scene leaves them to the full run."""

QUICK_LADDER = 3
"""Time steps a contact scene keeps (its coarsest): as many as the full run's verdict bounds name."""

QUICK_SAMPLES = 100
"""Configurations a kinematics scene samples: enough to hit every joint range."""

QUICK_TARGETS = 50
"""Random IK targets: a solve rate to 2 %, at half the cost of a kinematics sample (each target
is an iterative solve on every engine)."""

QUICK_STATES = 20
"""States a joint-dynamics scene samples: every identity and error is a maximum over states of smooth functions,
met or broken at any generic state; 20 keep a 7-joint arm's case well under a second on every engine."""

PROFILES = ("full", "quick")


def _divides(duration: float, dt: float) -> bool:
    steps = duration / dt
    return abs(steps - round(steps)) <= 1e-9 * steps


def _rotates(scene: DynamicsScene) -> bool:
    """A body spins at the start or a force turns one: the orientation updates differ."""
    return scene.forces.exerts_torque or any(bool(np.any(b.angular_velocity_world != 0)) for b in scene.bodies)


def quick(scene, engines: EngineSet | None = None):
    """The ``quick`` version of a scene (see the module docstring); scenes of other kinds unchanged."""
    if isinstance(scene, DynamicsScene):
        dts = tuple(sorted(scene.dts, reverse=True))
        if scene.contact is not None:
            dts = dts[:QUICK_LADDER]
        coarsest = dts[0]
        steps = QUICK_MAX_STEPS if scene.contact is None else QUICK_CONTACT_STEPS
        duration = max(1, math.floor(steps * dts[-1] / coarsest + 1e-9)) * coarsest
        if duration >= scene.duration or not all(_divides(duration, dt) for dt in dts):
            duration = scene.duration
        integrators = scene.integrators  # a short rotating scene: every variant
        if not (duration / dts[-1] <= QUICK_VARIANT_STEPS * (1 + 1e-9) and _rotates(scene)):
            engines = engines or EngineSet()
            named = scene.integrators or engines.integrators
            integrators = tuple(i for i in named if i not in engines.other_variants) or named
        return replace(scene, duration=duration, dts=tuple(sorted(dts)), integrators=integrators)
    if isinstance(scene, KinematicsScene):
        return replace(scene, n_configurations=min(scene.n_configurations, QUICK_SAMPLES))
    if isinstance(scene, IKScene):
        return replace(scene, n_targets=min(scene.n_targets, QUICK_TARGETS))
    if isinstance(scene, JointDynamicsScene):
        return replace(scene, n_states=min(scene.n_states, QUICK_STATES))
    if isinstance(scene, JointMotionScene):  # the coarsest steps: enough for an order, the fewest steps
        return replace(scene, dts=tuple(sorted(scene.dts, reverse=True))[:QUICK_MOTION_LADDER])
    return scene


def apply_profile(scenes: list, profile: str, engines: EngineSet | None = None) -> list:
    """The scenes as the profile runs them (``full``: unchanged); the quick profile runs ``engines``' integrators
    on a scene that names none."""
    engines = engines or EngineSet()
    return [quick(s, engines) for s in scenes] if profile == "quick" else list(scenes)
