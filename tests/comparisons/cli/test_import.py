"""``simparity import FILE`` (issue #45): one line per reader, core's and each engine's importer, on a robot file as
a user has it; exit 2 only when no reader reads it."""

from __future__ import annotations

import os

import pybullet_data

from simparity.comparisons.cli.main import EXIT_OK, EXIT_USAGE, main

READERS = ("core", "mujoco", "pinocchio", "pybullet")
IIWA = os.path.join(pybullet_data.getDataPath(), "kuka_iiwa", "model.urdf")


def _lines(capsys, path: str) -> tuple[int, dict[str, str], str]:
    code = main(["import", path])
    captured = capsys.readouterr()
    said = dict(line.split(": ", 1) for line in captured.out.splitlines())
    return code, said, captured.err


def test_a_file_every_reader_reads(capsys):
    code, said, _ = _lines(capsys, IIWA)
    assert code == EXIT_OK and tuple(said) == READERS
    assert all(line.startswith("reads it") for line in said.values()), said


def test_a_file_only_pybullet_reads_is_not_refused_and_each_refusal_is_one_line(capsys):
    """pybullet_data's bike.urdf writes commas between numbers: core, MuJoCo and Pinocchio refuse it, PyBullet reads
    it (docs/robots.md)."""
    code, said, _ = _lines(capsys, os.path.join(pybullet_data.getDataPath(), "bicycle", "bike.urdf"))
    assert code == EXIT_OK and tuple(said) == READERS
    assert said["core"].startswith("refuses it: robot/joint[@name='handlebar_to_frontwheel']/origin/@xyz")
    assert said["mujoco"].startswith("refuses it") and said["pinocchio"].startswith("refuses it")
    assert said["pybullet"].startswith("reads it")


def test_a_file_no_reader_reads_exits_2_in_one_line(tmp_path, capsys):
    path = tmp_path / "broken.urdf"
    path.write_text('<robot name="r"><link name="a"/><joint name="j" type="revolute"><parent link="a"/>')
    code, said, err = _lines(capsys, str(path))
    assert code == EXIT_USAGE and tuple(said) == READERS
    assert not any(line.startswith("reads it") for line in said.values()), said
    assert err.count("\n") == 1 and "no reader reads this URDF file" in err


def test_what_is_no_robot_file_is_one_line(tmp_path, capsys):
    path = tmp_path / "notes.txt"
    path.write_text("hello")
    assert main(["import", str(path)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a robot file" in err
