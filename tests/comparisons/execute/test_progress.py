"""The progress bar: drawn only on a terminal, with counts and the time left (every case is counted whichever
process ran it: tests/comparisons/execute/test_execution.py)."""

import io

import pytest

from simparity.comparisons.execute.estimate import RunEstimate
from simparity.comparisons.execute.progress import ProgressBar


@pytest.fixture(autouse=True)
def _wide_terminal(monkeypatch):
    """The bar is cut to the terminal's width (COLUMNS first): a wide one shows the whole line."""
    monkeypatch.setenv("COLUMNS", "200")


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bar_shows_counts_scene_and_time_left_on_a_terminal():
    clock = iter([0.0, 10.0, 20.0]).__next__   # start, then two cases 10 s apart
    stream = _Terminal()
    bar = ProgressBar(4, stream, clock=clock)
    bar.case_done("wind", "core", "rk4")
    bar.case_done("wind", "mujoco", "euler")
    text = stream.getvalue().split("\r")[-1]
    assert "2/4 cases · wind · mujoco euler" in text and "20s left" in text   # 20 s for 2, 2 to go
    bar.clear()
    assert stream.getvalue().endswith("\r\033[K")


def test_nothing_is_drawn_when_not_on_a_terminal():
    stream = io.StringIO()
    bar = ProgressBar(3, stream)
    bar.case_done("wind", "core", "rk4")
    bar.scene_done(3)
    assert stream.getvalue() == "" and not bar.active and bar.done == 3


def test_time_left_is_the_modelled_cost_still_to_run_at_the_pace_measured():
    """Issue #39: a cheap case done in 10 s, a case modelled 99 x costlier to go: 990 s left, not 10 s."""
    clock = iter([0.0, 10.0]).__next__
    stream = _Terminal()
    costs = {("chain", "pinocchio", "recursive"): 1.0, ("chain", "core", "jacobian_sum"): 99.0}
    bar = ProgressBar(2, stream, clock=clock, estimate=RunEstimate(2, 99.0, 2, 100.0, by_case=costs))
    bar.case_done("chain", "pinocchio", "recursive")
    assert "1/2 cases" in stream.getvalue() and "16m30s left" in stream.getvalue()
