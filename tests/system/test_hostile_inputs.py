"""A corpus of hostile and malformed inputs, one or two per class found by the held-out corpus (issue #7).

Every one must end in exit code 2 with exactly one line on stderr that starts ``simparity: error:``,
says what is allowed, holds no traceback, and comes back fast (refused before anything runs).
"""

import os
import random
import time

import pytest

from simparity.comparisons.cli.main import EXIT_USAGE, main
from simparity.core.model.files import MAX_XML_DEPTH
from tests.comparisons.scenes.test_loader import VALID_DYNAMICS, VALID_KINEMATICS
from tests.core.test_urdf import DEEP_URDF, DOCTYPE_URDF

FAST_SECONDS = 20.0
"""A refusal is made on loading: well under the time any run would take (parsing the million-value sweep alone
takes ~4 s on an idle core, 11 s measured beside a run on a loaded 2-core machine)."""

VALID_IK = VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"')

URDF = """<?xml version="1.0" encoding="{encoding}"?>
<robot name="r">
  <link name="base"/><link name="{tip}"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="{tip}"/>
    <axis xyz="0 0 1"/><limit lower="{lower}" upper="{upper}"/></joint>
</robot>
"""


def _urdf_scene(tmp_path, urdf_name="robot.urdf", extra=""):
    return f'[scene]\nname = "u"\nkind = "kinematics"\nreference = "core"\n[chain]\nurdf = "{urdf_name}"\n{extra}'


def _many_joints(n):
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(f'<joint name="j{i}" type="continuous"><parent link="l{i}"/><child link="l{i + 1}"/></joint>'
                     for i in range(n))
    return f'<robot name="r">{links}{joints}</robot>'


SCENES = [
    # name injection into the engines' models
    ("injected end effector", VALID_KINEMATICS.replace("[chain]", '[chain]\nend_effector = \'tip"/><include file="/etc/passwd"/>\'')),
    ("injected body name", VALID_DYNAMICS.replace('name = "ball"', 'name = "ball</body><include file=\\"x\\"/>"')),
    ("name of 50,000 characters", VALID_DYNAMICS.replace('name = "ball"', f'name = "{"b" * 50_000}"')),
    ("newline in a name", VALID_DYNAMICS.replace('name = "ball"', 'name = "ba\\nll"')),
    # numbers outside their physical range
    ("denormal mass", VALID_DYNAMICS.replace("mass = 1.5", "mass = 5e-324")),
    ("huge mass", VALID_DYNAMICS.replace("mass = 1.5", "mass = 1e308")),
    ("huge inertia", VALID_DYNAMICS.replace("[0.1, 0.1, 0.1]", "[1e200, 1e200, 1e200]")),
    ("denormal inertia", VALID_DYNAMICS.replace("[0.1, 0.1, 0.1]", "[1e-300, 1e-300, 1e-300]")),
    ("overflowing full inertia", VALID_DYNAMICS.replace("inertia_body_diagonal = [0.1, 0.1, 0.1]",
                                                        "inertia_body = [[1e308, 1e308, 0], [1e308, 1e308, 0], [0, 0, 1]]")),
    ("huge velocity", VALID_DYNAMICS.replace("velocity_world = [1.0, 0.0, 0.0]", "velocity_world = [1e308, 0, 0]")),
    ("huge gravity", VALID_DYNAMICS.replace("[0.0, 0.0, -9.81]", "[0.0, 0.0, -1e308]")),
    ("huge drag", VALID_DYNAMICS.replace('name = "ball"', 'name = "ball"\nlinear_drag = 1e308')),
    ("tiny quaternion", VALID_DYNAMICS.replace('name = "ball"', 'name = "ball"\nquat_wxyz = [1e-200, 0, 0, 0]')),
    ("huge quaternion", VALID_DYNAMICS.replace('name = "ball"', 'name = "ball"\nquat_wxyz = [1e200, 1e200, 0, 0]')),
    ("tiny joint axis", VALID_KINEMATICS.replace("axis = [0.0, 0.0, 1.0]", "axis = [0.0, 0.0, 1e-200]")),
    ("huge joint axis", VALID_KINEMATICS.replace("axis = [0.0, 0.0, 1.0]", "axis = [1e200, 1e200, 1e200]")),
    ("joint limits of 1e308", VALID_KINEMATICS.replace("lower = -1.0\nupper = 1.0", "lower = -1e308\nupper = 1e308")),
    ("denormal dt", VALID_DYNAMICS.replace("dt = [0.01]", "dt = [5e-324]")),
    ("dt longer than the duration", VALID_DYNAMICS.replace("dt = [0.01]", "dt = [0.01, 2.0]")),
    ("duplicated dt", VALID_DYNAMICS.replace("dt = [0.01]", "dt = [0.01, 0.01]")),
    ("IK tolerance of 1e308", VALID_IK.replace("[chain]", "[targets]\nposition_tolerance = 1e308\n[chain]")),
    ("IK orientation tolerance of a turn", VALID_IK.replace("[chain]", "[targets]\norientation_tolerance = 6.3\n[chain]")),
    # resource bombs, refused before running
    ("1e9 steps", VALID_DYNAMICS.replace("duration = 1.0\ndt = [0.01]", "duration = 1e6\ndt = [0.001]")),
    ("a ladder of 1,000 time steps", VALID_DYNAMICS.replace(
        "duration = 1.0\ndt = [0.01]", "duration = 1.0\nrate_hz = [" + ", ".join(str(k) for k in range(1, 1001)) + "]")),
    ("20,000 bodies", VALID_DYNAMICS + "".join(
        f'\n[[body]]\nname = "b{i}"\nmass = 1.0\ninertia_body_diagonal = [1.0, 1.0, 1.0]\n' for i in range(20_000))),
    ("1e9 configurations", VALID_KINEMATICS.replace("[chain]", "[sampling]\nconfigurations = 1000000000\n[chain]")),
    ("1e6 IK targets", VALID_IK.replace("[chain]", "[targets]\ncount = 1000000\n[chain]")),
    ("1e12 IK iterations", VALID_IK.replace("[chain]", "[targets]\nmax_iterations = 1000000000000\n[chain]")),
    ("deeply nested arrays", VALID_DYNAMICS.replace("dt = [0.01]", "dt = " + "[" * 5000 + "]" * 5000)),
    ("deeply nested inline tables", VALID_DYNAMICS + "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n"),
    # sweeps (issue #12): a bad [sweep] table, or a variant the loader refuses
    ("sweep of a key the file does not set", VALID_DYNAMICS + '[sweep]\n"body[ball].colour" = [1.0]\n'),
    ("sweep of the scene name", VALID_DYNAMICS + '[sweep]\n"scene.name" = [1.0]\n'),
    ("sweep of a text key", VALID_DYNAMICS + '[sweep]\n"body[ball].name" = [1.0]\n'),
    ("sweep of a whole vector", VALID_DYNAMICS + '[sweep]\n"body[ball].velocity_world" = [1.0]\n'),
    ("sweep of an empty list", VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = []\n'),
    ("sweep range without num", VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = {start = 1.0, stop = 2.0}\n'),
    ("sweep log range through zero", VALID_DYNAMICS
     + '[sweep]\n"body[ball].mass" = {start = -1.0, stop = 2.0, num = 3, spacing = "log"}\n'),
    ("swept value outside its range", VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [1.5, 1e308]\n'),
    ("swept seed not whole", VALID_IK + '[sweep]\n"targets.seed" = [1.5]\n'.replace("[sweep]", "[targets]\nseed = 0\n[sweep]")),
    ("sweep of 10,000 variants", VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = {start = 1.0, stop = 2.0, num = 100}\n'
     '"world.gravity_world[2]" = {start = -9.0, stop = -10.0, num = 100}\n'),
    ("sweep of a 400-digit number", VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [1' + "0" * 400 + "]\n"),
    ("sweep key unquoted", VALID_DYNAMICS + "[sweep]\nbody.mass = [1.0]\n"),
    ("sweep key with a newline", VALID_DYNAMICS + '[sweep]\n"body[ball].ma\\nss" = [1.0]\n'),
    ("sweep that is not a table", "sweep = 3\n" + VALID_DYNAMICS),
    ("sweep of a million values", VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [' + ", ".join(["1.0"] * 1_000_000) + "]\n"),
    # references that cannot serve the scene
    ("analytic reference for a point force", VALID_DYNAMICS.replace(
        'name = "ball"', 'name = "ball"\n[[body.force]]\nforce_world = [0.0, 1.0, 0.0]\npoint_body = [0.1, 0.0, 0.0]')),
    ("tight reference for kinematics", VALID_KINEMATICS.replace('reference = "core"', 'reference = "tight"')),
]


def _refused(capsys, argv):
    start = time.perf_counter()
    code = main(argv)
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err
    assert code == EXIT_USAGE, err
    assert err.startswith("simparity: error: ") and err.count("\n") == 1, err[:500]
    assert "(allowed: " in err and "Traceback" not in err and len(err) <= 1100
    assert elapsed < FAST_SECONDS
    return err


@pytest.mark.parametrize("text", [pytest.param(t, marks=pytest.mark.slow)
                                  if n in ("20,000 bodies", "sweep of a million values") else t for n, t in SCENES],
                         ids=[n for n, _ in SCENES])
def test_hostile_scene_is_refused_on_one_line(tmp_path, capsys, text):
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    _refused(capsys, ["run", str(path), "--out", str(tmp_path / "out")])
    assert not (tmp_path / "out").exists()


def test_injected_names_are_refused_for_their_characters(tmp_path, capsys):
    path = tmp_path / "scene.toml"
    path.write_text(SCENES[0][1], encoding="utf-8")
    err = _refused(capsys, ["export", str(path), "--engine", "mujoco"])
    assert "chain.end_effector" in err and "outside the allowed set" in err and "passwd" in err  # echoed, not read


@pytest.mark.parametrize("name, raw", [
    ("BOM", b"\xef\xbb\xbf" + VALID_DYNAMICS.encode()),
    ("Latin-1 scene", VALID_DYNAMICS.replace("ball", "b\xe4ll").encode("latin-1")),
    ("TOML syntax error", b"[scene\nname = 1\n"),
])
def test_encodings_and_syntax_give_a_position(tmp_path, capsys, name, raw):
    path = tmp_path / "scene.toml"
    path.write_bytes(raw)
    err = _refused(capsys, ["run", str(path), "--out", str(tmp_path / "out")])
    assert ": line " in err
    assert name != "BOM" or "byte-order mark (BOM)" in err


@pytest.mark.parametrize("encoding, codec", [("ISO-8859-1", "latin-1"), ("UTF-16", "utf-16")])
def test_urdf_in_another_declared_encoding_loads(tmp_path, capsys, encoding, codec):
    """A URDF declared Latin-1 or UTF-16 is read in its encoding (it used to crash 'export')."""
    (tmp_path / "robot.urdf").write_bytes(URDF.format(encoding=encoding, tip="tip", lower=-1, upper=1).encode(codec))
    (tmp_path / "scene.toml").write_text(_urdf_scene(tmp_path), encoding="utf-8")
    assert main(["export", str(tmp_path / "scene.toml"), "--engine", "pybullet"]) == 0
    assert "<robot" in capsys.readouterr().out


@pytest.mark.parametrize("name, urdf, extra, words", [
    ("URDF joint with lower above upper", URDF.format(encoding="UTF-8", tip="tip", lower=1, upper=0), "",
     "above upper"),
    ("URDF tip name injected", URDF.format(encoding="UTF-8", tip="ti&quot;p", lower=-1, upper=1), "",
     "outside the allowed set"),
    ("URDF of 1,000 joints", _many_joints(1000), "", "1,000 movable joints"),
    ("URDF not XML", "<robot", "", "not well-formed"),
])
def test_bad_urdf_names_the_scene_and_the_element(tmp_path, capsys, name, urdf, extra, words):
    (tmp_path / "robot.urdf").write_text(urdf, encoding="utf-8")
    (tmp_path / "scene.toml").write_text(_urdf_scene(tmp_path, extra=extra), encoding="utf-8")
    err = _refused(capsys, ["run", str(tmp_path / "scene.toml"), "--out", str(tmp_path / "out")])
    assert str(tmp_path / "scene.toml") in err and "chain.urdf" in err and "robot.urdf" in err and words in err


@pytest.mark.parametrize("name, urdf, words", [(n, t, "<!DOCTYPE robot>: a document type declaration")
                                                for n, t in DOCTYPE_URDF]
                         + [(n, t, f"<a> at depth {MAX_XML_DEPTH + 1}: elements nested more than") for n, t in DEEP_URDF],
                         ids=[n for n, _ in DOCTYPE_URDF + DEEP_URDF])
def test_export_of_a_doctype_or_deeply_nested_urdf_is_one_line(tmp_path, capsys, name, urdf, words):
    """Issue #25: 'simparity export' of a URDF nested 1,000 deep used to end in a RecursionError traceback; a
    DOCTYPE (entities internal, parameter or external, a billion laughs) is refused before it is read."""
    (tmp_path / "robot.urdf").write_text(urdf, encoding="utf-8")
    (tmp_path / "scene.toml").write_text(_urdf_scene(tmp_path), encoding="utf-8")
    err = _refused(capsys, ["export", str(tmp_path / "scene.toml"), "--engine", "mujoco"])
    assert f"{tmp_path / 'scene.toml'}: chain.urdf: robot.urdf: {words}" in err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_is_never_opened(tmp_path, capsys):
    """A scene or URDF that is a FIFO would block forever if opened: refused as not a regular file."""
    os.mkfifo(tmp_path / "robot.urdf")
    (tmp_path / "scene.toml").write_text(_urdf_scene(tmp_path), encoding="utf-8")
    _refused(capsys, ["run", str(tmp_path / "scene.toml"), "--out", str(tmp_path / "out")])
    os.mkfifo(tmp_path / "fifo.toml")
    _refused(capsys, ["run", str(tmp_path / "fifo.toml"), "--out", str(tmp_path / "out")])


@pytest.mark.parametrize("argv", [
    ["run", "x" * 5000 + ".toml"],
    ["run", "/dev/zero"],
    ["run", "bad\nname.toml"],
    ["run", "lecture-projectile", "--max-steps", "0"],
    ["run", "lecture-projectile", "--jobs", "0"],
    ["export", "lecture-projectile", "--engine", "mujoco", "--dt", "inf"],
    ["check", "/no/such/run"],
])
def test_hostile_arguments_are_refused_on_one_line(tmp_path, capsys, argv):
    _refused(capsys, argv)


def test_limits_can_be_raised_for_a_big_honest_run(tmp_path, capsys):
    """--max-steps lifts the step limit the message points at."""
    path = tmp_path / "scene.toml"
    path.write_text(VALID_DYNAMICS.replace("duration = 1.0\ndt = [0.01]", "duration = 30000.0\ndt = [0.01]"),
                    encoding="utf-8")
    err = _refused(capsys, ["run", str(path), "--out", str(tmp_path / "out")])
    assert "--max-steps" in err


FUZZ_CASES = 300
"""Random [sweep] tables tried by the fuzz test: every kind of key and value below, several times over."""
FUZZ_KEYS = ["body[ball].mass", "body[0].velocity_world[1]", "body[ball]", "body[x].mass", "body[9].mass", "scene.kind",
             "simulation.dt", "simulation.dt[5]", "simulation.duration", "world.gravity_world[2]", "world", "combine",
             "targets.seed", "..", "body[ball].mass[0]", "body[ball].velocity_world[-1]", "\u00e9", "a" * 300]
FUZZ_VALUES = [[], [1.0], [0.5, 2.0], [1.0, 1.0], ["a"], [True], [[1.0]], [{}], 1.0, "x", {}, {"start": 1.0},
               {"start": 1.0, "stop": 2.0, "num": 3}, {"start": 1.0, "stop": 2.0, "num": 0},
               {"start": 0.0, "stop": 2.0, "num": 3, "spacing": "log"}, {"start": 1.0, "stop": 1.0, "num": 2},
               {"start": 1.0, "stop": 2.0, "num": 3, "spacing": 7}, {"stop": [1], "num": 2, "x": None},
               [float("nan")], [-1e300, 1e300], [10**30], list(range(200)), "zip"]


def test_fuzzed_sweep_tables_load_or_are_refused_on_one_line():
    """Seeded random [sweep] tables over valid and broken keys and values: each loads, or raises SceneError with
    one line that says what is allowed; nothing else escapes (no traceback in the CLI)."""
    from simparity.comparisons.scenes.loading.scene_file import parse_scenes
    from simparity.core.model.errors import SceneError
    from simparity.core.model.files import tomllib

    rng = random.Random(12)
    base = tomllib.loads(VALID_DYNAMICS)
    refused = 0
    for _ in range(FUZZ_CASES):
        keys = rng.sample(FUZZ_KEYS, rng.randint(0, 3))
        data = dict(base, sweep={key: rng.choice(FUZZ_VALUES) for key in keys})
        try:
            parse_scenes(data, "fuzz.toml")
        except SceneError as err:
            refused += 1
            text = str(err)
            assert text.startswith("fuzz.toml: sweep") and "\n" not in text and "(allowed: " in text, text
    assert 0 < refused < FUZZ_CASES   # both outcomes drawn
