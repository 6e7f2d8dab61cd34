"""Issue #29: sweeps of a thousand variants. A file expands into 1,000 variants; the client lets go of every scene's
cases once its rows are handed back (its memory bounded by the scenes still running, not by the run); a sweep killed
midway and resumed stores the results of an uninterrupted run; the 1,000-variant run on a local Dask cluster does
so too (marked sweep: minutes)."""

from __future__ import annotations

import gc
import subprocess
import sys
import weakref

import pytest

from simparity.comparisons.bench.sweep import SPEEDS, sweep_scene
from simparity.comparisons.cli.main import main
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.execution import run_scenes
from simparity.comparisons.execute.timing import PeakMemory
from simparity.comparisons.scenes import library
from simparity.comparisons.scenes.sweep import MAX_VARIANTS
from tests.helpers import InProcess, killed_and_resumed
from tests.same_results import differences

CASES_PER_VARIANT = 2
"""sweep_scene's cases per variant on core alone: RK4 and semi-implicit Euler at its one time step."""
KILL_WAIT_SECONDS = 600
"""How long a test waits for half the cases of its run to be kept before it gives up."""
CLIENT_PEAK_MIB = 1024
"""[MiB] What the client of the 1,000-variant run may hold at its peak, report included (measured: about 300 MiB,
the imports and the LocalCluster's scheduler; the bench's sweep rows)."""


def _scene(tmp_path, variants: int):
    path = tmp_path / f"throw-{variants}.toml"
    path.write_text(sweep_scene(variants), encoding="utf-8")
    return path


def test_a_file_expands_into_a_thousand_variants(tmp_path):
    variants = library.load([str(_scene(tmp_path, MAX_VARIANTS))])
    assert len(variants) == MAX_VARIANTS == 1000 and len({v.name for v in variants}) == MAX_VARIANTS
    assert [v.sweep.index for v in variants] == list(range(MAX_VARIANTS))


class _Watched(InProcess):
    """This process's executor, keeping a weak reference to every outcome it hands back."""

    def __init__(self) -> None:
        super().__init__()
        self.outcomes: list[weakref.ref] = []

    def run(self, jobs):
        for key, index, outcome in super().run(jobs):
            self.outcomes.append(weakref.ref(outcome))
            yield key, index, outcome


@pytest.mark.slow  # ~2.5 s of CPU: a sweep run
def test_the_cases_of_a_scene_handed_back_are_let_go(tmp_path):
    """Once a scene's rows are handed back, nothing of the run holds its cases' outcomes: when each variant's rows
    arrive, every earlier variant's outcome is gone (the run held every one until it ended)."""
    variants = library.load([str(_scene(tmp_path, SPEEDS))])
    executor = _Watched()
    alive = []
    for k, (scene, rows, _) in enumerate(run_scenes(variants, [make_engine("core")], make_engine, 0, executor)):
        assert scene.name == variants[k].name and rows
        del rows
        gc.collect()
        alive.append(sum(ref() is not None for ref in executor.outcomes[:CASES_PER_VARIANT * k]))
    assert len(executor.outcomes) == CASES_PER_VARIANT * SPEEDS and alive == [0] * SPEEDS


@pytest.mark.slow
def test_a_sweep_killed_midway_and_resumed_stores_the_uninterrupted_results(tmp_path):
    scene = _scene(tmp_path, 3 * SPEEDS)
    _killed_and_resumed(tmp_path, scene, 3 * SPEEDS, ["--jobs", "2"], report=False, whole_in_process=True)


@pytest.mark.slow
@pytest.mark.sweep  # two runs of 1,000 variants on a local Dask cluster: minutes, with the other sweeps
def test_a_thousand_variants_on_dask_killed_and_resumed_store_the_uninterrupted_results(tmp_path):
    scene = _scene(tmp_path, MAX_VARIANTS)
    whole = _killed_and_resumed(tmp_path, scene, MAX_VARIANTS, ["--executor", "dask", "--jobs", "2"])
    peak = PeakMemory.of_run(whole)
    assert peak is None or peak.this_process_bytes < CLIENT_PEAK_MIB * 2**20


def _arguments(scene, out, options: list[str]) -> list[str]:
    return ["run", str(scene), "--engines", "core", "--repeats", "0", *options, "--out", str(out)]


def _command(scene, out, options: list[str]) -> list[str]:
    return [sys.executable, "-m", "simparity.comparisons.cli", *_arguments(scene, out, options)]


def _killed_and_resumed(tmp_path, scene, variants: int, options: list[str], report: bool = True,
                        whole_in_process: bool = False):
    """Run ``scene`` whole, and again killed once half its cases are kept, then resumed: the two stored runs must be
    the same, timing aside. Returns the whole run's folder. ``report`` False: no report drawn (what is compared is
    the stored run, not its drawing). ``whole_in_process``: the whole run is ``main`` in this process, on one case
    worker (a command's start and a second worker cost ~3.5 CPU-s; what is stored does not depend on either, and the
    run killed beside it keeps ``options``), else a command of its own with ``options`` (its client's peak memory is
    then the run's)."""
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    drawn = () if report else ("--no-report",)
    if whole_in_process:
        assert main(_arguments(scene, whole, [*options, *drawn, "--jobs", "1"])) == 0  # the last --jobs counts
    else:
        subprocess.run(_command(scene, whole, [*options, *drawn]), check=True, capture_output=True)
    killed_and_resumed(_command(scene, killed, [*options, *drawn]), killed, CASES_PER_VARIANT * variants,
                       KILL_WAIT_SECONDS, drawn)
    assert differences(whole, killed) == []
    return whole
