"""`simparity bench` (issue #11): its measurements, the target verdicts and BENCHMARKS.md."""

from __future__ import annotations

import math

import pytest

from simparity.comparisons import bench
from simparity.comparisons.bench import BenchRow, equal_error_factor, markdown, targets


def _row(section, workload, engine, method, batch, value, accuracy, unit="rad", note=""):
    return BenchRow(section, workload, engine, method, batch, value, "us/body-step", accuracy, unit, note)


def test_equal_error_converts_a_larger_error_into_steps_and_never_rewards_a_smaller_one():
    # RK4: 16x the error needs 16^(1/4) = 2x the steps, so half the speed advantage.
    assert equal_error_factor(16e-12, 1e-12, 4) == pytest.approx(0.5)
    assert equal_error_factor(1e-12, 16e-12, 4) == 1.0
    assert equal_error_factor(0.0, 1e-12, 4) == 1.0


def test_targets_judge_speed_at_equal_error_and_ik_rates():
    rows = [_row("dynamics", "tumbling", "core", "rk4", 10_000, 0.3, 1.6e-11),
            _row("dynamics", "tumbling", "mujoco", "rk4", 10_000, 1.8, 1e-12),
            _row("dynamics", "tumbling", "mujoco-rollout", "rk4", 10_000, 3.6, 1e-12),
            _row("dynamics", "tumbling", "mujoco-rollout", "euler", 10_000, 1.2, 3e-3),
            BenchRow("ik", "arm", "core", "damped_least_squares+restarts", 100, 0.1, "ms/solve", 0.9995,
                     "solve rate", "0 solutions outside the limits"),
            BenchRow("ik", "arm", "pybullet", "calculateInverseKinematics", 100, 0.2, "ms/solve", 0.5,
                     "solve rate", "0 solutions outside the limits"),
            BenchRow("ik", "arm", "mink", "documented loop", 100, math.nan, "ms/solve", math.nan, "solve rate",
                     "n/a: mink not installed")]
    verdicts = [(target, met) for target, _, met in targets(rows)]
    results = [met for _, met in verdicts]
    # 6x per body-step but 16x the error: 3x at equal error, below 5x -> missed; 4x rollout Euler with a
    # smaller error -> met; IK rate and speed -> met (the uninstalled library is left out).
    assert results[:3] == [False, True, True] and all(results[3:]), verdicts


def test_markdown_shows_tables_ratios_and_misses():
    rows = [_row("dynamics", "tumbling", "core", "rk4", 1, 200.0, 1e-11),
            _row("dynamics", "tumbling", "mujoco", "rk4", 1, 6.0, 1e-12),
            _row("dynamics", "tumbling", "pybullet", "euler", 1, math.nan, 3e-3, note="n/a: skipped")]
    text = markdown(rows, {"cores": "2"}, "simparity bench", "profile lines", 12.0)
    assert "| mujoco | rk4 | 6 |" in text and "**MISSED**" in text and "n/a: skipped" in text
    assert "0.03" in text  # the ratio mujoco / core = 6 / 200
    assert "profile lines" in text


@pytest.mark.slow
def test_a_small_real_run_measures_every_section(monkeypatch, tmp_path):
    """Every section runs end to end on tiny sizes and gives finite times with errors (or n/a saying why)."""
    monkeypatch.setattr(bench, "DYNAMICS", (("core", "rk4"), ("mujoco", "rk4"), ("mujoco-rollout", "euler")))
    monkeypatch.setattr(bench, "ERROR_STEPS", 20)
    monkeypatch.setattr(bench, "KINEMATICS", ("core", "pinocchio"))
    monkeypatch.setattr(bench, "IK", (("core", "damped_least_squares+restarts"), ("mujoco", "dls")))
    monkeypatch.setattr(bench, "LIBRARY_TARGETS", 3)
    lines = []
    rows = bench.dynamics_rows([1, 3], quick=True, say=lines.append)
    rows += bench.kinematics_rows([2], say=lines.append)
    rows += bench.ik_rows(5, say=lines.append)
    measured = [r for r in rows if math.isfinite(r.value)]
    assert {r.section for r in measured} == {"dynamics", "kinematics", "ik"}
    assert all(math.isfinite(r.accuracy) for r in measured)
    assert all(r.note.startswith("n/a: ") for r in rows if not math.isfinite(r.value))
    core_rk4 = [r for r in rows if (r.engine, r.method) == ("core", "rk4")]
    assert core_rk4 and all(r.accuracy < 1e-9 for r in core_rk4)  # rk4 at dt 1e-3 over 20 steps
    bench.write_csv(rows, tmp_path / "benchmarks.csv")
    assert (tmp_path / "benchmarks.csv").read_text().count("\n") == len(rows) + 1


def test_a_measurement_over_budget_is_skipped_with_its_probed_estimate(monkeypatch):
    """The skip rule probes the batch size itself (a smaller batch's cost per body-step overestimated core's
    batched cost a hundredfold and skipped rows that take a quarter second)."""
    monkeypatch.setattr(bench, "DYNAMICS", (("core", "rk4"),))
    monkeypatch.setattr(bench, "ERROR_STEPS", 5)
    monkeypatch.setattr(bench, "BUDGET_SECONDS", 0.0)
    rows = bench.dynamics_rows([2], quick=True, say=lambda line: None)
    assert rows and all(not math.isfinite(r.value) and "steps predict" in r.note for r in rows)
    assert all(math.isfinite(r.accuracy) for r in rows)  # the error is still measured


def test_memory_targets_say_whether_memory_is_flat_in_the_steps():
    rows = [BenchRow("memory", "hard-million-steps", "simparity run", "every default engine", steps, mib, "MiB", 1.0,
                     "s") for steps, mib in ((100_000, 330.0), (1_000_000, 960.0))]
    verdicts = {target.split(" (")[0].split(" for ")[0]: (measured, met) for target, measured, met in targets(rows)
                if "memory" in target}
    assert verdicts["peak memory <= 1,024 MiB"][1] is True
    flat_measured, flat_met = verdicts["memory flat in the number of steps"]
    assert flat_met is False and "734 bytes per step" in flat_measured  # (960 - 330) MiB / 900,000 steps
