"""Issue #43's held-out check of model parity through the gate: a user's engine whose importer reads every joint
axis with the wrong sign, or its limits in degrees (a planted bug in its adapter; its dynamics are core's, right), is
caught by the model rows, naming it, and the built-in engines pass beside it."""

from __future__ import annotations

import sys

import pytest

from simparity.comparisons.cli.main import main

PLANTED_ADAPTER = '''
from dataclasses import replace

from simparity.core.inhouse import InHouseEngine


class FlippedAxes(InHouseEngine):
    """Core's joint dynamics, reporting every joint axis with the wrong sign (an importer's sign error)."""

    name = "flipped-axes"

    def build_joint_dynamics(self, chain, method, gravity_world):
        model = super().build_joint_dynamics(chain, method, gravity_world)
        honest = model.rigid_groups

        def flipped(q):
            groups = honest(q)
            return replace(groups, axis_world=-groups.axis_world)

        model.rigid_groups = flipped
        return model
'''


@pytest.mark.slow
def test_an_importer_s_flipped_axes_are_caught_naming_the_engine(tmp_path, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")  # the probes and workers import it
    (tmp_path / "planted_importer.py").write_text(PLANTED_ADAPTER, encoding="utf-8")
    code = main(["run", "oblique-arm-dynamics", "--quick", "--check", "--engines",
                 "core,mujoco,pybullet,pinocchio,planted_importer:FlippedAxes", "--out", str(tmp_path / "run"),
                 "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    violations = [line for line in capsys.readouterr().out.splitlines() if line.startswith("violation: ")]
    assert code == 1
    assert {line.split()[2] for line in violations} == {"flipped-axes"}
    assert all("model_axis_error_max" in line for line in violations), violations
    assert any("3.14" in line for line in violations), violations


NAN_REPORT = PLANTED_ADAPTER.replace("FlippedAxes", "NanMasses").replace('"flipped-axes"', '"nan-masses"').replace(
    "return replace(groups, axis_world=-groups.axis_world)", "return replace(groups, mass=groups.mass * float('nan'))")


@pytest.mark.slow
def test_a_compiled_model_with_nan_fails_its_rows_instead_of_passing_as_n_a(tmp_path, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")
    (tmp_path / "nan_importer.py").write_text(NAN_REPORT, encoding="utf-8")
    code = main(["run", "oblique-arm-dynamics", "--quick", "--check", "--engines", "core,nan_importer:NanMasses",
                 "--out", str(tmp_path / "run"), "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    out = capsys.readouterr().out
    assert code == 1 and "nan-masses" in out and "non-finite mass" in out, out[-1500:]



DEGREE_LIMITS = PLANTED_ADAPTER.replace("FlippedAxes", "DegreeLimits").replace('"flipped-axes"', '"degree-limits"').replace(
    "model.rigid_groups", "model.compiled_joints").replace("def flipped(q):\n            groups = honest(q)", (
        "def flipped():\n            groups = honest()")).replace(
    "return replace(groups, axis_world=-groups.axis_world)",
    "return replace(groups, lower=groups.lower * 57.29577951308232, upper=groups.upper * 57.29577951308232)")


@pytest.mark.slow
def test_an_importer_s_limits_in_degrees_are_caught_naming_the_engine(tmp_path, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")
    (tmp_path / "degree_importer.py").write_text(DEGREE_LIMITS, encoding="utf-8")
    code = main(["run", "oblique-arm-dynamics", "--quick", "--check", "--engines",
                 "core,mujoco,pybullet,pinocchio,degree_importer:DegreeLimits", "--out", str(tmp_path / "run"),
                 "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    violations = [line for line in capsys.readouterr().out.splitlines() if line.startswith("violation: ")]
    assert code == 1
    assert {line.split()[2] for line in violations} == {"degree-limits"}
    assert all("model_limit_mismatches" in line for line in violations), violations
