"""The built-in library and its suites (comparisons/scenes/library.py), and the hard suite's verdicts."""

import dataclasses
import fnmatch
import math
import re

from pathlib import Path

import pandas as pd
import numpy as np
import pytest

from simparity.comparisons.scenes import library
from simparity.comparisons.gate.check import check_table
from simparity.comparisons.scenes.describe import describe
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.profiles import quick
from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_PREFIX
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.core.model.errors import SceneError, SimparityError, UnknownSceneError
from simparity.core.model.files import tomllib
from simparity.core.model.results import COLUMNS, DIVERGED, OK, ResultRow
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.suites import SweepPoint
from tests.helpers import builtin

MIN_HARD_CASES = 20
"""Issue #8: the hard suite gathers at least 20 cases (a dynamics scene, or one hard IK target)."""


def _table(rows):
    return pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))


@pytest.mark.slow
def test_default_suite_is_every_scene_marked_default_and_hard_is_its_own():
    default = {s.name for s in library.suite("default")}
    hard = {s.name for s in library.suite("hard")}
    contact = {s.name for s in library.suite("contact")}
    bench = {s.name for s in library.suite("bench")}
    articulated = {s.name for s in library.suite("articulated")}
    robots = {s.name for s in library.suite("robots")}
    assert "lecture-projectile" in default and "lecture-projectile" not in hard
    assert "hard-stiff-drag" in hard and "hard-stiff-drag" not in default
    assert "fast-spinner" in default & hard
    assert default | hard | contact | bench | articulated | robots == {
        s.name for s in library.load(list(library.builtin_paths()))}
    files = {s.sweep.base if s.sweep else s.name
             for name in ("default", "hard", "contact", "bench", "articulated", "robots") for s in library.suite(name)}   # a sweep's variants are named after their file's scene
    assert files == set(library.builtin_paths())


RESTITUTION_SWEEP = ["restitution-sweep_restitution-0.3", "restitution-sweep_restitution-0.5",
                     "restitution-sweep_restitution-0.7", "restitution-sweep_restitution-0.9"]
"""The variants of the built-in example sweep, written out from its file's range (0.3 to 0.9 in 4 values)."""


def test_a_file_with_a_sweep_loads_as_its_variants_in_the_sweeps_order():
    """Issue #12: one file, one scene per swept value, in the sweep's order and where the file was named."""
    loaded = library.load(["wind", "restitution-sweep", "dzhanibekov"])
    assert [s.name for s in loaded] == ["wind"] + RESTITUTION_SWEEP + ["dzhanibekov"]
    variants = loaded[1:5]
    assert [s.sweep.values for s in variants] == [(("contact.restitution", k),) for k in (0.3, 0.5, 0.7, 0.9)]
    assert [float(s.contact.restitution[0, 0]) for s in variants] == [0.3, 0.5, 0.7, 0.9]
    assert [s.name for s in library.load([str(library.builtin_paths()["restitution-sweep"])])] == RESTITUTION_SWEEP


def test_a_built_in_variant_is_found_by_the_name_simparity_list_shows():
    (variant,) = library.load(["restitution-sweep_restitution-0.7"])
    assert variant.sweep == SweepPoint("restitution-sweep", (("contact.restitution", 0.7),), 2, 4)
    assert ("variant 3 of 4 of the sweep of restitution-sweep: contact.restitution = 0.7 (as written in the file)"
            in describe(variant).splitlines())   # what `simparity show` prints
    with pytest.raises(UnknownSceneError, match="not a built-in scene or an existing file; closest: restitution-sweep"):
        library.load(["restitution-sweep_restitution-0.8"])


@pytest.mark.parametrize("name", ["nosuchfile.toml", "some/dir/x.toml", "robot.URDF", "model.xml", "dir/noext"])
def test_a_missing_path_is_one_line_saying_the_file_does_not_exist(tmp_path, monkeypatch, name):
    """Issue #25: anything that looks like a path (a separator, or .toml/.urdf/.xml) names the file as resolved,
    never the built-in scenes."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UnknownSceneError) as info:
        library.load([name])
    text = str(info.value)
    assert text.startswith(f"{name}: the file {tmp_path / name} does not exist (allowed: ")
    assert "\n" not in text and "lecture-projectile" not in text and "built-in scene name" in text


def test_a_path_that_is_not_a_regular_file_says_why(tmp_path):
    with pytest.raises(UnknownSceneError, match="not a regular file"):
        library.resolve(str(tmp_path))


@pytest.mark.parametrize("word, closest", [("lecture-projectil", ["lecture-projectile", "lecture-bouncing-particle"]),
                                           ("no-such-scene", [])])
def test_an_unknown_bare_word_names_the_closest_built_in_scenes_only(word, closest):
    """A word is taken for a scene name: the closest built-in names (at most CLOSEST_NAMES), not the whole list."""
    with pytest.raises(UnknownSceneError) as info:
        library.resolve(word)
    text = str(info.value)
    assert text.startswith(f"'{word}' is not a built-in scene or an existing file")
    assert ("; closest: " + ", ".join(closest) + " (") in text if closest else "closest" not in text
    shown = [name for name in library.builtin_paths() if re.search(rf"[ ,]{re.escape(name)}[,;( ]", text)]
    assert shown == sorted(closest) and len(shown) <= library.CLOSEST_NAMES


def test_the_example_sweep_is_in_the_contact_suite_only():
    """Not in the default suite: it must not slow `simparity run`."""
    contact = [s.name for s in library.suite("contact")]
    assert [n for n in contact if n.startswith("restitution-sweep")] == RESTITUTION_SWEEP
    assert not any(s.sweep for s in library.suite("default"))


def test_the_bench_suite_is_the_three_arms_with_10000_targets_each():
    """Issue #11: the arms `simparity bench` times, TRAC-IK protocol (10,000 targets from mid-range, 1e-6)."""
    bench = library.suite("bench")
    assert sorted(s.name for s in bench) == ["bench-iiwa-ik", "bench-panda-ik", "bench-ur5-ik"]
    for scene in bench:
        assert scene.n_targets == 10_000 and scene.position_tolerance == scene.orientation_tolerance == 1e-6
        mid = np.where(np.isfinite(scene.chain.lower + scene.chain.upper), (scene.chain.lower + scene.chain.upper) / 2, 0)
        np.testing.assert_array_equal(scene.q_start, mid)


@pytest.mark.slow
def test_the_contact_suite_is_every_scene_with_planes():
    """Issue #10: every built-in scene with a plane is in the contact suite, and nothing else is."""
    scenes = library.load(list(library.builtin_paths().values()))
    with_planes = {s.name for s in scenes if getattr(s, "contact", None) is not None}
    assert {s.name for s in library.suite("contact")} == with_planes
    assert {"hard-fast-impact", "hard-penalty-stiff", "hard-zeno"} <= {s.name for s in library.suite("hard")}


def test_an_unknown_suite_is_refused_with_the_allowed_names():
    with pytest.raises(SimparityError, match=r"allowed: default, hard, contact"):
        library.suite("nightly")


def test_a_scene_file_naming_an_unknown_suite_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    text = library.builtin_paths()["wind"].read_text(encoding="utf-8")
    path.write_text(text.replace('reference = "analytic"', 'reference = "analytic"\nsuites = ["nightly"]'),
                    encoding="utf-8")
    with pytest.raises(SceneError, match=r"scene\.suites\[0\].*allowed: .*default, hard"):
        library.load([str(path)])


def test_the_hard_suite_has_enough_cases_and_each_has_its_own_expected_verdict():
    bounds = load_tolerances()
    scenes = library.suite("hard")
    cases = [s.name for s in scenes if isinstance(s, DynamicsScene)]
    cases += [f"{s.name}/{t}" for s in scenes if isinstance(s, IKScene) for t in s.hard_targets]
    assert len(cases) >= MIN_HARD_CASES, cases
    for scene in scenes:  # a bound written for this scene or for the hard scenes (not a catch-all)
        named = [b for b in bounds if b.scene not in ("*", "*-ik") and fnmatch.fnmatchcase(scene.name, b.scene)]
        assert named, f"{scene.name} has no expected verdict of its own in the shipped tolerances"


@pytest.mark.slow
def test_stiff_drag_verdicts_follow_linear_stability_theory():
    """h c/m = 2.5: Euler (|1 + z| = 1.5) and the second-order rules (1.625) diverge, RK4 (0.648) and
    MuJoCo's implicit damping stay bounded; the shipped tolerances hold exactly that."""
    scene = quick(builtin("hard-stiff-drag"))
    scene = dataclasses.replace(scene, integrators=("explicit_euler", "midpoint", "rk4", "implicit", "euler"))
    rows = run_scene(scene, [make_engine("core"), make_engine("mujoco")], make_engine, repeats=0)
    table = _table(rows)
    coarse = table[(table["dt"] - 0.05).abs() < 1e-12]
    status = coarse.groupby(["engine", "integrator"])["status"].agg(set)
    assert status[("core", "explicit_euler")] == {DIVERGED}
    assert status[("core", "midpoint")] == {DIVERGED}
    assert status[("mujoco", "euler")] == {DIVERGED}
    assert DIVERGED not in status[("core", "rk4")] | status[("mujoco", "rk4")] | status[("mujoco", "implicit")]
    result = check_table(table, load_tolerances())
    assert result.passed, [v.line() for v in result.violations][:5]


@pytest.mark.parametrize("scene, engine, integrator, dt", [
    ("hard-stiff-drag", "core", "explicit_euler", 0.05), ("hard-needle", "mujoco", "euler", 0.001),
    ("hard-needle", "pybullet", "euler", 0.005)])
def test_a_blow_up_reported_as_bounded_fails_the_hard_gate(scene, engine, integrator, dt):
    """The gate checks stability: a case theory says must blow up fails the check when it stays ok (the row
    carries the kind of scheme its engine declares: the gate holds the kind)."""
    scheme = make_engine(engine).scheme(integrator, builtin(scene))
    row = ResultRow(scene, engine, integrator, dt, "energy_drift_max", 1e-3, "1", "analytic:exact", OK, scheme=scheme)
    result = check_table(_table([row]), load_tolerances())
    assert not result.passed and "diverged" in result.violations[0].line()


def test_a_limit_blocked_target_claimed_solved_fails_the_hard_gate():
    row = ResultRow("hard-planar-ik", "mujoco", "dls", math.nan, "hard_beyond_limits_solved", 1.0, "1", "analytic:fk", OK)
    assert not check_table(_table([row]), load_tolerances()).passed


def test_a_suite_loads_only_its_own_scenes(monkeypatch):
    """A scene outside the suite is never loaded, so what it needs cannot break the suite."""
    loaded = []
    real_load = library.load
    monkeypatch.setattr(library, "load", lambda paths, *a: loaded.extend(Path(p).stem for p in paths) or real_load(paths, *a))
    names = [s.name for s in library.suite("default")]
    assert sorted(loaded) == sorted(names) and "hard-stiff-drag" not in loaded


def test_built_in_scenes_need_only_the_runtime_dependencies():
    """`pip install .` must run every built-in suite: no built-in scene names a robot from a test extra."""
    extras = tomllib.loads((Path(__file__).parents[3] / "pyproject.toml").read_text(encoding="utf-8"))
    runtime = " ".join(extras["project"]["dependencies"])
    for name, path in library.builtin_paths().items():
        if EXAMPLE_ROBOT_DATA_PREFIX in path.read_text(encoding="utf-8"):
            assert "example-robot-data" in runtime, f"{name} needs example-robot-data, a test-only extra"


@pytest.mark.parametrize("engine, integrator, scene, kind", [
    # MuJoCo: Euler is semi-implicit with the exponential map; implicit(fast) take damping implicitly; with planes
    # its soft constraint drives them; dls is damped least squares (docs/check.md, engine-conventions notes).
    ("mujoco", "euler", "wind", "engine_euler"),
    ("mujoco", "implicitfast", "wind", "implicit_damping"),
    ("mujoco", "euler", "ball-bounce-k05", "soft+engine_euler"),
    ("mujoco", "dls", "ur5-ik", "damped_least_squares"),
    # Bullet: the same Euler step; with planes, velocity-level impulses; its IK with a rest pose is null-space.
    ("pybullet", "euler", "wind", "engine_euler"),
    ("pybullet", "euler", "ball-bounce-k05", "impulse+engine_euler"),
    ("pybullet", "dls-nullspace", "iiwa-ik", "damped_least_squares+nullspace"),
    # The harness's steppers on Pinocchio, and its documented CLIK.
    ("pinocchio", "euler", "wind", "engine_euler"),
    ("pinocchio", "clik", "ur5-ik", "damped_least_squares"),
    # Core: named after what they are; a variant is its scheme; penalty drives a time integrator; IK keeps limits.
    ("core", "rk4+matrix", "wind", "rk4"),
    ("core", "penalty_rk4", "lecture-bouncing-particle", "penalty+rk4"),
    ("core", "backup", "ball-bounce-k05", "backup"),
    ("core", "damped_least_squares", "iiwa-ik", "damped_least_squares+limits"),
    # The truths.
    ("analytic", "closed_form", "wind", "closed_form"),
    ("tight", "dop853", "dzhanibekov", "adaptive"),
])
def test_every_built_in_engine_declares_the_kind_of_scheme_it_runs(engine, integrator, scene, kind):
    """The gate's bounds are keyed by these kinds: a wrong declaration would hold a scheme to another kind's
    bounds (or to none)."""
    assert make_engine(engine).scheme(integrator, builtin(scene)) == kind


def test_a_plugin_that_names_its_integrators_after_their_kind_needs_no_declaration():
    """Engine.scheme's default: an integrator named as a kind is of that kind, its variant left out; on a contact
    scene penalty_<kind> is penalty+<kind>; a name that is no kind says nothing ("")."""
    from simparity.core.model.engine import Engine

    default = Engine.scheme
    plugin = make_engine("core")
    assert default(plugin, "midpoint+expmap", builtin("wind")) == "midpoint"
    assert default(plugin, "penalty_semi_implicit_euler", builtin("lecture-bouncing-particle")) == (
        "penalty+semi_implicit_euler")
    assert default(plugin, "leapfrog_demo", builtin("wind")) == ""
    assert default(plugin, "damped_least_squares", builtin("iiwa-ik")) == "damped_least_squares"
