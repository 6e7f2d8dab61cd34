"""The differential-IK libraries users pick, run as their documentation shows, behind :class:`core.engine.IKModel`.

``mink`` (on MuJoCo) and ``pin-pink`` (on Pinocchio) solve one quadratic program per step for a
joint velocity that drives task errors to zero under limits; their documented use is a loop
(mink's quickstart and examples, pink's README):

    task = FrameTask(end effector, position_cost 1, orientation_cost 1, lm_damping 1)
    task.set_target(target pose)
    repeat: v = solve_ik(configuration, [task], dt, "daqp", damping 1e-3, limits=[ConfigurationLimit])
            configuration.integrate_inplace(v, dt)
    until the scene's tolerances hold or ``max_iterations`` updates

With the task gain 1, a step moves by the whole linearised error, so ``dt`` only scales the
velocity (:data:`DT`). Both keep the joints inside their limits (the ConfigurationLimit
constraint). Targets are given in the chain's base frame and moved into the library's world
(:mod:`references.common.base_frame`); residuals come from the library's own forward kinematics at the
returned configuration: |p_target - p| [m] and the angle of R^T R_target [rad]. pink stops with
``NotWithinConfigurationLimits`` (its default safety break) when an iterate leaves the limits
by rounding; that target ends there. Judged by
:func:`references.common.ik_outcome.ik_outcome` like every library adapter. Position-only targets use
orientation_cost 0.

Optional: ``pip install 'simparity[bench]'`` installs both (and the ``daqp`` QP solver);
:func:`available` says what is missing.
"""

from __future__ import annotations

import importlib.util

import numpy as np

from simparity.core.model.engine import IKModel
from simparity.core.model.ik_problem import IKTolerances, check_inputs
from simparity.core.model.ik_result import IKResult
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.conventions import rotation_angle
from simparity.references.common.ik_outcome import ik_outcome

DT = 1e-2
"""[s] Step of the velocity integration (with gain 1 the update is the same for any dt)."""
QP_SOLVER = "daqp"
"""The QP solver of mink's quickstart."""
DAMPING = 1e-3
"""solve_ik's Levenberg-Marquardt damping of the velocity, as mink's examples pass it."""
LM_DAMPING = 1.0
"""The frame task's error-dependent damping, as mink's arm examples set it."""

LIBRARIES = {"mink": ("mink", "daqp"), "pink": ("pink", "daqp")}
"""Solver name -> modules it needs."""


def available(name: str) -> str:
    """'' when ``name``'s library is installed, else what to install."""
    missing = [m for m in LIBRARIES[name] if importlib.util.find_spec(m) is None]
    return f"{', '.join(missing)} not installed (pip install 'simparity[bench]')" if missing else ""


def _converged(options: IKTolerances, position: float, angle: float) -> bool:
    return position <= options.position_tolerance and angle <= options.orientation_tolerance


class MinkIK(IKModel):
    """mink's documented loop on the chain's MuJoCo model (:class:`references.mujoco.adapter.MujocoChain`)."""

    def __init__(self, kinematics, chain: Chain, options: IKTolerances) -> None:
        import mink

        self._mink, self._kinematics, self._chain, self._options = mink, kinematics, chain, options
        self._configuration = mink.Configuration(kinematics.model)
        self._site = kinematics.model.site(kinematics.site).name
        self._limits = [mink.ConfigurationLimit(kinematics.model)]
        self.detail = (f"mink {_version('mink')}: FrameTask on site {self._site} (costs 1, lm_damping {LM_DAMPING:g}), "
                       f"solve_ik with {QP_SOLVER}, damping {DAMPING:g}, ConfigurationLimit, dt {DT:g}; at most "
                       f"{options.max_iterations} updates; stops at the scene's tolerances")

    def solve(self, target_position_world, target_rotation_world, q_start) -> IKResult:
        mink = self._mink
        p, r, q0 = check_inputs(self._chain, target_position_world, target_rotation_world, q_start)
        p_world, r_world = self._kinematics.base.targets_to_world(p, r)
        batch = len(p)
        q, iterations = np.empty_like(q0), np.empty(batch, int)
        position, angle = np.empty(batch), np.zeros(batch)
        task = mink.FrameTask(self._site, "site", position_cost=1.0, orientation_cost=0.0 if r is None else 1.0,
                              lm_damping=LM_DAMPING)
        for k in range(batch):
            rotation = np.eye(3) if r_world is None else r_world[k]
            task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rotation), p_world[k]))
            full = self._configuration.q.copy()
            full[self._kinematics.qpos_adr] = q0[k]
            self._configuration.update(full)
            steps = 0
            while True:
                pose = self._configuration.get_transform_frame_to_world(self._site, "site")
                position[k] = np.linalg.norm(pose.translation() - p_world[k])
                angle[k] = 0.0 if r is None else float(rotation_angle(pose.rotation().as_matrix(), rotation))
                if _converged(self._options, position[k], angle[k]) or steps >= self._options.max_iterations:
                    break
                v = mink.solve_ik(self._configuration, [task], DT, QP_SOLVER, damping=DAMPING, limits=self._limits)
                self._configuration.integrate_inplace(v, DT)
                steps += 1
            q[k], iterations[k] = self._configuration.q[self._kinematics.qpos_adr], steps
        return ik_outcome(self._chain, q, iterations, position, angle, p, self._options)

class PinkIK(IKModel):
    """pink's documented loop on the chain's Pinocchio model (:class:`references.pinocchio.adapter.PinocchioChain`)."""

    def __init__(self, kinematics, chain: Chain, options: IKTolerances) -> None:
        import pink
        import pinocchio as pin

        self._pink, self._pin, self._kinematics, self._chain, self._options = pink, pin, kinematics, chain, options
        self._frame = kinematics.model.frames[kinematics.end_frame].name
        self._limits = [pink.limits.ConfigurationLimit(kinematics.model)]
        self.detail = (f"pin-pink {_version('pin-pink')}: FrameTask on {self._frame} (costs 1, lm_damping "
                       f"{LM_DAMPING:g}), solve_ik with {QP_SOLVER}, damping {DAMPING:g}, ConfigurationLimit, dt "
                       f"{DT:g}; at most {options.max_iterations} updates; stops at the scene's tolerances")

    def solve(self, target_position_world, target_rotation_world, q_start) -> IKResult:
        pink, pin, kin = self._pink, self._pin, self._kinematics
        p, r, q0 = check_inputs(self._chain, target_position_world, target_rotation_world, q_start)
        p_world, r_world = kin.base.targets_to_world(p, r)
        batch = len(p)
        q, iterations = np.empty_like(q0), np.empty(batch, int)
        position, angle = np.empty(batch), np.zeros(batch)
        task = pink.tasks.FrameTask(self._frame, position_cost=1.0, orientation_cost=0.0 if r is None else 1.0,
                                    lm_damping=LM_DAMPING)
        for k in range(batch):
            rotation = np.eye(3) if r_world is None else r_world[k]
            task.set_target(pin.SE3(rotation, p_world[k]))
            configuration = pink.Configuration(kin.model, kin.data, kin.configuration(q0[k]))
            steps = 0
            while True:
                pose = configuration.get_transform_frame_to_world(self._frame)
                position[k] = np.linalg.norm(pose.translation - p_world[k])
                angle[k] = 0.0 if r is None else float(rotation_angle(pose.rotation, rotation))
                if _converged(self._options, position[k], angle[k]) or steps >= self._options.max_iterations:
                    break
                try:
                    v = pink.solve_ik(configuration, [task], DT, QP_SOLVER, damping=DAMPING, limits=self._limits)
                except pink.exceptions.NotWithinConfigurationLimits:
                    break  # pink's documented safety break: the iterate left the limits; the target fails here
                configuration.integrate_inplace(v, DT)
                steps += 1
            q[k], iterations[k] = kin.joint_values(configuration.q), steps
        return ik_outcome(self._chain, q, iterations, position, angle, p, self._options)


def _version(distribution: str) -> str:
    from importlib import metadata
    return metadata.version(distribution)
