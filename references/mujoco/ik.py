"""Damped least squares on MuJoCo's site Jacobian, as dm_control does it, behind :class:`core.engine.IKModel`.

MuJoCo has no IK solver; its ecosystem iterates damped least squares on ``mj_jacSite``.
This is dm_control's ``utils/inverse_kinematics.qpos_from_site_pose`` with its defaults,
step for step:

    err = (p_target - p, quat2Vel(q_target * conj(q_site)))    world axes, rot_weight 1
    err_norm = |err_pos| + |err_rot|
    dq = solve(J^T J + lambda I, J^T err)    lambda = 3e-2 while err_norm > 0.1,
                                             else least squares (lstsq) with lambda = 0
    halt when err_norm / |dq| > 20 (too little progress)
    dq *= min(1, 2.0 / |dq|); qpos = mj_integratePos(qpos, dq, 1)

Departures from dm_control, all because the scene decides: the stopping rule is the
scene's (position residual <= ``options.position_tolerance`` and angle <=
``options.orientation_tolerance``, checked also after the last update) instead of
``err_norm < tol``, and ``max_steps`` = ``options.max_iterations``.

Conventions and what the adapter does (pinned in ``tests/references/mujoco/test_ik.py``)
---------------------------------------------------------------------------
- The model is the chain's (:class:`references.mujoco.adapter.MujocoChain`: its URDF file
  without geometry, or the MJCF export); the end effector is its site. Targets are given
  in the chain's base frame and moved into MuJoCo's world (:mod:`references.common.base_frame`);
  residuals are distances, the same in either frame.
- ``mj_kinematics`` then ``mj_comPos`` before ``mj_jacSite`` (the Jacobian is silently
  zero without ``mj_comPos``); dm_control calls ``mj_fwdPosition``, which does both.
- MuJoCo quaternions are (w, x, y, z), the project's order: no reordering. The rotation
  error is MuJoCo's ``mju_quat2Vel`` of q_target * conj(q_site): the rotation vector of
  R_target R_site^T (angle in [0, pi]), in world axes like ``jacr``.
- No joint limits (dm_control ignores them): ``limit_violation`` says how far outside
  the returned joint values are.
- Residuals are MuJoCo's own (double): |err_pos| [m] and |err_rot| [rad] at the returned
  qpos. A progress halt is reported as ``"iteration_cap"`` (see :mod:`references.common.ik_outcome`).
"""

from __future__ import annotations

import mujoco
import numpy as np

from simparity.core.model.engine import IKModel
from simparity.core.model.ik_problem import IKTolerances, check_inputs
from simparity.core.model.ik_result import IKResult
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.ik_outcome import ik_outcome

SOLVERS = ("dls",)
"""dm_control's damped least squares."""

# dm_control qpos_from_site_pose defaults.
REGULARIZATION_THRESHOLD = 0.1  # err_norm above which lambda is used [mixed m and rad]
REGULARIZATION_STRENGTH = 3e-2  # lambda added to J^T J
MAX_UPDATE_NORM = 2.0  # largest |dq| per step [rad or m]
PROGRESS_THRESH = 20.0  # halt when err_norm / |dq| exceeds this


class MujocoIK(IKModel):
    """dm_control-style damped least squares on ``mj_jacSite``.

    Configures: dm_control's defaults (:data:`REGULARIZATION_THRESHOLD`,
    :data:`REGULARIZATION_STRENGTH`, :data:`MAX_UPDATE_NORM`, :data:`PROGRESS_THRESH`,
    rot_weight 1), max_steps = ``options.max_iterations``, and the scene's tolerances as
    the stopping rule.

    Parameters
    ----------
    kinematics : MujocoChain
        The chain's MuJoCo model (``references.mujoco.adapter``).
    chain : Chain
    solver : str
        ``"dls"``.
    options : IKTolerances
    """

    def __init__(self, kinematics, chain: Chain, solver: str, options: IKTolerances) -> None:
        if solver not in SOLVERS:
            raise ValueError(f"unknown MuJoCo IK solver {solver!r}, expected one of {SOLVERS}")
        self._chain, self._options = chain, options
        self._model, self._data = kinematics.model, kinematics.data
        self._qadr, self._dofadr, self._site = kinematics.qpos_adr, kinematics.dof_adr, kinematics.site
        self._base = kinematics.base
        self.detail = (f"dm_control qpos_from_site_pose on mj_jacSite: lambda {REGULARIZATION_STRENGTH:g} while "
                       f"err > {REGULARIZATION_THRESHOLD:g}, |dq| <= {MAX_UPDATE_NORM:g}, progress halt "
                       f"{PROGRESS_THRESH:g}; max_steps {options.max_iterations}; stops at the scene's "
                       "tolerances; no joint limits")

    def solve(self, target_position_world: np.ndarray, target_rotation_world: np.ndarray | None,
              q_start: np.ndarray) -> IKResult:
        p, r, q0 = check_inputs(self._chain, target_position_world, target_rotation_world, q_start)
        world_p, world_r = self._base.targets_to_world(p, r)
        quat = None if world_r is None else np.array([_mat2quat(m) for m in world_r])
        batch = len(p)
        q = np.empty_like(q0)
        iterations = np.empty(batch, int)
        position_residual, orientation_residual = np.empty(batch), np.zeros(batch)
        for k in range(batch):
            q[k], iterations[k], position_residual[k], orientation_residual[k] = self._dls(
                world_p[k], None if quat is None else quat[k], q0[k])
        return ik_outcome(self._chain, q, iterations, position_residual, orientation_residual, p, self._options)

    def _dls(self, target_pos: np.ndarray, target_quat: np.ndarray | None,
             q_row: np.ndarray) -> tuple[np.ndarray, int, np.floating, float | np.floating]:
        """One target; returns q (n,), updates applied, position [m] and angle [rad] residuals."""
        model, data = self._model, self._data
        rows = 3 if target_quat is None else 6
        jac = np.zeros((rows, model.nv))
        jacr = None if target_quat is None else jac[3:]
        err = np.zeros(rows)
        site_quat, neg_site_quat, err_quat = np.empty(4), np.empty(4), np.empty(4)
        update = np.zeros(model.nv)
        data.qpos[self._qadr] = q_row
        steps = 0
        while True:
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            err[:3] = target_pos - data.site_xpos[self._site]
            position = np.linalg.norm(err[:3])
            angle: float | np.floating = 0.0
            if target_quat is not None:
                mujoco.mju_mat2Quat(site_quat, data.site_xmat[self._site])
                mujoco.mju_negQuat(neg_site_quat, site_quat)
                mujoco.mju_mulQuat(err_quat, target_quat, neg_site_quat)
                mujoco.mju_quat2Vel(err[3:], err_quat, 1.0)
                angle = np.linalg.norm(err[3:])
            solved = position <= self._options.position_tolerance and angle <= self._options.orientation_tolerance
            if solved or steps >= self._options.max_iterations:
                break
            err_norm = position + angle
            mujoco.mj_jacSite(model, data, jac[:3], jacr, self._site)
            regularization = REGULARIZATION_STRENGTH if err_norm > REGULARIZATION_THRESHOLD else 0.0
            dq = _nullspace_method(jac[:, self._dofadr], err, regularization)
            dq_norm = np.linalg.norm(dq)
            if err_norm > PROGRESS_THRESH * dq_norm:  # err_norm / |dq| > thresh, also for dq = 0
                break
            update[self._dofadr] = dq * min(1.0, MAX_UPDATE_NORM / dq_norm)
            mujoco.mj_integratePos(model, data.qpos, update, 1.0)
            steps += 1
        return data.qpos[self._qadr].copy(), steps, position, angle


def _mat2quat(rotation: np.ndarray) -> np.ndarray:
    """MuJoCo's quaternion (w, x, y, z) of a rotation matrix (3, 3)."""
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation).ravel())
    return quat


def _nullspace_method(jac: np.ndarray, err: np.ndarray, regularization: float) -> np.ndarray:
    """dm_control's step: solve (J^T J + lambda I) dq = J^T err, or lstsq(J, err) when lambda = 0.

    (m, n) x (m,) -> (n,).
    """
    if regularization > 0:
        return np.linalg.solve(jac.T @ jac + regularization * np.eye(jac.shape[1]), jac.T @ err)
    return np.linalg.lstsq(jac, err, rcond=-1)[0]
