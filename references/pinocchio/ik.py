"""Pinocchio's documented CLIK iteration behind :class:`core.engine.IKModel`.

Pinocchio has no IK solver; its documentation ("Inverse kinematics (clik)") gives this
closed-loop iteration, reproduced here step for step on the end-effector FRAME:

    err = log6(oMf.actInv(oMdes))                  (6,) twist in the end-effector frame
    stop when |err| < eps, give up after IT_MAX updates
    J = -Jlog6(iMd.inverse()) @ J_local            computeFrameJacobian(..., LOCAL)
    v = -J^T (J J^T + damp I)^-1 err
    q = integrate(q, v * DT)

Position-only targets use the same damped update on the 3 translational rows of the
LOCAL_WORLD_ALIGNED frame Jacobian with err = p_des - p [m] and v = J^T (J J^T + damp
I)^-1 err.

Conventions and what the adapter does (pinned in ``tests/references/pinocchio/test_ik.py``)
-------------------------------------------------------------------------------
- The model is the chain's (:class:`references.pinocchio.adapter.PinocchioChain`: its
  URDF file without geometry, or the export, read by ``buildModelFromXML``; fixed base);
  the end effector is the BODY frame named after it. Targets are given in the chain's
  base frame and moved into Pinocchio's world (:mod:`references.common.base_frame`).
- A ``continuous`` (unlimited revolute) joint has nq = 2, (cos, sin): the start angle is
  converted in, the result converted back with atan2 (in (-pi, pi]). ``integrate``
  keeps (cos, sin) on the unit circle; nothing else is normalised.
- Only the chain's joints move: the Jacobian's columns of joints off the chain (above its
  base link, or on other branches of the file) are left out and their velocity is 0.
- No joint limits (the documentation has none): revolute angles can leave their limits
  and are returned as they are; ``limit_violation`` says by how much.
- Residuals come from Pinocchio's forward kinematics at the returned q (double):
  |p_des - p| [m] and the angle of R^T R_des [rad] (the norm of log6's angular part).
  The 6-vector |err| mixes metres and radians, and its linear part is not p_des - p; it
  is only the documented stopping rule.
- ``clik-documented`` declares that rule (:class:`StoppingRule`, the ``solve_rate_own_stop``
  row) in the residuals the harness measures: position <= :data:`DOCUMENTED_EPS` m and angle
  <= :data:`DOCUMENTED_EPS` rad, both of which |err| < eps implies (its angular part is the
  angle; its linear part equals p_des - p up to second order in the angle); ``clik`` stops at
  the scene's tolerances.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from simparity.core.model.engine import IKModel, StoppingRule
from simparity.core.model.ik_problem import IKTolerances, check_inputs
from simparity.core.model.ik_result import IKResult
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.ik_outcome import ik_outcome

SOLVERS = ("clik", "clik-documented")
"""The documented iteration stopped by the scene's tolerances; the documentation's own constants."""

DOCUMENTED_EPS = 1e-4  # stop when |err| < eps [mixed m and rad]
DOCUMENTED_IT_MAX = 1000
DT = 1e-1  # integration step of v [1]
DAMP = 1e-12  # damping added to J J^T [m^2 / rad^2 or 1]


class PinocchioIK(IKModel):
    """Pinocchio's documented CLIK iteration on the adapter's URDF.

    Configures, per solver (DT = :data:`DT`, damp = :data:`DAMP` for both):

    - ``"clik-documented"``: the documentation's stopping rule |err| < :data:`DOCUMENTED_EPS`
      and at most :data:`DOCUMENTED_IT_MAX` updates; success is still judged by the
      scene's tolerances.
    - ``"clik"``: stops when the position residual <= ``options.position_tolerance`` and
      the angle <= ``options.orientation_tolerance``; at most ``options.max_iterations``
      updates.

    Parameters
    ----------
    kinematics : PinocchioChain
        The chain's Pinocchio model (``references.pinocchio.adapter``).
    chain : Chain
    solver : str
        One of :data:`SOLVERS`.
    options : IKTolerances
    """

    def __init__(self, kinematics, chain: Chain, solver: str, options: IKTolerances) -> None:
        if solver not in SOLVERS:
            raise ValueError(f"unknown Pinocchio IK solver {solver!r}, expected one of {SOLVERS}")
        self._chain, self._options = chain, options
        self._documented = solver == "clik-documented"
        self._max_updates = DOCUMENTED_IT_MAX if self._documented else options.max_iterations
        self._kinematics = kinematics
        self._model, self._data, self._frame = kinematics.model, kinematics.data, kinematics.end_frame
        self._idx_v = kinematics.idx_v
        stop = (f"|log6 err| < {DOCUMENTED_EPS:g}, IT_MAX {DOCUMENTED_IT_MAX}" if self._documented else
                f"position <= {options.position_tolerance:g} m and angle <= {options.orientation_tolerance:g} rad, "
                f"IT_MAX {options.max_iterations}")
        if self._documented:
            self.stopping_rule = StoppingRule(
                DOCUMENTED_EPS, DOCUMENTED_EPS, f"|log6 err| < {DOCUMENTED_EPS:g} (the documentation's eps)")
        self.detail = (f"Pinocchio documented CLIK (log6 / Jlog6, LOCAL frame Jacobian), DT {DT:g}, damp {DAMP:g}; "
                       f"stops at {stop}; no joint limits; residuals from Pinocchio FK (double)")

    def solve(self, target_position_world: np.ndarray, target_rotation_world: np.ndarray | None,
              q_start: np.ndarray) -> IKResult:
        p, r, q0 = check_inputs(self._chain, target_position_world, target_rotation_world, q_start)
        p_world, r_world = self._kinematics.base.targets_to_world(p, r)
        batch = len(p)
        q = np.empty_like(q0)
        iterations = np.empty(batch, int)
        position_residual, orientation_residual = np.empty(batch), np.zeros(batch)
        for k in range(batch):
            if r is None:
                config, iterations[k], position_residual[k] = self._position_clik(
                    p_world[k], self._kinematics.configuration(q0[k]))
            else:
                config, iterations[k], position_residual[k], orientation_residual[k] = self._pose_clik(
                    pin.SE3(r_world[k], p_world[k]), self._kinematics.configuration(q0[k]))
            q[k] = self._kinematics.joint_values(config)
        return ik_outcome(self._chain, q, iterations, position_residual, orientation_residual, p, self._options)

    def _pose_clik(self, o_m_des: pin.SE3, q: np.ndarray) -> tuple[np.ndarray, int, np.floating, np.floating]:
        """The documented loop; returns q, updates applied, position [m] and angle [rad] residuals."""
        model, data = self._model, self._data
        i = 0
        while True:
            pin.framesForwardKinematics(model, data, q)
            i_m_d = data.oMf[self._frame].actInv(o_m_des)
            err = pin.log6(i_m_d).vector
            position, angle = np.linalg.norm(i_m_d.translation), np.linalg.norm(err[3:])
            if self._converged(np.linalg.norm(err), position, angle) or i >= self._max_updates:
                return q, i, position, angle
            jac = pin.computeFrameJacobian(model, data, q, self._frame, pin.LOCAL)[:, self._idx_v]
            jac = -pin.Jlog6(i_m_d.inverse()) @ jac
            v = -jac.T @ np.linalg.solve(jac @ jac.T + DAMP * np.eye(6), err)
            q = pin.integrate(model, q, self._on_chain(v) * DT)
            i += 1

    def _position_clik(self, p_des: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, int, np.floating]:
        """The documented loop on the translational rows; returns q, updates applied, position residual [m]."""
        model, data = self._model, self._data
        i = 0
        while True:
            pin.framesForwardKinematics(model, data, q)
            err = p_des - data.oMf[self._frame].translation
            position = np.linalg.norm(err)
            if self._converged(position, position, 0.0) or i >= self._max_updates:
                return q, i, position
            jac = pin.computeFrameJacobian(model, data, q, self._frame, pin.LOCAL_WORLD_ALIGNED)[:3, self._idx_v]
            v = jac.T @ np.linalg.solve(jac @ jac.T + DAMP * np.eye(3), err)
            q = pin.integrate(model, q, self._on_chain(v) * DT)
            i += 1

    def _on_chain(self, v_chain: np.ndarray) -> np.ndarray:
        """The model's velocity (nv,): the chain joints' (n,) in place, 0 for every other joint."""
        v = np.zeros(self._model.nv)
        v[self._idx_v] = v_chain
        return v

    def _converged(self, err_norm: float | np.floating, position: float | np.floating,
                   angle: float | np.floating) -> bool | np.bool_:
        if self._documented:
            return err_norm < DOCUMENTED_EPS
        return position <= self._options.position_tolerance and angle <= self._options.orientation_tolerance
