"""The physical force scale of a chain at a joint-dynamics scene's states: what the joint-force errors and identities
of :mod:`comparisons.measure.joint_dynamics_metrics` are never divided by less than a fraction of.

A joint force (h, tau, a force the round trip or the gravity identity leaves) can be ~0 at every sampled state while
the terms it is computed from are not: prismatic joints across gravity and no velocity-dependent term give
h = 0 + rounding of m g. Relative to its own magnitude, that rounding is a 100 % "error". Per joint i [N m or N],
from the model and outputs of whichever engine is asked (the reference, for errors against it), the largest over the
sample's states of:

- inertia: sum_j |M_ij| |qddot_j| at the sampled accelerations (the force the chain's inertia takes);
- weight: |g| |w_i(q)|, w_i the gravity torque per unit gravity, as a vector over the three directions of gravity
  (the model built with unit gravity along x, y and z): the largest torque the chain's weight can exert on joint i
  at that configuration, whichever way gravity points;
- velocity: |h(q, qdot) - h(q, 0)|_i, the Coriolis and centrifugal force at the sampled speeds;
- damping: |tau - M qddot - h|_i = |D qdot|_i.

The floor is :data:`FLOOR_FRACTION` of it: a force the reference computes below that is a near-cancellation of
larger terms, whose rounding is of their size, not of the result's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from simparity.core.model.engine import JointDynamicsModel

FLOOR_FRACTION = 0.1
"""A joint-force error is relative to the larger of the reference's own largest force and this fraction of the
chain's force scale. Rounding of a force is ~10-100 eps of the terms summed (<= the scale): over a tenth of the
scale it stays <= 2e-14, far inside the 1e-12 bounds. The floor acts only where the reference's force is below a
tenth of what the chain's inertia, weight, speeds and damping produce (on every shipped scene the force itself is
larger: their values are unchanged); and since the scale is at most ~the terms' sum, an error of 1e-9 of the
scale (a bug confined to the lightest link) still reads >= 1e-9, a thousand times any bound."""


@dataclass(frozen=True)
class ForceScale:
    """A chain's physical joint-force scale at a sample of states, per joint (n,) [N m or N], by source (the module
    docstring): each the largest over the states."""

    inertia: np.ndarray
    weight: np.ndarray
    velocity: np.ndarray
    damping: np.ndarray

    @property
    def per_joint(self) -> np.ndarray:
        """(n,) the sum of the four sources, joint by joint."""
        return self.inertia + self.weight + self.velocity + self.damping

    @property
    def floors(self) -> np.ndarray:
        """(n,) :data:`FLOOR_FRACTION` of each joint's scale: what joint i's force is never divided by less than."""
        return FLOOR_FRACTION * self.per_joint

    @property
    def floor(self) -> float:
        """The largest of :attr:`floors`: what a force error over every joint is never divided by less than."""
        return float(np.max(self.floors, initial=0.0))

    def describe(self) -> str:
        """``0.1 x the chain's force scale 35.2 (joint 2: inertia 3.1 + weight 32 + velocity 0.1 + damping 0)``."""
        i = int(np.argmax(self.per_joint)) if self.per_joint.size else 0
        parts = " + ".join(f"{name} {float(getattr(self, name)[i]):.3g}" for name in
                           ("inertia", "weight", "velocity", "damping")) if self.per_joint.size else "no joints"
        return f"{FLOOR_FRACTION:g} x the chain's force scale {self.floor / FLOOR_FRACTION:.3g} (joint {i + 1}: {parts})"


def force_scale(model: JointDynamicsModel, build: Callable[[np.ndarray], JointDynamicsModel],
                gravity_world: np.ndarray | None, states: tuple[np.ndarray, ...],
                values: dict[str, np.ndarray]) -> ForceScale:
    """The :class:`ForceScale` of ``model`` (built under ``gravity_world``, (3,) [m/s^2] or None) at ``states``
    (q, qdot, qddot, tau), (B, nq) and (B, nv), from its ``values`` there ({"M": (B, n, n), "h", "tau": (B, n)});
    ``build(g)`` builds the same engine's model of the same chain under gravity ``g`` (3,), for the weight."""
    q, qd, qdd, _ = states
    zeros = np.zeros_like(qd)
    mass, bias = values["M"], values["h"]
    inertia = np.einsum("bij,bj->bi", np.abs(mass), np.abs(qdd))
    damping = np.abs(values["tau"] - np.einsum("bij,bj->bi", mass, qdd) - bias)
    velocity = np.abs(bias - model.bias_forces(q, zeros))
    magnitude = 0.0 if gravity_world is None else float(np.linalg.norm(gravity_world))
    weight = np.zeros_like(qd)
    if magnitude > 0:
        per_unit = np.stack([np.asarray(build(axis).bias_forces(q, zeros), dtype=float) for axis in np.eye(3)])
        weight = magnitude * np.linalg.norm(per_unit, axis=0)
    return ForceScale(*(np.max(part, axis=0, initial=0.0) for part in (inertia, weight, velocity, damping)))
