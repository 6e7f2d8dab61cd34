"""Issue #42: the planted bugs of time-varying loads are caught naming the engine, and a faithful copy of core
passes, under every metamorphic transform (a time-unit rescale rescales the loads' frequencies and periods)."""

from __future__ import annotations

import compileall
import sys

import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.invariance.transforms import TRANSFORM_NAMES
from tests.mutation.catalogue import MUTANTS
from tests.mutation.copy_of_core import materialise

FORCED_MUTANTS = ("stage_time_at_step_start", "hold_one_period_late", "sinusoid_phase_in_degrees")
"""The three bugs issue #42 names: an RK stage at the step's start time, a hold one period late, a phase in
degrees."""

PUSHED_AND_PULSED = """
[scene]
name = "pushed-and-pulsed"
kind = "dynamics"
reference = "analytic"
[[body]]
name = "puck"
mass = 0.8
inertia_body_diagonal = [0.02, 0.03, 0.04]
velocity_world = [0.5, 0.0, 0.0]
[[body.load]]
frame = "world"
[body.load.force]
function = "smooth"
polynomial = [[0.0, 0.3, 0.0]]
[[body.load.force.sinusoid]]
amplitude = [1.5, 0.0, 0.4]
frequency_hz = 1.25
phase_rad = 0.7
[[body.load]]
frame = "body"
[body.load.torque]
function = "held"
period = 0.2
samples = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.4], [0.0, 0.0, -0.1], [0.0, 0.0, 0.0]]
[[body]]
name = "disc"
mass = 0.5
inertia_body_diagonal = [0.01, 0.01, 0.02]
position_world = [1.0, 0.0, 0.0]
[[body.load]]
frame = "world"
[body.load.force]
function = "smooth"
[[body.load.force.sinusoid]]
amplitude = [0.0, 0.8, 0.0]
frequency_hz = 2.0
phase_rad = 1.1
[simulation]
duration = 0.8
dt = [0.04, 0.02, 0.01]
integrators = ["rk4", "midpoint", "semi_implicit_euler"]
"""
"""Two bodies (so that permute reorders them) under a smooth world force with a phase, and a held body-axes torque
about a principal axis whose samples fall on every step's grid: a closed form for both, every scheme at its order
in a faithful engine, and each of the three bugs a wrong load."""


def _gate(tmp_path, monkeypatch, capsys, transforms: tuple[str, ...]) -> None:
    """The gate on the scene with core, a faithful copy and the three mutants (under ``transforms``): each mutant
    named by a violation of an order or an error, nothing else."""
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")  # the probes and workers import the copies
    mutants = [materialise(m, tmp_path) for m in MUTANTS if m.id in FORCED_MUTANTS]
    faithful = materialise(None, tmp_path)
    compileall.compile_dir(tmp_path, quiet=1)
    scene = tmp_path / "pushed-and-pulsed.toml"
    scene.write_text(PUSHED_AND_PULSED, encoding="utf-8")
    engines = ",".join(["core", faithful.spec] + [m.spec for m in mutants])
    transform = ["--transform", ",".join(transforms)] if transforms else []
    code = main(["run", str(scene), "--quick", "--check", "--engines", engines, *transform,
                 "--out", str(tmp_path / "run"), "--history", str(tmp_path / "h.db"), "--no-report"])
    violations = [line for line in capsys.readouterr().out.splitlines() if line.startswith("violation: ")]
    named = {line.split()[2] for line in violations}  # "violation: scene engine ..."
    assert code == 1
    assert named == {m.engine_name for m in mutants}, "each mutant named, nothing else (core, the faithful copy)"
    for mutant in mutants:
        own = [line for line in violations if line.split()[2] == mutant.engine_name]
        assert any("order_" in line or "error" in line for line in own), (mutant.engine_name, own[:3])


@pytest.mark.slow
def test_the_forcing_mutants_are_caught_and_a_faithful_copy_passes(tmp_path, monkeypatch, capsys):
    _gate(tmp_path, monkeypatch, capsys, ())


@pytest.mark.slow
@pytest.mark.sweep
def test_the_forcing_mutants_are_caught_and_a_faithful_copy_passes_under_every_transform(tmp_path, monkeypatch,
                                                                                         capsys):
    _gate(tmp_path, monkeypatch, capsys, TRANSFORM_NAMES)
