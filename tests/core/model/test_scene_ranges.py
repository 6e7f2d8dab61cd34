"""Issue #39: a scene built in code is held to the ranges a scene file is held to as it is read (a damping of 1e308,
a centre of mass 1e308 m away, a subnormal armature), by ``simparity.run_scene`` and the pytest fixture, before any
case runs; every built-in scene as loaded passes."""

import dataclasses

import numpy as np
import pytest

from simparity.comparisons.api import load_scene, load_scenes, run_scene
from simparity.comparisons.scenes.library import builtin_paths
from simparity.core.model.errors import SceneError
from simparity.core.model.scene_ranges import check_scene_ranges

ARM = "crafted-arm-dynamics"
"""A built-in joint-dynamics scene whose chain has links, damping and armature to edit."""


def _with_joint(scene, **changes):
    joints = list(scene.chain.joints)
    joints[0] = dataclasses.replace(joints[0], **changes)
    return dataclasses.replace(scene, chain=dataclasses.replace(scene.chain, joints=tuple(joints)))


def _with_link(scene, **changes):
    link = dataclasses.replace(scene.chain.joints[0].link, **changes)
    return _with_joint(scene, link=link)


@pytest.mark.slow  # over 1.5 s of CPU on a 2-core CI-class machine (tests/conftest.py)
def test_every_builtin_scene_as_loaded_is_within_the_ranges():
    for path in builtin_paths().values():
        for scene in load_scenes(path):
            check_scene_ranges(scene)


@pytest.mark.parametrize("edit, key, allowed", [
    (lambda s: _with_joint(s, damping=1e308), "chain.joints[0].damping", "N m s/rad"),
    (lambda s: _with_joint(s, armature=5e-324), "chain.joints[0].armature", "subnormal"),
    (lambda s: _with_joint(s, armature=1e300), "chain.joints[0].armature", "kg m^2"),
    (lambda s: _with_link(s, com_xyz=np.array([1e308, 0.0, 0.0])), "chain.joints[0].link.com_xyz", "1000 km"),
    (lambda s: _with_link(s, mass=1e12), "chain.joints[0].link.mass", "kg"),
    (lambda s: dataclasses.replace(s, gravity_world=np.array([0.0, 0.0, -1e300])), "gravity_world", "m/s^2"),
])
def test_a_scene_built_in_code_out_of_range_is_refused_naming_the_field(edit, key, allowed):
    scene = edit(load_scene(ARM))
    with pytest.raises(SceneError) as refused:
        run_scene(scene, engines=["core"], isolate=False)
    assert refused.value.key == key and allowed in refused.value.allowed


def test_an_infinite_joint_limit_is_no_limit_and_passes():
    scene = _with_joint(load_scene(ARM), lower=-np.inf, upper=np.inf)
    check_scene_ranges(scene)
