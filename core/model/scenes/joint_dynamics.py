"""The joint-space dynamics scene: :class:`JointDynamicsScene`, instant by instant."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.chain import Chain, sample_configurations
from simparity.core.model.scenes.suites import SweepPoint


BASE_POSITION_RANGE = 1.0
"""[m] A floating base's origin is drawn uniform in [-range, range]^3: where the base is changes no dynamics quantity
(the model is invariant under translation), only their rounding, which stays at the model's own scale."""


@dataclass(frozen=True)
class JointDynamicsScene:
    """A chain's joint-space dynamics (mass matrix, bias forces, inverse and forward dynamics) compared at
    seeded random states: instant by instant, no time stepping.

    The chain's base link is fixed in the world and its frame is the world frame, or floats free
    (:attr:`Chain.floating_base`: the state then starts with the base's pose and velocity).

    Attributes
    ----------
    name, description, reference : str
    chain : Chain
        With mass properties on every link (:meth:`Chain.dynamics_problem` is "").
    gravity_world : (3,) ndarray or None
        [m/s^2] in the base frame; None: no gravity.
    n_states : int
        Seeded random states (q, qdot, qddot, tau).
    seed : int
    velocity_scale, acceleration_scale, torque_scale : float or (nv,) ndarray
        qdot, qddot and tau are uniform in [-scale, scale] per velocity component [rad/s or m/s, rad/s^2 or m/s^2,
        N m or N]; q is uniform within the limits (:func:`sample_configurations`). One number serves every component;
        stored as one per component, (nv,) (a floating base's six first: :attr:`Chain.nv`), so that a change of units
        can scale a revolute and a prismatic joint's differently.
    source : str
    suites : tuple of str
    sweep : SweepPoint or None
    """

    name: str
    description: str
    reference: str
    chain: Chain
    gravity_world: np.ndarray | None
    n_states: int
    seed: int
    velocity_scale: float | np.ndarray = 1.0
    acceleration_scale: float | np.ndarray = 1.0
    torque_scale: float | np.ndarray = 1.0
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="joint_dynamics", init=False)

    def __post_init__(self) -> None:
        problem = self.chain.dynamics_problem()
        if problem:
            raise SceneError(self.source, "chain", problem, "a chain with mass properties on every link")
        if self.gravity_world is not None:
            object.__setattr__(self, "gravity_world", readonly(self.gravity_world, shape=(3,)))
        for key in ("velocity_scale", "acceleration_scale", "torque_scale"):
            scale = np.broadcast_to(np.asarray(getattr(self, key), dtype=float), (self.chain.nv,))
            if not np.all(np.isfinite(scale) & (scale > 0)):
                raise SceneError(self.source, key, f"{scale.tolist()}",
                                 "finite numbers > 0, one or one per velocity component")
            object.__setattr__(self, key, readonly(scale, shape=(self.chain.nv,)))

    def states(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(q, qdot, qddot, tau), (n_states, nq) and (n_states, nv) (:attr:`Chain.nq`, :attr:`Chain.nv`): seeded, the
        joints within their limits; a floating base's origin uniform in [-1, 1]^3 m (:data:`BASE_POSITION_RANGE`) and
        its orientation uniform over the rotations (a normalised Gaussian quat_wxyz, w >= 0)."""
        rng = np.random.default_rng(self.seed)
        q = sample_configurations(self.chain, self.n_states, rng)
        shape = (self.n_states, self.chain.nv)
        qd, qdd, tau = (scale * rng.uniform(-1.0, 1.0, size=shape)
                        for scale in (self.velocity_scale, self.acceleration_scale, self.torque_scale))
        if self.chain.floating_base:
            position = rng.uniform(-BASE_POSITION_RANGE, BASE_POSITION_RANGE, size=(self.n_states, 3))
            turn = rng.normal(size=(self.n_states, 4))
            turn *= np.where(turn[:, :1] < 0, -1.0, 1.0) / np.linalg.norm(turn, axis=1, keepdims=True)
            q = np.concatenate([position, turn, q], axis=1)
        return q, qd, qdd, tau
