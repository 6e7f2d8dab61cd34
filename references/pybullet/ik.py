"""PyBullet's ``calculateInverseKinematics`` behind :class:`core.engine.IKModel`.

PyBullet's IK (Bullet's ``IKTrajectoryHelper`` on Buss's ``Jacobian``) is damped least
squares, dq = (J^T J + diag(jointDamping))^-1 J^T e with each step's largest joint change
capped at 45 deg, iterated up to ``maxNumIterations`` times and stopped early when the
POSITION error falls below ``residualThreshold`` (the orientation error is never
tested). With lowerLimits, upperLimits, jointRanges and restPoses all given it switches
to a null-space variant that IGNORES jointDamping: it damps J J^T with a fixed
lambda^2 = 0.36 and adds (I - J^T (J J^T + lambda^2 I)^-1 J) times a push toward the
rest pose and back inside the limits. That projector is damped, so the push leaks into
the task and the iteration settles millimetres from the target (measured on the iiwa),
and the limits stay soft: the result can still lie outside them. The lists have the right
length (one entry per movable joint of the body, ``n_dof``; a list of any other length, the
body's joint count included, makes PyBullet fall back to the plain solver without a word,
bullet3 #3199, #1714): with them the result differs from the plain solver's, with a wrong
length it is the same bit for bit; the millimetres stay with limits pushed to +-1e6, with the
rest pose at the target's own configuration and with 2000 iterations (iiwa, UR5, Panda,
measured), so they are Bullet's damped projector (``Jacobian::CalcDeltaThetasDLSwithNullspace``),
reported upstream as bullet3 #2210 (:data:`NULLSPACE_LIMITATION`, in the rows' detail).

Conventions and what the adapter does (pinned in ``tests/references/pybullet/test_ik.py``)
-----------------------------------------------------------------------------
- The chain is the URDF of :func:`references.common.urdf_export.chain_urdf`, loaded with a fixed
  base (:class:`references.pybullet.adapter.PybulletChain`). Targets are given in the
  chain's base frame and moved into PyBullet's world (:mod:`references.common.base_frame`).
- PyBullet's target POSITION is the URDF link frame's origin of the end-effector link, but
  its target ORIENTATION is that of the link's INERTIAL frame, which PyBullet rotates to
  principal axes when the URDF inertia has products of inertia (measured on the Panda's
  ``panda_link7``: a 0.24 rad miss). The adapter passes R_target R_inertial, with
  R_inertial the inertial frame's orientation in the link frame (``getDynamicsInfo``).
- ``targetOrientation`` is a quaternion (x, y, z, w): reordered from the project's
  (w, x, y, z). Position-only targets are called without it.
- The solver starts from the body's current joint state: every target starts with the
  joints reset to ``q_start``. The call returns the movable joints in joint-index order,
  which is the chain's order.
- Residuals come from PyBullet's own forward kinematics (``getLinkState`` with
  ``computeForwardKinematics=True`` at the returned joint values): FLOAT32 link frames,
  so residuals below ~1e-7 m or ~3e-7 rad are rounding, and a 1e-6 tolerance is judged
  at float32 resolution.
- PyBullet reports neither iterations (``iterations`` is -1) nor why it stopped (see
  :mod:`references.common.ik_outcome` for the failure reasons); it does not clamp to the limits,
  and neither does the adapter (``limit_violation`` says how far outside they are).
- Its own stopping rule (:class:`StoppingRule`, the ``solve_rate_own_stop`` row): the position
  residual within ``residualThreshold`` (:data:`DEFAULT_RESIDUAL_THRESHOLD` by default, the
  scene's tolerance when tuned), the orientation never tested.
"""

from __future__ import annotations

import numpy as np
from simparity.references.pybullet.quiet import pybullet

from simparity.core.model.engine import IKModel, StoppingRule
from simparity.core.model.ik_problem import IKTolerances, check_inputs
from simparity.core.model.ik_result import IKResult
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.conventions import matrix_to_quat_wxyz, rotation_angle, xyzw_from_wxyz
from simparity.references.common.ik_outcome import ik_outcome

SOLVERS = ("calculateInverseKinematics", "calculateInverseKinematics-tuned",
           "calculateInverseKinematics-tuned-nullspace")
"""As users call it (PyBullet's defaults); tuned to the scene; tuned with limits and rest pose."""

# jointDamping of the tuned solvers, added to J^T J [m^2/rad^2]. Small against J^T J: on
# the iiwa its smallest nonzero eigenvalue has median 1.5e-2 (10th percentile 5.6e-4)
# over 1000 random configurations, so a step still removes >= 90 % of the error along
# that direction at the median, and (J^T J + d I) stays invertible although J^T J has
# rank <= 6 for 7 joints. PyBullet's default (0.5 per joint, the project's notes)
# stopped a 3-joint chain at 9.6e-3 m after 20 iterations where 1e-3 converged.
TUNED_JOINT_DAMPING = 1e-3

DEFAULT_RESIDUAL_THRESHOLD = 1e-4
"""[m] PyBullet's default ``residualThreshold``: it stops once the position error is below it."""

NULLSPACE_LIMITATION = (
    "upstream: Bullet's null-space IK damps its projector (J J^T + 0.36 I, jointDamping ignored), so the rest-pose "
    "and limit push leaks into the task and the solve settles ~mm from the target whatever the iterations "
    "(https://github.com/bulletphysics/bullet3/issues/2210)")
"""The known limitation of the ``-nullspace`` solver, in its ``solve_rate_own_stop`` row's detail."""

# Joint limits handed to the null-space solver for an unlimited joint [rad or m]: far
# outside any reachable value, so its limit push never acts (jointRanges divides it).
_UNLIMITED = 1e6


class PybulletIK(IKModel):
    """PyBullet ``calculateInverseKinematics`` (IK_DLS) on the adapter's URDF.

    Configures, per solver:

    - ``"calculateInverseKinematics"``: nothing beyond the target; PyBullet's defaults
      (maxNumIterations 20, residualThreshold 1e-4 m, default jointDamping).
    - ``"calculateInverseKinematics-tuned"``: maxNumIterations = ``options.max_iterations``,
      residualThreshold = ``options.position_tolerance``, jointDamping
      :data:`TUNED_JOINT_DAMPING` on every joint.
    - ``"calculateInverseKinematics-tuned-nullspace"``: the tuned settings plus
      lowerLimits / upperLimits / jointRanges from the chain (+-:data:`_UNLIMITED` for
      unlimited joints) and restPoses = ``q_start``, which switches on PyBullet's soft
      limit handling.

    Parameters
    ----------
    kinematics : PybulletChain
        The chain loaded in PyBullet (``references.pybullet.adapter``).
    chain : Chain
    solver : str
        One of :data:`SOLVERS`.
    options : IKTolerances
        The scene's tolerances and iteration cap.
    """

    def __init__(self, kinematics, chain: Chain, solver: str, options: IKTolerances) -> None:
        if solver not in SOLVERS:
            raise ValueError(f"unknown PyBullet IK solver {solver!r}, expected one of {SOLVERS}")
        self._chain, self._options, self._solver = chain, options, solver
        self._kinematics = kinematics
        self._settings = {}
        configured = "PyBullet defaults (maxNumIterations 20, residualThreshold 1e-4 m, jointDamping)"
        threshold = DEFAULT_RESIDUAL_THRESHOLD
        if solver != "calculateInverseKinematics":
            threshold = options.position_tolerance
            self._settings = dict(maxNumIterations=options.max_iterations,
                                  residualThreshold=options.position_tolerance,
                                  jointDamping=[TUNED_JOINT_DAMPING] * kinematics.n_dof)
            configured = (f"maxNumIterations {options.max_iterations}, residualThreshold "
                          f"{options.position_tolerance:g} m, jointDamping {TUNED_JOINT_DAMPING:g}")
        if solver.endswith("-nullspace"):
            lower = np.where(np.isfinite(chain.lower), chain.lower, -_UNLIMITED)
            upper = np.where(np.isfinite(chain.upper), chain.upper, _UNLIMITED)
            self._settings.update(lowerLimits=self._per_dof(lower, -_UNLIMITED),
                                  upperLimits=self._per_dof(upper, _UNLIMITED),
                                  jointRanges=self._per_dof(upper - lower, 2 * _UNLIMITED))
            configured += "; joint limits and restPoses = q_start (null-space variant, soft limits)"
        self.stopping_rule = StoppingRule(
            threshold, description=f"residualThreshold {threshold:g} m (PyBullet never tests the orientation)",
            note=NULLSPACE_LIMITATION if solver.endswith("-nullspace") else "")
        self.detail = (f"pybullet.calculateInverseKinematics (IK_DLS), {configured}; "
                       "residuals from getLinkState (float32); iterations not reported")

    def _per_dof(self, chain_values: np.ndarray, other: float) -> list[float]:
        """A list over the body's movable joints: the chain's values, ``other`` for joints off the chain."""
        out = np.full(self._kinematics.n_dof, other)
        out[self._kinematics.dof_index] = chain_values
        return out.tolist()

    def solve(self, target_position_world: np.ndarray, target_rotation_world: np.ndarray | None,
              q_start: np.ndarray) -> IKResult:
        p, r, q0 = check_inputs(self._chain, target_position_world, target_rotation_world, q_start)
        kin = self._kinematics
        settings = dict(self._settings)
        world_p, world_r = kin.base.targets_to_world(p, r)
        quat_xyzw = None if r is None else xyzw_from_wxyz(matrix_to_quat_wxyz(world_r @ kin.end_inertial_rotation))
        q = np.empty_like(q0)
        for k in range(len(p)):
            kin.set(q0[k])
            if self._solver.endswith("-nullspace"):
                settings["restPoses"] = self._per_dof(q0[k], 0.0)
            if quat_xyzw is not None:
                settings["targetOrientation"] = quat_xyzw[k].tolist()
            q[k] = np.asarray(pybullet.calculateInverseKinematics(
                kin.body, kin.end_link, world_p[k].tolist(), physicsClientId=kin.client, **settings))[kin.dof_index]
        position, rotation = kin.end_effector_frames(q)
        position_residual = np.linalg.norm(p - position, axis=1)
        orientation_residual = np.zeros(len(p)) if r is None else rotation_angle(rotation, r)
        return ik_outcome(self._chain, q, np.full(len(p), -1), position_residual, orientation_residual,
                          p, self._options)
