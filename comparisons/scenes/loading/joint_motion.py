"""A joint-motion scene (``kind = "joint_motion"``): ``[chain]`` with mass properties, ``[world]``, ``[initial]``,
``[drive]`` and ``[simulation]``."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simparity.comparisons.engines.registry import EngineSet
from simparity.comparisons.scenes.loading.chain_contact import read_chain_contact
from simparity.comparisons.scenes.loading.chain import (
    joint_powers,
    joint_values,
    read_dynamics_chain,
    within_limits,
)
from simparity.comparisons.scenes.loading.reader import MAX_SEED, TableReader
from simparity.comparisons.scenes.loading.time_functions import FUNCTION_KEYS, read_time_function, within_range_over
from simparity.comparisons.scenes.loading.time_steps import STEP_COUNT_RTOL, time_step_ladder
from simparity.core.model.errors import echo
from simparity.core.model.scenes.chain import Chain, sample_configurations
from simparity.core.model.scenes.joint_motion import UNIT_QUATERNION_TOLERANCE, JointMotionScene

_INITIAL = ("q", "qdot", "seed")
_BASE_INITIAL = ("base_position", "base_quat_wxyz", "base_velocity_world", "base_angular_velocity_world")
"""A floating base's initial state (``[chain] floating_base = true``): its origin's position [m] and orientation
(default: the world's origin, unturned), its origin's velocity [m/s] and its angular velocity [rad/s] in world axes
(default: at rest)."""
_MOTION_SIMULATION = ("duration", "dt", "integrators", "segments", "perturbation")
MAX_PERTURBATION = 1e-3
"""[rad] The largest start perturbation for predictability: at the parting threshold itself the runs would part at once."""
MAX_SEGMENTS = 1000
"""Segments of a self-consistency scene at most: each is a copy stepped twice (at dt and dt / 16)."""


def _initial_q(r: TableReader, chain: Chain) -> np.ndarray:
    """(n,) the initial joint values: a list, "zeros" or "random" (uniform within the limits, ``seed``)."""
    value = r.table.get("q", "zeros")
    if value == "zeros":
        q = np.zeros(chain.n_joints)
    elif value == "random":
        q = sample_configurations(chain, 1, r.integer("seed", 0, maximum=MAX_SEED))[0]
    elif isinstance(value, list):
        q = joint_values(r, "q", chain, joint_powers(chain, 0, 1), None)
    else:
        raise r.fail("q", f"{echo(value)} is not allowed", f'"zeros", "random" or a list of {chain.n_joints} numbers')
    return within_limits(r, "q", chain, q)


def _with_base(initial: TableReader, q0: np.ndarray, qdot0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((7 + n,), (6 + n,)): the joints' initial state after the floating base's (:data:`_BASE_INITIAL`)."""
    quat = initial.vector("base_quat_wxyz", 4, [1.0, 0.0, 0.0, 0.0])
    if abs(float(np.linalg.norm(quat)) - 1.0) > UNIT_QUATERNION_TOLERANCE:
        raise initial.fail("base_quat_wxyz", f"length {float(np.linalg.norm(quat)):.17g}",
                           f"a unit quaternion (w, x, y, z), length 1 within {UNIT_QUATERNION_TOLERANCE:g}")
    base_q = np.concatenate([initial.vector("base_position", 3, [0.0] * 3, length=1), quat])
    base_v = np.concatenate([initial.vector("base_velocity_world", 3, [0.0] * 3, length=1),
                             initial.vector("base_angular_velocity_world", 3, [0.0] * 3)])
    return np.concatenate([base_q, q0]), np.concatenate([base_v, qdot0])


def _with_damping(drive: TableReader, chain: Chain) -> Chain:
    """``chain`` with the joint damping ``[drive] damping`` gives: one number for every joint or one per joint
    [N m s/rad = kg m^2/s, or N s/m = kg/s], >= 0."""
    value = drive.table["damping"]
    if not isinstance(value, list):
        drive.table = dict(drive.table, damping=[value] * chain.n_joints)
    damping = joint_values(drive, "damping", chain, joint_powers(chain, 2, 0))
    if np.any(damping < 0):
        raise drive.fail("damping", f"a negative damping {float(damping.min()):g}", "numbers >= 0 (N m s/rad or N s/m)")
    return replace(chain, joints=tuple(replace(j, damping=float(d)) for j, d in zip(chain.joints, damping)))


def read_joint_motion(top: TableReader, head: dict, engines: EngineSet) -> JointMotionScene:
    """The joint-motion scene of the file's tables ``top``; ``head``: its ``[scene]`` keys; ``engines`` offer the
    integrators it may name."""
    chain = read_dynamics_chain(top, head, floating_allowed=True)
    world = top.optional_subtable("world", ("gravity_world",))
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    keys = _INITIAL + (_BASE_INITIAL if chain.floating_base else ())
    initial = top.optional_subtable("initial", keys) or TableReader(top.source, {}, "initial", keys, top.scale,
                                                                    top.limits)
    q0 = _initial_q(initial, chain)
    qdot0 = joint_values(initial, "qdot", chain, joint_powers(chain, 0, 1))
    if chain.floating_base:
        q0, qdot0 = _with_base(initial, q0, qdot0)
    drive = top.optional_subtable("drive", ("torque", "damping", "timed_torque"))
    torque = (joint_values(drive, "torque", chain, joint_powers(chain, 2, 1)) if drive and drive.has("torque")
              else np.zeros(chain.n_joints))  # N m = kg m^2 / s^2 (mass and time fixed) or N = kg m / s^2
    sim = top.subtable("simulation", _MOTION_SIMULATION)
    duration = sim.number("duration", positive=True)
    timed_table = drive.optional_subtable("timed_torque", FUNCTION_KEYS) if drive else None
    timed = (within_range_over(drive, "timed_torque",
                               read_time_function(timed_table, np.asarray(joint_powers(chain, 2, 1), dtype=float)),
                               duration) if drive and timed_table else None)
    if drive and drive.has("damping"):  # replaces the chain's own (a URDF's <dynamics damping>)
        chain = _with_damping(drive, chain)
    dts = time_step_ladder(sim, duration, 1)
    segments = sim.integer("segments", 0, maximum=MAX_SEGMENTS, why="") if sim.has("segments") else 0
    for i, dt in enumerate(dts if segments else ()):  # each segment a whole number of every step
        steps = duration / segments / dt
        if abs(steps - round(steps)) > STEP_COUNT_RTOL * max(steps, 1.0) or round(steps) < 1:
            raise sim.fail("segments", f"{segments} segments of {duration / segments:g} s are not a whole number of "
                           f"steps of dt[{i}] = {dt:g} s", "a count of segments each a whole number of every dt")
    perturbation = sim.number("perturbation", 0.0) if sim.has("perturbation") else 0.0  # rad (a prismatic joint: m)
    if not 0 <= perturbation <= MAX_PERTURBATION:
        raise sim.fail("perturbation", f"{perturbation:g} is out of range",
                       f"0 (none) to {MAX_PERTURBATION:g} rad: a small change of the start, for predictability")
    integrators = (sim.strings("integrators", engines.joint_motion_integrators, "no engine steps a chain with {}")
                   if sim.has("integrators") else ())
    contact = read_chain_contact(top, chain, q0, duration)
    return JointMotionScene(chain=chain, gravity_world=gravity, q0=q0, qdot0=qdot0, torque=torque, timed_torque=timed,
                            duration=duration, dts=dts, integrators=integrators, segments=segments,
                            perturbation=perturbation, contact=contact, **head)
