"""Issue #38 section 3: a plugin engine under ``--transform`` gets the verdicts a built-in gets.

A user's engine is described once, in a probe process, about the run's own scenes; the transformed and the one-ulp
perturbed scenes an invariance check makes later were unknown to its description, so every case of a plugin in
them failed ("was not asked about scene ... (a harness bug)") and its invariance rows became status changes and
missing rows: even a faithful copy of core failed the gate under every transform.
"""

from __future__ import annotations

import compileall
import sys

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.engines.probe import DescribedEngine, EngineProbes, asked_about
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.invariance.metamorphic import CHANGES_METRIC, RATIO_METRIC
from simparity.comparisons.invariance.perturb import ulp_perturbed
from simparity.comparisons.invariance.transforms import FIXED_TRANSFORMS, TRANSFORM_NAMES, transform_scene
from simparity.core.inhouse import InHouseEngine
from simparity.core.model.errors import PluginError
from tests.comparisons.engines.probe_spy import spy_probes
from tests.helpers import builtin
from tests.mutation.catalogue import MUTANTS
from tests.mutation.copy_of_core import FAITHFUL_NAME, materialise

CORE_SPEC = "simparity.core.inhouse:InHouseEngine"
"""Core named by its spec: described in a probe like any user's engine."""

TWO_LEAVES = """
[scene]
name = "two-leaves"
kind = "dynamics"
reference = "analytic"
[world]
gravity_world = [0.0, 0.0, -9.81]
air_velocity_world = [4.0, 1.0, 0.0]
[[body]]
name = "leaf"
mass = 1.0
inertia_body_diagonal = [0.01, 0.02, 0.03]
velocity_world = [1.0, 0.0, 5.0]
angular_velocity_world = [0.5, 1.0, 0.0]
linear_drag = 0.5
[[body]]
name = "twig"
mass = 0.5
inertia_body_diagonal = [0.02, 0.01, 0.01]
position_world = [1.0, 0.0, 0.0]
velocity_world = [0.0, 2.0, 4.0]
linear_drag = 0.2
[simulation]
duration = 1.0
dt = [0.04, 0.02, 0.01]
integrators = ["rk4", "semi_implicit_euler"]
"""
"""Two bodies thrown into wind with linear drag (a closed form), turning: every fixed transform applies (permute
needs two bodies), RK4 is not exact (its order is measured) and a few cases keep the runs short."""

RK4_MUTANT = next(m for m in MUTANTS if m.id == "rk4_weights")
"""A planted bug the order bounds catch on any free body in wind (RK4 with equal weights: second order)."""


@pytest.mark.slow
def test_a_described_engine_is_asked_about_scenes_made_after_it_was_described():
    scene = builtin("lecture-projectile")
    probes = EngineProbes()
    described = probes.describe([CORE_SPEC], [scene])[CORE_SPEC]
    assert isinstance(described, DescribedEngine)
    later = [transform_scene(scene, t) for t in FIXED_TRANSFORMS if t.name in ("translate", "rescale")]
    later.append(ulp_perturbed(scene, 1)[0])
    for other in later:  # before: the run's own scenes only, "a harness bug" for any other
        with pytest.raises(PluginError, match="was not asked about scene"):
            described.scene_integrators(other)
    core = make_engine("core")
    again = asked_about([core, described], later, {described.name: CORE_SPEC}, probes)  # its kept probe
    assert again[0] is core  # a built-in is built here: nothing to ask
    real = InHouseEngine()
    for other in later + [scene]:
        assert again[1].scene_integrators(other) == real.scene_integrators(other)
    assert asked_about(again, later, {described.name: CORE_SPEC}, probes)[1] is again[1]  # nothing new: no probe
    probes.close()


@pytest.mark.slow
def test_a_faithful_plugin_passes_and_a_planted_bug_fails_under_every_transform(tmp_path, monkeypatch, capsys):
    """Before: 'no such row in the transformed run' for every plugin row, the faithful copy red under every
    transform. After: the faithful copy's invariance rows are those of core, and the planted bug is still caught by
    the bounds that catch it without a transform."""
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")  # the probes and workers import the copies
    faithful, mutant = materialise(None, tmp_path), materialise(RK4_MUTANT, tmp_path)
    # compiled once here: each probe and worker importing the copies (two probes and a worker) would compile them
    # anew where PYTHONDONTWRITEBYTECODE is set (~0.6 CPU-s a process)
    compileall.compile_dir(tmp_path, quiet=1)
    probes = spy_probes(monkeypatch).started
    scene = tmp_path / "two-leaves.toml"
    scene.write_text(TWO_LEAVES, encoding="utf-8")
    out = tmp_path / "run"
    code = main(["run", str(scene), "--quick", "--check", "--engines", f"core,{faithful.spec},{mutant.spec}",
                 "--transform", ",".join(TRANSFORM_NAMES), "--out", str(out), "--history", str(tmp_path / "h.db"),
                 "--no-report", "--jobs", "1"])  # what is read: the verdicts printed and results.csv
    # before: each plugin probed anew for each question (what it offers, the run's scenes, the transformed ones...)
    assert probes == {faithful.spec: 1, mutant.spec: 1}, "one probe per engine, asked again"
    lines = capsys.readouterr().out.splitlines()
    violations = [line for line in lines if line.startswith("violation: ")]
    assert code == 1 and violations
    assert {line.split()[2] for line in violations} == {mutant.engine_name}  # "violation: scene engine ..."
    table = pd.read_csv(out / "results.csv", keep_default_na=False)
    assert not table.detail.str.contains("no such row|was not asked about", regex=True).any()
    for name in TRANSFORM_NAMES:
        for engine in ("core", FAITHFUL_NAME, mutant.engine_name):
            rows = table[(table.engine == engine) & (table.metric == CHANGES_METRIC + name)]
            assert len(rows) and (rows.status == "ok").all() and (rows.value.astype(float) == 0).all(), (engine, name)
            ratio = table[(table.engine == engine) & (table.metric == RATIO_METRIC + name)]
            assert (ratio.status == "ok").any() and (ratio[ratio.status == "ok"].value.astype(float) <= 1).all()
    caught = {line for line in violations if "order_" in line}
    assert caught, "the planted bug is caught by its order, whatever the transform"
