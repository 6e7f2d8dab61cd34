"""Absolute constants inside the engines that a change of frame or units exposes, named in invariance rows.

An engine that compares a dimensioned quantity with a fixed number (a solver tolerance, a contact threshold, a
float32 representation) cannot give the same results in every frame and system of units. Those found by
``comparisons.invariance.metamorphic`` on the built-in engines are listed here, each with the part of a transform that
exposes it and where it lives, so an invariance row that breaks names the cause instead of leaving a user to
find it. Measured on the built-in scenes; docs/invariance.md has the numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.comparisons.invariance.transforms import IDENTITY_QUAT, Transform

TRANSLATION, ROTATION, LENGTH, MASS, TIME = "translation", "rotation", "length", "mass", "time"
"""Parts of a transform that can expose a constant."""

DYNAMICS, CHAINS = ("dynamics",), ("kinematics", "ik")
"""Kinds of scene."""


@dataclass(frozen=True)
class EngineConstant:
    """A constant of an engine that a part of a transform exposes.

    Attributes
    ----------
    engine : str
    kinds : tuple of str
        The kinds of scene (``dynamics``, ``kinematics``, ``ik``) whose results it moves.
    parts : tuple of str
        The parts of a transform (:data:`TRANSLATION`, ...) that change what the constant means.
    text : str
        The constant, its value and where it lives.
    """

    engine: str
    kinds: tuple[str, ...]
    parts: tuple[str, ...]
    text: str


ENGINE_CONSTANTS = (
    EngineConstant("mujoco", ("joint_motion",), (TIME, LENGTH, MASS), (
        "a chain's contact in MuJoCo keeps its default soft-contact constants, solref = (0.02, 1) (a time constant "
        "in the model's unit of time) and solimp's width 0.001 (in its unit of length; references/mujoco/contact.py): "
        "in other units the contact is softer or stiffer, its penetration and settling differ")),
    EngineConstant("mujoco", DYNAMICS, (TIME, LENGTH), (
        "MuJoCo's constraint solver stops when its improvement (a cost of mass x acceleration^2, x T^-4) or its "
        "gradient (x T^-2), divided by the mean of the inertia matrix's diagonal (kg and kg m^2 mixed) x nv, falls "
        "below mjOption.tolerance = 1e-8, and its line search at tolerance x ls_tolerance (0.01) "
        "(src/engine/engine_solver.c, mj_solCGNewton and CGsearch): with time in ms the solve stops 10^6-10^12 x "
        "earlier, after fewer iterations or none (block-slide implicit, dt 5 ms: 262 of 400 steps without an "
        "iteration instead of 140; the resting block is lifted, |v_z| 1.13 m/s instead of 0.066 m/s)")),
    EngineConstant("mujoco", DYNAMICS, (LENGTH,), (
        "the MuJoCo adapter's spheres standing for points are POINT_RADIUS = 1e-5 m (references/common/contact_params.py, "
        "with the pair margin -POINT_RADIUS): they do not scale with the unit of length")),
    EngineConstant("mujoco", DYNAMICS, (ROTATION,), (
        "MuJoCo's implicit and implicitfast integrators amplify a rounding-level asymmetry of a box resting or "
        "landing on several corners (box-flat-drop turned: 0.04 rad; Euler: 4e-12 rad), and a contact is active "
        "while its distance is below the pair's margin (0), so rounding decides whether a body placed exactly on "
        "a plane touches it at t = 0")),
    EngineConstant("pybullet", DYNAMICS, (ROTATION,), (
        "PyBullet's friction is not isotropic in the world: a block turned about the plane's normal slides 0.6746 m "
        "at 0 and 90 degrees, 0.7494 m at 45 degrees (friction directions tied to world axes)")),
    EngineConstant("pybullet", CHAINS, (TRANSLATION,), (
        "PyBullet's link states (getLinkState) are float32: 2 km from the origin a frame is off by ~1e-4 m, beyond "
        "the adapter's judge resolution LINK_STATE_RESOLUTION = 1e-6 m (references/pybullet/adapter.py), which "
        "holds for coordinates of a few metres")),
    EngineConstant("pybullet", DYNAMICS, (LENGTH, TIME), (
        "the PyBullet adapter's solverResidualThreshold SOLVER_RESIDUAL = 1e-12 (m/s)^2 "
        "(references/pybullet/adapter.py) and contactSlop / point spheres POINT_RADIUS = 1e-5 m are absolute "
        "(scaled by (L/T)^2 and L, the runs agree to 3e-8)")),
    EngineConstant("pybullet", ("ik",), (LENGTH,), (
        "calculateInverseKinematics' default residualThreshold 1e-4 and its joint damping (TUNED_JOINT_DAMPING "
        "1e-3, references/pybullet/ik.py) are absolute")),
    EngineConstant("mujoco", ("ik",), (LENGTH,), (
        "dm_control's damped least squares adds lambda = 3e-2 while |e_pos| [m] + |e_rot| [rad] > 0.1 "
        "(references/mujoco/ik.py REGULARIZATION_*): metres added to radians, compared with fixed numbers")),
    EngineConstant("pinocchio", ("ik",), (LENGTH,), (
        "the CLIK loops' damping DAMP = 1e-12 and the documented stop |e| < DOCUMENTED_EPS = 1e-4 on an error "
        "that adds metres to radians (references/pinocchio/ik.py)")),
    EngineConstant("pinocchio", ("joint_motion",), (TIME,), (
        "the Pinocchio adapter's DOP853 solves (references/pinocchio/joint_motion.py TOLERANCES: rtol 1e-13 and 1e-11, "
        "atol per the scene's duration on qdot) pick their own steps: in ms the reference's error stays within its "
        "spread (invariance ratio <= 0.19 measured), the coarse solve's own error at the 1e-11 level moves (ratio up "
        "to 8.2 on oblique-arm-swing, quick)")),
    EngineConstant("core", ("ik",), (LENGTH,), (
        "core's IK: damping_max 1e-3 and singular_threshold 1e-2 in m/rad (core/ik/jacobian_solvers.py IKOptions), "
        "and a pose error that adds metres to radians")),
)
"""Every known constant of a built-in engine."""


def transform_parts(transform: Transform) -> set[str]:
    """The parts of ``transform`` that change anything."""
    parts = {TRANSLATION} if np.any(transform.translation_world) else set()
    if not np.array_equal(transform.quat_wxyz, IDENTITY_QUAT):
        parts.add(ROTATION)
    for part, scale in ((LENGTH, transform.length_scale), (MASS, transform.mass_scale), (TIME, transform.time_scale)):
        if scale != 1.0:
            parts.add(part)
    return parts


def constants_exposed(engine: str, kind: str, transform: Transform) -> list[str]:
    """The texts of ``engine``'s known constants that ``transform`` exposes in a scene of ``kind``."""
    parts = transform_parts(transform)
    return [c.text for c in ENGINE_CONSTANTS if c.engine == engine and kind in c.kinds and parts & set(c.parts)]
