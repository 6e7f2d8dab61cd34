"""Issue #29: ``simparity bench``'s sweep rows (comparisons/bench/sweep.py): the wall time and the client's peak memory
of ``simparity run`` on sweeps of 10, 100 and 1,000 variants on a local Dask cluster."""

from __future__ import annotations

import math

import pytest

from simparity.comparisons.bench import sweep as bench_sweep
from simparity.comparisons.bench.memory import run_peak_memory
from simparity.comparisons.bench.rows import BenchRow
from simparity.comparisons.execute.timing import PeakMemory
from simparity.comparisons.scenes import library


@pytest.mark.parametrize("variants", [10, 100])
def test_the_swept_scene_has_the_variants_asked_for(tmp_path, variants):
    path = tmp_path / "throw.toml"
    path.write_text(bench_sweep.sweep_scene(variants), encoding="utf-8")
    scenes = library.load([str(path)])
    assert len(scenes) == variants and scenes[0].sweep.count == variants
    assert {len(s.dts) for s in scenes} == {1} and scenes[0].integrators == ("rk4", "semi_implicit_euler")


@pytest.mark.parametrize("variants", [0, 15])
def test_a_count_the_sweep_cannot_make_is_refused(variants):
    with pytest.raises(ValueError, match=f"variants {variants}"):
        bench_sweep.sweep_scene(variants)


def test_a_row_per_count_of_variants_and_its_table(monkeypatch):
    """Each count is one run (a fresh folder, the local Dask cluster): its client's peak [MiB] with its wall time;
    a run that recorded no peak is n/a with why."""
    asked = []

    def run(arguments, out):
        asked.append((arguments, out))
        return (PeakMemory(300 * 2**20, 500 * 2**20), 12.5, "") if len(asked) == 1 else (None, 3.0, "killed")

    rows = bench_sweep.sweep_rows(True, run, BenchRow, lambda line: None)
    assert [r.batch for r in rows] == list(bench_sweep.QUICK_VARIANTS)
    assert rows[0].value == 300 and rows[0].accuracy == 12.5 and rows[0].unit == "MiB"
    assert math.isnan(rows[1].value) and rows[1].note == "n/a: the run recorded no peak memory: killed"
    assert all("--executor" in arguments and "dask" in arguments for arguments, _ in asked)
    assert len({out for _, out in asked}) == len(asked)
    text = "\n".join(bench_sweep.markdown_lines(rows))
    assert "| 10 | 20 | 300 | 12 |" in text and "| 100 | 200 | n/a | 3 |" in text
    assert bench_sweep.markdown_lines([]) == []


def _unreported(arguments, out):
    """:func:`run_peak_memory` of a run that draws no report: the client's peak is recorded all the same."""
    return run_peak_memory([*arguments, "--no-report"], out)


@pytest.mark.slow
def test_a_real_sweep_run_records_its_clients_peak(monkeypatch):
    """The smallest sweep on a local Dask cluster of one worker (what is checked is the client's recorded peak, not the
    cluster's parallelism): a Python process with NumPy, pandas and the scheduler holds well over 50 MiB."""
    monkeypatch.setattr(bench_sweep, "QUICK_VARIANTS", (10,))
    monkeypatch.setattr(bench_sweep, "WORKERS", 1)
    [row] = bench_sweep.sweep_rows(True, _unreported, BenchRow, lambda line: None)
    assert 50 < row.value < 2048 and row.accuracy > 0 and not row.note.startswith("n/a")
