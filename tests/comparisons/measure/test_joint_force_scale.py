"""Issue #38, section 1: joint-force errors are relative to a scale that never vanishes. A chain whose bias forces
vanish at every state (rounding of m g is all the reference computes) passes on every correct engine, while a bug
confined to the light last link's Coriolis term on a chain whose bias is small still fails, and the floor is what a
row says it is relative to."""

from __future__ import annotations

import numpy as np
import pytest

import simparity
from simparity.comparisons.gate.check import check_table
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.comparisons.measure.joint_dynamics_metrics import reference_errors
from simparity.comparisons.measure.joint_force_scale import ForceScale
from simparity.comparisons.scenes import library
from simparity.core.model.metric_catalogue import BIAS_FORCE_ERROR_MAX, INVERSE_DYNAMICS_ERROR_MAX
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from tests.mutation.catalogue import by_id
from tests.system.test_mutation import imported  # noqa: F401 - the fixture that materialises copies of core

SHIPPED_BOUND = 1e-12
"""The shipped tolerances' bound on the joint-force errors of every engine but PyBullet (default.toml)."""
ROUNDING = 1e-14
"""A correct engine's joint-force error over the chain's force scale: rounding of a few dozen products."""


def _slides() -> Chain:
    """Three prismatic joints whose axes are all perpendicular to gravity (-6, -8) along y, z: h = 0 + the rounding
    of m g at every state (no velocity-dependent term on a chain of slides)."""
    def link(mass: float, com: tuple[float, float, float]) -> LinkInertia:
        return LinkInertia(mass, np.array(com), np.diag([0.01, 0.02, 0.03]) * mass)

    axes = ((1.0, 0.0, 0.0), (0.0, 0.8, -0.6), (0.6, 0.48, -0.36))
    origins = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.1), (0.0, 0.2, 0.1))
    links = (link(2.0, (0.1, 0.2, 0.0)), link(1.0, (0.0, 0.1, 0.0)), link(0.5, (0.05, 0.0, 0.0)))
    return Chain("slides", tuple(Joint(f"slide{i}", "prismatic", np.array(axis), np.array(origin), np.eye(3), -1.0,
                                       1.0, link=inertia)
                                 for i, (axis, origin, inertia) in enumerate(zip(axes, origins, links))))


def test_a_chain_whose_bias_vanishes_passes_every_correct_engine():
    """Before the floor, core got a bias-force 'error' of 4.0 (MuJoCo and PyBullet 0 or ~1 by luck) against
    Pinocchio's h of 9e-16, and --check failed correct engines."""
    scene = JointDynamicsScene("slides-dynamics", "", "pinocchio", _slides(), np.array([0.0, -6.0, -8.0]),
                               n_states=20, seed=3)
    table = simparity.run_scene(scene, ("core", "mujoco", "pybullet", "pinocchio"), repeats=0, isolate=False)
    result = check_table(table, load_tolerances())
    assert result.passed, [str(v) for v in result.violations][:3]
    bias = table[(table["metric"] == BIAS_FORCE_ERROR_MAX) & (table["status"] == "ok")].set_index(
        ["engine", "integrator"])
    assert set(bias.index) >= {("core", "recursive"), ("core", "jacobian_sum"), ("mujoco", "recursive"),
                               ("pybullet", "recursive"), ("pinocchio", "recursive")}
    assert (bias["value"] <= ROUNDING).all(), bias["value"].to_dict()
    assert bias["detail"].str.contains("force scale").all()


def _scale(per_joint: float, n: int = 2) -> ForceScale:
    """A force scale of ``per_joint`` [N m] on each of ``n`` joints, all of it weight."""
    zero = np.zeros(n)
    return ForceScale(inertia=zero, weight=np.full(n, per_joint), velocity=zero, damping=zero)


def _values(h: np.ndarray) -> dict[str, np.ndarray]:
    """An engine's outputs at 3 states of a 2-joint chain with bias ``h`` (3, 2) and M = 1, qddot = 1."""
    mass = np.broadcast_to(np.eye(2), (3, 2, 2)).copy()
    return {"M": mass, "h": h, "tau": 1.0 + h, "qdd": np.ones((3, 2))}


def test_rounding_of_a_vanishing_bias_is_no_error_and_a_bug_of_a_billionth_of_the_scale_is():
    """h_ref is 1e-18 noise on a chain whose weight can exert 30 N m: an engine's 3e-18 noise is ~1e-18 of the
    scale, not 300 %; a bug of 1e-9 of the scale (the lightest link's term) reads >= 1e-9, above any bound."""
    rng = np.random.default_rng(38)
    scale = _scale(30.0)
    reference = _values(1e-18 * rng.standard_normal((3, 2)))
    noisy = _values(3e-18 * rng.standard_normal((3, 2)))
    assert reference_errors(noisy, reference, scale)[BIAS_FORCE_ERROR_MAX].value <= ROUNDING
    buggy = _values(reference["h"] + np.array([0.0, 1e-9 * 30.0]))
    errors = reference_errors(buggy, reference, scale)
    assert errors[BIAS_FORCE_ERROR_MAX].value >= 1e-9
    assert errors[INVERSE_DYNAMICS_ERROR_MAX].value > SHIPPED_BOUND


def test_a_massless_chain_at_rest_has_nothing_to_be_relative_to():
    values = _values(np.zeros((3, 2)))
    values["M"][:] = 0.0
    measured = reference_errors(values, values, _scale(0.0))[BIAS_FORCE_ERROR_MAX]
    assert np.isnan(measured.value) and "nothing to be relative to" in measured.unmeasurable


@pytest.mark.parametrize("planted", [False, True], ids=["faithful", "tip_coriolis"])
def test_a_bug_only_in_the_last_links_coriolis_term_fails_on_a_chain_whose_bias_is_small(imported, planted):
    """The catalogue's rnea_tip_velocity_product (the velocity-product force of the 0.1 kg last link dropped) on the
    slow SCARA arm, whose h is ~1e-4 of its force scale: the floor must not hide it; the faithful copy passes."""
    copy = imported(by_id("rnea_tip_velocity_product") if planted else None)
    table = simparity.run_scene(library.load(["scara-slow-dynamics"])[0], ("pinocchio", copy.spec), repeats=0,
                                isolate=False)
    rows = table[table["metric"] == BIAS_FORCE_ERROR_MAX].set_index(["engine", "integrator"])
    assert "force scale" in rows.loc[("pinocchio", "recursive"), "detail"]  # h < the floor: the floor acts here
    violations = {(v.engine, v.integrator, v.metric) for v in check_table(table, load_tolerances()).violations}
    if planted:
        assert (copy.engine_name, "recursive", BIAS_FORCE_ERROR_MAX) in violations
        assert rows.loc[(copy.engine_name, "recursive"), "value"] > 1e3 * SHIPPED_BOUND
        assert (copy.engine_name, "jacobian_sum", BIAS_FORCE_ERROR_MAX) not in violations  # RNEA's bug only
    else:
        assert not violations


def test_without_a_reference_the_identities_are_floored_at_the_engines_own_force_scale():
    """A reference that cannot do the chain (the closed form is for 1 or 2 joints): each engine's identities still
    run, floored at the force scale of its own model (the weight of the slides, which their forces never feel)."""
    scene = JointDynamicsScene("slides-dynamics", "", "analytic", _slides(), np.array([0.0, -6.0, -8.0]),
                               n_states=20, seed=3)
    table = simparity.run_scene(scene, ("core", "analytic"), repeats=0, isolate=False)
    rows = table[(table["engine"] == "core") & (table["metric"] == "gravity_identity_residual")]
    assert set(rows["status"]) == {"ok"} and (rows["value"] <= ROUNDING).all()
    assert rows["detail"].str.contains("force scale").all()
    assert set(table[(table["engine"] == "core") & (table["metric"] == BIAS_FORCE_ERROR_MAX)]["status"]) == {"n/a"}
