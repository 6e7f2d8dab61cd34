"""A chain's contact under the fixed transforms (``comparisons/invariance/transforms.py``, issue #46): the plane moves
with the world, spheres on links scale in their frames, a sphere on a fixed base's link (the world's frame) moves as a
point, and core's penalty constants take the new units; so every sphere's gap is the same up to the length scale, and
the contact force at the same state is the same up to the force unit."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.invariance.transforms import FIXED_TRANSFORMS, transform_scene
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.core.model.scenes.chain_contact import ChainContact, ContactSphere
from simparity.core.model.scenes.contact import Plane
from simparity.core.model.scenes.joint_motion import JointMotionScene

ROUNDING = 1e-9
"""Relative agreement of gaps and forces across a transform: a 2 km translation rounds positions at ~5e-13 m."""



def _centres(chain, contact, q: np.ndarray) -> np.ndarray:
    """(B, S, 3) the spheres' centres by core's FK at configurations q (B, nq)."""
    return ChainContactForces(chain, contact).centres_world(np.asarray(q).T)

def _scene(friction: float = 0.0) -> JointMotionScene:
    link = LinkInertia(1.0, np.array([0.15, 0.0, 0.0]), np.diag([1e-4, 7.5e-3, 7.5e-3]))
    joints = (Joint("hinge", "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.eye(3), link=link),
              Joint("slide", "prismatic", np.array([1.0, 0.0, 0.0]), np.array([0.3, 0.0, 0.0]), np.eye(3),
                    lower=-0.1, upper=0.1, link=link))
    spheres = (ContactSphere("tip", np.zeros(3), 0.02), ContactSphere("hinge", np.array([0.2, 0.0, 0.0]), 0.03),
               ContactSphere("base", np.array([0.0, -0.3, 0.0]), 0.05))
    contact = ChainContact(Plane(np.array([0.0, 1.0, 0.0]), 0.3), spheres, 1e4, 50.0, friction=friction,
                           friction_speed=1.0)  # faster than the case's slips: core's friction in its linear part
    chain = Chain("arm", joints, "tip", np.array([0.1, 0.0, 0.0]), base_link="base")
    return JointMotionScene("press", "", "core", chain, np.array([0.0, -9.81, 0.0]), np.array([[-0.8, 0.05]]),
                            np.zeros((1, 2)), np.zeros(2), 1.0, (0.01,), contact=contact)


@pytest.mark.parametrize("friction", [0.0, 0.5])
@pytest.mark.parametrize("transform", [t for t in FIXED_TRANSFORMS if t.name != "permute"], ids=lambda t: t.name)
def test_gaps_and_forces_are_the_same_in_every_frame_and_unit(transform, friction):
    """With friction too: core's regularisation speed is a scene input, converted with the units."""
    scene = _scene(friction)
    moved = transform_scene(scene, transform)
    q, qdot = scene.q0, np.array([[0.3, -0.02]])
    powers = scene.chain.length_powers
    q_moved = transform.length_scale ** powers * q
    qdot_moved = transform.length_scale ** powers / transform.time_scale * qdot
    gaps = scene.contact.gaps(_centres(scene.chain, scene.contact, q))
    gaps_moved = moved.contact.gaps(_centres(moved.chain, moved.contact, q_moved))
    np.testing.assert_allclose(gaps_moved, transform.length_scale * gaps, rtol=ROUNDING, atol=ROUNDING)
    assert np.any(gaps < 0)  # the case presses
    if friction:
        moved_speed = transform.factor(length=1, time=-1) * scene.contact.friction_speed
        assert moved.contact.friction_speed == pytest.approx(moved_speed, rel=1e-15)
    force = ChainContactForces(scene.chain, scene.contact).forces_world(q.T, qdot.T)
    force_moved = ChainContactForces(moved.chain, moved.contact).forces_world(q_moved.T, qdot_moved.T)
    unit = transform.factor(length=1, mass=1, time=-2)
    np.testing.assert_allclose(force_moved, unit * transform.vector(force), rtol=ROUNDING,
                               atol=ROUNDING * float(np.abs(force).max()) * unit)


@pytest.mark.parametrize("transform", [t for t in FIXED_TRANSFORMS if t.name != "permute"], ids=lambda t: t.name)
def test_the_time_the_robot_rests_from_takes_the_new_unit_of_time(transform):
    from dataclasses import replace

    scene = _scene()
    scene = replace(scene, contact=replace(scene.contact, rest_after=0.4))
    moved = transform_scene(scene, transform)
    assert moved.contact.rest_after == pytest.approx(0.4 * transform.time_scale, rel=1e-15)
    assert moved.duration == pytest.approx(scene.duration * transform.time_scale, rel=1e-15)
