"""A chain stepped through time by PyBullet's own ``stepSimulation`` (Bullet's multibody, Featherstone's
articulated-body algorithm), for joint-motion scenes.

The model is part 1's stepped body (:class:`references.pybullet.joint_dynamics.ChainBodies`, whose module docstring
gives every default and why): the chain's dynamics URDF with its axes normalised, ``URDF_USE_INERTIA_FROM_FILE``,
gravity exactly the scene's (None: zero), link damping 0, braking motors off (VELOCITY_CONTROL, force 0), joint limits
without force, the velocity cap raised to 1e300, jointDamping the chain's. The world holds nothing else: no ground
plane, and the bodies have no collision shapes (the dynamics URDF has none), so nothing collides; a scene with contact
adds its plane and its spheres and nothing more (:mod:`references.pybullet.chain_contact`). Each setting is pinned by
``tests/references/pybullet/test_joint_motion.py`` (the contact's by
``tests/references/pybullet/test_chain_contact.py``):

- Time step exactly dt (``setTimeStep``), ``numSubSteps`` 0: one ``stepSimulation`` is one step of dt (read back by
  ``getPhysicsEngineParameters``).
- The step (measured, one step of a damped arm at dt 0.1 s): qdot' = qdot + dt qddot(q, qdot, tau) from the
  articulated-body algorithm at the step's start, then q' = q + dt qdot' (the NEW velocity): semi-implicit Euler,
  first order, one force evaluation per step.
- Joint damping is PyBullet's own ``changeDynamics(jointDamping=D)``, which Bullet applies as the joint force
  -D qdot at the step's start: EXPLICIT (measured: the one-step velocity change of a damped joint is -dt M^-1 D qdot,
  not the implicit -dt (M + dt D)^-1 D qdot), the same as a torque -D qdot sent before each step. It is stable only
  while dt b / I stays below 2 on every joint: the iiwa's last link (I = 1e-3 kg m^2, b = 0.5 N m s) blows up at
  dt = 4 ms (measured: finite at 3 ms).
- Applied joint forces: ``setJointMotorControlArray(TORQUE_CONTROL)`` before EVERY step, the scene's timed torque
  (:mod:`references.common.time_loads`) evaluated at the step's start (Bullet's step evaluates forces once). Bullet clears the applied
  joint torques after each step (measured: a torque sent once acts on one step only), so it is sent again each time.
- PyBullet has no joint armature: a chain with armature > 0 is refused (:meth:`PybulletEngine.supports_joint_motion`).
- B copies: one body per copy in the same world, stepped together by one ``stepSimulation``. They cannot touch (no
  collision shapes) and every link is taken out of the broadphase (``setCollisionFilterGroupMask`` group 0, mask 0:
  without it Bullet still pairs the links' empty colliders, all of them overlapping across copies; measured on the
  iiwa, ``stepSimulation`` took 1.4x as long for one body and 2.7x for 100). Each copy's trajectory is bit for bit
  the one it has alone (tested). ``batched`` steps copies of the first initial state the same way. Bullet's step
  still costs more per copy as B grows (measured on the iiwa, per copy and step against one body alone: about 1x at
  B = 10, 4x at B = 100, 12-14x at B = 300; the same with and without joint limits): the batched time is PyBullet's
  one-world batching as it is, not a loop over worlds.
- Samples: ``getJointStates`` after every step. A velocity at the cap (Bullet clamps there) means the run blew up:
  DivergedError.

Energies from PyBullet's own model of a second body (:class:`ChainBodies`, unstepped): kinetic 1/2 qdot^T M qdot with
``calculateMassMatrix`` (Bullet's inertia tensors diagonalised by its Jacobi iteration, as its stepping uses them: M
off by up to ~1e-10 relative from the file's tensors on the Panda, see the joint-dynamics module), potential
-sum m g.c over every link of the body (``getLinkStates(computeForwardKinematics=True)``'s centre-of-mass positions,
double, and ``getDynamicsInfo`` masses; the base never moves and is left out: its mass in the dynamics URDF is 0).
The end effector by :class:`references.pybullet.adapter.PybulletChain` (``getLinkState``, float32).
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.engine import BatchedRun, JointSimulation
from simparity.core.model.errors import DivergedError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory
from simparity.references.common import time_loads
from simparity.references.common.dynamics_urdf import dynamics_source
from simparity.references.pybullet.adapter import PybulletChain
from simparity.references.pybullet.chain_contact import PlaneContact, link_frame, link_index
from simparity.references.pybullet.floating_body import MassStates
from simparity.references.pybullet.joint_dynamics import CLIPPED, ChainBodies, axes_changed
from simparity.references.pybullet.quiet import pybullet


def _world(scene: JointMotionScene, dt: float, copies: int) -> tuple[ChainBodies, PlaneContact | None]:
    """``copies`` bodies of the scene's chain stepping at ``dt`` [s] in one world, out of every collision pair but
    their contact spheres' with the scene's plane (:mod:`references.pybullet.chain_contact`), and that contact."""
    world = ChainBodies(scene.chain, scene.gravity_world, time_step=dt, copies=copies, contact=scene.contact)
    for body in world.bodies:
        for link in (-1, *world.links):
            pybullet.setCollisionFilterGroupMask(body, link, 0, 0, physicsClientId=world.client)
    contact = (None if scene.contact is None else
               PlaneContact(world.client, world.bodies, scene.chain, scene.contact, world.urdf_text, world.base))
    return world, contact


def _collisions(scene: JointMotionScene) -> str:
    """What collides in the world, for the rows' detail."""
    if scene.contact is None:
        return "no collision shapes (collision filter group and mask 0), no ground"
    return ("collision spheres on the contact links against a static GEOM_PLANE, nothing else colliding; frictionless, "
            "restitution 0, contactERP 0, contactSlop 0, no speculative contact (contactProcessingThreshold 0), "
            "100 solver iterations (all of them: residual threshold 0); forces by getContactPoints of one step of a "
            "scratch world from each state")


class PybulletJointMotion(JointSimulation):
    """A joint-motion scene stepped by PyBullet (module docstring: what is set, how damping and torque act)."""

    def __init__(self, scene: JointMotionScene, dt: float) -> None:
        self._scene, self._dt = scene, dt
        self._world, self._contact = _world(scene, dt, scene.copies)
        probe: tuple[ChainBodies | None, PlaneContact | None] = (_world(scene, dt, 1) if scene.contact is not None
                                                                  else (None, None))
        self._probe, self._probe_contact = probe
        self._model = ChainBodies(scene.chain, scene.gravity_world)
        if not scene.chain.floating_base:  # a floating base's energy and momentum are summed from its link states
            self._model.build_tree()
        self._kinematics = PybulletChain(scene.chain)
        m = self._model
        self._masses = np.array([pybullet.getDynamicsInfo(m.body, link, physicsClientId=m.client)[0]
                                 for link in m.links])
        self._gravity = np.zeros(3) if scene.gravity_world is None else np.asarray(scene.gravity_world, dtype=float)
        floating = scene.chain.floating_base
        base = ("a free multibody (its base's inertial frame converted to the base link's: floating_body; its base "
                "inertial frame stepped by semi-implicit Euler, turned by the exponential map)"
                if floating else "a fixed-base multibody")
        own = ("energy and momentum summed over getLinkStates' centre-of-mass and angular velocities; end effector "
               "from its link's inertial frame (double)" if floating else
               "energy from calculateMassMatrix and getLinkStates; end effector by getLinkState (float32)")
        self.detail = (f"stepSimulation of {base} per copy in one world (Featherstone ABA, "
                       f"semi-implicit Euler: q from the new qdot), setTimeStep(dt), numSubSteps 0; "
                       f"loadURDF(URDF_USE_INERTIA_FROM_FILE) of {dynamics_source(scene.chain)}; "
                       f"{axes_changed(scene.chain)}; {_collisions(scene)}; gravity set; link damping 0, joint limits, velocity cap and braking motors off; joint "
                       f"damping by changeDynamics(jointDamping) (Bullet: -D qdot at the step's start, explicit); torque by "
                       f"TORQUE_CONTROL re-sent before every step (Bullet clears it after each); {own}")

    def run(self, n_steps: int) -> JointTrajectory:
        return self._step(self._world, np.asarray(self._scene.q0), np.asarray(self._scene.qdot0), n_steps)

    def batched(self, copies: int) -> BatchedRun:
        """``copies`` bodies of the first initial state in one world, one ``stepSimulation`` per step."""
        world, _ = _world(self._scene, self._dt, copies)
        q0 = np.repeat(np.asarray(self._scene.q0)[:1], copies, axis=0)
        qdot0 = np.repeat(np.asarray(self._scene.qdot0)[:1], copies, axis=0)
        return lambda n_steps: self._step(world, q0, qdot0, n_steps)

    def _torque(self, t: float) -> list[float]:
        """The joints' applied forces at time t [s] (the scene's constant and timed torque), as PyBullet's list."""
        constant, timed = np.asarray(self._scene.torque), self._scene.timed_torque
        return (constant if timed is None else constant + time_loads.at(timed, t)).tolist()

    def contact_centres(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) [m]: the spheres' centres as PyBullet places its links (:class:`PlaneContact`)."""
        if self._probe is None or self._probe_contact is None:
            raise NotImplementedError("the scene has no contact")
        out = []
        for row in np.atleast_2d(q):
            self._probe.reset(row, np.zeros(self._scene.chain.nv))
            out.append(self._probe_contact.centres(self._probe.body))
        return np.array(out)

    def contact_forces(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray) -> np.ndarray:
        """(B, S, 3) [N]: the plane's forces in one step of a scratch world from each state under the scene's torque at
        its time (:mod:`references.pybullet.chain_contact`)."""
        if self._probe is None or self._probe_contact is None:
            raise NotImplementedError("the scene has no contact")
        probe, c = self._probe, self._probe.client
        out = []
        for row, rates, t in zip(np.atleast_2d(q), np.atleast_2d(qdot), times):
            probe.reset(row, rates)
            pybullet.setJointMotorControlArray(probe.body, probe.joints, pybullet.TORQUE_CONTROL,
                                               forces=self._torque(float(t)), physicsClientId=c)
            pybullet.stepSimulation(physicsClientId=c)
            out.append(self._probe_contact.forces(probe.body))
        return np.array(out)

    def _step(self, world: ChainBodies, q0: np.ndarray, qdot0: np.ndarray, n_steps: int) -> JointTrajectory:
        """Every body of ``world`` from (q0, qdot0) ((B, n) each) for ``n_steps`` steps, sampled after each."""
        c = world.client
        q = np.empty((n_steps + 1,) + q0.shape)
        qdot = np.empty((n_steps + 1,) + qdot0.shape)
        for k in range(len(world.bodies)):
            world.reset(q0[k], qdot0[k], copy=k)
        q[0], qdot[0] = q0, qdot0
        torque = self._torque(0.0)
        for i in range(1, n_steps + 1):
            if self._scene.timed_torque is not None:  # at the step's start: the step evaluates the forces once
                torque = self._torque((i - 1) * self._dt)
            for body in world.bodies:
                pybullet.setJointMotorControlArray(body, world.joints, pybullet.TORQUE_CONTROL, forces=torque,
                                                   physicsClientId=c)
            pybullet.stepSimulation(physicsClientId=c)
            for k in range(len(world.bodies)):
                q[i, k], qdot[i, k] = world.state(k)
        fastest = np.max(np.abs(qdot))
        if fastest >= CLIPPED:
            raise DivergedError(f"PyBullet clamped a joint velocity at {fastest:.3g} (its cap): the run blew up")
        return JointTrajectory(np.arange(n_steps + 1) * self._dt, q, qdot)

    def _mass_states(self, q: np.ndarray, qdot: np.ndarray) -> list[MassStates]:
        """Each state's links of the model body, its base included (a floating base: :class:`MassStates`)."""
        m = self._model
        out = []
        for row, rates in zip(np.atleast_2d(q), np.atleast_2d(qdot)):
            m.reset(row, rates)
            out.append(MassStates.of(m.client, m.body, m.links))
        return out

    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic 1/2 qdot^T M qdot (calculateMassMatrix), potential -sum m g.c (getLinkStates), each (B,) [J]; a
        floating base's kinetic energy summed over its links (:class:`MassStates`: calculateMassMatrix of a free body
        is not trusted, ``docs/floating-bases.md``), its base's mass in the potential."""
        q, qdot = np.atleast_2d(q), np.atleast_2d(qdot)
        if self._scene.chain.floating_base:
            states = self._mass_states(q, qdot)
            return (np.array([s.kinetic() for s in states]),
                    np.array([s.potential(self._gravity) for s in states]))
        m = self._model
        kinetic = 0.5 * np.einsum("bi,bij,bj->b", qdot, m.mass_matrix(q), qdot)
        potential = np.empty(len(q))
        for k, row in enumerate(q):
            m.reset(row, np.zeros_like(row))
            states = pybullet.getLinkStates(m.body, m.links, computeForwardKinematics=True, physicsClientId=m.client)
            coms = np.array([s[0] for s in states])
            potential[k] = -self._masses @ (coms @ self._gravity)
        return kinetic, potential

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, 6) a floating base's P and angular momentum about the centre of mass, summed over the model body's links
        (:class:`MassStates`)."""
        if not self._scene.chain.floating_base:
            raise NotImplementedError("a fixed base's momentum is not conserved: it is not reported")
        return np.array([s.momentum() for s in self._mass_states(q, qdot)])

    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        """(B, 3) [m]: a fixed base's by :class:`PybulletChain` (``getLinkState``, float32); a floating base's end
        effector link frame in the world, in double (:func:`link_frame`)."""
        if not self._scene.chain.floating_base:
            return self._kinematics.end_effector_frames(np.atleast_2d(q))[0]
        m = self._model
        link = link_index(m.body, m.client, self._scene.chain.end_effector_name)
        out = []
        for row in np.atleast_2d(q):
            m.reset(row, np.zeros(len(row) - 1))
            out.append(link_frame(m.client, m.body, link, m.base)[1])
        return np.array(out)
