"""The report's figures (reports/figures.py), drawn from hand-made cases: laid out once with no layout engine left
(a save draws once), log ticks without mathtext, and the sweep's figures."""

import os
import subprocess
import sys
import time

import pandas as pd
import pytest

from simparity.reports import figures

REFERENCE = "analytic:exact"


def _cases():
    """Two schemes at three time steps (summary.dynamics_cases' columns)."""
    return pd.DataFrame([{"scene": "s", "engine": engine, "integrator": "rk4", "dt": dt, "status": "ok",
                          "error": scale * dt ** 4, "time_per_step": 1e-5, "cost": 1e-5 / dt}
                         for engine, scale in (("core", 1.0), ("mujoco", 2.0)) for dt in (0.01, 0.02, 0.04)])


def _drawn_labels(fig) -> list[str]:
    fig.canvas.draw()
    return [t.get_text() for ax in fig.axes for t in ax.get_xticklabels() + ax.get_yticklabels() if t.get_text()]


@pytest.mark.slow
def test_dynamics_figures_leave_no_layout_engine_and_label_log_ticks_in_unicode():
    for fig in (figures.work_precision_figure("s", _cases(), "position_error_max", REFERENCE),
                figures.convergence_figure("s", _cases(), "position_error_max", REFERENCE, {}, {"core": {"rk4": 4}})):
        assert fig.get_layout_engine() is None
        labels = _drawn_labels(fig)
        assert any("10⁻" in label for label in labels) and not any("$" in label for label in labels)
        figures.plt.close(fig)


def _across(statuses=("ok", "ok")):
    """One scheme over a sweep's variants at two time steps (sweep_summary.across' columns)."""
    return pd.DataFrame({"engine": "core", "integrator": "rk4", "dt": [0.01, 0.02], "status": list(statuses),
                         "value": [1e-6, 1e-5], "best": [1e-8, 0.0], "median": [1e-7, 1e-6], "cost": [1e-3, 5e-4]})


def test_the_sweeps_work_precision_figure_draws_the_worst_variant_and_a_band_to_the_best():
    fig = figures.sweep_work_precision_figure("b", _across(), "position error max [m]", REFERENCE, 100)
    (ax,) = fig.axes
    line = ax.get_lines()[0]
    assert list(line.get_xdata()) == [1e-6, 1e-5] and list(line.get_ydata()) == [1e-3, 5e-4]
    assert "over 100 variants" in ax.get_title(loc="left")
    figures.plt.close(fig)
    assert figures.sweep_work_precision_figure("b", _across(("diverged", "n/a")), "e", REFERENCE, 2) is None


def test_the_sweep_figure_draws_a_panel_per_combination_it_is_given():
    cases = pd.DataFrame({"engine": "core", "integrator": "rk4", "status": "ok", "value": [1.0, 2.0, 3.0, 4.0],
                          "x": [0.1, 0.2, 0.1, 0.2], "y": [1.0, 1.0, 2.0, 2.0]})
    fig = figures.sweep_figure("b", cases, "x", ["y"], "error [m]", REFERENCE)
    assert len(fig.axes) == 2 and fig.get_layout_engine() is None
    figures.plt.close(fig)
    assert figures.sweep_figure("b", cases.assign(status="n/a"), "x", ["y"], "error [m]", REFERENCE) is None


ORPHAN_SECONDS = 10.0
"""How long the figure processes of a killed report may take to go: the kernel signals them at once."""

KILLED_WRITER = """
import os, signal, sys
from pathlib import Path
import matplotlib.pyplot as plt
from simparity.reports.figures import FigureWriter
with FigureWriter(2) as writer:
    writer.submit(plt.figure(), Path(sys.argv[1]), "first").result()  # the pool's processes are up
    print(" ".join(str(pid) for pid in writer._pool._processes), flush=True)
    os.kill(os.getpid(), signal.SIGKILL)
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/status", encoding="utf-8") as f:
            return not any(line.startswith("State:") and "Z" in line for line in f)
    except FileNotFoundError:
        return False


@pytest.mark.slow
def test_the_figure_processes_of_a_killed_report_do_not_outlive_it(tmp_path):
    """SIGKILL while figures are written (a CI job cancelled): the pool's processes end with their parent."""
    done = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(tmp_path)], capture_output=True, text=True,
                          timeout=120)
    pids = [int(p) for p in done.stdout.split()]
    assert done.returncode == -9 and len(pids) >= 1, done.stderr
    deadline = time.monotonic() + ORPHAN_SECONDS
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(p) for p in pids)
    assert os.path.exists(tmp_path / "first.svg")
