"""IK targets of a scene: seeded random reachable ones and the hard cases.

Random targets follow the TRAC-IK protocol: the end-effector poses (by the scene's reference
engine's forward kinematics) of seeded random configurations within the joint limits, every
one solved from the scene's single start pose.

Hard targets (one each; poses for pose scenes, positions for position scenes):

- ``stretched``: the chain fully stretched (the zero configuration of the library's chains)
  with the first joint turned by 0.5 rad: on the workspace boundary, at a singularity;
- ``beyond_reach``: 1.5 times the reach bound from the first joint: unreachable;
- ``at_base``: the first joint's own position: unreachable or degenerate;
- ``near_limits``: every joint 1e-3 of its range inside a (seeded) limit: reachable;
- ``beyond_limits``: the pose of the start configuration with every limited joint moved a quarter
  of its range past its upper limit: blocked by the limits (unless another branch reaches it, or
  a revolute joint's range spans more than a turn): a solver must not pass a limit to get there;
- ``orientation_in_place``: the start pose turned 90 deg about the end effector's z axis,
  same position (pose scenes only);
- ``wrist_flip``: the start configuration with its last three joints moved half a turn
  (within the limits): a large wrist flip (pose scenes only).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.engine import KinematicsModel
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.rotations import so3_exp
from simparity.core.model.scenes.ik import IKScene

ORIENTATION_ONLY = ("orientation_in_place", "wrist_flip")
"""Hard targets that only make sense for pose targets."""
_NEAR_LIMIT_FRACTION = 1e-3
_BEYOND_LIMIT_FRACTION = 0.25


@dataclass(frozen=True)
class Targets:
    """A batch of targets.

    Attributes
    ----------
    name : str
        ``"random"`` or a hard target's name.
    position_world : (B, 3) ndarray
    rotation_world : (B, 3, 3) ndarray or None
        None for position targets.
    note : str
        What the targets are, for the report.
    """

    name: str
    position_world: np.ndarray
    rotation_world: np.ndarray | None
    note: str


def _poses(scene: IKScene, q: np.ndarray, fk: KinematicsModel) -> tuple[np.ndarray, np.ndarray | None]:
    frames = fk.forward_kinematics(q)
    rotation = frames.rotation_world[:, -1] if scene.target_kind == "pose" else None
    return frames.position_world[:, -1], rotation


def random_targets(scene: IKScene, fk: KinematicsModel) -> Targets:
    """End-effector targets (by ``fk``) of the scene's seeded random configurations within the limits."""
    position, rotation = _poses(scene, scene.configurations(), fk)
    return Targets("random", position, rotation,
                   f"{scene.n_targets} seeded random reachable {scene.target_kind} targets (seed {scene.seed})")


def _clip(scene: IKScene, q: np.ndarray) -> np.ndarray:
    return np.clip(q, scene.chain.lower, scene.chain.upper)


def hard_target(scene: IKScene, name: str, fk: KinematicsModel) -> Targets:
    """The hard target ``name`` of the scene (see the module docstring), poses by ``fk``. Directions and
    orientations are the first joint's frame's (the chain's base as the scene places it), never the world's, so
    that the same chain turned in the world is asked the same targets."""
    chain, q0 = scene.chain, scene.q_start
    center, radius = reach_upper_bound(chain)
    if name == "stretched":
        q = np.zeros(chain.n_joints)
        q[0] = 0.5
        position, rotation = _poses(scene, _clip(scene, q)[None], fk)
        note = "the zero (stretched) configuration with joint 1 at 0.5 rad: boundary, singular"
    elif name in ("beyond_reach", "at_base"):
        base = np.asarray(chain.joints[0].origin_rotation, dtype=float)  # the chain's base as placed in the world
        direction = base @ (np.ones(3) / np.sqrt(3))
        position = (center + 1.5 * radius * direction if name == "beyond_reach" else center)[None]
        rotation = None if scene.target_kind == "position" else base[None]
        note = ("1.5 x the reach bound from joint 1: unreachable" if name == "beyond_reach"
                else "joint 1's own position: unreachable or degenerate")
    elif name == "near_limits":
        rng = np.random.default_rng(scene.seed)
        span = np.where(np.isfinite(chain.upper - chain.lower), chain.upper - chain.lower, 2 * np.pi)
        at_upper = rng.random(chain.n_joints) < 0.5
        q = np.where(at_upper, chain.upper - _NEAR_LIMIT_FRACTION * span, chain.lower + _NEAR_LIMIT_FRACTION * span)
        q = np.where(np.isfinite(q), q, np.pi - _NEAR_LIMIT_FRACTION * span)
        position, rotation = _poses(scene, q[None], fk)
        note = f"every joint {_NEAR_LIMIT_FRACTION:g} of its range inside a limit: reachable"
    elif name == "beyond_limits":
        q = np.where(np.isfinite(chain.upper - chain.lower),
                     chain.upper + _BEYOND_LIMIT_FRACTION * (chain.upper - chain.lower), q0)
        position, rotation = _poses(scene, q[None], fk)
        note = (f"the start configuration with every limited joint {_BEYOND_LIMIT_FRACTION:g} of its range past its "
                "upper limit: blocked by the limits unless another branch reaches it")
    elif name == "orientation_in_place":
        position, rotation = _poses(scene, q0[None], fk)
        rotation = rotation @ so3_exp(np.array([0.0, 0.0, np.pi / 2]))
        note = "the start pose turned 90 deg about the tool z axis, same position"
    elif name == "wrist_flip":
        q = q0.copy()
        q[-3:] += np.pi
        position, rotation = _poses(scene, _clip(scene, q)[None], fk)
        note = "the start configuration with its last three joints turned half a turn (clipped to limits)"
    else:
        raise ValueError(f"unknown hard target {name!r}")
    return Targets(name, position, rotation, note)
