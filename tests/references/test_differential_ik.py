"""mink and pin-pink behind the IK interface (references/differential_ik.py), as `simparity bench` runs them."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.execute.ik_targets import random_targets
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.ik_result import LIMIT_TOLERANCE
from simparity.references.differential_ik import QP_SOLVER, MinkIK, PinkIK, available
from simparity.references.mujoco.adapter import MujocoChain
from simparity.references.pinocchio.adapter import PinocchioChain
from tests.helpers import builtin

pytestmark = pytest.mark.skipif(bool(available("mink") or available("pink")),
                                reason="mink or pin-pink not installed (pip install '.[test]')")

N_TARGETS = 20
MIN_SOLVED = 15
"""Of the iiwa's first 20 TRAC-IK targets from mid-range: both libraries solved 19 when this was written (97.5 %
of 10,000 in BENCHMARKS.md); a convention error (a wrong frame or quaternion order) solves none."""
ENGINE_FK_AGREEMENT = 1e-9
"""[m], [rad] A solution judged by the library's FK, checked again by the other engine's FK: double precision
FK of a 1 m arm agrees to ~1e-15, so this only tolerates the residual bookkeeping."""


@pytest.fixture(scope="module")
def iiwa():
    scene = builtin("bench-iiwa-ik")
    targets = random_targets(scene, PinocchioChain(scene.chain))
    options = IKTolerances(scene.position_tolerance, scene.orientation_tolerance, scene.max_iterations)
    return scene, targets.position_world[:N_TARGETS], targets.rotation_world[:N_TARGETS], options


@pytest.mark.parametrize("name", ["mink", "pink"])
def test_the_libraries_reach_the_targets_inside_the_limits_as_another_engine_checks(iiwa, name):
    scene, p, r, options = iiwa
    model = (MinkIK(MujocoChain(scene.chain), scene.chain, options) if name == "mink"
             else PinkIK(PinocchioChain(scene.chain), scene.chain, options))
    result = model.solve(p, r, scene.q_start)
    assert result.success.sum() >= MIN_SOLVED
    # The ConfigurationLimit constraint both are given keeps every joint inside its limits.
    assert np.all(result.limit_violation <= LIMIT_TOLERANCE)
    # A success is a success for the other engine too (the adapters convert frames and quaternions right).
    other = PinocchioChain(scene.chain) if name == "mink" else MujocoChain(scene.chain)
    frames = other.forward_kinematics(result.q[result.success])
    reached = np.linalg.norm(frames.position_world[:, -1] - p[result.success], axis=1)
    assert np.all(reached <= options.position_tolerance + ENGINE_FK_AGREEMENT)
    assert f"solve_ik with {QP_SOLVER}" in model.detail and "ConfigurationLimit" in model.detail
