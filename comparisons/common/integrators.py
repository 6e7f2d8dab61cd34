"""The integrator names every folder of comparisons agrees on: the n/a case's, and the one a joint-motion
scene's reference runs (the loader checks a scene file's against it, the planner labels the reference by it)."""

from __future__ import annotations

from simparity.core.model.engine import TRUTH_SCHEMES, Engine
from simparity.core.model.scenes.joint_motion import JointMotionScene

NO_INTEGRATOR = "-"
"""The integrator of the one n/a case of an engine that offers none of the integrators a scene runs
(or no IK solver)."""


def motion_reference_integrator(scene: JointMotionScene, reference: Engine) -> str:
    """The integrator a joint-motion scene's reference runs: its first of a truth's kind (:data:`TRUTH_SCHEMES`),
    else its first; NO_INTEGRATOR when it offers none."""
    try:
        offered = tuple(reference.joint_motion_integrators())
        truths = [i for i in offered if reference.scheme(i, scene) in TRUTH_SCHEMES]
    except Exception:  # noqa: BLE001 - a user's engine as a reference: its rows say what fails
        return NO_INTEGRATOR
    return (truths or list(offered) or [NO_INTEGRATOR])[0]
