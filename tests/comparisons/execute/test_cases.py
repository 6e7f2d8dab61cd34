"""Issue #12: the unit of work. A scene is planned into groups of cases in its stored order; a scene's content
hash (the key a finished case is kept under) is the same in every process and moves with any value."""

from __future__ import annotations

import dataclasses
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from simparity.comparisons.execute.cases import DYNAMICS, IK, KINEMATICS, STABILITY, plan_scene
from simparity.comparisons.common.integrators import NO_INTEGRATOR
from simparity.comparisons.common.scene_hash import scene_hash
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.library import builtin_paths
from simparity.comparisons.scenes.loading.scene_file import load_scene
from tests.helpers import builtin


@pytest.mark.slow
def test_the_same_scene_hashes_the_same_in_another_process():
    here = scene_hash(builtin("ball-bounce-k05"))
    code = ("from simparity.comparisons.common.scene_hash import scene_hash; "
            "from simparity.comparisons.scenes.loading.scene_file import "
            f"load_scene; print(scene_hash(load_scene({str(builtin_paths()['ball-bounce-k05'])!r})))")
    there = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env={"PYTHONHASHSEED": "123", "PATH": "",  # the simparity under test, not the installed one
                                **{k: v for k, v in os.environ.items() if k == "PYTHONPATH"}}).stdout.strip()
    assert here == there == scene_hash(builtin("ball-bounce-k05"))


def test_any_changed_value_changes_the_hash():
    scene = builtin("lecture-projectile")
    body = scene.bodies[0]
    nudged = dataclasses.replace(body, mass=np.nextafter(body.mass, 2.0))
    variants = [dataclasses.replace(scene, bodies=(nudged,)), dataclasses.replace(scene, name="other"),
                dataclasses.replace(scene, dts=scene.dts[:-1])]
    hashes = {scene_hash(s) for s in variants} | {scene_hash(scene)}
    assert len(hashes) == len(variants) + 1


def test_the_same_file_by_a_relative_or_absolute_path_or_moved_hashes_the_same(tmp_path, monkeypatch):
    """A scene's hash is its content, not where it was read from: a run started with a relative path and
    resumed (which names it absolutely) keeps every finished case. Its URDF is named absolutely either way."""
    import pybullet_data

    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        shutil.copy(builtin_paths()["lecture-projectile"], tmp_path / folder / "scene.toml")
        shutil.copy(Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf", tmp_path / folder / "arm.urdf")
        (tmp_path / folder / "arm.toml").write_text('[scene]\nname = "arm"\nkind = "kinematics"\nreference = '
                                                   '"pinocchio"\n[chain]\nurdf = "arm.urdf"\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    for name in ("scene.toml", "arm.toml"):
        relative, absolute = load_scene(f"a/{name}"), load_scene(str(tmp_path / "a" / name))
        assert relative.source != absolute.source and scene_hash(relative) == scene_hash(absolute)
    arms = [load_scene("a/arm.toml"), load_scene(str(tmp_path / "a" / "arm.toml"))]
    assert arms[0].chain.urdf_path == arms[1].chain.urdf_path == str(tmp_path / "a" / "arm.urdf")
    assert scene_hash(load_scene("a/scene.toml")) == scene_hash(load_scene("b/scene.toml"))  # moved: the same


def test_a_dynamics_scene_is_a_group_per_time_step_then_the_stability_limits():
    scene = builtin("hard-penalty-stiff")
    engines = [make_engine(n) for n in ("core", "mujoco")]
    groups = plan_scene(scene, engines, make_engine(scene.reference), 0)
    assert [g.kind for g in groups] == [DYNAMICS] * len(scene.dts) + [STABILITY]
    assert [g.dt for g in groups[:-1]] == list(scene.dts) and math.isnan(groups[-1].dt)
    engine_order = [c.engine for c in groups[0].cases]
    assert engine_order == sorted(engine_order, key=("core", "mujoco").index)  # the run's engine order
    assert groups[-1].cases and all(c.integrator.startswith("penalty") for c in groups[-1].cases)


def test_an_engine_offering_none_of_the_scene_integrators_has_one_na_case():
    scene = dataclasses.replace(builtin("lecture-projectile"), integrators=("rk4",))
    groups = plan_scene(scene, [make_engine("pybullet")], make_engine(scene.reference), 0)
    assert [(c.engine, c.integrator) for g in groups for c in g.cases] == [("pybullet", NO_INTEGRATOR)] * len(scene.dts)


@pytest.mark.parametrize("name, kind", [("ur5-kinematics", KINEMATICS), ("lecture-2link-ik", IK)])
def test_kinematics_and_ik_scenes_are_one_group(name, kind):
    scene = builtin(name)
    engines = [make_engine(n) for n in ("core", "mujoco")]
    [group] = plan_scene(scene, engines, make_engine(scene.reference), 0)
    assert group.kind == kind and group.engine_names == ("core", "mujoco")
    assert {c.engine for c in group.cases} == {"core", "mujoco"}
