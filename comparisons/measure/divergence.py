"""Has a finite run blown up? Bounds the exact motion cannot cross, from the scene's energy budget.

A run is diverged when, for some body,

- its speed exceeds what its forces can give it: the drag pushes v toward the air velocity w
  and never speeds the body up relative to it, so |v(t)| <= |w| + |v(0) - w| + (|g| + sum |f_i| / m) t, the
  loads that change with time counted at their largest magnitude over the run
  (:func:`comparisons.measure.load_budget.largest_magnitude`);
- its angular speed exceeds what its angular momentum allows: |omega| <= |L| / I_min, with
  |L(t)| <= |L(0)| + sum |p_i| |f_i| t (angular drag only takes momentum away); without applied
  forces also |omega| <= sqrt(2 KE_rot(0) / I_min), as the rotational energy cannot grow. With
  contact a plane's impulse can turn a body, and the bound is its energy budget instead:
  |omega| <= sqrt(2 (KE(0) + (m |g| + sum |f_i|) v_max t) / I_min);
- a quantity the scene conserves grows by more than :data:`CONSERVED_GROWTH_LIMIT` of its
  scale: the energy (E - E(0) > limit x the body's energy scale, KE(0) plus the largest drop of its
  potential energy along the run, at least m |g| size: not |E(0)|, which depends on where the origin
  is; contact only takes energy away, so this holds with contact too) or |L| (not with contact).

Speeds are compared with :data:`DIVERGENCE_MARGIN` times their bound. Energies come from
:mod:`comparisons.measure.metrics`, rotations from SciPy; nothing here is in-house code.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.body_scales import body_sizes
from simparity.comparisons.measure.contact_metrics import ContactReading, contact_blow_up, read_contact
from simparity.comparisons.measure.extents import RunExtents
from simparity.comparisons.measure.invariants import angular_momentum_world
from simparity.comparisons.measure.load_budget import load_budget
from simparity.comparisons.measure.metrics import energy_scale
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.references.common.conventions import quat_wxyz_to_matrix

DIVERGENCE_MARGIN = 2.0
"""A speed more than twice its bound is divergence. The bounds hold for the exact motion; an
accurate run stays near or below them, a run that is merely inaccurate exceeds them by its
error, and a blown-up one grows geometrically past any factor."""

CONSERVED_GROWTH_LIMIT = 1.0
"""A conserved quantity that grows by more than 100 % of its initial size (energy or |L|
doubled) is divergence, not drift."""

AT_REST = 1e-9
"""Added to every speed bound, times the body's size over the run's duration (linear) or one over it
(angular): a body with no motion budget at all may still show rounding-level speeds. Relative to the
body's own scales, so that it scales with the scene's units."""


def _speed_bounds(scene: DynamicsScene) -> tuple[np.ndarray, np.ndarray]:
    """(linear [m/s], angular [rad/s]) upper bounds of the exact motion per body, each (B,)."""
    forces, duration = scene.forces, scene.duration
    gravity = 0.0 if forces.gravity_world is None else float(np.linalg.norm(forces.gravity_world))
    air = np.zeros(3) if forces.air_velocity_world is None else forces.air_velocity_world
    linear, angular = [], []
    for index, body in enumerate(scene.bodies):
        pushed = any(a.body == index for a in forces.applied) or any(load.body == index for load in forces.timed)
        force, torque = load_budget(scene, index)
        linear.append(np.linalg.norm(air) + np.linalg.norm(body.velocity_world - air)
                      + (gravity + force / body.mass) * duration)
        moments = np.linalg.eigvalsh(body.inertia_body)
        rotation = quat_wxyz_to_matrix(body.quat_wxyz)
        momentum = np.linalg.norm(angular_momentum_world(body.inertia_body, body.angular_velocity_world, rotation))
        bound = (momentum + torque * duration) / moments[0]
        omega_body = rotation.T @ body.angular_velocity_world
        spin_energy = max(omega_body @ body.inertia_body @ omega_body, 0.0) / 2
        if scene.contact is not None:
            # A plane's impulse can turn the body (a box landing on an edge), so |L| is no bound; its
            # energy is: contact only takes energy away, and gravity and the applied forces give at
            # most their force times the distance the COM can travel.
            work = (body.mass * gravity + force) * linear[-1] * duration
            kinetic = spin_energy + body.mass * float(body.velocity_world @ body.velocity_world) / 2
            bound = max(bound, np.sqrt(2 * (kinetic + work) / moments[0]))
        elif not pushed:
            bound = min(bound, np.sqrt(2 * spin_energy / moments[0]))
        angular.append(bound)
    return np.array(linear), np.array(angular)


def _conserved_growth(scene: DynamicsScene, run: RunExtents) -> str:
    if run.energy is not None:
        scale = energy_scale(scene, run.energy)
        growth = run.energy.change_max
        grown = (scale > 0) & (growth > CONSERVED_GROWTH_LIMIT * scale)
        if grown.any():
            b = int(np.argmax(np.where(grown, growth / np.where(scale > 0, scale, 1.0), -np.inf)))
            return (f"energy of {scene.bodies[b].name} rose by {growth[b] / scale[b]:.3g} x its energy scale "
                    f"{scale[b]:.3g} J (KE(0) + the largest drop of its potential, at least m |g| size; conserved, "
                    f"limit {CONSERVED_GROWTH_LIMIT:g} x)")
    if run.momentum is not None and scene.contact is None:
        size0, size_max = run.momentum.size0, run.momentum.size_max
        grown = (size0 > 0) & (size_max > (1 + CONSERVED_GROWTH_LIMIT) * size0)
        if grown.any():
            b = int(np.argmax(grown))
            return (f"|L| of {scene.bodies[b].name} grew to {size_max[b] / size0[b]:.3g} x |L(0)| "
                    f"(conserved; limit {1 + CONSERVED_GROWTH_LIMIT:g} x)")
    return ""


def divergence(scene: DynamicsScene, traj: Trajectory) -> str:
    """:func:`divergence_of` the whole trajectory ``traj``."""
    return divergence_of(scene, RunExtents.of(scene, traj))


def divergence_of(scene: DynamicsScene, run: RunExtents) -> str:
    """Why a finite run counts as diverged (see the module's bounds), or "" when it does not."""
    linear, angular = _speed_bounds(scene)
    duration = max(scene.duration, np.finfo(float).tiny)
    for quantity, peak, bound, rounding in (
            ("speed", run.speed_max, linear, AT_REST * body_sizes(scene) / duration),
            ("angular speed", run.spin_max, angular, AT_REST / duration)):
        limit = DIVERGENCE_MARGIN * bound + rounding
        over = peak > limit
        if over.any():
            b = int(np.argmax(peak / limit))
            return (f"{quantity} of {scene.bodies[b].name} reached {peak[b]:.3g}, more than {DIVERGENCE_MARGIN:g} x "
                    f"the {bound[b]:.3g} its forces allow")
    return _conserved_growth(scene, run)


def blow_up(scene: DynamicsScene, traj: Trajectory) -> tuple[str, ContactReading | None]:
    """(why ``traj`` counts as diverged, "" if it does not; its contact reading, None without contact or when
    it blew up before one was taken). Non-finite, :func:`divergence`, or with contact energy gained across
    one beyond :data:`comparisons.measure.contact_metrics.UNSTABLE_ENERGY_GAIN`."""
    blown = blow_up_of(scene, RunExtents.of(scene, traj))
    if blown or scene.contact is None:
        return blown, None
    reading = read_contact(scene, traj)
    return contact_blow_up(scene, reading), reading


def blow_up_of(scene: DynamicsScene, run: RunExtents) -> str:
    """Why a run whose extents are ``run`` counts as diverged without looking at its contacts: non-finite, or
    :func:`divergence_of`; "" when it does not."""
    return "non-finite state" if not run.finite else divergence_of(scene, run)
