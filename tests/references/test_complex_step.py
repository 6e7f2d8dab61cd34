"""The complex-step truth of the dynamics' derivatives (issue #44, references/derivatives/complex_step.py): its RNEA is
the dynamics (Pinocchio's to rounding), its derivatives match central finite differences to their truncation and the
planar 2-link arm's closed-form derivatives to rounding, it is complex-safe (run with ComplexWarning as an error), and
∂τ/∂q̈ = M exactly. On a floating base (Solo-12's leg, Go1's with damping): its RNEA is Pinocchio's free flyer's in the
project's convention, its exponential is SciPy's rotation vector and complex-safe, and its derivatives are central
differences in the project's chart (the base moved and turned in world axes), with ∂τ/∂p = 0 (uniform gravity)."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.scenes import library
from simparity.references.derivatives.complex_step import (
    mass_and_bias,
    derivatives,
    exp_so3,
    forward_dynamics,
    rnea,
    tree_from_chain,
)
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics
from tests.helpers import SPONG_GRAVITY, floating_states, solo12_leg, spong_chain, spong_partials

ROUNDING = 1e-13
"""Two double evaluations of the same sums of O(n^2) products, relative to the largest entry (measured <= 3e-14)."""
CLOSED_FORM = 1e-14
"""The elbow arm's partials by hand against the truth: both sums of a handful of O(1) products (measured <= 2e-15)."""
FD_STEP = 1e-5
FD_AGREEMENT = 1e-7
"""Central differences at 1e-5 rad: truncation h^2 / 6 |d3 tau| ~ 2e-11 relative, rounding eps |tau| / h ~ 2e-11;
1e-7 is far above both and far below any wrong term."""

SCENES = ["crafted-arm-dynamics", "oblique-arm-dynamics", "armature-arm-dynamics", "panda-dynamics"]


@pytest.fixture(scope="module", params=SCENES)
def case(request):
    scene = library.load([request.param])[0]
    q, qd, qdd, tau = (x[:6] for x in scene.states())
    return scene, tree_from_chain(scene.chain, scene.gravity_world), (q, qd, qdd, tau)


def test_its_rnea_is_the_dynamics(case):
    scene, tree, (q, qd, qdd, _) = case
    pinocchio = PinocchioJointDynamics(scene.chain, scene.gravity_world).inverse_dynamics(q, qd, qdd)
    assert np.max(np.abs(rnea(tree, q, qd, qdd) - pinocchio)) <= ROUNDING * np.max(np.abs(pinocchio))


def test_its_derivatives_match_central_differences(case):
    scene, tree, (q, qd, _, tau) = case
    truth = derivatives(tree, q, qd, tau)
    mass, bias = mass_and_bias(tree, q, qd)
    qdd = np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]
    for name, moved in (("dtau_dq", 0), ("dtau_dqdot", 1)):
        columns = []
        for e in np.eye(scene.chain.n_joints):
            plus, minus = [q, qd], [q, qd]
            plus[moved], minus[moved] = plus[moved] + FD_STEP * e, minus[moved] - FD_STEP * e
            columns.append((rnea(tree, *plus, qdd) - rnea(tree, *minus, qdd)).real / (2 * FD_STEP))
        fd = np.stack(columns, axis=-1)
        reference = getattr(truth, name)
        assert np.max(np.abs(fd - reference)) <= FD_AGREEMENT * np.max(np.abs(reference)), name
    exact_mass = np.linalg.inv(truth.dqddot_dtau)
    assert np.max(np.abs(exact_mass - mass)) <= ROUNDING * np.max(np.abs(mass))  # dtau/dqddot = M


def test_the_planar_arm_s_closed_form_derivatives_to_rounding():
    """The elbow manipulator's partials differentiated by hand (tests.helpers.spong_partials)."""
    tree = tree_from_chain(spong_chain(), np.array([0.0, -SPONG_GRAVITY, 0.0]))
    rng = np.random.default_rng(44)
    q, qd, tau = (rng.uniform(-2, 2, (5, 2)) for _ in range(3))
    truth = derivatives(tree, q, qd, tau)
    mass, bias = mass_and_bias(tree, q, qd)
    by_q, by_qd = spong_partials(q, qd, np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0])
    assert np.max(np.abs(truth.dtau_dq - by_q)) <= CLOSED_FORM * np.max(np.abs(by_q))
    assert np.max(np.abs(truth.dtau_dqdot - by_qd)) <= CLOSED_FORM * np.max(np.abs(by_qd))


def test_it_is_complex_safe():
    """A complex input's imaginary part carries through as the derivative (no part dropped or conjugated), and the
    RNEA raises if anything casts complex to real (ComplexWarning is an error inside it)."""
    scene = library.load(["oblique-arm-dynamics"])[0]
    tree = tree_from_chain(scene.chain, scene.gravity_world)
    q, qd, qdd, _ = (x[:3] for x in scene.states())
    perturbed = rnea(tree, q + 1e-30j, qd, qdd)
    assert perturbed.dtype == complex and np.all(perturbed.imag != 0)
    real = rnea(tree, q, qd, qdd)  # the real part is the function itself, to the rounding of complex products
    assert np.max(np.abs(perturbed.real - real)) <= ROUNDING * np.max(np.abs(real))


GRAVITY = np.array([0.0, 0.0, -9.81])


def _go1_leg():
    from importlib import metadata

    from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_ROBOTS
    from simparity.core.urdf import chain_from_urdf

    robots = metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)
    return chain_from_urdf(str(robots / "go1_description/urdf/go1.urdf"), "trunk", "FR_foot", dynamics=True,
                           floating_base=True)


@pytest.fixture(scope="module", params=["solo12", "go1"])
def floating(request):
    chain = solo12_leg() if request.param == "solo12" else _go1_leg()
    return chain, tree_from_chain(chain, GRAVITY), floating_states(chain, 4, 7)


def _moved(q: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """q ⊕ δ in the project's chart, by SciPy: position + δp, R' = exp([δθ]x) R, joints + δ."""
    from scipy.spatial.transform import Rotation

    turned = Rotation.from_rotvec(np.tile(delta[3:6], (len(q), 1))) * Rotation.from_quat(q[:, 3:7], scalar_first=True)
    return np.concatenate([q[:, :3] + delta[:3], turned.as_quat(scalar_first=True), q[:, 7:] + delta[6:]], axis=1)


def test_the_exponential_is_scipy_s_and_complex_safe():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    vectors = rng.uniform(-0.6, 0.6, (20, 3))  # |theta| <= 1, the series' range
    assert np.max(np.abs(exp_so3(vectors) - Rotation.from_rotvec(vectors).as_matrix())) <= 1e-15
    slopes = exp_so3(1e-30j * np.eye(3)).imag / 1e-30  # d exp / d delta_k at 0: the generators [e_k]x
    generators = np.array([[[0, 0, 0], [0, 0, -1], [0, 1, 0]], [[0, 0, 1], [0, 0, 0], [-1, 0, 0]],
                           [[0, -1, 0], [1, 0, 0], [0, 0, 0]]], dtype=float)
    np.testing.assert_array_equal(slopes, generators)


def test_on_a_floating_base_its_rnea_is_pinocchio_s_free_flyer(floating):
    from simparity.references.pinocchio.floating import PinocchioFloatingDynamics

    chain, tree, (q, qd, qdd, _) = floating
    pinocchio = PinocchioFloatingDynamics(chain, GRAVITY).inverse_dynamics(q, qd, qdd)
    assert np.max(np.abs(rnea(tree, q, qd, qdd) - pinocchio)) <= ROUNDING * np.max(np.abs(pinocchio))


def test_on_a_floating_base_its_derivatives_are_central_differences_in_the_project_s_chart(floating):
    chain, tree, (q, qd, _, tau) = floating
    truth = derivatives(tree, q, qd, tau)
    qdd = forward_dynamics(tree, q, qd, tau)
    for name in ("dtau_dq", "dtau_dqdot"):
        columns = []
        for e in np.eye(chain.nv):
            if name == "dtau_dq":
                up, down = rnea(tree, _moved(q, FD_STEP * e), qd, qdd), rnea(tree, _moved(q, -FD_STEP * e), qd, qdd)
            else:
                up, down = rnea(tree, q, qd + FD_STEP * e, qdd), rnea(tree, q, qd - FD_STEP * e, qdd)
            columns.append((up - down).real / (2 * FD_STEP))
        reference = np.stack(columns, axis=-1)
        assert np.max(np.abs(getattr(truth, name) - reference)) <= FD_AGREEMENT * np.max(np.abs(reference)), name
    assert np.all(truth.dtau_dq[:, :, :3] == 0.0)  # the base's position: gravity is uniform, nothing depends on it
    mass, _ = mass_and_bias(tree, q, qd)
    assert np.max(np.abs(np.linalg.inv(truth.dqddot_dtau) - mass)) <= ROUNDING * np.max(np.abs(mass))
