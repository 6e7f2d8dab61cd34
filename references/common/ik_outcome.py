"""The IK adapters' shared verdict: success, reason and limit violation from residuals.

Every library IK adapter (:mod:`references.pybullet.ik`, :mod:`references.pinocchio.ik`,
:mod:`references.mujoco.ik`) judges its solutions the same way, whatever the library's
own stopping rule was:

- success: position residual <= ``options.position_tolerance`` [m] AND orientation
  residual <= ``options.orientation_tolerance`` [rad] (0 for position-only targets) AND
  every joint within its limits (up to :data:`core.ik.result.LIMIT_TOLERANCE`): a solution
  outside the limits is no solution for the robot (the TRAC-IK protocol counts the same way);
- reason of a failure: ``"outside_limits"`` when only the limits fail, else ``"unreachable"`` when the target is farther from the first joint
  than the chain could possibly reach (:func:`reach_bound`, plus the position tolerance), else
  ``"iteration_cap"``: the libraries report no cause (a stop at their own looser
  threshold, a stall and the cap all look alike), and :data:`core.ik.result.REASONS` has
  no "stopped early";
- limit violation: measured on the returned joint values, which are never clamped.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.ik_result import LIMIT_TOLERANCE, IKReason, IKResult
from simparity.core.model.scenes.chain import Chain


def reach_bound(chain: Chain) -> tuple[np.ndarray, float]:
    """(first joint's origin (3,) [m], the farthest the end effector can be from it [m]).

    Every later joint origin and the end effector sit at fixed offsets along the chain, and
    a prismatic joint adds at most its largest |limit|: by the triangle inequality the end
    effector is never farther than the sum of their lengths (inf with an unlimited
    prismatic joint).
    """
    lengths = [float(np.linalg.norm(joint.origin_xyz)) for joint in chain.joints[1:]]
    lengths.append(float(np.linalg.norm(chain.end_effector_xyz)))
    lengths += [max(-joint.lower, joint.upper) for joint in chain.joints if joint.type == "prismatic"]
    return np.asarray(chain.joints[0].origin_xyz, dtype=float), float(np.sum(lengths))


def ik_outcome(chain: Chain, q: np.ndarray, iterations: np.ndarray, position_residual: np.ndarray,
               orientation_residual: np.ndarray, target_position_world: np.ndarray,
               options: IKTolerances) -> IKResult:
    """Judge a batch of library IK solutions.

    Parameters
    ----------
    chain : Chain
    q : (B, n) ndarray
        Joint values the library returned [rad or m].
    iterations : (B,) int ndarray
        Joint updates applied, -1 where the library does not report them.
    position_residual, orientation_residual : (B,) ndarray
        Measured with the library's forward kinematics at ``q`` [m], [rad].
    target_position_world : (B, 3) ndarray
        [m].
    options : IKTolerances
        Only the two tolerances are read.

    Returns
    -------
    IKResult
    """
    reached = ((position_residual <= options.position_tolerance)
               & (orientation_residual <= options.orientation_tolerance))
    violation = np.max(np.maximum(np.maximum(chain.lower - q, q - chain.upper), 0.0), axis=1, initial=0.0)
    inside = violation <= LIMIT_TOLERANCE
    success = reached & inside
    center, radius = reach_bound(chain)
    beyond = np.linalg.norm(target_position_world - center, axis=1) > radius + options.position_tolerance
    reason = np.where(success, IKReason.SOLVED,
                      np.where(reached, IKReason.OUTSIDE_LIMITS,
                               np.where(beyond, IKReason.UNREACHABLE, IKReason.ITERATION_CAP)))
    return IKResult(q=q, success=success, iterations=iterations, position_residual=position_residual,
                    orientation_residual=orientation_residual, limit_violation=violation, reason=reason)
