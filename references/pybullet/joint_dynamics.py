"""PyBullet's joint-space dynamics of a chain: M, h and inverse dynamics from its inverse-dynamics library, forward
dynamics from one step of its simulator, kinetic energy from its link states.

PyBullet reads :func:`references.common.dynamics_urdf.dynamics_urdf` (the chain's own file below its base link,
without geometry and ``<dynamics>``, held joints fixed, links without ``<inertial>`` given an explicit zero one; or
the declared mass properties of a chain without a file) with its own URDF parser, loaded from a temporary file
(``useFixedBase``; the adapter's ``_load_urdf``, its console output kept off). Joints are found by name
(``getJointInfo``): PyBullet counts every URDF joint, fixed ones too, and its calls take the positions of ALL movable
joints in its own order. Each default below is switched off or set, and pinned by
``tests/references/pybullet/test_joint_dynamics.py``:

- Gravity defaults to 0: set to exactly the scene's ``gravity_world`` (None: zero).
- Inertia: ``URDF_USE_INERTIA_FROM_FILE`` (else PyBullet recomputes it from collision shapes: a body without any
  gets ~1e-6 kg m^2). A link without ``<inertial>`` would get 1 kg and a unit inertia; the export's explicit zero
  gives it mass 0. Off-diagonal inertias are diagonalised by Bullet's Jacobi iteration
  (``btMatrix3x3::diagonalize``, threshold 1e-6 of the trace, then one more rotation) and the remaining
  off-diagonal terms dropped: the tensors PyBullet uses are off by up to 8e-9 relative (panda_link1), M by up to
  1.3e-10 and qddot by 1.7e-9 against Pinocchio (Panda; arms with diagonal inertias agree to ~1e-15).
- Non-unit axes: PyBullet keeps the URDF's axis as written; its simulator moves a joint along ``axis * qdot``
  (``btMultiBody::setupRevolute``) while rotating positions by q about the unit axis, and its inverse-dynamics library
  normalises it: with axis (0, 0, 2) the link turns at 2 qdot. Every ``<axis>`` is normalised here (the model's
  meaning: q is the angle or distance along the unit axis).
- Joint limits act by default (a limit constraint per limited joint; ``changeDynamics`` cannot remove one from
  Python, the binding drops lower > upper): ``jointLimitForce`` 0 leaves the constraint no impulse.
- Joint velocities are capped at 100 rad/s (``maxJointVelocity``): raised to :data:`MAX_VELOCITY` (1e300; a stepped
  velocity at the cap fails the row instead of clipping qddot).
- Every revolute and prismatic joint starts with a velocity motor braking it to 0 (max impulse 1 per step):
  ``setJointMotorControlArray(VELOCITY_CONTROL, forces=0)`` disables it; torques are given with TORQUE_CONTROL.
- Link linear and angular damping default to 0.04 (body-wide): 0.
- ``jointDamping`` is the chain's ``Joint.damping`` (PyBullet applies -damping qdot before each step); the URDF's
  ``<dynamics damping friction>`` is stripped by the export. ``calculateInverseDynamics`` ignores jointDamping:
  D qdot is added here.
- URDF multibodies never sleep unless loaded with ``URDF_ENABLE_SLEEPING`` (not passed).

Two PyBullet models, each a fresh body in a DIRECT world of its own (:class:`ChainBodies`, which
:mod:`references.pybullet.joint_motion` reuses with the scene's time step and a body per copy):

- ``calculateMassMatrix`` / ``calculateInverseDynamics`` run on a btInverseDynamics tree that PyBullet builds from
  the body at the first such call and CACHES (a later ``changeDynamics`` of a mass does not reach it): it is built
  here once the body is configured. M = calculateMassMatrix(q), h = calculateInverseDynamics(q, qdot, 0),
  tau = calculateInverseDynamics(q, qdot, qddot) + D qdot. The tree's root is Bullet's base INERTIAL frame, and it
  takes the world's gravity as given in that frame: a root link whose ``<inertial>`` is rotated would feel gravity
  turned. The base never moves, so :mod:`references.common.dynamics_urdf` gives it (and every link welded to it) the
  explicit zero ``<inertial>``, whose frame is the link's: gravity is the world's.
- ``forward_dynamics`` steps the second body once: ``resetJointState`` (q, qdot), TORQUE_CONTROL tau,
  ``stepSimulation`` with time step :data:`STEP`, qddot = (qdot' - qdot) / STEP. Bullet's step is semi-implicit:
  qdot' = qdot + STEP * qddot(q, qdot, tau) from its articulated-body algorithm
  (``computeAccelerationsArticulatedBodyAlgorithmMultiDof``), with the joint damping at qdot, so the difference
  is exact up to rounding. It is the forward dynamics PyBullet simulates with, and an algorithm independent of the
  tree: forward(inverse(qddot)) = qddot then checks Bullet's two codes against each other (measured agreement
  ~1e-15 relative with M^-1 (tau - h - D qdot) from the tree).
- ``link_kinetic_energy``: ``getLinkStates(computeLinkVelocity=1, computeForwardKinematics=1)`` gives each link's
  centre-of-mass velocity, angular velocity and the world orientation R of its inertial (principal-axes) frame, all
  double; ``getDynamicsInfo`` its mass and principal moments I; sum 1/2 m |v|^2 + 1/2 (R^T w)^T I (R^T w) over
  every link (fixed-joint links and held branches are links of their own in PyBullet). The URDF link frames
  ``getLinkState`` returns (``worldLinkFrameOrientation``) are FLOAT32 (composed in the client's b3Transform): R from
  them would cost ~5e-9 relative.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.errors import SimparityError
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact
from simparity.references.common.conventions import fmt, quat_wxyz_to_matrix, wxyz_from_xyzw
from simparity.references.common.rigid_groups import summed
from simparity.references.common.dynamics_urdf import chain_joint_names, dynamics_source, dynamics_urdf
from simparity.references.common.quiet import captured_output
from simparity.references.pybullet.adapter import _Client, _load_mjcf, _load_urdf, pybullet_mjcf
from simparity.references.pybullet.chain_contact import with_spheres
from simparity.references.pybullet.floating_body import BaseInertial
from simparity.references.pybullet.quiet import pybullet

STEP = 1.0  # [s]
"""Time step of the stepped body. qdot' = qdot + STEP qddot is rounded to eps max(|qdot|, STEP |qddot|), so
(qdot' - qdot) / STEP carries eps (|qdot| / STEP + |qddot|): a long step costs nothing (the step starts from a
reset state, and nothing else in the world acts) and keeps the estimate as precise as the tree's (at 1e-3 s a
state with |qdot| = 1 and |qddot| = 1e-3 would lose 6 digits)."""


MAX_VELOCITY = 1e300  # [rad/s or m/s]
"""PyBullet's joint velocity cap (its default 100, the stepping adapter's 1e9) for the stepped body: one step of
STEP reaches qdot + qddot, and a cap below that clips qddot (a 1 g link of inertia 1e-10 kg m^2 at the tip of an arm
accelerates at ~1e10 rad/s^2 under 1 N m: with the cap at 1e9 its qddot came out 14 % off). Bullet is double
precision: 1e300 clips nothing a finite state reaches; a velocity at the cap is refused (:data:`CLIPPED`)."""
CLIPPED = 0.5 * MAX_VELOCITY
"""A stepped velocity this large has reached the cap: the row fails with the reason instead of a clipped qddot."""


def _axes(root: ET.Element) -> list[tuple[ET.Element, ET.Element, np.ndarray]]:
    """(``<joint>``, its ``<axis>`` element, the axis' xyz (3,)) of every joint with an ``<axis>``, in file order."""
    found = []
    for joint in root.iter("joint"):
        for axis in joint.findall("axis"):
            found.append((joint, axis, np.array([float(v) for v in axis.get("xyz", "1 0 0").split()])))
    return found


def unit_axes(text: str) -> str:
    """URDF ``text`` with every joint ``<axis>`` normalised (see the module docstring); a zero axis (on a fixed or
    held joint, which has none: real files write ``0 0 0`` there) is left as written."""
    root = ET.fromstring(text)
    for _, axis, xyz in _axes(root):
        if np.any(xyz):
            axis.set("xyz", fmt(xyz / np.linalg.norm(xyz)))
    return ET.tostring(root, encoding="unicode")


def axes_changed(chain: Chain) -> str:
    """Which joints :func:`unit_axes` changes in ``chain``'s dynamics URDF, named for the rows' detail."""
    names = [joint.get("name", "") for joint, _, xyz in _axes(ET.fromstring(dynamics_urdf(chain)))
             if joint.get("type") != "fixed" and np.linalg.norm(xyz) != 1.0]  # a fixed joint's axis means nothing
    return f"axes normalised ({'non-unit: ' + ', '.join(names) if names else 'all unit already'})"


class ChainBodies:
    """``copies`` bodies of the chain in a private DIRECT world, every default of the module docstring switched off:
    gravity exactly ``gravity_world`` (None: zero), time step ``time_step`` [s] without sub-steps. The bodies have no
    collision shapes, so they never touch each other: one ``stepSimulation`` steps each as if it were alone. With
    ``contact`` the URDF's links carry its spheres (:func:`references.pybullet.chain_contact.with_spheres`; the file
    loaded is ``urdf_text``).

    Attributes
    ----------
    client : int
    bodies : list of int
        The bodies' unique ids, one per copy.
    body : int
        The first copy's.
    joints : list of int
        PyBullet joint index of each chain joint (the same in every copy).
    columns : list of int
        Position of each chain joint among the body's movable joints (PyBullet's order).
    links : list of int
        Every link of the body (its joints' indices; the fixed base, -1, left out).
    """

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None, time_step: float = STEP,
                 copies: int = 1, contact: ChainContact | None = None) -> None:
        self._client = _Client()
        c = self.client = self._client.id
        pybullet.setTimeStep(time_step, physicsClientId=c)
        pybullet.setPhysicsEngineParameter(numSubSteps=0, physicsClientId=c)
        pybullet.setGravity(*(np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float)),
                            physicsClientId=c)
        self.urdf_text = ""
        if chain.mjcf_path is not None:
            mjcf = pybullet_mjcf(chain)
            self.bodies = [_load_mjcf(c, mjcf) for _ in range(copies)]
        else:
            text = unit_axes(dynamics_urdf(chain))
            if contact is not None:
                text = with_spheres(text, chain, contact)
            self.urdf_text = text
            self.bodies = [_load_urdf(c, text, useFixedBase=not chain.floating_base) for _ in range(copies)]
        self.body = b = self.bodies[0]
        self.base = BaseInertial.of(c, b) if chain.floating_base else None
        info = [pybullet.getJointInfo(b, j, physicsClientId=c)
                for j in range(pybullet.getNumJoints(b, physicsClientId=c))]
        index = {i[1].decode(): i[0] for i in info}
        movable = [i[0] for i in info if i[2] != pybullet.JOINT_FIXED]
        self.joints = [index[name] for name in chain_joint_names(chain)]
        self.columns = [movable.index(j) for j in self.joints]
        self.links = [i[0] for i in info]
        self._movable = movable
        for body in self.bodies:
            self._configure(body, chain)

    def _configure(self, body: int, chain: Chain) -> None:
        """Link damping 0, velocity cap raised, jointDamping the chain's, joint limits and braking motors off."""
        c = self.client
        pybullet.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0, maxJointVelocity=MAX_VELOCITY,
                                physicsClientId=c)
        for joint, j in zip(chain.joints, self.joints):
            pybullet.changeDynamics(body, j, jointDamping=joint.damping, jointLimitForce=0.0, physicsClientId=c)
        pybullet.setJointMotorControlArray(body, self._movable, pybullet.VELOCITY_CONTROL,
                                           forces=[0.0] * len(self._movable), physicsClientId=c)

    def build_tree(self) -> None:
        """Have PyBullet build (and cache) the first body's inverse-dynamics tree now that it is configured."""
        with captured_output():  # PyBullet prints while building it
            pybullet.calculateMassMatrix(self.body, self.movable(np.zeros(len(self.joints))),
                                         physicsClientId=self.client)

    def movable(self, row: np.ndarray) -> list[float]:
        """The values ``row`` (n,) of the chain's joints as PyBullet's list over all movable joints."""
        out = np.zeros(len(self._movable))
        out[self.columns] = row
        return out.tolist()

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M (B, n, n) at ``q`` (B, n) from the first body's tree (:meth:`build_tree` first)."""
        chain_block = np.ix_(self.columns, self.columns)
        return np.stack([np.array(pybullet.calculateMassMatrix(self.body, self.movable(row),
                                                               physicsClientId=self.client))[chain_block]
                         for row in q])

    def reset(self, q: np.ndarray, qdot: np.ndarray, copy: int = 0) -> None:
        """Put body ``copy`` at the state ``q``, ``qdot`` ((n,) each; a floating base's (7 + n,) and (6 + n,), the
        project's convention: :class:`BaseInertial`)."""
        if self.base is not None:
            self.base.put(self.client, self.bodies[copy], np.asarray(q, dtype=float), np.asarray(qdot, dtype=float))
            q, qdot = q[7:], qdot[6:]
        for j, position, velocity in zip(self.joints, q, qdot):
            pybullet.resetJointState(self.bodies[copy], j, float(position), float(velocity),
                                     physicsClientId=self.client)

    def state(self, copy: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """(q, qdot) of body ``copy`` now, as :meth:`reset` takes them."""
        states = pybullet.getJointStates(self.bodies[copy], self.joints, physicsClientId=self.client)
        q, qdot = np.array([s[0] for s in states]), np.array([s[1] for s in states])
        if self.base is None:
            return q, qdot
        base_q, base_qdot = self.base.read(self.client, self.bodies[copy])
        return np.concatenate([base_q, q]), np.concatenate([base_qdot, qdot])


def _rows(*arrays: np.ndarray) -> list[np.ndarray]:
    """Each array as float (B, n): a single state (n,) becomes a batch of one."""
    return [np.atleast_2d(np.asarray(a, dtype=float)) for a in arrays]


class PybulletJointDynamics(JointDynamicsModel):
    """A chain's joint-space dynamics in PyBullet (module docstring: what is set, which call gives what)."""

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        self._tree = ChainBodies(chain, gravity_world)
        self._tree.build_tree()
        self._stepped = ChainBodies(chain, gravity_world)
        self._damping = np.array([j.damping for j in chain.joints])
        loader = ("loadMJCF (the base fixed by PyBullet's own fixed root joint) of" if chain.mjcf_path is not None
                  else "loadURDF(useFixedBase, URDF_USE_INERTIA_FROM_FILE) of")
        axes = ("axes normalised by PyBullet's MJCF importer" if chain.mjcf_path is not None
                else axes_changed(chain))
        self.detail = (f"{loader} {dynamics_source(chain)}; {axes}; gravity set; link damping 0, jointDamping = the chain's, joint limits, "
                       f"velocity cap and braking motors off; M, h, tau from calculateMassMatrix / "
                       f"calculateInverseDynamics (+ D qdot); qddot from one stepSimulation of {STEP:g} s under TORQUE_CONTROL; kinetic energy "
                       f"from getLinkStates' centre-of-mass velocities and inertial frames")

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        (q,) = _rows(q)
        return self._tree.mass_matrix(q)

    def _inverse(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        """calculateInverseDynamics (without damping), (B, n)."""
        t = self._tree
        return np.stack([np.array(pybullet.calculateInverseDynamics(
            t.body, t.movable(a), t.movable(v), t.movable(dv), physicsClientId=t.client))[t.columns]
            for a, v, dv in zip(q, qdot, qddot)])

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        q, qdot = _rows(q, qdot)
        return self._inverse(q, qdot, np.zeros_like(q))

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        q, qdot, qddot = _rows(q, qdot, qddot)
        return self._inverse(q, qdot, qddot) + self._damping * qdot

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        q, qdot, tau = _rows(q, qdot, tau)
        s = self._stepped
        out = np.empty_like(q)
        for k in range(len(q)):
            s.reset(q[k], qdot[k])
            pybullet.setJointMotorControlArray(s.body, s.joints, pybullet.TORQUE_CONTROL, forces=tau[k].tolist(),
                                               physicsClientId=s.client)
            pybullet.stepSimulation(physicsClientId=s.client)
            states = pybullet.getJointStates(s.body, s.joints, physicsClientId=s.client)
            stepped = np.array([state[1] for state in states])
            if not np.all(np.abs(stepped) < CLIPPED):
                raise SimparityError(f"PyBullet's stepped joint velocity reached its cap {MAX_VELOCITY:g} (qddot "
                                     "would be clipped): forward dynamics not measurable at this state")
            out[k] = (stepped - qdot[k]) / STEP
        return out

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        q, qdot = _rows(q, qdot)
        t = self._tree
        info = [pybullet.getDynamicsInfo(t.body, link, physicsClientId=t.client) for link in t.links]
        mass = np.array([i[0] for i in info])
        moments = np.array([i[2] for i in info])
        out = np.empty(len(q))
        for k in range(len(q)):
            t.reset(q[k], qdot[k])
            states = pybullet.getLinkStates(t.body, t.links, computeLinkVelocity=1, computeForwardKinematics=1,
                                            physicsClientId=t.client)
            velocity = np.array([s[6] for s in states])
            rotation = quat_wxyz_to_matrix(wxyz_from_xyzw(np.array([s[1] for s in states])))
            omega_principal = np.einsum("lji,lj->li", rotation, np.array([s[7] for s in states]))
            out[k] = 0.5 * (mass @ np.sum(velocity**2, axis=1) + np.sum(moments * omega_principal**2))
        return out

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        """PyBullet keeps every fixed-joint link as a link of its own: each chain joint's group is the links whose
        nearest movable joint up the tree (``getJointInfo``'s parent index) is that joint, summed with the references'
        own code (:mod:`references.common.rigid_groups`) from ``getDynamicsInfo`` (mass, principal moments) and
        ``getLinkStates`` (the centre of mass and its inertial frame, double). The link frame is the inertial frame
        moved back by ``getDynamicsInfo``'s local inertial pose (double), not ``worldLinkFramePosition`` (float32);
        the axis is ``getJointInfo``'s (the file's, made unit by the export), which PyBullet gives in the link's inertial
        frame (its link frame), not the URDF link frame."""
        q, _ = _rows(q, np.zeros_like(q))
        t = self._tree
        c = t.client
        info = {link: pybullet.getJointInfo(t.body, link, physicsClientId=c) for link in t.links}
        dynamics = {link: pybullet.getDynamicsInfo(t.body, link, physicsClientId=c) for link in t.links}
        mover = {}
        for link in t.links:
            up = link
            while up != -1 and info[up][2] == pybullet.JOINT_FIXED:
                up = info[up][16]
            mover[link] = up
        members = [[link for link in t.links if mover[link] == joint] for joint in t.joints]
        local = {link: (np.array(dynamics[link][3]), quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(dynamics[link][4]))))
                 for link in t.links}
        out = [np.empty((len(q), len(t.joints)) + tail) for tail in ((), (3,), (3, 3), (3,), (3,))]
        for k in range(len(q)):
            t.reset(q[k], np.zeros_like(q[k]))
            states = dict(zip(t.links, pybullet.getLinkStates(t.body, t.links, computeForwardKinematics=1,
                                                              physicsClientId=c)))
            com = {link: np.array(states[link][0]) for link in t.links}
            frame = {link: quat_wxyz_to_matrix(wxyz_from_xyzw(np.array(states[link][1]))) for link in t.links}
            for i, (joint, group) in enumerate(zip(t.joints, members)):
                link_rotation = frame[joint] @ local[joint][1].T
                origin = com[joint] - link_rotation @ local[joint][0]
                inertias = np.array([frame[m] @ np.diag(dynamics[m][2]) @ frame[m].T for m in group])
                mass, centre, inertia = summed(np.array([dynamics[m][0] for m in group]),
                                               np.array([com[m] for m in group]), inertias, origin)
                out[0][k, i], out[1][k, i], out[2][k, i] = mass, centre, inertia
                out[3][k, i], out[4][k, i] = frame[joint] @ np.array(info[joint][13]), origin
        return RigidGroups(*out)

    def compiled_joints(self) -> CompiledJoints:
        """``getJointInfo``'s jointType (``JOINT_PRISMATIC``) and jointLowerLimit / jointUpperLimit; upper < lower is
        PyBullet's "no limit" (a continuous joint loads as (0, -1))."""
        t = self._tree
        info = [pybullet.getJointInfo(t.body, joint, physicsClientId=t.client) for joint in t.joints]
        lower, upper = np.array([i[8] for i in info], dtype=float), np.array([i[9] for i in info], dtype=float)
        unlimited = upper < lower
        return CompiledJoints(np.array([i[2] == pybullet.JOINT_PRISMATIC for i in info]),
                              np.where(unlimited, -np.inf, lower), np.where(unlimited, np.inf, upper))

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray):
        """PyBullet has none: its API computes no derivative of its dynamics."""
        raise NotImplementedError("PyBullet exposes no derivatives of its dynamics (no analytic or finite-difference "
                                  "Jacobian of calculateInverseDynamics or of its step)")
