"""The joint-motion scene: :class:`JointMotionScene`, a chain stepped through time."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact, frame_index
from simparity.core.model.scenes.suites import SweepPoint
from simparity.core.model.scenes.time_functions import TimeFunction


UNIT_QUATERNION_TOLERANCE = 1e-12
"""How far from 1 a floating base's initial quaternion may be: rounding of a written unit quaternion (a few eps),
far below any orientation a scene means; every engine is given it as written."""


@dataclass(frozen=True)
class JointMotionScene:
    """A chain's motion through time: its joints stepped from an initial state under gravity, its joints' damping,
    constant joint forces and a joint force that changes with time, for ``duration`` at each time step of ``dts``.

    The chain's base link is fixed in the world and its frame is the world frame, or it floats free
    (``chain.floating_base``): the state then starts with the base's pose and velocity, in the project's convention
    (:class:`core.model.scenes.chain.Chain`), and the applied forces act on the joints only. Every engine is given the
    same model. The constant joint forces are the same at every stage; the timed one is evaluated at each stage's time
    where the engine can (:mod:`core.model.scenes.time_functions`).

    Attributes
    ----------
    name, description, reference : str
        ``reference`` is ``engine`` or ``engine:integrator`` (the integrator defaults to the engine's first).
    chain : Chain
        With mass properties on every link (:meth:`Chain.dynamics_problem` is ""); its joints' ``damping`` and
        ``armature`` are part of the motion.
    gravity_world : (3,) ndarray or None
        [m/s^2] in the base frame; None: no gravity.
    q0, qdot0 : (B, nq), (B, nv) ndarray
        Initial joint values and velocities of B copies [rad or m, rad/s or m/s] (one copy: B = 1); with a floating
        base nq = 7 + n and nv = 6 + n (:attr:`Chain.nq`, :attr:`Chain.nv`), the base's quaternion of unit length.
    torque : (n,) ndarray
        Constant applied joint forces [N m or N].
    timed_torque : TimeFunction or None
        Applied joint forces that change with time, n components [N m or N], added to ``torque``; None: none.
    duration : float
        [s].
    dts : tuple of float
        The time-step ladder [s], largest first or in any order.
    integrators : tuple of str
        The integrators to run (empty: every one each engine offers for joint motion).
    perturbation : float
        > 0: every case also runs from q0 + perturbation on every joint [rad or m] and reports when its two runs part,
        beside when it parts from the reference (predictability, Chung and Pollard 2016); 0: not run.
    segments : int
        0: every engine against the reference. k > 0: accuracy as self-consistency (Erez, Tassa and Todorov
        2015): the motion is cut into k segments starting on the reference's trajectory, and each engine's
        state at a segment's end is compared with the same engine and integrator at a much smaller step from
        the same start, averaged over segments, so that a chaotic chain's divergence is not counted as error.
    contact : ChainContact or None
        Spheres on the chain's frames against a plane (:mod:`core.model.scenes.chain_contact`); None: nothing touches.
        A scene with contact is held to truths that need no engine (each engine's contact is its own); it takes no
        perturbation and no segments.
    source : str
    suites : tuple of str
    sweep : SweepPoint or None
    """

    name: str
    description: str
    reference: str
    chain: Chain
    gravity_world: np.ndarray | None
    q0: np.ndarray
    qdot0: np.ndarray
    torque: np.ndarray
    duration: float
    dts: tuple[float, ...]
    integrators: tuple[str, ...] = ()
    segments: int = 0
    perturbation: float = 0.0
    timed_torque: TimeFunction | None = None
    contact: ChainContact | None = None
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="joint_motion", init=False)

    def __post_init__(self) -> None:
        problem = self.chain.dynamics_problem()
        if problem:
            raise SceneError(self.source, "chain", problem, "a chain with mass properties on every link")
        n = self.chain.n_joints
        if self.gravity_world is not None:
            object.__setattr__(self, "gravity_world", readonly(self.gravity_world, shape=(3,)))
        for key, size in (("q0", self.chain.nq), ("qdot0", self.chain.nv)):
            value = np.asarray(getattr(self, key), dtype=float)
            value = value.reshape(1, -1) if value.ndim == 1 else value
            if value.ndim != 2 or value.shape[1] != size or not np.all(np.isfinite(value)):
                raise SceneError(self.source, key, f"shape {value.shape}", f"finite numbers, (B, {size}) or ({size},)")
            object.__setattr__(self, key, readonly(value))
        if self.chain.floating_base:
            self._floating_checks()
        if self.contact is not None:
            self._contact_checks(self.contact)
        if self.q0.shape[0] != self.qdot0.shape[0]:
            raise SceneError(self.source, "qdot0", f"{self.qdot0.shape[0]} copies, q0 has {self.q0.shape[0]}",
                             "as many initial velocities as initial joint values")
        object.__setattr__(self, "torque", readonly(np.asarray(self.torque, dtype=float), shape=(n,)))
        if self.timed_torque is not None and self.timed_torque.size != n:
            raise SceneError(self.source, "timed_torque", f"{self.timed_torque.size} components",
                             f"one per joint ({n})")
        if not (np.isfinite(self.duration) and self.duration > 0):
            raise SceneError(self.source, "duration", f"{self.duration}", "a finite number of seconds > 0")
        if not self.dts or not all(np.isfinite(dt) and 0 < dt <= self.duration for dt in self.dts):
            raise SceneError(self.source, "dt", f"{list(self.dts)}", "time steps > 0 and at most the duration")
        if self.segments < 0:
            raise SceneError(self.source, "segments", f"{self.segments}", "0 (against the reference) or more")
        if self.segments and self.timed_torque is not None:
            raise SceneError(self.source, "simulation.segments", f"{self.segments} segments with a timed torque: each "
                             "segment is stepped from its own start at t = 0, where the torque would restart",
                             "segments = 0 (against the reference) with [drive.timed_torque]")
        if not (np.isfinite(self.perturbation) and self.perturbation >= 0):
            raise SceneError(self.source, "perturbation", f"{self.perturbation}", "a finite number >= 0 (0: none)")

    def _floating_checks(self) -> None:
        """A floating base's quaternion of unit length (to :data:`UNIT_QUATERNION_TOLERANCE`); no perturbation or
        segments yet (they move every configuration component alike, a quaternion's too)."""
        norms = np.linalg.norm(self.q0[:, 3:7], axis=1)
        bad = np.flatnonzero(~(np.abs(norms - 1.0) <= UNIT_QUATERNION_TOLERANCE))
        if bad.size:
            raise SceneError(self.source, "base_quat_wxyz", f"length {norms[bad[0]]:.17g} (copy {bad[0]})",
                             f"a unit quaternion (w, x, y, z), length 1 within {UNIT_QUATERNION_TOLERANCE:g}")
        for key, value in (("perturbation", self.perturbation), ("segments", self.segments)):
            if value:
                raise SceneError(self.source, f"simulation.{key}", f"{value:g} with a floating base",
                                 f"0: a floating base's motion is compared against the reference only")

    def _contact_checks(self, contact: ChainContact) -> None:
        """Every sphere on a frame of the chain; no perturbation or segments (a contact scene has no reference run)."""
        chain = self.chain
        names = tuple(j.name for j in chain.joints)
        for k, sphere in enumerate(contact.spheres):
            try:
                frame_index(sphere.frame, names, chain.end_effector_name, chain.base_link)
            except ValueError:
                frames = ", ".join(names + (chain.end_effector_name,) + ((chain.base_link,) if chain.base_link else ()))
                raise SceneError(self.source, f"contact.sphere[{k}].frame", f"{sphere.frame!r} is no frame of the chain",
                                 f"a chain joint's name (the link it moves), the end effector or the base link: {frames}"
                                 ) from None
        for key, value in (("perturbation", self.perturbation), ("segments", self.segments)):
            if value:
                raise SceneError(self.source, f"simulation.{key}", f"{value:g} with contact",
                                 "0: a scene with contact is held to truths that need no reference run")

    @property
    def copies(self) -> int:
        """B, the copies stepped together."""
        return self.q0.shape[0]

    def n_steps(self, dt: float) -> int:
        """Number of steps of size ``dt`` that cover ``duration`` (at least one)."""
        return max(1, int(round(self.duration / dt)))

    def starting_from(self, q0: np.ndarray, qdot0: np.ndarray, duration: float) -> "JointMotionScene":
        """The same chain and forces from other initial states ((B, nq) and (B, nv)) for ``duration`` [s]."""
        return replace(self, q0=q0, qdot0=qdot0, duration=duration, dts=tuple(min(dt, duration) for dt in self.dts))
