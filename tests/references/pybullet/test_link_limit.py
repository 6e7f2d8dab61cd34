"""PyBullet holds at most 128 links per body (issue #39: a 128-joint chain's dynamics failed with 'getJointState
failed'): the adapter says n/a with the reason before building, and the engine's limit is pinned here so the
reason cannot go stale."""

import numpy as np
import pytest

from simparity.references.common.urdf_export import chain_urdf
from simparity.references.pybullet.adapter import MAX_LINKS, PybulletEngine, _load_urdf
from simparity.references.pybullet.quiet import pybullet
from tests.helpers import random_chain

WITHIN, BEYOND = MAX_LINKS - 1, MAX_LINKS
"""Movable joints of a chain PyBullet holds (its URDF adds the end effector's fixed joint: MAX_LINKS links) and of one
it does not (MAX_LINKS + 1 links)."""


@pytest.mark.parametrize("joints, holds", [(WITHIN, True), (BEYOND, False)])
def test_pybullet_reads_joint_states_up_to_its_link_limit_only(joints, holds):
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = _load_urdf(client, chain_urdf(random_chain(np.random.default_rng(39), joints)), useFixedBase=True)
        try:
            pybullet.getJointState(body, 0, physicsClientId=client)
            read = True
        except pybullet.error:
            read = False
    finally:
        pybullet.disconnect(client)
    assert read == holds


@pytest.mark.parametrize("joints, holds", [(WITHIN, True), (BEYOND, False)])
def test_a_chain_beyond_pybullets_link_limit_is_na_with_the_reason(joints, holds):
    support = PybulletEngine().supports_kinematics(random_chain(np.random.default_rng(39), joints))
    assert support.ok == holds
    assert holds or f"at most {MAX_LINKS} links" in support.reason
