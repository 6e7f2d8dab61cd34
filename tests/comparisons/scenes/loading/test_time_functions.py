"""Loads that change with time in a scene file (issue #42): a body's ``[[body.load]]`` and a chain's
``[drive.timed_torque]`` read into the scene model in SI units, and every bad input (a negative control period, an
unknown time function, NaN coefficients, ...) refused in one line naming the key, exit 2 through the CLI."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from simparity.comparisons.cli.main import EXIT_USAGE, main
from simparity.comparisons.scenes.loading.scene_file import load_scene
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.time_functions import HeldFunction, SmoothFunction

BODY = """
[scene]
name = "pushed"
kind = "dynamics"
reference = "tight"
{head}
[[body]]
name = "box"
mass = 1.0
inertia_body_diagonal = [0.1, 0.2, 0.3]

[[body.load]]
frame = "body"
point_body = [0.1, 0.0, 0.0]

[body.load.force]
function = "smooth"
polynomial = [[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]]

[[body.load.force.sinusoid]]
amplitude = [0.0, 2.0, 0.0]
frequency_hz = 3.0
phase_rad = 0.25

[body.load.torque]
function = "held"
period = 0.05
phase = 0.01
samples = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]

[simulation]
duration = 1.0
dt = [0.01]
"""

JOINT = """
[scene]
name = "driven"
kind = "joint_motion"
reference = "analytic"

[chain]
end_effector = "tip"
end_effector_xyz = [1.0, 0.0, 0.0]

[[chain.joint]]
name = "hinge"
type = "revolute"
axis = [0.0, 0.0, 1.0]
mass = 1.0
com_xyz = [0.5, 0.0, 0.0]
inertia = [[1e-4, 0.0, 0.0], [0.0, 0.08, 0.0], [0.0, 0.0, 0.08]]

[drive.timed_torque]
function = "held"
period = 0.1
samples = [[0.5], [-0.5]]

[simulation]
duration = 1.0
dt = [0.01]
"""


def _write(tmp_path, text: str):
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_body_s_loads_are_read_in_si_units(tmp_path):
    """In centimetres a force's polynomial and amplitudes (N = kg m / s^2) scale by 0.01, a torque's samples (N m) by
    1e-4, the point by 0.01; times, frequencies and phases do not scale."""
    metres = load_scene(_write(tmp_path, BODY.format(head="")))
    centimetres = load_scene(_write(tmp_path, BODY.format(head='length_unit = "cm"')))
    load, small = metres.forces.timed[0], centimetres.forces.timed[0]
    assert load.frame == "body" and load.body == 0 and metres.forces.names() == ("timed_load",)
    assert isinstance(load.force, SmoothFunction) and isinstance(load.torque, HeldFunction)
    np.testing.assert_array_equal(load.force.polynomial, [[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]])
    assert (load.force.sinusoids[0].frequency_hz, load.force.sinusoids[0].phase_rad) == (3.0, 0.25)
    assert (load.torque.period_s, load.torque.phase_s) == (0.05, 0.01)
    np.testing.assert_allclose(small.force.polynomial, 0.01 * load.force.polynomial, rtol=1e-15)
    np.testing.assert_allclose(small.force.sinusoids[0].amplitude, 0.01 * load.force.sinusoids[0].amplitude, rtol=1e-15)
    np.testing.assert_allclose(small.torque.samples, 1e-4 * load.torque.samples, rtol=1e-15)
    np.testing.assert_allclose(small.point_body, 0.01 * load.point_body, rtol=1e-15)
    assert (small.torque.period_s, small.force.sinusoids[0].frequency_hz) == (0.05, 3.0)


def test_self_consistency_segments_and_a_timed_torque_are_refused_together(tmp_path):
    """Each segment is stepped from t = 0: a torque that changes with time would restart in every one."""
    with pytest.raises(SceneError, match=r"simulation\.segments: 2 segments with a timed torque"):
        load_scene(_write(tmp_path, JOINT.replace("dt = [0.01]", "dt = [0.01]\nsegments = 2")))


def test_a_chain_s_timed_torque_has_one_component_per_joint(tmp_path):
    scene = load_scene(_write(tmp_path, JOINT))
    assert isinstance(scene.timed_torque, HeldFunction)
    np.testing.assert_array_equal(scene.timed_torque.samples, [[0.5], [-0.5]])
    with pytest.raises(SceneError, match=r"drive\.timed_torque\.samples\[0\].*expected a list of 1 numbers"):
        load_scene(_write(tmp_path, JOINT.replace("[[0.5], [-0.5]]", "[[0.5, 1.0], [-0.5, 1.0]]")))


BAD_BODY = [
    ("period = 0.05", "period = -0.05", "body[0].load[0].torque.period", "not positive"),
    ("period = 0.05", "period = 0.0", "body[0].load[0].torque.period", "not positive"),
    ("phase = 0.01", "phase = 0.05", "body[0].load[0].torque.phase", "not within the first control period"),
    ('function = "held"', 'function = "ramp"', "body[0].load[0].torque.function", "'ramp' is not allowed"),
    ("[[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]]", "[[0.0, 0.0, nan], [0.5, 0.0, 0.0]]",
     "body[0].load[0].force.polynomial[0][2]", "not finite"),
    ("amplitude = [0.0, 2.0, 0.0]", "amplitude = [0.0, inf, 0.0]", "force.sinusoid[0].amplitude[1]", "not finite"),
    ("frequency_hz = 3.0", "frequency_hz = -3.0", "force.sinusoid[0].frequency_hz", "negative"),
    ("phase_rad = 0.25", "phase_rad = nan", "force.sinusoid[0].phase_rad", "not finite"),
    ("[[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]", "[[0.0, 0.0, 1.0], [0.0, -1.0]]", "torque.samples[1]",
     "expected a list of 3 numbers"),
    ("[[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]", "[[0.0, 0.0, 1e300]]", "torque.samples[0][2]", "outside the physical range"),
    ('frame = "body"', 'frame = "joint"', "body[0].load[0].frame", "'joint' is not allowed"),
    ("period = 0.05", "period = 0.05\npolynomial = [[1.0, 0.0, 0.0]]", "torque.polynomial",
     "not a key of a held function"),
]


@pytest.mark.parametrize("good, bad, key, words", BAD_BODY, ids=[c[1][:24] for c in BAD_BODY])
def test_a_bad_load_is_refused_in_one_line_naming_its_key(tmp_path, capsys, good, bad, key, words):
    text = BODY.format(head="")
    assert good in text
    path = _write(tmp_path, text.replace(good, bad, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SceneError) as caught:
            load_scene(path)
    message = str(caught.value)
    assert key in message and words in message and "\n" not in message and "(allowed: " in message, message
    code = main(["show", str(path)])
    err = capsys.readouterr().err
    assert code == EXIT_USAGE and err.startswith("simparity: error: ") and err.count("\n") == 1, err


def test_a_load_with_nothing_in_it_or_on_a_scene_with_contact_is_refused(tmp_path):
    empty = BODY.format(head="").split("[body.load.force]")[0] + "[simulation]\nduration = 1.0\ndt = [0.01]\n"
    with pytest.raises(SceneError, match=r"body\[0\]\.load\[0\]\.force: a load with neither a force nor a torque"):
        load_scene(_write(tmp_path, empty))
    smooth = BODY.format(head="").replace('function = "smooth"\npolynomial = [[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]]\n',
                                          'function = "smooth"\n').split("[[body.load.force.sinusoid]]")[0]
    with pytest.raises(SceneError, match="neither a polynomial nor a sinusoid"):
        load_scene(_write(tmp_path, smooth + "[simulation]\nduration = 1.0\ndt = [0.01]\n"))
    plane = BODY.format(head="").replace("[simulation]", '[[plane]]\nname = "floor"\ncoefficients = [0.0, 0.0, 1.0, '
                                         '0.0]\n\n[contact]\nmethods = ["backup"]\nrestitution = 0.5\n\n[simulation]')
    with pytest.raises(SceneError, match="body\\[0\\]\\.load: a load that changes with time on a scene with contact"):
        load_scene(_write(tmp_path, plane))


def test_a_load_that_outgrows_its_range_over_the_run_is_refused(tmp_path):
    """Each coefficient in range, the whole polynomial not: c_15 = 1e11 over 100 s reaches 1e41 N, which no engine
    steps (a held-out run's tight solve never finished); refused naming the load, as a constant force of that size is."""
    text = BODY.format(head="").replace("polynomial = [[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]]",
                                        "polynomial = " + str([[0.0, 0.0, 0.0]] * 15 + [[0.0, 0.0, 1e11]]))
    assert load_scene(_write(tmp_path, text)).forces.timed  # over 1 s: at most 1e11 N
    with pytest.raises(SceneError, match=r"body\[0\]\.load\[0\]\.force: reaches 1e\+41 over the run's 100 s"):
        load_scene(_write(tmp_path, text.replace("duration = 1.0", "duration = 100.0")))
    with pytest.raises(SceneError, match=r"drive\.timed_torque\.samples\[1\]\[0\]: -5e\+14 is outside the physical"):
        load_scene(_write(tmp_path, JOINT.replace("samples = [[0.5], [-0.5]]", "samples = [[0.5], [-5e14]]")))
    grown = JOINT.replace('function = "held"\nperiod = 0.1\nsamples = [[0.5], [-0.5]]',
                          'function = "smooth"\npolynomial = ' + str([[0.0]] * 15 + [[1e11]]))
    with pytest.raises(SceneError, match=r"drive\.timed_torque: reaches 1e\+41 over the run's 100 s"):
        load_scene(_write(tmp_path, grown.replace("duration = 1.0", "duration = 100.0")))
