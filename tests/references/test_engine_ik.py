"""Every engine's IK solvers, judged alike: residuals honest, unreachable targets reported, bad names refused."""

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.ik.jacobian_solvers import IKOptions
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.kinematics import forward_kinematics
from simparity.core.rotations import geodesic_angle_matrix
from tests.helpers import CONTINUOUS7, IIWA, MIXED6, REVOLUTE7, build_ik, far_targets, reachable_targets

OPTIONS = IKOptions()  # 1e-6 m, 1e-6 rad, 200 iterations
# Double-precision FK on both sides: ~1e-15 for joint values of a few rad, growing with them.
# Pinocchio's CLIK (DT 0.1, damp 1e-12) drives joints to ~1e2 rad and prismatic joints to
# ~1e5 m, so its bound scales with 1 + max |q| (measured worst 1.7e-15 per unit).
DOUBLE_TOL = 1e-12
# PyBullet's residuals come from getLinkState, which is FLOAT32.
FLOAT32_POSITION_TOL = 1e-6  # [m]
FLOAT32_ORIENTATION_TOL = 2e-6  # [rad]

SOLVERS = [("core", "damped_least_squares"), ("mujoco", "dls"), ("pinocchio", "clik"),
           ("pybullet", "calculateInverseKinematics-tuned")]
ALL_SOLVERS = [(e, s) for e in ("core", "mujoco", "pinocchio", "pybullet") for s in make_engine(e).ik_solvers()]


def _tolerances(engine: str, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(position [m], orientation [rad]) bounds on |reported - recomputed| residuals, per target."""
    if engine == "pybullet":
        return np.full(len(q), FLOAT32_POSITION_TOL), np.full(len(q), FLOAT32_ORIENTATION_TOL)
    scale = 1 + np.abs(q).max(axis=1) if engine == "pinocchio" else np.ones(len(q))
    return DOUBLE_TOL * scale, DOUBLE_TOL * scale


@pytest.mark.parametrize("chain", [IIWA, pytest.param(MIXED6, marks=pytest.mark.slow),
                                   pytest.param(CONTINUOUS7, marks=pytest.mark.slow)],
                         ids=["iiwa", "mixed6", "continuous7"])
@pytest.mark.parametrize("pose", [True, False], ids=["pose", "position"])
@pytest.mark.parametrize("engine, solver", SOLVERS)
def test_residuals_agree_with_core_fk(engine, solver, chain, pose):
    """Each engine's reported residuals equal core FK's at the returned q, within the engine's FK precision."""
    p, r = reachable_targets(chain, 30, seed=2)
    result = build_ik(engine, chain, solver, OPTIONS).solve(p, r if pose else None, np.zeros(chain.n_joints))
    frames = forward_kinematics(chain, result.q)
    position_tol, orientation_tol = _tolerances(engine, result.q)
    assert np.all(np.abs(result.position_residual - np.linalg.norm(frames.position_world[:, -1] - p, axis=1))
                  <= position_tol)
    if pose:
        angle = geodesic_angle_matrix(frames.rotation_world[:, -1], r)
        assert np.all(np.abs(result.orientation_residual - angle) <= orientation_tol)
    else:
        assert np.all(result.orientation_residual == 0)


@pytest.mark.parametrize("chain", [IIWA, pytest.param(REVOLUTE7, marks=pytest.mark.slow)], ids=["iiwa", "revolute7"])
@pytest.mark.parametrize("engine, solver", ALL_SOLVERS)
def test_unreachable_targets_fail_with_reason(engine, solver, chain):
    """Targets far beyond the reach bound fail as "unreachable" with finite residuals, never an exception."""
    if engine == "core" and solver == "jacobian_inverse":
        pytest.skip("the Jacobian inverse needs a square Jacobian (n/a for these chains)")
    p, r = far_targets(chain, 5, seed=3)
    result = build_ik(engine, chain, solver, OPTIONS).solve(p, r, np.zeros(chain.n_joints))
    center, radius = reach_upper_bound(chain)
    assert not np.any(result.success)
    assert set(result.reason.tolist()) == {"unreachable"}
    assert np.all(np.isfinite(result.q)) and np.all(np.isfinite(result.position_residual))
    # No configuration comes closer than the reach bound allows.
    assert np.all(result.position_residual >= np.linalg.norm(p - center, axis=1) - radius - FLOAT32_POSITION_TOL)


@pytest.mark.parametrize("engine", ["mujoco", "pinocchio", "pybullet"])
def test_unknown_solver_is_refused(engine):
    """Support names the solvers on offer; building an unknown one is a ValueError naming it."""
    support = make_engine(engine).supports_ik(IIWA, "no-such-solver", position_only=False)
    assert not support.ok and "no-such-solver" in support.reason
    with pytest.raises(ValueError, match="no-such-solver"):
        build_ik(engine, IIWA, "no-such-solver", OPTIONS)
