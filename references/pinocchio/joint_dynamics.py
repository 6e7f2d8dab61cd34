"""A chain's joint-space dynamics in Pinocchio: mass matrix, bias forces, inverse and forward dynamics (issue #27).

What Pinocchio is given, and each default handled (each pinned by ``tests/references/test_joint_dynamics_engines.py``)
---------------------------------------------------------------------------------------------------------
- The model: the URDF text of :func:`references.common.dynamics_urdf.dynamics_urdf` (the chain's file, base
  subtree only, without geometry and ``<dynamics>``, held joints fixed, links without ``<inertial>`` given an
  explicit zero one; or the chain's declared mass properties), read by Pinocchio's OWN URDF parser
  (``buildModelFromXML``, fixed base). No mass property is ever taken from the chain of a file. Links hung by
  fixed joints are merged into their joint's ``model.inertias`` by the parser.
- ``model.damping`` and ``model.friction`` (read from ``<dynamics>``) are 0: ``dynamics_urdf`` strips
  ``<dynamics>``, and no algorithm used here reads them anyway (``aba`` and ``rnea`` ignore them).
- Gravity: ``model.gravity`` = the scene's ``gravity_world`` exactly; None is zero (Pinocchio's default is
  (0, 0, -9.81)).
- Damping D = diag(the chain's damping), added here: tau = ``rnea`` + D qdot, qddot = ``aba``(tau - D qdot).
- Armature: ``model.armature`` = the chain's armature; Pinocchio 4.1's ``crba`` adds it to M's diagonal, ``rnea``
  adds armature * qddot and ``aba`` includes it (measured, and pinned by the tests: an armature changes M by
  exactly diag(armature)).
- M = ``crba`` (4.1 fills both triangles; the strict lower one is taken from the upper here all the same, as
  older Pinocchio filled only the upper); h = ``nle`` (Coriolis, centrifugal and gravity).
- Configurations: a continuous joint has nq = 2, (cos q, sin q); velocities are indexed by each chain joint's
  ``idx_v`` (joints found by name).
- Kinetic energy from Pinocchio's own link kinematics, not from M: ``forwardKinematics(q, v)``, then per chain
  joint 1/2 v_i^T I_i v_i with ``data.v[i]`` (the joint's spatial velocity in its own frame) and
  ``model.inertias[i]`` (its spatial inertia, fixed children merged): ``Inertia.vtiv``.
- Joint limits: Pinocchio's dynamics never applies them.
"""

from __future__ import annotations

import os
import tempfile

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.conventions import fmt
from simparity.references.common.dynamics_mjcf import dynamics_mjcf
from simparity.references.common.dynamics_urdf import chain_joint_names, dynamics_source, dynamics_urdf
from simparity.references.common.quiet import captured_output
from simparity.references.pinocchio.joints import configuration
from simparity.references.pinocchio.mass import mass_matrix


@dataclass(frozen=True)
class ChainModel:
    """Pinocchio's model of a chain's dynamics (see the module docstring), shared by joint-space dynamics and joint
    motion (:mod:`references.pinocchio.joint_motion`).

    Attributes
    ----------
    model : pinocchio.Model
        With the scene's gravity and the chain's armature.
    joint_ids : list of int
        Pinocchio's joint id of each chain joint.
    idx_q : list of int
        Configuration index of each chain joint.
    continuous : list of bool
        Whether each chain joint is continuous (nq = 2: (cos q, sin q) at ``idx_q``).
    idx_v : (n,) int ndarray
        Velocity index of each chain joint.
    damping : (n,) ndarray
        The chain's joint damping [N m s/rad or N s/m].
    source : str
        Where the model comes from and how gravity, armature and damping reach it (for the rows' detail).
    """

    model: pin.Model
    joint_ids: list[int]
    idx_q: list[int]
    continuous: list[bool]
    idx_v: np.ndarray
    damping: np.ndarray
    source: str

    def configuration(self, q_row: np.ndarray) -> np.ndarray:
        """Pinocchio configuration (nq,) of joint values (n,): (cos, sin) for continuous joints."""
        return configuration(self.model, self.idx_q, self.continuous, q_row)

    def velocity(self, qdot_row: np.ndarray) -> np.ndarray:
        """Pinocchio velocity (nv,) of joint rates (n,) (or any joint-space vector: forces, accelerations)."""
        v = np.zeros(self.model.nv)
        v[self.idx_v] = qdot_row
        return v


def chain_model(chain: Chain, gravity_world: np.ndarray | None) -> ChainModel:
    """``chain``'s dynamics model read by Pinocchio's URDF parser, ``gravity_world`` ((3,) [m/s^2] in the base
    frame, None for none) as ``model.gravity`` and the chain's armature as ``model.armature``."""
    printed = None
    try:
        with captured_output() as printed:
            model = _mjcf_model(chain) if chain.mjcf_path is not None else (
                pin.buildModelFromXML(dynamics_urdf(chain), pin.JointModelFreeFlyer()) if chain.floating_base
                else pin.buildModelFromXML(dynamics_urdf(chain)))
    except (RuntimeError, ValueError) as err:  # urdfdom says why on stderr ("joint [j]: limit has no effort")
        said = [line.strip()[len("Error:"):].strip() for line in (printed.text if printed else "").splitlines()
                if line.strip().startswith("Error:")]
        raise ValueError(f"{err}{f' (urdfdom: {said[0]})' if said else ''}") from None
    model.gravity = pin.Motion(np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float),
                               np.zeros(3))
    joint_ids = [model.getJointId(name) for name in chain_joint_names(chain)]
    missing = [name for name, i in zip(chain_joint_names(chain), joint_ids) if i >= model.njoints]
    if missing:
        composite = [name for name, joint in zip(model.names, model.joints) if joint.shortname() == COMPOSITE]
        raise PinocchioModelError(f"the chain's joints {missing[:3]} are no Pinocchio joints of their own"
                                  + (f": its MJCF parser merges a body's several joints into one composite joint "
                                     f"({', '.join(composite[:3])}), addressed as a whole" if composite else ""))
    joints = [model.joints[i] for i in joint_ids]
    idx_v = np.array([j.idx_v for j in joints])
    armature = np.zeros(model.nv)
    armature[idx_v] = [j.armature for j in chain.joints]
    model.armature = armature
    gravity = "none" if gravity_world is None else fmt(gravity_world)
    root = "; the base a JointModelFreeFlyer" if chain.floating_base else ""
    parser = "buildModelFromMJCF" if chain.mjcf_path is not None else "buildModelFromXML"
    source = (f"pinocchio.{parser} of {dynamics_source(chain)}{root}; gravity {gravity}; armature as "
              "model.armature")
    return ChainModel(model, joint_ids, [j.idx_q for j in joints], [j.nq == 2 for j in joints], idx_v,
                      np.array([j.damping for j in chain.joints]), source)


def _mjcf_model(chain: Chain) -> pin.Model:
    """Pinocchio's MJCF parser on :func:`references.common.dynamics_mjcf.dynamics_mjcf` (it reads files only: the
    text is written to a temporary one), a floating base its free flyer."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "model.xml")
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(dynamics_mjcf(chain))
        if chain.floating_base:  # with a root joint it answers (model, constraint models) and needs the joint's name
            return pin.buildModelFromMJCF(path, pin.JointModelFreeFlyer(), "root_joint")[0]
        return pin.buildModelFromMJCF(path)


COMPOSITE = "JointModelComposite"
"""The joint Pinocchio's MJCF parser makes of a body's several joints (the MuJoCo humanoid's hips: Composite_right_hip_x
of right_hip_x, right_hip_z and right_hip_y), one joint with one placement and one inertia."""


class PinocchioModelError(ValueError):
    """Pinocchio's model of the file does not hold the chain's joints one by one."""


def pinocchio_dynamics_problem(chain: Chain) -> str:
    """Why Pinocchio cannot build the chain's dynamics ("" when it can): its parser's refusal, in its words, or the
    chain's joints it does not keep apart."""
    parser = "MJCF" if chain.mjcf_path is not None else "URDF"
    try:
        chain_model(chain, None)
    except PinocchioModelError as error:
        return f"Pinocchio's {parser} parser loads the file, but {error}"
    except (RuntimeError, ValueError) as error:
        return f"Pinocchio's {parser} parser refuses the file: {' '.join(str(error).split())}"
    return ""


class PinocchioJointDynamics(JointDynamicsModel):
    """A chain's joint-space dynamics from Pinocchio's recursive algorithms (see the module docstring).

    Attributes
    ----------
    model, data : pinocchio.Model, pinocchio.Data
    joint_ids : list of int
        Pinocchio's joint id of each chain joint.
    idx_v : (n,) int ndarray
        Velocity index of each chain joint.
    damping : (n,) ndarray
        The chain's joint damping [N m s/rad or N s/m].
    """

    def __init__(self, chain: Chain, gravity_world: np.ndarray | None) -> None:
        self._chain = chain_model(chain, gravity_world)
        self.model, self.data = self._chain.model, self._chain.model.createData()
        self.joint_ids, self.idx_v, self.damping = self._chain.joint_ids, self._chain.idx_v, self._chain.damping
        self._configuration, self._velocity = self._chain.configuration, self._chain.velocity
        self.detail = (f"{self._chain.source}; M = crba, h = nle, tau = rnea + D qdot, qddot = aba(tau - D qdot); "
                       "kinetic energy from forwardKinematics' joint velocities and model.inertias")

    def configuration(self, q_row: np.ndarray) -> np.ndarray:
        """Pinocchio's configuration (nq,) of a project configuration (n,)."""
        return self._configuration(q_row)

    def local_velocity(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """Pinocchio's velocity (nv,) of a project state q (1, n), qdot (1, n) (a fixed base's: its joint rates)."""
        return self._velocity(qdot[0])

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        out = np.empty((len(q), len(self.idx_v), len(self.idx_v)))
        for k, row in enumerate(q):
            out[k] = mass_matrix(self.model, self.data, self._configuration(row))[np.ix_(self.idx_v, self.idx_v)]
        return out

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return np.array([pin.nle(self.model, self.data, self._configuration(row), self._velocity(rates))[self.idx_v]
                         for row, rates in zip(q, qdot)]).reshape(np.shape(q))

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        tau = [pin.rnea(self.model, self.data, self._configuration(row), self._velocity(rates),
                        self._velocity(accelerations))[self.idx_v]
               for row, rates, accelerations in zip(q, qdot, qddot)]
        return np.array(tau).reshape(np.shape(q)) + self.damping * qdot

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        damped = tau - self.damping * qdot
        return np.array([pin.aba(self.model, self.data, self._configuration(row), self._velocity(rates),
                                 self._velocity(force))[self.idx_v]
                         for row, rates, force in zip(q, qdot, damped)]).reshape(np.shape(q))

    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        out = np.empty(len(q))
        for k, (row, rates) in enumerate(zip(q, qdot)):
            pin.forwardKinematics(self.model, self.data, self._configuration(row), self._velocity(rates))
            out[k] = sum(0.5 * self.model.inertias[i].vtiv(self.data.v[i]) for i in self.joint_ids)
        return out

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        """Pinocchio merges every link welded by a fixed joint into its joint's body (``model.inertias``: mass,
        lever and inertia about the centre of mass in the joint frame); placed by ``forwardKinematics``' ``oMi``. The
        axis is the joint's motion subspace (``getJointJacobian`` in its LOCAL frame: the angular part of a revolute
        joint, the linear part of a prismatic one) turned into the base frame."""
        model, data = self.model, self.data
        out = [np.empty((len(q), len(self.joint_ids)) + tail) for tail in ((), (3,), (3, 3), (3,), (3,))]
        for k, row in enumerate(q):
            configuration = self._configuration(row)
            pin.forwardKinematics(model, data, configuration)
            pin.computeJointJacobians(model, data, configuration)
            for i, (joint, column) in enumerate(zip(self.joint_ids, self.idx_v)):
                placement, inertia = data.oMi[joint], model.inertias[joint]
                rotation = placement.rotation
                # (6, nv): reshaped, for the binding returns a (6,) vector when nv is 1
                jacobian = np.asarray(pin.getJointJacobian(model, data, joint, pin.ReferenceFrame.LOCAL))
                motion = jacobian.reshape(6, model.nv)[:, column]
                axis = motion[3:] if np.linalg.norm(motion[3:]) > np.linalg.norm(motion[:3]) else motion[:3]
                out[0][k, i] = inertia.mass
                out[1][k, i] = placement.act(inertia.lever)
                out[2][k, i] = rotation @ inertia.inertia @ rotation.T
                out[3][k, i] = rotation @ axis
                out[4][k, i] = placement.translation
        return RigidGroups(*out)

    def compiled_joints(self) -> CompiledJoints:
        """The joint model's type (``shortname``: a prismatic one's names ``Prismatic`` or ``JointModelP``) and
        ``lowerPositionLimit`` / ``upperPositionLimit`` at its configuration index; an unbounded revolute joint
        (``RevoluteUnbounded``, ``RUB``: a URDF continuous joint, nq = 2) holds none (its +-1.01 bound the cosine and
        sine)."""
        joints = [self.model.joints[i] for i in self.joint_ids]
        names = [j.shortname() for j in joints]
        unbounded = np.array(["Unbounded" in name or name.startswith("JointModelRUB") for name in names])
        lower = np.array([self.model.lowerPositionLimit[j.idx_q] for j in joints])
        upper = np.array([self.model.upperPositionLimit[j.idx_q] for j in joints])
        return CompiledJoints(np.array(["Prismatic" in name or name.startswith("JointModelP") for name in names]),
                              np.where(unbounded, -np.inf, lower), np.where(unbounded, np.inf, upper))

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """Pinocchio's analytic derivatives: ``computeRNEADerivatives`` at q̈ = ``aba``(τ - D q̇) (+ D on ∂τ/∂q̇) and
        ``computeABADerivatives`` at τ - D q̇ (∂q̈/∂q̇ - ∂q̈/∂τ D); a continuous joint on its angle (the tangent)."""
        index = np.ix_(self.idx_v, self.idx_v)
        damping = np.diag(self.damping)
        out = [np.empty((len(q), len(self.idx_v), len(self.idx_v))) for _ in range(5)]
        accelerations = self.forward_dynamics(q, qdot, tau)
        for k, (row, rates, force, acceleration) in enumerate(zip(q, qdot, tau, accelerations)):
            configuration, velocity = self._configuration(row), self._velocity(rates)
            dq, dv, _ = pin.computeRNEADerivatives(self.model, self.data, configuration, velocity,
                                                  self._velocity(acceleration))
            out[0][k], out[1][k] = np.asarray(dq)[index], np.asarray(dv)[index] + damping
            aq, av, atau = pin.computeABADerivatives(self.model, self.data, configuration, velocity,
                                                    self._velocity(force - self.damping * rates))
            atau = np.asarray(atau)[index]
            out[2][k], out[3][k], out[4][k] = np.asarray(aq)[index], np.asarray(av)[index] - atau @ damping, atau
        return DynamicsDerivatives(out[0], out[1], out[2], out[3], out[4])
